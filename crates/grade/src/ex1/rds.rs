//! Exercise 1's `rds_right` task: the right image of Julesz's random-dot stereo pair (the SIRDS
//! paper (Petz et al.), §1), built by the student from their own `remap_right_to_left` and
//! `visible`. The library's version is [`rds_right`](stereolab_core::rds_right).
//!
//! A case is a whole pair: both eyes' depth buffers rendered by stereolab, their MVPs, the left
//! random dots and the fresh dots, and the depth tolerance. The answer is the right image's dots
//! (1 white, 0 black), top row first. The reference composes the exercise slides' chain in f64
//! ([`remap_reference`]), the nearest-texel lookup and the visibility check with the given
//! tolerance. A pixel whose f64 reference lies so close to a texel edge or to the depth
//! tolerance that f32 rounding may decide it either way, and where the two ways give different
//! dots, is expected as 0.5 and accepts both (the task's tolerance is 0.5 on answers that are 0
//! or 1); every other pixel must be exact.

use glam::Mat4;
use serde_json::{Value, json};

use super::remap::{RemapVariant, remap_reference};
use super::{HIDDEN_SETUPS, eyes, random_setup};
use crate::fixture::{Fixture, pixel_uv};
use crate::spec::{Case, Mistake, Picture, SplitMix64, TaskSpec, Tolerance, hidden_cases};
use stereolab::plan::Shading;
use stereolab::render::render_view;
use stereolab::scene::Scene;
use stereolab_core::{
    Camera, CameraMode, EyeMatrices, Framebuffer, Lighting, rds_dot, right_only_seed,
};

/// The visibility check's depth tolerance (as the `visible` task's fixture uses: a few times the
/// depth change across one pixel on the grading scene's slanted faces at 64×48).
const DEPTH_TOLERANCE: f32 = 2e-3;

/// How close (in pixels) to a texel edge the f64 remap may land before f32 rounding could pick
/// the neighbouring texel. The `remap` task measured f32 chains 3.4e-5 off in texture
/// coordinates at worst over 8000 random setups: 2.2e-3 px at 64 pixels. 5e-3 px leaves room.
const TEXEL_EDGE_PX: f64 = 5e-3;

/// How close the depth difference may come to the tolerance before f32 rounding could decide
/// the visibility check either way (the same measurement: 3.4e-5 at worst).
const DEPTH_EDGE: f64 = 1e-4;

/// Ambiguous pixels are expected as this and accept 0 and 1.
const EITHER: f64 = 0.5;

/// Side of the hidden cases' images (rows; columns follow the random aspect).
const HIDDEN_ROWS: u32 = 24;

/// One pair to build the right dots of.
#[derive(Clone)]
struct RdsCase {
    label: String,
    left_mvp: Mat4,
    right_mvp: Mat4,
    width: u32,
    height: u32,
    left_depth: Vec<f32>,
    right_depth: Vec<f32>,
    left_dots: Vec<bool>,
    fresh_dots: Vec<bool>,
    tolerance: f32,
}

/// Random dots of `seed` (dot size 1, `true` white), the library's texture.
fn dots(seed: u64, width: u32, height: u32) -> Vec<bool> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| rds_dot(seed, 1, x, y)[0] == 255))
        .collect()
}

impl RdsCase {
    fn new(
        label: String,
        eyes: &[EyeMatrices; 2],
        views: [&Framebuffer; 2],
        seed: u64,
        tolerance: f32,
    ) -> RdsCase {
        let (width, height) = (views[0].width(), views[0].height());
        RdsCase {
            label,
            left_mvp: eyes[0].mvp,
            right_mvp: eyes[1].mvp,
            width,
            height,
            left_depth: views[0].depth().to_vec(),
            right_depth: views[1].depth().to_vec(),
            left_dots: dots(seed, width, height),
            fresh_dots: dots(right_only_seed(seed), width, height),
            tolerance,
        }
    }

    /// The input as `rds_right` reads it: `[MVP_l, MVP_r, left depth, right depth, left dots,
    /// fresh dots, tolerance]`, each texture `{width, height, texels}`.
    fn input(&self) -> Value {
        let tex = |t: Value| json!({"width": self.width, "height": self.height, "texels": t});
        json!([
            self.left_mvp.to_cols_array(),
            self.right_mvp.to_cols_array(),
            tex(json!(self.left_depth)),
            tex(json!(self.right_depth)),
            tex(json!(self.left_dots)),
            tex(json!(self.fresh_dots)),
            self.tolerance,
        ])
    }
}

