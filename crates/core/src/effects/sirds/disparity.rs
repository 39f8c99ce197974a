//! How far apart two linked pixels are: the SIRDS paper's §2's two models, and the one place where
//! physical parameters (inches, DPI) become pixels.
//!
//! Depth conventions used by every SIRDS function:
//! - `t` is the depth of a scene point behind the image plane (the SIRDS paper's `z`), in pixels once
//!   [`Geometry::to_pixels`] has run;
//! - `z` is normalized nearness in [0, 1] as in Thimbleby–Inglis–Witten (1994): 0 is the
//!   background plane at `t_far`, 1 the front of the depth range at `t_near`, linearly between:
//!   `t = t_far − z (t_far − t_near)`.

use crate::error::{Error, Result};

/// Which projection model of the visual system maps depth to separation (the SIRDS paper's §2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DisparityModel {
    /// Eq. 1, constant viewing direction: `d = 2 t / tan φ`, linear in depth.
    ViewAngle,
    /// Eq. 3, constant eye distance `a` and focal length `f`: `d = a t / (t + f)`. The default;
    /// it is Thimbleby–Inglis–Witten's separation formula.
    #[default]
    EyeDistance,
}

/// The SIRDS paper's eq. 1: separation `d = 2 t / tan φ` of a point `t` behind the image plane, seen
/// along a constant direction at angle `φ` to the plane. `t` and `d` share one length unit.
pub fn separation_view_angle(t: f32, tan_phi: f32) -> f32 {
    2.0 * t / tan_phi
}

/// The SIRDS paper's eq. 3: separation `d = a t / (t + f)` for eye distance `a`, focal length (eye to
/// image plane) `f` and depth `t` behind the image plane, all in one length unit. Note the
/// division: a public Rust port multiplies by `(t + f)` instead, which grows without bound.
///
/// # Errors
/// `Invalid` when `t + f ≤ 0` (the point is at or behind the eyes, the formula's pole) or a
/// result is not finite.
pub fn separation_eye_distance(t: f32, a: f32, f: f32) -> Result<f32> {
    let denominator = t + f;
    if denominator.is_nan() || denominator <= 0.0 {
        return Err(Error::invalid(
            "sirds depth + viewing distance",
            denominator,
            format!("eq. 3 needs t + f > 0 (t = {t}, f = {f}): the point must lie beyond the eyes"),
        ));
    }
    let d = a * t / denominator;
    if d.is_finite() {
        Ok(d)
    } else {
        Err(Error::invalid("sirds separation", d, "is not finite"))
    }
}

/// The SIRDS paper's eq. 2: `tan φ = 2 (t + f) / a`, the slope (depth per lateral length) of the ray from
/// a point `t` behind the image plane to an eye, under the eq. 3 model.
pub fn tan_phi_eye_distance(t: f32, a: f32, f: f32) -> f32 {
    2.0 * (t + f) / a
}

/// The physical viewing set-up, as the scene's `[sirds]` table gives it (lengths in inches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// Depth → separation model.
    pub model: DisparityModel,
    /// Distance between the eyes `a` (TIW: 2.5 in).
    pub eye_separation_in: f32,
    /// Output resolution in dots per inch (TIW: 72).
    pub dpi: f32,
    /// Eye-to-image-plane distance `f` (TIW's `D`).
    pub viewing_distance_in: f32,
    /// Depth behind the image plane of the front of the depth range (`z = 1`); > 0 because
    /// the SIRDS paper's §3 needs a non-zero minimum separation.
    pub depth_near_in: f32,
    /// Depth behind the image plane of the background plane (`z = 0`).
    pub depth_far_in: f32,
    /// Eq. 1's angle φ in degrees; `None` derives it from eq. 2 at the background plane, so
    /// both models agree there.
    pub view_angle_deg: Option<f32>,
}

