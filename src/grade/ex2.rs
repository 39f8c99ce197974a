//! Exercise 2 (seed 000, ChromaDepth): the tasks, reference answers, mistakes, image checks.
//!
//! The reference ramp and texgen are the grader's own (seed 000's formulas, below) until the
//! ChromaDepth module lands on main.

use glam::Vec3;
use serde_json::json;

use super::ex1::{blank, flat};
use super::fixture::{Fixture, unproject};
use super::spec::{Case, ImageCheck, Mistake, Picture, TaskSpec, Tolerance};
use crate::framebuffer::Framebuffer;
use crate::math::EyeMatrices;
use crate::shade::to_rgba8;

/// Every task of exercise 2.
pub fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![ramp_task(), texgen_task(fx), depth_range_task()]
}

/// HSV (hue in degrees, S = V = 1) to RGB.
fn hue_to_rgb(hue: f32) -> [f32; 3] {
    let h = hue.rem_euclid(360.0) / 60.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    match h as u32 {
        0 => [1.0, x, 0.0],
        1 => [x, 1.0, 0.0],
        2 => [0.0, 1.0, x],
        3 => [0.0, x, 1.0],
        4 => [x, 0.0, 1.0],
        _ => [1.0, 0.0, x],
    }
}

/// Seed 000's ramp: hue 240° · clamp(t), red near, blue far.
pub fn reference_ramp(t: f32) -> [f32; 3] {
    hue_to_rgb(240.0 * t.clamp(0.0, 1.0))
}

/// Seed 000's texgen plane `[A, B, C, D]`.
pub fn reference_texgen(d1: f32, d2: f32) -> [f32; 4] {
    [0.0, 0.0, -1.0 / (d2 - d1), -d1 / (d2 - d1)]
}

const RAMP_STRIP_WIDTH: u32 = 64;
const RAMP_STRIP_HEIGHT: u32 = 6;

fn strip(colors: &[Option<[f32; 3]>]) -> Framebuffer {
    let mut fb = Framebuffer::new(RAMP_STRIP_WIDTH, RAMP_STRIP_HEIGHT, [0, 0, 0, 255])
        .expect("a valid constant size");
    fb.depth.fill(0.0);
    for y in 0..RAMP_STRIP_HEIGHT {
        for (x, c) in colors.iter().enumerate() {
            let i = fb.index(x as u32, y);
            fb.color[i] = c.map_or([0, 0, 0, 255], |c| to_rgba8(Vec3::from(c)));
        }
    }
    fb
}

fn rgb_of(a: &Option<Vec<f64>>) -> Option<[f32; 3]> {
    match a.as_deref() {
        Some([r, g, b]) => Some([*r as f32, *g as f32, *b as f32]),
        _ => None,
    }
}

fn ramp_task() -> TaskSpec {
    let ts = [0.0, 1.0 / 6.0, 0.25, 0.5, 0.6, 0.75, 0.9, 1.0, -0.2, 1.3];
    let each = |f: &dyn Fn(f32) -> [f32; 3]| ts.iter().map(|t| flat(&f(*t))).collect();
    let strip_ts: Vec<f32> = (0..RAMP_STRIP_WIDTH)
        .map(|x| (x as f32 + 0.5) / RAMP_STRIP_WIDTH as f32)
        .collect();
    let expected = strip(
        &strip_ts
            .iter()
            .map(|t| Some(reference_ramp(*t)))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: "hsv_ramp_strip".into(),
            expected: expected.clone(),
            actual: strip(&answers.iter().map(rgb_of).collect::<Vec<_>>()),
        }]
    };
    TaskSpec {
        name: "hsv_ramp",
        points: 2.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 1e-5,
            rel: 0.0,
            why: "HSV sextant arithmetic in f32: ~1e-7 per step",
        },
        cases: ts
            .iter()
            .map(|t| Case {
                label: format!("t = {t}"),
                input: json!(t),
                expected: flat(&reference_ramp(*t)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "ramp-reversed",
                hint: "the ramp runs backwards: NEAR is red (t = 0, hue 0°), FAR is blue \
                       (t = 1, hue 240°)",
                answers: each(&|t| reference_ramp(1.0 - t.clamp(0.0, 1.0))),
            },
            Mistake {
                id: "ramp-full-circle",
                hint: "the hue runs to 240° (blue), not around the whole circle to 360° (back to \
                       red)",
                answers: each(&|t| hue_to_rgb(360.0 * t.clamp(0.0, 1.0))),
            },
            Mistake {
                id: "ramp-rgb-lerp",
                hint: "interpolate in HSV, not in RGB: halfway between red and green is yellow \
                       (1, 1, 0), not (0.5, 0.5, 0)",
                answers: each(&|t| {
                    let t = t.clamp(0.0, 1.0);
                    if t < 0.5 {
                        [1.0 - 2.0 * t, 2.0 * t, 0.0]
                    } else {
                        [0.0, 2.0 - 2.0 * t, 2.0 * t - 1.0]
                    }
                }),
            },
            Mistake {
                id: "no-clamp",
                hint: "clamp t to [0, 1] first (GL_CLAMP): outside the ramp the end colors hold",
                answers: each(&|t| hue_to_rgb(240.0 * t)),
            },
        ],
        image: Some(ImageCheck {
            inputs: strip_ts.iter().map(|t| json!(t)).collect(),
            build: Box::new(build),
        }),
    }
}

