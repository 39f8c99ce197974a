//! Stereo pair layouts (the StereoGraphics guide's §8 for above-below): pure functions of the two eye images.

use image::{Rgba, RgbaImage};

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

fn same_size(left: &Framebuffer, right: &Framebuffer) -> Result<()> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::invalid(
            "eye framebuffers",
            format!(
                "{}x{} vs {}x{}",
                left.width, left.height, right.width, right.height
            ),
            "left and right must have the same size",
        ));
    }
    Ok(())
}

/// `a | b` side by side. Parallel (wall-eyed) viewing: `side_by_side(left, right)`;
/// cross-eyed viewing: `side_by_side(right, left)`.
///
/// # Errors
/// Different sizes.
pub fn side_by_side(a: &Framebuffer, b: &Framebuffer) -> Result<RgbaImage> {
    same_size(a, b)?;
    let (w, h) = (a.width, a.height);
    Ok(RgbaImage::from_fn(2 * w, h, |x, y| {
        Rgba(if x < w {
            a.pixel(x, y)
        } else {
            b.pixel(x - w, y)
        })
    }))
}

/// Left on top of right, each at full size.
///
/// # Errors
/// Different sizes.
pub fn above_below(left: &Framebuffer, right: &Framebuffer) -> Result<RgbaImage> {
    same_size(left, right)?;
    let (w, h) = (left.width, left.height);
    Ok(RgbaImage::from_fn(w, 2 * h, |x, y| {
        Rgba(if y < h {
            left.pixel(x, y)
        } else {
            right.pixel(x, y - h)
        })
    }))
}

/// The StereoGraphics guide's sync-doubling format in a frame of the eyes' size W×H: each view squashed to
/// `(H − blank)/2` rows (area-averaged), left on top, a black blank interval between them.
/// With H = 768 and blank = 40: left rows 0–363, blank 364–403, right 404–767 (the StereoGraphics guide (Akka)).
///
/// # Errors
/// Different sizes, or a blank interval that leaves no rows.
pub fn above_below_squashed(
    left: &Framebuffer,
    right: &Framebuffer,
    blank: u32,
) -> Result<RgbaImage> {
    same_size(left, right)?;
    let (w, h) = (left.width, left.height);
    if u64::from(blank) + 2 > u64::from(h) {
        return Err(Error::invalid(
            "layout.blank_interval",
            blank,
            format!("leaves no rows in a {h}-row frame"),
        ));
    }
    let rows = (h - blank) / 2;
    let mut out = RgbaImage::from_pixel(w, h, Rgba([0, 0, 0, 255]));
    for (fb, top) in [(left, 0), (right, rows + blank)] {
        for j in 0..rows {
            for x in 0..w {
                out.put_pixel(x, top + j, Rgba(area_average_column(fb, x, j, rows)));
            }
        }
    }
    Ok(out)
}

/// The mean of column `x` over source rows `[j·H/rows, (j+1)·H/rows)`, partial rows weighted.
fn area_average_column(fb: &Framebuffer, x: u32, j: u32, rows: u32) -> [u8; 4] {
    let scale = fb.height as f64 / rows as f64;
    let (y0, y1) = (j as f64 * scale, (j + 1) as f64 * scale);
    let mut acc = [0f64; 4];
    let mut y = y0.floor() as u32;
    while (y as f64) < y1 && y < fb.height {
        let weight = (y1.min(y as f64 + 1.0) - y0.max(y as f64)).max(0.0);
        let p = fb.pixel(x, y);
        for c in 0..4 {
            acc[c] += weight * p[c] as f64;
        }
        y += 1;
    }
    acc.map(|a| (a / scale).round().clamp(0.0, 255.0) as u8)
}

/// Interleaves the two views per pixel: `pick_left(x, y)` chooses the source.
///
/// # Errors
/// Different sizes.
pub fn interleave(
    left: &Framebuffer,
    right: &Framebuffer,
    pick_left: impl Fn(u32, u32) -> bool,
) -> Result<RgbaImage> {
    same_size(left, right)?;
    Ok(RgbaImage::from_fn(left.width, left.height, |x, y| {
        Rgba(if pick_left(x, y) {
            left.pixel(x, y)
        } else {
            right.pixel(x, y)
        })
    }))
}
