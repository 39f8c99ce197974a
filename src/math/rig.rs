//! The stereo rig: two eyes from one camera (the SGI course notes, the StereoGraphics guide (Akka) and the exercise slides).

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use super::{frustum, look_at};
use crate::error::{Error, Result};

/// A mono camera: where it is, where it looks, and its symmetric frustum.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// Eye position (world), the midpoint between the two stereo eyes.
    pub eye: [f32; 3],
    /// Point looked at (world).
    pub target: [f32; 3],
    /// Up direction (world); need not be orthogonal to the view direction.
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov")]
    pub fov_y: f32,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    50.0
}

impl Camera {
    /// Checks every field.
    ///
    /// # Errors
    /// NaN/Inf anywhere, `near ≤ 0`, `far ≤ near`, fov outside (0°, 180°), eye == target,
    /// up parallel to the view direction.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if v.iter().any(|c| !c.is_finite()) {
                return Err(Error::invalid(
                    format!("camera.{name}"),
                    format!("{v:?}"),
                    "must be finite",
                ));
            }
        }
        if !(self.near > 0.0 && self.near.is_finite()) {
            return Err(Error::invalid("camera.near", self.near, "must be > 0"));
        }
        if !(self.far > self.near && self.far.is_finite()) {
            return Err(Error::invalid(
                "camera.far",
                self.far,
                format!("must be > camera.near ({})", self.near),
            ));
        }
        if !(self.fov_y > 0.0 && self.fov_y < 180.0) {
            return Err(Error::invalid(
                "camera.fov_y",
                self.fov_y,
                "must be in (0, 180) degrees",
            ));
        }
        let dir = Vec3::from(self.target) - Vec3::from(self.eye);
        // In f64: the lengths of far-out points overflow f32.
        let (eye64, target64) = (
            Vec3::from(self.eye).as_dvec3(),
            Vec3::from(self.target).as_dvec3(),
        );
        let far_out = eye64.length().max(target64.length());
        if self.target != self.eye
            && !(f64::from(dir.length()) > f64::from(f32::EPSILON) * far_out.max(1.0)
                && dir.length().is_finite())
        {
            return Err(Error::invalid(
                "camera.eye",
                format!("{:?}", self.eye),
                format!(
                    "lies {far_out:.3e} from the origin and {:.3e} from camera.target {:?}: \
                     single precision loses the view direction at that scale; bring the \
                     camera and the scene nearer the origin",
                    target64.distance(eye64),
                    self.target
                ),
            ));
        }
        if dir.length() <= f32::EPSILON * Vec3::from(self.eye).length().max(1.0) {
            return Err(Error::invalid(
                "camera.target",
                format!("{:?}", self.target),
                "must differ from camera.eye",
            ));
        }
        if dir
            .normalize()
            .cross(Vec3::from(self.up).normalize_or_zero())
            .length()
            < 1e-6
        {
            return Err(Error::invalid(
                "camera.up",
                format!("{:?}", self.up),
                "must not be parallel to the view direction",
            ));
        }
        Ok(())
    }

    /// The cyclopean modelview (world → eye space).
    pub fn view(&self) -> Mat4 {
        look_at(self.eye.into(), self.target.into(), self.up.into())
    }

    /// Half-extents `(w, h)` of the symmetric frustum on the near plane.
    pub fn near_half_extents(&self, aspect: f32) -> (f32, f32) {
        let h = self.near * (self.fov_y.to_radians() * 0.5).tan();
        (h * aspect, h)
    }
}

/// How the two eyes are derived from the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum CameraMode {
    /// Parallel axes + asymmetric frustum (the StereoGraphics guide's §5–6, the exercise slides). The correct one; default.
    #[default]
    OffAxis,
    /// Each eye rotated by atan((iod/2)/fusion) towards the fusion point (the SGI course notes). Produces
    /// vertical parallax off-center (the StereoGraphics guide (Akka) warns against it); kept for teaching.
    ToeIn,
    /// Parallel axes, symmetric frusta: zero parallax at infinity, everything in front of the screen.
    Parallel,
}

/// Which modelview the shading sees (the exercise slides' "Effect on lighting"): per-eye
/// (`MV± = T±·MV`, each eye lights from its own position) or cyclopic (`P± = P_frustum±·T±`,
/// both eyes shade as the cyclopean eye does). One type with the exercises, whose crate defines
/// it (a student's crate cannot depend on stereolab).
pub use exercise_api::Lighting;

/// Eye separation: an absolute distance or the StereoGraphics guide's automatic rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Separation {
    /// Distance between the two eyes in world units (≥ 0).
    Absolute(f32),
    /// The StereoGraphics guide's §7: each camera is offset by `Xrange · 0.035 · user_offset`, where `Xrange` is the
    /// frustum's width at the zero-parallax plane; the separation is twice that offset.
    Auto,
}

