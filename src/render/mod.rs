//! The passes: runs a plan's rasterizations over a scene and returns their framebuffers.
//!
//! - [`render`]: the eye passes (Blinn-Phong color or depth only) and the center pass;
//! - [`chromadepth`]: the ChromaDepth pass (texgen into the ramp);
//! - [`sirds_strips`]: the SIRDS paper's per-vertex strip passes.

pub mod chromadepth;
pub mod sirds_strips;

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::error::Result;
use crate::framebuffer::Framebuffer;
use crate::math::{EyeMatrices, StereoRig};
use crate::plan::{Pass, Plan, Shading, View};
use crate::raster::{RasterStats, rasterize};
use crate::scene::Scene;
use crate::shade::{BlinnPhong, DepthOnly};

/// What one pass produced.
#[derive(Clone, Debug)]
pub struct PassResult {
    /// The pass.
    pub pass: Pass,
    /// Its framebuffer.
    pub framebuffer: Framebuffer,
    /// Rasterizer counts summed over objects.
    pub stats: RasterStats,
    /// Wall time of the pass.
    pub time: Duration,
}

/// Everything rendered for one scene: the plan's passes and the matrices they used.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The plan that was run.
    pub plan: Plan,
    /// One entry per pass, in plan order.
    pub passes: Vec<PassResult>,
    /// Left and right eye matrices (index 0 left).
    pub eyes: [EyeMatrices; 2],
    /// The cyclopean eye.
    pub center: EyeMatrices,
}

impl Frame {
    /// The framebuffer of `view`, if the plan rendered it.
    pub fn view(&self, view: View) -> Option<&Framebuffer> {
        self.passes
            .iter()
            .find(|p| p.pass.view == view)
            .map(|p| &p.framebuffer)
    }

    /// The eye framebuffer behind an OpenGL stereo draw buffer (`BACK_LEFT` is the left eye's,
    /// `BACK_RIGHT` the right eye's), if the plan rendered that eye.
    pub fn draw_buffer(&self, buffer: crate::framebuffer::DrawBuffer) -> Option<&Framebuffer> {
        self.view(match buffer {
            crate::framebuffer::DrawBuffer::BackLeft => View::Left,
            crate::framebuffer::DrawBuffer::BackRight => View::Right,
        })
    }

    /// The matrices of `view`.
    pub fn matrices(&self, view: View) -> &EyeMatrices {
        match view {
            View::Left => &self.eyes[0],
            View::Right => &self.eyes[1],
            View::Center => &self.center,
        }
    }
}

/// Renders every pass of `plan`. Passes run in parallel (one per thread); each pass is itself
/// sequential, so the bytes never depend on the thread count.
///
/// # Errors
/// Invalid camera or rig, or an image size refused by [`Framebuffer::new`].
pub fn render(scene: &Scene, plan: &Plan) -> Result<Frame> {
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    let center = StereoRig::center(&scene.camera, scene.aspect())?;
    let matrices = |v: View| match v {
        View::Left => eyes[0],
        View::Right => eyes[1],
        View::Center => center,
    };
    let passes = plan
        .passes
        .par_iter()
        .map(|p| {
            let start = Instant::now();
            let (framebuffer, stats) = render_view(scene, &matrices(p.view), p.shading)?;
            Ok(PassResult {
                pass: *p,
                framebuffer,
                stats,
                time: start.elapsed(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Frame {
        plan: plan.clone(),
        passes,
        eyes,
        center,
    })
}

/// Renders the whole scene once from `m`: shaded Blinn-Phong, ChromaDepth, or depth only.
///
/// # Errors
/// An image size refused by [`Framebuffer::new`].
pub fn render_view(
    scene: &Scene,
    m: &EyeMatrices,
    shading: Shading,
) -> Result<(Framebuffer, RasterStats)> {
    if shading == Shading::ChromaDepth {
        return chromadepth::render_center(scene, m);
    }
    let mut fb = Framebuffer::new(scene.width, scene.height, scene.background)?;
    let mut total = RasterStats::default();
    for o in &scene.objects {
        let mesh = &o.mesh;
        let s = match shading {
            Shading::Color => {
                let shader = BlinnPhong::new(
                    &mesh.positions,
                    &mesh.normals,
                    o.model,
                    m.view,
                    m.projection,
                    o.color,
                    scene.light,
                );
                rasterize(
                    &mesh.triangles,
                    mesh.positions.len(),
                    &shader,
                    &mut fb,
                    &scene.raster,
                )
            }
            Shading::DepthOnly | Shading::ChromaDepth => {
                let shader = DepthOnly {
                    positions: &mesh.positions,
                    mvp: m.mvp * o.model,
                };
                rasterize(
                    &mesh.triangles,
                    mesh.positions.len(),
                    &shader,
                    &mut fb,
                    &scene.raster,
                )
            }
        };
        total.triangles += s.triangles;
        total.non_finite += s.non_finite;
        total.clipped += s.clipped;
        total.culled += s.culled;
        total.fragments += s.fragments;
    }
    Ok((fb, total))
}
