//! Bad input to every finalize mode is a clear error, never a panic.

use glam::Mat4;
use stereolab_core::{
    AnaglyphKind, AnaglyphOptions, Camera, Framebuffer, ParallaxRig, Precision, StereoRig,
    anaglyph, occlusion_image, parallax_image, remap_color, visibility_map,
};

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

/// A framebuffer holds `width × height` colors and depths by construction: buffers from
/// elsewhere of another length are refused where they come in, naming the buffer.
#[test]
fn buffers_of_the_wrong_length_are_refused() {
    let n = 8 * 6;
    let msg = Framebuffer::from_buffers(8, 6, vec![[0; 4]; n], Vec::new())
        .expect_err("no depth")
        .to_string();
    assert!(
        msg.contains("framebuffer depth") && msg.contains("48"),
        "{msg}"
    );
    let msg = Framebuffer::from_buffers(8, 6, vec![[0; 4]; n - 1], vec![1.0; n])
        .expect_err("short color")
        .to_string();
    assert!(
        msg.contains("framebuffer color") && msg.contains("47"),
        "{msg}"
    );
    let msg = Framebuffer::from_buffers(0, 6, Vec::new(), Vec::new())
        .expect_err("zero width")
        .to_string();
    assert!(msg.contains("image.width"), "{msg}");
}

/// Every depth of a framebuffer is a window depth in [0, 1] by construction: a NaN, an
/// infinity or a value outside is refused where the buffers come in, the first bad pixel
/// named wherever it lies, so no effect ever reads one.
#[test]
fn a_bad_depth_anywhere_is_refused_naming_the_first() {
    let (w, h) = (1030u32, 40u32);
    let n = (w * h) as usize;
    // Something drawn, so the bad value sits among real depths.
    let drawn: Vec<f32> = (0..n)
        .map(|k| {
            if k % 3 == 0 {
                0.25 + (k % 1000) as f32 / 4000.0
            } else {
                1.0
            }
        })
        .collect();
    assert!(Framebuffer::from_buffers(w, h, vec![[0; 4]; n], drawn.clone()).is_ok());
    for (x, y) in [(0, 0), (1029, 0), (517, 16), (7, 39), (1029, 39)] {
        for bad in [f32::NAN, -0.25, 1.0f32.next_up(), 1.5, f32::NEG_INFINITY] {
            let mut depth = drawn.clone();
            let i = (y * w + x) as usize;
            depth[i] = bad;
            // A later bad value must not be named instead.
            if i != n - 1 {
                depth[n - 1] = 2.0;
            }
            let msg = Framebuffer::from_buffers(w, h, vec![[0; 4]; n], depth)
                .expect_err("bad depth")
                .to_string();
            assert!(
                msg.contains(&format!("pixel ({x}, {y})")) && msg.contains(&bad.to_string()),
                "{bad} at ({x}, {y}): {msg}"
            );
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
