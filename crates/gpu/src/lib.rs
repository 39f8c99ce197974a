//! The GPU parity path: the same [`Plan`](stereolab::plan::Plan), meshes and matrices as the CPU
//! path, rendered by wgpu (on lavapipe when no GPU is present) and read back into the same
//! [`Framebuffer`](stereolab_core::Framebuffer) type, so that [`compare`](stereolab::compare) can measure the
//! two paths pixel by pixel. Built only with the cargo feature `gpu`.
//!
//! Conventions (docs/ARCHITECTURE.md "Conventions"):
//! - the matrices are OpenGL's (NDC z in [−1, 1]); wgpu clips and maps z in [0, 1], so every
//!   projection goes through [`GL_TO_WGPU_DEPTH`] (the only place the two conventions meet);
//! - wgpu's NDC has y = +1 at the top row (wgpu itself gives Vulkan a negative viewport height),
//!   exactly as the CPU viewport `y_win = (y/w)·(−H/2) + H/2`: nothing is flipped here;
//! - color targets are `Rgba8Unorm` without sRGB; shaders quantize like
//!   [`to_rgba8`](stereolab_core::to_rgba8) so the unorm store is exact;
//! - depth is `Depth32Float`, read back bit for bit.
//!
//! Layout: [`device`] (adapter, device, pipeline cache), [`raster`] (scene passes),
//! [`fullscreen`] (the generic full-screen pass that effects mirror), [`effects`] (the finalize
//! effects in WGSL), `readback` (textures to framebuffers), [`resident`] (frames whose eyes
//! stay on the GPU: the finalize passes read them there and only the outputs come back),
//! [`sirds`] (the SIRDS paper's strips as render-to-texture ping-pong), [`parity`] (render both
//! paths and compare, and the benchmark row).

pub mod device;
pub mod effects;
pub mod fullscreen;
pub mod output;
pub mod parity;
pub mod raster;
mod readback;
pub mod resident;
mod resources;
pub mod sirds;
pub mod sirds_frame;

pub use device::GpuRenderer;
pub use effects::GpuFinalize;
pub use fullscreen::FullscreenPass;
pub use raster::GpuScene;

use glam::{Mat4, Vec4};

/// OpenGL clip space to wgpu clip space: `z' = z/2 + w/2`, x, y and w unchanged, so NDC z in
/// [−1, 1] (`glDepthRange(0, 1)` then maps it to `z/2 + 1/2`) becomes wgpu's [0, 1] with the
/// same window depth. Rows 0, 1 and 3 are unit rows: x, y and w stay bit for bit.
///
/// It is applied to clip positions, never folded into a projection matrix: the shaders'
/// `gl_to_wgpu_depth` (common.wgsl) computes `0.5·(z + w)` after the OpenGL projection, and
/// the SIRDS strips multiply their clip positions by this matrix on the host, which rounds
/// the same (`0.5·z + 0.5·w` is one rounding of the exact `0.5·(z + w)`). The CPU's window
/// depth is computed from the same `0.5·(z + w)`, so the depth planes of both paths start from
/// the same bits (docs/gpu-parity.md "Depth bit for bit").
pub const GL_TO_WGPU_DEPTH: Mat4 = Mat4::from_cols(
    Vec4::new(1.0, 0.0, 0.0, 0.0),
    Vec4::new(0.0, 1.0, 0.0, 0.0),
    Vec4::new(0.0, 0.0, 0.5, 0.0),
    Vec4::new(0.0, 0.0, 0.5, 1.0),
);

/// A failure of the GPU itself ([`stereolab_core::Error::Gpu`]: `gpu <what>: <why>`).
pub(crate) fn gpu_error(
    what: impl std::fmt::Display,
    why: impl Into<String>,
) -> stereolab_core::Error {
    stereolab_core::Error::gpu(what, why)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_remap_maps_gl_near_and_far_to_zero_and_one() {
        let near = GL_TO_WGPU_DEPTH * Vec4::new(0.3, -0.2, -2.0, 2.0);
        let far = GL_TO_WGPU_DEPTH * Vec4::new(0.3, -0.2, 2.0, 2.0);
        assert_eq!(near, Vec4::new(0.3, -0.2, 0.0, 2.0));
        assert_eq!(far, Vec4::new(0.3, -0.2, 2.0, 2.0));
    }

    #[test]
    fn depth_remap_keeps_x_y_w_of_a_projection_bit_for_bit() {
        let p = stereolab_core::frustum(-0.7, 0.55, -0.4, 0.45, 1.3, 17.0);
        let q = GL_TO_WGPU_DEPTH * p;
        for c in 0..4 {
            for r in [0, 1, 3] {
                assert_eq!(
                    q.col(c)[r].to_bits(),
                    p.col(c)[r].to_bits(),
                    "col {c} row {r}"
                );
            }
        }
    }
}
