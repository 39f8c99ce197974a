//! Text in pictures: labels drawn with the font stereolab ships (`assets/fonts/DejaVuSans.ttf`,
//! DejaVu Sans, under the Bitstream Vera licence in `assets/fonts/LICENSE-DejaVu.txt`).
//!
//! Each glyph's outline is rasterized by `ab_glyph` into coverage values in [0, 1], and each
//! covered pixel is blended towards the text color by its coverage. Deterministic: the same
//! text gives the same bytes on every machine (the font is compiled in, no system fonts).

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use image::{Rgba, RgbaImage};

/// The shipped font, compiled in.
const FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn font() -> FontRef<'static> {
    // The bytes are a constant checked by the tests: parsing cannot fail at run time.
    FontRef::try_from_slice(FONT).expect("the shipped font parses")
}

/// The width in pixels of `text` at `size` pixels (the font's em height).
pub fn width(text: &str, size: f32) -> f32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            w += scaled.kern(p, id);
        }
        w += scaled.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Draws `text` with its top-left corner at `(x, y)`, `size` pixels high, in `color`, onto
/// `img` (pixels outside the image are skipped).
pub fn draw(img: &mut RgbaImage, x: f32, y: f32, size: f32, text: &str, color: [u8; 3]) {
    let (w, h) = img.dimensions();
    draw_rgba(img.as_mut(), w, h, x, y, size, text, color, false);
}

/// How a label sits on its point: by its left edge, its center or its right edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    /// The point is the label's left edge.
    Left,
    /// The point is the label's horizontal center.
    Center,
    /// The point is the label's right edge.
    Right,
}

/// Draws `text` onto an opaque RGBA8 buffer of `width`×`height` pixels (row-major, 4 bytes a
/// pixel; a tiny-skia `Pixmap`'s data is one when every pixel is opaque, as a figure's white
/// page is). `(x, y)` is the top-left corner of the text box; with `vertical` the text reads
/// bottom to top (a y-axis label) and `(x, y)` is the top-left corner of the rotated box, which
/// is `size · 1.2` wide and [`width`] high.
#[allow(clippy::too_many_arguments)]
pub fn draw_rgba(
    buf: &mut [u8],
    width: u32,
    height: u32,
    x: f32,
    y: f32,
    size: f32,
    text: &str,
    color: [u8; 3],
    vertical: bool,
) {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size));
    // Glyphs are laid out from (0, 0) and mapped onto the buffer by `place`: unrotated, or
    // turned a quarter counter-clockwise (text x runs up the page).
    let run = self::width(text, size);
    let place = |gx: i64, gy: i64| -> (i64, i64) {
        if vertical {
            (
                x.round() as i64 + gy,
                y.round() as i64 + run.ceil() as i64 - gx,
            )
        } else {
            (x.round() as i64 + gx, y.round() as i64 + gy)
        }
    };
    let baseline = scaled.ascent();
    let mut caret = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            caret += scaled.kern(p, id);
        }
        let glyph =
            id.with_scale_and_position(PxScale::from(size), ab_glyph::point(caret, baseline));
        caret += scaled.h_advance(id);
        prev = Some(id);
        let Some(outlined) = font.outline_glyph(glyph) else {
            continue; // a space
        };
        let bounds = outlined.px_bounds();
        outlined.draw(|gx, gy, coverage| {
            let (px, py) = place(
                bounds.min.x as i64 + i64::from(gx),
                bounds.min.y as i64 + i64::from(gy),
            );
            let (Ok(px), Ok(py)) = (u32::try_from(px), u32::try_from(py)) else {
                return;
            };
            if px >= width || py >= height {
                return;
            }
            let a = coverage.clamp(0.0, 1.0);
            let i = 4 * (py as usize * width as usize + px as usize);
            let Some(p) = buf.get_mut(i..i + 4) else {
                return;
            };
            for k in 0..3 {
                let v = f32::from(p[k]) * (1.0 - a) + f32::from(color[k]) * a;
                p[k] = v.round() as u8;
            }
            p[3] = 255;
        });
    }
}

/// A band `height` pixels high and `width` wide, filled with `background`, with `text` centered
/// in it at `size` pixels: a caption above a picture.
pub fn caption(width: u32, height: u32, text: &str, size: f32, background: [u8; 3]) -> RgbaImage {
    let [r, g, b] = background;
    let mut band = RgbaImage::from_pixel(width, height, Rgba([r, g, b, 255]));
    let w = self::width(text, size);
    let x = ((width as f32 - w) / 2.0).max(2.0);
    let y = (height as f32 - size) / 2.0;
    let luma = 0.299 * f32::from(r) + 0.587 * f32::from(g) + 0.114 * f32::from(b);
    let ink = if luma > 128.0 {
        [0, 0, 0]
    } else {
        [255, 255, 255]
    };
    draw(&mut band, x, y, size, text, ink);
    band
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_draws_ink_inside_its_width_and_nothing_else() {
        let mut img = RgbaImage::from_pixel(200, 40, Rgba([255, 255, 255, 255]));
        let w = width("expected", 20.0);
        assert!(w > 40.0 && w < 150.0, "{w}");
        draw(&mut img, 10.0, 10.0, 20.0, "expected", [0, 0, 0]);
        let inked: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| p[0] < 128)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert!(inked.len() > 50, "{}", inked.len());
        for (x, y) in inked {
            assert!(
                (9..=11 + w as u32).contains(&x) && (10..=32).contains(&y),
                "({x}, {y})"
            );
        }
    }

    #[test]
    fn vertical_text_is_the_horizontal_text_turned_a_quarter() {
        let (size, text) = (16.0, "depth z");
        let w = width(text, size).ceil() as u32;
        let mut flat = vec![255u8; 4 * (w as usize + 4) * 24];
        draw_rgba(&mut flat, w + 4, 24, 0.0, 0.0, size, text, [0, 0, 0], false);
        let mut up = vec![255u8; 4 * 24 * (w as usize + 4)];
        draw_rgba(&mut up, 24, w + 4, 0.0, 0.0, size, text, [0, 0, 0], true);
        let ink = |b: &[u8]| b.chunks(4).filter(|p| p[0] < 128).count();
        assert!(ink(&flat) > 60);
        assert_eq!(ink(&flat), ink(&up));
        // Flat pixel (gx, gy) lands at (gy, w − gx) when turned.
        for gy in 0..24u32 {
            for gx in 0..w {
                let a = flat[4 * (gy * (w + 4) + gx) as usize];
                let b = up[4 * ((w - gx) * 24 + gy) as usize];
                assert_eq!(a, b, "({gx}, {gy})");
            }
        }
    }
}
