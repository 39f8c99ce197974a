//! Disparity by semi-global matching (H. Hirschmüller, "Stereo Processing by Semiglobal
//! Matching and Mutual Information", IEEE PAMI 30(2), 2008), with a census transform as the
//! matching cost (R. Zabih, J. Woodfill, "Non-parametric Local Transforms for Computing
//! Visual Correspondence", ECCV 1994), sub-pixel refinement by a parabola through the best
//! cost and its neighbours, a left-right consistency check and a confidence per pixel.
//!
//! Disparity here is stereolab's parallax: `d = x_right − x_left` in pixels, positive behind
//! the zero-parallax plane. A left pixel `(x, y)` is matched with the right pixel `(x + d, y)`.
//! Every step is integer arithmetic on 8-bit inputs until the sub-pixel fit, so the map is the
//! same on every machine and thread count.

use stereolab_core::{Error, Result};

/// The census window's half size: 5×5 pixels, 24 comparisons with the centre.
const CENSUS_RADIUS: i32 = 2;
/// The largest census distance (24 bits).
const MAX_COST: u16 = 24;
/// The most cells (pixels × disparities) a cost volume may hold: three volumes of 2 bytes a
/// cell (the costs, one path's sums, the sum over paths), 384 MiB at most.
pub const MAX_CELLS: u64 = 1 << 26;

/// How to match.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SgmSettings {
    /// The smallest disparity searched (px).
    pub min: i32,
    /// The largest disparity searched (px).
    pub max: i32,
    /// The penalty for a change of disparity by one pixel between neighbours.
    pub p1: u16,
    /// The penalty for a larger change (a depth edge).
    pub p2: u16,
    /// The most two matches may disagree (px) in the left-right check.
    pub lr_tolerance: f32,
}

impl SgmSettings {
    /// Searching `−range..=range`, with penalties for census costs: P1 = 3, P2 = 20 (the
    /// 5×5 census's costs run from 0 to 24).
    pub fn symmetric(range: i32) -> SgmSettings {
        SgmSettings {
            min: -range,
            max: range,
            p1: 3,
            p2: 20,
            lr_tolerance: 1.0,
        }
    }
}

/// A disparity map of the left view.
#[derive(Clone, Debug, PartialEq)]
pub struct DisparityMap {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `x_right − x_left` per left pixel, sub-pixel; NaN where the match failed the left-right
    /// check, left the right view, or the left pixel's 5×5 window is flat (no texture to
    /// match: the value would only be what the paths carried in from elsewhere).
    pub disparity: Vec<f32>,
    /// 0..1 per pixel: how much better the best match is than the best one more than a pixel
    /// away (`(S₂ − S₁)/S₂` of the aggregated costs); 0 where the disparity is NaN.
    pub confidence: Vec<f32>,
}

impl DisparityMap {
    /// The valid disparities (not NaN).
    pub fn valid(&self) -> impl Iterator<Item = f32> + '_ {
        self.disparity.iter().copied().filter(|d| !d.is_nan())
    }
}

