// The SIRDS paper's strip pass (§3–4, Fig. 4) on the GPU: a mirror of `StripShader` in
// src/render/sirds_strips/. The host uploads the shifted clip positions (x + toward·s·w/W,
// computed exactly as the CPU does, z already in wgpu's [0, w]) and each vertex's separation s;
// the scissor rect is the strip, so only its pixels are shaded. The fragment reads the previous
// image (`image`, RGBA8 as 0..1) at x − toward·s with `textureLoad` (no sampler: exact texels).

struct Strip {
    // +1: copies from x − s (right-going strips), −1: from x + s (left-going).
    toward: f32,
    // Sources allowed in [lo, hi); outside, the fragment is discarded and the pixel keeps its
    // value (the pattern).
    lo: i32,
    hi: i32,
    // 1: linear between the two nearest pixels, 0: the nearest pixel.
    bilinear: u32,
}

@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var<uniform> strip: Strip;

struct VsOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(perspective) separation: f32,
}

@vertex
fn vs_main(@location(0) clip: vec4<f32>, @location(1) separation: f32) -> VsOut {
    var out: VsOut;
    out.pos = clip;
    out.separation = separation;
    return out;
}

// The stored 8-bit levels of a texel (Rgba8Unorm reads back as k/255; rounding recovers k).
fn levels(x: i32, y: i32) -> vec4<f32> {
    return floor(textureLoad(image, vec2<i32>(x, y), 0) * 255.0 + 0.5);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let x = i32(in.pos.x);
    let y = i32(in.pos.y);
    // Source position in pixel-index units (pixel centers at integers), as the CPU computes it:
    // toward is ±1, so the product is exact and a fused multiply-add cannot change p.
    let p = f32(x) - strip.toward * in.separation;
    if strip.bilinear != 0u {
        let f = floor(p);
        let i0 = i32(f);
        let t = p - f;
        var i1 = i0;
        if t > 0.0 {
            i1 = i0 + 1;
        }
        if i0 < strip.lo || i1 >= strip.hi {
            discard;
        }
        let a = levels(i0, y);
        let b = levels(i1, y);
        // `(a + (b − a) t + 0.5) as u8`: truncation of a non-negative value ≤ 255.5 is floor.
        let m = floor(a + (b - a) * t + 0.5);
        return vec4<f32>(m.rgb / 255.0, 1.0);
    }
    let i = i32(floor(p + 0.5));
    if i < strip.lo || i >= strip.hi {
        discard;
    }
    return levels(i, y) / 255.0;
}
