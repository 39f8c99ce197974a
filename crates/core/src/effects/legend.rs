//! The parallax legend bar, drawn with tiny-skia: the color scale, ticks, and labels in a tiny
//! built-in 3×5 pixel font (tiny-skia draws no text).

use std::mem::MaybeUninit;
use std::ops::Range;

use tiny_skia::{Color, IntSize, Paint, Pixmap, Rect, Transform};

use super::parallax::PARALLAX_BUDGET_PERCENT;
use crate::error::{Error, Result};

/// Height of the legend strip in pixels.
pub const LEGEND_HEIGHT: u32 = 40;
const MARGIN: f32 = 6.0;
const BAR_TOP: f32 = 4.0;
const BAR_HEIGHT: f32 = 12.0;
const LABEL_TOP: f32 = 26.0;

/// 3×5 glyphs, rows top to bottom, `#` lit.
fn glyph(c: char) -> Option<[&'static str; 5]> {
    Some(match c {
        '0' => ["###", "#.#", "#.#", "#.#", "###"],
        '1' => [".#.", "##.", ".#.", ".#.", "###"],
        '2' => ["###", "..#", "###", "#..", "###"],
        '3' => ["###", "..#", "###", "..#", "###"],
        '4' => ["#.#", "#.#", "###", "..#", "..#"],
        '5' => ["###", "#..", "###", "..#", "###"],
        '6' => ["###", "#..", "###", "#.#", "###"],
        '7' => ["###", "..#", "..#", "..#", "..#"],
        '8' => ["###", "#.#", "###", "#.#", "###"],
        '9' => ["###", "#.#", "###", "..#", "###"],
        '-' => ["...", "...", "###", "...", "..."],
        '+' => ["...", ".#.", "###", ".#.", "..."],
        '.' => ["...", "...", "...", "...", ".#."],
        '%' => ["#.#", "..#", ".#.", "#..", "#.#"],
        'P' => ["###", "#.#", "###", "#..", "#.."],
        'X' => ["#.#", "#.#", ".#.", "#.#", "#.#"],
        ' ' => ["...", "...", "...", "...", "..."],
        _ => return None,
    })
}

fn paint(rgba: [u8; 4]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]));
    p.anti_alias = false;
    p
}

/// One filled rectangle of the legend: x, y, width, height (pixels, fractions allowed) and its
/// color.
type Fill = ([f32; 4], [u8; 4]);

/// Width in pixels of `text` at glyph cell size `s` (3 cells + 1 space per character).
fn text_width(text: &str, s: f32) -> f32 {
    text.chars().count() as f32 * 4.0 * s - s
}

fn draw_text(fills: &mut Vec<Fill>, text: &str, x: f32, y: f32, s: f32, rgba: [u8; 4]) {
    for (k, c) in text.chars().enumerate() {
        let Some(g) = glyph(c) else { continue };
        for (row, bits) in g.iter().enumerate() {
            for (col, bit) in bits.chars().enumerate() {
                if bit == '#' {
                    let gx = x + (k as f32 * 4.0 + col as f32) * s;
                    fills.push(([gx, y + row as f32 * s, s, s], rgba));
                }
            }
        }
    }
}

/// The largest side tiny-skia fills a rectangle on directly (`DrawTiler::MAX_DIMENSIONS`);
/// wider pixmaps go through its tiled path filling.
const TINY_SKIA_TILE: u32 = 8191;

/// The background color of the legend strip.
const LEGEND_BACKGROUND: [u8; 4] = [24, 24, 24, 255];

/// What the legend draws over its background, in order: one rectangle per bar column colored
/// by `color_of(parallax)`, a tick at 0, taller ticks at the StereoGraphics guide's ±3% budget
/// when it lies inside the scale, and the end labels in pixels and percent of the width
/// (omitted when too narrow).
fn legend_fills(width: u32, scale: f64, color_of: &dyn Fn(f64) -> [u8; 4]) -> Vec<Fill> {
    let mut fills = Vec::new();
    let bar_w = width as f32 - 2.0 * MARGIN;
    if bar_w < 2.0 {
        return fills;
    }
    let x_of = |p: f64| MARGIN + ((p / scale + 1.0) * 0.5) as f32 * bar_w;
    for i in 0..bar_w as u32 {
        let p = ((i as f64 + 0.5) / bar_w as f64 * 2.0 - 1.0) * scale;
        fills.push(([MARGIN + i as f32, BAR_TOP, 1.0, BAR_HEIGHT], color_of(p)));
    }
    let tick = [200, 200, 200, 255];
    let below_bar = BAR_TOP + BAR_HEIGHT;
    fills.push(([x_of(0.0) - 0.5, below_bar, 1.0, 5.0], tick));
    let budget = PARALLAX_BUDGET_PERCENT as f64 / 100.0 * width as f64;
    if budget < scale {
        for p in [-budget, budget] {
            fills.push(([x_of(p) - 0.5, BAR_TOP - 3.0, 1.0, BAR_HEIGHT + 9.0], tick));
        }
    }
    let pct = scale / width as f64 * 100.0;
    let left = format!("-{scale:.1}PX -{pct:.2}%");
    let right = format!("+{scale:.1}PX +{pct:.2}%");
    for s in [2.0, 1.0] {
        let (lw, rw) = (text_width(&left, s), text_width(&right, s));
        if lw + rw + 4.0 * s + text_width("0", s) <= bar_w {
            draw_text(&mut fills, &left, MARGIN, LABEL_TOP, s, tick);
            draw_text(&mut fills, &right, MARGIN + bar_w - rw, LABEL_TOP, s, tick);
            draw_text(&mut fills, "0", x_of(0.0) - 1.5 * s, LABEL_TOP, s, tick);
            break;
        }
    }
    fills
}

