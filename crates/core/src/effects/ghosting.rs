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
//!
//! Cancellation (Bino's `--ghostbust`; crosstalk cancellation by subtraction, Lipscomb &
//! Wooten 1994, Konrad, Lacotte & Dubois 2000) sends each eye a corrected image so that after
//! the leak above each eye sees its own image and none of the other's. With both eyes
//! corrected, the sent pair `s` must solve `s_this + k·s_other = target_this` for both eyes, and
//! since no display emits less than black, the target is the original with black lifted to `k`:
//! `target = k + (1 − k)·this` is the widest range whose solution stays within [0, 1]. Solving
//! the 2×2 system gives [`cancel_value`]; `cancel` scales `k` (1: full, 0: none).

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
    /// How much of the leak to cancel, 0 (none) to 1 (all, black lifted to `leak`): the
    /// `cancelled_*` outputs are the images sent, and `ghosting_*` show them after the leak.
    pub cancel: f32,
}

impl Default for GhostingSettings {
    fn default() -> Self {
        GhostingSettings {
            leak: DEFAULT_LEAK,
            cancel: 0.0,
        }
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
        if !(0.0..=1.0).contains(&self.cancel) {
            return Err(Error::invalid(
                "ghosting.cancel",
                self.cancel,
                "must be 0 (no cancellation) to 1 (cancel the whole leak)",
            ));
        }
        Ok(())
    }

    /// The leak the cancellation corrects for, per channel: `cancel · leak`. It is also how far
    /// black is lifted, in linear light: a cancelled pair is seen as `k + (1 − k)·original`.
    pub fn cancelled_leak(&self) -> [f32; 3] {
        self.leak.map(|l| self.cancel * l)
    }
}

/// One channel of crosstalk cancellation in linear light: the value to send for `this` so that,
/// with `other` sent as `cancel_value(other, this, k)`, the eye sees `k + (1 − k)·this` under
/// [`ghost_pixel`]'s leak `k`:
///
/// ```text
/// sent = (this − k·other + k) / (1 + k)
/// ```
///
/// From `s_t + k·s_o = k + (1 − k)·t` and `s_o + k·s_t = k + (1 − k)·o` (both eyes corrected):
/// `s_t = (target_t − k·target_o)/(1 − k²)`, which simplifies to the above and lies in [0, 1]
/// for all `t`, `o` in [0, 1] (0 at `t = 0, o = 1`; 1 at `t = 1, o = 0`). The subtraction is
/// the crosstalk cancellation of Lipscomb & Wooten (1994) and Bino's `--ghostbust`; the black
/// lift `k` is what keeps it from clipping.
#[inline]
pub fn cancel_value(this: f32, other: f32, k: f32) -> f32 {
    ((this - k * other + k) / (1.0 + k)).clamp(0.0, 1.0)
}

/// One pixel of [`cancelled`]: [`cancel_value`] per channel in linear light, encoded back to
/// 8-bit sRGB (rounded). Alpha stays `this`'s; `k = 0` returns `this` unchanged.
#[inline]
pub fn cancel_pixel(this: [u8; 4], other: [u8; 4], k: [f32; 3]) -> [u8; 4] {
    let mut out = this;
    for c in 0..3 {
        if k[c] == 0.0 {
            continue;
        }
        let t = srgb_to_linear(this[c] as f32 / 255.0);
        let o = srgb_to_linear(other[c] as f32 / 255.0);
        out[c] = (linear_to_srgb(cancel_value(t, o, k[c])) * 255.0).round() as u8;
    }
    out
}

/// `this` eye's image corrected for crosstalk from `other` (`s.cancel · s.leak` per channel),
/// as it is sent to the display.
///
/// # Errors
/// Different sizes, or a leak or cancel outside 0 to 1.
pub fn cancelled(
    this: &Framebuffer,
    other: &Framebuffer,
    s: &GhostingSettings,
) -> Result<RgbaImage> {
    let k = s.cancelled_leak();
    pixel_pairs(this, other, s, |t, o| cancel_pixel(t, o, k))
}

/// `pixel(this, other)` at every pixel of a pair, after checking the settings and the sizes.
fn pixel_pairs(
    this: &Framebuffer,
    other: &Framebuffer,
    s: &GhostingSettings,
    pixel: impl Fn([u8; 4], [u8; 4]) -> [u8; 4],
) -> Result<RgbaImage> {
    s.validate()?;
    check_same_size(this, other)?;
    let bytes = this
        .color
        .iter()
        .zip(&other.color)
        .flat_map(|(t, o)| pixel(*t, *o))
        .collect();
    Ok(RgbaImage::from_raw(this.width, this.height, bytes).expect("4 bytes per pixel"))
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

/// `this` eye's image as it is seen with crosstalk from `other`: the pair sent is the
/// [`cancelled`] one (the originals when `s.cancel` is 0), and `s.leak` leaks in.
///
/// # Errors
/// Different sizes, or a leak or cancel outside 0 to 1.
pub fn ghosted(this: &Framebuffer, other: &Framebuffer, s: &GhostingSettings) -> Result<RgbaImage> {
    let k = s.cancelled_leak();
    pixel_pairs(this, other, s, |t, o| {
        let (sent_t, sent_o) = if s.cancel == 0.0 {
            (t, o)
        } else {
            (cancel_pixel(t, o, k), cancel_pixel(o, t, k))
        };
        ghost_pixel(sent_t, sent_o, s.leak)
    })
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
            let e = GhostingSettings {
                leak: bad,
                cancel: 0.0,
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("ghosting.leak"), "{e}");
        }
        for bad in [-0.5, 1.01, f32::NAN] {
            let e = GhostingSettings {
                leak: DEFAULT_LEAK,
                cancel: bad,
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("ghosting.cancel") && e.contains("0 (no"), "{e}");
        }
    }

    #[test]
    fn cancelled_pair_is_seen_as_the_lifted_original() {
        // The 2×2 system solved exactly, in real numbers: each eye sees k + (1 − k)·own.
        for k in [0.0f32, 0.01, 0.06, 0.3, 1.0] {
            for (t, o) in [
                (0.0f32, 1.0f32),
                (1.0, 0.0),
                (0.2, 0.7),
                (0.5, 0.5),
                (1.0, 1.0),
            ] {
                let (st, so) = (cancel_value(t, o, k), cancel_value(o, t, k));
                assert!((0.0..=1.0).contains(&st) && (0.0..=1.0).contains(&so));
                let seen = st + k * so;
                assert!(
                    (seen - (k + (1.0 - k) * t)).abs() < 1e-6,
                    "k {k} t {t} o {o}"
                );
            }
        }
    }
}
