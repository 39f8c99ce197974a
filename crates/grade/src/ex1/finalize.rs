//! Exercise 1's `finalize_pixel` task: the finalize shader's anaglyph pixel,
//! `clamp(ML·left + MR·right, 0, 1)`, checked on single colors and applied pixel by pixel to the
//! grading fixture's two reference views.

use glam::Vec3;
use serde_json::json;

use super::anaglyph::reference_anaglyph;
use super::flat;
use crate::exercise::{
    AnaglyphKind, AnaglyphMatrices, ColorMatrix, exercise_matrices, reference_matrices,
};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, TaskSpec, Tolerance, hidden_cases};
use stereolab_core::{AnaglyphKind::DuboisRedCyan, Framebuffer, anaglyph_pixel, to_rgba8};

/// The known slips as switches.
#[derive(Clone, Copy, Default)]
struct FinalizeVariant {
    /// `m[j][i]` where `m[i][j]` belongs (the slides' rows read as columns).
    transposed: bool,
    /// No clamp to [0, 1].
    no_clamp: bool,
    /// ML applied to the right eye's color and MR to the left's.
    swapped: bool,
}

/// The finalize pixel in f64, with the known slips as switches.
fn finalize_reference(
    left: [f32; 3],
    right: [f32; 3],
    m: &AnaglyphMatrices,
    v: FinalizeVariant,
) -> [f64; 3] {
    let (left, right) = if v.swapped {
        (right, left)
    } else {
        (left, right)
    };
    let at = |c: &ColorMatrix, i: usize, j: usize| {
        f64::from(if v.transposed { c[j][i] } else { c[i][j] })
    };
    std::array::from_fn(|i| {
        let s: f64 = (0..3)
            .map(|j| {
                at(&m.left, i, j) * f64::from(left[j]) + at(&m.right, i, j) * f64::from(right[j])
            })
            .sum();
        if v.no_clamp { s } else { s.clamp(0.0, 1.0) }
    })
}

fn dubois() -> AnaglyphMatrices {
    exercise_matrices(DuboisRedCyan.matrices())
}

/// Twice the color anaglyph's matrices: bright colors overflow and must be clamped to 1.
fn doubled_color() -> AnaglyphMatrices {
    let m = reference_anaglyph(AnaglyphKind::Color);
    let twice = |c: ColorMatrix| c.map(|row| row.map(|x| 2.0 * x));
    AnaglyphMatrices {
        left: twice(m.left),
        right: twice(m.right),
    }
}

/// Every second pixel of the fixture's views in x and y: a 32 × 24 picture, few inputs.
const STEP: u32 = 2;

fn rgb(p: [u8; 4]) -> [f32; 3] {
    [p[0], p[1], p[2]].map(|c| f32::from(c) / 255.0)
}

fn finalize_input(left: [f32; 3], right: [f32; 3], m: &AnaglyphMatrices) -> serde_json::Value {
    json!([left, right, m])
}

