//! Crosstalk ("ghosting"): a share of the other eye's image leaking into each eye, and the
//! contrast check that predicts where it shows.
//!
//! The StereoGraphics guide (Akka), §8: "very high contrast values in a stereo image will often
//! result in 'ghosting', in which some of one eye's view appears as a 'ghost' in the other
//! eye's view. This tends to be caused by CRT phosphor persistence … Green tends to be the
//! worst offender. … Use a gray background instead of a black background … and if possible,
//! try to avoid using bright white, green, and cyan scene elements against a dark background."
//!
//! The model, per pixel and channel c, in linear light (sRGB decoded, IEC 61966-2-1):
//!
//! ```text
//! seen_c = min(1, this_c + leak_c · other_c)
//! ```
//!
//! Phosphor persistence adds light: when this eye's shutter opens, the other eye's frame still
//! glows with a share `leak_c` of its brightness. The guide gives no numbers, only the order
//! (green worst); the defaults [`DEFAULT_LEAK`] are illustrative values in that order, not
//! measurements.

use image::RgbaImage;
use serde::Deserialize;

use super::anaglyph::{linear_to_srgb, srgb_to_linear};
use super::eye_input::check_same_size;
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// Default leak per channel (R, G, B): green largest, as the StereoGraphics guide orders them
/// (its P22-era CRTs: green phosphor persists longest, blue shortest). Illustrative, not from a
/// measurement: set `ghosting.leak` for a real display.
pub const DEFAULT_LEAK: [f32; 3] = [0.03, 0.06, 0.01];

/// `[ghosting]` in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GhostingSettings {
    /// Share of the other eye's linear light leaking in, per channel R, G, B, each 0 to 1.
    pub leak: [f32; 3],
}

impl Default for GhostingSettings {
    fn default() -> Self {
        GhostingSettings { leak: DEFAULT_LEAK }
    }
}

impl GhostingSettings {
    /// # Errors
    /// `Invalid` naming `ghosting.leak` when a share is not within 0 to 1.
    pub fn validate(&self) -> Result<()> {
        if self.leak.iter().any(|l| !(0.0..=1.0).contains(l)) {
            return Err(Error::invalid(
                "ghosting.leak",
                format!("{:?}", self.leak),
                "each channel's share must be 0 to 1 (e.g. [0.03, 0.06, 0.01])",
            ));
        }
        Ok(())
    }
}

/// One pixel of [`ghosted`]: `this` with `leak` of `other` added in linear light, encoded back
/// to 8-bit sRGB (rounded). Alpha stays `this`'s.
#[inline]
pub fn ghost_pixel(this: [u8; 4], other: [u8; 4], leak: [f32; 3]) -> [u8; 4] {
    let mut out = this;
    for c in 0..3 {
        let t = srgb_to_linear(this[c] as f32 / 255.0);
        let o = srgb_to_linear(other[c] as f32 / 255.0);
        let seen = (t + leak[c] * o).min(1.0);
        out[c] = (linear_to_srgb(seen) * 255.0).round() as u8;
    }
    out
}

/// `this` eye's image as it is seen with crosstalk from `other`.
///
/// # Errors
/// Different sizes, or a leak outside 0 to 1.
pub fn ghosted(this: &Framebuffer, other: &Framebuffer, s: &GhostingSettings) -> Result<RgbaImage> {
    s.validate()?;
    check_same_size(this, other)?;
    let bytes = this
        .color
        .iter()
        .zip(&other.color)
        .flat_map(|(t, o)| ghost_pixel(*t, *o, s.leak))
        .collect();
    Ok(RgbaImage::from_raw(this.width, this.height, bytes).expect("4 bytes per pixel"))
}

/// Relative luminance of an 8-bit sRGB color in linear light (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: [u8; 4]) -> f32 {
    let l = |k: usize| srgb_to_linear(c[k] as f32 / 255.0);
    0.2126 * l(0) + 0.7152 * l(1) + 0.0722 * l(2)
}

