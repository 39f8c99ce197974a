// The anaglyph family's arithmetic: a mirror of `anaglyph::anaglyph_pixel` in
// src/effects/anaglyph.rs, shared by the full-screen pass (anaglyph.wgsl) and the anaglyph
// folded into the eye passes (anaglyph_fused.wgsl), which declare `params` and `LINEAR_LIGHT`.
// params[0..3]: ML rows (xyz), params[3..6]: MR rows (xyz). Linear light is `LINEAR_LIGHT`,
// a constant the host prepends (one pipeline per mode, src/gpu/effects.rs): llvmpipe may run
// both sides of a branch under an execution mask, and a uniform flag would then pay for the
// sRGB curves on every pixel of a stored-value anaglyph too.
// The matrices come from `AnaglyphKind::matrices` on the host; none is written here.

// IEC 61966-2-1 decoding, as `srgb_to_linear`.
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        return c / 12.92;
    }
    return pow((c + 0.055) / 1.055, 2.4);
}

// IEC 61966-2-1 encoding, as `linear_to_srgb`.
fn linear_to_srgb(l: f32) -> f32 {
    if l <= 0.0031308 {
        return 12.92 * l;
    }
    return 1.055 * pow(l, 1.0 / 2.4) - 0.055;
}

// `mix` for row i, summed left to right as the CPU does:
// ((((l0·a0 + l1·a1) + l2·a2) + r0·b0) + r1·b1) + r2·b2, then clamped to [0, 1].
fn mix_row(i: i32, a: vec3<f32>, b: vec3<f32>) -> f32 {
    let l = params[i].xyz;
    let r = params[i + 3].xyz;
    var v = l.x * a.x;
    v = v + l.y * a.y;
    v = v + l.z * a.z;
    v = v + r.x * b.x;
    v = v + r.y * b.y;
    v = v + r.z * b.z;
    return clamp(v, 0.0, 1.0);
}

// The anaglyph of stored colors `a` (the eye ML reads) and `b` (the eye MR reads), each as the
// texture unit decodes RGBA8, quantized for an RGBA8 store.
fn anaglyph_of(a_stored: vec3<f32>, b_stored: vec3<f32>) -> vec4<f32> {
    let linear_light = LINEAR_LIGHT;
    var a = a_stored;
    var b = b_stored;
    if linear_light {
        a = vec3<f32>(srgb_to_linear(a.x), srgb_to_linear(a.y), srgb_to_linear(a.z));
        b = vec3<f32>(srgb_to_linear(b.x), srgb_to_linear(b.y), srgb_to_linear(b.z));
    }
    var c = vec3<f32>(mix_row(0, a, b), mix_row(1, a, b), mix_row(2, a, b));
    if linear_light {
        c = vec3<f32>(linear_to_srgb(c.x), linear_to_srgb(c.y), linear_to_srgb(c.z));
    }
    return quantize(c);
}
