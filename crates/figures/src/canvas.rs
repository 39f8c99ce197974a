//! The drawing kit every figure uses: a white tiny-skia page with lines, arrows, dots, filled
//! shapes, pasted images, and text in the shipped font ([`draw_text_rgba`]); and [`Axes`], a
//! plot frame with tick values, axis labels with units and a legend.

use image::RgbaImage;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

use stereolab_core::{Error, Result, TextAlign, draw_text_rgba, text_width};

/// An RGB color.
pub type Rgb = (u8, u8, u8);

/// Black ink.
pub const INK: Rgb = (0, 0, 0);
/// Gray, for guides and secondary labels.
pub const GRAY: Rgb = (120, 120, 120);
/// The left eye's color in every figure (red, as the left lens of red–cyan glasses).
pub const LEFT: Rgb = (210, 40, 40);
/// The right eye's color in every figure (cyan-blue).
pub const RIGHT: Rgb = (20, 140, 190);
/// Label size in pixels.
pub const LABEL: f32 = 15.0;
/// Small label size (tick values).
pub const SMALL: f32 = 13.0;

fn paint(rgb: Rgb, alpha: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb.0, rgb.1, rgb.2, alpha);
    p.anti_alias = true;
    p
}

/// A figure being drawn: a white page `width`×`height` pixels.
pub struct Canvas {
    pm: Pixmap,
}

impl Canvas {
    /// A white page.
    ///
    /// # Errors
    /// A zero or huge size.
    pub fn new(width: u32, height: u32) -> Result<Canvas> {
        if width > 4096 || height > 4096 {
            return Err(Error::invalid(
                "figure size",
                format!("{width}x{height}"),
                "must be at most 4096x4096",
            ));
        }
        let mut pm = Pixmap::new(width, height).ok_or_else(|| {
            Error::invalid("figure size", format!("{width}x{height}"), "must be > 0")
        })?;
        pm.fill(tiny_skia::Color::WHITE);
        Ok(Canvas { pm })
    }

    /// Width in pixels.
    pub fn width(&self) -> f32 {
        self.pm.width() as f32
    }

    /// Height in pixels.
    pub fn height(&self) -> f32 {
        self.pm.height() as f32
    }

    fn stroke(&mut self, pb: PathBuilder, rgb: Rgb, width: f32, dash: bool) {
        if let Some(path) = pb.finish() {
            let stroke = Stroke {
                width,
                dash: if dash {
                    StrokeDash::new(vec![6.0, 4.0], 0.0)
                } else {
                    None
                },
                ..Stroke::default()
            };
            self.pm.stroke_path(
                &path,
                &paint(rgb, 255),
                &stroke,
                Transform::identity(),
                None,
            );
        }
    }

    /// A straight line.
    pub fn line(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb, width: f32) {
        self.polyline(&[a, b], rgb, width);
    }

    /// A dashed straight line.
    pub fn dashed(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb, width: f32) {
        let mut pb = PathBuilder::new();
        pb.move_to(a.0, a.1);
        pb.line_to(b.0, b.1);
        self.stroke(pb, rgb, width, true);
    }

    /// A polyline through `points`.
    pub fn polyline(&mut self, points: &[(f32, f32)], rgb: Rgb, width: f32) {
        let pb = path_through(points);
        self.stroke(pb, rgb, width, false);
    }

    /// A line from `a` to `b` with an arrow head at `b`.
    pub fn arrow(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb, width: f32) {
        self.line(a, b, rgb, width);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let len = (dx * dx + dy * dy).sqrt().max(1e-6);
        let (ux, uy) = (dx / len, dy / len);
        let head = 4.0 + 2.5 * width;
        let l = (b.0 - head * (ux - 0.5 * uy), b.1 - head * (uy + 0.5 * ux));
        let r = (b.0 - head * (ux + 0.5 * uy), b.1 - head * (uy - 0.5 * ux));
        self.fill_polygon(&[b, l, r], rgb, 255);
    }

