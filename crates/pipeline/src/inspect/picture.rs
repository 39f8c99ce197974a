//! The picture beside `inspect`'s report: the left view with the findings drawn on it, and the
//! disparity map with its legend.

use image::{Rgba, RgbaImage};
use stereolab_core::{Error, Result};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

use super::{Finding, Measured, VerticalSample, disparity_image, window_violations};

/// How many times the vertical disparity's arrows are drawn longer than they are.
pub const VERTICAL_GAIN: f64 = 10.0;

/// `inspect.png`: on the left, the left view dimmed, each matched block's vertical disparity as
/// a cyan arrow [`VERTICAL_GAIN`] times its length (a keystone fans out toward the corners, a
/// rotation turns at the sides), yellow arrows at the edge rows with a window violation, and the
/// findings' names below; on the right, [`disparity_image`] with its legend.
///
/// # Errors
/// A view too small for the legend, or a picture that cannot be drawn.
pub fn findings_picture(
    left: &RgbaImage,
    m: &Measured,
    samples: &[VerticalSample],
    findings: &[Finding],
) -> Result<RgbaImage> {
    let (w, h) = left.dimensions();
    let map = disparity_image(m)?;
    // The map is at the matching scale: bring it to the view's width.
    let map = if map.width() == w {
        map
    } else {
        let mh = (f64::from(map.height()) * f64::from(w) / f64::from(map.width())).round() as u32;
        image::imageops::resize(&map, w, mh.max(1), image::imageops::FilterType::Nearest)
    };
    let mut pixmap = Pixmap::new(w, h).ok_or_else(|| Error::internal("inspect", "empty view"))?;
    for (p, q) in pixmap.pixels_mut().iter_mut().zip(left.pixels()) {
        // Dimmed halfway toward black, so the arrows stand out.
        let c = q.0.map(|v| v / 2);
        *p = tiny_skia::ColorU8::from_rgba(c[0], c[1], c[2], 255).premultiply();
    }
    let paint = |rgb: [u8; 3]| {
        let mut p = Paint::default();
        p.set_color(Color::from_rgba8(rgb[0], rgb[1], rgb[2], 255));
        p.anti_alias = true;
        p
    };
    let stroke = Stroke {
        width: (w.max(h) as f32 / 400.0).max(1.0),
        ..Stroke::default()
    };
    let arrow = |pixmap: &mut Pixmap, from: (f32, f32), to: (f32, f32), rgb: [u8; 3]| {
        let mut pb = PathBuilder::new();
        pb.move_to(from.0, from.1);
        pb.line_to(to.0, to.1);
        if let Some(path) = pb.finish() {
            pixmap.stroke_path(&path, &paint(rgb), &stroke, Transform::identity(), None);
        }
        // The head: a triangle at `to`.
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        let len = (dx * dx + dy * dy).sqrt();
        if len > 1.0 {
            let head = (3.0 * stroke.width).min(len / 2.0);
            let (ux, uy) = (dx / len, dy / len);
            let mut pb = PathBuilder::new();
            pb.move_to(to.0, to.1);
            pb.line_to(to.0 - head * (ux - uy * 0.6), to.1 - head * (uy + ux * 0.6));
            pb.line_to(to.0 - head * (ux + uy * 0.6), to.1 - head * (uy - ux * 0.6));
            pb.close();
            if let Some(path) = pb.finish() {
                pixmap.fill_path(
                    &path,
                    &paint(rgb),
                    FillRule::Winding,
                    Transform::identity(),
                    None,
                );
            }
        }
    };
    for s in samples {
        let (x, y) = (s.x as f32, s.y as f32);
        arrow(
            &mut pixmap,
            (x, y),
            (x, y + (s.v * VERTICAL_GAIN) as f32),
            [0, 220, 255],
        );
    }
    // Window violations: one arrow toward the edge at the middle of each run of rows.
    let (lv, rv) = window_violations(m);
    let len = (w as f32 / 12.0).max(8.0);
    for (rows, at_left) in [(&lv, true), (&rv, false)] {
        for run in runs(rows) {
            let y = (run.0 + run.1) as f32 / 2.0 * m.scale as f32 + m.scale as f32 / 2.0;
            let (from, to) = if at_left {
                ((len + 2.0, y), (2.0, y))
            } else {
                ((w as f32 - len - 2.0, y), (w as f32 - 2.0, y))
            };
            arrow(&mut pixmap, from, to, [255, 230, 0]);
        }
    }
    let view = RgbaImage::from_fn(w, h, |x, y| {
        let c = pixmap.pixel(x, y).map(|p| p.demultiply());
        c.map_or(Rgba([0, 0, 0, 255]), |c| {
            Rgba([c.red(), c.green(), c.blue(), 255])
        })
    });
    // The findings below the view, one caption.
    let names: Vec<&str> = findings.iter().map(|f| f.name).collect();
    let text = if names.is_empty() {
        "no finding".to_string()
    } else {
        format!("findings: {}", names.join(", "))
    };
    let band_h = (h / 12).clamp(16, 40);
    let band = stereolab_core::caption(w, band_h, &text, band_h as f32 * 0.6, [32, 32, 32]);
    let total_h = (h + band_h).max(map.height());
    let mut out = RgbaImage::from_pixel(2 * w + 8, total_h, Rgba([24, 24, 24, 255]));
    image::imageops::replace(&mut out, &view, 0, 0);
    image::imageops::replace(&mut out, &band, 0, i64::from(h));
    image::imageops::replace(&mut out, &map, i64::from(w) + 8, 0);
    Ok(out)
}

/// Runs of nearly consecutive numbers (gaps of up to 8) in a sorted list, as `(first, last)`.
fn runs(rows: &[u32]) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = Vec::new();
    for &r in rows {
        match out.last_mut() {
            Some(last) if r <= last.1 + 8 => last.1 = r,
            _ => out.push((r, r)),
        }
    }
    out
}
