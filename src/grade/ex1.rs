//! Exercise 1 (seed 004): the tasks, their reference answers, known mistakes and image checks.

use glam::{DMat4, DVec4, Mat4, Vec3};
use serde_json::{Value, json};

use super::fixture::{Fixture, reference_rig};
use super::spec::{Case, ImageCheck, Mistake, Picture, TaskSpec, Tolerance};
use crate::effects::anaglyph::AnaglyphKind::DuboisRedCyan;
use crate::effects::anaglyph::anaglyph_pixel;
use crate::effects::remap::{Precision, Remapped, Remapper};
use crate::exercise::{AnaglyphKind, AnaglyphMatrices, Answer, ColorMatrix, StereoSetup};
use crate::framebuffer::Framebuffer;
use crate::math::{Camera, CameraMode, EyeMatrices, Lighting, frustum};
use crate::plan::Shading;
use crate::render::render_view;
use crate::shade::to_rgba8;

pub(crate) fn flat<A: Answer>(a: &A) -> Vec<f64> {
    let mut v = Vec::new();
    a.flatten(&mut v);
    v
}

/// Every task of exercise 1.
pub fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![
        frustum_task(fx),
        stereo_frustum_task(fx),
        stereo_matrices_task(fx),
        anaglyph_task(fx),
        dubois_task(),
        remap_task(fx),
        visible_task(fx),
        parallax_task(),
        parallax_color_task(fx),
    ]
}

const MATRIX_TOLERANCE: Tolerance = Tolerance {
    abs: 1e-5,
    rel: 1e-4,
    why: "f32 arithmetic in another order differs by ~1e-6 relative; elements that should be 0 \
          come out near 1e-7 after a product with an inverse",
};

fn frustum_task(fx: &Fixture) -> TaskSpec {
    let e = fx.eyes[0].frustum;
    let args: Vec<[f32; 6]> = vec![
        [-1.0, 1.0, -0.75, 0.75, 1.0, 20.0],
        [-0.9, 1.1, -0.6, 0.7, 0.5, 50.0],
        [-2.0, 0.5, -1.0, 1.5, 2.0, 10.0],
        [-0.01, 0.012, -0.008, 0.009, 0.01, 1000.0],
        e,
    ];
    let cases = args
        .iter()
        .map(|a| Case {
            label: format!("P_frustum{a:?}"),
            input: json!(a),
            expected: flat(&frustum(a[0], a[1], a[2], a[3], a[4], a[5])),
        })
        .collect();
    let each = |f: &dyn Fn(&[f32; 6]) -> Mat4| args.iter().map(|a| flat(&f(a))).collect();
    TaskSpec {
        name: "frustum",
        points: 2.0,
        bonus: false,
        tolerance: Tolerance {
            rel: 1e-5,
            abs: 1e-6,
            why: "the same formula in f32: a few units in the last place (1.2e-7 relative)",
        },
        cases,
        mistakes: vec![
            Mistake {
                id: "transposed",
                hint: "the matrix is transposed: Mat4::from_cols takes COLUMNS, so the slide's \
                       rows must not be typed in as they are written",
                answers: each(&|a| frustum(a[0], a[1], a[2], a[3], a[4], a[5]).transpose()),
            },
            Mistake {
                id: "wrong-ndc-range",
                hint: "wrong NDC range: this maps depth to [0, 1] (Direct3D/Vulkan); seed 004's \
                       OpenGL matrix maps near to −1 and far to +1: (n+f)/(n−f) and 2nf/(n−f)",
                answers: each(&|a| {
                    let mut m = frustum(a[0], a[1], a[2], a[3], a[4], a[5]);
                    let (n, f) = (a[4], a[5]);
                    m.z_axis.z = f / (n - f);
                    m.w_axis.z = n * f / (n - f);
                    m
                }),
            },
            Mistake {
                id: "left-handed",
                hint: "the w row should be (0, 0, −1, 0): eye space is right-handed and looks \
                       down −Z",
                answers: each(&|a| {
                    let mut m = frustum(a[0], a[1], a[2], a[3], a[4], a[5]);
                    m.z_axis.w = 1.0;
                    m
                }),
            },
        ],
        image: None,
    }
}

