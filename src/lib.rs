//! stereolab: a deterministic CPU software rasterizer that teaches, and serves as the reference
//! for, stereoscopic rendering.
//!
//! Data flow (see DESIGN.md): [`scene::Scene`] → [`plan::Plan`] → passes
//! ([`render::render`], built on [`raster::rasterize`]) → [`effects`] → [`output`].
#![warn(missing_docs)]

pub mod bench;
pub mod compare;
pub mod effects;
pub mod error;
pub mod exercise;
pub mod figures;
pub mod framebuffer;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod grade;
pub mod info;
pub mod math;
pub mod output;
pub mod plan;
pub mod raster;
pub mod render;
pub mod scene;
pub mod shade;

pub use error::{Error, Result};
pub use framebuffer::{EyePair, Framebuffer};
