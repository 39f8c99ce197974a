//! Stereo layouts, the StereoGraphics guide's above-below format included.

use stereolab_core::{
    Framebuffer, above_below, above_below_squashed, frame_packing, half_above_below,
    half_side_by_side, interleave, side_by_side,
};

const RED: [u8; 4] = [255, 0, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];
const BLACK: [u8; 4] = [0, 0, 0, 255];

fn pair(w: u32, h: u32) -> (Framebuffer, Framebuffer) {
    (
        Framebuffer::new(w, h, RED).unwrap(),
        Framebuffer::new(w, h, BLUE).unwrap(),
    )
}

#[test]
fn guides_above_below_1024x768_with_blank_40_has_364_row_views() {
    let (l, r) = pair(1024, 768);
    let img = above_below_squashed(&l, &r, 40).unwrap();
    assert_eq!(img.dimensions(), (1024, 768));
    for (rows, color) in [(0..364, RED), (364..404, BLACK), (404..768, BLUE)] {
        for y in rows.clone() {
            assert_eq!(img.get_pixel(517, y).0, color, "row {y}");
        }
    }
}

#[test]
fn above_below_squash_averages_row_pairs() {
    // A left eye of alternating black/white rows squashes 2:1 to mid-gray.
    let (mut l, r) = pair(4, 8);
    for y in 0..8 {
        for x in 0..4 {
            let i = l.index(x, y);
            l.color_mut()[i] = if y % 2 == 0 {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            };
        }
    }
    let img = above_below_squashed(&l, &r, 0).unwrap();
    assert_eq!(img.get_pixel(1, 1).0, [128, 128, 128, 255]);
}

#[test]
fn side_by_side_interlaced_and_checkerboard_pick_the_right_eye() {
    let (l, r) = pair(6, 4);
    let sbs = side_by_side(&l, &r).unwrap();
    assert_eq!((sbs.get_pixel(5, 0).0, sbs.get_pixel(6, 0).0), (RED, BLUE));
    let ab = above_below(&l, &r).unwrap();
    assert_eq!((ab.get_pixel(0, 3).0, ab.get_pixel(0, 4).0), (RED, BLUE));
    let rows = interleave(&l, &r, |_, y| y % 2 == 0).unwrap();
    assert_eq!(
        (rows.get_pixel(3, 0).0, rows.get_pixel(3, 1).0),
        (RED, BLUE)
    );
    let checker = interleave(&l, &r, |x, y| (x + y) % 2 == 0).unwrap();
    assert_eq!(
        (
            checker.get_pixel(0, 0).0,
            checker.get_pixel(1, 0).0,
            checker.get_pixel(1, 1).0
        ),
        (RED, BLUE, RED)
    );
}

#[test]
fn layouts_refuse_mismatched_eyes_and_blank_intervals_without_rows() {
    let l = Framebuffer::new(4, 4, RED).unwrap();
    let r = Framebuffer::new(5, 4, BLUE).unwrap();
    assert!(
        side_by_side(&l, &r)
            .unwrap_err()
            .to_string()
            .contains("4x4 vs 5x4")
    );
    let r = Framebuffer::new(4, 4, BLUE).unwrap();
    assert!(above_below_squashed(&l, &r, 3).is_err());
}

/// A deterministic pair of noise images (a 32-bit LCG), alpha opaque.
fn noise_pair(w: u32, h: u32) -> (Framebuffer, Framebuffer) {
    let mut state = 0x2545_f491u32;
    let mut next = || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 24) as u8
    };
    let mut make = || {
        let mut fb = Framebuffer::new(w, h, BLACK).unwrap();
        for p in fb.color_mut() {
            *p = [next(), next(), next(), 255];
        }
        fb
    };
    (make(), make())
}

