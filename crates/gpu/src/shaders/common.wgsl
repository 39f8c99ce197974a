// The math the scene shaders share, in glam's order of operations so that every result has
// the CPU's bits (prepended to blinn_phong.wgsl, chromadepth.wgsl and the full-screen
// prelude by the host: WGSL has no #include).

// glam's `Mat4::transform_point3`: ((c0·x + c1·y) + c2·z) + c3, in that order.
fn transform_point3(m: mat4x4<f32>, p: vec3<f32>) -> vec3<f32> {
    var r = m[0] * p.x;
    r = m[1] * p.y + r;
    r = m[2] * p.z + r;
    r = m[3] + r;
    return r.xyz;
}

// glam's `Mat4 * Vec4`: ((c0·x + c1·y) + c2·z) + c3·w.
fn mul_vec4(m: mat4x4<f32>, v: vec4<f32>) -> vec4<f32> {
    var r = m[0] * v.x;
    r = r + m[1] * v.y;
    r = r + m[2] * v.z;
    r = r + m[3] * v.w;
    return r;
}

// GL_TO_WGPU_DEPTH (src/gpu/mod.rs) applied to a clip position: z' = 0.5·(z + w), one
// rounding per operation, as the CPU's `WindowVertex::from_clip` computes it (depth bit for
// bit: docs/gpu-parity.md).
fn gl_to_wgpu_depth(c: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(c.x, c.y, 0.5 * (c.z + c.w), c.w);
}

// glam's `Mat3 * Vec3`: (c0·x + c1·y) + c2·z.
fn mul_vec3(m: mat3x3<f32>, v: vec3<f32>) -> vec3<f32> {
    var r = m[0] * v.x;
    r = r + m[1] * v.y;
    r = r + m[2] * v.z;
    return r;
}

// glam's `Vec3::dot`: (x·x' + y·y') + z·z'.
fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

// glam's `Vec3::normalize_or_zero`: v · (1 / sqrt(v·v)), zero when that is not finite or ≤ 0.
fn normalize_or_zero(v: vec3<f32>) -> vec3<f32> {
    let rcp = 1.0 / sqrt(dot3(v, v));
    // 3.4028235e38 is f32::MAX: `rcp <= MAX && rcp > 0` is glam's `is_finite() && > 0`.
    if rcp > 0.0 && rcp <= 3.4028235e38 {
        return v * rcp;
    }
    return vec3<f32>(0.0);
}

// `to_rgba8`: (clamp(x, 0, 1)·255 + 0.5) truncated, returned as k/255 so that the Rgba8Unorm
// store (round to nearest) writes exactly k.
fn quantize(c: vec3<f32>) -> vec4<f32> {
    let k = floor(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return vec4<f32>(k / 255.0, 1.0);
}
