//! Julesz's random-dot stereo pair (the SIRDS paper (Petz et al.), §1: "the HVS can perform
//! this complex task purely from stereopsis, i.e. without relying on any other clues such as
//! perspective or contours using Random Dot Stereograms (RDS)"), built from the exercise slides'
//! remap and their random texture `rnd_tex`.
//!
//! - The **left** image is a random-dot texture: black and white square dots of
//!   `dot_size` pixels, a pure function of (seed, dot column, dot row). It holds no shape.
//! - The **right** image is the left eye's dots as the right eye sees them: each right pixel is
//!   remapped into the left eye (`MVP_l · MVP_r⁻¹`, [`Remapper`]) and takes the dot there,
//!   when the left eye sees the same surface point (the visibility check). Where it does not
//!   (the strip only the right eye sees beside a near object, or outside the left image), the
//!   pixel gets a fresh dot from a second, independent stream: Julesz's uncorrelated region.
//!
//! So the right image is statistically the same noise as the left, and only the horizontal
//! shift between the two, `p(z)` pixels at a surface at eye distance z (the exercise slides'
//! `p(z) = d·(1 − z0/z)`), carries the scene. Pixels where nothing was drawn (depth 1) are the
//! far plane: the background lies at the far clipping distance.

use glam::Mat4;
use image::RgbaImage;
use serde::Deserialize;

use super::eye_input::check_same_size;
use super::remap::{Precision, Remapper, Visibility, classify, depth_slope, tolerance};
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// The largest dot: a side of 64 pixels already shows shapes only in huge images.
pub const MAX_DOT_SIZE: u32 = 64;

/// `[rds]` in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RdsSettings {
    /// Seed of the dots (the same seed gives the same bytes).
    pub seed: u64,
    /// Side of one square dot in pixels, 1 to [`MAX_DOT_SIZE`].
    pub dot_size: u32,
}

impl Default for RdsSettings {
    fn default() -> Self {
        RdsSettings {
            seed: 1,
            dot_size: 2,
        }
    }
}

impl RdsSettings {
    /// # Errors
    /// `Invalid` naming `rds.dot_size` outside 1 to [`MAX_DOT_SIZE`].
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_DOT_SIZE).contains(&self.dot_size) {
            return Err(Error::invalid(
                "rds.dot_size",
                self.dot_size,
                format!("must be 1 to {MAX_DOT_SIZE} pixels"),
            ));
        }
        Ok(())
    }
}

const WHITE: [u8; 4] = [255, 255, 255, 255];
const BLACK: [u8; 4] = [0, 0, 0, 255];

// Every dot is a pure function of (seed, x, y) through SplitMix64's finalizer, the SIRDS
// patterns' own hash, so the bytes do not depend on the order pixels are computed in.
use super::sirds::pattern::mix;

/// The dot covering pixel (x, y) of the texture with `seed`: black or white with equal chance.
#[inline]
pub fn dot(seed: u64, dot_size: u32, x: u32, y: u32) -> [u8; 4] {
    let (cx, cy) = (x / dot_size.max(1), y / dot_size.max(1));
    let h = mix(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ ((u64::from(cy) << 32) | u64::from(cx)));
    if h >> 63 == 0 { BLACK } else { WHITE }
}

/// The seed of the second stream, for the pixels only the right eye sees.
pub fn right_only_seed(seed: u64) -> u64 {
    mix(seed ^ 0x005e_ed0f_4a11_0e5e)
}

/// The left image: the random-dot texture (`rnd_tex`) itself, `width`×`height`.
pub fn rds_left(width: u32, height: u32, s: &RdsSettings) -> RgbaImage {
    RgbaImage::from_fn(width, height, |x, y| {
        image::Rgba(dot(s.seed, s.dot_size, x, y))
    })
}

/// Where right pixel (x, y), at window depth `depth`, finds its dot in the left image: the left
/// texel when the left eye sees the same surface point there, `None` otherwise. `remapper`
/// maps the right eye into the left one; `left` supplies the left eye's depth for the
/// visibility check. The background (depth 1) is the far plane: visible to the left eye where
/// the left eye's depth there is the background too.
#[inline]
pub fn source_texel(
    remapper: &Remapper,
    right: &Framebuffer,
    left: &Framebuffer,
    x: u32,
    y: u32,
) -> Option<(u32, u32)> {
    let d = right.depth[right.index(x, y)];
    let m = remapper.remap(x, y, d)?;
    let (tx, ty) = m.texel(left.width, left.height)?;
    let left_depth = left.depth[left.index(tx, ty)];
    if d >= 1.0 {
        return (left_depth >= 1.0).then_some((tx, ty));
    }
    let visible = classify(
        d,
        Some((m, left_depth)),
        tolerance(depth_slope(right, x, y)),
    ) == Visibility::Visible;
    visible.then_some((tx, ty))
}

/// The right image: the left image's dots seen by the right eye. `left` and `right` are the
/// eyes' depth buffers (their colors are not read), `left_mvp` and `right_mvp` their matrices.
///
/// # Errors
/// Different sizes, a singular MVP, or invalid settings.
pub fn rds_right(
    left: &Framebuffer,
    right: &Framebuffer,
    left_mvp: &Mat4,
    right_mvp: &Mat4,
    s: &RdsSettings,
) -> Result<RgbaImage> {
    s.validate()?;
    check_same_size(left, right)?;
    let r = Remapper::new(
        right_mvp,
        left_mvp,
        right.width,
        right.height,
        Precision::F64,
    )?;
    let fresh = right_only_seed(s.seed);
    Ok(RgbaImage::from_fn(right.width, right.height, |x, y| {
        image::Rgba(match source_texel(&r, right, left, x, y) {
            Some((tx, ty)) => dot(s.seed, s.dot_size, tx, ty),
            None => dot(fresh, s.dot_size, x, y),
        })
    }))
}

/// Both images as a framebuffer pair (color only; depth cleared), e.g. for an anaglyph.
pub fn as_framebuffer(img: &RgbaImage) -> Framebuffer {
    Framebuffer {
        width: img.width(),
        height: img.height(),
        color: img.pixels().map(|p| p.0).collect(),
        depth: vec![1.0; img.width() as usize * img.height() as usize],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_are_half_black_and_fixed_by_the_seed() {
        let s = RdsSettings {
            seed: 7,
            dot_size: 1,
        };
        let a = rds_left(128, 128, &s);
        assert_eq!(a, rds_left(128, 128, &s));
        assert_ne!(a, rds_left(128, 128, &RdsSettings { seed: 8, ..s }));
        let black = a.pixels().filter(|p| p.0 == BLACK).count() as f64 / (128.0 * 128.0);
        assert!((black - 0.5).abs() < 0.02, "{black}");
    }

    #[test]
    fn a_dot_covers_dot_size_pixels() {
        let s = RdsSettings {
            seed: 3,
            dot_size: 4,
        };
        let a = rds_left(16, 16, &s);
        for y in 0..16 {
            for x in 0..16 {
                assert_eq!(a.get_pixel(x, y), a.get_pixel(x / 4 * 4, y / 4 * 4));
            }
        }
    }

    #[test]
    fn dot_size_is_bounded() {
        for bad in [0, MAX_DOT_SIZE + 1] {
            let e = RdsSettings {
                seed: 1,
                dot_size: bad,
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("rds.dot_size"), "{e}");
        }
    }
}
