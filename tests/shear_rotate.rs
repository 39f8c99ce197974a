//! Shear vs rotate side by side (the SGI course notes §4.1.3), and the
//! viewer at one eye (§4.1.1).

use glam::Vec3;
use stereolab::output::shear_rotate::shear_vs_rotate;
use stereolab::plan::{Output, Plan, Shading, View};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{CameraMode, Viewer};

use crate::common::asset;

fn load(name: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::load(&asset(&format!("scenes/{name}.toml")), &sets).expect("scene loads")
}

#[test]
fn shear_vs_rotate_runs_both_rigs_eye_passes_and_nothing_else() {
    let plan = Plan::new(&[Output::ShearVsRotate]);
    let views: Vec<View> = plan.passes.iter().map(|p| p.view).collect();
    assert_eq!(
        views,
        [
            View::ShearLeft,
            View::ShearRight,
            View::RotateLeft,
            View::RotateRight
        ]
    );
    assert!(plan.passes.iter().all(|p| p.shading == Shading::Color));
    assert_eq!(
        Output::parse("shear_vs_rotate").expect("name"),
        Output::ShearVsRotate
    );
}

#[test]
fn toe_in_has_vertical_parallax_and_off_axis_none() {
    let mut s = load("wuson_shear_vs_rotate", &[]);
    s.set_size(320, 240).expect("size");
    let frame = render(&s, &Plan::new(&s.outputs)).expect("renders");
    let (img, n) = shear_vs_rotate(&frame).expect("output");
    eprintln!("{}", n.report());
    // Off-axis: parallel axes, the eyes differ by an x translation and shear: no vertical
    // parallax but rounding (the reprojection runs through an f32 depth buffer).
    assert!(n.shear_max_vertical < 1e-3, "{}", n.shear_max_vertical);
    // Toe-in: each eye rotated by atan((d/2)/z0) = 3.7°; off the centre lines the two images of
    // a point sit at different heights (the StereoGraphics guide (Akka) §5).
    assert!(n.rotate_max_vertical > 0.5, "{}", n.rotate_max_vertical);
    // The two rigs' images of the same eye differ (rotation moves everything off-centre).
    assert!(n.left.share() > 0.1 && n.right.share() > 0.1, "{n:?}");
    assert_eq!(n.left.pixels, 320 * 240);
    assert_eq!(img.width(), 2 * 320);
    assert!(img.height() > 2 * 240);
    let r = n.report();
    assert!(r.contains("toe-in vertical parallax up to") && r.contains("differing"));

    // Half the separation: toe-in's angle halves, and so (to first order) does its vertical
    // parallax.
    let mut half = load("wuson_shear_vs_rotate", &["stereo.eye_separation=0.3"]);
    half.set_size(320, 240).expect("size");
    let (_, h) = shear_vs_rotate(&render(&half, &Plan::new(&half.outputs)).expect("renders"))
        .expect("output");
    let ratio = h.rotate_max_vertical / n.rotate_max_vertical;
    assert!((0.4..0.6).contains(&ratio), "ratio {ratio}");
}

#[test]
fn the_comparison_passes_are_the_scene_rig_in_each_mode() {
    for (mode, same) in [("off-axis", View::ShearLeft), ("toe-in", View::RotateLeft)] {
        let mut s = load(
            "wuson_shear_vs_rotate",
            &[&format!("stereo.mode=\"{mode}\"")],
        );
        s.set_size(160, 120).expect("size");
        let f = render(&s, &Plan::new(&[Output::Left, Output::ShearVsRotate])).expect("renders");
        assert_eq!(
            f.view(View::Left).expect("left"),
            f.view(same).expect("compare pass"),
            "{mode}: the scene's own left eye is the {same:?} pass"
        );
    }
}

/// The camera's right axis (world).
fn right_axis(s: &Scene) -> Vec3 {
    s.camera.view().inverse().transform_vector3(Vec3::X)
}

#[test]
fn viewer_at_the_left_eye_puts_the_left_eye_at_the_camera() {
    let s = load("wuson_viewer_left_eye", &[]);
    assert_eq!(s.rig.viewer, Viewer::LeftEye);
    let cam = Vec3::from(s.camera.eye);
    let d = s
        .rig
        .resolve(&s.camera, s.aspect())
        .expect("rig")
        .eye_separation;
    assert!(d > 0.1);
    for mode in [
        CameraMode::OffAxis,
        CameraMode::ToeIn,
        CameraMode::Parallel,
        CameraMode::ImageShift,
    ] {
        let rig = stereolab_core::StereoRig { mode, ..s.rig };
        let e = rig
            .eyes_for_image(&s.camera, s.width, s.height)
            .expect("eyes");
        let want_right = cam + d * right_axis(&s);
        assert!(
            e[0].eye_world.distance(cam) < 1e-4,
            "{mode:?}: left {:?}",
            e[0].eye_world
        );
        assert!(
            e[1].eye_world.distance(want_right) < 1e-4,
            "{mode:?}: right {:?} vs {want_right:?}",
            e[1].eye_world
        );
        // The midpoint viewer: the camera halfway between the eyes.
        let mid = stereolab_core::StereoRig {
            viewer: Viewer::Midpoint,
            ..rig
        }
        .eyes_for_image(&s.camera, s.width, s.height)
        .expect("eyes");
        let centre = (mid[0].eye_world + mid[1].eye_world) * 0.5;
        assert!(centre.distance(cam) < 1e-4, "{mode:?}: {centre:?}");
        assert!((mid[1].eye_world - mid[0].eye_world).length() - d < 1e-4);
    }
    // Toe-in: both eyes still aim at the fusion point on the centre line between them.
    let toe = stereolab_core::StereoRig {
        mode: CameraMode::ToeIn,
        ..s.rig
    };
    let e = toe
        .eyes_for_image(&s.camera, s.width, s.height)
        .expect("eyes");
    let z0 = s
        .rig
        .resolve(&s.camera, s.aspect())
        .expect("rig")
        .zero_parallax_distance;
    let dir = (Vec3::from(s.camera.target) - cam).normalize();
    let fusion = cam + 0.5 * d * right_axis(&s) + z0 * dir;
    for m in e {
        let p = m.mvp.project_point3(fusion);
        assert!(p.x.abs() < 1e-4 && p.y.abs() < 1e-4, "{p:?}");
    }
    let f = render(&s, &Plan::new(&s.outputs)).expect("renders");
    assert!(f.view(View::Left).is_some() && f.view(View::Right).is_some());
    // A wrong word names the field and the choices.
    let e = Scene::load(
        &asset("scenes/wuson_viewer_left_eye.toml"),
        &["stereo.viewer=\"right-eye\"".into()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("viewer") && e.contains("left-eye"), "{e}");
}
