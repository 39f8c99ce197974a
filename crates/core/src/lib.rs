//! stereolab's teaching core: the stereo rig's matrices, the fixed-point rasterizer that covers
//! the pixels lavapipe covers, the f64 reference the hard cases are measured against, and the
//! effects (anaglyphs, remapping and the visibility check, parallax, layouts, ChromaDepth,
//! SIRDS), each a function of framebuffers, matrices and its own settings.
//!
//! A pass is [`raster::rasterize`] with a [`shade::Shader`] into a [`Framebuffer`], with the
//! matrices of [`math::StereoRig::eyes`]; an effect reads the framebuffers, e.g.
//! [`effects::anaglyph::anaglyph`]. Scene files, the plan and the outputs are the `stereolab`
//! crate's; `examples/` in the repository has small complete programs.
//!
//! Its modules import lower ones only, in the order `tests/architecture.rs` holds.
//!
#![doc = include_str!("../../../docs/formulas.md")]
#![warn(missing_docs)]

pub mod effects;
pub mod error;
pub mod eye;
pub mod files;
pub mod framebuffer;
pub mod math;
pub mod raster;
pub mod reference;
pub mod shade;
pub mod simd;
pub mod text;

pub use error::{Error, Result};
pub use eye::Eye;
pub use framebuffer::{EyePair, Framebuffer};
