//! Scene passes on the GPU: the plan's passes with the CPU path's meshes and matrices, drawn
//! with the WGSL mirror of the CPU shaders and read back into [`Framebuffer`]s.

use std::time::Instant;

use glam::Mat3;

use stereolab::plan::{Pass, Plan, Shading};
use stereolab::render::chromadepth::resolve_texgen;
use stereolab::render::{Frame, PassResult, ViewMatrices};
use stereolab::scene::{Object, Scene};
use stereolab_core::{
    BlinnPhong, EyeMatrices, Framebuffer, Ramp, RampSampling, RasterOptions, RasterStats, Result,
    Texgen, TexgenMode,
};

use super::device::{FusedEye, GpuRenderer, PipelineKey};
use super::readback::{COLOR_FORMAT, DepthKind, Readback, Target, submit_and_read};
use super::resources::{buffer_with, clear_color};

/// The mirror of [`BlinnPhong`](stereolab_core::BlinnPhong).
const BLINN_PHONG_WGSL: &str = concat!(
    include_str!("shaders/common.wgsl"),
    include_str!("shaders/blinn_phong.wgsl")
);
/// The mirror of [`ChromaDepthShader`](stereolab::render::chromadepth::ChromaDepthShader).
const CHROMADEPTH_WGSL: &str = concat!(
    include_str!("shaders/common.wgsl"),
    include_str!("shaders/chromadepth.wgsl")
);
/// The anaglyph folded into the eye passes (after [`BLINN_PHONG_WGSL`] and `LINEAR_LIGHT`).
const FUSED_WGSL: &str = concat!(
    include_str!("shaders/anaglyph_mix.wgsl"),
    include_str!("shaders/anaglyph_fused.wgsl")
);
/// What [`GpuRenderer::encode_views`] needs to fold the anaglyph into the eye passes.
pub(crate) struct Fused<'a> {
    /// Mix in linear light (the `LINEAR_LIGHT` of the anaglyph).
    pub linear_light: bool,
    /// anaglyph_fused.wgsl's `params`: seven vec4 (the matrices' rows, then the right eye's
    /// background as the texture unit reads it).
    pub params: &'a wgpu::Buffer,
    /// The target the anaglyph is drawn into (its color texture).
    pub anaglyph: &'a Target,
    /// The anaglyph of the two backgrounds, where neither eye draws.
    pub clear: wgpu::Color,
}

/// The mirror of [`DepthOnly`](stereolab_core::DepthOnly).
const DEPTH_ONLY_WGSL: &str = include_str!("shaders/depth_only.wgsl");

/// Interleaved position + normal, 6 × f32.
const VERTEX_STRIDE: u64 = 24;
/// Bytes of the largest uniform block (blinn_phong.wgsl and chromadepth.wgsl `Uniforms`: 2 mat4,
/// 1 mat3, 3 × 16).
const UNIFORM_BYTES: u64 = 224;

/// One object's geometry on the GPU.
struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

/// A scene whose meshes have been uploaded once; render it as often as needed.
pub struct GpuScene<'a> {
    /// The scene (matrices, light, options are read from it at every render).
    pub scene: &'a Scene,
    meshes: Vec<GpuMesh>,
}

impl<'a> GpuScene<'a> {
    /// Uploads every object's positions, normals and triangles.
    ///
    /// # Errors
    /// The scene's rasterizer options have no GPU equivalent (subpixel bits other than
    /// llvmpipe's 8), or the image is larger than the device allows.
    pub fn upload(r: &GpuRenderer, scene: &'a Scene) -> Result<Self> {
        if scene.raster.subpixel_bits != RasterOptions::default().subpixel_bits {
            return Err(stereolab_core::Error::invalid(
                "gpu",
                format!("raster.subpixel_bits = {}", scene.raster.subpixel_bits),
                "the GPU snaps to its own fixed 8 subpixel bits",
            ));
        }
        if scene.raster.depth != stereolab_core::DepthMode::Standard {
            return Err(stereolab_core::Error::invalid(
                "raster.depth",
                scene.raster.depth.name(),
                "the GPU path renders lavapipe's standard f32 depth only; use --backend cpu \
                 for reversed-z or f64 depth, or set raster.depth = \"standard\"",
            ));
        }
        r.check_target_size(scene.width, scene.height)?;
        let meshes = scene
            .objects
            .iter()
            .map(|o| {
                let m = &o.mesh;
                let vertices: Vec<u8> = m
                    .positions
                    .iter()
                    .zip(&m.normals)
                    .flat_map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z])
                    .flat_map(f32::to_ne_bytes)
                    .collect();
                let indices: Vec<u8> = m
                    .triangles
                    .iter()
                    .flatten()
                    .flat_map(|i| i.to_ne_bytes())
                    .collect();
                GpuMesh {
                    vertices: buffer_with(r, "vertices", &vertices, wgpu::BufferUsages::VERTEX),
                    indices: buffer_with(r, "indices", &indices, wgpu::BufferUsages::INDEX),
                    index_count: 3 * m.triangles.len() as u32,
                }
            })
            .collect();
        Ok(GpuScene { scene, meshes })
    }
}

