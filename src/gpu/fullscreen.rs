//! The generic full-screen pass: a WGSL fragment shader run once per pixel over input
//! framebuffers (color and depth), read back as a [`Framebuffer`]. Each effect (anaglyph,
//! remap, parallax color, ChromaDepth, SIRDS strips) is mirrored as one such fragment shader;
//! [`FullscreenPass::copy`] is the identity, which proves the plumbing exact.

use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

use super::device::GpuRenderer;
use super::gpu_error;
use super::readback::{COLOR_FORMAT, DepthKind, Target, submit_and_read};
use super::resources::{texture_2d, write_texels};

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
}

impl FullscreenPass {
    /// Compiles `fragment_wgsl`, which defines `fs_main(@builtin(position) pos: vec4<f32>) ->
    /// FullscreenOut` and may read `input0_color` … `input{n−1}_depth` and `params`
    /// (see shaders/fullscreen.wgsl).
    ///
    /// # Errors
    /// No inputs, or the shader does not compile or validate (the message is naga's).
    pub fn new(r: &GpuRenderer, label: &str, fragment_wgsl: &str, inputs: usize) -> Result<Self> {
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

        let texture_entry = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let mut entries: Vec<_> = (0..2 * inputs as u32).map(texture_entry).collect();
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 2 * inputs as u32,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        });
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
                    targets: &[target(COLOR_FORMAT), target(DepthKind::ColorR32.format())],
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
        if inputs.len() != self.inputs {
            return Err(Error::invalid(
                format!("{} inputs", self.label),
                inputs.len(),
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
        let (width, height) = (inputs[0].width, inputs[0].height);
        if let Some(f) = inputs
            .iter()
            .find(|f| (f.width, f.height) != (width, height))
        {
            return Err(Error::invalid(
                format!("{} inputs", self.label),
                format!("{}x{} vs {}x{}", f.width, f.height, width, height),
                "all inputs must have the same size",
            ));
        }
        let target = Target::take(r, width, height, DepthKind::ColorR32)?;
        let mut views = Vec::with_capacity(2 * inputs.len());
        for fb in inputs {
            let color: Vec<u8> = fb.color.iter().flatten().copied().collect();
            let depth: Vec<u8> = fb.depth.iter().flat_map(|d| d.to_ne_bytes()).collect();
            views.push(upload_texture(r, COLOR_FORMAT, width, height, &color));
            views.push(upload_texture(
                r,
                DepthKind::ColorR32.format(),
                width,
                height,
                &depth,
            ));
        }
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
        let mut entries: Vec<wgpu::BindGroupEntry> = views
            .iter()
            .enumerate()
            .map(|(i, v)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: wgpu::BindingResource::TextureView(v),
            })
            .collect();
        entries.push(wgpu::BindGroupEntry {
            binding: views.len() as u32,
            resource: param_buffer.as_entire_binding(),
        });
        let bind_group = r.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(&self.label),
            layout: &self.layout,
            entries: &entries,
        });
        let mut encoder = r
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        {
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
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(&self.label),
                color_attachments: &[
                    attachment(&target.color_view),
                    attachment(&target.depth_view),
                ],
                ..Default::default()
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        target.encode_copies(&mut encoder);
        let mut out = submit_and_read(r, encoder, &[&target])?;
        Target::give_back(r, [target]);
        out.pop()
            .ok_or_else(|| crate::Error::internal(&self.label, "no framebuffer came back"))
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
