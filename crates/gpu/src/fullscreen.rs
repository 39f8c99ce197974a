//! The generic full-screen pass: a WGSL fragment shader run once per pixel over input
//! framebuffers (color and depth), read back as a [`Framebuffer`]. Each effect (anaglyph,
//! remap, parallax color, ChromaDepth, SIRDS strips) is mirrored as one such fragment shader;
//! [`FullscreenPass::copy`] is the identity, which proves the plumbing exact.

use std::fmt::Write as _;

use stereolab_core::{Error, Framebuffer, Result};

use super::device::GpuRenderer;
use super::gpu_error;
use super::readback::{
    COLOR_FORMAT, DepthKind, Readback, Target, submit_and_read, submit_and_read_colors,
};
use super::resources::{fragment_texture_entry, fragment_uniform_entry, texture_2d, write_texels};

/// Vertex stage and helpers every full-screen shader gets.
const PRELUDE_WGSL: &str = concat!(
    include_str!("shaders/common.wgsl"),
    include_str!("shaders/fullscreen.wgsl")
);
/// The identity pass.
const COPY_WGSL: &str = include_str!("shaders/copy.wgsl");

/// Most `f32` parameters a pass takes (`params: array<vec4<f32>, 16>`).
pub const MAX_PARAMS: usize = 64;

/// A compiled full-screen pass with a fixed number of inputs.
pub struct FullscreenPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    inputs: usize,
    label: String,
    /// The pass has the R32 depth target (else its shader's `depth` output is ignored).
    writes_depth: bool,
}

impl FullscreenPass {
    /// `inputs` textures and `params` as this pass takes them: its number of inputs, at most
    /// [`MAX_PARAMS`] parameters.
    fn check_arguments(&self, inputs: usize, params: &[f32]) -> Result<()> {
        if inputs != self.inputs {
            return Err(Error::invalid(
                format!("{} inputs", self.label),
                inputs,
                format!("this pass takes {}", self.inputs),
            ));
        }
        if params.len() > MAX_PARAMS {
            return Err(Error::invalid(
                format!("{} params", self.label),
                params.len(),
                format!("at most {MAX_PARAMS}"),
            ));
        }
        Ok(())
    }

    /// Compiles `fragment_wgsl`, which defines `fs_main(@builtin(position) pos: vec4<f32>) ->
    /// FullscreenOut` and may read `input0_color` … `input{n−1}_depth` and `params`
    /// (see shaders/fullscreen.wgsl).
    ///
    /// # Errors
    /// No inputs, or the shader does not compile or validate (the message is naga's).
    pub fn new(r: &GpuRenderer, label: &str, fragment_wgsl: &str, inputs: usize) -> Result<Self> {
        FullscreenPass::build(r, label, fragment_wgsl, inputs, true)
    }

    /// As [`FullscreenPass::new`], for a pass whose output is its color alone: the pipeline
    /// has no R32 depth target, so the shader's `depth` output is dropped instead of written
    /// to (and cleared in) a second 4-byte-per-pixel texture. [`FullscreenPass::run`] then
    /// returns depth 0 everywhere.
    ///
    /// # Errors
    /// As [`FullscreenPass::new`].
    pub fn new_color_only(
        r: &GpuRenderer,
        label: &str,
        fragment_wgsl: &str,
        inputs: usize,
    ) -> Result<Self> {
        FullscreenPass::build(r, label, fragment_wgsl, inputs, false)
    }

