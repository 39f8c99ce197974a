//! Exercise 1's anaglyph tasks: the anaglyph matrices of every kind and the Dubois bonus.

use serde_json::{Value, json};

use super::flat;
use crate::exercise::{
    AnaglyphKind, AnaglyphMatrices, ColorMatrix, exercise_matrices, reference_kind,
    reference_matrices,
};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, TaskSpec, Tolerance};
use stereolab_core::{AnaglyphKind::DuboisRedCyan, Framebuffer, anaglyph_pixel};

/// The exercise slides' anaglyph matrices from stereolab's anaglyph module.
pub(crate) fn reference_anaglyph(kind: AnaglyphKind) -> AnaglyphMatrices {
    exercise_matrices(reference_kind(kind).matrices())
}

fn transposed(m: &ColorMatrix) -> ColorMatrix {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}

fn transposed_pair(m: &AnaglyphMatrices) -> AnaglyphMatrices {
    AnaglyphMatrices {
        left: transposed(&m.left),
        right: transposed(&m.right),
    }
}

fn swapped_pair(m: &AnaglyphMatrices) -> AnaglyphMatrices {
    AnaglyphMatrices {
        left: m.right,
        right: m.left,
    }
}

/// The finalize shader's anaglyph pixel (stored 8-bit values, no sRGB decoding: the exercise slides).
fn mix(m: &AnaglyphMatrices, l: [u8; 4], r: [u8; 4]) -> [u8; 4] {
    anaglyph_pixel(&reference_matrices(*m), l, r, false)
}

fn matrices_from(a: &[f64]) -> Option<AnaglyphMatrices> {
    if a.len() != 18 || a.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let m = |o: usize| std::array::from_fn(|i| std::array::from_fn(|j| a[o + 3 * i + j] as f32));
    Some(AnaglyphMatrices {
        left: m(0),
        right: m(9),
    })
}

fn anaglyph_picture(fx: &Fixture, m: &AnaglyphMatrices) -> Framebuffer {
    let mut fb = fx.canvas([0, 0, 0, 255]);
    for (i, px) in fb.color_mut().iter_mut().enumerate() {
        *px = mix(m, fx.views[0].color()[i], fx.views[1].color()[i]);
    }
    fb
}

pub(super) fn anaglyph_task(fx: &Fixture) -> TaskSpec {
    let kinds = AnaglyphKind::ALL;
    let cases = kinds
        .iter()
        .map(|k| Case {
            label: format!("{k:?} anaglyph"),
            input: json!(k),
            expected: flat(&reference_anaglyph(*k)),
        })
        .collect();
    let each = |f: &dyn Fn(&AnaglyphMatrices) -> AnaglyphMatrices| {
        kinds
            .iter()
            .map(|k| flat(&f(&reference_anaglyph(*k))))
            .collect()
    };
    let reference: Vec<Framebuffer> = kinds
        .iter()
        .map(|k| anaglyph_picture(fx, &reference_anaglyph(*k)))
        .collect();
    let blank_fb = fx.canvas([0, 0, 0, 255]);
    let views = fx.views.clone();
    let build = move |answers: &[Option<Vec<f64>>]| {
        kinds
            .iter()
            .zip(&reference)
            .zip(answers)
            .map(|((k, expected), a)| {
                let mut actual = blank_fb.clone();
                if let Some(m) = a.as_deref().and_then(matrices_from) {
                    for (i, px) in actual.color_mut().iter_mut().enumerate() {
                        *px = mix(&m, views[0].color()[i], views[1].color()[i]);
                    }
                }
                Picture {
                    name: format!("anaglyph_{}", format!("{k:?}").to_lowercase()),
                    expected: expected.clone(),
                    actual,
                }
            })
            .collect()
    };
    TaskSpec {
        name: "anaglyph_matrices",
        points: 2.0,
        bonus: false,
        depends_on: &[],
        hidden: Vec::new(),
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 0.0,
            why: "the slides' numbers are short decimals; f32 holds them to 1e-8",
        },
        cases,
        mistakes: vec![
            Mistake {
                id: "transposed",
                hint: "the matrices are transposed: rows are the OUTPUT channels, so the \
                       luminance weights of a true anaglyph's left eye fill the first row",
                answers: each(&transposed_pair),
            },
            Mistake {
                id: "swapped-eyes",
                hint: "swapped eyes: the left eye (index 0) sees through the red filter, its \
                       matrix feeds the red output",
                answers: each(&swapped_pair),
            },
        ],
        image: Some(crate::pictures::check(
            kinds.iter().map(|k| json!(k)).collect(),
            Box::new(build),
        )),
    }
}

pub(super) fn dubois_task() -> TaskSpec {
    let dubois = exercise_matrices(DuboisRedCyan.matrices());
    let mut typo = dubois;
    typo.left[1][0] = -0.400822;
    TaskSpec {
        name: "dubois_matrices",
        points: 1.0,
        bonus: true,
        depends_on: &[],
        hidden: Vec::new(),
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 0.0,
            why: "six significant digits as published; f32 holds them to ~1e-8",
        },
        cases: vec![Case {
            label: "Dubois red-cyan".into(),
            input: Value::Null,
            expected: flat(&dubois),
        }],
        mistakes: vec![
            Mistake {
                id: "dubois-typo",
                hint: "the common typo: ML[1][0] is −0.0400822, not −0.400822",
                answers: vec![flat(&typo)],
            },
            Mistake {
                id: "transposed",
                hint: "the matrices are transposed: rows are the output channels",
                answers: vec![flat(&transposed_pair(&dubois))],
            },
        ],
        image: None,
    }
}
