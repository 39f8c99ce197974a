//! Exercise 1's `visible` task: whether a left pixel is seen by the right eye (occlusion).

use serde_json::json;

use super::remap::{stereolab_remap, texel_of};
use super::{flat, left_samples};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, SplitMix64, TaskSpec, Tolerance, hidden_cases};

/// The visibility inputs `(uv_right, remapped, stored, tolerance)` of a left pixel, using the
/// reference remap and a nearest lookup in the right depth buffer.
type VisibleInput = (Option<[f32; 2]>, f32, f32, f32);

/// Depth tolerance of the fixture's visibility check: a few times the depth change across one
/// pixel on the fixture's slanted faces (nearest-texel lookup error), ~5e-4 at 64×48.
const FIXTURE_DEPTH_TOLERANCE: f32 = 2e-3;

fn fixture_visible_inputs(fx: &Fixture) -> Vec<(u32, u32, VisibleInput)> {
    let (l, r) = (fx.eyes[0].mvp, fx.eyes[1].mvp);
    let (w, h) = fx.size();
    let right = &fx.views[1];
    left_samples(fx)
        .into_iter()
        .map(|(x, y, _, d)| {
            let a = stereolab_remap(&l, &r, (w, h), (x, y), d);
            let input = match a.as_slice() {
                [u, v, z] => {
                    let stored = texel_of(*u, *v, w, h)
                        .map_or(1.0, |(tx, ty)| right.depth()[right.index(tx, ty)]);
                    (
                        Some([*u as f32, *v as f32]),
                        *z as f32,
                        stored,
                        FIXTURE_DEPTH_TOLERANCE,
                    )
                }
                _ => (None, 1.0, 1.0, FIXTURE_DEPTH_TOLERANCE),
            };
            (x, y, input)
        })
        .collect()
}

/// The reference visibility check, with the known mistakes as switches.
fn visible_reference(i: &VisibleInput, mistake: Option<&str>) -> bool {
    let (uv, remapped, stored, tol) = *i;
    let Some([u, v]) = uv else { return false };
    let inside = (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v);
    match mistake {
        Some("ignores-out-of-frame") => (stored - remapped).abs() <= tol,
        Some("no-tolerance") => inside && stored == remapped,
        Some("one-sided") => inside && stored >= remapped - tol,
        _ => inside && (stored - remapped).abs() <= tol,
    }
}

/// Occlusion map: left color where visible to the right eye, red where not.
const HIDDEN_COLOR: [u8; 4] = [230, 40, 40, 255];

/// Hidden visibility cases per seed.
const HIDDEN_VISIBLE: usize = 10;

/// Hidden case `i`: inside the image or clearly outside it (never on its border; case 3 outside
/// with agreeing depths, case 9 behind the right eye), depths that agree, differ a little
/// inside the tolerance, or clearly beyond it in either direction (never on its edge).
fn hidden_visible(rng: &mut SplitMix64, i: usize) -> VisibleInput {
    let mut coordinate = |outside: bool| {
        if outside {
            let c = rng.range(0.02, 0.3);
            if rng.next_u64().is_multiple_of(2) {
                -c
            } else {
                1.0 + c
            }
        } else {
            rng.range(0.01, 0.99)
        }
    };
    let outside = i % 5 == 3;
    let uv = (i % 10 != 9).then(|| [coordinate(outside), coordinate(false)]);
    let remapped = rng.range(0.2, 0.98);
    let tol = rng.range(1e-4, 5e-3);
    let factor = match i % 3 {
        0 => rng.range(-0.5, 0.5),
        1 => rng.range(2.0, 20.0),
        _ => -rng.range(2.0, 20.0),
    };
    let stored = (remapped + factor * tol).min(1.0);
    (uv, remapped, stored, tol)
}

