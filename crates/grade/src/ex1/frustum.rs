//! Exercise 1's frustum tasks: the mono `frustum` matrix and each eye's off-axis `stereo_frustum`.

use glam::Mat4;
use serde_json::json;

use super::{HIDDEN_SETUPS, MATRIX_TOLERANCE, eyes, flat, random_setup, setups};
use crate::exercise::Eye;
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, TaskSpec, Tolerance, hidden_cases};
use stereolab_core::{CameraMode, Lighting, frustum};

pub(super) fn frustum_task(fx: &Fixture) -> TaskSpec {
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
        depends_on: &[],
        hidden: hidden_cases("frustum", 6, |rng, _| {
            let (l, r) = (rng.range(-3.0, -0.01), rng.range(0.01, 3.0));
            let (b, t) = (rng.range(-3.0, -0.01), rng.range(0.01, 3.0));
            let n = rng.range(0.01, 5.0);
            let f = n * rng.range(2.0, 1000.0);
            let a = [l, r, b, t, n, f];
            Case {
                label: format!("hidden P_frustum{a:?}"),
                input: json!(a),
                expected: flat(&frustum(l, r, b, t, n, f)),
            }
        }),
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
                hint: "wrong NDC range: this maps depth to [0, 1] (Direct3D/Vulkan); the exercise slides' \
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

pub(super) fn stereo_frustum_task(fx: &Fixture) -> TaskSpec {
    let mut cases = Vec::new();
    let mut wrong: [Vec<Vec<f64>>; 4] = Default::default();
    for (s, cam) in setups(fx) {
        let d = s.eye_separation;
        let ok = eyes(&s, &cam, d, CameraMode::OffAxis, Lighting::PerEye);
        let toe = eyes(&s, &cam, d, CameraMode::Parallel, Lighting::PerEye);
        let double = eyes(&s, &cam, 2.0 * d, CameraMode::OffAxis, Lighting::PerEye);
        for eye in Eye::BOTH {
            let i = eye.index();
            cases.push(Case {
                label: format!("eye {i} of {s:?}"),
                input: json!([s, eye]),
                expected: flat(&ok[i].frustum),
            });
            wrong[0].push(flat(&ok[eye.other().index()].frustum));
            wrong[1].push(flat(&toe[i].frustum));
            wrong[2].push(flat(&double[i].frustum));
            let mut no_scale = toe[i].frustum;
            let shift = -eye.sign() * 0.5 * d;
            no_scale[0] += shift;
            no_scale[1] += shift;
            wrong[3].push(flat(&no_scale));
        }
    }
    // φ in degrees fed to tan as if radians: t = n·tan(fov_y/2) with fov_y in degrees.
    let fov_degrees = setups(fx)
        .iter()
        .flat_map(|(s, _)| {
            let t = s.near * (0.5 * s.fov_y_degrees).tan();
            let w = t * s.aspect;
            Eye::BOTH.map(|eye| {
                let shift = -eye.sign() * 0.5 * s.eye_separation * s.near / s.zero_parallax;
                flat(&[-w + shift, w + shift, -t, t, s.near, s.far])
            })
        })
        .collect();
    let [swapped, toe, double, no_scale] = wrong;
    TaskSpec {
        name: "stereo_frustum",
        points: 2.0,
        bonus: false,
        depends_on: &[],
        hidden: hidden_cases("stereo_frustum", 2 * HIDDEN_SETUPS, |rng, i| {
            let (s, cam) = random_setup(rng);
            let eye = Eye::BOTH[i % 2];
            let ok = eyes(
                &s,
                &cam,
                s.eye_separation,
                CameraMode::OffAxis,
                Lighting::PerEye,
            );
            Case {
                label: format!("hidden: eye {} of {s:?}", eye.index()),
                input: json!([s, eye]),
                expected: flat(&ok[eye.index()].frustum),
            }
        }),
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
                       are not the exercise slides' stereo frusta",
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
            Mistake {
                id: "degrees-not-radians",
                hint: "the field of view is in DEGREES (fov_y_degrees) and tan takes radians: \
                       t = n·tan(fov_y.to_radians() / 2)",
                answers: fov_degrees,
            },
        ],
        image: None,
    }
}
