// The anaglyph family as a full-screen pass (anaglyph_mix.wgsl prepended).
// input0 = the eye ML reads, input1 = the eye MR reads (the host swaps them for `swap_eyes`).

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> FullscreenOut {
    let a = textureLoad(input0_color, texel(pos), 0).rgb;
    let b = textureLoad(input1_color, texel(pos), 0).rgb;
    var out: FullscreenOut;
    out.color = anaglyph_of(a, b);
    out.depth = 0.0;
    return out;
}
