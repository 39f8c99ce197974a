//! The instructor's solution (feature `solution`). Never part of the student handout.
//!
//! `STEREOLAB_MUTANT=name[,name]` plants a known mistake for the grader's mutation tests:
//! `full-disparity` (pairs at x ∓ s instead of x ∓ s/2), `no-hidden-surfaces`.

use stereolab::exercise::SirdsGeometry;

fn planted(mistake: &str) -> bool {
    std::env::var("STEREOLAB_MUTANT").is_ok_and(|v| v.split(',').any(|m| m == mistake))
}

/// Eq. (1) of seed 002.
pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {
    2.0 * z / phi.tan()
}

/// Eq. (3) of seed 002.
pub fn disparity_constant_eyes(z: f32, geometry: &SirdsGeometry) -> f32 {
    geometry.eye_distance * z / (z + geometry.focal_length)
}

/// Thimbleby's linking with seed 002's geometry.
pub fn link_row(depths: &[f32], geometry: &SirdsGeometry) -> Vec<usize> {
    let w = depths.len();
    let mut same: Vec<usize> = (0..w).collect();
    for x in 0..w {
        let s = disparity_constant_eyes(depths[x], geometry)
            .round()
            .max(0.0) as usize;
        let (left, width) = if planted("full-disparity") {
            (x.checked_sub(s), 2 * s)
        } else {
            (x.checked_sub(s / 2), s)
        };
        let Some(left) = left else { continue };
        let right = left + width;
        if right >= w || (!planted("no-hidden-surfaces") && hidden(depths, x, geometry)) {
            continue;
        }
        link(&mut same, left, right);
    }
    same
}

/// Whether something nearer blocks the ray from (x, depth) to either eye.
fn hidden(depths: &[f32], x: usize, g: &SirdsGeometry) -> bool {
    let z = depths[x];
    let slope = (z + g.focal_length) / (0.5 * g.eye_distance);
    for t in 1.. {
        let ray = z - t as f32 * slope;
        if ray <= 0.0 || t > x || x + t >= depths.len() {
            return false;
        }
        if depths[x - t] < ray || depths[x + t] < ray {
            return true;
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
            same[left] = right;
            left = right;
            right = k;
        }
        k = same[left];
    }
    same[left] = right;
}