impl Default for Geometry {
    /// Thimbleby–Inglis–Witten's set-up: 2.5 in eyes, 72 DPI, far plane as far behind the image
    /// as the eyes are in front of it, depth of field μ = 1/3 (near plane at 2/3 of that).
    fn default() -> Self {
        Geometry {
            model: DisparityModel::EyeDistance,
            eye_separation_in: 2.5,
            dpi: 72.0,
            viewing_distance_in: 12.0,
            depth_near_in: 8.0,
            depth_far_in: 12.0,
            view_angle_deg: None,
        }
    }
}

/// The set-up in pixels: every separation function works on these numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Disparity {
    /// Depth → separation model.
    pub model: DisparityModel,
    /// Eye distance `a` in pixels.
    pub eye_separation: f32,
    /// Viewing distance `f` in pixels.
    pub viewing_distance: f32,
    /// Depth of `z = 1` behind the image plane, pixels.
    pub t_near: f32,
    /// Depth of `z = 0` (background plane), pixels.
    pub t_far: f32,
    /// Eq. 1's `tan φ` (unused by eq. 3).
    pub tan_phi: f32,
}

impl Geometry {
    /// Checks the set-up and converts it to pixels: every length times `dpi` — the one place
    /// where inches become pixels.
    ///
    /// # Errors
    /// `Invalid` naming the `sirds.*` field: non-finite or non-positive lengths and DPI,
    /// `depth_near_in ≥ depth_far_in`, an angle outside (0°, 90°).
    pub fn to_pixels(&self) -> Result<Disparity> {
        for (name, v) in [
            ("sirds.eye_separation_in", self.eye_separation_in),
            ("sirds.dpi", self.dpi),
            ("sirds.viewing_distance_in", self.viewing_distance_in),
            ("sirds.depth_near_in", self.depth_near_in),
            ("sirds.depth_far_in", self.depth_far_in),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(name, v, "must be a finite number > 0"));
            }
        }
        if self.depth_near_in >= self.depth_far_in {
            return Err(Error::invalid(
                "sirds.depth_near_in",
                self.depth_near_in,
                format!(
                    "must be less than sirds.depth_far_in ({}): the background plane is the farthest depth",
                    self.depth_far_in
                ),
            ));
        }
        let px = |inches: f32| inches * self.dpi;
        let (a, f, t_far) = (
            px(self.eye_separation_in),
            px(self.viewing_distance_in),
            px(self.depth_far_in),
        );
        let tan_phi = match self.view_angle_deg {
            Some(deg) if deg > 0.0 && deg < 90.0 => deg.to_radians().tan(),
            Some(deg) => {
                return Err(Error::invalid(
                    "sirds.view_angle_deg",
                    deg,
                    "must lie strictly between 0 and 90 degrees",
                ));
            }
            None => tan_phi_eye_distance(t_far, a, f),
        };
        let d = Disparity {
            model: self.model,
            eye_separation: a,
            viewing_distance: f,
            t_near: px(self.depth_near_in),
            t_far,
            tan_phi,
        };
        // Lengths in inches times the dots per inch: past single precision the separations
        // come out infinite or NaN; name the field that scales them all.
        let (front, back) = (d.min_separation(), d.max_separation());
        if !(front.is_finite() && back.is_finite() && t_far.is_finite() && tan_phi.is_finite()) {
            return Err(Error::invalid(
                "sirds.dpi",
                format!("{:?}", self.dpi),
                format!(
                    "with these lengths in inches the separations are beyond single precision \
                     ({front} .. {back} px); give the dots per inch of a screen or a printer \
                     (72 to 2400)"
                ),
            ));
        }
        Ok(d)
    }
}

impl Disparity {
    /// Depth behind the image plane (pixels) of normalized nearness `z` (0 background, 1 front):
    /// `t_far − z (t_far − t_near)`, evaluated in f64 and rounded once. In f32 the difference
    /// `t_far − t_near` rounds to a multiple of `ulp(t_far)`, so with `sirds.depth_far_in = 1e8`
    /// (`t_far` = 7.2e9 px, ulp 512) the front `z = 1` landed at 512 px instead of
    /// `t_near` = 576 px: a front separation of 67 px instead of 72.
    #[inline]
    pub fn depth_of(&self, z: f32) -> f32 {
        let (t_far, t_near) = (f64::from(self.t_far), f64::from(self.t_near));
        (t_far - f64::from(z) * (t_far - t_near)) as f32
    }

