//! Bad input to every finalize mode is a clear error, never a panic.

use glam::Mat4;
use stereolab_core::Framebuffer;
use stereolab_core::effects::anaglyph::{AnaglyphKind, AnaglyphOptions, anaglyph};
use stereolab_core::effects::occlusion::occlusion_image;
use stereolab_core::effects::parallax::{ParallaxRig, parallax_image, parallax_image_reference};
use stereolab_core::effects::remap::{
    Precision, remap_color, remap_color_reference, visibility_map,
};
use stereolab_core::math::{Camera, StereoRig};

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

/// The remap and the parallax image test the depth values inside a pass they make anyway (a
/// row at a time, or the extremes' scan in blocks): on an image of several rows and blocks, on
/// the AVX2 loops and the scalar references, the first bad pixel is the one named, wherever it lies, and
/// every kind of bad value is found.
#[test]
fn a_bad_depth_anywhere_is_refused_naming_the_first() {
    let (w, h) = (1030u32, 40u32);
    let mut a = fb(w, h);
    // Something drawn, so the modes do real work around the bad value.
    for (k, d) in a.depth.iter_mut().enumerate() {
        if k % 3 == 0 {
            *d = 0.25 + (k % 1000) as f32 / 4000.0;
        }
    }
    let b = fb(w, h);
    let m = mvps();
    let rig = parallax_rig(w, h);
    for (x, y) in [(0, 0), (1029, 0), (517, 16), (7, 39), (1029, 39)] {
        for bad in [f32::NAN, -0.25, 1.0f32.next_up(), f32::NEG_INFINITY] {
            let mut a = a.clone();
            let i = a.index(x, y);
            a.depth[i] = bad;
            // A later bad value must not be named instead.
            let last = a.depth.len() - 1;
            if i != last {
                a.depth[last] = 2.0;
            }
            for (what, e) in [
                (
                    "remap_color",
                    remap_color(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
                ),
                (
                    "remap_color_reference",
                    remap_color_reference(&a, &b, &m[0], &m[1], Precision::F64).map(drop),
                ),
                ("parallax_image", parallax_image(&a, &rig).map(drop)),
                (
                    "parallax_image_reference",
                    parallax_image_reference(&a, &rig).map(drop),
                ),
            ] {
                let msg = e.expect_err("bad depth").to_string();
                assert!(
                    msg.contains(&format!("pixel ({x}, {y})")),
                    "{bad} at ({x}, {y}), {what}: {msg}"
                );
            }
        }
    }
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
