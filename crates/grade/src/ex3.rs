//! Exercise 3 (the SIRDS paper (Petz et al.), SIRDS): the tasks, reference answers, mistakes, image checks.
//!
//! The reference is stereolab's SIRDS module: its Eq. (3) separation and its per-pixel linking
//! (`stereolab_core::RowLinker`, Thimbleby, Inglis and Witten's algorithm). The known
//! mistakes are modelled by `variant_links`, which a unit test holds equal to the module when
//! no mistake is switched on.

use serde_json::json;

use super::ex1::flat;
use super::fixture::{Fixture, unproject};
use super::spec::{Case, Mistake, Picture, TaskSpec, Tolerance, hidden_cases};
use crate::exercise::{SirdsGeometry, SirdsSetup};
use stereolab_core::{
    Disparity, DisparityModel, Framebuffer, RowLinker, separation_eye_distance,
    separation_view_angle,
};

/// Every task of exercise 3.
pub(crate) fn tasks(fx: &Fixture) -> Vec<TaskSpec> {
    vec![direction_task(), eyes_task(), link_task(fx)]
}

/// The viewing set-up of the link checks: eyes 64 px apart, 240 px in front of the image,
/// nearness spanning 20 … 60 px behind it (separations 4.9 … 12.8 px).
pub(crate) const SETUP: SirdsSetup = SirdsSetup {
    eye_distance: 64.0,
    focal_length: 240.0,
    depth_near: 20.0,
    depth_far: 60.0,
};

fn disparity(z: f32, g: &SirdsGeometry) -> f32 {
    separation_eye_distance(z, g.eye_distance, g.focal_length).unwrap_or(f32::NAN)
}

/// stereolab's pixel set-up for `s` (Eq. (3)).
fn module_disparity(s: &SirdsSetup) -> Disparity {
    Disparity {
        model: DisparityModel::EyeDistance,
        eye_separation: s.eye_distance,
        viewing_distance: s.focal_length,
        t_near: s.depth_near,
        t_far: s.depth_far,
        tan_phi: 0.0,
    }
}

/// stereolab's links of one row (hidden-surface removal on or off).
fn module_links(nearness: &[f32], row: u32, s: &SirdsSetup, hidden: bool) -> Vec<usize> {
    let mut linker = RowLinker::default();
    linker.link_row(nearness, row, &module_disparity(s), 1, hidden);
    linker.same.iter().map(|&v| v as usize).collect()
}

/// Known linking mistakes.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Linking {
    FullDisparity,
    Truncated,
    NoRowAlternation,
}

/// The stub's algorithm (see its doc comment), with one mistake switched on or none.
fn variant_links(nearness: &[f32], row: u32, s: &SirdsSetup, how: Option<Linking>) -> Vec<usize> {
    let n = nearness.len();
    let span = s.depth_far - s.depth_near;
    let mut same: Vec<usize> = (0..n).collect();
    for (x, &z) in nearness.iter().enumerate() {
        let t = s.depth_far - z * span;
        let d = s.eye_distance * t / (t + s.focal_length);
        let sep = if how == Some(Linking::Truncated) {
            d
        } else {
            d + 0.5
        }
        .max(0.0) as usize;
        let shift = match how {
            Some(Linking::FullDisparity) => Some(sep),
            Some(Linking::NoRowAlternation) => Some(sep / 2),
            _ => Some((sep + (sep & row as usize & 1)) / 2),
        };
        let Some(left) = shift.and_then(|h| x.checked_sub(h)) else {
            continue;
        };
        let right = if how == Some(Linking::FullDisparity) {
            x + sep
        } else {
            left + sep
        };
        let rise = 2.0 * (t + s.focal_length) / s.eye_distance / span;
        if right >= n || hidden(nearness, x, rise) {
            continue;
        }
        link(&mut same, left, right);
    }
    same
}

/// Something at least as near blocks a ray from the point at `x` to either eye.
fn hidden(nearness: &[f32], x: usize, rise: f32) -> bool {
    let z = nearness[x];
    let mut k = 1;
    loop {
        let zk = z + k as f32 * rise;
        let at_least = |i: Option<usize>| i.and_then(|i| nearness.get(i)).is_some_and(|&v| v >= zk);
        if at_least(x.checked_sub(k)) || at_least(Some(x + k)) {
            return true;
        }
        if zk >= 1.0 {
            return false;
        }
        k += 1;
    }
}

/// Thimbleby, Inglis and Witten's union, keeping `same[i] ≥ i`.
fn link(same: &mut [usize], mut left: usize, mut right: usize) {
    let mut k = same[left];
    while k != left && k != right {
        if k < right {
            left = k;
        } else {
            left = right;
            right = k;
        }
        k = same[left];
    }
    same[left] = right;
}