    fn build(
        r: &GpuRenderer,
        label: &str,
        fragment_wgsl: &str,
        inputs: usize,
        writes_depth: bool,
    ) -> Result<Self> {
        if inputs == 0 {
            return Err(Error::invalid(
                "fullscreen pass inputs",
                0,
                "needs at least one input",
            ));
        }
        let mut source = String::new();
        for i in 0..inputs {
            let _ = writeln!(
                source,
                "@group(0) @binding({}) var input{i}_color: texture_2d<f32>;\n\
                 @group(0) @binding({}) var input{i}_depth: texture_2d<f32>;",
                2 * i,
                2 * i + 1
            );
        }
        let _ = writeln!(
            source,
            "@group(0) @binding({}) var<uniform> params: array<vec4<f32>, {}>;",
            2 * inputs,
            MAX_PARAMS / 4
        );
        source.push_str(PRELUDE_WGSL);
        source.push_str(fragment_wgsl);

        let mut entries: Vec<_> = (0..2 * inputs as u32).map(fragment_texture_entry).collect();
        entries.push(fragment_uniform_entry(2 * inputs as u32));
        let scope = r.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let layout = r
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &entries,
            });
        let module = r.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline_layout = r
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let target = |format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = r
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[target(COLOR_FORMAT), target(DepthKind::ColorR32.format())]
                        [..1 + usize::from(writes_depth)],
                }),
                multiview_mask: None,
                cache: None,
            });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(gpu_error(
                label,
                format!("full-screen shader rejected: {e}"),
            ));
        }
        Ok(FullscreenPass {
            pipeline,
            layout,
            inputs,
            label: label.to_string(),
            writes_depth,
        })
    }

    /// The identity pass: returns its one input unchanged (color and depth).
    ///
    /// # Errors
    /// As [`FullscreenPass::new`].
    pub fn copy(r: &GpuRenderer) -> Result<Self> {
        FullscreenPass::new(r, "copy.wgsl", COPY_WGSL, 1)
    }

    /// Runs the pass over `inputs` (all the same size) with up to [`MAX_PARAMS`] parameters.
    ///
    /// # Errors
    /// Wrong number of inputs, different sizes, too many parameters, or a GPU failure.
    pub fn run(
        &self,
        r: &GpuRenderer,
        inputs: &[&Framebuffer],
        params: &[f32],
    ) -> Result<Framebuffer> {
        self.run_readback(r, inputs, params)?.into_framebuffer()
    }

    /// [`FullscreenPass::run`] without reading its R32 output as depths: the values as the
    /// pass wrote them (the parallax pass writes p(z) there).
    pub(crate) fn run_readback(
        &self,
        r: &GpuRenderer,
        inputs: &[&Framebuffer],
        params: &[f32],
    ) -> Result<Readback> {
        self.check_arguments(inputs.len(), params)?;
        let (width, height) = (inputs[0].width(), inputs[0].height());
        if let Some(f) = inputs
            .iter()
            .find(|f| (f.width(), f.height()) != (width, height))
        {
            return Err(Error::invalid(
                format!("{} inputs", self.label),
                format!("{}x{} vs {}x{}", f.width(), f.height(), width, height),
                "all inputs must have the same size",
            ));
        }
        let target = Target::take(r, width, height, DepthKind::ColorR32)?;
        let mut views = Vec::with_capacity(inputs.len());
        for fb in inputs {
            let color: Vec<u8> = fb.color().iter().flatten().copied().collect();
            let depth: Vec<u8> = fb.depth().iter().flat_map(|d| d.to_ne_bytes()).collect();
            views.push([
                upload_texture(r, COLOR_FORMAT, width, height, &color),
                upload_texture(r, DepthKind::ColorR32.format(), width, height, &depth),
            ]);
        }
        let mut encoder = r
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let refs: Vec<[&wgpu::TextureView; 2]> = views.iter().map(|[c, d]| [c, d]).collect();
        self.encode(r, &mut encoder, &refs, params, &target)?;
        let out = if self.writes_depth {
            target.encode_copies(&mut encoder);
            submit_and_read(r, encoder, &[&target])?.pop()
        } else {
            target.encode_color_copy(&mut encoder);
            submit_and_read_colors(r, encoder, &[&target])?
                .pop()
                .map(|img| Readback {
                    width,
                    height,
                    color: img.pixels().map(|p| p.0).collect(),
                    values: vec![0.0; width as usize * height as usize],
                })
        };
        Target::give_back(r, [target]);
        out.ok_or_else(|| stereolab_core::Error::internal(&self.label, "no framebuffer came back"))
    }

    /// Records the pass into `encoder`, reading `inputs` (per input its color view and its
    /// depth view, as textures where they lie: uploaded by [`FullscreenPass::run`], or the
    /// eye targets a scene pass just drew, which are read without leaving the GPU) and
    /// drawing into `target`'s color and R32 depth (color alone for a
    /// [`FullscreenPass::new_color_only`] pass). The same shader, parameters and input
    /// texels give the same bytes either way.
    ///
    /// # Errors
    /// Wrong number of inputs or too many parameters.
    pub(crate) fn encode(
        &self,
        r: &GpuRenderer,
        encoder: &mut wgpu::CommandEncoder,
        inputs: &[[&wgpu::TextureView; 2]],
        params: &[f32],
        target: &Target,
    ) -> Result<()> {
        self.check_arguments(inputs.len(), params)?;
        let mut param_bytes = vec![0u8; 4 * MAX_PARAMS];
        for (i, p) in params.iter().enumerate() {
            param_bytes[4 * i..4 * i + 4].copy_from_slice(&p.to_ne_bytes());
        }
        let param_buffer = r.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fullscreen params"),
            size: param_bytes.len() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        r.queue.write_buffer(&param_buffer, 0, &param_bytes);
        let mut entries: Vec<wgpu::BindGroupEntry> = inputs
            .iter()
            .flatten()
            .enumerate()
            .map(|(i, v)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: wgpu::BindingResource::TextureView(v),
            })
            .collect();
        entries.push(wgpu::BindGroupEntry {
            binding: 2 * inputs.len() as u32,
            resource: param_buffer.as_entire_binding(),
        });
        let bind_group = r.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&self.label),
            layout: &self.layout,
            entries: &entries,
        });
        let attachment = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let attachments = [
            attachment(&target.color_view),
            attachment(&target.depth_view),
        ];
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(&self.label),
            color_attachments: &attachments[..1 + usize::from(self.writes_depth)],
            ..Default::default()
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
        Ok(())
    }
}

/// A sampled texture holding `data` (tightly packed rows of 4-byte texels).
fn upload_texture(
    r: &GpuRenderer,
    format: wgpu::TextureFormat,
    width: u32,
    height: u32,
    data: &[u8],
) -> wgpu::TextureView {
    let texture = texture_2d(
        r,
        "fullscreen input",
        width,
        height,
        format,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    );
    write_texels(r, &texture, data);
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}
