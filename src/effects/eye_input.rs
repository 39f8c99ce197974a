//! Checks on the framebuffers a finalize mode reads, so bad input is a clear error, never a
//! panic or a silently wrong image.

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// Checks that `left` and `right` have the same size and color buffers of that size.
///
/// # Errors
/// `Invalid` naming both sizes, or the eye whose color buffer has the wrong length.
pub(crate) fn check_same_size(left: &Framebuffer, right: &Framebuffer) -> Result<()> {
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
    for (name, fb) in [("left", left), ("right", right)] {
        let n = fb.width as usize * fb.height as usize;
        if fb.color.len() != n {
            return Err(Error::invalid(
                format!("{name} eye color"),
                format!("{} pixels", fb.color.len()),
                format!("a {}x{} framebuffer needs {n}", fb.width, fb.height),
            ));
        }
    }
    Ok(())
}

/// Checks that `fb` (called `name` in messages) has a depth buffer of its size whose values are
/// all window depths in [0, 1] (`glDepthRange(0, 1)`): no NaN, no infinity.
///
/// # Errors
/// `Invalid` for a missing or short depth buffer, or naming the first bad pixel and its value.
pub(crate) fn check_depth(name: &str, fb: &Framebuffer) -> Result<()> {
    let n = fb.width as usize * fb.height as usize;
    if fb.depth.len() != n {
        return Err(Error::invalid(
            format!("{name} eye depth"),
            format!("{} values", fb.depth.len()),
            format!(
                "missing depth: a {}x{} framebuffer needs {n} depth values",
                fb.width, fb.height
            ),
        ));
    }
    if let Some(i) = fb.depth.iter().position(|d| !(0.0..=1.0).contains(d)) {
        let (x, y) = (i % fb.width as usize, i / fb.width as usize);
        return Err(Error::invalid(
            format!("{name} eye depth at pixel ({x}, {y})"),
            fb.depth[i],
            "window depth must be a number in [0, 1] (NaN or out of range found)",
        ));
    }
    Ok(())
}