pub(super) fn visible_task(fx: &Fixture) -> TaskSpec {
    let mut inputs: Vec<(String, VisibleInput)> = vec![
        ("behind the right eye".into(), (None, 0.5, 0.5, 1e-3)),
        (
            "right of the image".into(),
            (Some([1.2, 0.5]), 0.5, 0.5, 1e-3),
        ),
        (
            "below the image".into(),
            (Some([0.5, -0.1]), 0.6, 0.6, 1e-3),
        ),
        (
            "within tolerance".into(),
            (Some([0.5, 0.5]), 0.6, 0.6004, 1e-3),
        ),
        ("occluded".into(), (Some([0.5, 0.5]), 0.6, 0.55, 1e-3)),
        (
            "exact, zero tolerance".into(),
            (Some([0.3, 0.7]), 0.7, 0.7, 0.0),
        ),
        ("stored farther".into(), (Some([0.3, 0.7]), 0.7, 0.72, 1e-3)),
        (
            "just inside, farther within tolerance".into(),
            (Some([0.3, 0.7]), 0.7, 0.7008, 1e-3),
        ),
    ];
    let fixture_inputs = fixture_visible_inputs(fx);
    inputs.extend(
        fixture_inputs
            .iter()
            .enumerate()
            .filter(|(i, _)| i % 53 == 0)
            .map(|(_, (x, y, i))| (format!("left pixel ({x}, {y})"), *i)),
    );
    let cases = inputs
        .iter()
        .map(|(label, i)| Case {
            label: format!("{label}: {i:?}"),
            input: json!(i),
            expected: flat(&visible_reference(i, None)),
        })
        .collect();
    let each = |m: &str| {
        inputs
            .iter()
            .map(|(_, i)| flat(&visible_reference(i, Some(m))))
            .collect()
    };
    let picture = {
        let left = fx.views[0].clone();
        let pixels: Vec<(u32, u32)> = fixture_inputs.iter().map(|(x, y, _)| (*x, *y)).collect();
        move |answers: &[Option<bool>]| {
            let mut fb = left.clone();
            for ((x, y), a) in pixels.iter().zip(answers) {
                let i = fb.index(*x, *y);
                if *a != Some(true) {
                    fb.color_mut()[i] = HIDDEN_COLOR;
                }
            }
            fb
        }
    };
    let expected = picture(
        &fixture_inputs
            .iter()
            .map(|(_, _, i)| Some(visible_reference(i, None)))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        let a: Vec<Option<bool>> = answers
            .iter()
            .map(|a| a.as_ref().filter(|a| a.len() == 1).map(|a| a[0] == 1.0))
            .collect();
        vec![Picture {
            name: "visible_occlusion_map".into(),
            expected: expected.clone(),
            actual: picture(&a),
        }]
    };
    TaskSpec {
        name: "visible",
        points: 1.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("visible", HIDDEN_VISIBLE, |rng, i| {
            let input = hidden_visible(rng, i);
            Case {
                label: format!("hidden: {input:?}"),
                input: json!(input),
                expected: flat(&visible_reference(&input, None)),
            }
        }),
        tolerance: Tolerance::EXACT,
        cases,
        mistakes: vec![
            Mistake {
                id: "ignores-out-of-frame",
                hint: "a point remapped outside [0, 1]² is not in the right image at all: not \
                       visible",
                answers: each("ignores-out-of-frame"),
            },
            Mistake {
                id: "no-tolerance",
                hint: "compare depths within the tolerance, |stored − remapped| ≤ tolerance: \
                       exact equality fails on resampled depth",
                answers: each("no-tolerance"),
            },
            Mistake {
                id: "one-sided",
                hint: "visible means the depths AGREE within the tolerance; a stored depth far \
                       behind the point is a mismatch too",
                answers: each("one-sided"),
            },
        ],
        image: Some(crate::pictures::check(
            fixture_inputs.iter().map(|(_, _, i)| json!(i)).collect(),
            Box::new(build),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_seed_s_hidden_cases_catch_each_known_mistake() {
        for seed in 0..200u64 {
            let mut rng = SplitMix64::for_task(seed, "visible");
            let inputs: Vec<VisibleInput> = (0..HIDDEN_VISIBLE)
                .map(|i| hidden_visible(&mut rng, i))
                .collect();
            for m in ["ignores-out-of-frame", "no-tolerance", "one-sided"] {
                assert!(
                    inputs
                        .iter()
                        .any(|i| visible_reference(i, None) != visible_reference(i, Some(m))),
                    "seed {seed}: {m} passes every hidden case: {inputs:?}"
                );
            }
        }
    }
}
