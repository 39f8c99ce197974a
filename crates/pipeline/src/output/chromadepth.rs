//! The ChromaDepth outputs from a frame's ChromaDepth pass.

use crate::plan::Output;
use crate::render::Frame;
use stereolab_core::{
    ChromaDepthSettings, ChromaDepthView, Error, Framebuffer, Result, chromadepth_view,
};

/// Produces a ChromaDepth output from the frame's ChromaDepth pass: the image itself, one eye's
/// view through the glasses, or both views as an anaglyph (`chromadepth.anaglyph`, default gray).
///
/// # Errors
/// The frame has no ChromaDepth pass (a plan bug), or `output` is not a ChromaDepth output.
pub fn produce(
    output: Output,
    frame: &Frame,
    settings: &ChromaDepthSettings,
) -> Result<Framebuffer> {
    let fb = frame
        .passes
        .iter()
        .find(|p| Output::ChromaDepth.needs().contains(&p.pass))
        .map(|p| &p.framebuffer)
        .ok_or_else(|| {
            Error::internal(
                "plan",
                format!("{}: the ChromaDepth pass was not run", output.name()),
            )
        })?;
    let view = match output {
        Output::ChromaDepth => ChromaDepthView::Image,
        Output::ChromaDepthLeft => ChromaDepthView::Left,
        Output::ChromaDepthRight => ChromaDepthView::Right,
        Output::ChromaDepthAnaglyph => ChromaDepthView::Anaglyph,
        other => {
            return Err(Error::invalid(
                "output",
                other.name(),
                "is not a ChromaDepth output",
            ));
        }
    };
    chromadepth_view(fb, view, settings)
}
