//! `zero_parallax = "auto"` and `"fit"`, the budget's two remedies, and the
//! field-of-view advice (the StereoGraphics guide (Akka) §7–8).

use glam::Vec3;
use stereolab::info::{describe, horizontal_fov_degrees, scene_budget};
use stereolab::scene::Scene;
use stereolab_core::{PARALLAX_BUDGET_PERCENT, ZeroParallax};

use crate::common::asset;

fn load(name: &str, sets: &[String]) -> Scene {
    Scene::load(&asset(&format!("scenes/{name}.toml")), sets).expect("scene loads")
}

fn z0(s: &Scene) -> f32 {
    match s.rig.zero_parallax {
        ZeroParallax::Distance(z) => z,
        other => panic!("auto/fit must resolve to a distance, got {other:?}"),
    }
}

/// Worst |parallax| in percent of the width, and (min, max) in percent.
fn range(s: &Scene) -> (f64, f64, f64) {
    let b = scene_budget(s).expect("budget");
    let (lo, hi) = (b.percent(b.min_pixels), b.percent(b.max_pixels));
    (lo.abs().max(hi.abs()), lo, hi)
}

#[test]
fn auto_is_the_camera_target_distance_and_fits_the_budget() {
    let s = load("wuson_zero_parallax_auto", &[]);
    let want = (Vec3::from(s.camera.target) - Vec3::from(s.camera.eye)).length();
    assert!((z0(&s) - want).abs() < 1e-5, "z0 {} vs {want}", z0(&s));
    let (worst, lo, hi) = range(&s);
    assert!(
        lo < 0.0 && hi > 0.0,
        "the subject straddles the screen: {lo}..{hi}"
    );
    assert!(worst <= PARALLAX_BUDGET_PERCENT as f64, "{lo}..{hi}");
}

#[test]
fn fit_is_the_harmonic_mean_of_the_visible_depths_and_balances_the_range() {
    let s = load("wuson_zero_parallax_fit", &[]);
    // Independently: eye distances of the vertices inside the vertical field of view.
    let view = s.camera.view();
    let t = (s.camera.fov_y.to_radians() * 0.5).tan();
    let (mut near, mut far) = (f32::INFINITY, 0.0f32);
    for p in s.world_points() {
        let e = view.transform_point3(p);
        let z = -e.z;
        if z > s.camera.near && z < s.camera.far && e.y.abs() <= t * z {
            near = near.min(z);
            far = far.max(z);
        }
    }
    let harmonic = 2.0 / (1.0 / near + 1.0 / far);
    assert!(
        (z0(&s) - harmonic).abs() < 1e-4,
        "z0 {} vs {harmonic}",
        z0(&s)
    );
    let (worst, lo, hi) = range(&s);
    assert!(lo < 0.0 && hi > 0.0, "{lo}..{hi}");
    assert!(worst <= PARALLAX_BUDGET_PERCENT as f64, "{lo}..{hi}");
    // Balanced: the two ends within 20% of each other, and a smaller worst end than "auto".
    assert!((lo.abs() - hi).abs() < 0.2 * worst, "{lo}..{hi}");
    let (auto_worst, ..) = range(&load("wuson_zero_parallax_auto", &[]));
    assert!(worst < auto_worst, "fit {worst}% vs auto {auto_worst}%");
}

#[test]
fn over_budget_report_names_both_remedies_and_each_works() {
    let s = load("wuson_no_zero_parallax", &[]);
    let (worst, lo, _) = range(&s);
    assert!(
        lo < -9.0 && worst > 9.0,
        "the unfixed scene is far over budget: {lo}"
    );
    let text = describe(&s).expect("info");
    let number_after = |key: &str| -> String {
        let at = text
            .find(key)
            .unwrap_or_else(|| panic!("{key:?} missing in:\n{text}"));
        text[at + key.len()..]
            .split_whitespace()
            .next()
            .expect("a number")
            .to_string()
    };
    let z = number_after("stereo.zero_parallax = ");
    let d = number_after("stereo.eye_separation = ");
    for set in [
        format!("stereo.zero_parallax={z}"),
        format!("stereo.eye_separation={d}"),
    ] {
        let fixed = load("wuson_no_zero_parallax", std::slice::from_ref(&set));
        let (w, lo, hi) = range(&fixed);
        // Printed to 3–4 decimals: allow that rounding.
        assert!(
            w <= PARALLAX_BUDGET_PERCENT as f64 + 0.01,
            "{set}: {lo}..{hi}"
        );
    }
}

#[test]
fn info_prints_the_horizontal_fov_and_warns_under_50_degrees() {
    assert!((horizontal_fov_degrees(40.0, 4.0 / 3.0) - 51.78).abs() < 0.01);
    assert!((horizontal_fov_degrees(90.0, 1.0) - 90.0).abs() < 1e-3);
    let wide = describe(&load("wuson", &[])).expect("info");
    assert!(wide.contains("horizontal field of view 51.8°"), "{wide}");
    assert!(!wide.contains("is under 50°"), "{wide}");
    let narrow = describe(&load("wuson_narrow_fov", &[])).expect("info");
    assert!(
        narrow.contains("horizontal field of view 32.9°"),
        "{narrow}"
    );
    assert!(
        narrow.contains("warning: horizontal field of view 32.9° is under 50°"),
        "{narrow}"
    );
}
