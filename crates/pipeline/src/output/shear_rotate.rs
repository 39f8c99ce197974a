//! `shear_vs_rotate`: the SGI course notes' §4.1.3 "Rotate vs. Shear" as one picture and a
//! few measured numbers (the pure pieces are [`vertical_parallax_map`] and
//! [`shear_rotate_difference`]).
//!
//! The picture is a 2 × 2 grid of `W×H` panels, each captioned:
//!
//! ```text
//! off-axis (shear), left eye      | toe-in (rotate), left eye
//! toe-in vertical parallax        | |off-axis − toe-in|, left eye
//! ```

use std::fmt::Write as _;

use image::{RgbaImage, imageops};

use crate::plan::{Output, View};
use crate::render::Frame;
use stereolab_core::{
    Error, Framebuffer, Result, ShearRotateDifference, caption, max_abs_vertical_parallax,
    shear_rotate_difference, vertical_parallax_image, vertical_parallax_map,
};

/// The measured numbers of a shear-vs-rotate comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearVsRotate {
    /// Largest |vertical parallax| of the toe-in pair over the left eye's drawn pixels (px).
    pub rotate_max_vertical: f64,
    /// The same for the off-axis pair: zero up to rounding (parallel axes).
    pub shear_max_vertical: f64,
    /// Off-axis vs toe-in, left eye.
    pub left: ShearRotateDifference,
    /// Off-axis vs toe-in, right eye.
    pub right: ShearRotateDifference,
    /// Image height (for the percentages).
    pub height: u32,
}

impl ShearVsRotate {
    /// The lines of the render report.
    pub fn report(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "  shear vs rotate (the SGI course notes §4.1.3): toe-in vertical parallax up to \
             {:.3} px ({:.3}% of height), off-axis {:.2e} px",
            self.rotate_max_vertical,
            self.rotate_max_vertical / self.height as f64 * 100.0,
            self.shear_max_vertical
        );
        let _ = writeln!(
            s,
            "    pixels differing between off-axis and toe-in: left eye {:.2}% ({} of {}, \
             largest channel difference {}), right eye {:.2}% ({} of {}, {})",
            self.left.share() * 100.0,
            self.left.differing,
            self.left.pixels,
            self.left.max_channel,
            self.right.share() * 100.0,
            self.right.differing,
            self.right.pixels,
            self.right.max_channel
        );
        s
    }
}

fn pass(frame: &Frame, view: View) -> Result<&Framebuffer> {
    frame.view(view).ok_or_else(|| {
        Error::internal(
            "plan",
            format!(
                "{}: the {view:?} pass was not run",
                Output::ShearVsRotate.name()
            ),
        )
    })
}

fn mvp(frame: &Frame, view: View) -> Result<glam::Mat4> {
    frame.try_matrices(view).map(|m| m.mvp).ok_or_else(|| {
        Error::internal(
            "plan",
            format!("{}: no matrices for {view:?}", Output::ShearVsRotate.name()),
        )
    })
}

/// The picture and the numbers, from a frame whose plan ran the four shear/rotate passes.
///
/// # Errors
/// A missing pass (a plan bug) or a singular eye matrix.
pub fn shear_vs_rotate(frame: &Frame) -> Result<(RgbaImage, ShearVsRotate)> {
    let shear = [
        pass(frame, View::ShearLeft)?,
        pass(frame, View::ShearRight)?,
    ];
    let rotate = [
        pass(frame, View::RotateLeft)?,
        pass(frame, View::RotateRight)?,
    ];
    let (w, h) = (shear[0].width(), shear[0].height());
    let rotate_map = vertical_parallax_map(
        rotate[0],
        &mvp(frame, View::RotateLeft)?,
        &mvp(frame, View::RotateRight)?,
    )?;
    let shear_map = vertical_parallax_map(
        shear[0],
        &mvp(frame, View::ShearLeft)?,
        &mvp(frame, View::ShearRight)?,
    )?;
    let (diff_left, left) = shear_rotate_difference(shear[0], rotate[0])?;
    let (_, right) = shear_rotate_difference(shear[1], rotate[1])?;
    let numbers = ShearVsRotate {
        rotate_max_vertical: max_abs_vertical_parallax(&rotate_map),
        shear_max_vertical: max_abs_vertical_parallax(&shear_map),
        left,
        right,
        height: h,
    };
    let caption_h = (h / 12).clamp(14, 40);
    let size = caption_h as f32 * 0.6;
    let panels = [
        (
            shear[0].to_rgba_image(),
            "off-axis (shear), left eye".to_string(),
        ),
        (
            rotate[0].to_rgba_image(),
            "toe-in (rotate), left eye".to_string(),
        ),
        (
            vertical_parallax_image(&rotate_map, w, h),
            format!(
                "toe-in vertical parallax, max {:.2} px",
                numbers.rotate_max_vertical
            ),
        ),
        (
            diff_left,
            format!(
                "|off-axis - toe-in|, {:.1}% differ",
                numbers.left.share() * 100.0
            ),
        ),
    ];
    let mut out = RgbaImage::new(2 * w, 2 * (h + caption_h));
    for (i, (img, label)) in panels.iter().enumerate() {
        let (x, y) = ((i as u32 % 2) * w, (i as u32 / 2) * (h + caption_h));
        let band = caption(w, caption_h, label, size, [255, 255, 255]);
        imageops::replace(&mut out, &band, i64::from(x), i64::from(y));
        imageops::replace(&mut out, img, i64::from(x), i64::from(y + caption_h));
    }
    Ok((out, numbers))
}

/// The render report's shear-vs-rotate lines, when the frame's plan made the output.
///
/// # Errors
/// As [`shear_vs_rotate`].
pub fn report(frame: &Frame) -> Result<Option<String>> {
    if !frame.plan.outputs.contains(&Output::ShearVsRotate) {
        return Ok(None);
    }
    Ok(Some(shear_vs_rotate(frame)?.1.report()))
}
