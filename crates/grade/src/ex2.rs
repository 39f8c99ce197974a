//! Exercise 2 (the ChromaDepth article, ChromaDepth): the tasks, reference answers, mistakes, image checks.
//!
//! The reference is stereolab's ChromaDepth module (`effects::chromadepth`): its exact HSV ramp,
//! its texgen plane and its bounding-sphere range; the texgen image check renders the real
//! ChromaDepth pass with the student's plane.

use glam::{Vec3, Vec4};
use serde_json::json;

use super::ex1::flat;
use super::fixture::Fixture;
use super::spec::{Case, Mistake, Picture, TaskSpec, Tolerance, hidden_cases};
use stereolab::render::chromadepth::ChromaDepthShader;
use stereolab::scene::Scene;
use stereolab_core::{
    ChromaDepthSettings, EyeMatrices, Framebuffer, Ramp, RampKind, Texgen, auto_range, hsv_to_rgb,
    ramp_exact, rasterize, to_rgba8,
};

/// Every task of exercise 2.
pub(crate) fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![ramp_task(), texgen_task(fx), depth_range_task()]
}

/// HSV (hue in degrees, S = V = 1) to RGB.
fn hue_to_rgb(hue: f32) -> [f32; 3] {
    hsv_to_rgb(hue, 1.0, 1.0).to_array()
}

/// The ChromaDepth article's ramp as stereolab computes it: hue 240° · clamp(t), red near, blue far.
pub(crate) fn reference_ramp(t: f32) -> [f32; 3] {
    ramp_exact(RampKind::Hsv, t).to_array()
}

/// The ChromaDepth article's texgen plane `[A, B, C, D]` as stereolab's `Texgen::from_range` computes it; for
/// `d1 ≥ d2`, which it refuses, the formula itself.
pub(crate) fn reference_texgen(d1: f32, d2: f32) -> [f32; 4] {
    Texgen::from_range(d1, d2).map_or_else(
        |_| [0.0, 0.0, -1.0 / (d2 - d1), -d1 / (d2 - d1)],
        |t| t.plane.to_array(),
    )
}

const RAMP_STRIP_WIDTH: u32 = 64;
const RAMP_STRIP_HEIGHT: u32 = 6;

fn strip(colors: &[Option<[f32; 3]>]) -> Framebuffer {
    let mut fb = Framebuffer::new(RAMP_STRIP_WIDTH, RAMP_STRIP_HEIGHT, [0, 0, 0, 255])
        .expect("a valid constant size");
    fb.cover_all();
    for y in 0..RAMP_STRIP_HEIGHT {
        for (x, c) in colors.iter().enumerate() {
            let i = fb.index(x as u32, y);
            fb.color_mut()[i] = c.map_or([0, 0, 0, 255], |c| to_rgba8(Vec3::from(c)));
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
        depends_on: &[],
        hidden: hidden_cases("hsv_ramp", 8, |rng, i| {
            // Mostly inside the ramp, one below and one above it.
            let t = match i {
                0 => rng.range(-0.5, -0.01),
                1 => rng.range(1.01, 1.5),
                _ => rng.range(0.0, 1.0),
            };
            Case {
                label: format!("hidden: t = {t}"),
                input: json!(t),
                expected: flat(&reference_ramp(t)),
            }
        }),
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
        image: Some(crate::pictures::check(
            strip_ts.iter().map(|t| json!(t)).collect(),
            Box::new(build),
        )),
    }
}

/// The ChromaDepth article's bounding-sphere range of the fixture's objects, seen from the cyclopean eye
/// (stereolab's `auto_range`, which keeps it between the clip planes).
fn fixture_range(fx: &Fixture) -> [f32; 2] {
    let points: Vec<Vec3> = fx.scene.world_points().collect();
    let (n, f) = (fx.scene.camera.near, fx.scene.camera.far);
    auto_range(&points, fx.center_matrices.view, n, f).map_or([n, f], |(a, b)| [a, b])
}

/// The real ChromaDepth pass (HSV ramp, the scene's other settings) seen with `m`, with the
/// texgen plane `plane` (blank for a missing or non-finite plane).
fn chromadepth_render(scene: &Scene, m: &EyeMatrices, plane: Option<[f32; 4]>) -> Framebuffer {
    let mut fb = Framebuffer::new(scene.width, scene.height, scene.background)
        .expect("the scene's size was validated");
    let Some(p) = plane.filter(|p| p.iter().all(|x| x.is_finite())) else {
        return fb;
    };
    let settings = ChromaDepthSettings {
        ramp: RampKind::Hsv,
        ..scene.chromadepth.clone()
    };
    let Ok(ramp) = Ramp::new(settings.ramp, settings.texels) else {
        return fb;
    };
    // d1, d2 only label the plane; the shader evaluates the plane itself.
    let texgen = Texgen {
        plane: Vec4::from(p),
        d1: 0.0,
        d2: 1.0,
    };
    for o in &scene.objects {
        let shader = ChromaDepthShader::new(o, m, texgen, &ramp, &settings, scene);
        rasterize(
            &o.mesh.triangles,
            o.mesh.positions.len(),
            &shader,
            &mut fb,
            &scene.raster,
        );
    }
    fb
}

fn texgen_task(fx: &Fixture) -> TaskSpec {
    let range = fixture_range(fx);
    let inputs = [[5.0f32, 15.0], [1.0, 20.0], [0.5, 0.75], range];
    let each =
        |f: &dyn Fn(f32, f32) -> [f32; 4]| inputs.iter().map(|[a, b]| flat(&f(*a, *b))).collect();
    let (scene, m) = (fx.scene.clone(), fx.center_matrices);
    let expected = chromadepth_render(&scene, &m, Some(reference_texgen(range[0], range[1])));
    let pictures = move |answers: &[Option<Vec<f64>>]| {
        let plane = match answers.first().and_then(|a| a.as_deref()) {
            Some([a, b, c, d]) => Some([*a as f32, *b as f32, *c as f32, *d as f32]),
            _ => None,
        };
        vec![Picture {
            name: "chromadepth_texgen".into(),
            expected: expected.clone(),
            actual: chromadepth_render(&scene, &m, plane),
        }]
    };
    TaskSpec {
        name: "texgen",
        points: 2.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("texgen", 6, |rng, _| {
            let d1 = rng.range(0.1, 50.0);
            let d2 = d1 + rng.range(0.1, 100.0);
            Case {
                label: format!("hidden: D1 = {d1}, D2 = {d2}"),
                input: json!([d1, d2]),
                expected: flat(&reference_texgen(d1, d2)),
            }
        }),
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
        image: Some(crate::pictures::check(
            vec![json!(range)],
            Box::new(pictures),
        )),
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
        depends_on: &[],
        hidden: hidden_cases("depth_range", 6, |rng, _| {
            let c = [
                rng.range(-5.0, 5.0),
                rng.range(-5.0, 5.0),
                -rng.range(1.0, 100.0),
            ];
            let r = rng.range(0.1, 0.9) * -c[2];
            Case {
                label: format!("hidden: center {c:?}, radius {r}"),
                input: json!([c, r]),
                expected: flat(&range(c, r)),
            }
        }),
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