/// The census transform of an 8-bit gray image: per pixel, one bit per neighbour in the 5×5
/// window, set where the neighbour is darker than the centre (outside the image: the edge
/// pixel repeated).
pub fn census(gray: &[u8], width: u32, height: u32) -> Vec<u32> {
    let (w, h) = (width as i32, height as i32);
    let at = |x: i32, y: i32| gray[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
    let mut out = Vec::with_capacity(gray.len());
    for y in 0..h {
        for x in 0..w {
            let c = at(x, y);
            let mut bits = 0u32;
            for dy in -CENSUS_RADIUS..=CENSUS_RADIUS {
                for dx in -CENSUS_RADIUS..=CENSUS_RADIUS {
                    if dx == 0 && dy == 0 {
                        continue;
                    }
                    bits = (bits << 1) | u32::from(at(x + dx, y + dy) < c);
                }
            }
            out.push(bits);
        }
    }
    out
}

/// The path directions of the aggregation: the 8 of Hirschmüller's paper (§3.3).
const PATHS: [(i32, i32); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (-1, -1),
    (1, -1),
    (-1, 1),
];

/// One path's recurrence at one pixel (eq. 13): `L(p, d) = C(p, d) + min(L(p−r, d),
/// L(p−r, d±1) + P1, min_k L(p−r, k) + P2) − min_k L(p−r, k)`; `prev` is `L(p−r, ·)`, or
/// `None` where the path enters the image.
fn path_step(cost: &[u16], prev: Option<&[u16]>, p1: u16, p2: u16, out: &mut [u16]) {
    let Some(prev) = prev else {
        out.copy_from_slice(cost);
        return;
    };
    let best = prev.iter().copied().min().unwrap_or(0);
    let n = cost.len();
    for d in 0..n {
        let mut m = prev[d];
        if d > 0 {
            m = m.min(prev[d - 1].saturating_add(p1));
        }
        if d + 1 < n {
            m = m.min(prev[d + 1].saturating_add(p1));
        }
        m = m.min(best.saturating_add(p2));
        out[d] = cost[d] + (m - best);
    }
}

/// The disparity map of `left` against `right` (8-bit gray, the same size) by semi-global
/// matching.
///
/// # Errors
/// Different sizes, an empty range, or a cost volume above [`MAX_CELLS`].
pub fn sgm(
    left: &[u8],
    right: &[u8],
    width: u32,
    height: u32,
    settings: SgmSettings,
) -> Result<DisparityMap> {
    let pixels = u64::from(width) * u64::from(height);
    if left.len() as u64 != pixels || right.len() as u64 != pixels || pixels == 0 {
        return Err(Error::invalid(
            "disparity",
            format!("{width}×{height}"),
            "both views must be that size and not empty",
        ));
    }
    if settings.min > settings.max {
        return Err(Error::invalid(
            "disparity range",
            format!("{}..={}", settings.min, settings.max),
            "the smallest disparity must not exceed the largest",
        ));
    }
    let nd = (settings.max - settings.min + 1) as usize;
    let cells = pixels * nd as u64;
    if cells > MAX_CELLS {
        return Err(Error::invalid(
            "disparity",
            format!("{width}×{height} × {nd} disparities"),
            format!("more than {MAX_CELLS} cells; search a narrower range or a smaller picture"),
        ));
    }
    let (w, h) = (width as i32, height as i32);
    let (cl, cr) = (census(left, width, height), census(right, width, height));
    // C(x, y, d): the census distance, the largest cost where x + d leaves the right view.
    let mut cost = vec![MAX_COST; cells as usize];
    for y in 0..h {
        for x in 0..w {
            let base = ((y * w + x) as usize) * nd;
            for (k, d) in (settings.min..=settings.max).enumerate() {
                let xr = x + d;
                if (0..w).contains(&xr) {
                    let a = cl[(y * w + x) as usize];
                    let b = cr[(y * w + xr) as usize];
                    cost[base + k] = (a ^ b).count_ones() as u16;
                }
            }
        }
    }
    // S(p, d) = Σ_r L_r(p, d), path by path; each path needs only its previous pixel's L.
    let mut sum = vec![0u16; cells as usize];
    let mut l_prev = vec![0u16; (w * h) as usize * nd];
    let mut step = vec![0u16; nd];
    for (dx, dy) in PATHS {
        // Visit pixels so that p − r is always visited before p.
        let xs: Vec<i32> = if dx >= 0 {
            (0..w).collect()
        } else {
            (0..w).rev().collect()
        };
        let ys: Vec<i32> = if dy >= 0 {
            (0..h).collect()
        } else {
            (0..h).rev().collect()
        };
        for &y in &ys {
            for &x in &xs {
                let i = (y * w + x) as usize;
                let (px, py) = (x - dx, y - dy);
                let inside = (0..w).contains(&px) && (0..h).contains(&py);
                let c = &cost[i * nd..(i + 1) * nd];
                if inside {
                    let j = (py * w + px) as usize;
                    path_step(
                        c,
                        Some(&l_prev[j * nd..(j + 1) * nd]),
                        settings.p1,
                        settings.p2,
                        &mut step,
                    );
                } else {
                    path_step(c, None, settings.p1, settings.p2, &mut step);
                }
                l_prev[i * nd..(i + 1) * nd].copy_from_slice(&step);
                for (s, l) in sum[i * nd..(i + 1) * nd].iter_mut().zip(&step) {
                    *s = s.saturating_add(*l);
                }
            }
        }
    }
    drop(l_prev);
    // The right view's best match per pixel, for the left-right check: argmin_d S(xr − d, d).
    let mut right_best = vec![f32::NAN; (w * h) as usize];
    for y in 0..h {
        for xr in 0..w {
            let mut best = (u16::MAX, 0i32);
            for (k, d) in (settings.min..=settings.max).enumerate() {
                let x = xr - d;
                if (0..w).contains(&x) {
                    let s = sum[((y * w + x) as usize) * nd + k];
                    if s < best.0 {
                        best = (s, d);
                    }
                }
            }
            if best.0 != u16::MAX {
                right_best[(y * w + xr) as usize] = best.1 as f32;
            }
        }
    }
    let mut disparity = vec![f32::NAN; (w * h) as usize];
    let mut confidence = vec![0f32; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if flat(left, w, h, x, y) {
                continue;
            }
            let s = &sum[i * nd..(i + 1) * nd];
            // Only disparities that stay inside the right view.
            let valid = |k: usize| (0..w).contains(&(x + settings.min + k as i32));
            let Some(k) = (0..nd).filter(|&k| valid(k)).min_by_key(|&k| (s[k], k)) else {
                continue;
            };
            let d = settings.min + k as i32;
            let xr = x + d;
            if (right_best[(y * w + xr) as usize] - d as f32).abs() > settings.lr_tolerance {
                continue;
            }
            disparity[i] = d as f32 + subpixel(s, k, &valid);
            let second = (0..nd)
                .filter(|&j| valid(j) && j.abs_diff(k) > 1)
                .map(|j| s[j])
                .min();
            confidence[i] = match second {
                Some(s2) if s2 > 0 => f32::from(s2 - s[k].min(s2)) / f32::from(s2),
                _ => 0.0,
            };
        }
    }
    Ok(DisparityMap {
        width,
        height,
        disparity,
        confidence,
    })
}

