//! Shear vs rotate (the SGI course notes §4.1.3, "Rotate vs. Shear"): the same frame from the
//! off-axis rig, whose eyes keep the view direction and are *sheared* so the two frusta converge
//! at the fusion distance, and from the toe-in rig, whose eyes are *rotated* towards the fusion
//! point. The notes: shearing is "less physically accurate" but easier to fuse, "because the two
//! eye views have the same orientation"; the StereoGraphics guide (Akka) §5 names what rotation
//! costs: "some variable vertical misalignment between stereo pair elements".
//!
//! Two measurements, both pure functions of framebuffers and matrices:
//!
//! - [`vertical_parallax_map`]: per pixel of one eye, how far (in pixels, down positive) the
//!   surface point it shows lies in the other eye: unproject with `MVP_this⁻¹`, project with
//!   `MVP_other` (the exercise slides' remapping, [`Remapper`] in f64). Zero for the sheared rig
//!   (parallel axes: the eyes differ by an x translation and an x shear only), growing towards
//!   the image corners for the rotated one.
//! - [`difference`]: where the sheared and the rotated image of the same eye differ, and by how
//!   much (largest channel difference per pixel).

use glam::Mat4;
use image::{Rgba, RgbaImage};

use super::eye_input::check_same_size;
use super::remap::{Precision, Remapper};
use crate::error::Result;
use crate::framebuffer::Framebuffer;

/// Vertical parallax in pixels of every pixel of `this` (row-major): the other eye's window y
/// of the surface point the pixel shows, minus the pixel's own (`y + 0.5`). `None` on the
/// background (depth 1) and for points behind the other eye.
///
/// # Errors
/// A singular `this_mvp`.
pub fn vertical_parallax_map(
    this: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
) -> Result<Vec<Option<f64>>> {
    let (w, h) = (this.width, this.height);
    let r = Remapper::new(this_mvp, other_mvp, w, h, Precision::F64)?;
    Ok((0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = this.depth[this.index(x, y)];
            if d >= 1.0 {
                return None;
            }
            r.remap(x, y, d)
                .map(|m| m.window(w, h)[1] - (y as f64 + 0.5))
        })
        .collect())
}

/// The largest |vertical parallax| of a map, in pixels (0 when nothing is drawn).
pub fn max_abs(map: &[Option<f64>]) -> f64 {
    map.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Color of a vertical parallax `v` (pixels): white at zero, towards green for a point lower in
/// the other eye and magenta for a higher one, saturating at ±`scale`.
pub fn vertical_parallax_color(v: f64, scale: f64) -> [u8; 4] {
    let t = (v / scale).clamp(-1.0, 1.0);
    let (end, s) = if t < 0.0 {
        ([200.0, 0.0, 200.0], -t)
    } else {
        ([0.0, 150.0, 0.0], t)
    };
    let c = |k: usize| (255.0 + (end[k] - 255.0) * s).round() as u8;
    [c(0), c(1), c(2), 255]
}

/// Background of the vertical parallax image.
pub const BACKGROUND: [u8; 4] = [24, 24, 24, 255];

/// A vertical parallax map as an image, its color scale the map's largest |value| (at least a
/// hundredth of a pixel, so a zero map stays white instead of amplifying rounding noise).
pub fn vertical_parallax_image(map: &[Option<f64>], width: u32, height: u32) -> RgbaImage {
    let scale = max_abs(map).max(0.01);
    let bytes = map
        .iter()
        .flat_map(|v| v.map_or(BACKGROUND, |v| vertical_parallax_color(v, scale)))
        .collect();
    RgbaImage::from_raw(width, height, bytes).expect("4 bytes per pixel")
}

/// Where two images of the same size differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Difference {
    /// Pixels whose color differs in any channel.
    pub differing: usize,
    /// Pixels compared (width × height).
    pub pixels: usize,
    /// Largest channel difference.
    pub max_channel: u8,
}

impl Difference {
    /// Share (0..1) of pixels that differ.
    pub fn share(&self) -> f64 {
        self.differing as f64 / self.pixels.max(1) as f64
    }
}

/// The difference of `a` and `b`: per pixel the largest RGB channel difference as gray, ×4 so
/// a difference of 64 levels is white (black where the two agree), and its counts.
///
/// # Errors
/// The two framebuffers differ in size.
pub fn difference(a: &Framebuffer, b: &Framebuffer) -> Result<(RgbaImage, Difference)> {
    check_same_size(a, b)?;
    let mut d = Difference {
        differing: 0,
        pixels: a.color.len(),
        max_channel: 0,
    };
    let mut img = RgbaImage::new(a.width, a.height);
    for ((p, ca), cb) in img.pixels_mut().zip(&a.color).zip(&b.color) {
        let m = (0..3).map(|k| ca[k].abs_diff(cb[k])).max().unwrap_or(0);
        d.differing += usize::from(m > 0);
        d.max_channel = d.max_channel.max(m);
        let g = (u16::from(m) * 4).min(255) as u8;
        *p = Rgba([g, g, g, 255]);
    }
    Ok((img, d))
}
