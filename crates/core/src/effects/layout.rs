//! Stereo pair layouts (the StereoGraphics guide's §8 for above-below): pure functions of the two eye images.

use image::{Rgba, RgbaImage};

use super::anaglyph::{linear_to_srgb, srgb_to_linear};
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

/// The grid `(columns, rows)` that [`view_tiles`] lays `views` views out in: `⌈√N⌉` columns and
/// as many rows as the views fill (2 → 2×1, 4 → 2×2, 5 → 3×2, 9 → 3×3).
pub fn view_grid(views: u32) -> (u32, u32) {
    let mut columns = 1;
    while columns * columns < views {
        columns += 1;
    }
    (columns, views.div_ceil(columns))
}

/// The N views as tiles of one image, row-major from the top left in [`view_grid`]'s grid: view
/// `i` at column `i mod C`, row `⌊i / C⌋` (view 0, the leftmost camera, top left, as a quilt
/// of a multi-view display lists them); tiles no view fills are opaque black.
///
/// # Errors
/// No views, or views of different sizes.
pub fn view_tiles(views: &[&Framebuffer]) -> Result<RgbaImage> {
    let first = check_views(views)?;
    let (w, h) = (first.width, first.height);
    let (columns, rows) = view_grid(views.len() as u32);
    Ok(RgbaImage::from_fn(columns * w, rows * h, |x, y| {
        let i = (y / h) * columns + x / w;
        Rgba(match views.get(i as usize) {
            Some(v) => v.pixel(x % w, y % h),
            None => [0, 0, 0, 255],
        })
    }))
}

/// The view a lenticular sheet's column `x` shows with `views` views under each lenticule:
/// `N − 1 − (x mod N)`. A lenticule images the strips under it mirrored (the strip at its left
/// edge is seen from the right), so each lenticule holds the views right-most first (the
/// rightmost camera's strip leftmost: "Lenticular stereogram maker", Charles Douglas Wehner;
/// "3D Lenticular Printing Interlacing Algorithm Illustrated Using Photoshop", Isaac Cheung).
pub fn lenticular_view(x: u32, views: u32) -> u32 {
    views - 1 - x % views
}

/// The N views interleaved column by column for a lenticular sheet with one pixel column per
/// view under each lenticule: column `x` from view [`lenticular_view`]`(x, N)`, one eye-sized
/// image.
///
/// # Errors
/// No views, or views of different sizes.
pub fn lenticular_interleave(views: &[&Framebuffer]) -> Result<RgbaImage> {
    let first = check_views(views)?;
    let n = views.len() as u32;
    Ok(RgbaImage::from_fn(first.width, first.height, |x, y| {
        Rgba(views[lenticular_view(x, n) as usize].pixel(x, y))
    }))
}

/// The first of `views`, after checking there is one and that all have its size.
fn check_views<'a>(views: &[&'a Framebuffer]) -> Result<&'a Framebuffer> {
    let first = *views.first().ok_or_else(|| {
        Error::internal(
            "multiview",
            "no views to lay out (the plan ran no view pass)",
        )
    })?;
    for v in views {
        same_size(first, v)?;
    }
    Ok(first)
}

/// The mean of `n` pixels' linear light in one channel, encoded back to 8-bit sRGB: the box
/// filter of the frame-compatible formats. `weights` pair each pixel with its share of the
/// output pixel's footprint (they sum to 1). Color channels are decoded (IEC 61966-2-1) before
/// averaging, so the squeezed pixel emits the light of the pixels it replaces (a black and a
/// white pixel make sRGB 188, not 128); alpha is averaged as stored.
fn box_filter_linear(samples: &[([u8; 4], f64)]) -> [u8; 4] {
    let mut acc = [0f64; 4];
    for (p, weight) in samples {
        for c in 0..3 {
            acc[c] += weight * f64::from(srgb_to_linear(f32::from(p[c]) / 255.0));
        }
        acc[3] += weight * f64::from(p[3]);
    }
    let encode = |l: f64| (linear_to_srgb(l.clamp(0.0, 1.0) as f32) * 255.0).round() as u8;
    [
        encode(acc[0]),
        encode(acc[1]),
        encode(acc[2]),
        acc[3].round().clamp(0.0, 255.0) as u8,
    ]
}

/// Source pixels `[i·n/out, (i+1)·n/out)` of a line of `n` pixels squeezed to `out`, each with
/// its share of the footprint (partial pixels weighted): for `n = 2·out`, pixels `2i` and
/// `2i + 1` at ½ each.
fn footprint(i: u32, out: u32, n: u32) -> Vec<(u32, f64)> {
    let scale = f64::from(n) / f64::from(out);
    let (a, b) = (f64::from(i) * scale, f64::from(i + 1) * scale);
    (a.floor() as u32..n)
        .take_while(|&s| f64::from(s) < b)
        .map(|s| (s, (b.min(f64::from(s) + 1.0) - a.max(f64::from(s))) / scale))
        .filter(|&(_, w)| w > 0.0)
        .collect()
}

