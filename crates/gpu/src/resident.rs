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

use stereolab::plan::{Output, Plan, Shading, View};
use stereolab::scene::Scene;
use stereolab_core::{AnaglyphKind, AnaglyphOptions, Error, EyeMatrices, Result};

use super::device::GpuRenderer;
use super::effects::{GpuFinalize, anaglyph_params, remap_params};
use super::raster::{Fused, GpuScene, plan_views};
use super::readback::{DepthKind, Target, submit_and_read_colors, submit_and_wait};
use super::resources::{buffer_with, clear_color};

/// Most clear values of fused frames kept ([`GpuRenderer`]'s `fused_clears`).
const MAX_FUSED_CLEARS: usize = 64;

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

/// Whether a frame of `outputs` on `scene` folds the anaglyph into the eye passes
/// ([`GpuRenderer::render_resident`]): the only output is an anaglyph, its plan is the left and
/// then the right eye, both Blinn-Phong, each drawing every column (no image-shift viewport),
/// and the eyes are not swapped. Other anaglyph frames run the full-screen pass over the eye
/// textures.
///
/// # Errors
/// An invalid camera or rig (as the frame itself).
pub fn folds_anaglyph(scene: &Scene, outputs: &[Output]) -> Result<bool> {
    let plan = Plan::new(outputs);
    Ok(matches!(outputs, [Output::Anaglyph(_)])
        && folds(scene, &plan, &plan_views(scene, &plan)?.passes))
}

/// [`folds_anaglyph`] of a frame of `plan` with the scene passes `passes`, its only output an
/// anaglyph.
fn folds(scene: &Scene, plan: &Plan, passes: &[(EyeMatrices, Shading)]) -> bool {
    let views: Vec<View> = plan.passes.iter().map(|p| p.view).collect();
    let full = 0..scene.width;
    views == [View::Left, View::Right]
        && passes.len() == 2
        && passes
            .iter()
            .all(|(m, shading)| *shading == Shading::Color && m.drawn_columns(scene.width) == full)
        && !scene.finalize.swap_eyes
        && crate::effects::has_wgsl_anaglyph(scene.finalize)
}