/// A `width`×[`LEGEND_HEIGHT`] legend for a symmetric scale of ±`scale` pixels: the bar colored
/// by `color_of(parallax)` per column (so the bar matches the image exactly), a tick at 0,
/// taller ticks at the StereoGraphics guide's ±3% budget when it lies inside the scale, and
/// the end labels in pixels and percent of the width (omitted when too narrow).
///
/// The rectangles are written straight into the pixmap as tiny-skia fills them without
/// anti-aliasing (each rounded to whole pixels by [`Rect::round`], clipped, filled with the
/// opaque color), instead of one tiny-skia call per rectangle: each call builds three raster
/// pipelines, and the bar alone is a rectangle per column. [`draw_legend_reference`] draws the
/// same rectangles through tiny-skia; `draw_legend_matches_tiny_skia` holds the two equal.
///
/// # Errors
/// A zero width.
pub fn draw_legend(width: u32, scale: f64, color_of: &dyn Fn(f64) -> [u8; 4]) -> Result<Pixmap> {
    let size = IntSize::from_wh(width, LEGEND_HEIGHT)
        .ok_or_else(|| Error::invalid("legend width", width, "must be at least 1 pixel"))?;
    let n = width as usize * LEGEND_HEIGHT as usize;
    let mut data: Vec<[u8; 4]> = Vec::with_capacity(n);
    draw_legend_into(&mut data.spare_capacity_mut()[..n], width, scale, color_of)?;
    // SAFETY: `draw_legend_into` wrote all n pixels, within the capacity.
    unsafe { data.set_len(n) };
    Ok(Pixmap::from_vec(data.into_flattened(), size).expect("4 bytes per pixel of the size"))
}

/// [`draw_legend`] into `out`, `width` × [`LEGEND_HEIGHT`] pixels (RGBA, rows top to bottom),
/// every one of which it writes: the parallax image draws its legend straight into the rows
/// below the image this way.
///
/// # Errors
/// A zero width; `out` not `width` × [`LEGEND_HEIGHT`] pixels long.
pub(crate) fn draw_legend_into(
    out: &mut [MaybeUninit<[u8; 4]>],
    width: u32,
    scale: f64,
    color_of: &dyn Fn(f64) -> [u8; 4],
) -> Result<()> {
    if width == 0 {
        return Err(Error::invalid(
            "legend width",
            width,
            "must be at least 1 pixel",
        ));
    }
    if out.len() != width as usize * LEGEND_HEIGHT as usize {
        return Err(Error::internal(
            "legend",
            format!(
                "{} pixels to draw a {width}x{LEGEND_HEIGHT} legend into",
                out.len()
            ),
        ));
    }
    let fills = legend_fills(width, scale, color_of);
    if width > TINY_SKIA_TILE || fills.iter().any(|(_, rgba)| rgba[3] != 255) {
        // Translucent colors blend in tiny-skia's pipeline, and beyond its tile size it fills
        // rectangles as paths (other pixels at half-pixel edges): let it draw those.
        let pm = draw_legend_reference(width, scale, color_of)?;
        for (o, px) in out.iter_mut().zip(pm.data().as_chunks::<4>().0) {
            o.write(*px);
        }
        return Ok(());
    }
    for o in out.iter_mut() {
        o.write(LEGEND_BACKGROUND);
    }
    // SAFETY: every element was written just above, and `MaybeUninit<T>` has `T`'s layout.
    let data = unsafe { &mut *(std::ptr::from_mut(out) as *mut [[u8; 4]]) };
    let (w, h) = (width as i64, LEGEND_HEIGHT as i64);
    let w_px = width as usize;
    // A run of rectangles side by side over the same rows (the bar's columns): each is filled
    // in the run's first row, and the run's span is copied to its other rows once it ends.
    // Rectangles of a run cover the same rows and abut, so that gives each row what filling
    // them one by one would.
    type Run = Option<(Range<i64>, Range<usize>)>;
    let mut run: Run = None;
    let copy_down = |data: &mut [[u8; 4]], run: &Run| {
        if let Some((rows, span)) = run {
            let first = rows.start as usize * w_px;
            for y in rows.start + 1..rows.end {
                let row = y as usize * w_px;
                data.copy_within(first + span.start..first + span.end, row + span.start);
            }
        }
    };
    for ([x, y, rw, rh], rgba) in fills {
        let (x0, y0, x1, y1) = if let Some([x, y, rw, rh]) = whole_pixels([x, y, rw, rh]) {
            // What `Rect::round` gives such a rectangle, without its four calls to `floor`.
            (x, y, x + rw, y + rh)
        } else {
            let Some(r) = Rect::from_xywh(x, y, rw, rh).and_then(|r| r.round()) else {
                continue;
            };
            let (x0, y0) = (r.left() as i64, r.top() as i64);
            (x0, y0, x0 + r.width() as i64, y0 + r.height() as i64)
        };
        let (x0, x1) = (x0.clamp(0, w) as usize, x1.clamp(0, w) as usize);
        let (y0, y1) = (y0.clamp(0, h), y1.clamp(0, h));
        let x1 = x1.max(x0);
        match &mut run {
            Some((rows, span)) if *rows == (y0..y1) && span.end == x0 => span.end = x1,
            _ => {
                copy_down(data, &run);
                run = Some((y0..y1, x0..x1));
            }
        }
        if y0 < y1 {
            let row = y0 as usize * w_px;
            data[row + x0..row + x1].fill(rgba);
        }
    }
    copy_down(data, &run);
    Ok(())
}

