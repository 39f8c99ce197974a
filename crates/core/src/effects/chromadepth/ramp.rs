//! The ChromaDepth color ramp: a 1D texture from red through green to blue (the ChromaDepth article), or the
//! red–white–blue alternative, sampled like an OpenGL 1D texture with `GL_CLAMP_TO_EDGE`.

use glam::Vec3;
use serde::Deserialize;

use crate::error::{Error, Result};

/// Texels in the ramp unless the scene says otherwise (the ChromaDepth article builds a 1D texture; 256 is
/// one texel per 8-bit step).
pub const DEFAULT_TEXELS: usize = 256;

/// Hue of the far end of the HSV ramp: 0° is red (near), 120° green, 240° blue (far).
pub const FAR_HUE_DEGREES: f32 = 240.0;

/// Which colors the ramp runs through, near to far.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RampKind {
    /// The ChromaDepth article: hue 0° → 240° at full saturation and value, interpolated in HSV
    /// (red, yellow, green, cyan, blue).
    #[default]
    Hsv,
    /// The alternative ChromaDepth's maker documents: red → white → blue, linear in RGB. Through
    /// the glasses white sits between red and blue in depth (see `glasses`), and the ramp keeps
    /// a neutral middle for scenes where green would clash.
    RedWhiteBlue,
}

/// How the 1D texture is filtered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sampling {
    /// `GL_NEAREST`: the texel whose cell holds `s`.
    Nearest,
    /// `GL_LINEAR`: blend of the two texel centers around `s`.
    #[default]
    Linear,
}

/// A ramp texture: `texels[0]` is the near color (s = 0), the last texel the far color (s = 1).
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    kind: RampKind,
    texels: Vec<Vec3>,
}

impl Ramp {
    /// Builds `count` texels; texel `i` holds the exact ramp color at `t = i / (count − 1)`, so
    /// the first texel is pure red and the last pure blue.
    ///
    /// # Errors
    /// `Invalid` (`chromadepth.texels`) when `count` is outside 2..=65536.
    pub fn new(kind: RampKind, count: usize) -> Result<Ramp> {
        if !(2..=65536).contains(&count) {
            return Err(Error::invalid(
                "chromadepth.texels",
                count,
                "must lie in 2..=65536",
            ));
        }
        let last = (count - 1) as f32;
        Ok(Ramp {
            kind,
            texels: (0..count).map(|i| exact(kind, i as f32 / last)).collect(),
        })
    }

    /// The colors through which the ramp runs.
    pub fn kind(&self) -> RampKind {
        self.kind
    }

    /// The texels, near (red) first.
    pub fn texels(&self) -> &[Vec3] {
        &self.texels
    }

    /// Samples at texture coordinate `s` with OpenGL's 1D rules and `GL_CLAMP_TO_EDGE`:
    /// texel `i` is centered at `s = (i + ½)/N`; nearest takes `⌊s N⌋`, linear blends the
    /// texels around `u = s N − ½`. `s` is clamped to [0, 1] first (NaN counts as 0), so objects
    /// nearer than D1 stay red and objects beyond D2 stay blue: a repeat wrap would paint far
    /// objects red again.
    pub fn sample(&self, s: f32, sampling: Sampling) -> Vec3 {
        let s = clamp_unit(s);
        let n = self.texels.len();
        let last = n - 1;
        match sampling {
            Sampling::Nearest => self.texels[((s * n as f32) as usize).min(last)],
            Sampling::Linear => {
                // u + 1 = s N + ½ ≥ ½, so truncation is its floor (no libm `floor` call).
                let u1 = s * n as f32 + 0.5;
                let i1 = u1 as usize;
                let t = u1 - i1 as f32;
                let at = |i: usize| self.texels[i.min(last)];
                at(i1.saturating_sub(1)).lerp(at(i1), t)
            }
        }
    }
}

/// The exact (continuous) ramp color at `t`, clamped to [0, 1]: what an infinitely fine texture
/// would hold, and the reference the benchmark measures sampling errors against.
pub fn exact(kind: RampKind, t: f32) -> Vec3 {
    let t = clamp_unit(t);
    match kind {
        RampKind::Hsv => hsv_to_rgb(FAR_HUE_DEGREES * t, 1.0, 1.0),
        RampKind::RedWhiteBlue if t <= 0.5 => Vec3::new(1.0, 2.0 * t, 2.0 * t),
        RampKind::RedWhiteBlue => {
            let f = 2.0 - 2.0 * t;
            Vec3::new(f, f, 1.0)
        }
    }
}

/// Clamps to [0, 1], NaN to 0 (red): `f32::clamp` would pass the NaN on into the texel index.
fn clamp_unit(s: f32) -> f32 {
    if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) }
}

/// HSV → RGB (all in 0..1, hue in degrees, wrapped into [0°, 360°)): the standard hexcone
/// model (Smith 1978), `c = v s`, `x = c (1 − |(h/60°) mod 2 − 1|)`.
pub fn hsv_to_rgb(hue_degrees: f32, saturation: f32, value: f32) -> Vec3 {
    let h = hue_degrees.rem_euclid(360.0) / 60.0;
    let c = value * saturation;
    let x = c * (1.0 - ((h % 2.0) - 1.0).abs());
    let m = value - c;
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    Vec3::new(r + m, g + m, b + m)
}

/// The hue of an RGB color in degrees [0°, 360°), or `None` for a gray (no hue).
pub fn hue_degrees(rgb: Vec3) -> Option<f32> {
    let max = rgb.max_element();
    let min = rgb.min_element();
    let c = max - min;
    if c <= 0.0 {
        return None;
    }
    let h = if max == rgb.x {
        ((rgb.y - rgb.z) / c).rem_euclid(6.0)
    } else if max == rgb.y {
        (rgb.z - rgb.x) / c + 2.0
    } else {
        (rgb.x - rgb.y) / c + 4.0
    };
    Some(h * 60.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hsv_primaries_round_trip() {
        for (h, rgb) in [
            (0.0, Vec3::X),
            (60.0, Vec3::new(1.0, 1.0, 0.0)),
            (120.0, Vec3::Y),
            (180.0, Vec3::new(0.0, 1.0, 1.0)),
            (240.0, Vec3::Z),
        ] {
            assert_eq!(hsv_to_rgb(h, 1.0, 1.0), rgb, "hue {h}");
            assert_eq!(hue_degrees(rgb), Some(h), "rgb {rgb}");
        }
        assert_eq!(hue_degrees(Vec3::splat(0.5)), None);
    }

    #[test]
    fn linear_sampling_hits_texel_centers_exactly() {
        let r = Ramp::new(RampKind::Hsv, 8).expect("valid size");
        for (i, t) in r.texels().iter().enumerate() {
            let s = (i as f32 + 0.5) / 8.0;
            assert_eq!(r.sample(s, Sampling::Linear), *t, "texel {i}");
            assert_eq!(r.sample(s, Sampling::Nearest), *t, "texel {i}");
        }
    }
}
