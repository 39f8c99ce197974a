//! The yardstick of the CPU stereo pair: a plain wgpu program, written the way one would
//! write it without stereolab's parity machinery, that renders the same frame — both eyes of
//! the scene with Blinn-Phong, then the Dubois red-cyan anaglyph of the two — as **one**
//! command buffer (two render passes into textures, a full-screen anaglyph pass reading them,
//! one copy into a buffer) and **one** readback. On a machine without a GPU that is lavapipe
//! (llvmpipe), Mesa's JIT-compiled eight-wide software rasterizer: the bench row compares the
//! CPU path with it in the same run.
//!
//! It is not the parity path (`stereolab_gpu`): its WGSL uses the built-in `normalize`, `pow`
//! and the hardware's rounding, and it does not mirror the CPU's operation order, so its
//! pixels differ slightly; the row reports by how much.

use glam::{Mat3, Mat4};
use wgpu::util::DeviceExt;

use super::median_ms;
use stereolab::scene::Scene;
use stereolab_core::{AnaglyphKind, Error, EyeMatrices, Result};

/// Blinn-Phong (the CPU's `BlinnPhong`) and the anaglyph pass, plain WGSL.
const SHADER: &str = r#"
struct Eye {
    modelview: mat4x4<f32>,
    projection: mat4x4<f32>,
    // Columns of the normal matrix (w unused).
    n0: vec4<f32>,
    n1: vec4<f32>,
    n2: vec4<f32>,
    // xyz: the light in eye space; w: ambient.
    light: vec4<f32>,
    // xyz: the material color; w: specular.
    color: vec4<f32>,
    // x: shininess.
    power: vec4<f32>,
}
@group(0) @binding(0) var<uniform> eye: Eye;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) p: vec3<f32>,
    @location(1) n: vec3<f32>,
}

