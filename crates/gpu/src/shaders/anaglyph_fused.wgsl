// The anaglyph folded into the eye passes (src/gpu/resident.rs), after common.wgsl,
// blinn_phong.wgsl, `const LINEAR_LIGHT` and anaglyph_mix.wgsl. The left eye's pass writes its
// color and, as a second target, the anaglyph of that color with the right eye's background;
// the right eye's pass, depth-tested as usual, writes the anaglyph of the left eye's color
// under it with its own into that second target. Where neither eye drew, the target keeps its
// clear value, the anaglyph of the two backgrounds. Only the anaglyph comes back to the host.
// params[0..6]: anaglyph_mix.wgsl's; params[6].rgb: the right eye's background, stored.

@group(1) @binding(0) var<uniform> params: array<vec4<f32>, 7>;
@group(1) @binding(1) var left_color: texture_2d<f32>;

// A quantized color (`quantize`: k/255) as the texture unit reads the stored k back, so that
// the eye passes mix exactly what the full-screen pass reads from the eye textures: k·(1/255)
// on lavapipe (tests/gpu_finalize.rs holds the two frames' bytes equal).
fn stored(q: vec4<f32>) -> vec3<f32> {
    return round(q.rgb * 255.0) * (1.0 / 255.0);
}

struct LeftOut {
    @location(0) color: vec4<f32>,
    @location(1) anaglyph: vec4<f32>,
}

@fragment
fn fs_left(in: VertexOut, @builtin(front_facing) front_facing: bool) -> LeftOut {
    let q = shade(in, front_facing);
    var out: LeftOut;
    out.color = q;
    out.anaglyph = anaglyph_of(stored(q), params[6].rgb);
    return out;
}

@fragment
fn fs_right(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let q = shade(in, front_facing);
    let left = textureLoad(left_color, vec2<i32>(in.clip.xy), 0).rgb;
    return anaglyph_of(left, stored(q));
}