/// The known mistakes as switches (all off: the right answer).
#[derive(Clone, Copy, Default)]
struct Variant {
    /// Takes the left dot wherever the remap lands inside the image.
    no_visibility: bool,
    /// Texel row `⌊v·h⌋` instead of `⌊(1 − v)·h⌋`.
    v_not_flipped: bool,
    /// Pixel (x, y) at `(x/w, 1 − y/h)`, its corner, instead of its center.
    pixel_corner: bool,
    /// The left dot at the same pixel instead of a fresh one where the left eye does not see.
    left_fallback: bool,
    /// `remap` (left to right) applied to the right pixel instead of `remap_right_to_left`.
    wrong_direction: bool,
}

/// The dots of the right image under variant `v`, top row first: 1 white, 0 black,
/// [`EITHER`] where f32 rounding may decide it either way.
fn reference(c: &RdsCase, v: Variant) -> Vec<f64> {
    let (w, h) = (c.width, c.height);
    let (wf, hf) = (f64::from(w), f64::from(h));
    let bit = |b: bool| if b { 1.0 } else { 0.0 };
    // `remap_reference(from, to, …)`: the right pixel goes from the right eye into the left.
    let (from, to) = if v.wrong_direction {
        (c.left_mvp, c.right_mvp)
    } else {
        (c.right_mvp, c.left_mvp)
    };
    let mut out = Vec::with_capacity(c.right_depth.len());
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let uv = if v.pixel_corner {
                [x as f32 / w as f32, 1.0 - y as f32 / h as f32]
            } else {
                pixel_uv(w, h, x, y)
            };
            let fallback = if v.left_fallback {
                c.left_dots[i]
            } else {
                c.fresh_dots[i]
            };
            let m = remap_reference(&from, &to, uv, c.right_depth[i], RemapVariant::default());
            let [u, vv, depth] = m[..] else {
                out.push(bit(fallback));
                continue;
            };
            let wx = u * wf;
            let wy = if v.v_not_flipped {
                vv * hf
            } else {
                (1.0 - vv) * hf
            };
            let mut outcomes = Vec::with_capacity(8);
            for tx in [(wx - TEXEL_EDGE_PX).floor(), (wx + TEXEL_EDGE_PX).floor()] {
                for ty in [(wy - TEXEL_EDGE_PX).floor(), (wy + TEXEL_EDGE_PX).floor()] {
                    if tx < 0.0 || ty < 0.0 || tx >= wf || ty >= hf {
                        outcomes.push(fallback);
                        continue;
                    }
                    let t = (ty as u32 * w + tx as u32) as usize;
                    let gap = (f64::from(c.left_depth[t]) - depth).abs() - f64::from(c.tolerance);
                    let seen: &[bool] = if v.no_visibility {
                        &[true]
                    } else if gap.abs() <= DEPTH_EDGE {
                        &[true, false]
                    } else {
                        &[gap <= 0.0]
                    };
                    outcomes.extend(
                        seen.iter()
                            .map(|&s| if s { c.left_dots[t] } else { fallback }),
                    );
                }
            }
            out.push(if outcomes.iter().all(|&o| o == outcomes[0]) {
                bit(outcomes[0])
            } else {
                EITHER
            });
        }
    }
    out
}

/// The grading scene at another size, camera and rig, rendered by both eyes of the reference
/// rig in `mode`.
fn render_pair(
    scene: &Scene,
    size: (u32, u32),
    setup: &crate::exercise::StereoSetup,
    cam: &Camera,
    mode: CameraMode,
) -> ([EyeMatrices; 2], [Framebuffer; 2]) {
    let mut scene = scene.clone();
    (scene.width, scene.height) = size;
    scene.camera = cam.clone();
    let e = eyes(setup, cam, setup.eye_separation, mode, Lighting::PerEye);
    let view = |m: &EyeMatrices| {
        render_view(&scene, m, Shading::DepthOnly)
            .expect("the grader's own scenes render")
            .0
    };
    let views = [view(&e[0]), view(&e[1])];
    (e, views)
}

