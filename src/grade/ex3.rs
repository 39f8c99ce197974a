//! Exercise 3 (seed 002, SIRDS): the tasks, reference answers, mistakes, image checks.
//!
//! The reference linking is the grader's own (seed 002's disparity, Eq. (3), with the linking
//! and hidden-surface removal of Thimbleby, Inglis and Witten, 1994) until the SIRDS module lands
//! on main.

use serde_json::json;

use super::ex1::flat;
use super::fixture::{Fixture, unproject};
use super::spec::{Case, ImageCheck, Mistake, Picture, TaskSpec, Tolerance};
use crate::exercise::SirdsGeometry;
use crate::framebuffer::Framebuffer;

/// Every task of exercise 3.
pub fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![direction_task(), eyes_task(), link_task(fx)]
}

/// The viewing geometry of the image check: eyes 64 px apart, 240 px in front of the image.
pub const GEOMETRY: SirdsGeometry = SirdsGeometry {
    eye_distance: 64.0,
    focal_length: 240.0,
};
/// Depth (px behind the image plane) of the nearest surface of the depth map.
const NEAREST_PX: f32 = 20.0;
/// Depth of the background plane (seed 002 bounds the scene by one).
const BACKGROUND_PX: f32 = 60.0;

fn disparity(z: f32, g: &SirdsGeometry) -> f32 {
    g.eye_distance * z / (z + g.focal_length)
}

/// How the reference links a row; `Normal` is the specification.
#[derive(Clone, Copy, PartialEq)]
enum Linking {
    Normal,
    FullDisparity,
    NoHiddenSurfaces,
    Truncated,
}

fn reference_links(depths: &[f32], g: &SirdsGeometry, how: Linking) -> Vec<usize> {
    let w = depths.len();
    let mut same: Vec<usize> = (0..w).collect();
    for x in 0..w {
        let d = disparity(depths[x], g);
        let s = if how == Linking::Truncated {
            d.floor()
        } else {
            d.round()
        }
        .max(0.0) as usize;
        let (left, width) = if how == Linking::FullDisparity {
            (x.checked_sub(s), 2 * s)
        } else {
            (x.checked_sub(s / 2), s)
        };
        let Some(left) = left else { continue };
        let right = left + width;
        if right >= w || (how != Linking::NoHiddenSurfaces && hidden(depths, x, g)) {
            continue;
        }
        link(&mut same, left, right);
    }
    same
}

/// Something nearer than the ray from (x, depth) to either eye blocks it.
fn hidden(depths: &[f32], x: usize, g: &SirdsGeometry) -> bool {
    let z = depths[x];
    let slope = (z + g.focal_length) / (0.5 * g.eye_distance);
    let mut t = 1;
    loop {
        let ray = z - t as f32 * slope;
        if ray <= 0.0 || t > x || x + t >= depths.len() {
            return false;
        }
        if depths[x - t] < ray || depths[x + t] < ray {
            return true;
        }
        t += 1;
    }
}

/// Thimbleby's union keeping `same[i] ≥ i`.
fn link(same: &mut [usize], mut left: usize, mut right: usize) {
    let mut k = same[left];
    while k != left && k != right {
        if k < right {
            left = k;
        } else {
            same[left] = right;
            left = right;
            right = k;
        }
        k = same[left];
    }
    same[left] = right;
}

/// The fixture's cyclopean depth as a SIRDS depth map: rows of pixels behind the image plane.
fn depth_rows(fx: &Fixture) -> Vec<Vec<f32>> {
    let (w, h) = fx.size();
    let dist = |x, y| unproject(&fx.center_matrices, &fx.center, x, y).map(|p| -p.z);
    let all: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).filter_map(move |x| dist(x, y)))
        .collect();
    let lo = all.iter().copied().fold(f32::MAX, f32::min);
    let hi = all.iter().copied().fold(f32::MIN, f32::max).max(lo + 1e-6);
    (0..h)
        .map(|y| {
            (0..w)
                .map(|x| {
                    let t = dist(x, y).map_or(1.0, |d| ((d - lo) / (hi - lo)).clamp(0.0, 1.0));
                    NEAREST_PX + (BACKGROUND_PX - NEAREST_PX) * t
                })
                .collect()
        })
        .collect()
}

/// A deterministic random color per pixel (the "random dot" pattern).
fn dot(x: usize, y: usize) -> [u8; 4] {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    [h as u8, (h >> 8) as u8, (h >> 16) as u8, 255]
}

/// The SIRDS of rows of links: right to left, a linked pixel copies its partner.
fn sirds_picture(w: u32, rows: &[Option<Vec<usize>>]) -> Framebuffer {
    let h = rows.len() as u32;
    let mut fb = Framebuffer::new(w, h.max(1), [0, 0, 0, 255]).expect("the scene's size");
    fb.depth.fill(0.0);
    for (y, row) in rows.iter().enumerate() {
        let w = w as usize;
        let mut pix = vec![[0u8; 4]; w];
        for x in (0..w).rev() {
            let partner = row.as_ref().and_then(|r| r.get(x).copied());
            pix[x] = match partner {
                Some(p) if p > x && p < w => pix[p],
                _ => dot(x, y),
            };
        }
        let start = y * w;
        fb.color[start..start + w].copy_from_slice(&pix);
    }
    fb
}

fn links_of(a: &Option<Vec<f64>>) -> Option<Vec<usize>> {
    a.as_ref()?
        .iter()
        .map(|v| (v.is_finite() && *v >= 0.0 && v.fract() == 0.0).then_some(*v as usize))
        .collect()
}

