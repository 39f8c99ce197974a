//! The SIRDS paper's per-vertex strip algorithm as the paper built it, on the GPU: render-to-texture
//! ping-pong (§4). A mirror of [`per_vertex`](stereolab_core::per_vertex)
//! on the same [`StripGeometry`] and the same strips
//! ([`plan_strips`]):
//!
//! - texture A holds the image so far (the pattern at first), texture B is the render target;
//! - each iteration draws the whole scene into B with the scissor rect = its strip (the CPU
//!   traverses the strip alone the same way), depth LESS into one `Depth32Float`, the fragment reading A
//!   at `x − toward·s` (shaders/sirds_strip.wgsl); then the strip is copied from B to A, so the
//!   next iteration reads it;
//! - the depth buffer is cleared once per frame: the scissor keeps every strip's depth writes
//!   inside the strip and strips are disjoint, so each strip starts from a cleared depth buffer
//!   exactly as the CPU's fresh per-tile depth buffer does;
//! - each strip draws only the triangles whose shifted bounds reach it (an index range per
//!   strip), as the CPU traverses only the triangles whose columns reach the strip;
//! - B is read back into RGBA pixels.
//!
//! The vertex inputs are the CPU's bit for bit (`x + toward·s·w/W` computed on the host with
//! the same f32 expression, z through [`GL_TO_WGPU_DEPTH`]), and both paths set the triangles
//! up over the whole target and cut them to the strip with a scissor; what can differ is
//! depth rounding and the perspective-correct interpolation of `s` (tests/gpu_sirds.rs
//! measures it). Using the strips: [`sirds_frame`](super::sirds_frame).

use std::sync::Mutex;
use std::sync::mpsc;

use glam::Vec4;

use stereolab_core::{
    Disparity, PerVertexOptions, Result, SirdsPattern, StripFilter, check_sirds_inputs,
};
use stereolab_core::{StripGeometry, StripResult, plan_strips};

use super::device::GpuRenderer;
use super::readback::{COLOR_FORMAT, padded_row_bytes};
use super::resources::{buffer_with, fragment_texture_entry, texture_2d, write_texels};
use super::{GL_TO_WGPU_DEPTH, gpu_error};

/// The mirror of `StripShader`.
const STRIP_WGSL: &str = include_str!("shaders/sirds_strip.wgsl");

/// Bytes of sirds_strip.wgsl's `Strip` uniform.
const STRIP_UNIFORM_BYTES: u64 = 16;

/// Textures and the readback buffer of one image size, kept between frames.
struct StripTargets {
    width: u32,
    height: u32,
    /// The image so far (read by the fragment stage).
    a: wgpu::Texture,
    /// The render target.
    b: wgpu::Texture,
    depth: wgpu::TextureView,
    readback: wgpu::Buffer,
}

/// The compiled strip pipeline. Build once per device, run on any geometry.
pub struct GpuStrips {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    targets: Mutex<Option<StripTargets>>,
}