impl GpuRenderer {
    /// One frame of `outputs` (each [`is_resident`]) without the eyes leaving the GPU: the
    /// plan's scene passes into textures, one WGSL finalize pass per output reading them, one
    /// submission, and one readback of the outputs' color only. A lone anaglyph is folded into
    /// the eye passes instead, where [`folds_anaglyph`] says so: no pass over the whole frame.
    /// The images, in `outputs`' order, are byte for byte those of [`GpuRenderer::render`]
    /// followed by [`produce_wgsl`](super::effects::produce_wgsl).
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
        self.resident(scene, fin, outputs, true)
    }

    /// [`GpuRenderer::render_resident`], with the anaglyph folded into the eye passes where
    /// [`folds_anaglyph`] allows and `fold` asks, else as a full-screen pass (the bench times
    /// both routes).
    ///
    /// # Errors
    /// As [`GpuRenderer::render_resident`].
    pub fn resident(
        &self,
        scene: &GpuScene,
        fin: &GpuFinalize,
        outputs: &[Output],
        fold: bool,
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
        if let [Output::Anaglyph(kind)] = outputs
            && fold
            && folds(s, &plan, &planned.passes)
        {
            return Ok(vec![self.fused_anaglyph(
                scene,
                fin,
                *kind,
                &planned.passes,
            )?]);
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let eyes = self.encode_views(scene, &planned.passes, &mut encoder, None)?;
        // The eye drawn for `view`, as `Frame::view` finds it (the first pass from that view).
        let eye = |v: View| -> Result<[&wgpu::TextureView; 2]> {
            let i = plan
                .passes
                .iter()
                .position(|p| p.view == v)
                .ok_or_else(|| Error::internal("plan", format!("the {v:?} pass was not run")))?;
            Ok([&eyes[i].color_view, &eyes[i].depth_view])
        };
        let mvps = [&planned.views.eyes[0].mvp, &planned.views.eyes[1].mvp];
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

    /// A frame whose only output is an anaglyph, folded into the eye passes (see
    /// [`folds_anaglyph`]): one submission, and one readback of the anaglyph. The same bytes as
    /// the full-screen pass over the eye textures on lavapipe
    /// (`tests/gpu_finalize.rs`); the eye passes decode their own quantized colors as its
    /// texture unit does (`k · (1/255)`).
    ///
    /// # Errors
    /// As [`GpuRenderer::render_resident`].
    fn fused_anaglyph(
        &self,
        scene: &GpuScene,
        fin: &GpuFinalize,
        kind: AnaglyphKind,
        passes: &[(EyeMatrices, Shading)],
    ) -> Result<RgbaImage> {
        let s = scene.scene;
        let options = s.finalize;
        let mut params = anaglyph_params(kind);
        let clear = self.background_anaglyph(fin, options, &params, s.background)?;
        // The right eye's background as the texture unit reads the stored bytes.
        params.extend(s.background.map(|c| c as f32 * (1.0 / 255.0)));
        let bytes: Vec<u8> = params.iter().flat_map(|f| f.to_ne_bytes()).collect();
        let params = buffer_with(self, "fused anaglyph", &bytes, wgpu::BufferUsages::UNIFORM);
        let target = Target::take(self, s.width, s.height, DepthKind::ColorR32)?;
        let fused = Fused {
            linear_light: options.linear_light,
            params: &params,
            anaglyph: &target,
            clear: clear_color(clear),
        };
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let eyes = self.encode_views(scene, passes, &mut encoder, Some(&fused))?;
        target.encode_color_copy(&mut encoder);
        let mut out = submit_and_read_colors(self, encoder, &[&target])?;
        Target::give_back(self, eyes.into_iter().chain([target]));
        out.pop()
            .ok_or_else(|| Error::internal("fused anaglyph", "no image read back"))
    }

    /// The anaglyph of a pixel where both eyes show `background`, as the full-screen pass
    /// computes it (a 1×1 frame of it, run once per matrices, mode and background and kept).
    ///
    /// # Errors
    /// A GPU failure.
    fn background_anaglyph(
        &self,
        fin: &GpuFinalize,
        options: AnaglyphOptions,
        params: &[f32],
        background: [u8; 4],
    ) -> Result<[u8; 4]> {
        let key = (
            params.iter().map(|p| p.to_bits()).collect::<Vec<_>>(),
            options.linear_light,
            background,
        );
        let poisoned = || Error::internal("fused anaglyph", "cache poisoned by a panic");
        let cached = self
            .fused_clears
            .lock()
            .map_err(|_| poisoned())?
            .get(&key)
            .copied();
        if let Some(c) = cached {
            return Ok(c);
        }
        let eye = Target::take(self, 1, 1, DepthKind::DepthBuffer)?;
        let out = Target::take(self, 1, 1, DepthKind::ColorR32)?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("background"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &eye.color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear_color(background)),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        let views = [&eye.color_view, &eye.depth_view];
        fin.anaglyph_pass(options)
            .encode(self, &mut encoder, &[views, views], params, &out)?;
        out.encode_color_copy(&mut encoder);
        let image = submit_and_read_colors(self, encoder, &[&out])?;
        Target::give_back(self, [eye, out]);
        let c = image
            .first()
            .map(|i| i.get_pixel(0, 0).0)
            .ok_or_else(|| Error::internal("fused anaglyph", "no background read back"))?;
        let mut cache = self.fused_clears.lock().map_err(|_| poisoned())?;
        // Bounded: a program that renders many backgrounds recomputes some instead of growing.
        if cache.len() >= MAX_FUSED_CLEARS {
            cache.clear();
        }
        cache.insert(key, c);
        Ok(c)
    }

    /// The scene passes of `plan` into textures, submitted and waited for, with nothing read
    /// back: the floor under any frame of that plan (the bench's bound for
    /// [`GpuRenderer::render_resident`]).
    ///
    /// # Errors
    /// As [`GpuRenderer::render`].
    pub fn render_without_readback(&self, scene: &GpuScene, plan: &Plan) -> Result<()> {
        let planned = plan_views(scene.scene, plan)?;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let eyes = self.encode_views(scene, &planned.passes, &mut encoder, None)?;
        submit_and_wait(self, encoder)?;
        Target::give_back(self, eyes);
        Ok(())
    }
}
