// Blinn-Phong in eye space: a line-by-line mirror of `BlinnPhong` in src/shade.rs, so that the
// GPU path differs from the CPU path only where the hardware rounds differently (fused
// multiply-add, reciprocal, sqrt and pow precision: the README's "CPU vs GPU" section).

struct Uniforms {
    // view · model (`BlinnPhong::modelview`).
    modelview: mat4x4<f32>,
    // GL_TO_WGPU_DEPTH · projection: OpenGL clip space with z remapped to [0, w].
    projection: mat4x4<f32>,
    // Inverse transpose of the modelview's linear part.
    normal_matrix: mat3x3<f32>,
    light_eye: vec3<f32>,
    ambient: f32,
    color: vec3<f32>,
    specular: f32,
    shininess: f32,
}

@group(0) @binding(0) var<uniform> u: Uniforms;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(perspective) p_eye: vec3<f32>,
    @location(1) @interpolate(perspective) n_eye: vec3<f32>,
}

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

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    let p_eye = transform_point3(u.modelview, position);
    out.p_eye = p_eye;
    out.n_eye = mul_vec3(u.normal_matrix, normal);
    out.clip = mul_vec4(u.projection, vec4<f32>(p_eye, 1.0));
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let p = in.p_eye;
    var n = normalize_or_zero(in.n_eye);
    if !front_facing {
        n = -n; // two-sided lighting: back faces lit as seen
    }
    let l = normalize_or_zero(u.light_eye - p);
    let h = normalize_or_zero(l + normalize_or_zero(-p));
    let diffuse = max(dot3(n, l), 0.0);
    var spec = 0.0;
    if diffuse > 0.0 {
        spec = pow(max(dot3(n, h), 0.0), u.shininess) * u.specular;
    }
    let c = u.color * (u.ambient + (1.0 - u.ambient) * diffuse) + vec3<f32>(spec);
    return quantize(c);
}
