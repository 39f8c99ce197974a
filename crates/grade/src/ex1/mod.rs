//! Exercise 1 (the exercise slides): the tasks, their reference answers, known mistakes and image checks.
//!
//! One file per task group: `frustum` (mono and stereo frusta), `sheet` (the stereo frusta in
//! the exercise slides' screen-relative terms), `rig` (the stereo rig's view and projection
//! matrices), `anaglyph` (anaglyph and Dubois matrices), `finalize` (the finalize shader's
//! anaglyph pixel), `remap` (remapping in both directions), `visible` (occlusion), `rds` (the
//! random-dot pair built from both) and `parallax` (parallax and its color map). This file holds the task list and the helpers they
//! share.

mod anaglyph;
mod finalize;
mod frustum;
mod parallax;
mod rds;
mod remap;
mod rig;
mod sheet;
mod visible;

use super::fixture::{Fixture, reference_rig};
use super::spec::{SplitMix64, TaskSpec, Tolerance};
use crate::exercise::{Answer, StereoSetup};
use stereolab_core::{Camera, CameraMode, EyeMatrices, Framebuffer, Lighting};

#[cfg(feature = "gpu")]
pub(crate) use rig::{eye_matrices_from_answer, eye_view_input};

pub(crate) fn flat<A: Answer>(a: &A) -> Vec<f64> {
    let mut v = Vec::new();
    a.flatten(&mut v);
    v
}

/// Every task of exercise 1.
pub(crate) fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![
        frustum::frustum_task(fx),
        frustum::stereo_frustum_task(fx),
        sheet::sheet_frustum_task(),
        rig::stereo_matrices_task(fx),
        anaglyph::anaglyph_task(fx),
        finalize::finalize_task(fx),
        anaglyph::dubois_task(),
        remap::remap_task(fx),
        remap::remap_right_to_left_task(fx),
        visible::visible_task(fx),
        rds::rds_task(fx),
        parallax::parallax_task(),
        parallax::parallax_color_task(fx),
    ]
}

const MATRIX_TOLERANCE: Tolerance = Tolerance {
    abs: 1e-5,
    rel: 1e-4,
    why: "f32 arithmetic in another order differs by ~1e-6 relative; elements that should be 0 \
          come out near 1e-7 after a product with an inverse",
};

/// A camera with `setup`'s frustum looking from `eye` at `target`.
fn camera(setup: &StereoSetup, eye: [f32; 3], target: [f32; 3]) -> Camera {
    Camera {
        eye,
        target,
        up: [0.0, 1.0, 0.0],
        fov_y: setup.fov_y_degrees,
        near: setup.near,
        far: setup.far,
    }
}

/// The setups the numeric stereo checks use: the fixture's, the StereoGraphics guide's worked example, and a
/// wide, close one.
fn setups(fx: &Fixture) -> Vec<(StereoSetup, Camera)> {
    let guide = StereoSetup {
        fov_y_degrees: 90.0,
        aspect: 1.0,
        near: 1.0,
        far: 100.0,
        eye_separation: 1.0,
        zero_parallax: 9.0,
    };
    let wide = StereoSetup {
        fov_y_degrees: 70.0,
        aspect: 16.0 / 9.0,
        near: 0.3,
        far: 40.0,
        eye_separation: 0.065,
        zero_parallax: 2.0,
    };
    vec![
        (fx.setup, fx.scene.camera.clone()),
        (guide, camera(&guide, [0.0, 0.0, 9.0], [0.0, 0.0, 0.0])),
        (wide, camera(&wide, [3.0, 2.0, -1.0], [0.0, 0.5, 0.0])),
    ]
}

/// Hidden cases per ex1 task that draws random setups.
const HIDDEN_SETUPS: usize = 4;

/// A random but valid setup and camera for hidden cases: any field of view, aspect, near/far,
/// separation and zero-parallax distance a course scene could use, and a camera looking at a
/// point near the origin from any azimuth and from up to 60° above or below (so that the eye's
/// x axis is rotated about Y and X, and `up` is never parallel to the view direction).
fn random_setup(rng: &mut SplitMix64) -> (StereoSetup, Camera) {
    let near = rng.range(0.1, 2.0);
    let far = near * rng.range(10.0, 200.0);
    let s = StereoSetup {
        fov_y_degrees: rng.range(30.0, 100.0),
        aspect: rng.range(0.75, 2.0),
        near,
        far,
        eye_separation: rng.range(0.03, 1.0),
        zero_parallax: rng.range(1.5 * near, 0.5 * far),
    };
    let target = [
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
    ];
    let azimuth = rng.range(0.0, std::f32::consts::TAU);
    let elevation = rng.range(-60.0, 60.0).to_radians();
    let dist = rng.range(3.0, 10.0);
    let eye = [
        target[0] + dist * elevation.cos() * azimuth.sin(),
        target[1] + dist * elevation.sin(),
        target[2] + dist * elevation.cos() * azimuth.cos(),
    ];
    (s, camera(&s, eye, target))
}

/// The reference eyes for a setup with a changed separation, mode and lighting.
fn eyes(
    setup: &StereoSetup,
    cam: &Camera,
    separation: f32,
    mode: CameraMode,
    lighting: Lighting,
) -> [EyeMatrices; 2] {
    let s = StereoSetup {
        eye_separation: separation,
        ..*setup
    };
    let mut rig = reference_rig(&s, lighting);
    rig.mode = mode;
    rig.eyes(cam, setup.aspect)
        .expect("the grader's own setups are valid")
}

/// An empty framebuffer of `like`'s size: the picture of a missing answer.
pub(crate) fn blank(like: &Framebuffer, background: [u8; 4]) -> Framebuffer {
    Framebuffer::new(like.width(), like.height(), background).expect("same size as a valid one")
}

/// Covered pixels of the left view, with their texture coordinate and stored depth.
fn left_samples(fx: &Fixture) -> Vec<(u32, u32, [f32; 2], f32)> {
    view_samples(fx, 0)
}

/// Covered pixels of eye `eye`'s view, with their texture coordinate and stored depth.
fn view_samples(fx: &Fixture, eye: usize) -> Vec<(u32, u32, [f32; 2], f32)> {
    let (w, h) = fx.size();
    let left = &fx.views[eye];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter_map(|(x, y)| {
            let d = left.depth()[left.index(x, y)];
            (d < 1.0).then(|| (x, y, fx.uv(x, y), d))
        })
        .collect()
}
