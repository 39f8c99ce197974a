//! The stereo rig against the SGI course notes, the StereoGraphics guide (Akka) and the exercise slides.

use glam::{Vec3, Vec3Swizzles};
use proptest::prelude::*;
use stereolab_core::{
    Camera, CameraMode, Error, Lighting, Separation, StereoRig, ZeroParallax, frustum, project_ndc,
};

fn guide_camera() -> Camera {
    // The StereoGraphics guide's §5: camera at (0, 0, 9) looking at the xy plane; fov 90° so the plane spans ±9.
    Camera {
        eye: [0.0, 0.0, 9.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y: 90.0,
        near: 1.0,
        far: 100.0,
    }
}

fn rig(mode: CameraMode, separation: f32, z0: f32) -> StereoRig {
    StereoRig {
        mode,
        separation: Separation::Absolute(separation),
        zero_parallax: ZeroParallax::Distance(z0),
        ..StereoRig::default()
    }
}

#[test]
fn guides_worked_example_projects_to_5_875_and_6_125() {
    let cam = guide_camera();
    let eyes = rig(CameraMode::OffAxis, 1.0, 9.0).eyes(&cam, 1.0).unwrap();
    // NDC → coordinates on the zero-parallax plane z = 0, which spans ±9 (tan 45° · 9).
    let on_plane = |m: &glam::Mat4| project_ndc(m, Vec3::new(8.0, -5.0, -3.0)).unwrap().xy() * 9.0;
    let (l, r) = (on_plane(&eyes[0].mvp), on_plane(&eyes[1].mvp));
    assert!(
        (l.x - 5.875).abs() < 1e-5 && (l.y + 3.75).abs() < 1e-5,
        "left {l}"
    );
    assert!(
        (r.x - 6.125).abs() < 1e-5 && (r.y + 3.75).abs() < 1e-5,
        "right {r}"
    );
}

#[test]
fn frustum_matches_the_exercise_slides_entries() {
    let (l, r, b, t, n, f) = (-0.3f32, 0.5, -0.2, 0.4, 0.7, 11.0);
    let m = frustum(l, r, b, t, n, f);
    let expect = [
        [2.0 * n / (r - l), 0.0, (r + l) / (r - l), 0.0],
        [0.0, 2.0 * n / (t - b), (t + b) / (t - b), 0.0],
        [0.0, 0.0, (n + f) / (n - f), 2.0 * n * f / (n - f)],
        [0.0, 0.0, -1.0, 0.0],
    ];
    for (i, row) in expect.iter().enumerate() {
        for (j, e) in row.iter().enumerate() {
            assert!(
                (m.row(i)[j] - e).abs() < 1e-6,
                "P[{i}][{j}] = {} expected {e}",
                m.row(i)[j]
            );
        }
    }
    // Near plane maps to NDC z = −1, far plane to +1 (OpenGL).
    let near = m * glam::Vec4::new(0.0, 0.0, -n, 1.0);
    let far = m * glam::Vec4::new(0.0, 0.0, -f, 1.0);
    assert!((near.z / near.w + 1.0).abs() < 1e-6 && (far.z / far.w - 1.0).abs() < 1e-5);
}

#[test]
fn off_axis_frustum_shift_is_the_guides_frustum_asymmetry() {
    let cam = guide_camera();
    let mut r = rig(CameraMode::OffAxis, 0.8, 6.0);
    r.user_balance = 1.5;
    let eyes = r.eyes(&cam, 1.0).unwrap();
    // FrustumAsymmetry = −offset · balance · n / z0, positive for the left camera (offset = −d/2).
    let asym = 0.4 * 1.5 * 1.0 / 6.0;
    let w = cam.near * (45f32).to_radians().tan();
    assert!((eyes[0].frustum[0] - (-w + asym)).abs() < 1e-6);
    assert!((eyes[1].frustum[1] - (w - asym)).abs() < 1e-6);
}

#[test]
fn auto_separation_is_twice_the_guides_camera_offset() {
    let cam = guide_camera();
    let r = StereoRig {
        separation: Separation::Auto,
        zero_parallax: ZeroParallax::Distance(9.0),
        user_offset: 0.5,
        ..StereoRig::default()
    };
    let res = r.resolve(&cam, 2.0).unwrap();
    let xrange = 2.0 * 9.0 * 1.0 * 2.0; // 2 z0 tan(hfov/2), aspect 2
    assert!((res.xrange - xrange).abs() < 1e-4);
    assert!(
        (res.eye_separation - 2.0 * xrange * 0.035 * 0.5).abs() < 1e-5,
        "{}",
        res.eye_separation
    );
}

#[test]
fn zero_parallax_fraction_is_between_near_and_far() {
    let cam = guide_camera();
    let r = StereoRig {
        zero_parallax: ZeroParallax::Fraction(0.25),
        ..StereoRig::default()
    };
    assert!(
        (r.resolve(&cam, 1.0).unwrap().zero_parallax_distance - (1.0 + 0.25 * 99.0)).abs() < 1e-4
    );
}

#[test]
fn per_eye_and_cyclopic_share_mvp_but_not_modelview() {
    let cam = guide_camera();
    let mut r = rig(CameraMode::OffAxis, 1.0, 9.0);
    let per_eye = r.eyes(&cam, 1.0).unwrap();
    r.lighting = Lighting::Cyclopic;
    let cyclopic = r.eyes(&cam, 1.0).unwrap();
    for i in 0..2 {
        assert!(per_eye[i].mvp.abs_diff_eq(cyclopic[i].mvp, 1e-5));
        assert!(!per_eye[i].view.abs_diff_eq(cyclopic[i].view, 1e-3));
        assert!(cyclopic[i].view.abs_diff_eq(cam.view(), 1e-6));
    }
}

#[test]
fn toe_in_rotates_each_eye_by_atan_half_iod_over_fusion() {
    let cam = guide_camera();
    let eyes = rig(CameraMode::ToeIn, 1.0, 9.0).eyes(&cam, 1.0).unwrap();
    for (i, e) in eyes.iter().enumerate() {
        // The eye's forward axis is −Z of its view; its angle to the camera's −Z axis.
        let forward = e.view.inverse().transform_vector3(Vec3::NEG_Z).normalize();
        let angle = forward.angle_between(Vec3::NEG_Z);
        assert!(
            (angle - (0.5f32 / 9.0).atan()).abs() < 1e-5,
            "eye {i}: {angle}"
        );
        assert!((e.eye_world.x - if i == 0 { -0.5 } else { 0.5 }).abs() < 1e-6);
    }
}

#[test]
fn toe_in_has_vertical_parallax_off_center() {
    let cam = guide_camera();
    let eyes = rig(CameraMode::ToeIn, 1.0, 9.0).eyes(&cam, 1.0).unwrap();
    let vertical_px = |p: Vec3| {
        let (l, r) = (
            project_ndc(&eyes[0].mvp, p).unwrap(),
            project_ndc(&eyes[1].mvp, p).unwrap(),
        );
        (r.y - l.y) * 0.5 * 1024.0 // in pixels of a 1024-row image
    };
    // On the vertical center line the two rotations are mirror images: no vertical parallax.
    assert!(vertical_px(Vec3::new(0.0, 5.0, -3.0)).abs() < 1e-3);
    // Off center (the StereoGraphics guide's point): the keystone distortion differs between the eyes.
    let v = vertical_px(Vec3::new(8.0, -5.0, -3.0));
    println!("toe-in vertical parallax of (8,-5,-3), d = 1, z0 = 9, 1024 rows: {v:.3} px");
    assert!(
        v.abs() > 0.5,
        "expected a visible vertical parallax, got {v} px"
    );
}

proptest! {
    #[test]
    fn off_axis_zero_parallax_plane_lands_on_same_pixel(x in -8.0f32..8.0, y in -8.0f32..8.0, d in 0.01f32..2.0) {
        let cam = guide_camera();
        let eyes = rig(CameraMode::OffAxis, d, 9.0).eyes(&cam, 1.0).unwrap();
        let p = Vec3::new(x, y, 0.0);
        let (l, r) = (project_ndc(&eyes[0].mvp, p).unwrap(), project_ndc(&eyes[1].mvp, p).unwrap());
        prop_assert!((l.x - r.x).abs() < 2e-6 && (l.y - r.y).abs() < 2e-6, "{:?} vs {:?}", l, r);
    }

    #[test]
    fn off_axis_has_no_vertical_parallax(x in -8.0f32..8.0, y in -8.0f32..8.0, z in -80.0f32..7.0, d in 0.01f32..2.0) {
        let cam = guide_camera();
        let eyes = rig(CameraMode::OffAxis, d, 9.0).eyes(&cam, 1.0).unwrap();
        let p = Vec3::new(x, y, z);
        let (l, r) = (project_ndc(&eyes[0].mvp, p).unwrap(), project_ndc(&eyes[1].mvp, p).unwrap());
        prop_assert!((l.y - r.y).abs() < 1e-5);
        // and the horizontal parallax has the sign of the depth relative to z0 (behind → positive)
        let parallax = r.x - l.x;
        let sign_ok = if z < -1e-3 { parallax > 0.0 } else if z > 1e-3 { parallax < 0.0 } else { true };
        prop_assert!(sign_ok);
    }
}

fn invalid_field(e: Error) -> String {
    match e {
        Error::Invalid { field, .. } => field,
        other => panic!("expected Invalid, got {other}"),
    }
}

#[test]
fn bad_rig_parameters_name_their_field() {
    let cam = guide_camera();
    assert_eq!(
        invalid_field(
            rig(CameraMode::OffAxis, -0.1, 9.0)
                .eyes(&cam, 1.0)
                .unwrap_err()
        ),
        "stereo.eye_separation"
    );
    assert_eq!(
        invalid_field(
            rig(CameraMode::OffAxis, f32::NAN, 9.0)
                .eyes(&cam, 1.0)
                .unwrap_err()
        ),
        "stereo.eye_separation"
    );
    assert_eq!(
        invalid_field(
            rig(CameraMode::OffAxis, 1.0, 0.5)
                .eyes(&cam, 1.0)
                .unwrap_err()
        ),
        "stereo.zero_parallax"
    );
    assert_eq!(
        invalid_field(
            rig(CameraMode::OffAxis, 1.0, 100.0)
                .eyes(&cam, 1.0)
                .unwrap_err()
        ),
        "stereo.zero_parallax"
    );
    let mut r = rig(CameraMode::OffAxis, 1.0, 9.0);
    r.user_balance = 2.5;
    assert_eq!(
        invalid_field(r.eyes(&cam, 1.0).unwrap_err()),
        "stereo.user_balance"
    );
    let bad = |f: fn(&mut Camera)| {
        let mut c = guide_camera();
        f(&mut c);
        invalid_field(
            rig(CameraMode::OffAxis, 1.0, 9.0)
                .eyes(&c, 1.0)
                .unwrap_err(),
        )
    };
    assert_eq!(bad(|c| c.near = 0.0), "camera.near");
    assert_eq!(bad(|c| c.far = 0.5), "camera.far");
    assert_eq!(bad(|c| c.fov_y = 180.0), "camera.fov_y");
    assert_eq!(bad(|c| c.up = [0.0, 0.0, 1.0]), "camera.up");
    assert_eq!(bad(|c| c.eye = [f32::NAN, 0.0, 0.0]), "camera.eye");
}
