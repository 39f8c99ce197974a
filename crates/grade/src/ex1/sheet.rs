//! Exercise 1's `sheet_frustum` task: each eye's frustum in the exercise slides' own,
//! screen-relative terms (screen width w and height h at the zero-parallax distance z0, eye
//! separation d as a fraction of the screen width).

use serde_json::json;

use super::flat;
use crate::exercise::{Eye, ScreenSetup};
use crate::spec::{Case, Mistake, SplitMix64, TaskSpec, Tolerance, hidden_cases};

const SHEET_TOLERANCE: Tolerance = Tolerance {
    abs: 1e-6,
    rel: 1e-5,
    why: "a few products and sums in f32, in any order: a few units in the last place",
};

/// The known slips as switches.
#[derive(Clone, Copy, Default)]
struct SheetVariant {
    /// The eyes' signs exchanged.
    swapped: bool,
    /// The shift `±½·d·w` not scaled by `n/z0` (measured on the screen, not the near plane).
    unscaled_shift: bool,
    /// The whole frustum left on the screen: no `n/z0` anywhere.
    unscaled: bool,
    /// `½·d` instead of `½·d·w`: d read as an absolute separation.
    d_not_dw: bool,
    /// `d·w` instead of `½·d·w`.
    full_separation: bool,
}

/// The exercise slides' formulas, in f64: `t = ½·h·n/z0`, `l, r = ∓½·w·n/z0 ± ½·d·w·n/z0`
/// (+ for the left eye), with the known slips as switches.
fn sheet_reference(s: &ScreenSetup, eye: Eye, v: SheetVariant) -> [f64; 6] {
    let (w, h) = (f64::from(s.width), f64::from(s.height));
    let (n, f, z0) = (
        f64::from(s.near),
        f64::from(s.far),
        f64::from(s.zero_parallax),
    );
    let d = f64::from(s.eye_separation_fraction);
    let scale = if v.unscaled { 1.0 } else { n / z0 };
    let t = 0.5 * h * scale;
    let r = 0.5 * w * scale;
    let offset = if v.d_not_dw {
        0.5 * d
    } else if v.full_separation {
        d * w
    } else {
        0.5 * d * w
    };
    let shift = if v.unscaled_shift {
        offset
    } else {
        offset * scale
    };
    let left = (eye == Eye::Left) != v.swapped;
    let shift = if left { shift } else { -shift };
    [-r + shift, r + shift, -t, t, n, f]
}

/// The screens the public cases use: the StereoGraphics guide's worked example in the sheet's
/// terms (camera 9 in front of the screen, 90° field of view: the screen spans 18 × 18; the
/// separation 1 is 1/18 of its width), a 16:9 screen a viewer sits 2 from with 6.5 cm eyes,
/// a small portrait screen, and a wide screen with the near plane halfway to it; each named for
/// the case labels.
fn named_screens() -> Vec<(&'static str, ScreenSetup)> {
    vec![
        (
            "the StereoGraphics guide's example in the sheet's terms",
            ScreenSetup {
                width: 18.0,
                height: 18.0,
                near: 1.0,
                far: 100.0,
                zero_parallax: 9.0,
                eye_separation_fraction: 1.0 / 18.0,
            },
        ),
        (
            "a 16:9 screen 2 away, 6.5 cm eyes",
            ScreenSetup {
                width: 1.6,
                height: 0.9,
                near: 0.3,
                far: 40.0,
                zero_parallax: 2.0,
                eye_separation_fraction: 0.065 / 1.6,
            },
        ),
        (
            "a small portrait screen",
            ScreenSetup {
                width: 0.3,
                height: 0.5,
                near: 0.1,
                far: 10.0,
                zero_parallax: 0.6,
                eye_separation_fraction: 0.2,
            },
        ),
        (
            "a wide screen, near plane halfway to it",
            ScreenSetup {
                width: 4.0,
                height: 2.0,
                near: 1.0,
                far: 50.0,
                zero_parallax: 2.0,
                eye_separation_fraction: 0.25,
            },
        ),
    ]
}

/// A random but sensible screen for hidden cases.
fn random_screen(rng: &mut SplitMix64) -> ScreenSetup {
    let zero_parallax = rng.range(0.5, 20.0);
    let near = zero_parallax * rng.range(0.05, 0.9);
    ScreenSetup {
        width: rng.range(0.2, 10.0),
        height: rng.range(0.2, 10.0),
        near,
        far: zero_parallax * rng.range(1.5, 50.0),
        zero_parallax,
        eye_separation_fraction: rng.range(0.01, 0.3),
    }
}

