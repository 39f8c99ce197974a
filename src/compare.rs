//! Image metrics and diff images: coverage mismatch, channel differences, PSNR, depth error;
//! the ASCII coverage map and the `expected | diff | actual` PNG strip.

use std::path::{Path, PathBuf};

use image::{Rgba, RgbaImage};

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// How two framebuffers differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels whose covered/uncovered state differs (covered = depth < 1).
    pub coverage_mismatch: usize,
    /// Largest |difference| of any RGB channel, 0..255.
    pub max_channel_diff: u8,
    /// Mean |difference| over RGB channels.
    pub mean_channel_diff: f64,
    /// Peak signal-to-noise ratio in dB over RGB (infinite when identical).
    pub psnr: f64,
    /// Largest |depth difference| where both cover.
    pub max_depth_diff: f32,
}

impl Metrics {
    /// Coverage mismatch as a percentage of all pixels.
    pub fn coverage_mismatch_percent(&self) -> f64 {
        100.0 * self.coverage_mismatch as f64 / self.pixels.max(1) as f64
    }
}

/// Compares two framebuffers of the same size.
///
/// # Errors
/// Different sizes.
pub fn compare(expected: &Framebuffer, actual: &Framebuffer) -> Result<Metrics> {
    if (expected.width, expected.height) != (actual.width, actual.height) {
        return Err(Error::invalid(
            "compare",
            format!(
                "{}x{} vs {}x{}",
                expected.width, expected.height, actual.width, actual.height
            ),
            "images must have the same size",
        ));
    }
    let mut m = Metrics {
        pixels: expected.color.len(),
        coverage_mismatch: 0,
        max_channel_diff: 0,
        mean_channel_diff: 0.0,
        psnr: f64::INFINITY,
        max_depth_diff: 0.0,
    };
    let mut sum = 0u64;
    let mut sq = 0u64;
    for i in 0..expected.color.len() {
        let (a, b) = (expected.color[i], actual.color[i]);
        for c in 0..3 {
            let d = a[c].abs_diff(b[c]);
            m.max_channel_diff = m.max_channel_diff.max(d);
            sum += d as u64;
            sq += (d as u64) * (d as u64);
        }
        let (da, db) = (expected.depth[i], actual.depth[i]);
        let (ca, cb) = (da < 1.0, db < 1.0);
        if ca != cb {
            m.coverage_mismatch += 1;
        } else if ca {
            m.max_depth_diff = m.max_depth_diff.max((da - db).abs());
        }
    }
    let n = (3 * m.pixels).max(1) as f64;
    m.mean_channel_diff = sum as f64 / n;
    if sq > 0 {
        m.psnr = 10.0 * (255.0f64 * 255.0 / (sq as f64 / n)).log10();
    }
    Ok(m)
}

/// Coverage of each pixel: depth < 1 (something was drawn).
pub fn coverage(fb: &Framebuffer) -> Vec<bool> {
    fb.depth.iter().map(|d| *d < 1.0).collect()
}

/// Scotty3D-style ASCII map of two coverage masks: `#` both, `!` extra (actual only),
/// `?` missed (expected only), `.` neither. Only for small rasters: rows longer than
/// `max_width` are cut.
pub fn ascii_map(expected: &[bool], actual: &[bool], width: usize, max_width: usize) -> String {
    let mut s = String::new();
    for (row_e, row_a) in expected.chunks(width).zip(actual.chunks(width)) {
        for (e, a) in row_e.iter().zip(row_a).take(max_width) {
            s.push(match (e, a) {
                (true, true) => '#',
                (false, true) => '!',
                (true, false) => '?',
                (false, false) => '.',
            });
        }
        s.push('\n');
    }
    s
}

/// An image of where two framebuffers differ: black where equal, the per-pixel maximum channel
/// difference amplified ×8 in red, coverage mismatches in full yellow.
pub fn diff_image(expected: &Framebuffer, actual: &Framebuffer) -> RgbaImage {
    RgbaImage::from_fn(expected.width, expected.height, |x, y| {
        let i = expected.index(x, y);
        let (a, b) = (expected.color[i], actual.color[i]);
        if (expected.depth[i] < 1.0) != (actual.depth[i] < 1.0) {
            return Rgba([255, 255, 0, 255]);
        }
        let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        Rgba([d.saturating_mul(8), 0, 0, 255])
    })
}

/// Writes `expected | diff | actual` side by side as `DIR/NAME.png`; returns the path.
///
/// # Errors
/// Different sizes or an unwritable folder.
pub fn write_diff_strip(
    expected: &Framebuffer,
    actual: &Framebuffer,
    dir: &Path,
    name: &str,
) -> Result<PathBuf> {
    compare(expected, actual)?;
    let (w, h) = (expected.width, expected.height);
    let diff = diff_image(expected, actual);
    let (e, a) = (expected.to_rgba_image(), actual.to_rgba_image());
    let strip = RgbaImage::from_fn(3 * w, h, |x, y| match x / w {
        0 => *e.get_pixel(x, y),
        1 => *diff.get_pixel(x - w, y),
        _ => *a.get_pixel(x - 2 * w, y),
    });
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let path = dir.join(format!("{name}.png"));
    strip
        .save(&path)
        .map_err(|e| Error::io(&path, std::io::Error::other(e.to_string())))?;
    Ok(path)
}
