//! The stereo rig: two eyes from one camera (the SGI course notes, the StereoGraphics guide (Akka) and the exercise slides).

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use super::stereo::{
    auto_eye_separation, camera_frustum_asymmetry, camera_translation, cyclopic_projection,
    image_shift_translation, off_axis_frustum, toe_in_camera_view, view_offset, view_width_at,
    zero_parallax_at_fraction,
};
use super::{frustum, look_at};
use crate::error::{Error, Result};
use crate::eye::Eye;

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
    /// The StereoGraphics guide's §6 "imperfect approach": parallel axes and the same symmetric
    /// frustum in both eyes (as [`CameraMode::Parallel`]), then each eye's image shifted when
    /// viewported, the left one leftward and the right one rightward, by whole pixels, so that
    /// the zero-parallax plane has zero parallax. Geometrically the off-axis result, but the
    /// left and right edges of the two images no longer line up: the columns a shift uncovers
    /// are blank (the clear colour) in that eye. See [`ImageShift`].
    ImageShift,
}

/// Where the viewer (the camera position) sits in the rig: the SGI course notes §4.1.1, "the
/// position of the viewer can be defined to be at one of the eye points, or halfway between
/// them. In either case, the left and right eye locations are positioned relative to it."
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Viewer {
    /// Halfway between the eyes: left eye at `−d/2`, right eye at `+d/2` along the camera's x
    /// axis (the exercise slides' `T±`). Default.
    #[default]
    Midpoint,
    /// At the left eye: the left eye at the camera position, the right eye displaced by the
    /// full separation `d` along the camera's x axis. The whole rig (both eyes, the toe-in
    /// fusion point on the centre line between them) moves by `d/2`; the center pass
    /// (ChromaDepth, SIRDS) stays the camera, the viewer's own view.
    LeftEye,
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

/// The most cameras [`StereoRig::views`] places on the baseline (`[multiview] views`): each is
/// a full pass and an eye-sized image, and lenticular and multi-view panels use from 5 to about
/// 50 views.
pub const MAX_VIEWS: u32 = 64;

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
    /// Where the camera position sits in the rig: between the eyes or at the left eye.
    pub viewer: Viewer,
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
            viewer: Viewer::Midpoint,
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
    /// Pixels this eye's image is moved to the right when viewported ([`CameraMode::ImageShift`]:
    /// `−k_left` for the left eye, `+k_right` for the right; 0 in every other mode). The
    /// translation is part of `projection` (an NDC translation `2·shift/W` after `P_frustum`),
    /// so `mvp` maps to the image as shown; a pass leaves the `|shift|` columns the image moved
    /// away from blank ([`EyeMatrices::drawn_columns`]).
    pub viewport_shift: i32,
}

impl EyeMatrices {
    /// Whether every matrix is finite (an overflowing rig gives NaN or infinite cameras).
    pub fn is_finite(&self) -> bool {
        self.view.is_finite() && self.projection.is_finite() && self.mvp.is_finite()
    }

    /// The columns `x0..x1` of a `width`-pixel image that this eye draws: all of them, but for
    /// [`CameraMode::ImageShift`], whose shifted viewport leaves `|viewport_shift|` columns on
    /// one side blank (the right side of the left eye, the left side of the right eye).
    pub fn drawn_columns(&self, width: u32) -> std::ops::Range<u32> {
        let k = self.viewport_shift.unsigned_abs().min(width);
        if self.viewport_shift >= 0 {
            k..width
        } else {
            0..width - k
        }
    }
}

/// The whole-pixel shifts of [`CameraMode::ImageShift`] for one image width.
///
/// The off-axis rig shifts each eye's image by `b·(d/2)·W/Xrange` pixels (the StereoGraphics
/// guide §5–7: the frustum asymmetry, measured on the zero-parallax plane, equals the camera
/// offset times `UserBalanceAdjustment` b). Shifting when viewporting moves whole pixels only,
/// so the total relative shift `b·d·W/Xrange` is rounded to `K` pixels and split between the
/// eyes (`k_left = ⌊K/2⌋`, `k_right = K − k_left`): the zero-parallax plane then has parallax
/// `K − b·d·W/Xrange`, within half a pixel of zero. The balance the images really have is
/// `b' = b·K / (b·d·W/Xrange)`, and the parallax of the pair is `p(z) = d·(b' − z0/z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageShift {
    /// Pixels the left eye's image moves left (its rightmost `left` columns are blank).
    pub left: u32,
    /// Pixels the right eye's image moves right (its leftmost `right` columns are blank).
    pub right: u32,
    /// The exact total shift `b·d·W/Xrange` in pixels, before rounding.
    pub exact_total: f64,
    /// The balance the rounded shift applies, `b' = b·K/exact_total` (b itself when d = 0).
    pub balance: f64,
}

