//! Exercise 1's stereo rig task: each eye's view and projection (`stereo_matrices`), with
//! per-eye and cyclopic lighting, and its rendered pictures.

use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};

use super::{HIDDEN_SETUPS, MATRIX_TOLERANCE, blank, camera, eyes, flat, random_setup, setups};
use crate::exercise::{Eye, StereoSetup};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, TaskSpec, hidden_cases};
use stereolab::plan::Shading;
use stereolab::render::render_view;
use stereolab_core::{Camera, CameraMode, EyeMatrices, Framebuffer, Lighting};

/// The `stereo_matrices` task's input for one eye: setup, cyclopean modelview, eye (0 = left
/// in JSON), lighting.
pub(crate) fn eye_view_input(s: &StereoSetup, mv: &Mat4, eye: Eye, lighting: Lighting) -> Value {
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
        viewport_shift: 0,
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

/// The setups of the frustum tasks plus cameras whose eye x axis is not world x: the fixture's
/// camera orbited 50° about Y around its target, and a camera looking down from above and to
/// the side (rotated about Y and X). A camera that only tilts about X keeps eye x = world x,
/// where `MV · T±` equals `T± · MV` and the order cannot be checked.
fn rig_setups(fx: &Fixture) -> Vec<(StereoSetup, Camera)> {
    let mut v = setups(fx);
    let (s, cam) = v[0].clone();
    let target = Vec3::from(cam.target);
    let orbit = target + Quat::from_rotation_y(50f32.to_radians()) * (Vec3::from(cam.eye) - target);
    v.push((
        s,
        Camera {
            eye: orbit.to_array(),
            ..cam
        },
    ));
    let (s, _) = v[1].clone();
    v.push((s, camera(&s, [6.0, 4.0, 5.0], [0.0, -1.0, 0.0])));
    v
}

/// The reference's answer for a random setup and camera (hidden cases).
fn hidden_case(s: &StereoSetup, cam: &Camera, eye: Eye, lighting: Lighting) -> Case {
    let ok = eyes(s, cam, s.eye_separation, CameraMode::OffAxis, lighting);
    Case {
        label: format!(
            "hidden: eye {}, {lighting:?} lighting, camera at {:?} looking at {:?}, {s:?}",
            eye.index(),
            cam.eye,
            cam.target
        ),
        input: eye_view_input(s, &cam.view(), eye, lighting),
        expected: eye_answer(&ok[eye.index()]),
    }
}

pub(super) fn stereo_matrices_task(fx: &Fixture) -> TaskSpec {
    let mut cases = Vec::new();
    let mut wrong: [Vec<Vec<f64>>; 6] = Default::default();
    for (s, cam) in rig_setups(fx) {
        let d = s.eye_separation;
        let mv = cam.view();
        for lighting in [Lighting::PerEye, Lighting::Cyclopic] {
            let ok = eyes(&s, &cam, d, CameraMode::OffAxis, lighting);
            let toe = eyes(&s, &cam, d, CameraMode::ToeIn, lighting);
            let double = eyes(&s, &cam, 2.0 * d, CameraMode::OffAxis, lighting);
            let swapped_light = eyes(&s, &cam, d, CameraMode::OffAxis, other(lighting));
            for eye in Eye::BOTH {
                let i = eye.index();
                cases.push(Case {
                    label: format!("eye {i}, {lighting:?} lighting, {s:?}"),
                    input: eye_view_input(&s, &mv, eye, lighting),
                    expected: eye_answer(&ok[i]),
                });
                wrong[0].push(eye_answer(&ok[eye.other().index()]));
                wrong[1].push(eye_answer(&toe[i]));
                wrong[2].push(eye_answer(&double[i]));
                wrong[3].push(eye_answer(&swapped_light[i]));
                // T± with the wrong sign, P± right.
                let side = eye.sign();
                let t = Mat4::from_translation(Vec3::new(side * 0.5 * d, 0.0, 0.0));
                let p = ok[i].projection;
                let flipped = match lighting {
                    Lighting::PerEye => (t * mv, p),
                    Lighting::Cyclopic => {
                        let p_only = eyes(&s, &cam, d, CameraMode::OffAxis, Lighting::PerEye);
                        (mv, p_only[i].projection * t)
                    }
                };
                let mut v = flat(&flipped.0);
                v.extend(flat(&flipped.1));
                wrong[4].push(v);
                // MV · T± instead of T± · MV (per-eye; cyclopic has no MV in the projection).
                let t_ok = Mat4::from_translation(Vec3::new(-side * 0.5 * d, 0.0, 0.0));
                wrong[5].push(match lighting {
                    Lighting::PerEye => {
                        let mut v = flat(&(mv * t_ok));
                        v.extend(flat(&ok[i].projection));
                        v
                    }
                    Lighting::Cyclopic => eye_answer(&ok[i]),
                });
            }
        }
    }
    let [swapped, toe, double, light, sign, mv_t] = wrong;
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
            let fb = render_view(&scene, &m[eye.index()], Shading::Color)
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
        depends_on: &["frustum", "stereo_frustum"],
        hidden: hidden_cases("stereo_matrices", 2 * HIDDEN_SETUPS, |rng, i| {
            let (s, cam) = random_setup(rng);
            let lighting = if i % 4 < 2 {
                Lighting::PerEye
            } else {
                Lighting::Cyclopic
            };
            hidden_case(&s, &cam, Eye::BOTH[i % 2], lighting)
        }),
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
                       vertical parallax (the StereoGraphics guide (Akka)); translate the eyes and shear the frusta",
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
            Mistake {
                id: "mv-t-order",
                hint: "MV · T± is the wrong order: T± moves the eye along the EYE's x axis, so \
                       it acts after the modelview: view = T± · MV. (MV · T± moves along the \
                       world's x axis, which only agrees when the camera is not turned about Y.)",
                answers: mv_t,
            },
        ],
        image: Some(crate::pictures::check(inputs, Box::new(build))),
    }
}

fn fixture_eye_inputs(_fx: &Fixture) -> Vec<(Eye, Lighting)> {
    vec![
        (Eye::Left, Lighting::PerEye),
        (Eye::Right, Lighting::PerEye),
        (Eye::Left, Lighting::Cyclopic),
        (Eye::Right, Lighting::Cyclopic),
    ]
}

fn picture_name(eye: Eye, l: Lighting) -> String {
    let side = match eye {
        Eye::Left => "left",
        Eye::Right => "right",
    };
    let light = match l {
        Lighting::PerEye => "per_eye",
        Lighting::Cyclopic => "cyclopic",
    };
    format!("{side}_{light}")
}
