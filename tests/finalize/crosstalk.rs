//! Crosstalk cancellation: the cancelled pair, after the simulated leak, no longer shows the
//! other eye; the residual ghost is measured against the uncorrected pair's.

use stereolab::output::report::effect_lines;
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{Framebuffer, GhostingSettings, cancelled};

use crate::common::asset;

/// IEC 61966-2-1 decoding in f64, written out here so the test does not call the library's.
fn decode(v: u8) -> f64 {
    let c = f64::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The leak as the simulation models it, per channel in linear light: `min(1, this + k·other)`.
fn seen(this: [u8; 4], other: [u8; 4], leak: [f32; 3]) -> [f64; 3] {
    [0, 1, 2].map(|c| (decode(this[c]) + f64::from(leak[c]) * decode(other[c])).min(1.0))
}

/// The left eye: every gray level 0–255 along a row, twice. The right eye: black in row 0,
/// white in row 1. The left eye's ghost at a level is how much its seen light differs between
/// the two rows, that is, how much of the right eye shows in it.
fn probe_pair() -> (Framebuffer, Framebuffer) {
    let mut left = Framebuffer::new(256, 2, [0, 0, 0, 255]).unwrap();
    let mut right = Framebuffer::new(256, 2, [0, 0, 0, 255]).unwrap();
    for x in 0..256u32 {
        for y in 0..2 {
            let (i, v) = (left.index(x, y), x as u8);
            left.color_mut()[i] = [v, v, v, 255];
            right.color_mut()[i] = if y == 0 {
                [0, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            };
        }
    }
    (left, right)
}

/// Max and mean over gray levels of the left eye's ghost, per channel, for the pair sent.
fn ghost(sent_left: &[[u8; 4]], sent_right: &[[u8; 4]], leak: [f32; 3]) -> [(f64, f64); 3] {
    [0, 1, 2].map(|c| {
        let per_level: Vec<f64> = (0..256)
            .map(|x| {
                let dark = seen(sent_left[x], sent_right[x], leak)[c];
                let bright = seen(sent_left[256 + x], sent_right[256 + x], leak)[c];
                (bright - dark).abs()
            })
            .collect();
        let max = per_level.iter().copied().fold(0.0, f64::max);
        (max, per_level.iter().sum::<f64>() / 256.0)
    })
}

fn pixels(img: &image::RgbaImage) -> Vec<[u8; 4]> {
    img.pixels().map(|p| p.0).collect()
}

#[test]
fn cancelled_pair_leaves_a_residual_ghost_far_below_the_uncorrected_one() {
    let leak = [0.03, 0.06, 0.2];
    let s = GhostingSettings { leak, cancel: 1.0 };
    let (left, right) = probe_pair();
    let plain = ghost(left.color(), right.color(), leak);
    let sent_left = pixels(&cancelled(&left, &right, &s).unwrap());
    let sent_right = pixels(&cancelled(&right, &left, &s).unwrap());
    let residual = ghost(&sent_left, &sent_right, leak);
    for c in 0..3 {
        eprintln!(
            "channel {c} leak {}: uncorrected ghost max {:.5} mean {:.5}; cancelled max {:.5} mean {:.5}",
            leak[c], plain[c].0, plain[c].1, residual[c].0, residual[c].1
        );
        // Uncorrected, the whole leak shows (less only where it clips at white).
        assert!((plain[c].0 - f64::from(leak[c])).abs() < 1e-6);
        // Cancelled, what is left is 8-bit rounding: a fraction of the leak.
        assert!(residual[c].1 < plain[c].1 / 8.0, "channel {c}");
        assert!(residual[c].0 < plain[c].0 / 2.0, "channel {c}");
    }
    // Black is lifted to the leak: the left eye's black, against the right eye's white, is
    // sent as 0 and seen as k.
    let black_seen = seen(sent_left[256], sent_right[256], leak);
    for c in 0..3 {
        assert_eq!(sent_left[256][c], 0);
        assert!(
            (black_seen[c] - f64::from(leak[c])).abs() < 0.004,
            "{black_seen:?}"
        );
    }
}

#[test]
fn no_cancellation_sends_the_originals_unchanged() {
    let s = GhostingSettings {
        leak: [0.5; 3],
        cancel: 0.0,
    };
    let (left, right) = probe_pair();
    assert_eq!(
        pixels(&cancelled(&left, &right, &s).unwrap()),
        left.color().to_vec()
    );
}

fn ghosting_scene(sets: &[&str]) -> stereolab_core::Result<Scene> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::load(&asset("scenes/ghosting.toml"), &sets)
}

#[test]
fn the_report_says_how_far_black_was_lifted() {
    let mut scene =
        ghosting_scene(&["ghosting.cancel=0.5", "ghosting.leak=[0.02, 0.1, 0.0]"]).unwrap();
    scene.set_size(64, 48).unwrap();
    let frame = render(&scene, &Plan::new(&[Output::CancelledLeft])).unwrap();
    let lines = effect_lines(&frame, &scene).unwrap();
    let line = lines
        .iter()
        .find(|l| l.contains("black lifted"))
        .unwrap_or_else(|| panic!("{lines:?}"));
    // Half of each leak; 0.05 linear is sRGB 63 of 255.
    assert!(
        line.contains("R 0.01, G 0.05, B 0 ") && line.contains("63"),
        "{line}"
    );
}

#[test]
fn cancel_outside_zero_to_one_is_refused_naming_the_field() {
    for bad in ["ghosting.cancel=1.5", "ghosting.cancel=-0.1"] {
        let Err(e) = ghosting_scene(&[bad]) else {
            panic!("{bad} accepted")
        };
        let e = e.to_string();
        assert!(e.contains("ghosting.cancel") && e.contains("0 (no"), "{e}");
    }
}
