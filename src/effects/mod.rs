//! Pure functions of framebuffers and the rig: layouts now; anaglyphs, remapping, parallax,
//! ChromaDepth and SIRDS as they land.

pub mod anaglyph;
pub mod chromadepth;
pub(crate) mod eye_input;
pub mod layout;
pub mod legend;
pub mod occlusion;
pub mod parallax;
pub mod remap;
pub mod sirds;
