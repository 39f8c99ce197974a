//! Exercise 1's parallax tasks: the screen parallax of a depth and its color map.

use glam::Vec3;
use serde_json::json;

use super::{flat, left_samples};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, TaskSpec, Tolerance, hidden_cases};
use stereolab_core::to_rgba8;

pub(super) fn parallax_task() -> TaskSpec {
    let inputs: [[f32; 3]; 7] = [
        [5.0, 5.0, 0.4],
        [2.5, 5.0, 0.4],
        [10.0, 5.0, 0.4],
        [1.0e6, 5.0, 0.4],
        [3.0, 6.0, 0.065],
        [7.5, 4.8, 1.2],
        [0.5, 5.0, 0.3],
    ];
    let p = |[z, z0, d]: [f32; 3]| d * (1.0 - z0 / z);
    let each = |f: &dyn Fn([f32; 3]) -> f32| inputs.iter().map(|i| vec![f(*i) as f64]).collect();
    TaskSpec {
        name: "parallax",
        points: 1.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("parallax", 6, |rng, _| {
            let i = [
                rng.range(0.1, 100.0),
                rng.range(0.5, 20.0),
                rng.range(0.03, 2.0),
            ];
            Case {
                label: format!("hidden: z = {}, z0 = {}, d = {}", i[0], i[1], i[2]),
                input: json!(i),
                expected: vec![p(i) as f64],
            }
        }),
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 1e-5,
            why: "one division and one product in f32",
        },
        cases: inputs
            .iter()
            .map(|i| Case {
                label: format!("z = {}, z0 = {}, d = {}", i[0], i[1], i[2]),
                input: json!(i),
                expected: vec![p(*i) as f64],
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "parallax-sign",
                hint: "sign of the parallax: points in front of the screen (z < z0) have \
                       NEGATIVE parallax: p = d·(1 − z0/z)",
                answers: each(&|i| -p(i)),
            },
            Mistake {
                id: "d-instead-of-half-d",
                hint: "half the separation: the parallax is the distance between the two \
                       projections, d·(1 − z0/z), not (d/2)·(…)",
                answers: each(&|i| 0.5 * p(i)),
            },
            Mistake {
                id: "inverted-ratio",
                hint: "the ratio is z0/z (screen distance over point distance), not z/z0",
                answers: each(&|[z, z0, d]| d * (1.0 - z / z0)),
            },
        ],
        image: None,
    }
}

fn color_reference(p: f32, max: f32, swapped: bool) -> [f32; 3] {
    let t = (p / max).clamp(-1.0, 1.0);
    let t = if swapped { -t } else { t };
    if t >= 0.0 {
        [t, 0.0, 0.0]
    } else {
        [0.0, 0.0, -t]
    }
}

pub(super) fn parallax_color_task(fx: &Fixture) -> TaskSpec {
    let inputs: [[f32; 2]; 6] = [
        [0.2, 0.4],
        [-0.1, 0.4],
        [0.0, 1.0],
        [0.8, 0.4],
        [-2.0, 0.5],
        [0.05, 0.1],
    ];
    let each = |f: &dyn Fn([f32; 2]) -> [f32; 3]| inputs.iter().map(|i| flat(&f(*i))).collect();
    // Image: the left view colored by the reference parallax of each covered pixel.
    let z0 = fx.setup.zero_parallax;
    let d = fx.setup.eye_separation;
    let samples: Vec<(u32, u32, f32)> = left_samples(fx)
        .into_iter()
        .filter_map(|(x, y, _, _)| {
            let p = fx.unproject(&fx.eyes[0], &fx.views[0], x, y)?;
            Some((x, y, d * (1.0 - z0 / -p.z)))
        })
        .collect();
    let max = samples
        .iter()
        .map(|s| s.2.abs())
        .fold(f32::MIN_POSITIVE, f32::max);
    let canvas = fx.canvas_over(&fx.views[0], fx.scene.background);
    let picture = {
        let samples = samples.clone();
        move |answers: &[Option<Vec<f64>>]| {
            let mut fb = canvas.clone();
            for ((x, y, _), a) in samples.iter().zip(answers) {
                let i = fb.index(*x, *y);
                fb.color_mut()[i] = match a.as_deref() {
                    Some([r, g, b]) => to_rgba8(Vec3::new(*r as f32, *g as f32, *b as f32)),
                    _ => [0, 0, 0, 255],
                };
            }
            fb
        }
    };
    let expected = picture(
        &samples
            .iter()
            .map(|(_, _, p)| Some(flat(&color_reference(*p, max, false))))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: "parallax_color_map".into(),
            expected: expected.clone(),
            actual: picture(answers),
        }]
    };
    TaskSpec {
        name: "parallax_color",
        points: 1.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("parallax_color", 6, |rng, _| {
            let max = rng.range(0.05, 2.0);
            let p = rng.range(-1.5 * max, 1.5 * max);
            Case {
                label: format!("hidden: p = {p}, max = {max}"),
                input: json!([p, max]),
                expected: flat(&color_reference(p, max, false)),
            }
        }),
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 0.0,
            why: "one division in f32",
        },
        cases: inputs
            .iter()
            .map(|i| Case {
                label: format!("p = {}, max = {}", i[0], i[1]),
                input: json!(i),
                expected: flat(&color_reference(i[0], i[1], false)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "parallax-colors-swapped",
                hint: "colors swapped: the exercise slides show NEGATIVE parallax (in front of the screen) \
                       blue and positive red",
                answers: each(&|[p, m]| color_reference(p, m, true)),
            },
            Mistake {
                id: "no-clamp",
                hint: "clamp p / max_abs to [−1, 1] before it becomes a color",
                answers: each(&|[p, m]| {
                    let t = p / m;
                    if t >= 0.0 {
                        [t, 0.0, 0.0]
                    } else {
                        [0.0, 0.0, -t]
                    }
                }),
            },
        ],
        image: Some(crate::pictures::check(
            samples.iter().map(|(_, _, p)| json!([p, max])).collect(),
            Box::new(build),
        )),
    }
}
