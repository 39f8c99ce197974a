// Parallax color: a mirror of `parallax_color(parallax_pixels(d), scale)` in
// src/effects/parallax.rs (the image area; the legend bar is 2D drawing done on the CPU).
// input0: the eye whose depth is read.
// params[0]: (A, B, scale, _) with p(d) = A + B·d pixels, the host's f64 rewrite of
//   p = ppu·e·(b − z0/z), z = n f/(f − d (f − n)):  A = ppu·e·(b − z0/n), B = ppu·e·z0 (f − n)/(n f)
//   (affine in the window depth d, so f32 keeps it to |B|·2⁻²⁴ px instead of cancelling in z).
// params[1]: the background color (0..1).
// Writes p in pixels to the depth output (NaN on the background), so the host can take the
// color scale from the GPU's own values.

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> FullscreenOut {
    let d = textureLoad(input0_depth, texel(pos), 0).r;
    var out: FullscreenOut;
    if !(d < 1.0) {
        out.color = params[1];
        out.depth = bitcast<f32>(0x7fc00000u);
        return out;
    }
    let p = params[0].x + params[0].y * d;
    let t = clamp(p / params[0].z, -1.0, 1.0);
    var end = vec3<f32>(255.0, 32.0, 0.0);
    var s = t;
    if t < 0.0 {
        end = vec3<f32>(0.0, 64.0, 255.0);
        s = -t;
    }
    // `(255 + (end − 255)·s).round()`: every value is ≥ 0, so round is floor(x + ½).
    let k = floor(vec3<f32>(255.0) + (end - vec3<f32>(255.0)) * s + 0.5);
    out.color = vec4<f32>(k / 255.0, 1.0);
    out.depth = p;
    return out;
}
