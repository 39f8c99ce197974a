//! Texture-resident frames: when the outputs need only the finalized image, the eye passes
//! draw into textures, the WGSL finalize passes read those textures where they lie (in the same
//! command submission), and only the outputs' color comes back to the host. No eye
//! framebuffer is read back or uploaded again.
//!
//! The route through the host stays for callers that need the eyes there (parity of each
//! pass, `compare`, the reports of `render --backend gpu`): [`GpuRenderer::render`] then
//! [`produce_wgsl`](super::effects::produce_wgsl). Both routes run the same shaders on the same
//! texels (RGBA8 and f32 depth survive the readback and the upload bit for bit), so their
//! images are byte-identical; tests/gpu_finalize.rs holds them equal.

use image::RgbaImage;

use crate::error::{Error, Result};
use crate::plan::{Output, Plan, View};

use super::device::GpuRenderer;
use super::effects::{GpuFinalize, anaglyph_params, remap_params};
use super::raster::{GpuScene, plan_views};
use super::readback::{DepthKind, Target, submit_and_read_colors, submit_and_wait};

/// Whether `output` is made by [`GpuRenderer::render_resident`]: the anaglyphs and the two
/// remaps, whose WGSL passes need nothing from the host but matrices. Occlusion and parallax
/// need host reductions over the eyes (depth extremes, the color scale, the window
/// violations), the layouts and the rest are CPU code: those take the host route.
pub fn is_resident(output: Output) -> bool {
    matches!(
        output,
        Output::Anaglyph(_) | Output::RemapLeft | Output::RemapRight
    )
}

impl GpuRenderer {
    /// One frame of `outputs` (each [`is_resident`]) without the eyes leaving the GPU: the
    /// plan's scene passes into textures, one WGSL finalize pass per output reading them, one
    /// submission, and one readback of the outputs' color only. The images, in `outputs`'
    /// order, are byte for byte those of [`GpuRenderer::render`] followed by
    /// [`produce_wgsl`](super::effects::produce_wgsl).
    ///
    /// # Errors
    /// An output that is not [`is_resident`], an invalid camera, rig or eye matrix, or a GPU
    /// failure.
    pub fn render_resident(
        &self,
        scene: &GpuScene,
        fin: &GpuFinalize,
        outputs: &[Output],
    ) -> Result<Vec<RgbaImage>> {
        if let Some(o) = outputs.iter().find(|o| !is_resident(**o)) {
            return Err(Error::invalid(
                "gpu resident output",
                o.name(),
                "needs the eye framebuffers on the host: render it with GpuRenderer::render \
                 and gpu::effects::produce_wgsl",
            ));
        }
        let s = scene.scene;
        let plan = Plan::new(outputs);
        let planned = plan_views(s, &plan)?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let eyes = self.encode_views(scene, &planned.passes, &mut encoder)?;
        // The eye drawn for `view`, as `Frame::view` finds it (the first pass from that view).
        let eye = |v: View| -> Result<[&wgpu::TextureView; 2]> {
            let i = plan
                .passes
                .iter()
                .position(|p| p.view == v)
                .ok_or_else(|| Error::internal("plan", format!("the {v:?} pass was not run")))?;
            Ok([&eyes[i].color_view, &eyes[i].depth_view])
        };
        let mvps = [&planned.eyes[0].mvp, &planned.eyes[1].mvp];
        let mut images = Vec::with_capacity(outputs.len());
        for o in outputs {
            let target = Target::take(self, s.width, s.height, DepthKind::ColorR32)?;
            match *o {
                Output::Anaglyph(kind) => {
                    let (left, right) = s.finalize.eyes(&View::Left, &View::Right);
                    let params = anaglyph_params(kind);
                    fin.anaglyph_pass(s.finalize).encode(
                        self,
                        &mut encoder,
                        &[eye(*left)?, eye(*right)?],
                        &params,
                        &target,
                    )?;
                }
                Output::RemapLeft | Output::RemapRight => {
                    let (this, other) = if *o == Output::RemapLeft {
                        (0, 1)
                    } else {
                        (1, 0)
                    };
                    let views = [View::Left, View::Right];
                    let params = remap_params(mvps[this], mvps[other], 0.0, (0.0, 1.0))?;
                    fin.remap.encode(
                        self,
                        &mut encoder,
                        &[eye(views[this])?, eye(views[other])?],
                        &params,
                        &target,
                    )?;
                }
                _ => return Err(Error::internal("gpu resident output", o.name())),
            }
            target.encode_color_copy(&mut encoder);
            images.push(target);
        }
        let refs: Vec<&Target> = images.iter().collect();
        let out = submit_and_read_colors(self, encoder, &refs)?;
        Target::give_back(self, eyes.into_iter().chain(images));
        Ok(out)
    }

    /// The scene passes of `plan` into textures, submitted and waited for, with nothing read
    /// back: the floor under any frame of that plan (the bench's bound for
    /// [`GpuRenderer::render_resident`]).
    ///
    /// # Errors
    /// As [`GpuRenderer::render`].
    pub(crate) fn render_without_readback(&self, scene: &GpuScene, plan: &Plan) -> Result<()> {
        let planned = plan_views(scene.scene, plan)?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let eyes = self.encode_views(scene, &planned.passes, &mut encoder)?;
        submit_and_wait(self, encoder)?;
        Target::give_back(self, eyes);
        Ok(())
    }
}
