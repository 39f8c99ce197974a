//! Exercise 1's frustum tasks: the mono `frustum` matrix and each eye's off-axis `stereo_frustum`.

use glam::Mat4;
use serde_json::json;

use super::{MATRIX_TOLERANCE, eyes, flat, setups};
use crate::grade::fixture::Fixture;
use crate::grade::spec::{Case, Mistake, TaskSpec, Tolerance};
use crate::math::{CameraMode, Lighting, frustum};

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
        ],
        image: None,
    }
}
