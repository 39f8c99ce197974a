//! Your code: complete every `todo!`. Each doc comment states the task, where its formula comes
//! from, and the conventions; `stereolab grade ex2` scores each function on its own and
//! `stereolab grade points` prints each task's points.

use glam::Vec3;

/// Task `hsv_ramp` (image check): the ChromaDepth color at ramp position `t`.
///
/// Source: the ChromaDepth article, "Creating ChromaDepth Scenes": a 1D texture running red (near, `t = 0`)
/// through green to blue (far, `t = 1`), interpolated in HSV: hue `240° · t`, saturation 1,
/// value 1, converted to RGB in [0, 1]. `t` outside [0, 1] is clamped first (`GL_CLAMP`).
pub fn hsv_ramp(t: f32) -> [f32; 3] {
    // TODO: clamp, hue in degrees, then the usual HSV → RGB sextants.
    todo!("ramp color at t = {t:?}")
}

/// Task `texgen` (image check): the eye-linear texgen plane `[A, B, C, D]` of
/// `s = A x + B y + C z + D` so that `s = 0` at distance `d1` in front of the eye and `s = 1` at
/// `d2`.
///
/// Source: the ChromaDepth article: `A = 0`, `B = 0`, `C = −1/(D2 − D1)`, `D = −D1/(D2 − D1)`. Eye space looks
/// down −Z: a point `d` in front of the eye has `z = −d`.
pub fn texgen(d1: f32, d2: f32) -> [f32; 4] {
    // TODO: four coefficients.
    todo!("texgen plane for D1 = {d1:?}, D2 = {d2:?}")
}

/// Task `depth_range`: `[D1, D2]` from a bounding sphere of the scene.
///
/// Source: the ChromaDepth article: "fit a spherical bounding volume around the center of the scene, and set
/// D1 and D2 to the limits of the sphere". `center` is in eye space (looking down −Z, so its
/// distance in front of the eye is `−center.z`); D1 is the sphere's nearest, D2 its farthest
/// distance along the view direction.
pub fn depth_range(center: Vec3, radius: f32) -> [f32; 2] {
    // TODO: two distances along −Z.
    todo!("D1, D2 of the sphere at {center:?} with radius {radius:?}")
}