/// The fixture's cyclopean depth as SIRDS nearness rows: 1 at the nearest surface, 0 at the
/// farthest (the backdrop) and for background pixels.
fn nearness_rows(fx: &Fixture) -> Vec<Vec<f32>> {
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
                .map(|x| dist(x, y).map_or(0.0, |d| (1.0 - (d - lo) / (hi - lo)).clamp(0.0, 1.0)))
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
    fb.cover_all();
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
        fb.color_mut()[start..start + w].copy_from_slice(&pix);
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
    let rows = nearness_rows(fx);
    let mut inputs: Vec<(String, Vec<f32>, u32)> = vec![
        ("flat row, nearness 0.5".into(), vec![0.5; 48], 0),
        (
            "near box on the background".into(),
            (0..48)
                .map(|x| if (18..30).contains(&x) { 1.0 } else { 0.0 })
                .collect(),
            0,
        ),
        (
            "narrow near pillar, odd row".into(),
            (0..48)
                .map(|x| if (22..25).contains(&x) { 1.0 } else { 0.1 })
                .collect(),
            1,
        ),
        (
            "ramp 1 → 0, odd row".into(),
            (0..48).map(|x| 1.0 - x as f32 / 47.0).collect(),
            3,
        ),
    ];
    inputs.extend(
        rows.iter()
            .enumerate()
            .map(|(y, r)| (format!("fixture row {y}"), r.clone(), y as u32)),
    );
    let each = |how| {
        inputs
            .iter()
            .map(|(_, r, y)| flat(&variant_links(r, *y, &SETUP, Some(how))))
            .collect()
    };
    let w = fx.size().0;
    let expected = sirds_picture(
        w,
        &rows
            .iter()
            .enumerate()
            .map(|(y, r)| Some(module_links(r, y as u32, &SETUP, true)))
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
        depends_on: &["disparity_constant_eyes"],
        hidden: hidden_cases("link_row", 6, |rng, _| {
            // A row of 32 … 64 pixels in flat steps of random nearness (steps are where hidden
            // surfaces and the row alternation show), a random row and viewing set-up.
            let n = 32 + (rng.next_u64() % 33) as usize;
            let mut row = Vec::with_capacity(n);
            while row.len() < n {
                let len = 3 + (rng.next_u64() % 12) as usize;
                let v = rng.range(0.0, 1.0);
                row.extend(std::iter::repeat_n(v, len.min(n - row.len())));
            }
            let y = (rng.next_u64() % 48) as u32;
            let depth_near = rng.range(10.0, 30.0);
            let s = SirdsSetup {
                eye_distance: rng.range(48.0, 80.0),
                focal_length: rng.range(180.0, 300.0),
                depth_near,
                depth_far: depth_near + rng.range(20.0, 60.0),
            };
            Case {
                label: format!("hidden: row {y} of {n} pixels, {s:?}"),
                input: json!([row, y, s]),
                expected: flat(&module_links(&row, y, &s, true)),
            }
        }),
        tolerance: Tolerance::EXACT,
        cases: inputs
            .iter()
            .map(|(label, r, y)| Case {
                label: label.clone(),
                input: json!([r, y, SETUP]),
                expected: flat(&module_links(r, *y, &SETUP, true)),
            })
            .collect(),
        mistakes: vec![
            Mistake {
                id: "d-instead-of-half-d",
                hint: "d instead of d/2: the two pixels sit s/2 to the left and s/2 to the right \
                       of x (the SIRDS paper (Petz et al.) shifts the vertex by d/2 and the texture by d/2)",
                answers: each(Linking::FullDisparity),
            },
            Mistake {
                id: "no-hidden-surfaces",
                hint: "hidden-surface removal missing: a point one eye cannot see must not be \
                       linked (check the rays to both eyes, step 2)",
                answers: inputs
                    .iter()
                    .map(|(_, r, y)| flat(&module_links(r, *y, &SETUP, false)))
                    .collect(),
            },
            Mistake {
                id: "truncated-separation",
                hint: "round the separation half up, ⌊d + ½⌋, do not truncate it",
                answers: each(Linking::Truncated),
            },
            Mistake {
                id: "no-row-alternation",
                hint: "for odd separations the extra pixel alternates with the row: \
                       left = x − (s + (s & row & 1)) / 2",
                answers: each(Linking::NoRowAlternation),
            },
        ],
        image: Some(crate::pictures::check(
            rows.iter()
                .enumerate()
                .map(|(y, r)| json!([r, y, SETUP]))
                .collect(),
            Box::new(build),
        )),
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
        depends_on: &[],
        hidden: hidden_cases("disparity_constant_direction", 5, |rng, _| {
            let (z, p) = (rng.range(0.0, 50.0), rng.range(0.1, 1.5));
            Case {
                label: format!("hidden: z = {z}, phi = {p} rad"),
                input: json!([z, p]),
                expected: vec![separation_view_angle(z, p.tan()) as f64],
            }
        }),
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
                expected: vec![separation_view_angle(*z, p.tan()) as f64],
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
                hint: "φ is given in radians already: to_radians() reads 0.785 rad as 0.785°",
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
        depends_on: &[],
        hidden: hidden_cases("disparity_constant_eyes", 5, |rng, _| {
            let z = rng.range(0.0, 1000.0);
            let g = g(rng.range(40.0, 130.0), rng.range(100.0, 600.0));
            Case {
                label: format!("hidden: z = {z}, {g:?}"),
                input: json!([z, g]),
                expected: vec![disparity(z, &g) as f64],
            }
        }),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixture::grading_scene;

    #[test]
    fn the_mistake_model_without_a_mistake_is_stereolabs_linking() {
        let fx = Fixture::new(grading_scene().unwrap()).unwrap();
        for (y, row) in nearness_rows(&fx).iter().enumerate() {
            for y in [y as u32, y as u32 + 1] {
                assert_eq!(
                    variant_links(row, y, &SETUP, None),
                    module_links(row, y, &SETUP, true),
                    "row {y}"
                );
            }
        }
    }
}
