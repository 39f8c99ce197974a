// Blinn-Phong in eye space: a line-by-line mirror of `BlinnPhong` in src/shade.rs, so that the
// GPU path differs from the CPU path only where the hardware rounds differently (fused
// multiply-add, reciprocal, sqrt and pow precision: docs/gpu-parity.md).

struct Uniforms {
    // view · model (`BlinnPhong::modelview`).
    modelview: mat4x4<f32>,
    // The OpenGL projection (`gl_to_wgpu_depth` then remaps z to [0, w]).
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

@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    var out: VertexOut;
    let p_eye = transform_point3(u.modelview, position);
    out.p_eye = p_eye;
    out.n_eye = mul_vec3(u.normal_matrix, normal);
    out.clip = gl_to_wgpu_depth(mul_vec4(u.projection, vec4<f32>(p_eye, 1.0)));
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return shade(in, front_facing);
}

// The fragment's color, quantized (`quantize`): also called by anaglyph_fused.wgsl.
fn shade(in: VertexOut, front_facing: bool) -> vec4<f32> {
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
