//! The instructor's solution (feature `solution`). Never part of the student handout.
//!
//! `STEREOLAB_MUTANT=name[,name]` plants a known mistake for the grader's mutation tests:
//! `full-disparity` (pairs at x ∓ s instead of x ∓ s/2), `no-hidden-surfaces`, `degrees-phi` (φ
//! converted from degrees although it is in radians).

use exercise_api::{SirdsGeometry, SirdsSetup};

fn planted(mistake: &str) -> bool {
    std::env::var("STEREOLAB_MUTANT").is_ok_and(|v| v.split(',').any(|m| m == mistake))
}

/// Eq. (1) of the SIRDS paper (Petz et al.).
pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {
    let phi = if planted("degrees-phi") {
        phi.to_radians()
    } else {
        phi
    };
    2.0 * z / phi.tan()
}

/// Eq. (3) of the SIRDS paper (Petz et al.).
pub fn disparity_constant_eyes(z: f32, geometry: &SirdsGeometry) -> f32 {
    geometry.eye_distance * z / (z + geometry.focal_length)
}

/// Thimbleby, Inglis and Witten's linking with the SIRDS paper's geometry.
pub fn link_row(nearness: &[f32], row: u32, setup: &SirdsSetup) -> Vec<usize> {
    let n = nearness.len();
    let span = setup.depth_far - setup.depth_near;
    let geometry = SirdsGeometry {
        eye_distance: setup.eye_distance,
        focal_length: setup.focal_length,
    };
    let mut same: Vec<usize> = (0..n).collect();
    for (x, &z) in nearness.iter().enumerate() {
        let t = setup.depth_far - z * span;
        let s = (disparity_constant_eyes(t, &geometry) + 0.5).max(0.0) as usize;
        let (left, right) = if planted("full-disparity") {
            (x.checked_sub(s), x + s)
        } else {
            let left = x.checked_sub((s + (s & row as usize & 1)) / 2);
            (left, left.map_or(0, |l| l + s))
        };
        let Some(left) = left else { continue };
        if right >= n {
            continue;
        }
        let rise = 2.0 * (t + setup.focal_length) / setup.eye_distance / span;
        if !planted("no-hidden-surfaces") && hidden(nearness, x, rise) {
            continue;
        }
        link(&mut same, left, right);
    }
    same
}

/// Whether something at least as near blocks a ray from the point at `x` to either eye.
fn hidden(nearness: &[f32], x: usize, rise: f32) -> bool {
    let z = nearness[x];
    for k in 1.. {
        let zk = z + k as f32 * rise;
        let at_least = |i: Option<usize>| i.and_then(|i| nearness.get(i)).is_some_and(|&v| v >= zk);
        if at_least(x.checked_sub(k)) || at_least(Some(x + k)) {
            return true;
        }
        if zk >= 1.0 {
            return false;
        }
    }
    false
}

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
