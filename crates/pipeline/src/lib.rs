//! stereolab's pipeline: a scene file becomes the images it asks for.
//!
//! ```text
//! scene.toml ─► Scene ─► Plan ─► passes ─────────────► effects ─────────► output
//!               scene    plan    render (on raster)    (stereolab-core)   PNG/PPM/GIF files,
//!                                eye, ChromaDepth,                        the render report
//!                                SIRDS strips
//! ```
//!
//! Start with [`Scene::load`], [`Plan::new`], [`render()`] and [`output::write_all`]. The
//! formulas, the rasterizer and the effects live in `stereolab-core`.
#![warn(missing_docs)]

pub mod compare;
pub mod fixtures;
pub mod info;
pub mod inspect;
pub mod memory;
pub mod output;
pub mod plan;
pub mod render;
pub mod scene;

pub use plan::{Output, Plan};
pub use render::{Frame, render};
pub use scene::Scene;
