// The ChromaDepth pass: a mirror of `ChromaDepthShader` in src/render/chromadepth.rs.
// Eye-linear texgen `s = A x + B y + C z + D` on the eye-space vertex (per vertex, interpolated)
// or from the fragment's own window depth (per pixel), then the ramp sampled like an OpenGL 1D
// texture with GL_CLAMP_TO_EDGE (`Ramp::sample`), optionally scaled by a gray diffuse term.

struct Uniforms {
    // view · model of the center eye (`ChromaDepthShader::new`).
    modelview: mat4x4<f32>,
    // The OpenGL projection (`gl_to_wgpu_depth` then remaps z to [0, w]).
    projection: mat4x4<f32>,
    // Inverse transpose of the modelview's linear part (lit only).
    normal_matrix: mat3x3<f32>,
    light_eye: vec3<f32>,
    ambient: f32,
    // The texgen plane (A, B, C, D), `Texgen::plane`.
    plane: vec4<f32>,
    // OpenGL projection's P[2][2] and P[3][2] (per-pixel texgen), texel count, flags
    // (1: linear sampling, 2: per-pixel texgen, 4: lit).
    misc: vec4<f32>,
}

@group(0) @binding(0) var<uniform> u: Uniforms;
// The ramp's texels, near (red) first (`Ramp::texels`).
@group(1) @binding(0) var<storage, read> ramp: array<vec4<f32>>;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(perspective) s: f32,
    @location(1) @interpolate(perspective) p_eye: vec3<f32>,
    @location(2) @interpolate(perspective) n_eye: vec3<f32>,
}

fn flag(bit: u32) -> bool {
    return (u32(u.misc.w) & bit) != 0u;
}

// `Texgen::s`: A x + B y + C z + D (the plane has A = B = 0, so the order of summation is moot).
fn texgen(p: vec3<f32>) -> f32 {
    return ((u.plane.x * p.x + u.plane.y * p.y) + u.plane.z * p.z) + u.plane.w;
}

// `Ramp::sample`: clamp s to [0, 1] (NaN to 0), then nearest ⌊s N⌋ or linear around s N − ½.
fn sample_ramp(s_in: f32) -> vec3<f32> {
    var s = clamp(s_in, 0.0, 1.0);
    if s_in != s_in {
        s = 0.0;
    }
    let n = u.misc.z;
    let last = u32(n) - 1u;
    if !flag(1u) {
        return ramp[min(u32(s * n), last)].xyz;
    }
    let u1 = s * n + 0.5;
    let i1 = u32(u1);
    let t = u1 - f32(i1);
    let a = ramp[min(max(i1, 1u) - 1u, last)].xyz;
    let b = ramp[min(i1, last)].xyz;
    // glam's `Vec3::lerp`: a·(1 − t) + b·t.
    return a * (1.0 - t) + b * t;
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    let p_eye = transform_point3(u.modelview, position);
    out.s = texgen(p_eye);
    out.p_eye = p_eye;
    out.n_eye = mul_vec3(u.normal_matrix, normal);
    out.clip = gl_to_wgpu_depth(mul_vec4(u.projection, vec4<f32>(p_eye, 1.0)));
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var s = in.s;
    if flag(2u) {
        // Per-pixel texgen: the window depth back to eye z through OpenGL's projection,
        // z_ndc = 2 z_win − 1, z_eye = −P[3][2] / (z_ndc + P[2][2]).
        let z_ndc = 2.0 * in.clip.z - 1.0;
        let z_eye = -u.misc.y / (z_ndc + u.misc.x);
        s = u.plane.z * z_eye + u.plane.w;
    }
    let color = sample_ramp(s);
    if !flag(4u) {
        return quantize(color);
    }
    var n = normalize_or_zero(in.n_eye);
    if !front_facing {
        n = -n;
    }
    let diffuse = max(dot3(n, normalize_or_zero(u.light_eye - in.p_eye)), 0.0);
    return quantize(color * (u.ambient + (1.0 - u.ambient) * diffuse));
}