/// Frame-compatible half side by side (HDMI 1.4a's "Side-by-Side (Half)", what 3D TVs and
/// projectors and Bino call half-width side by side): in a frame of one eye's size W×H, each
/// view squeezed to `⌊W/2⌋` columns, left view on the left. Squeezing is a box filter in linear
/// light (pixels `2i` and `2i + 1` averaged; an odd W averages each `W/⌊W/2⌋`-pixel footprint,
/// partial pixels weighted, and leaves the last column black).
///
/// # Errors
/// Different sizes.
pub fn half_side_by_side(left: &Framebuffer, right: &Framebuffer) -> Result<RgbaImage> {
    same_size(left, right)?;
    let (w, h) = (left.width, left.height);
    let half = w / 2;
    let mut out = RgbaImage::from_pixel(w, h, Rgba([0, 0, 0, 255]));
    if half == 0 {
        return Ok(out);
    }
    let spans: Vec<Vec<(u32, f64)>> = (0..half).map(|i| footprint(i, half, w)).collect();
    for (fb, x0) in [(left, 0), (right, half)] {
        for y in 0..h {
            for (i, span) in spans.iter().enumerate() {
                let samples: Vec<_> = span.iter().map(|&(x, wt)| (fb.pixel(x, y), wt)).collect();
                out.put_pixel(x0 + i as u32, y, Rgba(box_filter_linear(&samples)));
            }
        }
    }
    Ok(out)
}

/// Frame-compatible half above-below (HDMI 1.4a's "Top-and-Bottom"): in a frame of one eye's
/// size W×H, each view squeezed to `⌊H/2⌋` rows, left view on top. Squeezing is
/// [`half_side_by_side`]'s box filter in linear light, along columns (rows `2j` and `2j + 1`
/// averaged).
///
/// # Errors
/// Different sizes.
pub fn half_above_below(left: &Framebuffer, right: &Framebuffer) -> Result<RgbaImage> {
    same_size(left, right)?;
    let (w, h) = (left.width, left.height);
    let half = h / 2;
    let mut out = RgbaImage::from_pixel(w, h, Rgba([0, 0, 0, 255]));
    if half == 0 {
        return Ok(out);
    }
    let spans: Vec<Vec<(u32, f64)>> = (0..half).map(|j| footprint(j, half, h)).collect();
    for (fb, y0) in [(left, 0), (right, half)] {
        for (j, span) in spans.iter().enumerate() {
            for x in 0..w {
                let samples: Vec<_> = span.iter().map(|&(y, wt)| (fb.pixel(x, y), wt)).collect();
                out.put_pixel(x, y0 + j as u32, Rgba(box_filter_linear(&samples)));
            }
        }
    }
    Ok(out)
}

/// The active space of HDMI 1.4a frame packing for views `height` rows tall: the vertical
/// blanking of the 2D timing the packed frame replaces, 45 lines for 1080p (1125 − 1080) and
/// 30 for 720p (750 − 720). Both are `height / 24` (CEA-861's 1080p and 720p timings have
/// 25/24 as many total lines as active ones); other heights, which no HDMI timing has, get the
/// same rule rounded to the nearest line.
pub fn frame_packing_active_space(height: u32) -> u32 {
    (height + 12) / 24
}

/// HDMI 1.4a frame packing (progressive): one frame of W × (2H + active space), the left
/// view's H rows on top, [`frame_packing_active_space`] rows of black, the right view's H rows
/// below; no resampling. 1920×1080 views make the 1920×2205 frame, 1280×720 views 1280×1470.
/// Other sizes are packed by the same rule: a valid picture, but not a timing a TV recognizes.
///
/// # Errors
/// Different sizes.
pub fn frame_packing(left: &Framebuffer, right: &Framebuffer) -> Result<RgbaImage> {
    same_size(left, right)?;
    let (w, h) = (left.width, left.height);
    let gap = frame_packing_active_space(h);
    Ok(RgbaImage::from_fn(w, 2 * h + gap, |x, y| {
        Rgba(if y < h {
            left.pixel(x, y)
        } else if y < h + gap {
            [0, 0, 0, 255]
        } else {
            right.pixel(x, y - h - gap)
        })
    }))
}

#[cfg(test)]
mod view_layout_tests {
    use super::*;

    #[test]
    fn view_grids_are_the_smallest_square_side_wide() {
        for n in 1..=64u32 {
            let (c, r) = view_grid(n);
            // An independent definition: the fewest columns c with c² ≥ n, rows to fill.
            let want_c = (1..).find(|c: &u32| c * c >= n).unwrap();
            assert_eq!((c, r), (want_c, n.div_ceil(want_c)), "{n}");
            assert!(c * r >= n && c * (r - 1) < n, "{n}");
        }
        assert_eq!(view_grid(5), (3, 2));
        assert_eq!(view_grid(9), (3, 3));
    }

    #[test]
    fn lenticular_columns_run_from_the_rightmost_view() {
        let got: Vec<u32> = (0..8).map(|x| lenticular_view(x, 4)).collect();
        assert_eq!(got, [3, 2, 1, 0, 3, 2, 1, 0]);
    }
}
