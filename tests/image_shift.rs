//! Image-shift stereo (the StereoGraphics guide (Akka) §6): the parallel eyes
//! shifted apart when viewported by whole pixels. Measured on the images: the columns only one
//! eye covers, zero parallax at z0 within half a pixel, and each eye is the parallel eye moved.

use std::path::Path;

use stereolab::info::describe;
use stereolab::plan::{Output, Plan, View};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::{CameraMode, Framebuffer, ImageShift};

use crate::common::asset;

/// A backdrop filling the view at distance 20, and a red square tilted 30° about the view axis
/// at exactly the zero-parallax distance 10 (its slanted edges let its centroid be measured to
/// a small fraction of a pixel). The separation makes the exact total shift 8.6 px: rounded to
/// 9, split 4 (left) + 5 (right).
fn test_scene(mode: &str) -> Scene {
    let text = format!(
        r#"
outputs = ["left", "right"]
[image]
width = 320
height = 240
background = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.0, 10.0]
target = [0.0, 0.0, 0.0]
fov_y = 40.0
near = 1.0
far = 40.0
[stereo]
mode = "{mode}"
eye_separation = {separation}
zero_parallax = 10.0
[light]
position = [0.0, 0.0, 20.0]
specular = 0.0
[[mesh]]
kind = "plane"
size = 100.0
detail = 4
translate = [0.0, 0.0, -10.0]
color = [0.5, 0.5, 0.5]
[[mesh]]
kind = "plane"
size = 2.5
detail = 3
rotate = [0.0, 0.0, 30.0]
color = [1.0, 0.0, 0.0]
"#,
        // Xrange = 2·10·tan(20°)·4/3 = 9.7048; total shift d·W/Xrange = 8.6 px.
        separation = 8.6 * (2.0 * 10.0 * 20f64.to_radians().tan() * 4.0 / 3.0) / 320.0
    );
    Scene::from_toml(&text, Path::new("image_shift.toml"), Path::new("."), &[])
        .expect("test scene loads")
}

fn shift(s: &Scene) -> ImageShift {
    s.rig
        .image_shift(&s.camera, s.width, s.height)
        .expect("shift")
}

fn eyes(s: &Scene) -> Frame {
    render(s, &Plan::new(&[Output::Left, Output::Right])).expect("renders")
}

fn eye(f: &Frame, v: View) -> &Framebuffer {
    f.view(v).expect("eye pass")
}

/// Per column: does the eye draw anything there (any pixel with depth < 1)?
fn drawn_columns(fb: &Framebuffer) -> Vec<bool> {
    (0..fb.width())
        .map(|x| (0..fb.height()).any(|y| fb.depth()[fb.index(x, y)] < 1.0))
        .collect()
}

/// Columns from the left edge inwards, and from the right edge inwards, where exactly one eye
/// has content.
fn one_eye_columns(left: &Framebuffer, right: &Framebuffer) -> (usize, usize, Vec<usize>) {
    let (l, r) = (drawn_columns(left), drawn_columns(right));
    let odd: Vec<usize> = (0..l.len()).filter(|&x| l[x] != r[x]).collect();
    let from_left = (0..l.len()).take_while(|&x| l[x] != r[x]).count();
    let from_right = (0..l.len()).rev().take_while(|&x| l[x] != r[x]).count();
    (from_left, from_right, odd)
}

/// x centroid of the red square's pixels in one eye.
fn red_centroid(fb: &Framebuffer) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 0..fb.height() {
        for x in 0..fb.width() {
            let c = fb.pixel(x, y);
            if c[0] > 100 && c[1] < 60 && c[2] < 60 {
                sum += x as f64 + 0.5;
                n += 1;
            }
        }
    }
    assert!(n > 1000, "the red square is in view ({n} px)");
    sum / n as f64
}

#[test]
fn the_rounded_shift_is_split_between_the_eyes_and_balances_the_parallax() {
    let s = test_scene("image-shift");
    let sh = shift(&s);
    assert!((sh.exact_total - 8.6).abs() < 1e-3, "{sh:?}");
    assert_eq!((sh.left, sh.right, sh.total()), (4, 5, 9), "{sh:?}");
    // The balance the whole pixels apply, and the parallax report uses it: p(z0) = K − exact.
    assert!((sh.balance - 9.0 / 8.6).abs() < 1e-4, "{sh:?}");
    let p = s.parallax_rig().expect("rig");
    let at_z0 = p.parallax(10.0) * p.pixels_per_unit;
    assert!(
        (at_z0 - sh.zero_plane_error_pixels()).abs() < 1e-3 && at_z0.abs() <= 0.5,
        "p(z0) = {at_z0} px, rounding {}",
        sh.zero_plane_error_pixels()
    );
    let m = s
        .rig
        .eyes_for_image(&s.camera, s.width, s.height)
        .expect("eyes");
    assert_eq!((m[0].viewport_shift, m[1].viewport_shift), (-4, 5));
    // Without the image size the whole-pixel shift cannot be made: a clear error.
    let e = s.rig.eyes(&s.camera, s.aspect()).unwrap_err().to_string();
    assert!(e.contains("stereo.mode") && e.contains("image size"), "{e}");
}

