//! The course decks' figures (`slides/`), each drawn by calling the library function the
//! renderer uses — the rig's matrices and frusta, [`ParallaxRig::parallax`], the anaglyph
//! matrices, the remapper, the ChromaDepth texgen, ramp and glasses, the SIRDS disparity
//! models and strip renderer, the rasterizer's fixed-point setup — never a copy of a formula.
//! Labels, tick values, units and legends are drawn in the shipped font ([`caption`](stereolab_core::caption), [`draw_text_rgba`](stereolab_core::draw_text_rgba)).
//!
//! `stereolab figures SCENE --out slides/figures` writes them all; `tests/figures.rs` checks
//! that the committed PNGs are byte for byte what this code draws, and that plotted curves
//! agree with what the renderer measures.
//!
//! [`ParallaxRig::parallax`]: stereolab_core::ParallaxRig::parallax

pub mod bench;
pub mod canvas;
mod chromadepth;
mod finalize;
mod perception;
pub mod plot;
mod raster;
mod rig;
mod sirds;
mod thumbs;

use std::path::{Path, PathBuf};

pub use canvas::{Axes, Canvas};
pub use perception::{parallax_curve, parallax_types_geometry};
pub use rig::vertical_parallax_grid;

use stereolab::scene::Scene;
use stereolab_core::{Error, Result};

/// What a figure is drawn from: the course scene, and measured benchmark rows for the
/// accuracy-against-time plot.
pub struct Context<'a> {
    /// The course scene (`assets/scenes/wuson.toml`): its rig, camera and model.
    pub scene: &'a Scene,
    /// Rows of `stereolab bench --csv` (the committed `slides/data/bench.csv`).
    pub bench: &'a [bench::BenchRow],
}

/// One figure: its file name (without `.png`), the deck it belongs to, and how it is drawn.
pub struct Figure {
    /// File stem, e.g. `parallax_vs_depth`.
    pub name: &'static str,
    /// The deck (topic) that shows it.
    pub deck: &'static str,
    /// Draws it.
    pub draw: fn(&Context) -> Result<Canvas>,
}

/// Every figure of the decks, in deck order.
pub fn all() -> Vec<Figure> {
    let f = |name, deck, draw| Figure { name, deck, draw };
    vec![
        f(
            "parallax_types",
            "01-perception",
            perception::parallax_types,
        ),
        f(
            "vergence_accommodation",
            "01-perception",
            perception::vergence_accommodation,
        ),
        f(
            "parallax_vs_depth",
            "01-perception",
            perception::parallax_vs_depth,
        ),
        f("parallax_map", "01-perception", perception::parallax_map),
        f("rig_off_axis", "02-rig", rig::off_axis),
        f("rig_toe_in", "02-rig", rig::toe_in),
        f("rig_parallel", "02-rig", rig::parallel),
        f("rig_shear_vs_rotate", "02-rig", rig::shear_vs_rotate),
        f(
            "toe_in_vertical_parallax",
            "02-rig",
            rig::toe_in_vertical_parallax,
        ),
        f("eye_buffers", "03-finalize", finalize::eye_buffers),
        f("layouts", "03-finalize", finalize::layouts),
        f("anaglyph_matrices_1", "03-finalize", finalize::anaglyphs_1),
        f("anaglyph_matrices_2", "03-finalize", finalize::anaglyphs_2),
        f("linear_light", "03-finalize", finalize::linear_light),
        f("remap_one_pixel", "04-remap", finalize::remap_one_pixel),
        f("remap_occlusion", "04-remap", finalize::remap_occlusion),
        f("rds_pair", "04-remap", finalize::rds_pair),
        f(
            "chromadepth_texgen",
            "05-chromadepth",
            chromadepth::texgen_top_view,
        ),
        f(
            "chromadepth_ramp",
            "05-chromadepth",
            chromadepth::ramp_against_distance,
        ),
        f(
            "chromadepth_glasses",
            "05-chromadepth",
            chromadepth::glasses_shift,
        ),
        f("chromadepth_views", "05-chromadepth", chromadepth::views),
        f("sirds_linked_pixels", "06-sirds", sirds::linked_pixels),
        f(
            "sirds_disparity_models",
            "06-sirds",
            sirds::disparity_models,
        ),
        f("sirds_passes", "06-sirds", sirds::passes),
        f("sirds_start", "06-sirds", sirds::start),
        f("sirds_filter", "06-sirds", sirds::filter),
        f("raster_top_left", "07-reference", raster::top_left),
        f("bench_accuracy_time", "07-reference", bench::accuracy_time),
    ]
}

/// Draws every figure; returns `(file name, PNG bytes)` in deck order.
///
/// # Errors
/// A figure fails (invalid rig, a render error).
pub fn draw_all(ctx: &Context) -> Result<Vec<(String, Vec<u8>)>> {
    all()
        .into_iter()
        .map(|f| {
            let canvas = (f.draw)(ctx)?;
            Ok((format!("{}.png", f.name), canvas.png()?))
        })
        .collect()
}

/// Draws every figure into `dir`, all of them or none (one [`OutputSet`](stereolab_core::OutputSet)); returns the paths.
///
/// # Errors
/// A figure fails, or the folder cannot be created or written.
pub fn write_all(ctx: &Context, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut set = stereolab_core::OutputSet::new();
    for (name, png) in draw_all(ctx)? {
        set.stage_bytes(&dir.join(name), &png)?;
    }
    set.commit()
}
