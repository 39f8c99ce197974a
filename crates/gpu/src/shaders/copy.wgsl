// The identity full-screen pass: input 0's color and depth, unchanged. RGBA8 → f32 → RGBA8 is
// exact (k/255 rounds back to k), and depth goes through R32Float bit for bit.

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> FullscreenOut {
    var out: FullscreenOut;
    out.color = textureLoad(input0_color, texel(pos), 0);
    out.depth = textureLoad(input0_depth, texel(pos), 0).r;
    return out;
}