    /// Normalized nearness of a depth `t` behind the image plane (inverse of [`Self::depth_of`]).
    #[inline]
    pub fn nearness_of(&self, t: f32) -> f32 {
        let (t_far, t_near) = (f64::from(self.t_far), f64::from(self.t_near));
        ((t_far - f64::from(t)) / (t_far - t_near)) as f32
    }

    /// Separation in pixels of a point at depth `t` pixels behind the image plane.
    ///
    /// # Errors
    /// Eq. 3 with `t + f ≤ 0`.
    pub fn separation_at_depth(&self, t: f32) -> Result<f32> {
        match self.model {
            DisparityModel::ViewAngle => Ok(separation_view_angle(t, self.tan_phi)),
            DisparityModel::EyeDistance => {
                separation_eye_distance(t, self.eye_separation, self.viewing_distance)
            }
        }
    }

    /// Separation in pixels of normalized nearness `z` ∈ [0, 1]. Never fails: the validated
    /// depth range keeps `t ≥ t_near > 0`, far from eq. 3's pole.
    #[inline]
    pub fn separation(&self, z: f32) -> f32 {
        let t = self.depth_of(z.clamp(0.0, 1.0));
        match self.model {
            DisparityModel::ViewAngle => separation_view_angle(t, self.tan_phi),
            DisparityModel::EyeDistance => self.eye_separation * t / (t + self.viewing_distance),
        }
    }

    /// Normalized nearness whose separation is `d` pixels (the decoder's inverse), unclamped:
    /// eq. 1 `t = d tan φ / 2`, eq. 3 `t = f d / (a − d)`. `NaN` for `d ≥ a` under eq. 3.
    pub fn nearness_of_separation(&self, d: f32) -> f32 {
        let t = match self.model {
            DisparityModel::ViewAngle => d * self.tan_phi * 0.5,
            DisparityModel::EyeDistance if d < self.eye_separation => {
                self.viewing_distance * d / (self.eye_separation - d)
            }
            DisparityModel::EyeDistance => f32::NAN,
        };
        self.nearness_of(t)
    }

    /// Slope `tan φ` (depth per lateral pixel) of the ray from a point at depth `t` to either
    /// eye: constant under eq. 1, eq. 2 under eq. 3. Hidden-surface removal walks along it.
    #[inline]
    pub fn ray_slope(&self, t: f32) -> f32 {
        match self.model {
            DisparityModel::ViewAngle => self.tan_phi,
            DisparityModel::EyeDistance => {
                tan_phi_eye_distance(t, self.eye_separation, self.viewing_distance)
            }
        }
    }

    /// Smallest separation (front of the depth range, `z = 1`), pixels.
    pub fn min_separation(&self) -> f32 {
        self.separation(1.0)
    }

    /// Largest separation (background plane, `z = 0`), pixels.
    pub fn max_separation(&self) -> f32 {
        self.separation(0.0)
    }

    /// Checks that the separations fit an image `width` pixels wide.
    ///
    /// # Errors
    /// `Invalid` when the background separation is not narrower than the image, or the front
    /// separation is under 2 pixels (no room for a single strip).
    pub fn check_width(&self, width: u32) -> Result<()> {
        let (lo, hi) = (self.min_separation(), self.max_separation());
        if hi.is_nan() || hi >= width as f32 {
            return Err(Error::invalid(
                "sirds separation",
                format!("{hi:.1} px"),
                format!(
                    "the background separation must be narrower than the image ({width} px): lower sirds.dpi or sirds.eye_separation_in"
                ),
            ));
        }
        if lo.is_nan() || lo < 2.0 {
            return Err(Error::invalid(
                "sirds separation",
                format!("{lo:.2} px"),
                "the front separation must be at least 2 px: raise sirds.dpi or sirds.depth_near_in",
            ));
        }
        Ok(())
    }
}