/// A camera with `setup`'s frustum looking from `eye` at `target`.
fn camera(setup: &StereoSetup, eye: [f32; 3], target: [f32; 3]) -> Camera {
    Camera {
        eye,
        target,
        up: [0.0, 1.0, 0.0],
        fov_y: setup.fov_y_degrees,
        near: setup.near,
        far: setup.far,
    }
}

/// The setups the numeric stereo checks use: the fixture's, seed 003's worked example, and a
/// wide, close one.
fn setups(fx: &Fixture) -> Vec<(StereoSetup, Camera)> {
    let seed003 = StereoSetup {
        fov_y_degrees: 90.0,
        aspect: 1.0,
        near: 1.0,
        far: 100.0,
        eye_separation: 1.0,
        zero_parallax: 9.0,
    };
    let wide = StereoSetup {
        fov_y_degrees: 70.0,
        aspect: 16.0 / 9.0,
        near: 0.3,
        far: 40.0,
        eye_separation: 0.065,
        zero_parallax: 2.0,
    };
    vec![
        (fx.setup, fx.scene.camera.clone()),
        (seed003, camera(&seed003, [0.0, 0.0, 9.0], [0.0, 0.0, 0.0])),
        (wide, camera(&wide, [3.0, 2.0, -1.0], [0.0, 0.5, 0.0])),
    ]
}

/// The reference eyes for a setup with a changed separation, mode and lighting.
fn eyes(
    setup: &StereoSetup,
    cam: &Camera,
    separation: f32,
    mode: CameraMode,
    lighting: Lighting,
) -> [EyeMatrices; 2] {
    let s = StereoSetup {
        eye_separation: separation,
        ..*setup
    };
    let mut rig = reference_rig(&s, lighting);
    rig.mode = mode;
    rig.eyes(cam, setup.aspect)
        .expect("the grader's own setups are valid")
}

fn stereo_frustum_task(fx: &Fixture) -> TaskSpec {
    let mut cases = Vec::new();
    let mut wrong: [Vec<Vec<f64>>; 4] = Default::default();
    for (s, cam) in setups(fx) {
        let d = s.eye_separation;
        let ok = eyes(&s, &cam, d, CameraMode::OffAxis, Lighting::PerEye);
        let toe = eyes(&s, &cam, d, CameraMode::Parallel, Lighting::PerEye);
        let double = eyes(&s, &cam, 2.0 * d, CameraMode::OffAxis, Lighting::PerEye);
        for eye in 0..2 {
            cases.push(Case {
                label: format!("eye {eye} of {s:?}"),
                input: json!([s, eye]),
                expected: flat(&ok[eye].frustum),
            });
            wrong[0].push(flat(&ok[1 - eye].frustum));
            wrong[1].push(flat(&toe[eye].frustum));
            wrong[2].push(flat(&double[eye].frustum));
            let mut no_scale = toe[eye].frustum;
            let shift = if eye == 0 { 0.5 * d } else { -0.5 * d };
            no_scale[0] += shift;
            no_scale[1] += shift;
            wrong[3].push(flat(&no_scale));
        }
    }
    let [swapped, toe, double, no_scale] = wrong;
    TaskSpec {
        name: "stereo_frustum",
        points: 2.0,
        bonus: false,
        tolerance: MATRIX_TOLERANCE,
        cases,
        mistakes: vec![
            Mistake {
                id: "swapped-eyes",
                hint: "swapped eyes (or the sign of the shear): eye 0 is the LEFT eye at \
                       x = −d/2, and its l and r move by +(d/2)·n/z0",
                answers: swapped,
            },
            Mistake {
                id: "toe-in",
                hint: "no shear: l and r are the mono frustum's. The off-axis rig shears each \
                       eye's frustum; rotating the eyes (toe-in) or parallel symmetric frusta \
                       are not seed 004's stereo frusta",
                answers: toe,
            },
            Mistake {
                id: "d-instead-of-half-d",
                hint: "d instead of d/2: each eye sits d/2 from the center, so the shift on the \
                       near plane is (d/2)·n/z0",
                answers: double,
            },
            Mistake {
                id: "missing-near-scale",
                hint: "the shift is measured on the near plane: (d/2)·n/z0 (intercept theorem), \
                       not d/2",
                answers: no_scale,
            },
        ],
        image: None,
    }
}