impl GpuStrips {
    /// Compiles sirds_strip.wgsl into a pipeline: triangle list, no culling (as the CPU's
    /// `RasterOptions::default()`), depth LESS with writes, one `Rgba8Unorm` target.
    ///
    /// # Errors
    /// The shader does not compile or validate (naga's message).
    pub fn new(r: &GpuRenderer) -> Result<GpuStrips> {
        let scope = r.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let layout = r
            .device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("sirds strip"),
                entries: &[
                    fragment_texture_entry(0),
                    wgpu::BindGroupLayoutEntry {
                        binding: 1,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Buffer {
                            ty: wgpu::BufferBindingType::Uniform,
                            has_dynamic_offset: true,
                            min_binding_size: wgpu::BufferSize::new(STRIP_UNIFORM_BYTES),
                        },
                        count: None,
                    },
                ],
            });
        let module = r.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("sirds_strip.wgsl"),
            source: wgpu::ShaderSource::Wgsl(STRIP_WGSL.into()),
        });
        let pipeline_layout = r
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("sirds strip"),
                bind_group_layouts: &[Some(&layout)],
                immediate_size: 0,
            });
        let position = [wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x4,
            offset: 0,
            shader_location: 0,
        }];
        let separation = [wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32,
            offset: 0,
            shader_location: 1,
        }];
        let pipeline = r
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("sirds strip"),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[
                        Some(wgpu::VertexBufferLayout {
                            array_stride: 16,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &position,
                        }),
                        Some(wgpu::VertexBufferLayout {
                            array_stride: 4,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &separation,
                        }),
                    ],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: None,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: COLOR_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(gpu_error(
                "sirds_strip.wgsl",
                format!("strip shader rejected: {e}"),
            ));
        }
        Ok(GpuStrips {
            pipeline,
            layout,
            targets: Mutex::new(None),
        })
    }

    /// Makes a SIRDS with the strip algorithm on the GPU, as
    /// [`per_vertex`](stereolab_core::per_vertex) does on the CPU (same
    /// strips, same starts and filters; `links` is never recorded).
    ///
    /// # Errors
    /// As `per_vertex` (bad width or pattern, k too small for the front separation), an image
    /// larger than the device allows, or a GPU failure.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        r: &GpuRenderer,
        geometry: &StripGeometry,
        width: u32,
        height: u32,
        d: &Disparity,
        pattern: &SirdsPattern,
        opts: &PerVertexOptions,
    ) -> Result<StripResult> {
        check_sirds_inputs(width, d, pattern)?;
        let strips = plan_strips(width, d, opts)?;
        r.check_target_size(width, height)?;
        let wf = width as f32;
        // Both shifted copies of the vertices, from the function the CPU strips use, so that the
        // positions are the CPU's bit for bit.
        let right_clip = geometry.shifted(1.0, width);
        let left_clip = strips
            .iter()
            .any(|s| s.toward < 0.0)
            .then(|| geometry.shifted(-1.0, width));
        // Per strip, only the triangles that reach it (the CPU traverses only the triangles
        // whose columns reach the strip): one index buffer, one range per strip.
        let x_right = x_bounds(&right_clip, geometry.triangles(), wf);
        let x_left = left_clip
            .as_ref()
            .map(|c| x_bounds(c, geometry.triangles(), wf));
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges = Vec::with_capacity(strips.len());
        for s in &strips {
            let bounds = match (&x_left, s.toward < 0.0) {
                (Some(l), true) => l,
                _ => &x_right,
            };
            let (lo, hi) = (s.x0 as f32 - 1.0, (s.x0 + s.width) as f32 + 1.0);
            let start = indices.len() as u32;
            for (t, b) in geometry.triangles().iter().zip(bounds) {
                if b[1] >= lo && b[0] <= hi {
                    indices.extend(t);
                }
            }
            ranges.push(start..indices.len() as u32);
        }
        let vertex = |label, bytes: &[u8], usage| buffer_with(r, label, bytes, usage);
        // z goes to wgpu's [0, w]; x, y and w stay bit for bit (GL_TO_WGPU_DEPTH's unit rows).
        let positions = |label, clip: &[Vec4]| {
            let bytes: Vec<u8> = clip
                .iter()
                .flat_map(|c| (GL_TO_WGPU_DEPTH * *c).to_array())
                .flat_map(f32::to_ne_bytes)
                .collect();
            vertex(label, &bytes, wgpu::BufferUsages::VERTEX)
        };
        let right = positions("strip right", &right_clip);
        let left = left_clip.map(|c| positions("strip left", &c));
        let separation: Vec<u8> = geometry
            .separation()
            .iter()
            .flat_map(|s| s.to_ne_bytes())
            .collect();
        let separation = vertex("strip separation", &separation, wgpu::BufferUsages::VERTEX);
        let index_bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_ne_bytes()).collect();
        let indices = vertex("strip indices", &index_bytes, wgpu::BufferUsages::INDEX);

        let align = r.device.limits().min_uniform_buffer_offset_alignment as u64;
        let slot = STRIP_UNIFORM_BYTES.next_multiple_of(align);
        let mut uniforms = vec![0u8; slot as usize * strips.len()];
        for (k, s) in strips.iter().enumerate() {
            let at = k * slot as usize;
            let bilinear = u32::from(opts.filter == StripFilter::Bilinear);
            uniforms[at..at + 4].copy_from_slice(&s.toward.to_ne_bytes());
            uniforms[at + 4..at + 8].copy_from_slice(&(s.lo as i32).to_ne_bytes());
            uniforms[at + 8..at + 12].copy_from_slice(&(s.hi as i32).to_ne_bytes());
            uniforms[at + 12..at + 16].copy_from_slice(&bilinear.to_ne_bytes());
        }
        let uniforms = vertex("strip uniforms", &uniforms, wgpu::BufferUsages::UNIFORM);

        let mut cache = self.targets.lock().map_err(|_| {
            stereolab_core::Error::internal(
                "strip targets",
                "poisoned by a panic in another thread",
            )
        })?;
        let t = match cache.take() {
            Some(t) if (t.width, t.height) == (width, height) => t,
            _ => StripTargets::new(r, width, height),
        };
        let pattern_bytes: Vec<u8> = pattern.fill(width, height).into_iter().flatten().collect();
        for texture in [&t.a, &t.b] {
            write_texels(r, texture, &pattern_bytes);
        }
        let a_view = t.a.create_view(&wgpu::TextureViewDescriptor::default());
        let b_view = t.b.create_view(&wgpu::TextureViewDescriptor::default());
        let bind_group = r.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("sirds strip"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&a_view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &uniforms,
                        offset: 0,
                        size: wgpu::BufferSize::new(STRIP_UNIFORM_BYTES),
                    }),
                },
            ],
        });
        let mut encoder = r
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        for (k, s) in strips.iter().enumerate() {
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("sirds strip"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &b_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Load,
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &t.depth,
                        depth_ops: Some(wgpu::Operations {
                            load: if k == 0 {
                                wgpu::LoadOp::Clear(1.0)
                            } else {
                                wgpu::LoadOp::Load
                            },
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    ..Default::default()
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_scissor_rect(s.x0, 0, s.width, height);
                pass.set_bind_group(0, &bind_group, &[(k as u64 * slot) as u32]);
                let positions = match (&left, s.toward < 0.0) {
                    (Some(l), true) => l,
                    _ => &right,
                };
                pass.set_vertex_buffer(0, positions.slice(..));
                pass.set_vertex_buffer(1, separation.slice(..));
                pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(ranges[k].clone(), 0, 0..1);
            }
            // The finished strip into A, where the next iterations read it.
            let origin = wgpu::Origin3d {
                x: s.x0,
                y: 0,
                z: 0,
            };
            let at = |texture| wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin,
                aspect: wgpu::TextureAspect::All,
            };
            encoder.copy_texture_to_texture(
                at(&t.b),
                at(&t.a),
                wgpu::Extent3d {
                    width: s.width,
                    height,
                    depth_or_array_layers: 1,
                },
            );
        }
        let pixels = read_texture(r, encoder, &t);
        *cache = Some(t);
        Ok(StripResult {
            pixels: pixels?,
            iterations: strips.len() as u32,
            strip_width: strips.first().map_or(0, |s| s.width),
            links: None,
        })
    }
}

