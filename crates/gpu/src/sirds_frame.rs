//! The GPU strips in use: a scene's SIRDS from a frame's depth pass, the strip-parity row of
//! `compare SCENE`, and the SIRDS paper's Table 1's first row on both paths for `stereolab bench`.

use std::path::Path;

use stereolab::compare::{Comparison, compare, framebuffer_from_image, pictures, write_diff_strip};
use stereolab::output::sirds;
use stereolab::plan::Output;
use stereolab::render::Frame;
use stereolab::scene::Scene;
use stereolab_core::{Result, Sirds, SirdsAlgorithm};

use super::device::GpuRenderer;
use super::sirds::GpuStrips;

/// The scene's SIRDS (output `sirds`) from `frame`'s depth pass, as
/// [`sirds::from_frame`] but with the strips on the GPU.
/// The per-pixel algorithm (TIW: a serial chain of links along each row) has no WGSL mirror and
/// runs on the CPU.
///
/// # Errors
/// As `sirds::from_frame` and [`GpuStrips::run`].
pub fn from_frame(
    r: &GpuRenderer,
    strips: &GpuStrips,
    frame: &Frame,
    scene: &Scene,
) -> Result<Sirds> {
    let s = &scene.sirds;
    sirds::from_frame_with(frame, scene, |g, d| {
        strips.run(
            r,
            g,
            scene.width,
            scene.height,
            d,
            &s.pattern,
            &s.per_vertex,
        )
    })
}

/// Strip parity apart from raster parity: the SIRDS of the CPU frame's own depth pass made by
/// the CPU strips and by the WGSL strips (same [`StripGeometry`](stereolab_core::StripGeometry), same strips), as a row
/// `sirds (wgsl strips)`. Empty unless the plan makes a per-vertex `sirds`.
///
/// # Errors
/// Either path fails, or a strip cannot be written.
pub fn compare_strips(
    r: &GpuRenderer,
    frame: &Frame,
    scene: &Scene,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    if !frame.plan.outputs.contains(&Output::Sirds)
        || scene.sirds.algorithm != SirdsAlgorithm::PerVertex
    {
        return Ok(Vec::new());
    }
    let cpu = sirds::from_frame(frame, scene)?.to_rgba_image();
    let gpu = from_frame(r, &GpuStrips::new(r)?, frame, scene)?.to_rgba_image();
    let (e, a) = (
        framebuffer_from_image(&cpu, scene.background)?,
        framebuffer_from_image(&gpu, scene.background)?,
    );
    let metrics = compare(&e, &a)?;
    let strip = out
        .map(|dir| write_diff_strip(&e, &a, dir, "sirds_wgsl_strips"))
        .transpose()?;
    Ok(vec![Comparison {
        name: "sirds (wgsl strips)".into(),
        metrics,
        has_depth: false,
        strip,
        max_levels_16: None,
        pictures: pictures(&e, &a),
        flip: None,
    }])
}
