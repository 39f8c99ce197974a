// Shared by every full-screen pass (prepended by src/gpu/fullscreen.rs, after the generated
// input bindings `input{i}_color: texture_2d<f32>` (RGBA8 as 0..1) and
// `input{i}_depth: texture_2d<f32>` (window depth in .r), and `params`).
// One triangle covers the viewport; fragment (x, y) reads texel (x, y) of each input exactly
// (`textureLoad`, no filtering) and writes color and depth.

struct FullscreenOut {
    @location(0) color: vec4<f32>,
    @location(1) depth: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // Vertices (−1, −1), (3, −1), (−1, 3): the viewport and nothing but clipped-away area.
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

// The texel under the fragment.
fn texel(pos: vec4<f32>) -> vec2<i32> {
    return vec2<i32>(pos.xy);
}