/// The matrices and shading of every pass of a plan, with the matrices they were looked up
/// in (as [`stereolab::render::render`] looks them up).
pub(crate) struct PlannedViews {
    /// Every view's matrices.
    pub views: ViewMatrices,
    /// Per pass of the plan, in order.
    pub passes: Vec<(EyeMatrices, Shading)>,
}

/// The [`PlannedViews`] of `plan` on `s`.
///
/// # Errors
/// Invalid camera or rig.
pub(crate) fn plan_views(s: &Scene, plan: &Plan) -> Result<PlannedViews> {
    let views = ViewMatrices::new(s, plan)?;
    let passes = plan
        .passes
        .iter()
        .map(|p| Ok((views.of_pass(p.view)?, p.shading)))
        .collect::<Result<_>>()?;
    Ok(PlannedViews { views, passes })
}

impl GpuRenderer {
    /// Renders every pass of `plan`, like [`stereolab::render::render`]: all passes go into one
    /// submission, so each [`PassResult::time`] is the whole frame's time including readback,
    /// and [`PassResult::stats`] only counts the triangles submitted (the GPU does not report
    /// fragments).
    ///
    /// # Errors
    /// Invalid camera or rig, or a GPU failure.
    pub fn render(&self, scene: &GpuScene, plan: &Plan) -> Result<Frame> {
        let s = scene.scene;
        let start = Instant::now();
        let PlannedViews { views, passes } = plan_views(s, plan)?;
        let framebuffers = self.render_views(scene, &passes)?;
        let time = start.elapsed();
        let triangles: usize = s.objects.iter().map(|o| o.mesh.triangles.len()).sum();
        let passes = plan
            .passes
            .iter()
            .zip(framebuffers)
            .map(|(pass, framebuffer): (&Pass, Framebuffer)| PassResult {
                pass: *pass,
                framebuffer,
                stats: RasterStats {
                    triangles,
                    ..RasterStats::default()
                },
                time,
            })
            .collect();
        Ok(Frame {
            plan: plan.clone(),
            passes,
            views,
        })
    }

    /// Renders the whole scene once from `m`, like [`stereolab::render::render_view`].
    ///
    /// # Errors
    /// A GPU failure.
    pub fn render_view(
        &self,
        scene: &GpuScene,
        m: &EyeMatrices,
        shading: Shading,
    ) -> Result<Framebuffer> {
        let mut fbs = self.render_views(scene, &[(*m, shading)])?;
        fbs.pop().ok_or_else(|| {
            stereolab_core::Error::internal("render_view", "no framebuffer came back")
        })
    }

    /// Renders several views in one submission and reads them all back.
    ///
    /// # Errors
    /// A GPU failure.
    pub fn render_views(
        &self,
        scene: &GpuScene,
        views: &[(EyeMatrices, Shading)],
    ) -> Result<Vec<Framebuffer>> {
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let targets = self.encode_views(scene, views, &mut encoder, None)?;
        for t in &targets {
            t.encode_copies(&mut encoder);
        }
        let refs: Vec<&Target> = targets.iter().collect();
        let readbacks = submit_and_read(self, encoder, &refs)?;
        // Only after a clean readback: a failed one may leave a buffer mapped.
        Target::give_back(self, targets);
        readbacks
            .into_iter()
            .map(Readback::into_framebuffer)
            .collect()
    }

