//! Golden images: the deterministic path must reproduce the committed PNGs byte for byte.
//! Regenerate only on purpose: `UPDATE_GOLDENS=1 cargo test golden`.

use stereolab::plan::{Output, Plan, View};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::Framebuffer;

use crate::common::{asset, failure_dir};

/// Compares `actual`'s colours with `assets/golden/NAME.png` byte for byte (or writes it with
/// `UPDATE_GOLDENS=1`).
pub(crate) fn check_golden(name: &str, actual: &Framebuffer) {
    let path = asset(&format!("golden/{name}.png"));
    if std::env::var_os("UPDATE_GOLDENS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        actual.to_rgba_image().save(&path).unwrap();
        return;
    }
    let expected = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (run with UPDATE_GOLDENS=1 to create)",
                path.display()
            )
        })
        .to_rgba8();
    let mut exp_fb = Framebuffer::new(expected.width(), expected.height(), [0; 4]).unwrap();
    for (dst, src) in exp_fb.color_mut().iter_mut().zip(expected.pixels()) {
        *dst = src.0;
    }
    if exp_fb.color() != actual.color() {
        let m = stereolab::compare::compare(&exp_fb, actual);
        let strip = stereolab::compare::write_diff_strip(
            &exp_fb,
            actual,
            &failure_dir(),
            &format!("golden_{name}"),
        );
        panic!(
            "{name} differs from {}: {m:?}; wrote {strip:?}",
            path.display()
        );
    }
}

#[test]
fn wuson_pair_matches_golden_pngs() {
    let mut scene = Scene::load(&asset("scenes/wuson.toml"), &[]).unwrap();
    scene.set_size(128, 96).unwrap();
    let frame = render(&scene, &Plan::new(&[Output::Left, Output::Right])).unwrap();
    check_golden("wuson_left_128x96", frame.view(View::Left).unwrap());
    check_golden("wuson_right_128x96", frame.view(View::Right).unwrap());
}

#[test]
fn primitives_with_cyclopic_toe_in_match_golden_png() {
    let text = r#"
outputs = ["left"]
[image]
width = 96
height = 72
[camera]
eye = [0, 1, 6]
target = [0, 0, 0]
near = 1
far = 20
[stereo]
mode = "toe-in"
eye_separation = 0.4
zero_parallax = 6
lighting = "cyclopic"
[[mesh]]
kind = "sphere"
translate = [-1.2, 0, 0]
color = [0.9, 0.2, 0.2]
[[mesh]]
kind = "torus"
size = 0.8
minor = 0.25
rotate = [60, 0, 0]
translate = [1.2, 0, 0]
color = [0.2, 0.5, 0.9]
[[mesh]]
kind = "cube"
size = 1.2
rotate = [30, 40, 0]
translate = [0, 0, -2]
[[mesh]]
kind = "plane"
size = 8
rotate = [-90, 0, 0]
translate = [0, -1, 0]
color = [0.3, 0.7, 0.3]
"#;
    let scene = Scene::from_toml(
        text,
        std::path::Path::new("inline.toml"),
        std::path::Path::new("."),
        &[],
    )
    .unwrap();
    let frame = render(&scene, &Plan::new(&scene.outputs)).unwrap();
    check_golden("primitives_left_96x72", frame.view(View::Left).unwrap());
}
