//! Pure functions of framebuffers and the rig: layouts now; anaglyphs, remapping, parallax,
//! ChromaDepth and SIRDS as they land.

pub mod chromadepth;
pub mod layout;
