//! Projection matrices, look-at, and the stereo rig.
//!
//! Conventions (as in every source document): right-handed world, the camera looks down −Z,
//! Y is up, OpenGL NDC with Z in [−1, 1]. Matrices are column-major `glam::Mat4` applied to
//! column vectors (`P * MV * v`).

mod rig;
pub mod stereo;

pub use rig::{
    Camera, CameraMode, EyeMatrices, ImageShift, Lighting, MAX_VIEWS, ResolvedRig, Separation,
    StereoRig, Viewer, ZeroParallax, fit_zero_parallax,
};

use glam::{Mat4, Vec3, Vec4};

/// `P_frustum(l, r, b, t, n, f)` exactly as the exercise slides write it (OpenGL's `glFrustum`).
///
/// ```text
/// | 2n/(r-l)    0      (r+l)/(r-l)      0        |
/// |    0     2n/(t-b)  (t+b)/(t-b)      0        |
/// |    0        0      (n+f)/(n-f)  2nf/(n-f)    |
/// |    0        0         -1            0        |
/// ```
/// `l, r, b, t` are measured on the near plane, `n, f` are positive distances along −Z.
/// Right-handed eye space, outputs NDC with Z in [−1, 1] and Y up.
/// No checks: callers validate `n > 0`, `f > n`, `r != l`, `t != b` (see [`Camera::validate`]).
pub fn frustum(l: f32, r: f32, b: f32, t: f32, n: f32, f: f32) -> Mat4 {
    Mat4::from_cols(
        Vec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
        Vec4::new(
            (r + l) / (r - l),
            (t + b) / (t - b),
            (n + f) / (n - f),
            -1.0,
        ),
        Vec4::new(0.0, 0.0, 2.0 * n * f / (n - f), 0.0),
    )
}

/// Symmetric perspective from a vertical field of view (degrees) and aspect = width / height:
/// `frustum(-w, w, -h, h, n, f)` with `h = n tan(fov/2)`, `w = h aspect`. Same conventions as
/// [`frustum`].
pub fn perspective(fov_y_degrees: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let h = near * (fov_y_degrees.to_radians() * 0.5).tan();
    let w = h * aspect;
    frustum(-w, w, -h, h, near, far)
}

/// Right-handed look-at (`gluLookAt`): maps `eye` to the origin, `target` onto −Z, `up` towards +Y.
/// The rows of the rotation are the camera's right `s = f × up`, true up `u = s × f` and
/// backward `−f`, with `f` the unit view direction. Callers ensure `up` is not parallel to `f`.
pub fn look_at(eye: Vec3, target: Vec3, up: Vec3) -> Mat4 {
    let f = (target - eye).normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// Projects a world point with `mvp` to NDC (w-divided). `None` when w ≤ 0 (behind the eye).
pub fn project_ndc(mvp: &Mat4, p: Vec3) -> Option<Vec3> {
    let c = *mvp * p.extend(1.0);
    (c.w > 0.0).then(|| c.truncate() / c.w)
}
