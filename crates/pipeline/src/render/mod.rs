//! The passes: runs a plan's rasterizations over a scene and returns their framebuffers.
//!
//! - [`render`]: the eye passes (Blinn-Phong color or depth only) and the center pass;
//! - [`chromadepth`]: the ChromaDepth pass (texgen into the ramp);
//! - [`sirds_strips`]: the SIRDS paper's per-vertex strip passes.

pub mod chromadepth;
pub mod sirds_strips;

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::plan::{Pass, Plan, Shading, View};
use crate::scene::Scene;
use stereolab_core::error::Result;
use stereolab_core::framebuffer::Framebuffer;
use stereolab_core::math::{CameraMode, EyeMatrices, StereoRig};
use stereolab_core::raster::{RasterStats, rasterize, rasterize_blinn_phong};
use stereolab_core::shade::{BlinnPhong, DepthOnly};

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
    /// The scene's rig as off-axis (`[0]`, shear) and as toe-in (`[1]`, rotate), each left and
    /// right: the matrices of the [`View::ShearLeft`] … [`View::RotateRight`] passes, present
    /// when the plan runs them ([`shear_rotate_eyes`]).
    pub shear_rotate: Option<[[EyeMatrices; 2]; 2]>,
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
    pub fn draw_buffer(
        &self,
        buffer: stereolab_core::framebuffer::DrawBuffer,
    ) -> Option<&Framebuffer> {
        self.view(buffer.eye().into())
    }

    /// The matrices of `view`; `None` for a shear/rotate view the plan did not run.
    pub fn try_matrices(&self, view: View) -> Option<&EyeMatrices> {
        let compare = |rig: usize, eye: usize| self.shear_rotate.as_ref().map(|m| &m[rig][eye]);
        match view {
            View::Left => Some(&self.eyes[0]),
            View::Right => Some(&self.eyes[1]),
            View::Center => Some(&self.center),
            View::ShearLeft => compare(0, 0),
            View::ShearRight => compare(0, 1),
            View::RotateLeft => compare(1, 0),
            View::RotateRight => compare(1, 1),
        }
    }

    /// The matrices of `view`.
    ///
    /// # Panics
    /// For a shear/rotate view the frame's plan did not run (no matrices were made for it);
    /// [`Frame::try_matrices`] returns `None` instead.
    pub fn matrices(&self, view: View) -> &EyeMatrices {
        self.try_matrices(view)
            .expect("a shear/rotate view is asked for only when the plan ran it")
    }
}

/// The scene's rig as off-axis (`[0]`, the SGI course notes' shear) and as toe-in (`[1]`,
/// rotate), index 0 left and 1 right within each: everything else (separation, zero parallax,
/// balance, lighting, viewer) as the scene sets it.
///
/// # Errors
/// As [`StereoRig::eyes_for_image`].
pub fn shear_rotate_eyes(scene: &Scene) -> Result<[[EyeMatrices; 2]; 2]> {
    let rig = |mode| StereoRig { mode, ..scene.rig };
    let (w, h) = (scene.width, scene.height);
    Ok([
        rig(CameraMode::OffAxis).eyes_for_image(&scene.camera, w, h)?,
        rig(CameraMode::ToeIn).eyes_for_image(&scene.camera, w, h)?,
    ])
}

/// [`shear_rotate_eyes`] when `plan` runs a shear or rotate pass, `None` otherwise (so a rig
/// that only toe-in cannot represent never fails a plan that does not ask for it).
///
/// # Errors
/// As [`shear_rotate_eyes`].
pub fn planned_shear_rotate_eyes(
    scene: &Scene,
    plan: &Plan,
) -> Result<Option<[[EyeMatrices; 2]; 2]>> {
    let needed = plan.passes.iter().any(|p| {
        matches!(
            p.view,
            View::ShearLeft | View::ShearRight | View::RotateLeft | View::RotateRight
        )
    });
    needed.then(|| shear_rotate_eyes(scene)).transpose()
}

impl Frame {
    /// The matrices of every view, for a frame that is still being rendered.
    pub fn lookup(
        eyes: &[EyeMatrices; 2],
        center: &EyeMatrices,
        compare: &Option<[[EyeMatrices; 2]; 2]>,
        view: View,
    ) -> Result<EyeMatrices> {
        let m = match view {
            View::Left => Some(eyes[0]),
            View::Right => Some(eyes[1]),
            View::Center => Some(*center),
            View::ShearLeft => compare.map(|m| m[0][0]),
            View::ShearRight => compare.map(|m| m[0][1]),
            View::RotateLeft => compare.map(|m| m[1][0]),
            View::RotateRight => compare.map(|m| m[1][1]),
        };
        m.ok_or_else(|| {
            stereolab_core::Error::internal("plan", format!("no matrices for the {view:?} pass"))
        })
    }
}

/// Renders every pass of `plan`. Passes run in parallel (one per thread); each pass is itself
/// sequential, so the bytes never depend on the thread count.
///
/// # Errors
/// Invalid camera or rig, or an image size refused by [`Framebuffer::new`].
pub fn render(scene: &Scene, plan: &Plan) -> Result<Frame> {
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let center = StereoRig::center(&scene.camera, scene.aspect())?;
    let shear_rotate = planned_shear_rotate_eyes(scene, plan)?;
    let passes = plan
        .passes
        .par_iter()
        .map(|p| {
            let start = Instant::now();
            let m = Frame::lookup(&eyes, &center, &shear_rotate, p.view)?;
            let (framebuffer, stats) = render_view(scene, &m, p.shading)?;
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
        shear_rotate,
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
                rasterize_blinn_phong(
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
    // Image-shift: the shifted viewport covers only these columns (a scissor, on the GPU).
    let drawn = m.drawn_columns(scene.width);
    if drawn != (0..scene.width) {
        fb.clear_outside_columns(drawn, scene.background);
    }
    Ok((fb, total))
}