    /// Records one scene pass per view into `encoder`, each into a target of its own (color
    /// and depth textures that stay on the GPU until a copy is recorded), in `views`' order.
    /// Hand the targets back with `Target::give_back` once the submission has completed.
    ///
    /// With `fused`, the two views are the left and the right eye, shaded, and the anaglyph is
    /// folded into their passes (anaglyph_fused.wgsl): the left pass also writes the anaglyph
    /// of its color with the right eye's background into `fused.anaglyph` (cleared to
    /// `fused.clear` first), and the right pass writes the anaglyph of the left color under it
    /// with its own there instead of its color.
    ///
    /// # Errors
    /// Resolving a ChromaDepth view's texgen or ramp fails, or a target cannot be made.
    pub(crate) fn encode_views(
        &self,
        scene: &GpuScene,
        views: &[(EyeMatrices, Shading)],
        encoder: &mut wgpu::CommandEncoder,
        fused: Option<&Fused>,
    ) -> Result<Vec<Target>> {
        if fused.is_some() && (views.len() != 2 || views.iter().any(|v| v.1 != Shading::Color)) {
            return Err(stereolab_core::Error::internal(
                "fused anaglyph",
                "needs exactly the two eyes, shaded",
            ));
        }
        let s = scene.scene;
        let align = self.device.limits().min_uniform_buffer_offset_alignment as u64;
        let slot = UNIFORM_BYTES.next_multiple_of(align);
        let draws = views.len() * s.objects.len();
        let mut uniforms = vec![0u8; (draws as u64 * slot).max(slot) as usize];
        for (v, (m, shading)) in views.iter().enumerate() {
            // D1/D2 once per view (automatic ones fit a sphere around all of the scene's points).
            let texgen = (*shading == Shading::ChromaDepth)
                .then(|| resolve_texgen(s, m, &s.chromadepth))
                .transpose()?;
            for (k, o) in s.objects.iter().enumerate() {
                let at = (v * s.objects.len() + k) * slot as usize;
                let floats = match shading {
                    Shading::Color => shaded_uniforms(&BlinnPhong::new(
                        &[],
                        &[],
                        o.model,
                        m.view,
                        m.projection,
                        o.color,
                        s.light,
                    )),
                    Shading::DepthOnly => (m.mvp * o.model).to_cols_array().to_vec(),
                    Shading::ChromaDepth => match texgen {
                        Some(texgen) => chromadepth_uniforms(o, m, texgen, s),
                        None => {
                            return Err(stereolab_core::Error::internal(
                                "chromadepth",
                                "texgen not resolved",
                            ));
                        }
                    },
                };
                let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_ne_bytes()).collect();
                uniforms[at..at + bytes.len()].copy_from_slice(&bytes);
            }
        }
        let uniform_buffer = buffer_with(
            self,
            "scene uniforms",
            &uniforms,
            wgpu::BufferUsages::UNIFORM,
        );
        let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene uniforms"),
            layout: &self.uniform_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniform_buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(UNIFORM_BYTES),
                }),
            }],
        });
        let ramp_group = views
            .iter()
            .any(|(_, shading)| *shading == Shading::ChromaDepth)
            .then(|| ramp_bind_group(self, s))
            .transpose()?;
        let targets = views
            .iter()
            .map(|_| Target::take(self, s.width, s.height, DepthKind::DepthBuffer))
            .collect::<Result<Vec<_>>>()?;
        let clear = clear_color(s.background);
        // The fused anaglyph's group 1 for the left and the right pass.
        let fused_groups = fused.map(|f| {
            let params = wgpu::BindGroupEntry {
                binding: 0,
                resource: f.params.as_entire_binding(),
            };
            let left_color = wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&targets[0].color_view),
            };
            [vec![params.clone()], vec![params, left_color]]
                .iter()
                .zip(&self.fused_layouts)
                .map(|(entries, layout)| {
                    self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("fused anaglyph"),
                        layout,
                        entries,
                    })
                })
                .collect::<Vec<_>>()
        });
        for (v, ((m, shading), target)) in views.iter().zip(&targets).enumerate() {
            let key = PipelineKey {
                shaded: *shading != Shading::DepthOnly,
                chromadepth: *shading == Shading::ChromaDepth,
                cull_back: s.raster.cull_back,
                perspective_correct: s.raster.perspective_correct,
                depth_test: s.raster.depth_test,
                fused: fused.map(|f| FusedEye {
                    right: v == 1,
                    linear_light: f.linear_light,
                }),
            };
            let pipeline = self.scene_pipeline(key)?;
            let attachment = |view, load| wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load,
                    store: wgpu::StoreOp::Store,
                },
            };
            let color_attachment = attachment(&target.color_view, wgpu::LoadOp::Clear(clear));
            if !key.shaded {
                // A depth-only pipeline has no color target: clear the color in a pass of its own,
                // as the CPU path leaves the background where it never shades.
                encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("clear color"),
                    color_attachments: &[Some(color_attachment.clone())],
                    ..Default::default()
                });
            }
            let color_attachments = match (fused, v) {
                (None, _) => vec![Some(color_attachment)],
                (Some(f), 0) => vec![
                    Some(color_attachment),
                    Some(attachment(
                        &f.anaglyph.color_view,
                        wgpu::LoadOp::Clear(f.clear),
                    )),
                ],
                (Some(f), _) => vec![Some(attachment(&f.anaglyph.color_view, wgpu::LoadOp::Load))],
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene pass"),
                color_attachments: if key.shaded { &color_attachments } else { &[] },
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_pipeline(&pipeline);
            // Image-shift: the shifted viewport covers only these columns.
            let drawn = m.drawn_columns(s.width);
            if drawn != (0..s.width) {
                pass.set_scissor_rect(drawn.start, 0, drawn.end - drawn.start, s.height);
            }
            if let (true, Some(ramp)) = (key.chromadepth, &ramp_group) {
                pass.set_bind_group(1, ramp, &[]);
            }
            if let Some(groups) = &fused_groups {
                pass.set_bind_group(1, &groups[v.min(1)], &[]);
            }
            for (k, mesh) in scene.meshes.iter().enumerate() {
                let offset = ((v * s.objects.len() + k) as u64 * slot) as u32;
                pass.set_bind_group(0, &bind_group, &[offset]);
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.index_count, 0, 0..1);
            }
        }
        Ok(targets)
    }

    /// The pipeline for `key`, built on first use.
    fn scene_pipeline(&self, key: PipelineKey) -> Result<wgpu::RenderPipeline> {
        let mut cache = self.pipelines.lock().map_err(|_| {
            stereolab_core::Error::internal(
                "pipeline cache",
                "poisoned by a panic in another thread",
            )
        })?;
        Ok(cache
            .entry(key)
            .or_insert_with(|| build_scene_pipeline(self, key))
            .clone())
    }
}