fn link_task(fx: &Fixture) -> TaskSpec {
    let rows = depth_rows(fx);
    let mut inputs: Vec<(String, Vec<f32>)> = vec![
        ("flat row at 40 px".into(), vec![40.0; 48]),
        (
            "near box (20 px) on a far plane (60 px)".into(),
            (0..48)
                .map(|x| if (18..30).contains(&x) { 20.0 } else { 60.0 })
                .collect(),
        ),
        (
            "narrow near pillar".into(),
            (0..48)
                .map(|x| if (22..25).contains(&x) { 10.0 } else { 60.0 })
                .collect(),
        ),
        (
            "ramp 20 → 60 px".into(),
            (0..48).map(|x| 20.0 + 40.0 * x as f32 / 47.0).collect(),
        ),
    ];
    inputs.extend(
        rows.iter()
            .enumerate()
            .map(|(y, r)| (format!("fixture row {y}"), r.clone())),
    );
    let each = |how| {
        inputs
            .iter()
            .map(|(_, r)| flat(&reference_links(r, &GEOMETRY, how)))
            .collect()
    };
    let w = fx.size().0;
    let expected = sirds_picture(
        w,
        &rows
            .iter()
            .map(|r| Some(reference_links(r, &GEOMETRY, Linking::Normal)))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: "sirds".into(),
            expected: expected.clone(),
            actual: sirds_picture(w, &answers.iter().map(links_of).collect::<Vec<_>>()),
        }]
    };
    TaskSpec {
        name: "link_row",
        points: 3.0,
        bonus: false,
        tolerance: Tolerance::EXACT,
        cases: inputs
            .iter()
            .map(|(label, r)| Case {
                label: label.clone(),
                input: json!([r, GEOMETRY]),
                expected: flat(&reference_links(r, &GEOMETRY, Linking::Normal)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "d-instead-of-half-d",
                hint: "d instead of d/2: the two pixels sit s/2 to the left and s/2 to the right \
                       of x (seed 002 shifts the vertex by d/2 and the texture by d/2)",
                answers: each(Linking::FullDisparity),
            },
            Mistake {
                id: "no-hidden-surfaces",
                hint: "hidden-surface removal missing: a point one eye cannot see must not be \
                       linked (check the rays to both eyes, step 2)",
                answers: each(Linking::NoHiddenSurfaces),
            },
            Mistake {
                id: "truncated-separation",
                hint: "round the separation to the nearest pixel, do not truncate it",
                answers: each(Linking::Truncated),
            },
        ],
        image: Some(ImageCheck {
            inputs: rows.iter().map(|r| json!([r, GEOMETRY])).collect(),
            build: Box::new(build),
        }),
    }
}

fn direction_task() -> TaskSpec {
    let inputs: [[f32; 2]; 5] = [
        [10.0, std::f32::consts::FRAC_PI_4],
        [5.0, 1.2],
        [0.0, 0.8],
        [30.0, 0.3],
        [2.5, 1.5],
    ];
    let each =
        |f: &dyn Fn(f32, f32) -> f32| inputs.iter().map(|[z, p]| vec![f(*z, *p) as f64]).collect();
    TaskSpec {
        name: "disparity_constant_direction",
        points: 1.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 1e-5,
            rel: 1e-5,
            why: "a tangent and a division in f32",
        },
        cases: inputs
            .iter()
            .map(|[z, p]| Case {
                label: format!("z = {z}, phi = {p} rad"),
                input: json!([z, p]),
                expected: vec![(2.0 * z / p.tan()) as f64],
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "half-d-instead-of-d",
                hint: "this is half the distance: Eq. (1) is d = 2z / tan φ (both eyes' rays)",
                answers: each(&|z, p| z / p.tan()),
            },
            Mistake {
                id: "degrees",
                hint: "φ is given in radians already",
                answers: each(&|z, p| 2.0 * z / p.to_radians().tan()),
            },
            Mistake {
                id: "tan-inverted",
                hint: "divide by tan φ, do not multiply",
                answers: each(&|z, p| 2.0 * z * p.tan()),
            },
        ],
        image: None,
    }
}

fn eyes_task() -> TaskSpec {
    let g = |a, f| SirdsGeometry {
        eye_distance: a,
        focal_length: f,
    };
    let inputs = [
        (60.0f32, g(60.0, 240.0)),
        (0.0, g(60.0, 240.0)),
        (100.0, g(64.0, 240.0)),
        (20.0, g(120.0, 500.0)),
        (1000.0, g(64.0, 240.0)),
    ];
    let each = |f: &dyn Fn(f32, &SirdsGeometry) -> f32| {
        inputs.iter().map(|(z, g)| vec![f(*z, g) as f64]).collect()
    };
    TaskSpec {
        name: "disparity_constant_eyes",
        points: 1.0,
        bonus: false,
        tolerance: Tolerance {
            abs: 1e-5,
            rel: 1e-5,
            why: "one product and one division in f32",
        },
        cases: inputs
            .iter()
            .map(|(z, g)| Case {
                label: format!("z = {z}, {g:?}"),
                input: json!([z, g]),
                expected: vec![disparity(*z, g) as f64],
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "half-d-instead-of-d",
                hint: "this is half the distance: Eq. (3) is d = a z / (z + f)",
                answers: each(&|z, g| 0.5 * disparity(z, g)),
            },
            Mistake {
                id: "minus-f",
                hint: "z + f: the eyes are f in front of the image plane, the point z behind it",
                answers: each(&|z, g| g.eye_distance * z / (z - g.focal_length)),
            },
            Mistake {
                id: "f-over",
                hint: "the numerator is a·z (the point's depth), not a·f",
                answers: each(&|z, g| g.eye_distance * g.focal_length / (z + g.focal_length)),
            },
        ],
        image: None,
    }
}
