//! The parallax legend bar, drawn with tiny-skia: the color scale, ticks, and labels in a tiny
//! built-in 3×5 pixel font (tiny-skia draws no text).

use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

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

fn rect(pm: &mut Pixmap, x: f32, y: f32, w: f32, h: f32, rgba: [u8; 4]) {
    if let Some(r) = Rect::from_xywh(x, y, w, h) {
        pm.fill_rect(r, &paint(rgba), Transform::identity(), None);
    }
}

/// Width in pixels of `text` at glyph cell size `s` (3 cells + 1 space per character).
fn text_width(text: &str, s: f32) -> f32 {
    text.chars().count() as f32 * 4.0 * s - s
}

fn draw_text(pm: &mut Pixmap, text: &str, x: f32, y: f32, s: f32, rgba: [u8; 4]) {
    for (k, c) in text.chars().enumerate() {
        let Some(g) = glyph(c) else { continue };
        for (row, bits) in g.iter().enumerate() {
            for (col, bit) in bits.chars().enumerate() {
                if bit == '#' {
                    let gx = x + (k as f32 * 4.0 + col as f32) * s;
                    rect(pm, gx, y + row as f32 * s, s, s, rgba);
                }
            }
        }
    }
}

/// A `width`×[`LEGEND_HEIGHT`] legend for a symmetric scale of ±`scale` pixels: one
/// tiny-skia rectangle per bar column colored by `color_of(parallax)` (so the bar matches the
/// image exactly), a tick at 0, taller ticks at the StereoGraphics guide's ±3% budget when it lies inside the
/// scale, and the end labels in pixels and percent of the width (omitted when too narrow).
///
/// # Errors
/// A zero width.
pub fn draw_legend(width: u32, scale: f64, color_of: &dyn Fn(f64) -> [u8; 4]) -> Result<Pixmap> {
    let mut pm = Pixmap::new(width, LEGEND_HEIGHT)
        .ok_or_else(|| Error::invalid("legend width", width, "must be at least 1 pixel"))?;
    pm.fill(Color::from_rgba8(24, 24, 24, 255));
    let bar_w = width as f32 - 2.0 * MARGIN;
    if bar_w < 2.0 {
        return Ok(pm);
    }
    let x_of = |p: f64| MARGIN + ((p / scale + 1.0) * 0.5) as f32 * bar_w;
    for i in 0..bar_w as u32 {
        let p = ((i as f64 + 0.5) / bar_w as f64 * 2.0 - 1.0) * scale;
        rect(
            &mut pm,
            MARGIN + i as f32,
            BAR_TOP,
            1.0,
            BAR_HEIGHT,
            color_of(p),
        );
    }
    let tick = [200, 200, 200, 255];
    let below_bar = BAR_TOP + BAR_HEIGHT;
    rect(&mut pm, x_of(0.0) - 0.5, below_bar, 1.0, 5.0, tick);
    let budget = PARALLAX_BUDGET_PERCENT as f64 / 100.0 * width as f64;
    if budget < scale {
        for p in [-budget, budget] {
            rect(
                &mut pm,
                x_of(p) - 0.5,
                BAR_TOP - 3.0,
                1.0,
                BAR_HEIGHT + 9.0,
                tick,
            );
        }
    }
    let pct = scale / width as f64 * 100.0;
    let left = format!("-{scale:.1}PX -{pct:.2}%");
    let right = format!("+{scale:.1}PX +{pct:.2}%");
    for s in [2.0, 1.0] {
        let (lw, rw) = (text_width(&left, s), text_width(&right, s));
        if lw + rw + 4.0 * s + text_width("0", s) <= bar_w {
            draw_text(&mut pm, &left, MARGIN, LABEL_TOP, s, tick);
            draw_text(&mut pm, &right, MARGIN + bar_w - rw, LABEL_TOP, s, tick);
            draw_text(&mut pm, "0", x_of(0.0) - 1.5 * s, LABEL_TOP, s, tick);
            break;
        }
    }
    Ok(pm)
}
