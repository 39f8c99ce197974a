//! `stereolab render --backend gpu`: every output of a GPU frame written as PNG, each effect
//! that has a WGSL mirror made on the GPU.

use std::path::{Path, PathBuf};

use stereolab::output::{Image, produce, write_all_with};
use stereolab::plan::Output;
use stereolab::render::Frame;
use stereolab::scene::Scene;
use stereolab_core::Result;

use super::device::GpuRenderer;
use super::sirds::GpuStrips;
use super::sirds_frame::from_frame;

/// Writes every output of `frame` as `DIR/<name>.png` like
/// [`output::write_all`](stereolab::output::write_all), but makes `sirds` with the GPU strips and
/// the anaglyph, remap, occlusion and parallax outputs with their WGSL passes
/// ([`produce_wgsl`](super::effects::produce_wgsl)) (`stereolab render --backend gpu`).
///
/// # Errors
/// The folder cannot be created, or an output fails.
pub fn write_all(
    r: &GpuRenderer,
    frame: &Frame,
    scene: &Scene,
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    let strips = frame
        .plan
        .outputs
        .contains(&Output::Sirds)
        .then(|| GpuStrips::new(r))
        .transpose()?;
    let fin = super::effects::GpuFinalize::new(r)?;
    write_all_with(frame, dir, |o| {
        Ok(match (&strips, o) {
            (Some(strips), Output::Sirds) => {
                Image::Rgba(from_frame(r, strips, frame, scene)?.to_rgba_image())
            }
            _ => match super::effects::produce_wgsl(r, &fin, o, frame, scene)? {
                Some(img) => Image::Rgba(img),
                None => produce(o, frame, scene)?,
            },
        })
    })
}
