//! Bad input to every finalize mode is a clear error, never a panic.

use glam::Mat4;
use stereolab::Framebuffer;
use stereolab::effects::anaglyph::{AnaglyphKind, AnaglyphOptions, anaglyph};
use stereolab::effects::occlusion::occlusion_image;
use stereolab::effects::parallax::{ParallaxRig, parallax_image};
use stereolab::effects::remap::{Precision, remap_color, visibility_map};
use stereolab::math::{Camera, StereoRig};

fn fb(w: u32, h: u32) -> Framebuffer {
    Framebuffer::new(w, h, [90, 90, 90, 255]).expect("framebuffer")
}

fn mvps() -> [Mat4; 2] {
    let cam = Camera {
        eye: [0.0; 3],
        target: [0.0, 0.0, -1.0],
        up: [0.0, 1.0, 0.0],
        fov_y: 40.0,
        near: 1.0,
        far: 20.0,
    };
    let e = StereoRig::default().eyes(&cam, 8.0 / 6.0).expect("eyes");
    [e[0].mvp, e[1].mvp]
}

fn parallax_rig(w: u32, h: u32) -> ParallaxRig {
    let cam = Camera {
        eye: [0.0; 3],
        target: [0.0, 0.0, -1.0],
        up: [0.0, 1.0, 0.0],
        fov_y: 40.0,
        near: 1.0,
        far: 20.0,
    };
    ParallaxRig::new(&StereoRig::default(), &cam, w, h).expect("rig")
}

#[test]
fn framebuffers_of_different_sizes_are_refused() {
    let (a, b) = (fb(8, 6), fb(8, 5));
    let m = mvps();
    let errors = [
        anaglyph(&a, &b, AnaglyphKind::Gray, AnaglyphOptions::default()).map(drop),
        remap_color(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
        visibility_map(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
        occlusion_image(&a, &b, [&m[0], &m[1]], Precision::F64).map(drop),
        parallax_image(&b, &parallax_rig(8, 6)).map(drop),
    ];
    for e in errors {
        let msg = e.expect_err("sizes differ").to_string();
        assert!(msg.contains("8x5") || msg.contains("8x6"), "{msg}");
    }
}

#[test]
fn missing_depth_is_refused() {
    let mut a = fb(8, 6);
    a.depth.clear();
    let b = fb(8, 6);
    let m = mvps();
    for e in [
        remap_color(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
        visibility_map(&b, &a, &m[0], &m[1], Precision::F64).map(drop),
        occlusion_image(&a, &b, [&m[0], &m[1]], Precision::F64).map(drop),
        parallax_image(&a, &parallax_rig(8, 6)).map(drop),
    ] {
        let msg = e.expect_err("no depth").to_string();
        assert!(msg.contains("missing depth"), "{msg}");
    }
    let mut short = fb(8, 6);
    short.color.pop();
    let msg = anaglyph(&short, &b, AnaglyphKind::Color, AnaglyphOptions::default())
        .expect_err("short color")
        .to_string();
    assert!(msg.contains("left eye color"), "{msg}");
}

#[test]
fn nan_depth_is_refused_naming_the_pixel() {
    let mut a = fb(8, 6);
    let i = a.index(3, 2);
    a.depth[i] = f32::NAN;
    let b = fb(8, 6);
    let m = mvps();
    for e in [
        remap_color(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
        occlusion_image(&b, &a, [&m[0], &m[1]], Precision::F64).map(drop),
        parallax_image(&a, &parallax_rig(8, 6)).map(drop),
    ] {
        let msg = e.expect_err("NaN depth").to_string();
        assert!(msg.contains("pixel (3, 2)") && msg.contains("NaN"), "{msg}");
    }
    a.depth[i] = 1.5;
    let msg = parallax_image(&a, &parallax_rig(8, 6))
        .expect_err("depth > 1")
        .to_string();
    assert!(msg.contains("1.5"), "{msg}");
}

#[test]
fn a_singular_eye_matrix_is_refused() {
    let (a, b) = (fb(8, 6), fb(8, 6));
    let m = mvps();
    let msg = remap_color(&a, &b, &Mat4::ZERO, &m[1], Precision::F64)
        .expect_err("singular")
        .to_string();
    assert!(msg.contains("invertible"), "{msg}");
}
