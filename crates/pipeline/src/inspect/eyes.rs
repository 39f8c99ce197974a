//! Which view is the left eye's, told from the pair alone by its occlusions.
//!
//! Where a nearer surface ends in front of a farther one, the left eye sees a strip of the
//! farther surface, just left of the nearer one's edge, that the right eye does not: the strip
//! has no match, and the left-right check leaves a gap in the disparity map. Going right across
//! such an edge the parallax `x_right − x_left` always steps down, whichever eye is which. What
//! the eyes' order changes is which side the strip belongs to. The strip is part of the farther
//! surface, and with the eyes in order the farther surface is the side with the larger parallax
//! (the left side of the gap). With the views swapped every parallax changes sign: the side with
//! the larger parallax is now the nearer surface, and the strip looks like the side with the
//! smaller one. The strip's colour against its two sides' colours is the vote; only gaps as wide
//! as the step in parallax (an occlusion's width) and sides of clearly different colours vote.
//! A random-dot pair, whose surfaces look alike, gives no verdict, never a guess.

use super::{Finding, Measured, Views};

/// The votes of the pair's occlusions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EyeOrder {
    /// Occlusions whose hidden strip looks like the side with the larger parallax: the eyes
    /// in order.
    pub in_order: usize,
    /// Occlusions whose strip looks like the side with the smaller parallax: the eyes swapped.
    pub swapped: usize,
}

/// Fewest votes for a verdict.
pub const MIN_VOTES: usize = 20;

/// The share of the votes a verdict needs.
pub const VERDICT_SHARE: f64 = 0.75;

/// The least parallax step (px) that counts as an occlusion.
const MIN_STEP: f64 = 3.0;

/// The map pixels left out between a gap and its sides.
const MARGIN: usize = 2;

/// The least colour difference (Euclidean, 8-bit levels) between the two sides of a gap for
/// its strip to vote.
const MIN_CONTRAST: f64 = 24.0;

/// The least spread of gray levels (Rec. 601 luma) in the 5×5 window around a strip's pixel
/// for the strip to be a textured surface hidden from one eye. A strip of smooth shading or a
/// flat background has no match for want of texture, not because it is hidden: it does not
/// vote.
const MIN_TEXTURE: f64 = 16.0;

/// Counts the votes of every gap in every row of the disparity map.
pub fn eye_order(views: &Views, m: &Measured) -> EyeOrder {
    let (w, h) = (m.map.width as usize, m.map.height as usize);
    let s = m.scale;
    let d = |x: usize, y: usize| m.map.disparity[y * w + x];
    let (vw, vh) = views.left.dimensions();
    let gray = super::luma(&views.left);
    let luma = |x: u32, y: u32| f64::from(gray[(y.min(vh - 1) * vw + x.min(vw - 1)) as usize]);
    // The spread of gray levels in the 5×5 window around a map pixel's block centre.
    let texture = |x: usize, y: usize| -> f64 {
        let (cx, cy) = (x as u32 * s + s / 2, y as u32 * s + s / 2);
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for dy in 0..5 {
            for dx in 0..5 {
                let v = luma((cx + dx).saturating_sub(2), (cy + dy).saturating_sub(2));
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        hi - lo
    };
    // The left view's colour at a map pixel (the centre of its block).
    let colour = |x: usize, y: usize| -> [f64; 3] {
        let (fx, fy) = (x as u32 * s + s / 2, y as u32 * s + s / 2);
        let p = views.left.get_pixel(
            fx.min(views.left.width() - 1),
            fy.min(views.left.height() - 1),
        );
        [0, 1, 2].map(|c| f64::from(p.0[c]))
    };
    let mean = |xs: std::ops::Range<usize>, y: usize| -> [f64; 3] {
        let n = xs.len().max(1) as f64;
        let mut sum = [0.0; 3];
        for x in xs {
            let c = colour(x, y);
            (0..3).for_each(|i| sum[i] += c[i]);
        }
        sum.map(|v| v / n)
    };
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let mut votes = EyeOrder::default();
    for y in 0..h {
        let mut x = 0;
        while x < w {
            if !d(x, y).is_nan() {
                x += 1;
                continue;
            }
            let start = x;
            while x < w && d(x, y).is_nan() {
                x += 1;
            }
            let end = x; // the gap is start..end
            let len = end - start;
            // The sides: `k` matched pixels each, [`MARGIN`] pixels away from the gap (the
            // matcher's windows that straddle the edge belong to neither surface).
            let k = len.clamp(2, 6);
            if start < k + MARGIN || end + MARGIN + k > w {
                continue;
            }
            let (left, right) = (
                start - MARGIN - k..start - MARGIN,
                end + MARGIN..end + MARGIN + k,
            );
            if left.clone().chain(right.clone()).any(|x| d(x, y).is_nan()) {
                continue;
            }
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            let step = median(&mut left.clone().map(|x| f64::from(d(x, y))).collect())
                - median(&mut right.clone().map(|x| f64::from(d(x, y))).collect());
            let width = f64::from(len as u32 * s);
            // An occlusion: the parallax steps down by about the gap's width.
            if step < MIN_STEP || width < 0.4 * step - 1.0 || width > 1.6 * step + 2.0 {
                continue;
            }
            // The strip's inner pixels (its ends may hold a neighbour's blurred edge).
            let inner = if len >= 3 {
                start + 1..end - 1
            } else {
                start..end
            };
            // The strip and both sides textured.
            let textured = |xs: std::ops::Range<usize>| {
                median(&mut xs.map(|x| texture(x, y)).collect()) >= MIN_TEXTURE
            };
            if !(textured(inner.clone()) && textured(left.clone()) && textured(right.clone())) {
                continue;
            }
            let (strip, a, b) = (mean(inner, y), mean(left, y), mean(right, y));
            if dist(a, b) < MIN_CONTRAST {
                continue;
            }
            let (to_far, to_near) = (dist(strip, a), dist(strip, b));
            if to_far < 0.5 * to_near {
                votes.in_order += 1;
            } else if to_near < 0.5 * to_far {
                votes.swapped += 1;
            }
        }
    }
    votes
}

impl EyeOrder {
    /// All votes.
    pub fn total(&self) -> usize {
        self.in_order + self.swapped
    }

    /// The report's line.
    pub fn describe(&self) -> String {
        let n = self.total();
        let verdict = if n < MIN_VOTES {
            "too few occlusions between differently coloured surfaces to tell".to_string()
        } else if self.swapped as f64 >= VERDICT_SHARE * n as f64 {
            "swapped".to_string()
        } else if self.in_order as f64 >= VERDICT_SHARE * n as f64 {
            "left, then right".to_string()
        } else {
            "undecided".to_string()
        };
        format!(
            "  eye order: {verdict} ({} of {n} occlusions say in order, {} swapped)\n",
            self.in_order, self.swapped
        )
    }

    /// `eyes swapped` (an error) when at least [`MIN_VOTES`] occlusions vote and
    /// [`VERDICT_SHARE`] of them say swapped.
    pub fn findings(&self) -> Vec<Finding> {
        let n = self.total();
        if n >= MIN_VOTES && self.swapped as f64 >= VERDICT_SHARE * n as f64 {
            vec![Finding::error(
                "eyes swapped",
                format!(
                    "at {} of {n} occlusions the strip one eye alone sees belongs to the nearer \
                     surface by the parallax, which cannot be: the depth order is inverted; swap \
                     the views (or the cameras)",
                    self.swapped
                ),
            )]
        } else {
            Vec::new()
        }
    }
}