/// The public cases: the fixture's pair; the eyes twice as far apart with the screen moved
/// nearer (more occlusion, both signs of parallax); toe-in eyes (converged: `clip.w ≠ 1`, and
/// vertical parallax, so a forgotten row flip or half-pixel shows in y too).
fn public_cases(fx: &Fixture) -> Vec<RdsCase> {
    let size = fx.size();
    let cam = fx.scene.camera.clone();
    let wide = crate::exercise::StereoSetup {
        eye_separation: 2.0 * fx.setup.eye_separation,
        zero_parallax: 3.5,
        ..fx.setup
    };
    let (wide_eyes, wide_views) = render_pair(&fx.scene, size, &wide, &cam, CameraMode::OffAxis);
    let (toe_eyes, toe_views) = render_pair(&fx.scene, size, &fx.setup, &cam, CameraMode::ToeIn);
    let grid = |what: &str| {
        format!(
            "{what}, {}×{} (element k is pixel (k mod {}, ⌊k / {}⌋))",
            size.0, size.1, size.0, size.0
        )
    };
    vec![
        RdsCase::new(
            grid("the grading scene's pair"),
            &fx.eyes,
            [&fx.views[0], &fx.views[1]],
            1,
            DEPTH_TOLERANCE,
        ),
        RdsCase::new(
            grid("eyes twice as far apart, screen at 3.5"),
            &wide_eyes,
            [&wide_views[0], &wide_views[1]],
            2,
            DEPTH_TOLERANCE,
        ),
        RdsCase::new(
            grid("toe-in eyes (clip.w ≠ 1, vertical parallax)"),
            &toe_eyes,
            [&toe_views[0], &toe_views[1]],
            3,
            DEPTH_TOLERANCE,
        ),
    ]
}

/// One hidden case: a random setup and camera on the grading scene, at `HIDDEN_ROWS` rows.
fn hidden_case(fx: &Fixture, rng: &mut SplitMix64) -> RdsCase {
    let (mut s, cam) = random_setup(rng);
    let width = ((HIDDEN_ROWS as f32 * s.aspect).round() as u32).max(8);
    s.aspect = width as f32 / HIDDEN_ROWS as f32;
    let cam = Camera {
        fov_y: s.fov_y_degrees,
        near: s.near,
        far: s.far,
        ..cam
    };
    let (e, views) = render_pair(
        &fx.scene,
        (width, HIDDEN_ROWS),
        &s,
        &cam,
        CameraMode::OffAxis,
    );
    let seed = rng.next_u64();
    RdsCase::new(
        format!("hidden: {width}×{HIDDEN_ROWS}, {s:?}"),
        &e,
        [&views[0], &views[1]],
        seed,
        DEPTH_TOLERANCE,
    )
}

/// A dots answer (1 white) as a picture; `EITHER` and anything else not 0 shows as white.
fn dots_picture(like: &Framebuffer, dots: &[f64]) -> Framebuffer {
    let mut fb = like.clone();
    for (c, d) in fb.color_mut().iter_mut().zip(dots) {
        let v = if *d > 0.0 { 255 } else { 0 };
        *c = [v, v, v, 255];
    }
    fb
}

/// The red-cyan anaglyph of the pair: left dots in red, right dots in green and blue.
fn anaglyph_picture(like: &Framebuffer, left: &[bool], right: &[f64]) -> Framebuffer {
    let mut fb = like.clone();
    for ((c, l), r) in fb.color_mut().iter_mut().zip(left).zip(right) {
        let (l, r) = (if *l { 255 } else { 0 }, if *r > 0.0 { 255 } else { 0 });
        *c = [l, r, r, 255];
    }
    fb
}

