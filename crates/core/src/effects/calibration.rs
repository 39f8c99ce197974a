//! The above-below calibration screen (the StereoGraphics guide (Akka), §9).
//!
//! Sync-doubling hardware shows the top half of the frame to the left eye and the bottom half to
//! the right eye, each stretched to the full screen. The software must insert a black band as
//! thick as the display's own vertical blank interval between the halves ("20 to 50 invisible"
//! lines; "the newly created blank interval must have a vertical thickness that perfectly
//! matches the original blank interval"), and that thickness varies with the graphics card and
//! mode: "This usually means providing the user with some kind of calibration screen, in which
//! the user lines up two arrows while in stereo mode."
//!
//! This screen lays the frame out exactly as
//! [`above_below_squashed`](super::layout::above_below_squashed) does (`rows = (H − blank)/2` rows per view, left on top, the blank
//! band between) and draws one arrow in the middle row of each view, their tips meeting at the
//! centre column: the left eye's arrow points right, the right eye's points left. With the
//! glasses on, the arrows meet on one line exactly when `layout.blank_interval` matches the
//! display's; otherwise the right eye's arrow appears displaced up or down, and the user
//! changes the blank interval until they line up.

use image::RgbaImage;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Rect, Transform};

use crate::error::{Error, Result};

/// The color of the views (dark gray, so the black blank band stands out).
pub const VIEW_COLOR: [u8; 4] = [64, 64, 64, 255];
/// The blank interval's color: black, as the guide says ("draw it as a black field").
pub const BLANK_COLOR: [u8; 4] = [0, 0, 0, 255];
/// The arrows' color.
pub const ARROW_COLOR: [u8; 4] = [255, 255, 255, 255];

/// Where the calibration screen puts things, in pixels (rows from the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CalibrationLayout {
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Rows of each view, `(H − blank)/2`.
    pub rows: u32,
    /// The blank band: rows `rows .. rows + blank`.
    pub blank: u32,
    /// First row of the bottom (right eye) view, `rows + blank`.
    pub bottom_top: u32,
    /// The arrows' centre line in the top view, `rows/2` (a row boundary: the arrow covers as
    /// many rows above it as below).
    pub top_arrow_y: u32,
    /// The arrows' centre line in the bottom view, `bottom_top + rows/2`.
    pub bottom_arrow_y: u32,
    /// The column where the tips meet, `W/2` (a column boundary).
    pub tip_x: u32,
    /// Arrow length: `W/4`.
    pub length: u32,
    /// Half the height of an arrow head: `max(1, rows/8)`.
    pub head_half: u32,
    /// Half the height of the shaft: `max(1, rows/32)`, at most `head_half`.
    pub shaft_half: u32,
}

impl CalibrationLayout {
    /// The layout of a `width`×`height` frame with a blank band of `blank` rows.
    ///
    /// # Errors
    /// `Invalid` naming `layout.blank_interval` when it leaves fewer than 2 rows per view, or a
    /// frame narrower than 8 pixels (no room for the arrows).
    pub fn new(width: u32, height: u32, blank: u32) -> Result<CalibrationLayout> {
        if u64::from(blank) + 4 > u64::from(height) {
            return Err(Error::invalid(
                "layout.blank_interval",
                blank,
                format!("leaves fewer than 2 rows per view in a {height}-row frame"),
            ));
        }
        if width < 8 {
            return Err(Error::invalid(
                "image.width",
                width,
                "the calibration arrows need at least 8 columns",
            ));
        }
        let rows = (height - blank) / 2;
        let head_half = (rows / 8).max(1);
        Ok(CalibrationLayout {
            width,
            height,
            rows,
            blank,
            bottom_top: rows + blank,
            top_arrow_y: rows / 2,
            bottom_arrow_y: rows + blank + rows / 2,
            tip_x: width / 2,
            length: width / 4,
            head_half,
            shaft_half: (rows / 32).max(1).min(head_half),
        })
    }

    /// The arrow as a polygon (shaft and head, 7 corners) with its centre line at row boundary
    /// `cy`, its tip at column boundary `tip_x`, pointing right (`dir = 1`) or left (`-1`).
    fn arrow(&self, cy: u32, dir: f32) -> [(f32, f32); 7] {
        let (tip, cy) = (self.tip_x as f32, cy as f32);
        let len = self.length as f32;
        let head = (len / 2.0).min(2.0 * self.head_half as f32).max(1.0);
        let (hh, sh) = (self.head_half as f32, self.shaft_half as f32);
        let x = |d: f32| tip - dir * d;
        [
            (x(len), cy - sh),
            (x(head), cy - sh),
            (x(head), cy - hh),
            (tip, cy),
            (x(head), cy + hh),
            (x(head), cy + sh),
            (x(len), cy + sh),
        ]
    }
}

fn paint(rgba: [u8; 4]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
    p.anti_alias = false;
    p
}

/// The calibration screen for a `width`×`height` frame and a blank interval of `blank` rows,
/// drawn with tiny-skia (no antialiasing, so every pixel is one of the three colors).
///
/// # Errors
/// As [`CalibrationLayout::new`].
pub fn calibration_screen(width: u32, height: u32, blank: u32) -> Result<RgbaImage> {
    let l = CalibrationLayout::new(width, height, blank)?;
    let mut pm = Pixmap::new(width, height)
        .ok_or_else(|| Error::internal("calibration", format!("pixmap {width}x{height}")))?;
    pm.fill(tiny_skia::Color::from_rgba8(
        BLANK_COLOR[0],
        BLANK_COLOR[1],
        BLANK_COLOR[2],
        255,
    ));
    for top in [0, l.bottom_top] {
        if let Some(r) = Rect::from_xywh(0.0, top as f32, width as f32, l.rows as f32) {
            pm.fill_rect(r, &paint(VIEW_COLOR), Transform::identity(), None);
        }
    }
    for (cy, dir) in [(l.top_arrow_y, 1.0), (l.bottom_arrow_y, -1.0)] {
        let pts = l.arrow(cy, dir);
        let mut pb = PathBuilder::new();
        pb.move_to(pts[0].0, pts[0].1);
        for p in &pts[1..] {
            pb.line_to(p.0, p.1);
        }
        pb.close();
        if let Some(path) = pb.finish() {
            pm.fill_path(
                &path,
                &paint(ARROW_COLOR),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }
    // Every pixel is opaque, so the premultiplied bytes are the plain RGBA ones.
    let mut img = RgbaImage::from_raw(width, height, pm.take()).expect("4 bytes per pixel");
    let size = (l.rows as f32 / 8.0).clamp(8.0, 16.0);
    if l.rows as f32 >= 4.0 * size {
        crate::text::draw(
            &mut img,
            4.0,
            2.0,
            size,
            &format!("blank interval {blank} rows: line up the arrows"),
            [200, 200, 200],
        );
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_guide_example_puts_the_blank_at_rows_364_to_403() {
        let l = CalibrationLayout::new(1024, 768, 40).unwrap();
        assert_eq!((l.rows, l.bottom_top), (364, 404));
        assert_eq!((l.top_arrow_y, l.bottom_arrow_y), (182, 586));
    }

    #[test]
    fn a_blank_that_leaves_no_view_is_refused() {
        let e = calibration_screen(64, 40, 37).unwrap_err().to_string();
        assert!(e.contains("layout.blank_interval"), "{e}");
    }
}
