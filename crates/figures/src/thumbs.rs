//! Small renders of the course scene for the figures: the real passes and outputs at a small
//! size, and a captioned grid to lay them out.

use image::RgbaImage;

use super::canvas::{Canvas, INK, LABEL};
use stereolab::output::produce;
use stereolab::plan::{Output, Plan};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::{Result, TextAlign};

/// The course scene at `width`×`height`, edited by `edit`, rendered for `outputs`.
///
/// # Errors
/// As [`Scene::set_size`] and [`render`].
pub fn rendered(
    scene: &Scene,
    width: u32,
    height: u32,
    outputs: &[Output],
    edit: impl Fn(&mut Scene),
) -> Result<(Scene, Frame)> {
    let mut s = scene.clone();
    s.set_size(width, height)?;
    edit(&mut s);
    s.outputs = outputs.to_vec();
    let frame = render(&s, &Plan::new(outputs))?;
    Ok((s, frame))
}

/// One output of a rendered frame as 8-bit RGBA (16-bit depth scaled to 8 bits).
///
/// # Errors
/// As [`produce`].
pub fn image_of(output: Output, frame: &Frame, scene: &Scene) -> Result<RgbaImage> {
    Ok(produce(output, frame, scene)?.to_display_rgba())
}

/// Images in a grid of `cols` columns, each with its caption above, on a white page.
///
/// # Errors
/// An empty list or a page too large.
pub fn grid(cells: &[(String, RgbaImage)], cols: usize, scale: u32) -> Result<Canvas> {
    let cols = cols.max(1);
    let rows = cells.len().div_ceil(cols);
    let cw = cells.iter().map(|(_, i)| i.width()).max().unwrap_or(1) * scale;
    let ch = cells.iter().map(|(_, i)| i.height()).max().unwrap_or(1) * scale;
    let (gap, cap) = (12u32, 26u32);
    let w = cols as u32 * (cw + gap) + gap;
    let h = rows as u32 * (ch + cap + gap) + gap;
    let mut c = Canvas::new(w, h)?;
    for (i, (caption, img)) in cells.iter().enumerate() {
        let (col, row) = ((i % cols) as u32, (i / cols) as u32);
        let x = gap + col * (cw + gap);
        let y = gap + row * (ch + cap + gap);
        c.text(
            x as f32 + cw as f32 / 2.0,
            y as f32 + 3.0,
            LABEL,
            caption,
            INK,
            TextAlign::Center,
        );
        c.image(img, x, y + cap, scale);
    }
    Ok(c)
}