@vertex
fn vs_scene(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VOut {
    var o: VOut;
    let p = eye.modelview * vec4<f32>(position, 1.0);
    o.p = p.xyz;
    o.n = mat3x3<f32>(eye.n0.xyz, eye.n1.xyz, eye.n2.xyz) * normal;
    var c = eye.projection * vec4<f32>(p.xyz, 1.0);
    // OpenGL's depth range [-w, w] to WebGPU's [0, w].
    c.z = 0.5 * (c.z + c.w);
    o.clip = c;
    return o;
}

fn safe_normalize(v: vec3<f32>) -> vec3<f32> {
    let l = length(v);
    if l > 0.0 { return v / l; }
    return vec3<f32>(0.0);
}

@fragment
fn fs_scene(i: VOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    var n = safe_normalize(i.n);
    if !front { n = -n; }
    let l = safe_normalize(eye.light.xyz - i.p);
    let h = safe_normalize(l + safe_normalize(-i.p));
    let diffuse = max(dot(n, l), 0.0);
    var spec = 0.0;
    if diffuse > 0.0 {
        spec = pow(max(dot(n, h), 0.0), eye.power.x) * eye.color.w;
    }
    let ambient = eye.light.w;
    let c = eye.color.xyz * (ambient + (1.0 - ambient) * diffuse) + vec3<f32>(spec);
    return vec4<f32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}

struct Mix {
    // Rows of ML (xyz) and of MR.
    l0: vec4<f32>, l1: vec4<f32>, l2: vec4<f32>,
    r0: vec4<f32>, r1: vec4<f32>, r2: vec4<f32>,
}
@group(0) @binding(0) var left_eye: texture_2d<f32>;
@group(0) @binding(1) var right_eye: texture_2d<f32>;
@group(0) @binding(2) var<uniform> mix: Mix;

@vertex
fn vs_full(@builtin(vertex_index) k: u32) -> @builtin(position) vec4<f32> {
    let x = f32((k << 1u) & 2u);
    let y = f32(k & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

@fragment
fn fs_anaglyph(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let t = vec2<i32>(pos.xy);
    let a = textureLoad(left_eye, t, 0).rgb;
    let b = textureLoad(right_eye, t, 0).rgb;
    let c = vec3<f32>(
        dot(mix.l0.xyz, a) + dot(mix.r0.xyz, b),
        dot(mix.l1.xyz, a) + dot(mix.r1.xyz, b),
        dot(mix.l2.xyz, a) + dot(mix.r2.xyz, b),
    );
    return vec4<f32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
"#;

/// One object's vertex and index buffers.
struct MeshBuffers {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

/// Everything the frame needs, created once; [`OneShot::frame`] then records, submits and
/// reads back one frame.
pub(super) struct OneShot {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: String,
    scene_pipeline: wgpu::RenderPipeline,
    anaglyph_pipeline: wgpu::RenderPipeline,
    meshes: Vec<MeshBuffers>,
    /// Per eye, per object: the uniform bind group.
    eye_groups: [Vec<wgpu::BindGroup>; 2],
    eye_views: [wgpu::TextureView; 2],
    depth_view: wgpu::TextureView,
    anaglyph_group: wgpu::BindGroup,
    out: wgpu::Texture,
    readback: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
    clear: wgpu::Color,
}

fn gpu(what: &str, e: impl std::fmt::Display) -> Error {
    Error::gpu(
        format!("bench one-shot wgpu program: {what}"),
        e.to_string(),
    )
}

impl OneShot {
    /// Opens the first Vulkan adapter, uploads `scene`'s meshes and per-eye uniforms
    /// (`eyes`), and creates the targets.
    ///
    /// # Errors
    /// No Vulkan adapter, or the device cannot be created.
    pub(super) fn new(scene: &Scene, eyes: &[EyeMatrices; 2]) -> Result<OneShot> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| gpu("adapter", e))?;
        let name = adapter.get_info().name;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("bench one-shot"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| gpu("device", e))?;
        let (width, height) = (scene.width, scene.height);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("one-shot"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let color_format = wgpu::TextureFormat::Rgba8Unorm;
        let target = |label, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: color_format,
                usage,
                view_formats: &[],
            })
        };
        let eye_usage =
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let eye_textures = [target("left", eye_usage), target("right", eye_usage)];
        let out = target(
            "anaglyph",
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("depth"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let eye_views = eye_textures.map(|t| t.create_view(&Default::default()));
        let depth_view = depth.create_view(&Default::default());

        // The scene pipeline: position + normal, one uniform block per eye and object.
        let scene_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_scene"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 24,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
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
                entry_point: Some("fs_scene"),
                compilation_options: Default::default(),
                targets: &[Some(color_format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let anaglyph_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("anaglyph"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_full"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_anaglyph"),
                compilation_options: Default::default(),
                targets: &[Some(color_format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });

        let mut meshes = Vec::new();
        let mut eye_groups: [Vec<wgpu::BindGroup>; 2] = [Vec::new(), Vec::new()];
        let scene_layout = scene_pipeline.get_bind_group_layout(0);
        for o in &scene.objects {
            let m = &o.mesh;
            let vertices: Vec<f32> = m
                .positions
                .iter()
                .zip(&m.normals)
                .flat_map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z])
                .collect();
            let indices: Vec<u32> = m.triangles.iter().flatten().copied().collect();
            meshes.push(MeshBuffers {
                vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("vertices"),
                    contents: &f32_bytes(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("indices"),
                    contents: &u32_bytes(&indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                count: indices.len() as u32,
            });
            for (groups, e) in eye_groups.iter_mut().zip(eyes) {
                let modelview: Mat4 = e.view * o.model;
                let nm = Mat3::from_mat4(modelview).inverse().transpose();
                let light = e.view.transform_point3(scene.light.position);
                let mut u: Vec<f32> = Vec::new();
                u.extend(modelview.to_cols_array());
                u.extend(e.projection.to_cols_array());
                for c in [nm.x_axis, nm.y_axis, nm.z_axis] {
                    u.extend([c.x, c.y, c.z, 0.0]);
                }
                u.extend([light.x, light.y, light.z, scene.light.ambient]);
                u.extend([o.color.x, o.color.y, o.color.z, scene.light.specular]);
                u.extend([scene.light.shininess, 0.0, 0.0, 0.0]);
                let buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("eye uniforms"),
                    contents: &f32_bytes(&u),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                groups.push(device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("eye"),
                    layout: &scene_layout,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buf.as_entire_binding(),
                    }],
                }));
            }
        }
        let m = AnaglyphKind::DuboisRedCyan.matrices();
        let mix: Vec<f32> = m
            .left
            .iter()
            .chain(&m.right)
            .flat_map(|r| [r[0], r[1], r[2], 0.0])
            .collect();
        let mix = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("dubois"),
            contents: &f32_bytes(&mix),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let anaglyph_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("anaglyph"),
            layout: &anaglyph_pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&eye_views[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&eye_views[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: mix.as_entire_binding(),
                },
            ],
        });
        let padded_row = (width * 4).div_ceil(256) * 256;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: u64::from(padded_row) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let [r, g, b, _] = scene.background;
        let clear = wgpu::Color {
            r: f64::from(r) / 255.0,
            g: f64::from(g) / 255.0,
            b: f64::from(b) / 255.0,
            a: 1.0,
        };
        Ok(OneShot {
            device,
            queue,
            adapter: name,
            scene_pipeline,
            anaglyph_pipeline,
            meshes,
            eye_groups,
            eye_views,
            depth_view,
            anaglyph_group,
            out,
            readback,
            width,
            height,
            padded_row,
            clear,
        })
    }

    /// The adapter's name (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub(super) fn adapter(&self) -> &str {
        &self.adapter
    }

    /// One frame: both eyes and the anaglyph pass in one command buffer, one submission, one
    /// readback of the anaglyph; its RGBA8 pixels, rows top first.
    ///
    /// # Errors
    /// The readback buffer cannot be mapped.
    pub(super) fn frame(&self) -> Result<Vec<u8>> {
        let mut enc = self.device.create_command_encoder(&Default::default());
        for (eye, view) in self.eye_views.iter().enumerate() {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("eye"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(self.clear),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.scene_pipeline);
            for (m, group) in self.meshes.iter().zip(&self.eye_groups[eye]) {
                pass.set_bind_group(0, group, &[]);
                pass.set_vertex_buffer(0, m.vertices.slice(..));
                pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..m.count, 0, 0..1);
            }
        }
        {
            let view = self.out.create_view(&Default::default());
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("anaglyph"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.anaglyph_pipeline);
            pass.set_bind_group(0, &self.anaglyph_group, &[]);
            pass.draw(0..3, 0..1);
        }
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.out,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([enc.finish()]);
        let slice = self.readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| gpu("poll", e))?;
        let row = (self.width * 4) as usize;
        let mut pixels = Vec::with_capacity(row * self.height as usize);
        {
            let data = slice.get_mapped_range().map_err(|e| gpu("map", e))?;
            for y in 0..self.height as usize {
                let at = y * self.padded_row as usize;
                pixels.extend_from_slice(&data[at..at + row]);
            }
        }
        self.readback.unmap();
        Ok(pixels)
    }
}

