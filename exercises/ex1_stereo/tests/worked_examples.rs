//! Checks you can run yourself (`cargo test -p ex1_stereo`): the worked examples of the source
//! documents. They fail until your functions are complete; `stereolab grade ex1` scores more.

use exercise_api::{AnaglyphKind, StereoSetup};
use exercise_api::{Lighting, look_at};
use glam::{Mat4, Vec3, Vec4Swizzles};

/// The StereoGraphics guide's §5: camera at (0, 0, 9), 90° fov, separation 1, screen at the xy plane.
fn seed003() -> (StereoSetup, Mat4) {
    let setup = StereoSetup {
        fov_y_degrees: 90.0,
        aspect: 1.0,
        near: 1.0,
        far: 100.0,
        eye_separation: 1.0,
        zero_parallax: 9.0,
    };
    (
        setup,
        look_at(Vec3::new(0.0, 0.0, 9.0), Vec3::ZERO, Vec3::Y),
    )
}

#[test]
fn seed003_point_projects_to_5_875_left_and_6_125_right() {
    let (setup, mv) = seed003();
    for (eye, x) in [(0, 5.875), (1, 6.125)] {
        let m = ex1_stereo::stereo_matrices(&setup, mv, eye, Lighting::PerEye);
        let clip = m.projection * m.view * Vec3::new(8.0, -5.0, -3.0).extend(1.0);
        // NDC → the zero-parallax plane, which spans ±9 at 90° fov.
        let on_screen = clip.xy() / clip.w * 9.0;
        assert!(
            (on_screen.x - x).abs() < 1e-4 && (on_screen.y + 3.75).abs() < 1e-4,
            "eye {eye}: expected ({x}, -3.75), got {on_screen:?}"
        );
    }
}

#[test]
fn frustum_maps_near_to_minus_one_and_far_to_plus_one() {
    let p = ex1_stereo::frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 10.0);
    let ndc_z = |z: f32| {
        let c = p * glam::Vec4::new(0.0, 0.0, z, 1.0);
        c.z / c.w
    };
    assert!((ndc_z(-1.0) + 1.0).abs() < 1e-5, "near → {}", ndc_z(-1.0));
    assert!((ndc_z(-10.0) - 1.0).abs() < 1e-5, "far → {}", ndc_z(-10.0));
}

#[test]
fn point_on_the_screen_has_zero_parallax() {
    assert!(ex1_stereo::parallax(5.0, 5.0, 0.3).abs() < 1e-6);
    assert!(
        ex1_stereo::parallax(2.0, 5.0, 0.3) < 0.0,
        "in front of the screen is negative"
    );
}

#[test]
fn color_anaglyph_keeps_left_red_and_right_green_blue() {
    let m = ex1_stereo::anaglyph_matrices(AnaglyphKind::Color);
    assert_eq!(m.left[0], [1.0, 0.0, 0.0]);
    assert_eq!(m.right[1], [0.0, 1.0, 0.0]);
    assert_eq!(m.right[2], [0.0, 0.0, 1.0]);
}