/// Zero-parallax (fusion) distance along the view direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ZeroParallax {
    /// An eye-space distance, strictly between near and far.
    Distance(f32),
    /// The SGI course notes: a dimensionless position between the clip planes, `near + t (far − near)`, t in (0, 1).
    Fraction(f32),
}

/// The zero-parallax distance that best fits a depth range `[z_near, z_far]` (eye distances of
/// the nearest and farthest visible point) into the StereoGraphics guide's symmetric parallax
/// budget (§7–8: keep negative and positive parallax each within a few percent of the width).
///
/// The parallax `p(z) = d·(b − z0/z)` (the exercise slides, balance b) in pixels is, for a fixed
/// separation, `∝ b/z0 − 1/z`, and for the automatic separation (d ∝ z0) `∝ b − z0/z`: either
/// way the largest |p| over the range is smallest when `p(z_near) = −p(z_far)`, i.e.
/// `b/z0 = (1/z_near + 1/z_far)/2`: z0 is b times the harmonic mean of the two depths.
pub fn fit_zero_parallax(z_near: f32, z_far: f32, balance: f32) -> f32 {
    balance * 2.0 / (1.0 / z_near + 1.0 / z_far)
}

/// The stereo rig: separation, fusion distance, camera mode, and the StereoGraphics guide's user factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StereoRig {
    /// Off-axis, toe-in or parallel.
    pub mode: CameraMode,
    /// Eye separation.
    pub separation: Separation,
    /// Zero-parallax distance.
    pub zero_parallax: ZeroParallax,
    /// The StereoGraphics guide's `UserOffsetAdjustment`: multiplies the separation (and so the asymmetry), 0..2.
    pub user_offset: f32,
    /// The StereoGraphics guide's `UserBalanceAdjustment`: multiplies the frustum asymmetry only, 0..2.
    pub user_balance: f32,
    /// Per-eye or cyclopic modelview for shading.
    pub lighting: Lighting,
}

impl Default for StereoRig {
    fn default() -> Self {
        StereoRig {
            mode: CameraMode::OffAxis,
            separation: Separation::Auto,
            zero_parallax: ZeroParallax::Fraction(0.5),
            user_offset: 1.0,
            user_balance: 1.0,
            lighting: Lighting::PerEye,
        }
    }
}

/// The matrices one eye renders with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeMatrices {
    /// Modelview the shader lights in (per-eye: `T±·MV`; cyclopic: `MV`).
    pub view: Mat4,
    /// Projection that completes `view` (per-eye: `P_frustum±`; cyclopic: `P_frustum±·T±`).
    pub projection: Mat4,
    /// `projection · view`: identical for both lighting variants.
    pub mvp: Mat4,
    /// Where this eye is, in world space.
    pub eye_world: Vec3,
    /// The frustum arguments `(l, r, b, t, n, f)` of `P_frustum±`.
    pub frustum: [f32; 6],
}

/// The rig's numbers once resolved against a camera and an aspect ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResolvedRig {
    /// Total eye separation d (world units), `user_offset` applied.
    pub eye_separation: f32,
    /// Zero-parallax distance z0 (eye-space, positive).
    pub zero_parallax_distance: f32,
    /// Width of the view at the zero-parallax plane (the StereoGraphics guide's `Xrange`).
    pub xrange: f32,
}

impl StereoRig {
    /// Resolves separation and zero-parallax distance for `camera` at `aspect` = width/height.
    ///
    /// # Errors
    /// Negative or non-finite separation, zero parallax outside (near, far), factors outside 0..2.
    pub fn resolve(&self, camera: &Camera, aspect: f32) -> Result<ResolvedRig> {
        let z0 = match self.zero_parallax {
            ZeroParallax::Distance(z) => {
                if !(z > camera.near && z < camera.far) {
                    return Err(Error::invalid(
                        "stereo.zero_parallax",
                        z,
                        format!(
                            "must lie strictly between camera.near ({}) and camera.far ({})",
                            camera.near, camera.far
                        ),
                    ));
                }
                z
            }
            ZeroParallax::Fraction(t) => {
                if !(t > 0.0 && t < 1.0) {
                    return Err(Error::invalid(
                        "stereo.zero_parallax_fraction",
                        t,
                        "must lie strictly between 0 and 1",
                    ));
                }
                camera.near + t * (camera.far - camera.near)
            }
        };
        for (name, v) in [
            ("stereo.user_offset", self.user_offset),
            ("stereo.user_balance", self.user_balance),
        ] {
            if !(0.0..=2.0).contains(&v) {
                return Err(Error::invalid(
                    name,
                    v,
                    "must lie in 0..2 (the StereoGraphics guide (Akka): 1.0 default, 2.0 upper limit)",
                ));
            }
        }
        let xrange = 2.0 * z0 * (camera.fov_y.to_radians() * 0.5).tan() * aspect;
        let base = match self.separation {
            Separation::Absolute(d) => {
                if !(d >= 0.0 && d.is_finite()) {
                    return Err(Error::invalid(
                        "stereo.eye_separation",
                        d,
                        "must be a finite distance ≥ 0",
                    ));
                }
                d
            }
            Separation::Auto => 2.0 * xrange * 0.035,
        };
        Ok(ResolvedRig {
            eye_separation: base * self.user_offset,
            zero_parallax_distance: z0,
            xrange,
        })
    }