#[test]
fn the_edge_columns_hold_one_eye_only_as_many_as_each_eye_moved() {
    let s = test_scene("image-shift");
    let sh = shift(&s);
    let f = eyes(&s);
    let (from_left, from_right, odd) = one_eye_columns(eye(&f, View::Left), eye(&f, View::Right));
    // The right eye moved right by 5: the leftmost 5 columns show the left eye only; the left
    // eye moved left by 4: the rightmost 4 show the right eye only. Nowhere else.
    assert_eq!(
        (from_left, from_right),
        (sh.right as usize, sh.left as usize)
    );
    assert_eq!(odd.len(), sh.total() as usize, "{odd:?}");
    // The blank columns are the clear colour.
    let right = eye(&f, View::Right);
    assert!((0..5).all(|x| (0..right.height()).all(|y| right.pixel(x, y) == s.background)));
    // Off-axis lines the edges up: no column holds one eye only.
    let o = eyes(&test_scene("off-axis"));
    assert_eq!(
        one_eye_columns(eye(&o, View::Left), eye(&o, View::Right))
            .2
            .len(),
        0
    );
    // info and the render report say it.
    let text = describe(&s).expect("info");
    assert!(
        text.contains("one eye only: 5 columns at the left edge (left eye), 4 at the right edge"),
        "{text}"
    );
    let report = stereolab::info::frame_budget_report(&f, &s)
        .expect("report")
        .expect("an eye ran");
    assert!(report.contains("one eye only: 5 columns"), "{report}");
}

#[test]
fn zero_parallax_plane_has_zero_parallax_within_half_a_pixel() {
    let s = test_scene("image-shift");
    let f = eyes(&s);
    let measured = red_centroid(eye(&f, View::Right)) - red_centroid(eye(&f, View::Left));
    let want = shift(&s).zero_plane_error_pixels();
    assert!(
        measured.abs() <= 0.5 && (measured - want).abs() < 0.05,
        "parallax of the square at z0: measured {measured} px, the rounding leaves {want}"
    );
    // Parallel axes without the shift: the square has the full −8.6 px.
    let p = eyes(&test_scene("parallel"));
    let unshifted = red_centroid(eye(&p, View::Right)) - red_centroid(eye(&p, View::Left));
    assert!((unshifted + 8.6).abs() < 0.05, "{unshifted}");
}

#[test]
fn each_eye_is_the_parallel_eye_moved_by_its_shift() {
    let s = test_scene("image-shift");
    let p = test_scene("parallel");
    let (fs, fp) = (eyes(&s), eyes(&p));
    let sh = shift(&s);
    for (view, k) in [
        (View::Left, -(sh.left as i64)),
        (View::Right, sh.right as i64),
    ] {
        let (a, b) = (eye(&fs, view), eye(&fp, view));
        let (mut same, mut compared) = (0usize, 0usize);
        for y in 0..a.height() {
            for x in 0..a.width() {
                let src = x as i64 - k;
                if src < 0 || src >= a.width() as i64 {
                    continue;
                }
                compared += 1;
                same += usize::from(a.pixel(x, y) == b.pixel(src as u32, y));
            }
        }
        // Equal but for vertices whose moved position rounds to another 1/256 px step.
        assert!(
            same as f64 >= 0.999 * compared as f64,
            "{view:?}: {same} of {compared} pixels equal the parallel eye moved by {k}"
        );
    }
    assert_eq!(s.rig.mode, CameraMode::ImageShift);
}

#[test]
fn shipped_scene_and_refusals() {
    let s = Scene::load(&asset("scenes/wuson_image_shift.toml"), &[]).expect("loads");
    let sh = shift(&s);
    assert!(sh.total() > 0 && sh.left.abs_diff(sh.right) <= 1, "{sh:?}");
    // A separation that shifts the eyes past each other is refused at load, naming the field.
    let e = Scene::load(
        &asset("scenes/wuson_image_shift.toml"),
        &["stereo.eye_separation=50".into()],
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("stereo.eye_separation") && e.contains("no column"),
        "{e}"
    );
}