/// The `stereo_matrices` task's input for one eye: setup, cyclopean modelview, eye index
/// (0 = left), lighting.
pub(crate) fn eye_view_input(s: &StereoSetup, mv: &Mat4, eye: usize, lighting: Lighting) -> Value {
    json!([s, mv.to_cols_array(), eye, lighting])
}

/// The student's `stereo_matrices` answer (view then projection, 16 column-major numbers each)
/// as [`EyeMatrices`] for `render_view`; `None` when it has the wrong length.
pub(crate) fn eye_matrices_from_answer(a: &[f64]) -> Option<EyeMatrices> {
    if a.len() != 32 {
        return None;
    }
    let view = Mat4::from_cols_array(&std::array::from_fn(|i| a[i] as f32));
    let projection = Mat4::from_cols_array(&std::array::from_fn(|i| a[16 + i] as f32));
    Some(EyeMatrices {
        view,
        projection,
        mvp: projection * view,
        eye_world: Vec3::ZERO,
        frustum: [0.0; 6],
    })
}

fn eye_answer(m: &EyeMatrices) -> Vec<f64> {
    let mut v = flat(&m.view);
    v.extend(flat(&m.projection));
    v
}

fn other(l: Lighting) -> Lighting {
    match l {
        Lighting::PerEye => Lighting::Cyclopic,
        Lighting::Cyclopic => Lighting::PerEye,
    }
}

fn stereo_matrices_task(fx: &Fixture) -> TaskSpec {
    let mut cases = Vec::new();
    let mut wrong: [Vec<Vec<f64>>; 5] = Default::default();
    for (s, cam) in setups(fx) {
        let d = s.eye_separation;
        let mv = cam.view();
        for lighting in [Lighting::PerEye, Lighting::Cyclopic] {
            let ok = eyes(&s, &cam, d, CameraMode::OffAxis, lighting);
            let toe = eyes(&s, &cam, d, CameraMode::ToeIn, lighting);
            let double = eyes(&s, &cam, 2.0 * d, CameraMode::OffAxis, lighting);
            let swapped_light = eyes(&s, &cam, d, CameraMode::OffAxis, other(lighting));
            for eye in 0..2 {
                cases.push(Case {
                    label: format!("eye {eye}, {lighting:?} lighting, {s:?}"),
                    input: eye_view_input(&s, &mv, eye, lighting),
                    expected: eye_answer(&ok[eye]),
                });
                wrong[0].push(eye_answer(&ok[1 - eye]));
                wrong[1].push(eye_answer(&toe[eye]));
                wrong[2].push(eye_answer(&double[eye]));
                wrong[3].push(eye_answer(&swapped_light[eye]));
                // T± with the wrong sign, P± right.
                let side = if eye == 0 { -1.0 } else { 1.0 };
                let t = Mat4::from_translation(Vec3::new(side * 0.5 * d, 0.0, 0.0));
                let p = ok[eye].projection;
                let flipped = match lighting {
                    Lighting::PerEye => (t * mv, p),
                    Lighting::Cyclopic => {
                        let p_only = eyes(&s, &cam, d, CameraMode::OffAxis, Lighting::PerEye);
                        (mv, p_only[eye].projection * t)
                    }
                };
                let mut v = flat(&flipped.0);
                v.extend(flat(&flipped.1));
                wrong[4].push(v);
            }
        }
    }
    let [swapped, toe, double, light, sign] = wrong;
    let inputs: Vec<Value> = fixture_eye_inputs(fx)
        .into_iter()
        .map(|(eye, l)| eye_view_input(&fx.setup, &fx.modelview, eye, l))
        .collect();
    let scene = fx.scene.clone();
    let setup = fx.setup;
    let reference: Vec<(String, Framebuffer)> = fixture_eye_inputs(fx)
        .into_iter()
        .map(|(eye, l)| {
            let m = eyes(
                &setup,
                &scene.camera,
                setup.eye_separation,
                CameraMode::OffAxis,
                l,
            );
            let fb = render_view(&scene, &m[eye], Shading::Color)
                .expect("the fixture renders")
                .0;
            (picture_name(eye, l), fb)
        })
        .collect();
    let build = move |answers: &[Option<Vec<f64>>]| {
        reference
            .iter()
            .zip(answers)
            .map(|((name, expected), a)| {
                let actual = a
                    .as_deref()
                    .and_then(eye_matrices_from_answer)
                    .and_then(|m| render_view(&scene, &m, Shading::Color).ok().map(|r| r.0))
                    .unwrap_or_else(|| blank(expected, scene.background));
                Picture {
                    name: format!("stereo_matrices_{name}"),
                    expected: expected.clone(),
                    actual,
                }
            })
            .collect()
    };
    TaskSpec {
        name: "stereo_matrices",
        points: 2.0,
        bonus: false,
        tolerance: MATRIX_TOLERANCE,
        cases,
        mistakes: vec![
            Mistake {
                id: "swapped-eyes",
                hint: "swapped eyes: index 0 is the LEFT eye, at x = −d/2, so T_left = \
                       translate(+d/2, 0, 0)",
                answers: swapped,
            },
            Mistake {
                id: "toe-in",
                hint: "toe-in instead of shear: rotating each eye towards the fusion point gives \
                       vertical parallax (seed 003); translate the eyes and shear the frusta",
                answers: toe,
            },
            Mistake {
                id: "d-instead-of-half-d",
                hint: "d instead of d/2: each eye is d/2 from the center, in T± and in the shear",
                answers: double,
            },
            Mistake {
                id: "lighting-swapped",
                hint: "per-eye and cyclopic swapped: per-eye puts T± into the view \
                       (view = T±·MV), cyclopic into the projection (P±·T±)",
                answers: light,
            },
            Mistake {
                id: "translation-sign",
                hint: "T± moves the eye the wrong way: T moves the WORLD, so the left eye at \
                       x = −d/2 needs translate(+d/2, 0, 0)",
                answers: sign,
            },
        ],
        image: Some(ImageCheck {
            inputs,
            build: Box::new(build),
        }),
    }
}