/// `f32`s as their little-endian bytes (what a buffer upload takes).
fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

/// `u32`s as their little-endian bytes.
fn u32_bytes(v: &[u32]) -> Vec<u8> {
    v.iter().flat_map(|f| f.to_le_bytes()).collect()
}

/// The goal-1 rows: the CPU stereo pair + Dubois anaglyph (on the loops
/// [`uses_avx2`](stereolab_core::uses_avx2) tells: the AVX2 fragment stage where the CPU has
/// it, the scalar stage with `STEREOLAB_SCALAR=1`), beside [`OneShot`] on the same scene, timed
/// in the same run. The CPU row's note carries the ratio `cpu / wgpu`; the wgpu row's error is the largest
/// channel difference to the CPU's anaglyph (its arithmetic is not the parity path's).
/// Without a Vulkan adapter one row says so instead.
///
/// # Errors
/// The CPU path fails, or the wgpu frame cannot be read back.
pub(super) fn rows(scene: &Scene, iters: usize) -> Result<Vec<super::Row>> {
    use stereolab::output::{Image, produce};
    use stereolab::plan::{Output, Plan};
    use stereolab::render::render;

    let output = Output::Anaglyph(AnaglyphKind::DuboisRedCyan);
    let plan = Plan::new(&[output]);
    let size = format!("{}x{}", scene.width, scene.height);
    let row = |setting: &str, error, ms, note: String| super::Row {
        area: "gpu parity".into(),
        knob: "pair + anaglyph, one submission".into(),
        setting: setting.into(),
        error,
        error_unit: "max level vs cpu".into(),
        ms,
        note,
    };
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    let oneshot = match OneShot::new(scene, &eyes) {
        Ok(o) => o,
        Err(e) => {
            return Ok(vec![row(
                "wgpu",
                None,
                f64::NAN,
                format!("not measured: {e}"),
            )]);
        }
    };
    let cpu_frame = |s: &Scene| -> Result<Vec<u8>> {
        match produce(output, &render(s, &plan)?, s)? {
            Image::Rgba(img) => Ok(img.into_raw()),
            _ => Err(Error::internal("bench anaglyph", "not an RGBA image")),
        }
    };
    let cpu = cpu_frame(scene)?;
    let wgpu = oneshot.frame()?;
    let max_diff = cpu
        .iter()
        .zip(&wgpu)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0);
    let differ = cpu
        .chunks(4)
        .zip(wgpu.chunks(4))
        .filter(|(a, b)| a.iter().zip(b.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
        .count();
    let mut failed = None;
    let wgpu_ms = median_ms(iters, || oneshot.frame().map_err(|e| failed = Some(e)));
    let cpu_ms = median_ms(iters, || cpu_frame(scene).map_err(|e| failed = Some(e)));
    if let Some(e) = failed {
        return Err(e);
    }
    let simd = if stereolab_core::uses_avx2() {
        "AVX2 fragment stage"
    } else if stereolab_core::avx2_available() {
        "STEREOLAB_SCALAR: scalar"
    } else {
        "no AVX2 on this CPU: scalar"
    };
    Ok(vec![
        row(
            "cpu",
            Some(0.0),
            cpu_ms,
            format!(
                "{size}, {simd}; cpu/wgpu time = {:.2} (goal <= 0.5)",
                cpu_ms / wgpu_ms
            ),
        ),
        row(
            "wgpu",
            Some(f64::from(max_diff)),
            wgpu_ms,
            format!(
                "{size}: 2 eye passes + anaglyph pass, 1 command buffer, 1 readback; {}; \
                 {:.2}% pixels differ by > 2 levels",
                oneshot.adapter(),
                100.0 * differ as f64 / (cpu.len() / 4).max(1) as f64
            ),
        ),
    ])
}
