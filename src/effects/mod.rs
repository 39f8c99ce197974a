//! The effects: pure functions of framebuffers, matrices and their own settings types (never a
//! `Scene`, `Frame`, `Plan` or `Output`): anaglyphs, remapping and the visibility check,
//! occlusion, parallax and its budget, layouts, ChromaDepth's ramp, texgen and glasses, and the
//! SIRDS pieces (pattern, disparity, TIW linking, depth maps, decoding).

pub mod anaglyph;
pub mod calibration;
pub mod chromadepth;
pub(crate) mod eye_input;
pub mod frame_sequential;
pub mod ghosting;
pub mod layout;
pub mod legend;
pub mod occlusion;
pub mod parallax;
pub mod rds;
pub mod remap;
pub mod shear_rotate;
pub mod sirds;
