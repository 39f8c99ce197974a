//! Stereo layouts, the StereoGraphics guide's above-below format included.

use stereolab_core::{Framebuffer, above_below, above_below_squashed, interleave, side_by_side};

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