/// The rectangle `[x, y, w, h]` as whole numbers, where each is one (and the sides at least 1,
/// all within ±2²²): there tiny-skia's rounding (`x + ½` floored, the sides the difference of
/// the edges, at least 1) gives it unchanged. `None` otherwise.
fn whole_pixels(r: [f32; 4]) -> Option<[i64; 4]> {
    const LIMIT: f32 = (1 << 22) as f32;
    let whole = |v: f32| v.abs() <= LIMIT && v == (v as i64) as f32;
    (r.iter().all(|v| whole(*v)) && r[2] >= 1.0 && r[3] >= 1.0).then(|| r.map(|v| v as i64))
}

/// [`draw_legend`] drawn by tiny-skia, one `fill_rect` per rectangle: the reference it is held
/// to.
///
/// # Errors
/// A zero width.
pub fn draw_legend_reference(
    width: u32,
    scale: f64,
    color_of: &dyn Fn(f64) -> [u8; 4],
) -> Result<Pixmap> {
    let mut pm = Pixmap::new(width, LEGEND_HEIGHT)
        .ok_or_else(|| Error::invalid("legend width", width, "must be at least 1 pixel"))?;
    let [r, g, b, a] = LEGEND_BACKGROUND;
    pm.fill(Color::from_rgba8(r, g, b, a));
    for ([x, y, w, h], rgba) in legend_fills(width, scale, color_of) {
        if let Some(r) = Rect::from_xywh(x, y, w, h) {
            pm.fill_rect(r, &paint(rgba), Transform::identity(), None);
        }
    }
    Ok(pm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::parallax::parallax_color;

    /// The direct legend gives tiny-skia's pixels: widths from 1 (no bar) through the label
    /// thresholds to tiny-skia's largest untiled width (8191) and one beyond it (where
    /// `draw_legend` lets tiny-skia draw), scales whose ticks fall inside and outside the bar,
    /// at whole and half pixels.
    #[test]
    fn draw_legend_matches_tiny_skia() {
        let mut cases = 0;
        for width in [
            1, 2, 13, 14, 15, 16, 40, 77, 100, 101, 160, 333, 1024, 1025, 8191, 8200,
        ] {
            for scale in [0.5, 0.75, 3.0, 12.3456, 30.72, 31.0, 99.95, 1e4] {
                let color_of = |p: f64| parallax_color(p, scale);
                let fast = draw_legend(width, scale, &color_of).unwrap();
                let want = draw_legend_reference(width, scale, &color_of).unwrap();
                if let Some(i) = fast
                    .data()
                    .iter()
                    .zip(want.data())
                    .position(|(a, b)| a != b)
                {
                    let px = i / 4;
                    panic!(
                        "width {width}, scale {scale}: pixel ({}, {}) differs",
                        px % width as usize,
                        px / width as usize
                    );
                }
                cases += 1;
            }
        }
        assert_eq!(cases, 16 * 8);
    }

    /// A zero width is an error, not a panic; so is a buffer of another size than the legend's.
    #[test]
    fn draw_legend_rejects_zero_width() {
        assert!(draw_legend(0, 1.0, &|_| [0, 0, 0, 255]).is_err());
        let mut out = vec![MaybeUninit::uninit(); 4 * LEGEND_HEIGHT as usize - 1];
        let err = draw_legend_into(&mut out, 4, 1.0, &|_| [0, 0, 0, 255]).unwrap_err();
        assert!(err.to_string().contains("4x40"), "{err}");
    }
}
