//! stereolab: a deterministic CPU software rasterizer that teaches, and serves as the reference
//! for, stereoscopic rendering.
//!
//! # Data flow
//!
//! ```text
//! scene.toml ─► Scene ─► Plan ─► passes ─────────────► effects ─────────► output
//!               scene    plan    render (on raster)    anaglyph, remap,   PNG/PPM/GIF files,
//!                                eye, ChromaDepth,     parallax, layouts, the render report
//!                                SIRDS strips          ChromaDepth, SIRDS
//! ```
//!
//! Start with [`Scene::load`], [`Plan::new`], [`render()`] and [`output::write_all`]; a
//! rasterization pass is [`raster::rasterize`] with a [`shade::Shader`]. Every effect is a
//! function of framebuffers, matrices and its own settings (never a `Scene`, `Frame`, `Plan` or
//! `Output`), so each can be called, tested and read on its own.
//!
//! # Layers
//!
//! Modules import lower layers only; `tests/architecture.rs` reads the source and fails on an
//! import that goes up or round in a cycle (`cargo test --test main architecture --
//! --nocapture` prints the graph):
//! [`error`] → [`files`] → [`math`], [`framebuffer`], [`shade`] → [`raster`] → [`effects`] → [`plan`] →
//! [`scene`] → [`fixtures`] → [`render`](mod@render) → [`output`] → [`info`], [`figures`], [`compare`] →
//! `gpu` (feature `gpu`), [`exercise`] → [`grade`], [`bench`](mod@bench) → `viewer` (feature
//! `viewer`: `stereolab view`).
//!
//! The repository's `docs/ARCHITECTURE.md` has the conventions (coordinates, llvmpipe's
//! rasterization rules, determinism), `docs/sources.md` the course's five source documents.
//!
#![doc = include_str!("../../../docs/formulas.md")]
#![warn(missing_docs)]

pub mod effects;
pub mod error;
pub mod files;
pub mod framebuffer;
pub mod math;
pub mod raster;
pub mod reference;
pub mod shade;
pub mod text;

pub use error::{Error, Result};
pub use framebuffer::{EyePair, Framebuffer};
