//! The stereo rig's formulas, one short pure function each, with the document each comes from.
//! [`StereoRig`](super::StereoRig) checks its inputs and calls these.

use glam::{Mat4, Vec3};

use super::look_at;
use crate::eye::Eye;

/// The zero-parallax (fusion) distance a fraction `t` of the way from the near to the far plane:
/// `z0 = n + t (f − n)` (the SGI course notes §4.1.1).
pub fn zero_parallax_at_fraction(near: f32, far: f32, t: f32) -> f32 {
    near + t * (far - near)
}

/// The width of the view at distance `z0`, the StereoGraphics guide's `Xrange` (§7):
/// `Xrange = 2 · z0 · tan(fov_y / 2) · aspect`.
pub fn view_width_at(z0: f32, fov_y_degrees: f32, aspect: f32) -> f32 {
    2.0 * z0 * (fov_y_degrees.to_radians() * 0.5).tan() * aspect
}

/// The automatic eye separation of the StereoGraphics guide (Akka) §7: each camera is offset by
/// `Xrange · 0.035`, so the two eyes are `d = 2 · 0.035 · Xrange` apart.
pub fn auto_eye_separation(xrange: f32) -> f32 {
    2.0 * xrange * 0.035
}

/// The eye's offset `T±` in eye space (the exercise slides): the left eye sits at `x = −d/2`,
/// so its view translates the world by `+d/2`; the right eye's by `−d/2`.
pub fn eye_translation(eye: Eye, half_separation: f32) -> Mat4 {
    camera_translation(eye.sign() * half_separation)
}

/// A camera at `x = offset` on the rig's baseline (the rig's x axis): its view translates the
/// world by `−offset` (the exercise slides' `T±`, for any point of the baseline).
pub fn camera_translation(offset: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(-offset, 0.0, 0.0))
}

/// The baseline position of camera `index` of `views` cameras evenly spaced and centred on the
/// rig, adjacent cameras `separation` apart: `x_i = (i − (N − 1)/2) · d` (Blender's multi-view
/// rendering, "Multi-View" in the Blender manual: one camera per view along the baseline; the
/// exercise slides' `T±` at `∓d/2` for N = 2).
pub fn view_offset(index: u32, views: u32, separation: f32) -> f32 {
    (index as f32 - (views - 1) as f32 / 2.0) * separation
}

/// The off-axis frustum's horizontal shift on the near plane, the StereoGraphics guide's
/// `FrustumAsymmetry = −offset · UserBalanceAdjustment · n / z0` (§6–7, `offset = ±d/2`),
/// positive for the left eye: both frusta then meet on the zero-parallax plane.
pub fn frustum_asymmetry(
    eye: Eye,
    half_separation: f32,
    balance: f32,
    near: f32,
    zero_parallax: f32,
) -> f32 {
    camera_frustum_asymmetry(eye.sign() * half_separation, balance, near, zero_parallax)
}

/// [`frustum_asymmetry`] of a camera at `x = offset` on the baseline:
/// `−offset · UserBalanceAdjustment · n / z0` (the StereoGraphics guide §6–7), so every camera's
/// frustum meets the others' on the zero-parallax plane.
pub fn camera_frustum_asymmetry(offset: f32, balance: f32, near: f32, zero_parallax: f32) -> f32 {
    -offset * balance * near / zero_parallax
}

/// The off-axis eye's frustum `(l, r, b, t, n, f)`: the symmetric near-plane window
/// `(±w, ±h)` moved sideways by `asymmetry` (the exercise slides' "Projection Matrix Stereo
/// Case": parallel axes, asymmetric frusta).
pub fn off_axis_frustum(
    half_width: f32,
    half_height: f32,
    near: f32,
    far: f32,
    asymmetry: f32,
) -> [f32; 6] {
    let (w, h) = (half_width, half_height);
    [-w + asymmetry, w + asymmetry, -h, h, near, far]
}

/// The toe-in eye's view (the SGI course notes §4.1.2, per-eye look-at): the eye at `±d/2` on
/// the rig's x axis looks at the fusion point `z0` ahead on the centre line, so each eye is
/// turned by `atan((d/2)/z0)`.
pub fn toe_in_view(rig_view: Mat4, eye: Eye, half_separation: f32, zero_parallax: f32) -> Mat4 {
    toe_in_camera_view(rig_view, eye.sign() * half_separation, zero_parallax)
}

/// [`toe_in_view`] of a camera at `x = offset` on the baseline: it looks at the fusion point
/// `z0` ahead on the rig's centre line, turned by `atan(offset/z0)` (the SGI course notes
/// §4.1.2, each camera converging on the one fusion point).
pub fn toe_in_camera_view(rig_view: Mat4, offset: f32, zero_parallax: f32) -> Mat4 {
    let inverse = rig_view.inverse();
    let position = inverse.transform_point3(Vec3::new(offset, 0.0, 0.0));
    let fusion = inverse.transform_point3(Vec3::new(0.0, 0.0, -zero_parallax));
    let up = inverse.transform_vector3(Vec3::Y);
    look_at(position, fusion, up)
}

/// An image moved `pixels` to the right when viewported, as the NDC translation `2k/W` after
/// the projection (the StereoGraphics guide §6: "apply an offset … when viewporting").
pub fn image_shift_translation(pixels: i32, width: u32) -> Mat4 {
    let ndc = 2.0 * pixels as f32 / width as f32;
    Mat4::from_translation(Vec3::new(ndc, 0.0, 0.0))
}

/// Cyclopic lighting (the exercise slides, "Effect on lighting"): the eye shades in the
/// viewer's eye space and its projection carries the eye's offset, `P± = P_frustum± · T±`,
/// written for any eye view as `P · eye_view · viewer_view⁻¹`.
pub fn cyclopic_projection(projection: Mat4, eye_view: Mat4, viewer_view: Mat4) -> Mat4 {
    projection * eye_view * viewer_view.inverse()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_offsets_are_evenly_spaced_and_centred() {
        for n in [2u32, 3, 5, 8, 64] {
            let d = 0.3f32;
            let xs: Vec<f64> = (0..n).map(|i| f64::from(view_offset(i, n, d))).collect();
            // Centred on the rig: the offsets sum to zero.
            assert!(xs.iter().sum::<f64>().abs() < 1e-4, "{n}: {xs:?}");
            for pair in xs.windows(2) {
                assert!(
                    (pair[1] - pair[0] - f64::from(d)).abs() < 1e-5,
                    "{n}: {xs:?}"
                );
            }
        }
        // Two views are the exercise slides' eyes at ∓d/2, exactly.
        assert_eq!(view_offset(0, 2, 0.3), -(0.5 * 0.3));
        assert_eq!(view_offset(1, 2, 0.3), 0.5 * 0.3);
        for eye in [Eye::Left, Eye::Right] {
            let half = 0.5 * 0.37f32;
            assert_eq!(
                eye_translation(eye, half),
                Mat4::from_translation(Vec3::new(-eye.sign() * half, 0.0, 0.0))
            );
        }
    }
}