impl ImageShift {
    /// The whole-pixel total `K = k_left + k_right`.
    pub fn total(&self) -> u32 {
        self.left + self.right
    }

    /// Parallax at the zero-parallax plane left by the rounding, in pixels: `K − exact`.
    pub fn zero_plane_error_pixels(&self) -> f64 {
        self.total() as f64 - self.exact_total
    }

    /// The line `stereolab info` and the render report print: the shifts, the rounding, and
    /// how many columns on each side hold one eye only.
    pub fn describe(&self) -> String {
        format!(
            "image shift: left eye moved {} px left, right eye {} px right (exact total {:.3} px, \
             rounded to {}: parallax at z0 {:+.3} px, balance applied {:.4}); one eye only: {} \
             columns at the left edge (left eye), {} at the right edge (right eye)\n",
            self.left,
            self.right,
            self.exact_total,
            self.total(),
            self.zero_plane_error_pixels(),
            self.balance,
            self.right,
            self.left
        )
    }
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
        self.check(camera)?;
        let z0 = match self.zero_parallax {
            ZeroParallax::Distance(z) => z,
            ZeroParallax::Fraction(t) => zero_parallax_at_fraction(camera.near, camera.far, t),
        };
        let xrange = view_width_at(z0, camera.fov_y, aspect);
        let separation = match self.separation {
            Separation::Absolute(d) => d,
            Separation::Auto => auto_eye_separation(xrange),
        };
        Ok(ResolvedRig {
            eye_separation: separation * self.user_offset,
            zero_parallax_distance: z0,
            xrange,
        })
    }

    /// Checks the rig's fields against `camera`: the zero-parallax distance strictly between
    /// near and far (or its fraction strictly between 0 and 1), the user factors in 0..2, an
    /// absolute separation finite and ≥ 0.
    fn check(&self, camera: &Camera) -> Result<()> {
        match self.zero_parallax {
            ZeroParallax::Distance(z) if !(z > camera.near && z < camera.far) => {
                return Err(Error::invalid(
                    "stereo.zero_parallax",
                    z,
                    format!(
                        "must lie strictly between camera.near ({}) and camera.far ({})",
                        camera.near, camera.far
                    ),
                ));
            }
            ZeroParallax::Fraction(t) if !(t > 0.0 && t < 1.0) => {
                return Err(Error::invalid(
                    "stereo.zero_parallax_fraction",
                    t,
                    "must lie strictly between 0 and 1",
                ));
            }
            _ => {}
        }
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
        if let Separation::Absolute(d) = self.separation
            && !(d >= 0.0 && d.is_finite())
        {
            return Err(Error::invalid(
                "stereo.eye_separation",
                d,
                "must be a finite distance ≥ 0",
            ));
        }
        Ok(())
    }

    /// The two eyes' matrices, index 0 left, 1 right, for an image of aspect `width/height`.
    ///
    /// # Errors
    /// As [`Camera::validate`] and [`StereoRig::resolve`]; and [`CameraMode::ImageShift`],
    /// whose shift is a whole number of pixels and so needs the image size: use
    /// [`StereoRig::eyes_for_image`].
    pub fn eyes(&self, camera: &Camera, aspect: f32) -> Result<[EyeMatrices; 2]> {
        if self.mode == CameraMode::ImageShift {
            return Err(Error::invalid(
                "stereo.mode",
                "\"image-shift\"",
                "shifts each eye by whole pixels, so its matrices need the image size \
                 (StereoRig::eyes_for_image, which every render uses)",
            ));
        }
        self.eyes_with(camera, aspect, None)
    }

    /// The two eyes' matrices for a `width`×`height` image, index 0 left, 1 right: what the
    /// passes render with. The same as [`StereoRig::eyes`] but for
    /// [`CameraMode::ImageShift`], whose whole-pixel shifts ([`StereoRig::image_shift`]) this
    /// puts into the projections.
    ///
    /// # Errors
    /// As [`StereoRig::eyes`] and [`StereoRig::image_shift`].
    pub fn eyes_for_image(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> Result<[EyeMatrices; 2]> {
        let aspect = width as f32 / height as f32;
        let shift = match self.mode {
            CameraMode::ImageShift => Some((self.image_shift(camera, width, height)?, width)),
            _ => None,
        };
        self.eyes_with(camera, aspect, shift)
    }

    /// The whole-pixel shifts [`CameraMode::ImageShift`] applies to a `width`×`height` image
    /// (for any mode: what image-shift would do with this rig).
    ///
    /// # Errors
    /// As [`StereoRig::resolve`]; a shift that leaves no column to both eyes (total ≥ width).
    pub fn image_shift(&self, camera: &Camera, width: u32, height: u32) -> Result<ImageShift> {
        camera.validate()?;
        let r = self.resolve(camera, width as f32 / height as f32)?;
        // b·d·W/Xrange: both eyes' shifts on the zero-parallax plane, in pixels.
        let exact =
            self.user_balance as f64 * r.eye_separation as f64 * width as f64 / r.xrange as f64;
        let total = exact.round();
        if !(total.is_finite() && total < width as f64) {
            return Err(Error::invalid(
                "stereo.eye_separation",
                r.eye_separation,
                format!(
                    "shifts the two image-shift eyes {exact:.1} px apart, which leaves no column \
                     of the {width}-pixel image to both eyes; use a smaller separation, a \
                     smaller stereo.user_balance, or \"auto\""
                ),
            ));
        }
        let total = total as u32;
        let left = total / 2;
        Ok(ImageShift {
            left,
            right: total - left,
            exact_total: exact,
            balance: if exact > 0.0 {
                self.user_balance as f64 * total as f64 / exact
            } else {
                self.user_balance as f64
            },
        })
    }

    fn eyes_with(
        &self,
        camera: &Camera,
        aspect: f32,
        shift: Option<(ImageShift, u32)>,
    ) -> Result<[EyeMatrices; 2]> {
        camera.validate()?;
        let r = self.resolve(camera, aspect)?;
        let eyes = [
            self.eye(camera, aspect, &r, Eye::Left, shift),
            self.eye(camera, aspect, &r, Eye::Right, shift),
        ];
        // Every range check can pass and the matrices still overflow (toe-in's look-at squares
        // the eye offset): refuse them here, before anything renders with NaN cameras.
        if eyes.iter().any(|e| !e.is_finite()) {
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

    /// One eye's matrices; `shift` the image-shift pixels and the image width (image-shift
    /// only). Each step is one of the formulas in [`super::stereo`].
    fn eye(
        &self,
        camera: &Camera,
        aspect: f32,
        r: &ResolvedRig,
        eye: Eye,
        shift: Option<(ImageShift, u32)>,
    ) -> EyeMatrices {
        let half = 0.5 * r.eye_separation;
        let mut viewport_shift = None;
        if let (CameraMode::ImageShift, Some((s, width))) = (self.mode, shift) {
            // The left image moves left by its share of the whole-pixel shift, the right one right.
            let k = match eye {
                Eye::Left => -(s.left as i32),
                Eye::Right => s.right as i32,
            };
            viewport_shift = Some((k, width));
        }
        self.camera_at(camera, aspect, r, eye.sign() * half, viewport_shift)
    }

    /// The matrices of a camera at `x = offset` on the rig's baseline (the eyes at `∓d/2`),
    /// its image moved `viewport_shift = (pixels, width)` when viewported (image-shift only).
    fn camera_at(
        &self,
        camera: &Camera,
        aspect: f32,
        r: &ResolvedRig,
        offset: f32,
        viewport_shift: Option<(i32, u32)>,
    ) -> EyeMatrices {
        let half = 0.5 * r.eye_separation;
        let z0 = r.zero_parallax_distance;
        // The viewer's modelview (the camera's), and the rig's: centred between the eyes. With
        // the viewer at the left eye the rig's midpoint is d/2 to the camera's right.
        let viewer_mv = camera.view();
        let mv = match self.viewer {
            Viewer::Midpoint => viewer_mv,
            Viewer::LeftEye => Mat4::from_translation(Vec3::new(-half, 0.0, 0.0)) * viewer_mv,
        };
        let (w, h) = camera.near_half_extents(aspect);
        let (n, f) = (camera.near, camera.far);
        let symmetric = [-w, w, -h, h, n, f];
        let (eye_view, fr) = match self.mode {
            CameraMode::OffAxis => {
                let asymmetry = camera_frustum_asymmetry(offset, self.user_balance, n, z0);
                (
                    camera_translation(offset) * mv,
                    off_axis_frustum(w, h, n, f, asymmetry),
                )
            }
            // Image-shift renders the parallel eyes; the shift comes after the projection.
            CameraMode::Parallel | CameraMode::ImageShift => {
                (camera_translation(offset) * mv, symmetric)
            }
            CameraMode::ToeIn => (toe_in_camera_view(mv, offset, z0), symmetric),
        };
        let mut p = frustum(fr[0], fr[1], fr[2], fr[3], fr[4], fr[5]);
        let mut shift_pixels = 0i32;
        if let Some((k, width)) = viewport_shift {
            shift_pixels = k;
            p = image_shift_translation(k, width) * p;
        }
        let (view, projection) = match self.lighting {
            Lighting::PerEye => (eye_view, p),
            Lighting::Cyclopic => (viewer_mv, cyclopic_projection(p, eye_view, viewer_mv)),
        };
        EyeMatrices {
            view,
            projection,
            mvp: p * eye_view,
            eye_world: eye_view.inverse().transform_point3(Vec3::ZERO),
            frustum: fr,
            viewport_shift: shift_pixels,
        }
    }

    /// `views` cameras evenly spaced along the rig's baseline, index 0 the leftmost: camera `i`
    /// at [`view_offset`]`(i, views, d)`, adjacent cameras the rig's separation `d` apart, all
    /// with the rig's zero-parallax plane (off-axis: each frustum sheared to meet it; toe-in:
    /// each camera turned to the fusion point; parallel: symmetric, zero parallax at infinity).
    /// Two views are the rig's left and right eyes, the same matrices as
    /// [`StereoRig::eyes_for_image`] (for [`CameraMode::ImageShift`] too, whose whole-pixel
    /// split is defined for two eyes only).
    ///
    /// # Errors
    /// `views` outside 2..=[`MAX_VIEWS`]; more than two views of [`CameraMode::ImageShift`];
    /// as [`StereoRig::eyes`].
    pub fn views(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        views: u32,
    ) -> Result<Vec<EyeMatrices>> {
        if !(2..=MAX_VIEWS).contains(&views) {
            return Err(Error::invalid(
                "multiview.views",
                views,
                format!("must be 2 to {MAX_VIEWS} cameras"),
            ));
        }
        if self.mode == CameraMode::ImageShift {
            // Its whole-pixel shift is split between two eyes: two views are those eyes.
            if views == 2 {
                return Ok(self.eyes_for_image(camera, width, height)?.to_vec());
            }
            return Err(Error::invalid(
                "stereo.mode",
                "\"image-shift\"",
                format!(
                    "splits its whole-pixel shift between two eyes only, so it renders \
                     multiview.views = 2, not {views}; for more views use \"off-axis\", the \
                     same geometry without the blank columns"
                ),
            ));
        }
        camera.validate()?;
        let aspect = width as f32 / height as f32;
        let r = self.resolve(camera, aspect)?;
        let cameras: Vec<EyeMatrices> = (0..views)
            .map(|i| {
                let offset = view_offset(i, views, r.eye_separation);
                self.camera_at(camera, aspect, &r, offset, None)
            })
            .collect();
        if cameras.iter().any(|e| !e.is_finite()) {
            return Err(Error::invalid(
                "stereo.eye_separation",
                r.eye_separation,
                format!(
                    "makes the outer multiview cameras' matrices non-finite in single \
                     precision ({views} views span {} units); use fewer views or a smaller \
                     separation",
                    r.eye_separation * (views - 1) as f32
                ),
            ));
        }
        Ok(cameras)
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
            viewport_shift: 0,
        })
    }
}
