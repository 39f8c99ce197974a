// Depth only: a mirror of `DepthOnly` in src/shade.rs (no fragment stage at all).

struct Uniforms {
    // mvp · model (OpenGL clip space; z goes to wgpu's below).
    mvp: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> u: Uniforms;

// glam's `Mat4 * Vec4`: ((c0·x + c1·y) + c2·z) + c3·w.
@vertex
fn vs_main(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    let v = vec4<f32>(position, 1.0);
    var r = u.mvp[0] * v.x;
    r = r + u.mvp[1] * v.y;
    r = r + u.mvp[2] * v.z;
    r = r + u.mvp[3] * v.w;
    // GL_TO_WGPU_DEPTH, as common.wgsl's `gl_to_wgpu_depth`.
    return vec4<f32>(r.x, r.y, 0.5 * (r.z + r.w), r.w);
}