pub(super) fn sheet_frustum_task() -> TaskSpec {
    let inputs: Vec<(&str, ScreenSetup, Eye)> = named_screens()
        .into_iter()
        .flat_map(|(name, s)| Eye::BOTH.map(|eye| (name, s, eye)))
        .collect();
    let each = |v: SheetVariant| {
        inputs
            .iter()
            .map(|(_, s, eye)| flat(&sheet_reference(s, *eye, v)))
            .collect()
    };
    TaskSpec {
        name: "sheet_frustum",
        points: 1.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("sheet_frustum", 8, |rng, i| {
            let s = random_screen(rng);
            let eye = Eye::BOTH[i % 2];
            Case {
                label: format!("hidden: eye {} of {s:?}", eye.index()),
                input: json!([s, eye]),
                expected: flat(&sheet_reference(&s, eye, SheetVariant::default())),
            }
        }),
        tolerance: SHEET_TOLERANCE,
        cases: inputs
            .iter()
            .map(|(name, s, eye)| Case {
                label: format!("eye {}, {name}: {s:?}", eye.index()),
                input: json!([s, eye]),
                expected: flat(&sheet_reference(s, *eye, SheetVariant::default())),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "swapped-eyes",
                hint: "swapped eyes (or the sign of the shift): eye 0 is the LEFT eye at \
                       x = −½·d·w, and its l and r move by +½·d·w·n/z0",
                answers: each(SheetVariant {
                    swapped: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "screen-not-near-plane",
                hint: "l, r, b, t lie on the NEAR plane, not on the screen: scale the screen's \
                       ½·w, ½·h and the shift ½·d·w by n/z0 (intercept theorem: t = ½·h·n/z0)",
                answers: each(SheetVariant {
                    unscaled: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "missing-near-scale",
                hint: "the shift lies on the near plane too: ±½·d·w·n/z0, not ±½·d·w",
                answers: each(SheetVariant {
                    unscaled_shift: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "d-not-d-times-w",
                hint: "d is a FRACTION of the screen width: the eyes are d·w apart, so the shift \
                       is ½·d·w·n/z0, not ½·d·n/z0",
                answers: each(SheetVariant {
                    d_not_dw: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "d-instead-of-half-d",
                hint: "d·w instead of ½·d·w: each eye sits HALF the separation from the center",
                answers: each(SheetVariant {
                    full_separation: true,
                    ..Default::default()
                }),
            },
        ],
        image: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sheets_frustum_of_the_stereographics_example_is_the_field_of_view_one() {
        // Camera 9 from the screen, 90°: t = n·tan(45°) = 1 = ½·18·1/9; the shift (d/2)·n/z0
        // with d = 1 is 1/18 = ½·(1/18)·18·(1/9).
        let s = &named_screens()[0].1;
        let left = sheet_reference(s, Eye::Left, SheetVariant::default());
        let expected = [-1.0 + 1.0 / 18.0, 1.0 + 1.0 / 18.0, -1.0, 1.0, 1.0, 100.0];
        for (a, e) in left.iter().zip(expected) {
            assert!((a - e).abs() < 1e-7, "{left:?}");
        }
        let right = sheet_reference(s, Eye::Right, SheetVariant::default());
        assert!((right[0] + 1.0 + 1.0 / 18.0).abs() < 1e-7, "{right:?}");
    }

    #[test]
    fn every_public_case_tells_each_slip_from_the_right_answer() {
        let inputs: Vec<(ScreenSetup, Eye)> = named_screens()
            .into_iter()
            .flat_map(|(_, s)| Eye::BOTH.map(|eye| (s, eye)))
            .collect();
        let slips = [
            SheetVariant {
                swapped: true,
                ..Default::default()
            },
            SheetVariant {
                unscaled: true,
                ..Default::default()
            },
            SheetVariant {
                unscaled_shift: true,
                ..Default::default()
            },
            SheetVariant {
                d_not_dw: true,
                ..Default::default()
            },
            SheetVariant {
                full_separation: true,
                ..Default::default()
            },
        ];
        for v in slips {
            for (s, eye) in &inputs {
                let ok = sheet_reference(s, *eye, SheetVariant::default());
                let bad = sheet_reference(s, *eye, v);
                assert!(!SHEET_TOLERANCE.accepts(&ok, &bad), "{s:?} {eye:?} eye");
            }
        }
    }
}
