//! The wgpu device: adapter selection, the pipeline cache, and one submit-and-wait helper.

use std::collections::HashMap;
use std::sync::Mutex;

use stereolab_core::Result;

use super::gpu_error;
use super::readback::Target;
use super::resources::{fragment_texture_entry, fragment_uniform_entry};

/// Which pipeline a scene pass needs: its shading and the rasterizer options that change
/// fixed-function state or the shader (see [`stereolab_core::RasterOptions`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct PipelineKey {
    /// A color stage (Blinn-Phong or ChromaDepth: true) or depth only.
    pub shaded: bool,
    /// The ChromaDepth program (with its ramp in group 1) instead of Blinn-Phong.
    pub chromadepth: bool,
    /// Back-face culling.
    pub cull_back: bool,
    /// Perspective-correct varyings (true) or `@interpolate(linear)`.
    pub perspective_correct: bool,
    /// Depth test LESS with writes (true), or neither.
    pub depth_test: bool,
    /// A Blinn-Phong eye pass with the anaglyph folded in (src/gpu/resident.rs), or none.
    pub fused: Option<FusedEye>,
}

/// A fused frame's clear value is kept per the anaglyph's matrices (their bits), linear light
/// and the background color.
pub(crate) type FusedClearKey = (Vec<u32>, bool, [u8; 4]);

/// Which eye pass of a frame with the anaglyph folded into the eye passes
/// (anaglyph_fused.wgsl), and whether the anaglyph mixes in linear light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct FusedEye {
    /// The right eye (the anaglyph of the left eye's color under it with its own), else the
    /// left (its color, and the anaglyph with the right eye's background).
    pub right: bool,
    /// The anaglyph's `LINEAR_LIGHT`.
    pub linear_light: bool,
}

/// A wgpu device and queue with the pipelines built so far. Create once, render many frames.
pub struct GpuRenderer {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    info: wgpu::AdapterInfo,
    /// Uniform buffer with dynamic offset, shared by the scene pipelines (group 0).
    pub(crate) uniform_layout: wgpu::BindGroupLayout,
    /// The ChromaDepth ramp's texels as a read-only storage buffer (group 1).
    pub(crate) ramp_layout: wgpu::BindGroupLayout,
    /// The fused anaglyph's group 1 in the left eye's pass (its parameters) and in the right
    /// eye's (the parameters and the left eye's color texture).
    pub(crate) fused_layouts: [wgpu::BindGroupLayout; 2],
    /// The anaglyph of two background colors as the full-screen pass computes it, per
    /// (matrices' bits, linear light, background): the clear value of a fused frame's anaglyph.
    pub(crate) fused_clears: Mutex<HashMap<FusedClearKey, [u8; 4]>>,
    pub(crate) pipelines: Mutex<HashMap<PipelineKey, wgpu::RenderPipeline>>,
    /// Targets of earlier frames, reused when the size matches (fresh ones cost page faults).
    pub(crate) spare_targets: Mutex<Vec<Target>>,
}

impl GpuRenderer {
    /// Opens the first Vulkan adapter wgpu finds (lavapipe's "llvmpipe" on a machine without a
    /// GPU) and creates a device with the adapter's own limits.
    ///
    /// # Errors
    /// No Vulkan adapter (`mesa-vulkan-drivers` missing), or the device cannot be created.
    pub fn new() -> Result<GpuRenderer> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| {
            gpu_error(
                "adapter",
                format!(
                    "no Vulkan adapter found ({e}); on Debian/Ubuntu install \
                     mesa-vulkan-drivers and libvulkan1 for lavapipe"
                ),
            )
        })?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("stereolab"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| gpu_error(&info.name, format!("cannot create a device: {e}")))?;
        let uniform_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let ramp_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("chromadepth ramp"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let (params, left_color) = (fragment_uniform_entry(0), fragment_texture_entry(1));
        let fused_layouts = [&[params][..], &[params, left_color][..]].map(|entries| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("fused anaglyph"),
                entries,
            })
        });
        Ok(GpuRenderer {
            device,
            queue,
            info,
            uniform_layout,
            ramp_layout,
            fused_layouts,
            fused_clears: Mutex::new(HashMap::new()),
            pipelines: Mutex::new(HashMap::new()),
            spare_targets: Mutex::new(Vec::new()),
        })
    }

    /// The adapter's name and driver, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) (Mesa 22.3.6)`.
    pub fn adapter_name(&self) -> String {
        let i = &self.info;
        if i.driver_info.is_empty() {
            i.name.clone()
        } else {
            format!("{} ({})", i.name, i.driver_info)
        }
    }

    /// `lavapipe` for Mesa's CPU driver, else the adapter's name.
    pub fn short_name(&self) -> String {
        if self.is_cpu_adapter() && self.info.name.starts_with("llvmpipe") {
            "lavapipe".into()
        } else {
            self.info.name.clone()
        }
    }

    /// True when the adapter is a CPU implementation (lavapipe, SwiftShader).
    pub fn is_cpu_adapter(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Largest texture side the device accepts.
    pub fn max_texture_side(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// Checks that a `width × height` target fits the device.
    ///
    /// # Errors
    /// A side above [`GpuRenderer::max_texture_side`].
    pub(crate) fn check_target_size(&self, width: u32, height: u32) -> Result<()> {
        let max = self.max_texture_side();
        if width > max || height > max {
            return Err(stereolab_core::Error::invalid(
                "gpu",
                format!("{width}x{height}"),
                format!("the adapter's largest texture side is {max} pixels"),
            ));
        }
        Ok(())
    }
}
