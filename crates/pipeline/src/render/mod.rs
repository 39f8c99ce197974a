//! The passes: runs a plan's rasterizations over a scene and returns their framebuffers.
//!
//! - [`render`]: the eye passes (Blinn-Phong color or depth only) and the center pass;
//! - [`chromadepth`]: the ChromaDepth pass (texgen into the ramp).
//!
//! The SIRDS paper's per-vertex strip passes are the core's
//! ([`per_vertex`](stereolab_core::per_vertex)); `output::sirds` runs them on a scene.

pub mod chromadepth;
#[cfg(test)]
mod strip_tests;

use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::plan::{Pass, Plan, Shading, View};
use crate::scene::Scene;
use stereolab_core::{
    BlinnPhong, CameraMode, DepthOnly, Eye, EyeMatrices, Framebuffer, RasterStats, Result,
    StereoRig, rasterize, rasterize_blinn_phong,
};

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
    /// The matrices of every view the plan renders.
    pub views: ViewMatrices,
}

/// The matrices of every view a frame renders, made once per frame.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewMatrices {
    /// The scene's rig: left and right eye, indexed by [`Eye::index`].
    pub eyes: [EyeMatrices; 2],
    /// The cyclopean eye: the camera itself.
    pub center: EyeMatrices,
    /// The [`View::ShearLeft`] … [`View::RotateRight`] passes' eyes, present when the plan runs
    /// them ([`shear_rotate_eyes`]).
    pub shear_rotate: Option<ShearRotate>,
    /// The [`View::Multi`] cameras, index 0 the leftmost, when the plan runs them
    /// ([`StereoRig::views`]: as many as the plan's highest multiview pass needs); empty
    /// otherwise.
    pub multi: Vec<EyeMatrices>,
}

/// The scene's rig as off-axis (the SGI course notes' shear) and as toe-in (rotate), each eye
/// pair indexed by [`Eye::index`]; everything else (separation, zero parallax, balance,
/// lighting, viewer) as the scene sets it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShearRotate {
    /// The off-axis eyes.
    pub shear: [EyeMatrices; 2],
    /// The toe-in eyes.
    pub rotate: [EyeMatrices; 2],
}

impl ViewMatrices {
    /// The matrices of `plan`'s views of `scene`: the rig's eyes, the center, and the
    /// shear/rotate comparison's eyes only when the plan runs it (so a rig that only toe-in
    /// cannot represent never fails a plan that does not ask for it).
    ///
    /// # Errors
    /// As [`StereoRig::eyes_for_image`] and [`StereoRig::center`].
    pub fn new(scene: &Scene, plan: &Plan) -> Result<ViewMatrices> {
        let needed = plan.passes.iter().any(|p| {
            matches!(
                p.view,
                View::ShearLeft | View::ShearRight | View::RotateLeft | View::RotateRight
            )
        });
        // The multiview cameras' count is the plan's: every multiview output carries the
        // scene's `multiview.views`, and the plan runs that many passes.
        let views = plan
            .outputs
            .iter()
            .filter_map(|o| o.views())
            .max()
            .map(u32::from);
        let multi = match views {
            Some(n) => scene
                .rig
                .views(&scene.camera, scene.width, scene.height, n)?,
            None => Vec::new(),
        };
        Ok(ViewMatrices {
            eyes: scene
                .rig
                .eyes_for_image(&scene.camera, scene.width, scene.height)?,
            center: StereoRig::center(&scene.camera, scene.aspect())?,
            shear_rotate: needed.then(|| shear_rotate_eyes(scene)).transpose()?,
            multi,
        })
    }

    /// The matrices of `view`; `None` for a shear/rotate view the plan does not run. The one
    /// place a view is mapped to its matrices.
    pub fn get(&self, view: View) -> Option<&EyeMatrices> {
        let (l, r) = (Eye::Left.index(), Eye::Right.index());
        let compare = self.shear_rotate.as_ref();
        match view {
            View::Left => Some(&self.eyes[l]),
            View::Right => Some(&self.eyes[r]),
            View::Center => Some(&self.center),
            View::ShearLeft => compare.map(|c| &c.shear[l]),
            View::ShearRight => compare.map(|c| &c.shear[r]),
            View::RotateLeft => compare.map(|c| &c.rotate[l]),
            View::RotateRight => compare.map(|c| &c.rotate[r]),
            View::Multi(i) => self.multi.get(usize::from(i)),
        }
    }

    /// [`ViewMatrices::get`] for a pass of the plan these were made for.
    ///
    /// # Errors
    /// `Internal` when the plan's pass has no matrices (a plan bug).
    pub fn of_pass(&self, view: View) -> Result<EyeMatrices> {
        self.get(view).copied().ok_or_else(|| {
            stereolab_core::Error::internal("plan", format!("no matrices for the {view:?} pass"))
        })
    }
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
    pub fn draw_buffer(&self, buffer: stereolab_core::DrawBuffer) -> Option<&Framebuffer> {
        self.view(buffer.eye().into())
    }

    /// The matrices of `view`; `None` for a shear/rotate view the plan did not run.
    pub fn try_matrices(&self, view: View) -> Option<&EyeMatrices> {
        self.views.get(view)
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

/// The scene's rig as off-axis and as toe-in ([`ShearRotate`]).
///
/// # Errors
/// As [`StereoRig::eyes_for_image`].
pub fn shear_rotate_eyes(scene: &Scene) -> Result<ShearRotate> {
    let rig = |mode| StereoRig { mode, ..scene.rig };
    let (w, h) = (scene.width, scene.height);
    Ok(ShearRotate {
        shear: rig(CameraMode::OffAxis).eyes_for_image(&scene.camera, w, h)?,
        rotate: rig(CameraMode::ToeIn).eyes_for_image(&scene.camera, w, h)?,
    })
}

/// Renders every pass of `plan`. Passes run in parallel (one per thread); each pass is itself
/// sequential, so the bytes never depend on the thread count.
///
/// # Errors
/// Invalid camera or rig, or an image size refused by [`Framebuffer::new`].
pub fn render(scene: &Scene, plan: &Plan) -> Result<Frame> {
    let views = ViewMatrices::new(scene, plan)?;
    let passes = plan
        .passes
        .par_iter()
        .map(|p| {
            let start = Instant::now();
            let m = views.of_pass(p.view)?;
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
        views,
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
        total.clip_range.merge(s.clip_range);
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
