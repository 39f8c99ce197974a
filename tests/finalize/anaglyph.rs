//! Anaglyph matrices against their sources, white preservation, gray in → gray/red/cyan out,
//! linear light and swapped eyes.

use proptest::prelude::*;
use stereolab_core::{
    AnaglyphKind, AnaglyphMatrices, AnaglyphOptions, ColorMatrix, Framebuffer, anaglyph,
    anaglyph_mix, anaglyph_pixel, anaglyph_pixel_with, anaglyph_reference, linear_to_srgb,
    srgb_to_linear,
};

type Kind = AnaglyphKind;

/// three.js's `Matrix3.fromArray` takes column-major arrays; rows of the result are output
/// channels. Transposing here checks our row-major transcription independently.
fn from_column_major(a: [f32; 9]) -> ColorMatrix {
    [[a[0], a[3], a[6]], [a[1], a[4], a[7]], [a[2], a[5], a[8]]]
}

const LUMA: [f32; 3] = [0.299, 0.587, 0.114];
const Z: [f32; 3] = [0.0; 3];

/// The numbers exactly as each source writes them (see the doc of `AnaglyphKind::matrices`).
fn source(kind: Kind) -> (ColorMatrix, ColorMatrix) {
    match kind {
        // The exercise slides.
        Kind::True => ([LUMA, Z, Z], [Z, Z, LUMA]),
        Kind::Gray => ([LUMA, Z, Z], [Z, LUMA, LUMA]),
        Kind::Color => (
            [[1.0, 0.0, 0.0], Z, Z],
            [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        ),
        Kind::HalfColor => ([LUMA, Z, Z], [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        // 3dtv.at: R = 0.7 G_l + 0.3 B_l.
        Kind::Optimized => (
            [[0.0, 0.7, 0.3], Z, Z],
            [Z, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        ),
        // three.js examples/jsm/effects/AnaglyphEffect.js, column-major fromArray.
        Kind::DuboisRedCyan => (
            from_column_major([
                0.4561,
                -0.0400822,
                -0.0152161,
                0.500484,
                -0.0378246,
                -0.0205971,
                0.176381,
                -0.0157589,
                -0.00546856,
            ]),
            from_column_major([
                -0.0434706,
                0.378476,
                -0.0721527,
                -0.0879388,
                0.73364,
                -0.112961,
                -0.00155529,
                -0.0184503,
                1.2264,
            ]),
        ),
        Kind::ThreeJs(..) => unreachable!("three.js's table: tests/finalize/threejs.rs"),
        // dolphin-emu dubois.glsl (2009 LCD values).
        Kind::DuboisRedCyanLcd => (
            [
                [0.437, 0.449, 0.164],
                [-0.062, -0.062, -0.024],
                [-0.048, -0.050, -0.017],
            ],
            [
                [-0.011, -0.032, -0.007],
                [0.377, 0.761, 0.009],
                [-0.026, -0.093, 1.234],
            ],
        ),
        Kind::DuboisGreenMagenta => (
            [
                [-0.062, -0.158, -0.039],
                [0.284, 0.668, 0.143],
                [-0.015, -0.027, 0.021],
            ],
            [
                [0.529, 0.705, 0.024],
                [-0.016, -0.015, -0.065],
                [0.009, 0.075, 0.937],
            ],
        ),
        // vpinball.
        Kind::DuboisAmberBlue => (
            [
                [1.062, -0.205, 0.299],
                [-0.026, 0.908, 0.068],
                [-0.038, -0.173, 0.022],
            ],
            [
                [-0.016, -0.123, -0.017],
                [0.006, 0.062, -0.017],
                [0.094, 0.185, 0.911],
            ],
        ),
    }
}

fn row_sums(m: &AnaglyphMatrices) -> [f32; 3] {
    std::array::from_fn(|i| m.left[i].iter().sum::<f32>() + m.right[i].iter().sum::<f32>())
}

#[test]
fn each_matrix_matches_its_source() {
    for kind in Kind::ALL {
        let (l, r) = source(kind);
        let m = kind.matrices();
        assert_eq!(m.left, l, "{kind:?} ML");
        assert_eq!(m.right, r, "{kind:?} MR");
    }
}

#[test]
fn every_kind_has_a_distinct_output_name() {
    let mut names: Vec<&str> = Kind::ALL.iter().map(|k| k.output_name()).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), Kind::ALL.len());
    assert!(names.iter().all(|n| n.starts_with("anaglyph_")));
}

#[test]
fn white_preserved_where_the_source_claims_it() {
    for kind in Kind::ALL {
        let m = kind.matrices();
        let sums = row_sums(&m);
        let out = anaglyph_pixel(&m, [255; 4], [255; 4], false);
        if kind.preserves_white() {
            // Least-squares fits published to 3–6 digits: the CRT blue row sums to 0.9960.
            for (i, s) in sums.iter().enumerate() {
                assert!((s - 1.0).abs() < 0.005, "{kind:?} row {i} sums to {s}");
            }
            for c in 0..3 {
                assert!(out[c] >= 254, "{kind:?}: white became {out:?}");
            }
        } else {
            // The exercise slides' true anaglyph: white becomes magenta (documented exception).
            assert_eq!(out, [255, 0, 255, 255], "{kind:?}");
        }
    }
}

#[test]
fn row_sum_check_catches_the_known_transcription_errors() {
    // -0.400822 for -0.0400822 (Dubois CRT, ML[1][0]).
    let mut typo = Kind::DuboisRedCyan.matrices();
    typo.left[1][0] = -0.400822;
    assert!((row_sums(&typo)[1] - 1.0).abs() > 0.3);
    // +0.065 for -0.065 (green-magenta, MR[1][2]): the green row sums to 1.129.
    let mut sign = Kind::DuboisGreenMagenta.matrices();
    sign.right[1][2] = 0.065;
    assert!((row_sums(&sign)[1] - 1.129).abs() < 1e-3);
    // dolphin's amber-blue MR rows 2-3: sums 1.035 and 0.523.
    let mut amber = Kind::DuboisAmberBlue.matrices();
    amber.right[1] = [0.006, 0.062, 0.017];
    amber.right[2] = [-0.094, -0.185, 0.991];
    let s = row_sums(&amber);
    assert!(
        (s[1] - 1.035).abs() < 1e-3 && (s[2] - 0.523).abs() < 1e-3,
        "{s:?}"
    );
}

/// out = round(clamp(g · Σ row) · 255) per channel, from the source numbers, for a gray level
/// `g` in the eyes that `eyes` selects (left, right).
fn expected_gray(kind: Kind, g: u8, eyes: (bool, bool)) -> [u8; 3] {
    let (l, r) = source(kind);
    std::array::from_fn(|i| {
        let s = if eyes.0 {
            l[i].iter().sum::<f32>()
        } else {
            0.0
        } + if eyes.1 {
            r[i].iter().sum::<f32>()
        } else {
            0.0
        };
        ((g as f32 / 255.0 * s).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
    })
}

#[test]
fn gray_in_gives_gray_red_and_cyan_out() {
    let g = 180u8;
    let gray = [g, g, g, 255];
    let black = [0, 0, 0, 255];
    for kind in Kind::ALL {
        let m = kind.matrices();
        let both = anaglyph_pixel(&m, gray, gray, false);
        let left_only = anaglyph_pixel(&m, gray, black, false);
        let right_only = anaglyph_pixel(&m, black, gray, false);
        for (got, eyes) in [
            (both, (true, true)),
            (left_only, (true, false)),
            (right_only, (false, true)),
        ] {
            let want = expected_gray(kind, g, eyes);
            for c in 0..3 {
                assert!(
                    got[c].abs_diff(want[c]) <= 1,
                    "{kind:?} eyes {eyes:?}: got {got:?}, expected {want:?}"
                );
            }
        }
        // The named colors: red-cyan kinds give red from the left eye and cyan (or blue for
        // the true anaglyph) from the right.
        match kind {
            Kind::Gray | Kind::Color | Kind::HalfColor => {
                assert_eq!(both, [g, g, g, 255], "{kind:?} keeps gray gray");
                assert_eq!(left_only, [g, 0, 0, 255], "{kind:?} left is red");
                assert_eq!(right_only, [0, g, g, 255], "{kind:?} right is cyan");
            }
            Kind::True => {
                assert_eq!(left_only, [g, 0, 0, 255]);
                assert_eq!(right_only, [0, 0, g, 255]);
            }
            Kind::Optimized => {
                assert_eq!(both, [g, g, g, 255]);
                assert_eq!(right_only, [0, g, g, 255]);
            }
            Kind::DuboisRedCyan | Kind::DuboisRedCyanLcd => {
                assert!(left_only[0] > 150 && left_only[1] == 0 && left_only[2] == 0);
                assert!(right_only[0] == 0 && right_only[1] > 150 && right_only[2] > 150);
            }
            Kind::DuboisGreenMagenta => {
                assert!(left_only[1] > 150 && left_only[0] == 0 && left_only[2] == 0);
                assert!(right_only[0] > 150 && right_only[2] > 150 && right_only[1] == 0);
            }
            Kind::DuboisAmberBlue => {
                assert!(left_only[0] > 150 && left_only[1] > 100 && left_only[2] == 0);
                assert!(right_only[2] > 150 && right_only[0] == 0 && right_only[1] < 20);
            }
            Kind::ThreeJs(..) => unreachable!("three.js's table: tests/finalize/threejs.rs"),
        }
    }
}

fn solid(w: u32, h: u32, c: [u8; 4]) -> Framebuffer {
    Framebuffer::new(w, h, c).expect("framebuffer")
}

#[test]
fn swapped_eyes_apply_each_filter_to_the_other_eye() {
    let (a, b) = (
        solid(4, 3, [200, 30, 90, 255]),
        solid(4, 3, [10, 220, 140, 255]),
    );
    for kind in Kind::ALL {
        let swapped = AnaglyphOptions {
            swap_eyes: true,
            ..Default::default()
        };
        let s = anaglyph(&a, &b, kind, swapped).expect("anaglyph");
        let plain = anaglyph(&b, &a, kind, AnaglyphOptions::default()).expect("anaglyph");
        assert_eq!(s, plain, "{kind:?}");
        assert_ne!(
            s,
            anaglyph(&a, &b, kind, AnaglyphOptions::default()).expect("anaglyph"),
            "{kind:?}: swapping must change a colored pair"
        );
    }
}

#[test]
fn linear_light_mixes_decoded_values() {
    let m = Kind::HalfColor.matrices();
    // Pure red left: stored R = 0.299·255 = 76; linear R = encode(0.299 · 1).
    let stored = anaglyph_pixel(&m, [255, 0, 0, 255], [0, 0, 0, 255], false);
    let linear = anaglyph_pixel(&m, [255, 0, 0, 255], [0, 0, 0, 255], true);
    assert_eq!(stored[0], 76);
    let want = (linear_to_srgb(0.299) * 255.0 + 0.5) as u8;
    assert_eq!(linear[0], want);
    assert!(linear[0] > stored[0] + 50, "{linear:?} vs {stored:?}");
    // Gray stays gray in linear light too (rows sum to 1).
    let g = anaglyph_pixel(&Kind::Gray.matrices(), [90; 4], [90; 4], true);
    assert!(g[..3].iter().all(|c| c.abs_diff(90) <= 1), "{g:?}");
}

/// The image loop (`anaglyph`, on the AVX2 rows where the CPU has them) gives the per-pixel
/// definition's bytes and `anaglyph_reference`'s, for every kind (the nine and three.js's
/// table) with every option, on a patterned image and on random colours (no two neighbours
/// equal, a width that ends mid-vector).
#[test]
fn image_loop_matches_the_per_pixel_function() {
    let mut a = solid(5, 4, [0; 4]);
    let mut b = solid(5, 4, [0; 4]);
    for (i, (p, q)) in a
        .color_mut()
        .iter_mut()
        .zip(b.color_mut().iter_mut())
        .enumerate()
    {
        *p = [
            (i * 37 % 256) as u8,
            (i * 91 % 256) as u8,
            (i * 13 % 256) as u8,
            255,
        ];
        *q = [
            (i * 59 % 256) as u8,
            (i * 7 % 256) as u8,
            (i * 111 % 256) as u8,
            255,
        ];
    }
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut noise = || {
        let mut fb = solid(77, 9, [0; 4]);
        for c in fb.color_mut() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let w = state.to_le_bytes();
            *c = [w[0], w[1], w[2], w[3]];
        }
        fb
    };
    let (c, d) = (noise(), noise());
    for (left, right) in [(&a, &b), (&c, &d)] {
        for kind in Kind::ALL.into_iter().chain(Kind::THREE_JS) {
            for bits in 0..8 {
                let options = AnaglyphOptions {
                    linear_light: bits & 1 != 0,
                    swap_eyes: bits & 2 != 0,
                    anti_rivalry: bits & 4 != 0,
                };
                let img = anaglyph(left, right, kind, options).expect("anaglyph");
                let reference =
                    anaglyph_reference(left, right, kind, options).expect("anaglyph_reference");
                assert_eq!(img, reference, "{kind:?} {options:?}");
                let (l, r) = options.eyes(left, right);
                for (i, px) in img.pixels().enumerate() {
                    let want =
                        anaglyph_pixel_with(&kind.matrices(), l.color()[i], r.color()[i], options);
                    assert_eq!(px.0, want, "{kind:?} {options:?} pixel {i}");
                }
            }
        }
    }
}

proptest! {
    #[test]
    fn srgb_decode_then_encode_is_identity(v in 0u8..=255) {
        let c = v as f32 / 255.0;
        prop_assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
    }

    #[test]
    fn color_anaglyph_of_identical_eyes_is_the_image(r in 0u8..=255, g in 0u8..=255, b in 0u8..=255) {
        let p = [r, g, b, 255];
        prop_assert_eq!(anaglyph_pixel(&Kind::Color.matrices(), p, p, false), p);
    }

    #[test]
    fn mixed_channels_stay_in_unit_range(l in proptest::array::uniform3(0.0f32..=1.0),
                                          r in proptest::array::uniform3(0.0f32..=1.0)) {
        for kind in Kind::ALL {
            let out = anaglyph_mix(&kind.matrices(), l, r);
            prop_assert!(out.iter().all(|c| (0.0..=1.0).contains(c)));
        }
    }
}