pub(super) fn finalize_task(fx: &Fixture) -> TaskSpec {
    let white = [1.0, 1.0, 1.0];
    let orange = [0.9, 0.5, 0.3];
    let teal = [0.2, 0.7, 0.6];
    let inputs: Vec<(String, [f32; 3], [f32; 3], AnaglyphMatrices)> = vec![
        (
            "true anaglyph, orange | teal".into(),
            orange,
            teal,
            reference_anaglyph(AnaglyphKind::True),
        ),
        (
            "gray anaglyph, teal | orange".into(),
            teal,
            orange,
            reference_anaglyph(AnaglyphKind::Gray),
        ),
        (
            "color anaglyph, orange | teal".into(),
            orange,
            teal,
            reference_anaglyph(AnaglyphKind::Color),
        ),
        (
            "half-color anaglyph, white | white".into(),
            white,
            white,
            reference_anaglyph(AnaglyphKind::HalfColor),
        ),
        (
            "half-color anaglyph, orange | black".into(),
            orange,
            [0.0; 3],
            reference_anaglyph(AnaglyphKind::HalfColor),
        ),
        (
            "Dubois, pure red | pure green (negative sums: clamp to 0)".into(),
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            dubois(),
        ),
        (
            "Dubois, white | blue (above 1 and below 0)".into(),
            white,
            [0.0, 0.0, 1.0],
            dubois(),
        ),
        (
            "twice the color anaglyph, orange | teal (above 1: clamp to 1)".into(),
            orange,
            teal,
            doubled_color(),
        ),
    ];
    let each = |v: FinalizeVariant| {
        inputs
            .iter()
            .map(|(_, l, r, m)| flat(&finalize_reference(*l, *r, m, v)))
            .collect()
    };
    // The image check: the student's pixel over the fixture's two views, for two matrix sets.
    let (w, h) = fx.size();
    let (pw, ph) = (w / STEP, h / STEP);
    let pixels: Vec<([u8; 4], [u8; 4])> = (0..ph)
        .flat_map(|y| (0..pw).map(move |x| (x * STEP, y * STEP)))
        .map(|(x, y)| {
            let i = fx.views[0].index(x, y);
            (fx.views[0].color()[i], fx.views[1].color()[i])
        })
        .collect();
    let sets = [
        ("dubois", dubois()),
        ("half_color", reference_anaglyph(AnaglyphKind::HalfColor)),
    ];
    let canvas = {
        let mut fb = Framebuffer::new(pw, ph, [0, 0, 0, 255]).expect("half the fixture's size");
        fb.cover_all();
        fb
    };
    let image_inputs = sets
        .iter()
        .flat_map(|(_, m)| {
            pixels
                .iter()
                .map(move |(l, r)| finalize_input(rgb(*l), rgb(*r), m))
        })
        .collect();
    let expected: Vec<Framebuffer> = sets
        .iter()
        .map(|(_, m)| {
            let mut fb = canvas.clone();
            for (px, (l, r)) in fb.color_mut().iter_mut().zip(&pixels) {
                *px = anaglyph_pixel(&reference_matrices(*m), *l, *r, false);
            }
            fb
        })
        .collect();
    let names: Vec<&'static str> = sets.iter().map(|(n, _)| *n).collect();
    let count = pixels.len();
    let build = move |answers: &[Option<Vec<f64>>]| {
        names
            .iter()
            .zip(&expected)
            .enumerate()
            .map(|(k, (name, expected))| {
                let mut actual = canvas.clone();
                for (px, a) in actual
                    .color_mut()
                    .iter_mut()
                    .zip(&answers[k * count..(k + 1) * count])
                {
                    *px = match a.as_deref() {
                        Some([r, g, b]) => to_rgba8(Vec3::new(*r as f32, *g as f32, *b as f32)),
                        _ => [0, 0, 0, 255],
                    };
                }
                Picture {
                    name: format!("finalize_{name}"),
                    expected: expected.clone(),
                    actual,
                }
            })
            .collect()
    };
    TaskSpec {
        name: "finalize_pixel",
        points: 2.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("finalize_pixel", 8, |rng, _| {
            let mut color = || {
                [
                    rng.range(0.0, 1.0),
                    rng.range(0.0, 1.0),
                    rng.range(0.0, 1.0),
                ]
            };
            let (l, r) = (color(), color());
            let mut matrix = || -> ColorMatrix {
                std::array::from_fn(|_| std::array::from_fn(|_| rng.range(-0.4, 1.2)))
            };
            let m = AnaglyphMatrices {
                left: matrix(),
                right: matrix(),
            };
            Case {
                label: format!("hidden: left {l:?}, right {r:?}, {m:?}"),
                input: finalize_input(l, r, &m),
                expected: flat(&finalize_reference(l, r, &m, FinalizeVariant::default())),
            }
        }),
        tolerance: Tolerance {
            abs: 1e-5,
            rel: 0.0,
            why: "six products and a sum in f32 in any order: a few 1e-7",
        },
        cases: inputs
            .iter()
            .map(|(label, l, r, m)| Case {
                label: label.clone(),
                input: finalize_input(*l, *r, m),
                expected: flat(&finalize_reference(*l, *r, m, FinalizeVariant::default())),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "transposed",
                hint: "the matrices are used transposed: m.left[i] is ROW i, the weights of the \
                       output channel i: out[i] = Σ_j ML[i][j]·left[j] + MR[i][j]·right[j]",
                answers: each(FinalizeVariant {
                    transposed: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "no-clamp",
                hint: "clamp each channel to [0, 1]: matrices with negative or large weights \
                       (Dubois') give sums outside the displayable range",
                answers: each(FinalizeVariant {
                    no_clamp: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "swapped-eyes",
                hint: "swapped eyes: ML goes with the LEFT eye's color (index 0, the red \
                       filter), MR with the right eye's",
                answers: each(FinalizeVariant {
                    swapped: true,
                    ..Default::default()
                }),
            },
        ],
        image: Some(crate::pictures::check(image_inputs, Box::new(build))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereolab_core::anaglyph_mix;

    #[test]
    fn the_reference_pixel_is_stereolabs_mix_and_each_slip_shows_on_the_public_cases() {
        let cases = [
            ([0.9, 0.5, 0.3], [0.2, 0.7, 0.6], dubois()),
            ([1.0, 1.0, 1.0], [0.0, 0.0, 1.0], dubois()),
            ([0.9, 0.5, 0.3], [0.2, 0.7, 0.6], doubled_color()),
        ];
        for (l, r, m) in cases {
            let ours = finalize_reference(l, r, &m, FinalizeVariant::default());
            let module = anaglyph_mix(&reference_matrices(m), l, r);
            for (a, b) in ours.iter().zip(module) {
                assert!((a - f64::from(b)).abs() < 1e-6, "{ours:?} vs {module:?}");
            }
        }
        // The no-clamp slip must change at least one public case (else it cannot be named).
        let (l, r, m) = cases[1];
        assert_ne!(
            finalize_reference(l, r, &m, FinalizeVariant::default()),
            finalize_reference(
                l,
                r,
                &m,
                FinalizeVariant {
                    no_clamp: true,
                    ..Default::default()
                }
            )
        );
    }
}
