//! Checks you can run yourself (`cargo test -p ex1_stereo`): the worked examples of the source
//! documents. They fail until your functions are complete; `stereolab grade ex1` scores more.

use exercise_api::{AnaglyphKind, Eye, ScreenSetup, StereoSetup, Texture};
use exercise_api::{Lighting, look_at};
use glam::{Mat4, Vec3, Vec4Swizzles};

/// The StereoGraphics guide's §5: camera at (0, 0, 9), 90° fov, separation 1, screen at the xy plane.
fn stereographics_guide() -> (StereoSetup, Mat4) {
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
fn stereographics_guide_point_projects_to_5_875_left_and_6_125_right() {
    let (setup, mv) = stereographics_guide();
    for (eye, x) in [(Eye::Left, 5.875), (Eye::Right, 6.125)] {
        let m = ex1_stereo::stereo_matrices(&setup, mv, eye, Lighting::PerEye);
        let clip = m.projection * m.view * Vec3::new(8.0, -5.0, -3.0).extend(1.0);
        // NDC → the zero-parallax plane, which spans ±9 at 90° fov.
        let on_screen = clip.xy() / clip.w * 9.0;
        assert!(
            (on_screen.x - x).abs() < 1e-4 && (on_screen.y + 3.75).abs() < 1e-4,
            "{eye:?} eye: expected ({x}, -3.75), got {on_screen:?}"
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

/// The StereoGraphics guide's example in the exercise slides' screen-relative terms: the camera
/// is 9 in front of the screen with a 90° field of view, so the screen spans w = h = 18 there;
/// the separation 1 is d = 1/18 of the screen width.
#[test]
fn stereographics_example_in_the_sheets_terms_projects_to_5_875_and_6_125() {
    let screen = ScreenSetup {
        width: 18.0,
        height: 18.0,
        near: 1.0,
        far: 100.0,
        zero_parallax: 9.0,
        eye_separation_fraction: 1.0 / 18.0,
    };
    let mv = look_at(Vec3::new(0.0, 0.0, 9.0), Vec3::ZERO, Vec3::Y);
    for (eye, x) in [(Eye::Left, 5.875), (Eye::Right, 6.125)] {
        let [l, r, b, t, n, f] = ex1_stereo::sheet_frustum(&screen, eye);
        assert!(
            (t - 1.0).abs() < 1e-6 && (b + 1.0).abs() < 1e-6,
            "t = ½·h·n/z0 = 1: {t}"
        );
        // T± moves the eye at x = ∓½·d·w = ∓0.5 to the origin: translate(±0.5, 0, 0).
        let half = 0.5 * screen.eye_separation_fraction * screen.width;
        let shift = -eye.sign() * half;
        let mvp = ex1_stereo::frustum(l, r, b, t, n, f)
            * Mat4::from_translation(Vec3::new(shift, 0.0, 0.0))
            * mv;
        let clip = mvp * Vec3::new(8.0, -5.0, -3.0).extend(1.0);
        let on_screen = clip.xy() / clip.w * 9.0;
        assert!(
            (on_screen.x - x).abs() < 1e-4 && (on_screen.y + 3.75).abs() < 1e-4,
            "{eye:?} eye: expected ({x}, -3.75), got {on_screen:?}"
        );
    }
}

#[test]
fn remapping_to_the_right_and_back_returns_to_the_same_left_pixel() {
    let (setup, mv) = stereographics_guide();
    let mvp = |eye| {
        let m = ex1_stereo::stereo_matrices(&setup, mv, eye, Lighting::PerEye);
        m.projection * m.view
    };
    let (l, r) = (mvp(Eye::Left), mvp(Eye::Right));
    let uv = glam::Vec2::new(0.3, 0.6);
    let there = ex1_stereo::remap(l, r, uv, 0.95).expect("in front of the right eye");
    let back = ex1_stereo::remap_right_to_left(l, r, there.truncate(), there.z)
        .expect("in front of the left eye");
    assert!(
        (back.truncate() - uv).length() < 1e-4 && (back.z - 0.95).abs() < 1e-4,
        "{uv:?} at depth 0.95 → {there:?} → {back:?}"
    );
}

/// The random-dot pair of a wall facing the StereoGraphics guide's rig at eye distance `z`, in
/// a 36×36 image (the 18-unit wide screen at z0 = 9 is 2 pixels per unit): returns the left
/// dots, the fresh dots and the right dots.
fn rds_of_a_wall(z: f32) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
    let (setup, mv) = stereographics_guide();
    let mvp = |eye| {
        let m = ex1_stereo::stereo_matrices(&setup, mv, eye, Lighting::PerEye);
        m.projection * m.view
    };
    let (l, r) = (mvp(Eye::Left), mvp(Eye::Right));
    // The wall's window depth (the same for both eyes: the off-axis eyes share their z).
    let clip = l * Vec3::new(0.0, 0.0, 9.0 - z).extend(1.0);
    let depth = 0.5 * (clip.z / clip.w + 1.0);
    let n = 36;
    let left_dots = Texture {
        width: n,
        height: n,
        texels: (0..n * n).map(|i| (i * 7 + i / n) % 3 == 0).collect(),
    };
    let fresh = Texture::new(n, n, true);
    let depths = Texture::new(n, n, depth);
    let right = ex1_stereo::rds_right(l, r, &depths, &depths, &left_dots, &fresh, 1e-3);
    assert_eq!(right.texels.len(), n * n, "one dot per pixel");
    (left_dots.texels, fresh.texels, right.texels)
}

#[test]
fn random_dots_on_the_screen_plane_are_the_same_in_both_eyes() {
    let (left, _, right) = rds_of_a_wall(9.0);
    assert!(
        left == right,
        "zero parallax at z0: the right dots are the left dots"
    );
}

#[test]
fn random_dots_on_a_wall_behind_the_screen_shift_right_by_its_parallax() {
    // p(18) = d·(1 − z0/z) = 1·(1 − 9/18) = 0.5 units = 1 pixel: right pixel x shows left
    // pixel x − 1; column 0 of the right image sees what the left eye cannot: a fresh dot.
    let (left, fresh, right) = rds_of_a_wall(18.0);
    for y in 0..36 {
        for x in 0..36 {
            let want = if x == 0 {
                fresh[y * 36]
            } else {
                left[y * 36 + x - 1]
            };
            assert_eq!(right[y * 36 + x], want, "right pixel ({x}, {y})");
        }
    }
}

#[test]
fn finalize_true_anaglyph_of_white_is_magenta_and_sums_are_clamped() {
    let m = ex1_stereo::anaglyph_matrices(AnaglyphKind::True);
    // The luminance weights sum to 1: white in both eyes gives full red and full blue.
    let out = ex1_stereo::finalize_pixel([1.0; 3], [1.0; 3], &m);
    assert!(
        (out[0] - 1.0).abs() < 1e-6 && out[1] == 0.0 && (out[2] - 1.0).abs() < 1e-6,
        "{out:?}"
    );
    let twice = exercise_api::AnaglyphMatrices {
        left: m.left.map(|row| row.map(|x| 2.0 * x)),
        right: m.right.map(|row| row.map(|x| -x)),
    };
    assert_eq!(
        ex1_stereo::finalize_pixel([1.0; 3], [1.0; 3], &twice),
        [1.0, 0.0, 0.0]
    );
}
