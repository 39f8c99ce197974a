//! The check on the framebuffers a finalize mode reads: that the two eyes match. Each
//! framebuffer is valid on its own by construction (its size, its buffers' lengths, its depths
//! in [0, 1]: [`Framebuffer`]); a pair of them can still differ in size.

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// Checks that `left` and `right` have the same size.
///
/// # Errors
/// `Invalid` naming both sizes.
pub fn check_same_size(left: &Framebuffer, right: &Framebuffer) -> Result<()> {
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