fn fixture_eye_inputs(_fx: &Fixture) -> Vec<(usize, Lighting)> {
    vec![
        (0, Lighting::PerEye),
        (1, Lighting::PerEye),
        (0, Lighting::Cyclopic),
        (1, Lighting::Cyclopic),
    ]
}

fn picture_name(eye: usize, l: Lighting) -> String {
    let side = if eye == 0 { "left" } else { "right" };
    let light = match l {
        Lighting::PerEye => "per_eye",
        Lighting::Cyclopic => "cyclopic",
    };
    format!("{side}_{light}")
}

/// An empty framebuffer of `like`'s size: the picture of a missing answer.
pub(crate) fn blank(like: &Framebuffer, background: [u8; 4]) -> Framebuffer {
    Framebuffer::new(like.width, like.height, background).expect("same size as a valid one")
}

/// Seed 004's anaglyph matrices from stereolab's anaglyph module.
pub fn reference_anaglyph(kind: AnaglyphKind) -> AnaglyphMatrices {
    kind.reference().matrices()
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

/// The finalize shader's anaglyph pixel (stored 8-bit values, no sRGB decoding: seed 004).
fn mix(m: &AnaglyphMatrices, l: [u8; 4], r: [u8; 4]) -> [u8; 4] {
    anaglyph_pixel(m, l, r, false)
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
    for (i, px) in fb.color.iter_mut().enumerate() {
        *px = mix(m, fx.views[0].color[i], fx.views[1].color[i]);
    }
    fb
}

fn anaglyph_task(fx: &Fixture) -> TaskSpec {
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
                    for (i, px) in actual.color.iter_mut().enumerate() {
                        *px = mix(&m, views[0].color[i], views[1].color[i]);
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
        image: Some(ImageCheck {
            inputs: kinds.iter().map(|k| json!(k)).collect(),
            build: Box::new(build),
        }),
    }
}

fn dubois_task() -> TaskSpec {
    let dubois = DuboisRedCyan.matrices();
    let mut typo = dubois;
    typo.left[1][0] = -0.400822;
    TaskSpec {
        name: "dubois_matrices",
        points: 1.0,
        bonus: true,
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

/// The known remapping mistakes as switches.
#[derive(Clone, Copy, Default)]
struct RemapVariant {
    depth_as_ndc: bool,
    order_swapped: bool,
    no_divide: bool,
    ndc_out: bool,
}

/// The known mistakes' answers (and, with no switch set, the same numbers as
/// [`stereolab_remap`]): seed 004's chain in f64 from a texture coordinate.
fn remap_reference(l: &Mat4, r: &Mat4, uv: [f32; 2], depth: f32, v: RemapVariant) -> Vec<f64> {
    let (l, r) = (l.as_dmat4(), r.as_dmat4());
    let m: DMat4 = if v.order_swapped {
        l * r.inverse()
    } else {
        r * l.inverse()
    };
    let z = if v.depth_as_ndc {
        depth as f64
    } else {
        2.0 * depth as f64 - 1.0
    };
    let clip = m * DVec4::new(2.0 * uv[0] as f64 - 1.0, 2.0 * uv[1] as f64 - 1.0, z, 1.0);
    if clip.w <= 0.0 {
        return Vec::new();
    }
    let ndc = if v.no_divide {
        clip.truncate()
    } else {
        clip.truncate() / clip.w
    };
    if v.ndc_out {
        return ndc.to_array().to_vec();
    }
    let depth = if v.depth_as_ndc {
        ndc.z
    } else {
        0.5 * (ndc.z + 1.0)
    };
    vec![0.5 * (ndc.x + 1.0), 0.5 * (ndc.y + 1.0), depth]
}

/// Covered pixels of the left view, with their texture coordinate and stored depth.
fn left_samples(fx: &Fixture) -> Vec<(u32, u32, [f32; 2], f32)> {
    let (w, h) = fx.size();
    let left = &fx.views[0];
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter_map(|(x, y)| {
            let d = left.depth[left.index(x, y)];
            (d < 1.0).then(|| (x, y, fx.uv(x, y), d))
        })
        .collect()
}

/// stereolab's remapping (`effects::remap`, f64) of left pixel (x, y) at depth `d`:
/// `[u, v, depth]` in the right eye, empty when behind it.
fn stereolab_remap(l: &Mat4, r: &Mat4, (w, h): (u32, u32), (x, y): (u32, u32), d: f32) -> Vec<f64> {
    Remapper::new(l, r, w, h, Precision::F64)
        .ok()
        .and_then(|m| m.remap(x, y, d))
        .map_or_else(Vec::new, |m| vec![m.tex[0], m.tex[1], m.depth])
}

/// A remap check: label, MVP_l, MVP_r, the left pixel, its stored depth.
type RemapCase = (String, Mat4, Mat4, (u32, u32), f32);

fn remap_task(fx: &Fixture) -> TaskSpec {
    let (l, r) = (fx.eyes[0].mvp, fx.eyes[1].mvp);
    let size = fx.size();
    let mut inputs: Vec<RemapCase> = left_samples(fx)
        .into_iter()
        .enumerate()
        .filter(|(i, _)| i % 41 == 0)
        .map(|(_, (x, y, _, d))| (format!("left pixel ({x}, {y})"), l, r, (x, y), d))
        .collect();
    // A right eye looking the other way: the point is behind it (w ≤ 0) → None.
    let behind = r * Mat4::from_rotation_y(std::f32::consts::PI);
    let center = (size.0 / 2, size.1 / 2);
    inputs.push(("behind the right eye".into(), l, behind, center, 0.9));
    let json_of = |l: &Mat4, r: &Mat4, uv: [f32; 2], d: f32| {
        json!([l.to_cols_array(), r.to_cols_array(), uv, d])
    };
    let cases = inputs
        .iter()
        .map(|(label, l, r, (x, y), d)| Case {
            label: label.clone(),
            input: json_of(l, r, fx.uv(*x, *y), *d),
            expected: stereolab_remap(l, r, size, (*x, *y), *d),
        })
        .collect();
    let each = |v: RemapVariant| {
        inputs
            .iter()
            .map(|(_, l, r, (x, y), d)| remap_reference(l, r, fx.uv(*x, *y), *d, v))
            .collect()
    };
    let samples = left_samples(fx);
    let image_inputs = samples
        .iter()
        .map(|(_, _, uv, d)| json_of(&l, &r, *uv, *d))
        .collect();
    let picture = {
        let samples = samples.clone();
        let right = fx.views[1].clone();
        let mut canvas = fx.canvas(fx.scene.background);
        canvas.depth = fx.views[0].depth.clone();
        let (w, h) = fx.size();
        move |answers: &[Option<Vec<f64>>]| {
            let mut fb = canvas.clone();
            for ((x, y, _, _), a) in samples.iter().zip(answers) {
                let texel = a
                    .as_ref()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| texel_of(a[0], a[1], w, h));
                let i = fb.index(*x, *y);
                fb.color[i] = match texel {
                    Some((tx, ty)) => right.color[right.index(tx, ty)],
                    None => [0, 0, 0, 255],
                };
            }
            fb
        }
    };
    let expected = picture(
        &samples
            .iter()
            .map(|(x, y, _, d)| Some(stereolab_remap(&l, &r, size, (*x, *y), *d)))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: "remap_right_colors_on_left".into(),
            expected: expected.clone(),
            actual: picture(answers),
        }]
    };
    TaskSpec {
        name: "remap",
        points: 2.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 2e-4,
            rel: 0.0,
            why: "seed 004's f32 chain (inverse in f32, two products) is off by 4.4e-7 at most \
                  on these inputs against this f64 reference (measured); 2e-4 is a hundredth of \
                  a pixel at 64 pixels and leaves room for any evaluation order",
        },
        cases,
        mistakes: vec![
            Mistake {
                id: "opengl-depth",
                hint: "depth range: the depth texture holds window depth in [0, 1], NDC z is in \
                       [−1, 1]: z_ndc = 2·depth − 1 going in, depth = (z_ndc + 1)/2 coming out",
                answers: each(RemapVariant {
                    depth_as_ndc: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "matrix-order",
                hint: "MVP_l · MVP_r⁻¹ is the wrong way round: undo the LEFT eye's transform \
                       first, then apply the right eye's: MVP_r · MVP_l⁻¹",
                answers: each(RemapVariant {
                    order_swapped: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "no-w-divide",
                hint: "missing w-clip: divide x, y, z by w before leaving clip space",
                answers: each(RemapVariant {
                    no_divide: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "ndc-not-texture",
                hint: "wrong range: these are NDC in [−1, 1]; texture coordinates are \
                       (ndc + 1)/2 in [0, 1]",
                answers: each(RemapVariant {
                    ndc_out: true,
                    ..Default::default()
                }),
            },
        ],
        image: Some(ImageCheck {
            inputs: image_inputs,
            build: Box::new(build),
        }),
    }
}

/// The texel nearest filtering fetches at texture coordinate (u, v) (v = 0 bottom) in a w × h
/// image, if inside (stereolab's `Remapped::texel`).
fn texel_of(u: f64, v: f64, w: u32, h: u32) -> Option<(u32, u32)> {
    Remapped {
        tex: [u, v],
        depth: 0.0,
    }
    .texel(w, h)
}

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
                        .map_or(1.0, |(tx, ty)| right.depth[right.index(tx, ty)]);
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

fn visible_task(fx: &Fixture) -> TaskSpec {
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
                    fb.color[i] = HIDDEN_COLOR;
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
        image: Some(ImageCheck {
            inputs: fixture_inputs.iter().map(|(_, _, i)| json!(i)).collect(),
            build: Box::new(build),
        }),
    }
}

fn parallax_task() -> TaskSpec {
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

fn parallax_color_task(fx: &Fixture) -> TaskSpec {
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
    let mut canvas = fx.canvas(fx.scene.background);
    canvas.depth = fx.views[0].depth.clone();
    let picture = {
        let samples = samples.clone();
        move |answers: &[Option<Vec<f64>>]| {
            let mut fb = canvas.clone();
            for ((x, y, _), a) in samples.iter().zip(answers) {
                let i = fb.index(*x, *y);
                fb.color[i] = match a.as_deref() {
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
                hint: "colors swapped: seed 004 shows NEGATIVE parallax (in front of the screen) \
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
        image: Some(ImageCheck {
            inputs: samples.iter().map(|(_, _, p)| json!([p, max])).collect(),
            build: Box::new(build),
        }),
    }
}