/// Whether the census window around `(x, y)` spans at most [`FLAT`] gray levels.
fn flat(gray: &[u8], w: i32, h: i32, x: i32, y: i32) -> bool {
    let (mut lo, mut hi) = (u8::MAX, u8::MIN);
    for dy in -CENSUS_RADIUS..=CENSUS_RADIUS {
        for dx in -CENSUS_RADIUS..=CENSUS_RADIUS {
            let v = gray[((y + dy).clamp(0, h - 1) * w + (x + dx).clamp(0, w - 1)) as usize];
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    hi - lo <= FLAT
}

/// The widest spread of gray levels a window may have and still count as flat.
const FLAT: u8 = 2;

/// The offset in (−½, ½) of the minimum of the parabola through `s[k−1]`, `s[k]`, `s[k+1]`:
/// `(s₋ − s₊) / (2 (s₋ − 2 s₀ + s₊))`; 0 at the ends of the range or on a flat bottom.
pub fn subpixel(s: &[u16], k: usize, valid: &dyn Fn(usize) -> bool) -> f32 {
    if k == 0 || k + 1 >= s.len() || !valid(k - 1) || !valid(k + 1) {
        return 0.0;
    }
    let (a, b, c) = (f32::from(s[k - 1]), f32::from(s[k]), f32::from(s[k + 1]));
    let curvature = a - 2.0 * b + c;
    if curvature <= 0.0 {
        return 0.0;
    }
    ((a - c) / (2.0 * curvature)).clamp(-0.5, 0.5)
}