    /// A double-headed arrow (a dimension line).
    pub fn dimension(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb) {
        let mid = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
        self.arrow(mid, a, rgb, 1.0);
        self.arrow(mid, b, rgb, 1.0);
    }

    /// A filled circle.
    pub fn dot(&mut self, c: (f32, f32), r: f32, rgb: Rgb) {
        if let Some(path) = PathBuilder::from_circle(c.0, c.1, r) {
            self.pm.fill_path(
                &path,
                &paint(rgb, 255),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    /// A circle outline.
    pub fn circle(&mut self, c: (f32, f32), r: f32, rgb: Rgb, width: f32) {
        if let Some(path) = PathBuilder::from_circle(c.0, c.1, r) {
            self.pm.stroke_path(
                &path,
                &paint(rgb, 255),
                &Stroke {
                    width,
                    ..Stroke::default()
                },
                Transform::identity(),
                None,
            );
        }
    }

    /// A filled polygon, `alpha` 0..255.
    pub fn fill_polygon(&mut self, points: &[(f32, f32)], rgb: Rgb, alpha: u8) {
        let mut pb = path_through(points);
        pb.close();
        if let Some(path) = pb.finish() {
            self.pm.fill_path(
                &path,
                &paint(rgb, alpha),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    /// A filled axis-aligned rectangle between corners `a` and `b`.
    pub fn fill_rect(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb, alpha: u8) {
        if let Some(rect) = Rect::from_ltrb(a.0.min(b.0), a.1.min(b.1), a.0.max(b.0), a.1.max(b.1))
        {
            self.pm
                .fill_rect(rect, &paint(rgb, alpha), Transform::identity(), None);
        }
    }

    /// A rectangle outline.
    pub fn rect(&mut self, a: (f32, f32), b: (f32, f32), rgb: Rgb, width: f32) {
        self.polyline(&[a, (b.0, a.1), b, (a.0, b.1), a], rgb, width);
    }

    /// Pastes `img` with its top-left corner at `(x, y)`, each pixel `scale`×`scale` (nearest:
    /// a rendered image's pixels stay visible as pixels).
    pub fn image(&mut self, img: &RgbaImage, x: u32, y: u32, scale: u32) {
        let (w, h) = (self.pm.width(), self.pm.height());
        let data = self.pm.data_mut();
        for (ix, iy, p) in img.enumerate_pixels() {
            let a = f32::from(p[3]) / 255.0;
            for sy in 0..scale {
                for sx in 0..scale {
                    let (px, py) = (x + ix * scale + sx, y + iy * scale + sy);
                    if px < w && py < h {
                        let i = 4 * (py as usize * w as usize + px as usize);
                        for k in 0..3 {
                            let v = f32::from(p[k]) * a + f32::from(data[i + k]) * (1.0 - a);
                            data[i + k] = v.round() as u8;
                        }
                        data[i + 3] = 255;
                    }
                }
            }
        }
    }

    /// A label: `(x, y)` is the top of the text, aligned by `align`.
    pub fn text(&mut self, x: f32, y: f32, size: f32, s: &str, rgb: Rgb, align: TextAlign) {
        let w = text_width(s, size);
        let x = match align {
            TextAlign::Left => x,
            TextAlign::Center => x - w / 2.0,
            TextAlign::Right => x - w,
        };
        let (pw, ph) = (self.pm.width(), self.pm.height());
        draw_text_rgba(
            self.pm.data_mut(),
            pw,
            ph,
            x,
            y,
            size,
            s,
            [rgb.0, rgb.1, rgb.2],
            false,
        );
    }

    /// A label on a white box (readable over lines and images).
    pub fn boxed_text(&mut self, x: f32, y: f32, size: f32, s: &str, rgb: Rgb, align: TextAlign) {
        let w = text_width(s, size);
        let x0 = match align {
            TextAlign::Left => x,
            TextAlign::Center => x - w / 2.0,
            TextAlign::Right => x - w,
        };
        self.fill_rect(
            (x0 - 3.0, y - 1.0),
            (x0 + w + 3.0, y + size * 1.25),
            (255, 255, 255),
            235,
        );
        self.text(x0, y, size, s, rgb, TextAlign::Left);
    }

    /// A label reading bottom to top, centered vertically on `y`, its left edge at `x`.
    pub fn vertical_text(&mut self, x: f32, y: f32, size: f32, s: &str, rgb: Rgb) {
        let w = text_width(s, size);
        let (pw, ph) = (self.pm.width(), self.pm.height());
        draw_text_rgba(
            self.pm.data_mut(),
            pw,
            ph,
            x,
            y - w / 2.0,
            size,
            s,
            [rgb.0, rgb.1, rgb.2],
            true,
        );
    }

    /// The figure as PNG bytes: opaque RGB, best compression with adaptive filters (the
    /// figures live in the repository, so a smaller file is worth the encoder's time;
    /// deterministic, byte for byte).
    ///
    /// # Errors
    /// The encoder fails (a bug).
    pub fn png(&self) -> Result<Vec<u8>> {
        use image::ImageEncoder;
        use image::codecs::png::{CompressionType, FilterType, PngEncoder};
        let rgb: Vec<u8> = self
            .pm
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        let mut out = Vec::new();
        PngEncoder::new_with_quality(&mut out, CompressionType::Best, FilterType::Adaptive)
            .write_image(
                &rgb,
                self.pm.width(),
                self.pm.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(|e| Error::internal("figure PNG", e.to_string()))?;
        Ok(out)
    }

    /// The page as an RGBA image (the tests read figures back this way).
    pub fn to_image(&self) -> RgbaImage {
        RgbaImage::from_raw(self.pm.width(), self.pm.height(), self.pm.data().to_vec())
            .unwrap_or_default()
    }
}

/// A "nice" tick step (1, 2 or 5 × 10ⁿ) giving about `target` ticks over `span`.
pub fn nice_step(span: f64, target: f64) -> f64 {
    let raw = (span / target.max(1.0)).abs().max(1e-12);
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let nice = if f < 1.5 {
        1.0
    } else if f < 3.5 {
        2.0
    } else if f < 7.5 {
        5.0
    } else {
        10.0
    };
    nice * mag
}

/// A tick value with as many decimals as the step needs.
pub fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s.trim_start_matches(['-', '0', '.']).is_empty() {
        s[1..].to_string() // "-0.0" → "0.0"
    } else {
        s.replace('-', "−")
    }
}

/// A plot frame: a data rectangle `x` × `y` mapped onto the page box `(left, top, right,
/// bottom)` (pixels), y up.
#[derive(Clone, Copy, Debug)]
pub struct Axes {
    /// Page box of the data area: left, top, right, bottom.
    pub frame: (f32, f32, f32, f32),
    /// Data range along x.
    pub x: (f64, f64),
    /// Data range along y.
    pub y: (f64, f64),
}

impl Axes {
    /// The page point of data point `(x, y)`.
    pub fn px(&self, x: f64, y: f64) -> (f32, f32) {
        let (l, t, r, b) = self.frame;
        (
            l + ((x - self.x.0) / (self.x.1 - self.x.0)) as f32 * (r - l),
            b - ((y - self.y.0) / (self.y.1 - self.y.0)) as f32 * (b - t),
        )
    }

    /// Draws the frame, tick marks with their values (about `ticks` per axis), grid lines,
    /// and the axis labels (give the unit in the label: "eye distance z (world units)").
    pub fn draw(&self, c: &mut Canvas, x_label: &str, y_label: &str, ticks: (f64, f64)) {
        let (l, t, r, b) = self.frame;
        let xs = nice_step(self.x.1 - self.x.0, ticks.0);
        let ys = nice_step(self.y.1 - self.y.0, ticks.1);
        let mut v = (self.x.0 / xs).ceil() * xs;
        while v <= self.x.1 + 1e-9 * xs {
            let (px, _) = self.px(v, self.y.0);
            c.line((px, t), (px, b), (232, 232, 232), 1.0);
            c.line((px, b), (px, b + 5.0), INK, 1.0);
            c.text(
                px,
                b + 7.0,
                SMALL,
                &tick_label(v, xs),
                INK,
                TextAlign::Center,
            );
            v += xs;
        }
        let mut v = (self.y.0 / ys).ceil() * ys;
        while v <= self.y.1 + 1e-9 * ys {
            let (_, py) = self.px(self.x.0, v);
            c.line((l, py), (r, py), (232, 232, 232), 1.0);
            c.line((l - 5.0, py), (l, py), INK, 1.0);
            c.text(
                l - 8.0,
                py - SMALL * 0.6,
                SMALL,
                &tick_label(v, ys),
                INK,
                TextAlign::Right,
            );
            v += ys;
        }
        c.rect((l, t), (r, b), INK, 1.0);
        c.text(
            (l + r) / 2.0,
            b + 26.0,
            LABEL,
            x_label,
            INK,
            TextAlign::Center,
        );
        let widest_tick = [self.y.0, self.y.1]
            .iter()
            .map(|v| text_width(&tick_label(*v, ys), SMALL))
            .fold(0.0, f32::max);
        c.vertical_text(
            l - 14.0 - widest_tick - LABEL * 1.2,
            (t + b) / 2.0,
            LABEL,
            y_label,
            INK,
        );
    }

    /// A curve through data points, clipped to the y range.
    pub fn curve(&self, c: &mut Canvas, points: &[(f64, f64)], rgb: Rgb, width: f32) {
        let pts: Vec<(f32, f32)> = points
            .iter()
            .map(|&(x, y)| self.px(x, y.clamp(self.y.0, self.y.1)))
            .collect();
        c.polyline(&pts, rgb, width);
    }

    /// A legend box in the data area's corner (`top_right` or top left): a colored line and
    /// a label per entry.
    pub fn legend(&self, c: &mut Canvas, entries: &[(&str, Rgb)], top_right: bool) {
        let (l, t, r, _) = self.frame;
        let w = entries
            .iter()
            .map(|(s, _)| text_width(s, SMALL))
            .fold(0.0, f32::max)
            + 40.0;
        let h = entries.len() as f32 * (SMALL + 6.0) + 8.0;
        let x0 = if top_right { r - w - 8.0 } else { l + 8.0 };
        let y0 = t + 8.0;
        c.fill_rect((x0, y0), (x0 + w, y0 + h), (255, 255, 255), 240);
        c.rect((x0, y0), (x0 + w, y0 + h), GRAY, 1.0);
        for (i, (s, rgb)) in entries.iter().enumerate() {
            let y = y0 + 6.0 + i as f32 * (SMALL + 6.0);
            c.line(
                (x0 + 6.0, y + SMALL * 0.6),
                (x0 + 28.0, y + SMALL * 0.6),
                *rgb,
                2.5,
            );
            c.text(x0 + 34.0, y, SMALL, s, INK, TextAlign::Left);
        }
    }
}

/// A path from the first point through the others in order (open; close it to fill).
fn path_through(points: &[(f32, f32)]) -> PathBuilder {
    let mut pb = PathBuilder::new();
    for (i, &(x, y)) in points.iter().enumerate() {
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    pb
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(1.0, 5.0), 0.2);
        assert_eq!(nice_step(37.0, 5.0), 5.0);
        assert_eq!(tick_label(-0.0001, 0.5), "0.0");
        assert_eq!(tick_label(-3.0, 1.0), "−3");
        assert_eq!(tick_label(2.5, 0.5), "2.5");
    }

    #[test]
    fn axes_map_the_data_corners_onto_the_frame() {
        let a = Axes {
            frame: (50.0, 10.0, 250.0, 110.0),
            x: (1.0, 3.0),
            y: (-2.0, 2.0),
        };
        assert_eq!(a.px(1.0, -2.0), (50.0, 110.0));
        assert_eq!(a.px(3.0, 2.0), (250.0, 10.0));
        assert_eq!(a.px(2.0, 0.0), (150.0, 60.0));
    }
}