/// The floats of blinn_phong.wgsl's `Uniforms`, from the very values the CPU shader uses.
fn shaded_uniforms(bp: &BlinnPhong) -> Vec<f32> {
    let mut f = Vec::with_capacity(56);
    f.extend(bp.modelview().to_cols_array());
    f.extend(bp.projection().to_cols_array());
    let n = bp.normal_matrix();
    for c in [n.x_axis, n.y_axis, n.z_axis] {
        f.extend([c.x, c.y, c.z, 0.0]);
    }
    let light = bp.light();
    f.extend(bp.light_eye().to_array());
    f.push(light.ambient);
    f.extend(bp.color().to_array());
    f.push(light.specular);
    f.extend([light.shininess, 0.0, 0.0, 0.0]);
    f
}

/// The floats of chromadepth.wgsl's `Uniforms`, computed as `ChromaDepthShader::new` computes
/// them (the same glam expressions, so the same bits).
fn chromadepth_uniforms(o: &Object, m: &EyeMatrices, texgen: Texgen, s: &Scene) -> Vec<f32> {
    let settings = &s.chromadepth;
    let modelview = m.view * o.model;
    let normal_matrix = Mat3::from_mat4(modelview).inverse().transpose();
    let light_eye = m.view.transform_point3(s.light.position);
    let mut f = Vec::with_capacity(56);
    f.extend(modelview.to_cols_array());
    f.extend(m.projection.to_cols_array());
    for c in [
        normal_matrix.x_axis,
        normal_matrix.y_axis,
        normal_matrix.z_axis,
    ] {
        f.extend([c.x, c.y, c.z, 0.0]);
    }
    f.extend(light_eye.to_array());
    f.push(s.light.ambient);
    f.extend(texgen.plane.to_array());
    let flags = u32::from(settings.sampling == RampSampling::Linear)
        | (u32::from(settings.texgen == TexgenMode::PerPixel) << 1)
        | (u32::from(settings.lit) << 2);
    f.extend([
        m.projection.z_axis.z,
        m.projection.w_axis.z,
        settings.texels as f32,
        flags as f32,
    ]);
    f
}