/// A pixel is dark at most this linear luminance (sRGB ≈ 63 of 255).
pub const DARK: f32 = 0.05;
/// A pixel is bright at least this linear luminance (sRGB ≈ 188 of 255): 10:1 against [`DARK`].
pub const BRIGHT: f32 = 0.5;
/// A ghost band is large from this share of the image width (a third of the StereoGraphics
/// guide's 3% parallax budget), and at least [`MIN_WARN_RUN`] pixels.
pub const WARN_WIDTH_PERCENT: f32 = 1.0;
/// The narrowest ghost band warned about, in pixels.
pub const MIN_WARN_RUN: u32 = 2;

/// Where one eye's image is ghost-prone: dark in this eye where the other eye is bright. The
/// two eyes differ like that only where parallax moves a bright-on-dark edge, and the band is
/// as wide as the edge's parallax: its widest run along a row measures that parallax.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GhostRisk {
    /// Pixels dark here (≤ [`DARK`]) and bright in the other eye (≥ [`BRIGHT`]).
    pub pixels: usize,
    /// The widest horizontal run of such pixels, in pixels.
    pub widest_run: u32,
    /// Run width from which [`GhostRisk::warns`]: `max(MIN_WARN_RUN, ⌈1% of the width⌉)`.
    pub warn_run: u32,
}

impl GhostRisk {
    /// Whether the report warns: a ghost band at least [`GhostRisk::warn_run`] wide.
    pub fn warns(&self) -> bool {
        self.widest_run >= self.warn_run
    }
}

/// The ghost-prone pixels of `this` against `other`.
///
/// # Errors
/// Different sizes.
pub fn ghost_risk(this: &Framebuffer, other: &Framebuffer) -> Result<GhostRisk> {
    check_same_size(this, other)?;
    let warn_run =
        ((WARN_WIDTH_PERCENT / 100.0 * this.width as f32).ceil() as u32).max(MIN_WARN_RUN);
    let mut risk = GhostRisk {
        pixels: 0,
        widest_run: 0,
        warn_run,
    };
    let w = this.width.max(1) as usize;
    for (row_t, row_o) in this.color.chunks(w).zip(other.color.chunks(w)) {
        let mut run = 0u32;
        for (t, o) in row_t.iter().zip(row_o) {
            if luminance(*t) <= DARK && luminance(*o) >= BRIGHT {
                risk.pixels += 1;
                run += 1;
                risk.widest_run = risk.widest_run.max(run);
            } else {
                run = 0;
            }
        }
    }
    Ok(risk)
}

/// The render report's contrast warning for one eye (`name` is "left" or "right"), or `None`
/// when no ghost band is wide enough to warn about.
pub fn contrast_warning(name: &str, other: &str, r: &GhostRisk) -> Option<String> {
    r.warns().then(|| {
        format!(
            "warning: ghosting: {} pixels of the {name} eye are dark (linear luminance <= {DARK}) \
             where the {other} eye is bright (>= {BRIGHT}), in bands up to {} px wide (the \
             parallax of bright-on-dark edges; warned from {} px, {WARN_WIDTH_PERCENT}% of the \
             width): crosstalk will show there. The StereoGraphics guide: use a gray background \
             instead of black, avoid bright white, green and cyan against a dark background",
            r.pixels, r.widest_run, r.warn_run
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leak_adds_linear_light_per_channel() {
        // Black here, white there: each channel shows exactly its leak.
        let p = ghost_pixel([0, 0, 0, 255], [255, 255, 255, 255], [0.03, 0.06, 0.01]);
        for (c, leak) in [0.03f32, 0.06, 0.01].into_iter().enumerate() {
            assert_eq!(p[c], (linear_to_srgb(leak) * 255.0).round() as u8);
        }
        // Nothing leaks from black, and no leak changes nothing.
        assert_eq!(
            ghost_pixel([90, 20, 200, 255], [0, 0, 0, 255], [0.5; 3]),
            [90, 20, 200, 255]
        );
        assert_eq!(
            ghost_pixel([90, 20, 200, 255], [255; 4], [0.0; 3]),
            [90, 20, 200, 255]
        );
    }

    #[test]
    fn leak_outside_zero_to_one_is_refused() {
        for bad in [[-0.1, 0.0, 0.0], [0.0, 1.5, 0.0], [0.0, 0.0, f32::NAN]] {
            let e = GhostingSettings { leak: bad }
                .validate()
                .unwrap_err()
                .to_string();
            assert!(e.contains("ghosting.leak"), "{e}");
        }
    }
}