/// IEC 61966-2-1 in f64, written out here so the test does not call the library's.
fn decode(v: u8) -> f64 {
    let c = f64::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn encode(l: f64) -> f64 {
    let c = if l <= 0.0031308 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    c * 255.0
}

/// The linear-light mean of two pixels, each channel as an unrounded 8-bit value.
fn linear_mean(a: [u8; 4], b: [u8; 4]) -> [f64; 3] {
    [0, 1, 2].map(|c| encode((decode(a[c]) + decode(b[c])) / 2.0))
}

fn assert_within_rounding(got: [u8; 4], want: [f64; 3], at: &str) {
    for c in 0..3 {
        assert!(
            (f64::from(got[c]) - want[c]).abs() <= 0.5 + 1e-3,
            "{at} channel {c}: {} vs {:.3}",
            got[c],
            want[c]
        );
    }
    assert_eq!(got[3], 255, "{at} alpha");
}

#[test]
fn half_side_by_side_averages_column_pairs_in_linear_light() {
    let (l, r) = noise_pair(8, 3);
    let img = half_side_by_side(&l, &r).unwrap();
    assert_eq!(img.dimensions(), (8, 3), "one eye's size");
    for y in 0..3 {
        for i in 0..4 {
            for (fb, x0, name) in [(&l, 0, "left"), (&r, 4, "right")] {
                let want = linear_mean(fb.pixel(2 * i, y), fb.pixel(2 * i + 1, y));
                let at = format!("{name} ({}, {y})", x0 + i);
                assert_within_rounding(img.get_pixel(x0 + i, y).0, want, &at);
            }
        }
    }
    // A black and a white pixel emit half the light: sRGB 188, not the stored mean 128.
    let mut bw = Framebuffer::new(2, 1, BLACK).unwrap();
    bw.color_mut()[1] = [255, 255, 255, 255];
    let half = half_side_by_side(&bw, &bw).unwrap().get_pixel(0, 0).0;
    assert!((187..=188).contains(&half[0]), "{half:?}");
}

#[test]
fn half_above_below_averages_row_pairs_in_linear_light() {
    let (l, r) = noise_pair(3, 8);
    let img = half_above_below(&l, &r).unwrap();
    assert_eq!(img.dimensions(), (3, 8), "one eye's size");
    for j in 0..4 {
        for x in 0..3 {
            for (fb, y0, name) in [(&l, 0, "left"), (&r, 4, "right")] {
                let want = linear_mean(fb.pixel(x, 2 * j), fb.pixel(x, 2 * j + 1));
                let at = format!("{name} ({x}, {})", y0 + j);
                assert_within_rounding(img.get_pixel(x, y0 + j).0, want, &at);
            }
        }
    }
}

#[test]
fn half_formats_of_an_odd_size_leave_the_last_line_black() {
    let (l, r) = pair(5, 5);
    let sbs = half_side_by_side(&l, &r).unwrap();
    let views: Vec<[u8; 4]> = (0..5).map(|x| sbs.get_pixel(x, 2).0).collect();
    assert_eq!(views, [RED, RED, BLUE, BLUE, BLACK]);
    let ab = half_above_below(&l, &r).unwrap();
    let views: Vec<[u8; 4]> = (0..5).map(|y| ab.get_pixel(2, y).0).collect();
    assert_eq!(views, [RED, RED, BLUE, BLUE, BLACK]);
}

#[test]
fn frame_packing_is_hdmi_1_4a_at_1080p_and_720p() {
    // HDMI 1.4a: 1080p → 1920×2205 (45 rows of active space), 720p → 1280×1470 (30 rows).
    for (w, h, gap) in [(1920u32, 1080u32, 45u32), (1280, 720, 30)] {
        let (l, r) = noise_pair(w, h);
        let img = frame_packing(&l, &r).unwrap();
        assert_eq!(img.dimensions(), (w, 2 * h + gap));
        for x in [0, 1, w / 3, w - 1] {
            for y in [0, 1, h / 2, h - 1] {
                assert_eq!(img.get_pixel(x, y).0, l.pixel(x, y), "left ({x}, {y})");
                let below = h + gap + y;
                assert_eq!(img.get_pixel(x, below).0, r.pixel(x, y), "right ({x}, {y})");
            }
            for y in h..h + gap {
                assert_eq!(img.get_pixel(x, y).0, BLACK, "active space row {y}");
            }
        }
    }
}

#[test]
fn frame_packing_of_other_sizes_keeps_the_height_over_24_rule() {
    let (l, r) = pair(160, 120);
    let img = frame_packing(&l, &r).unwrap();
    assert_eq!(img.dimensions(), (160, 245), "120 + 5 + 120");
    assert_eq!(img.get_pixel(7, 119).0, RED);
    assert_eq!(img.get_pixel(7, 124).0, BLACK);
    assert_eq!(img.get_pixel(7, 125).0, BLUE);
}