    /// The two eyes' matrices, index 0 left, 1 right.
    ///
    /// # Errors
    /// As [`Camera::validate`] and [`StereoRig::resolve`].
    pub fn eyes(&self, camera: &Camera, aspect: f32) -> Result<[EyeMatrices; 2]> {
        camera.validate()?;
        let r = self.resolve(camera, aspect)?;
        let eyes = [
            self.eye(camera, aspect, &r, -1.0),
            self.eye(camera, aspect, &r, 1.0),
        ];
        // Every range check can pass and the matrices still overflow (toe-in's look-at squares
        // the eye offset): refuse them here, before anything renders with NaN cameras.
        if eyes
            .iter()
            .any(|e| !(e.view.is_finite() && e.projection.is_finite() && e.mvp.is_finite()))
        {
            return Err(Error::invalid(
                "stereo.eye_separation",
                r.eye_separation,
                format!(
                    "makes the {:?} eye matrices non-finite in single precision; use a \
                     separation comparable to the scene (about 1/30 of the zero-parallax \
                     distance {}), or \"auto\"",
                    self.mode, r.zero_parallax_distance
                ),
            ));
        }
        Ok(eyes)
    }

    /// One eye; `side` is −1 for left, +1 for right.
    fn eye(&self, camera: &Camera, aspect: f32, r: &ResolvedRig, side: f32) -> EyeMatrices {
        let mv = camera.view();
        let (w, h) = camera.near_half_extents(aspect);
        let (n, f) = (camera.near, camera.far);
        let half = 0.5 * r.eye_separation;
        // Eye offset along the camera's x axis, in eye space.
        let t = Mat4::from_translation(Vec3::new(-side * half, 0.0, 0.0));
        let (eye_view, fr) = match self.mode {
            CameraMode::OffAxis => {
                // The StereoGraphics guide (Akka): FrustumAsymmetry = −offset · balance · n/z0, positive for the left eye.
                let shift = -side * half * self.user_balance * n / r.zero_parallax_distance;
                (t * mv, [-w + shift, w + shift, -h, h, n, f])
            }
            CameraMode::Parallel => (t * mv, [-w, w, -h, h, n, f]),
            CameraMode::ToeIn => {
                // The SGI course notes, per-eye look-at: both eyes aim at the fusion point on the center line.
                let inv = mv.inverse();
                let eye = inv.transform_point3(Vec3::new(side * half, 0.0, 0.0));
                let fusion = inv.transform_point3(Vec3::new(0.0, 0.0, -r.zero_parallax_distance));
                let up = inv.transform_vector3(Vec3::Y);
                (look_at(eye, fusion, up), [-w, w, -h, h, n, f])
            }
        };
        let p = frustum(fr[0], fr[1], fr[2], fr[3], fr[4], fr[5]);
        let (view, projection) = match self.lighting {
            Lighting::PerEye => (eye_view, p),
            Lighting::Cyclopic => (mv, p * eye_view * mv.inverse()),
        };
        EyeMatrices {
            view,
            projection,
            mvp: p * eye_view,
            eye_world: eye_view.inverse().transform_point3(Vec3::ZERO),
            frustum: fr,
        }
    }

    /// The cyclopean (center) eye: the camera itself, symmetric frustum.
    ///
    /// # Errors
    /// As [`Camera::validate`].
    pub fn center(camera: &Camera, aspect: f32) -> Result<EyeMatrices> {
        camera.validate()?;
        let (w, h) = camera.near_half_extents(aspect);
        let fr = [-w, w, -h, h, camera.near, camera.far];
        let view = camera.view();
        let projection = frustum(fr[0], fr[1], fr[2], fr[3], fr[4], fr[5]);
        Ok(EyeMatrices {
            view,
            projection,
            mvp: projection * view,
            eye_world: camera.eye.into(),
            frustum: fr,
        })
    }
}