impl StripTargets {
    fn new(r: &GpuRenderer, width: u32, height: u32) -> StripTargets {
        let texture = |label, format, usage| texture_2d(r, label, width, height, format, usage);
        use wgpu::TextureUsages as U;
        let image = U::TEXTURE_BINDING | U::RENDER_ATTACHMENT | U::COPY_SRC | U::COPY_DST;
        let depth = texture(
            "strip depth",
            wgpu::TextureFormat::Depth32Float,
            U::RENDER_ATTACHMENT,
        );
        StripTargets {
            width,
            height,
            a: texture("strip image A", COLOR_FORMAT, image),
            b: texture("strip image B", COLOR_FORMAT, image),
            depth: depth.create_view(&wgpu::TextureViewDescriptor::default()),
            readback: r.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("strip readback"),
                size: padded_row_bytes(width) as u64 * height as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
        }
    }
}

/// Window-space `[x_min, x_max]` of each triangle of `clip`; everything for a triangle with a
/// vertex at or behind the eye (the clipper sorts it out).
fn x_bounds(clip: &[Vec4], triangles: &[[u32; 3]], width: f32) -> Vec<[f32; 2]> {
    triangles
        .iter()
        .map(|t| {
            let mut b = [f32::INFINITY, f32::NEG_INFINITY];
            for &i in t {
                let c = clip[i as usize];
                if c.w.is_nan() || c.w <= 0.0 {
                    return [f32::NEG_INFINITY, f32::INFINITY];
                }
                let x = (c.x / c.w + 1.0) * 0.5 * width;
                b = [b[0].min(x), b[1].max(x)];
            }
            b
        })
        .collect()
}

/// Copies B into the readback buffer, submits `encoder`, waits, and unpads the rows.
///
/// # Errors
/// The device was lost, or the buffer could not be mapped.
fn read_texture(
    r: &GpuRenderer,
    mut encoder: wgpu::CommandEncoder,
    t: &StripTargets,
) -> Result<Vec<[u8; 4]>> {
    let row = padded_row_bytes(t.width);
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &t.b,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &t.readback,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(t.height),
            },
        },
        wgpu::Extent3d {
            width: t.width,
            height: t.height,
            depth_or_array_layers: 1,
        },
    );
    r.queue.submit([encoder.finish()]);
    let (tx, rx) = mpsc::channel();
    t.readback.map_async(wgpu::MapMode::Read, .., move |res| {
        let _ = tx.send(res);
    });
    r.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| gpu_error("strip readback", format!("waiting for the GPU failed: {e}")))?;
    rx.recv()
        .map_err(|e| gpu_error("strip readback", e.to_string()))?
        .map_err(|e| gpu_error("strip readback", format!("cannot map the buffer: {e}")))?;
    let w = 4 * t.width as usize;
    let mut pixels = Vec::with_capacity(t.width as usize * t.height as usize);
    {
        let mapped = t
            .readback
            .get_mapped_range(..)
            .map_err(|e| gpu_error("strip readback", format!("buffer not mapped: {e}")))?;
        for line in mapped.chunks_exact(row as usize) {
            pixels.extend(line[..w].chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]]));
        }
    }
    t.readback.unmap();
    Ok(pixels)
}