/// Seed 000's bounding-sphere range of the fixture's objects, seen from the cyclopean eye.
fn fixture_range(fx: &Fixture) -> [f32; 2] {
    let view = fx.center_matrices.view;
    let pts: Vec<Vec3> = fx
        .scene
        .world_points()
        .map(|p| view.transform_point3(p))
        .collect();
    let (lo, hi) = pts.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    let c = 0.5 * (lo + hi);
    let r = pts.iter().map(|p| p.distance(c)).fold(0.0, f32::max);
    [(-c.z - r).max(fx.scene.camera.near), -c.z + r]
}

/// The cyclopean view colored by the reference ramp at `s` from `plane` (eye-space texgen).
fn chromadepth_picture(
    center: &Framebuffer,
    m: &EyeMatrices,
    background: [u8; 4],
    plane: Option<[f32; 4]>,
) -> Framebuffer {
    let Some(p) = plane.filter(|p| p.iter().all(|x| x.is_finite())) else {
        return blank(center, background);
    };
    let mut fb = center.clone();
    for y in 0..fb.height {
        for x in 0..fb.width {
            if let Some(e) = unproject(m, center, x, y) {
                let s = p[0] * e.x + p[1] * e.y + p[2] * e.z + p[3];
                let i = fb.index(x, y);
                fb.color[i] = to_rgba8(Vec3::from(reference_ramp(s)));
            }
        }
    }
    fb
}

fn texgen_task(fx: &Fixture) -> TaskSpec {
    let range = fixture_range(fx);
    let inputs = [[5.0f32, 15.0], [1.0, 20.0], [0.5, 0.75], range];
    let each =
        |f: &dyn Fn(f32, f32) -> [f32; 4]| inputs.iter().map(|[a, b]| flat(&f(*a, *b))).collect();
    let (center, m, bg) = (fx.center.clone(), fx.center_matrices, fx.scene.background);
    let expected = chromadepth_picture(&center, &m, bg, Some(reference_texgen(range[0], range[1])));
    let pictures = move |answers: &[Option<Vec<f64>>]| {
        let plane = match answers.first().and_then(|a| a.as_deref()) {
            Some([a, b, c, d]) => Some([*a as f32, *b as f32, *c as f32, *d as f32]),
            _ => None,
        };
        vec![Picture {
            name: "chromadepth_texgen".into(),
            expected: expected.clone(),
            actual: chromadepth_picture(&center, &m, bg, plane),
        }]
    };
    TaskSpec {
        name: "texgen",
        points: 2.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 1e-5,
            why: "two divisions in f32",
        },
        cases: inputs
            .iter()
            .map(|[a, b]| Case {
                label: format!("D1 = {a}, D2 = {b}"),
                input: json!([a, b]),
                expected: flat(&reference_texgen(*a, *b)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "texgen-sign",
                hint: "sign of C: eye space looks down −Z, a point d in front of the eye has \
                       z = −d, so C = −1/(D2 − D1)",
                answers: each(&|a, b| {
                    let mut p = reference_texgen(a, b);
                    p[2] = -p[2];
                    p
                }),
            },
            Mistake {
                id: "texgen-swapped-range",
                hint: "D1 and D2 swapped: s = 0 at D1 (near, red), s = 1 at D2 (far, blue)",
                answers: each(&|a, b| reference_texgen(b, a)),
            },
            Mistake {
                id: "texgen-sign-d",
                hint: "sign of D: D = −D1/(D2 − D1) so that s(z = −D1) = 0",
                answers: each(&|a, b| {
                    let mut p = reference_texgen(a, b);
                    p[3] = -p[3];
                    p
                }),
            },
        ],
        image: Some(ImageCheck {
            inputs: vec![json!(range)],
            build: Box::new(pictures),
        }),
    }
}

fn depth_range_task() -> TaskSpec {
    let inputs: [([f32; 3], f32); 4] = [
        ([0.0, 0.0, -10.0], 5.0),
        ([1.0, -2.0, -7.5], 1.5),
        ([0.3, 0.2, -4.0], 0.25),
        ([-3.0, 1.0, -30.0], 12.0),
    ];
    let range = |c: [f32; 3], r: f32| [-c[2] - r, -c[2] + r];
    let each = |f: &dyn Fn([f32; 3], f32) -> [f32; 2]| {
        inputs.iter().map(|(c, r)| flat(&f(*c, *r))).collect()
    };
    TaskSpec {
        name: "depth_range",
        points: 1.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 1e-6,
            rel: 1e-6,
            why: "one addition in f32",
        },
        cases: inputs
            .iter()
            .map(|(c, r)| Case {
                label: format!("center {c:?}, radius {r}"),
                input: json!([c, r]),
                expected: flat(&range(*c, *r)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "range-sign",
                hint: "the sphere's distance in front of the eye is −center.z (eye space looks \
                       down −Z)",
                answers: each(&|c, r| [c[2] - r, c[2] + r]),
            },
            Mistake {
                id: "range-euclidean",
                hint: "ChromaDepth colors by depth along the view axis (−z), not by Euclidean \
                       distance to the eye",
                answers: each(&|c, r| {
                    let d = Vec3::from(c).length();
                    [d - r, d + r]
                }),
            },
            Mistake {
                id: "range-diameter",
                hint: "D1 and D2 lie one RADIUS in front of and behind the center",
                answers: each(&|c, r| [-c[2] - 2.0 * r, -c[2] + 2.0 * r]),
            },
        ],
        image: None,
    }
}
