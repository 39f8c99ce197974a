//! Eye-linear texture-coordinate generation (the ChromaDepth article): `s = A x + B y + C z + D` on eye-space
//! positions, and the choice of D1/D2.

use glam::{Mat4, Vec3, Vec4};

use crate::error::{Error, Result};

/// The texgen plane `(A, B, C, D)` of the ChromaDepth article, fixed in eye space.
///
/// With `A = B = 0`, `C = −1/(D2 − D1)`, `D = −D1/(D2 − D1)`, a point `D1` units in front of
/// the eye (eye z = −D1, the camera looks down −Z) gets `s = 0` (red) and a point at `D2` gets
/// `s = 1` (blue). The plane is specified under an identity modelview, as the ChromaDepth article insists:
/// object transforms applied afterwards move objects through the ramp, never the ramp with them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texgen {
    /// `(A, B, C, D)`.
    pub plane: Vec4,
    /// Distance in front of the eye where the ramp starts (red).
    pub d1: f32,
    /// Distance in front of the eye where the ramp ends (blue).
    pub d2: f32,
}

impl Texgen {
    /// The plane [`eye_plane`] for the depth range `d1 .. d2` (eye-space distances in front of
    /// the eye), the range checked first.
    ///
    /// # Errors
    /// `Invalid` naming `chromadepth.d1`/`d2` when either is not finite, when `d1 == d2` (the
    /// plane would divide by zero) or when `d1 > d2`.
    pub fn from_range(d1: f32, d2: f32) -> Result<Texgen> {
        check_range(d1, d2)?;
        Ok(Texgen {
            plane: eye_plane(d1, d2),
            d1,
            d2,
        })
    }

    /// `s` of an eye-space point: `A x + B y + C z + D`.
    #[inline]
    pub fn s(&self, eye_point: Vec3) -> f32 {
        self.plane.dot(eye_point.extend(1.0))
    }

    /// `s` from a distance `−z_eye` in front of the eye, in f64 (the benchmark's reference).
    pub fn s_of_distance_f64(&self, distance: f64) -> f64 {
        (distance - self.d1 as f64) / (self.d2 as f64 - self.d1 as f64)
    }
}

/// What OpenGL stores for `glTexGenfv(GL_S, GL_EYE_PLANE, p)` issued while the modelview is `m`:
/// `p' = p · m⁻¹` (OpenGL 1.x spec §2.10.4). With `m` the identity, as the ChromaDepth article demands, the
/// plane stays fixed in eye space; under any other `m` it is carried along with `m`, the mistake
/// the ChromaDepth article warns about.
pub fn eye_plane_specified_under(plane: Vec4, modelview: Mat4) -> Vec4 {
    modelview.inverse().transpose() * plane
}

/// The eye-linear texgen plane `(A, B, C, D)` that maps the eye-space distance `D1` to `s = 0`
/// and `D2` to `s = 1` (the ChromaDepth article, "Creating ChromaDepth Scenes with OpenGL"):
/// `A = B = 0`, `C = −1/(D2 − D1)`, `D = −D1/(D2 − D1)`, so `s = (−z − D1)/(D2 − D1)` for an
/// eye-space point at `z` (the camera looks down −Z).
pub fn eye_plane(d1: f32, d2: f32) -> Vec4 {
    let span = d2 - d1;
    Vec4::new(0.0, 0.0, -1.0 / span, -d1 / span)
}

/// Checks a ramp range: both distances finite, `D1` nearer than `D2`.
///
/// `D1 > D2` is an error, not a reversed ramp: ChromaDepth glasses always put red in front, so
/// a reversed ramp shows the scene's depth inside out; swapped values are far more often a slip
/// than an intent.
///
/// # Errors
/// `Invalid` naming `chromadepth.d1`/`d2` when either is not finite, when `d1 == d2` (the
/// plane would divide by zero) or when `d1 > d2`.
fn check_range(d1: f32, d2: f32) -> Result<()> {
    for (name, v) in [("chromadepth.d1", d1), ("chromadepth.d2", d2)] {
        if !v.is_finite() {
            return Err(Error::invalid(name, v, "must be a finite distance"));
        }
    }
    if d1 == d2 {
        return Err(Error::invalid(
            "chromadepth.d2",
            d2,
            format!("equals chromadepth.d1 ({d1}): the ramp needs D2 - D1 != 0"),
        ));
    }
    if d1 > d2 {
        return Err(Error::invalid(
            "chromadepth.d1",
            d1,
            format!(
                "is beyond chromadepth.d2 ({d2}): D1 is where red (near) starts and must be \
                 nearer than D2; swap them (a reversed ramp would show depth inside out)"
            ),
        ));
    }
    Ok(())
}

/// A sphere around the scene's center: the center of the world-space bounding box and the
/// largest distance from it to any point. `None` for no points or a non-finite point.
pub fn bounding_sphere(points: &[Vec3]) -> Option<(Vec3, f32)> {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let center = (lo + hi) * 0.5;
    let radius = points
        .iter()
        .map(|p| p.distance(center))
        .fold(0.0, f32::max);
    Some((center, radius))
}

/// The ChromaDepth article's automatic D1/D2: "fit a spherical bounding volume around the center of the scene,
/// and set D1 and D2 to the limits of the sphere": `D1 = c − r`, `D2 = c + r` with `c` the
/// sphere center's distance in front of the eye (`−z` in eye space, `view` maps world → eye).
/// Each is then kept between the clip planes (the ChromaDepth article: "somewhere between the near and far
/// clipping planes") so the visible scene spans the whole ramp.
///
/// # Errors
/// `Invalid` when the scene has no finite points, or when the sphere lies entirely outside
/// `near .. far` (nothing of it is visible, so no range can be chosen).
pub fn auto_range(points: &[Vec3], view: Mat4, near: f32, far: f32) -> Result<(f32, f32)> {
    let (center, radius) = bounding_sphere(points).ok_or_else(|| {
        Error::invalid(
            "chromadepth.d1",
            "auto",
            "the scene has no finite points to fit a bounding sphere around",
        )
    })?;
    let c = -view.transform_point3(center).z;
    let (d1, d2) = ((c - radius).max(near), (c + radius).min(far));
    if d1 >= d2 {
        return Err(Error::invalid(
            "chromadepth.d1",
            "auto",
            format!(
                "the scene's bounding sphere ({:.3} .. {:.3} in front of the eye) lies outside \
                 camera.near .. camera.far ({near} .. {far}); give chromadepth.d1 and d2",
                c - radius,
                c + radius
            ),
        ));
    }
    Ok((d1, d2))
}