/// The scene's ChromaDepth ramp (`Ramp::new`, the CPU's texels) in a storage buffer, bound as
/// group 1.
///
/// # Errors
/// A bad texel count (as [`Ramp::new`]).
fn ramp_bind_group(r: &GpuRenderer, s: &Scene) -> Result<wgpu::BindGroup> {
    let ramp = Ramp::new(s.chromadepth.ramp, s.chromadepth.texels)?;
    let bytes: Vec<u8> = ramp
        .texels()
        .iter()
        .flat_map(|t| [t.x, t.y, t.z, 1.0])
        .flat_map(f32::to_ne_bytes)
        .collect();
    let buffer = buffer_with(r, "chromadepth ramp", &bytes, wgpu::BufferUsages::STORAGE);
    Ok(r.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("chromadepth ramp"),
        layout: &r.ramp_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: buffer.as_entire_binding(),
        }],
    }))
}

/// Builds the render pipeline for a scene pass: triangle list, counter-clockwise front faces
/// (as the CPU path: counter-clockwise in NDC), depth LESS into `Depth32Float`.
fn build_scene_pipeline(r: &GpuRenderer, key: PipelineKey) -> wgpu::RenderPipeline {
    let (source, label) = match (key.shaded, key.chromadepth) {
        (true, true) => (CHROMADEPTH_WGSL, "chromadepth.wgsl"),
        (true, false) => (BLINN_PHONG_WGSL, "blinn_phong.wgsl"),
        (false, _) => (DEPTH_ONLY_WGSL, "depth_only.wgsl"),
    };
    // The anaglyph folded into Blinn-Phong's eye passes: its arithmetic and entry points after
    // the shading (anaglyph_fused.wgsl).
    let (source, label, entry, group1, outputs) = match key.fused {
        None => (
            source.to_string(),
            label,
            "fs_main",
            key.chromadepth.then_some(&r.ramp_layout),
            1,
        ),
        Some(FusedEye {
            right,
            linear_light,
        }) => {
            let (entry, layout, outputs) = if right {
                ("fs_right", &r.fused_layouts[1], 1)
            } else {
                ("fs_left", &r.fused_layouts[0], 2)
            };
            let source = format!(
                "{BLINN_PHONG_WGSL}\nconst LINEAR_LIGHT: bool = {linear_light};\n{FUSED_WGSL}"
            );
            (source, "anaglyph_fused.wgsl", entry, Some(layout), outputs)
        }
    };
    // Affine varyings are the same shader with linear (screen-space) interpolation.
    let source = if key.perspective_correct {
        source
    } else {
        source.replace("@interpolate(perspective)", "@interpolate(linear)")
    };
    let module = r.device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let groups = [Some(&r.uniform_layout), group1];
    let layout = r
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene"),
            bind_group_layouts: &groups[..1 + usize::from(group1.is_some())],
            immediate_size: 0,
        });
    let attributes = [
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 0,
            shader_location: 0,
        },
        wgpu::VertexAttribute {
            format: wgpu::VertexFormat::Float32x3,
            offset: 12,
            shader_location: 1,
        },
    ];
    let attributes = if key.shaded {
        &attributes[..]
    } else {
        &attributes[..1]
    };
    let target = Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    });
    let targets = [target.clone(), target];
    r.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: VERTEX_STRIDE,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: key.cull_back.then_some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DepthKind::DepthBuffer.format(),
                depth_write_enabled: Some(key.depth_test),
                depth_compare: Some(if key.depth_test {
                    wgpu::CompareFunction::Less
                } else {
                    wgpu::CompareFunction::Always
                }),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: key.shaded.then(|| wgpu::FragmentState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                targets: &targets[..outputs],
            }),
            multiview_mask: None,
            cache: None,
        })
}