pub(super) fn rds_task(fx: &Fixture) -> TaskSpec {
    let cases = public_cases(fx);
    let each = |v: Variant| cases.iter().map(|c| reference(c, v)).collect();
    let mistakes = vec![
        Mistake {
            id: "rds-no-visibility",
            hint: "the right pixel takes the left dot only where the left eye SEES the same \
                   point: check `visible` with the left depth at that texel; the strips beside \
                   near objects that only the right eye sees get the fresh dots",
            answers: each(Variant {
                no_visibility: true,
                ..Variant::default()
            }),
        },
        Mistake {
            id: "rds-wrong-direction",
            hint: "a right pixel goes from the RIGHT eye into the left one: \
                   `remap_right_to_left`, not `remap` (which maps left pixels into the right \
                   image)",
            answers: each(Variant {
                wrong_direction: true,
                ..Variant::default()
            }),
        },
        Mistake {
            id: "rds-v-not-flipped",
            hint: "texture v = 0 is the BOTTOM row, texel rows count from the top: the left \
                   texel's row is ⌊(1 − v)·height⌋",
            answers: each(Variant {
                v_not_flipped: true,
                ..Variant::default()
            }),
        },
        Mistake {
            id: "rds-pixel-corner",
            hint: "a pixel's texture coordinate is its CENTER: u = (x + ½)/width, \
                   v = 1 − (y + ½)/height",
            answers: each(Variant {
                pixel_corner: true,
                ..Variant::default()
            }),
        },
        Mistake {
            id: "rds-left-fallback",
            hint: "where the left eye does not see the point, the right pixel gets a FRESH dot \
                   (`fresh_dots`), not the left dot at the same pixel: Julesz's uncorrelated \
                   region",
            answers: each(Variant {
                left_fallback: true,
                ..Variant::default()
            }),
        },
    ];
    let first = cases[0].clone();
    let like = fx.canvas([0, 0, 0, 255]);
    let reference_dots = reference(&first, Variant::default());
    let build = move |answers: &[Option<Vec<f64>>]| {
        let got = answers
            .first()
            .cloned()
            .flatten()
            .filter(|a| a.len() == first.left_dots.len())
            .unwrap_or_else(|| vec![0.0; first.left_dots.len()]);
        // Where either dot is right, the expected picture shows the one given.
        let expected: Vec<f64> = reference_dots
            .iter()
            .zip(&got)
            .map(|(e, g)| if *e == EITHER { *g } else { *e })
            .collect();
        vec![
            Picture {
                name: "rds_right_dots".into(),
                expected: dots_picture(&like, &expected),
                actual: dots_picture(&like, &got),
            },
            Picture {
                name: "rds_anaglyph".into(),
                expected: anaglyph_picture(&like, &first.left_dots, &expected),
                actual: anaglyph_picture(&like, &first.left_dots, &got),
            },
        ]
    };
    let image_inputs = vec![cases[0].input()];
    TaskSpec {
        name: "rds_right",
        points: 2.0,
        bonus: false,
        depends_on: &["remap_right_to_left", "visible"],
        hidden: hidden_cases("rds_right", HIDDEN_SETUPS, |rng, _| {
            let c = hidden_case(fx, rng);
            Case {
                label: c.label.clone(),
                input: c.input(),
                expected: reference(&c, Variant::default()),
            }
        }),
        tolerance: Tolerance {
            abs: EITHER,
            rel: 0.0,
            why: "dots are 0 (black) or 1 (white) and must match; a pixel whose f64 reference \
                  lies within 5e-3 px of a texel edge or 1e-4 of the depth tolerance, where f32 \
                  rounding may decide either way, is expected as 0.5 and accepts both",
        },
        cases: cases
            .iter()
            .map(|c| Case {
                label: c.label.clone(),
                input: c.input(),
                expected: reference(c, Variant::default()),
            })
            .collect(),
        mistakes,
        image: Some(crate::pictures::check(image_inputs, Box::new(build))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixture::grading_scene;

    fn either_share(v: &[f64]) -> f64 {
        v.iter().filter(|d| **d == EITHER).count() as f64 / v.len() as f64
    }

    #[test]
    fn every_mistake_changes_every_public_case_and_few_pixels_are_ambiguous() {
        let fx = Fixture::new(grading_scene().unwrap()).unwrap();
        let cases = public_cases(&fx);
        let t = Tolerance {
            abs: EITHER,
            rel: 0.0,
            why: "",
        };
        for c in &cases {
            let right = reference(c, Variant::default());
            // Measured: 1.9%, 1.4% and 1.1% of the pixels (mostly within 5e-3 px of a texel
            // edge); every other pixel is exact.
            assert!(
                either_share(&right) < 0.03,
                "{}: {}",
                c.label,
                either_share(&right)
            );
            // Both sources of dots occur: the pair shares dots and has uncorrelated strips.
            let from_left = right
                .iter()
                .zip(&c.fresh_dots)
                .filter(|(r, f)| **r != EITHER && (**r == 1.0) != **f)
                .count();
            assert!(from_left > 100, "{}: {from_left}", c.label);
            for (name, v) in [
                (
                    "no-visibility",
                    Variant {
                        no_visibility: true,
                        ..Variant::default()
                    },
                ),
                (
                    "wrong-direction",
                    Variant {
                        wrong_direction: true,
                        ..Variant::default()
                    },
                ),
                (
                    "v-not-flipped",
                    Variant {
                        v_not_flipped: true,
                        ..Variant::default()
                    },
                ),
                (
                    "pixel-corner",
                    Variant {
                        pixel_corner: true,
                        ..Variant::default()
                    },
                ),
                (
                    "left-fallback",
                    Variant {
                        left_fallback: true,
                        ..Variant::default()
                    },
                ),
            ] {
                let wrong = reference(c, v);
                let plain: Vec<f64> = wrong.iter().map(|d| d.round()).collect();
                assert!(!t.accepts(&right, &plain), "{name} passes {}", c.label);
            }
        }
    }

    #[test]
    fn the_library_pair_agrees_with_the_reference_where_the_tolerances_agree() {
        // The library's `rds_right` uses a per-pixel tolerance from the depth slope; with the
        // fixture's pair the two differ only on a few pixels at depth edges.
        let fx = Fixture::new(grading_scene().unwrap()).unwrap();
        let c = &public_cases(&fx)[0];
        let right = reference(c, Variant::default());
        let lib = stereolab_core::rds_right(
            &fx.views[0],
            &fx.views[1],
            &fx.eyes[0].mvp,
            &fx.eyes[1].mvp,
            &stereolab_core::RdsSettings {
                seed: 1,
                dot_size: 1,
            },
        )
        .unwrap();
        // The same dots (the case's fresh dots are the library's second stream) except where
        // the slope-dependent and the fixed tolerance decide differently.
        let same_source = lib
            .pixels()
            .zip(&right)
            .filter(|(p, r)| **r != EITHER && (p.0[0] == 255) == (**r == 1.0))
            .count();
        // Measured: 97.3%; the rest are pixels at occlusion edges where the library's
        // slope-dependent tolerance and the task's fixed 2e-3 decide differently.
        let share = same_source as f64 / right.len() as f64;
        assert!(share > 0.95, "{share}");
    }

    /// The exercise slides' chain in f32, as a student writes it: `[u, v, depth]` in the left eye.
    fn f32_chain(from: Mat4, to: Mat4, uv: [f32; 2], depth: f32) -> Option<[f32; 3]> {
        let ndc = glam::Vec4::new(2.0 * uv[0] - 1.0, 2.0 * uv[1] - 1.0, 2.0 * depth - 1.0, 1.0);
        let clip = to * from.inverse() * ndc;
        (clip.w > 0.0).then(|| {
            let n = clip.truncate() / clip.w;
            [0.5 * (n.x + 1.0), 0.5 * (n.y + 1.0), 0.5 * (n.z + 1.0)]
        })
    }

    #[test]
    fn the_f32_chain_stays_well_inside_the_ambiguity_margins() {
        // The margins must cover what f32 rounding can do, or a right answer could fail.
        let fx = Fixture::new(grading_scene().unwrap()).unwrap();
        let mut cases = public_cases(&fx);
        for seed in 0..20u64 {
            let mut rng = SplitMix64::for_task(seed, "rds_right");
            cases.push(hidden_case(&fx, &mut rng));
        }
        let (mut px, mut dz) = (0.0f64, 0.0f64);
        for c in &cases {
            let (w, h) = (c.width, c.height);
            for y in 0..h {
                for x in 0..w {
                    let i = (y * w + x) as usize;
                    let uv = pixel_uv(w, h, x, y);
                    let d = c.right_depth[i];
                    let e =
                        remap_reference(&c.right_mvp, &c.left_mvp, uv, d, RemapVariant::default());
                    let Some(a) = f32_chain(c.right_mvp, c.left_mvp, uv, d) else {
                        assert!(e.is_empty());
                        continue;
                    };
                    px = px
                        .max((f64::from(a[0]) - e[0]).abs() * f64::from(w))
                        .max((f64::from(a[1]) - e[1]).abs() * f64::from(h));
                    dz = dz.max((f64::from(a[2]) - e[2]).abs());
                }
            }
        }
        assert!(
            px < TEXEL_EDGE_PX / 2.0,
            "window coordinates off by {px:e} px"
        );
        assert!(dz < DEPTH_EDGE / 2.0, "depth off by {dz:e}");
    }

    #[test]
    fn hidden_cases_render_and_are_mostly_unambiguous() {
        for seed in 0..6u64 {
            let fx = Fixture::new(grading_scene().unwrap()).unwrap();
            let mut rng = SplitMix64::for_task(seed, "rds_right");
            let c = hidden_case(&fx, &mut rng);
            let right = reference(&c, Variant::default());
            assert_eq!(right.len(), (c.width * c.height) as usize);
            assert!(
                either_share(&right) < 0.03,
                "seed {seed}: {}",
                either_share(&right)
            );
        }
    }
}
