//! Finding an autostereogram's separations without being told them: the first stage of
//! [`decode_auto`](super::decode::decode_auto), for images made by other tools (netpbm's
//! `pamstereogram`, old magazine stereograms) whose viewing set-up nobody knows.
//!
//! # The algorithm
//!
//! An autostereogram repeats along each row: a pixel equals the pixel one separation `s(x)`
//! to its left, and `s` varies slowly with the depth it encodes. Any separation from a few
//! pixels to a third of the width is plausible (a viewer's eyes cannot fuse a repeat wider than
//! about a third of the picture at a normal viewing distance; TIW's far separation is half the
//! eye distance).
//!
//! 1. **Strips of rows bound the cost.** The search looks at whole-resolution strips of
//!    `2h + 1` = 7 rows (one window high), spread evenly down the image, as many as a budget
//!    of [`WORK_BUDGET`] pair differences allows (`7 · W · separations` each), at least one
//!    and at most every row. (Averaging the image down instead would break the exact copies:
//!    a random-dot copy shifted by a fraction of a coarse cell no longer matches.) A 600 × 300
//!    image is searched whole; a 2100 × 200 one in 13 of its 28 strips; the largest accepted
//!    image in one strip, ≈ 1.3·10⁹ differences.
//! 2. **Every whole separation, every column.** For each `s` in the searched range, each
//!    strip column's cost is the mean of `Σ_rgb |I(l) − I(l + s)|` over the pairs `(l, l + s)`
//!    of the 7 × 7 window centred on it (pairs attributed to their middle `l + ⌊s/2⌋`, as the
//!    decoder does); prefix sums along each row make each `s` cost `O(7 W)`. A first pass
//!    sums each column's costs for its mean cost; a second takes the **smallest** `s` that
//!    matches (step 3), not the cheapest: a repeat of `s` also repeats at `2s`, `3s`, ...,
//!    and where `s` drifts (a depth ramp) a harmonic can happen to be cheaper than the
//!    fundamental. Two passes: the budget counts both.
//! 3. **Matched cells.** A strip column (a cell) matches when some cost is at most
//!    `max_cost_ratio` (0.35) of its mean: the same test as the decoder. In noise a 7 × 7
//!    window almost never
//!    passes (for black/white dots at most 8 of 49 pairs may differ: probability about 10⁻⁶
//!    per try), so noise stays noise even with hundreds of separations tried.
//! 4. **The dominant repeat per region.** The cells are grouped in regions of 64 × 64
//!    pixels (the strips whose middle row falls inside). A region with at least a quarter of its cells matched reports the most frequent
//!    separation among them (its dominant repeat) and the 2nd and 98th percentiles (its
//!    spread, without the odd chance match). Harmonics are dropped first: a repeat of `s`
//!    also repeats at `2s`, `3s`, ..., and an autostereogram's own separations span less than
//!    a factor of two, so only matches within a factor of 7/4 of the dominant one count.
//! 5. **The range found** is the smallest 2nd percentile to the largest 98th percentile over
//!    those regions, leaving out a region whose dominant repeat is not within a factor of 7/4
//!    of the median region's (a harmonic, or chance), in image pixels. The decoder then searches only that range (±2 px, and
//!    a pixel of each cell's box) in quarter pixels, as when the range is known.

use rayon::prelude::*;

use crate::error::{Error, Result};

/// The search's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchOptions {
    /// Smallest separation searched, image pixels.
    pub min_separation: u32,
    /// Largest separation searched as a fraction of the width (a third).
    pub max_fraction: f32,
    /// Window half-width and half-height, in cells (a `2h + 1` square).
    pub half_window: u32,
    /// A cell matches when its best cost is at most this share of its mean cost.
    pub max_cost_ratio: f32,
    /// Pair differences the search may compute (at least one strip is always searched).
    pub work_budget: u64,
    /// Regions are squares of this many pixels a side.
    pub region_size: u32,
    /// A region reports when at least this share of its cells matched.
    pub min_region_share: f64,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            min_separation: 4,
            max_fraction: 1.0 / 3.0,
            half_window: 3,
            max_cost_ratio: 0.35,
            work_budget: WORK_BUDGET,
            region_size: 64,
            min_region_share: 0.25,
        }
    }
}

/// One region's dominant repeat.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// Left column of the region, image pixels.
    pub x: u32,
    /// Top row, image pixels.
    pub y: u32,
    /// Most frequent separation of its matched cells, image pixels.
    pub dominant: u32,
    /// 2nd percentile of its matched cells' separations, image pixels.
    pub low: u32,
    /// 98th percentile (harmonics left out), image pixels.
    pub high: u32,
    /// Share of its cells that matched, percent.
    pub matched_percent: u32,
}

/// What the search found.
#[derive(Clone, Debug, PartialEq)]
pub struct Search {
    /// Separations searched, image pixels (inclusive).
    pub searched: (u32, u32),
    /// Strips of rows searched, and how many the image holds.
    pub strips: (u32, u32),
    /// Share of the cells (where a window fits) that matched some separation.
    pub matched_share: f64,
    /// Regions with enough matched cells, row by row.
    pub regions: Vec<Region>,
    /// The separations found (smallest 2nd to largest 98th percentile over the regions),
    /// image pixels; `None` when no region repeats consistently.
    pub found: Option<(u32, u32)>,
}

/// Searches `pixels` (row-major RGBA, `width × height`) for its separations.
///
/// # Errors
/// `Invalid` for a size that does not match or an image too narrow to hold two repeats of the
/// smallest separation.
pub fn search(pixels: &[[u8; 4]], width: u32, height: u32, opts: &SearchOptions) -> Result<Search> {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || pixels.len() != w * h {
        return Err(Error::invalid(
            "decode image",
            format!("{} pixels", pixels.len()),
            format!("must be a non-empty {width}×{height} image"),
        ));
    }
    let hw = opts.half_window as usize;
    let s_hi = (width as f32 * opts.max_fraction) as usize;
    let s_lo = opts.min_separation.max(1) as usize;
    if s_hi < s_lo || w <= s_hi + 2 * hw + 1 {
        return Err(Error::invalid(
            "decode image",
            format!("{width}x{height}"),
            format!(
                "too narrow to search separations of {} px and more: an autostereogram needs room for three repeats",
                opts.min_separation
            ),
        ));
    }
    // Strips one window high, spread evenly; as many as the budget allows.
    let strip_h = (2 * hw + 1).min(h);
    let all = (h / strip_h).max(1);
    let per_strip = 2 * (strip_h * w * (s_hi - s_lo + 1)) as u64;
    let n = ((opts.work_budget / per_strip.max(1)) as usize).clamp(1, all);
    let tops: Vec<usize> = (0..n)
        .map(|i| {
            if n == 1 {
                (h - strip_h) / 2
            } else {
                i * (h - strip_h) / (n - 1)
            }
        })
        .collect();
    // Per strip and column: the best separation, 0 = no window fits, u32::MAX = no match.
    let best: Vec<Vec<u32>> = tops
        .par_iter()
        .map(|&top| {
            best_per_column(
                &pixels[top * w..(top + strip_h) * w],
                w,
                s_lo,
                s_hi,
                hw,
                opts,
            )
        })
        .collect();
    let tested: usize = best.iter().flatten().filter(|&&s| s != 0).count();
    let matched = best
        .iter()
        .flatten()
        .filter(|&&s| s != 0 && s != u32::MAX)
        .count();
    let rs = opts.region_size.max(1) as usize;
    let mut regions = Vec::new();
    for ry in (0..h).step_by(rs) {
        let strips: Vec<&Vec<u32>> = tops
            .iter()
            .zip(&best)
            .filter(|(top, _)| (ry..ry + rs).contains(&(*top + strip_h / 2)))
            .map(|(_, b)| b)
            .collect();
        for rx in (0..w).step_by(rs) {
            let mut seps = Vec::new();
            let mut cells = 0usize;
            for b in &strips {
                for &s in &b[rx..(rx + rs).min(w)] {
                    if s != 0 {
                        cells += 1;
                        if s != u32::MAX {
                            seps.push(s);
                        }
                    }
                }
            }
            if cells == 0 || (seps.len() as f64) < opts.min_region_share * cells as f64 {
                continue;
            }
            seps.sort_unstable();
            let matched_percent = (100 * seps.len() / cells) as u32;
            // Harmonics: what repeats at s also repeats at 2s, 3s, ... (less exactly); an
            // autostereogram's own separations span less than a factor of 2, so only those
            // within 7/4 of the region's dominant one are its own (`within_octave`).
            let dominant = mode(&seps);
            seps.retain(|&s| within_octave(s, dominant));
            let pct = |p: usize| seps[(seps.len() - 1) * p / 100];
            regions.push(Region {
                x: rx as u32,
                y: ry as u32,
                dominant,
                low: pct(LOW_PERCENT),
                high: pct(100 - LOW_PERCENT),
                matched_percent,
            });
        }
    }
    // A region whose dominant repeat is not within 7/4 of the regions' median dominant repeat
    // (a harmonic, or chance) does not widen the range.
    let mut dominants: Vec<u32> = regions.iter().map(|r| r.dominant).collect();
    dominants.sort_unstable();
    let median = dominants.get(dominants.len() / 2).copied().unwrap_or(0);
    let found = regions
        .iter()
        .filter(|r| within_octave(r.dominant, median))
        .map(|r| (r.low, r.high))
        .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)));
    Ok(Search {
        searched: (s_lo as u32, s_hi as u32),
        strips: (n as u32, all as u32),
        matched_share: matched as f64 / tested.max(1) as f64,
        regions,
        found,
    })
}

/// Pair differences the search computes at most, beyond its first strip: 2²⁸ (about a
/// second of one core).
pub const WORK_BUDGET: u64 = 1 << 28;

/// The percentile (and its mirror, `100 − LOW_PERCENT`) that bounds a region's separations:
/// a feature must cover this share of a region's matched cells to widen the range found.
const LOW_PERCENT: usize = 2;

/// Whether `s` lies within a factor of 7/4 of `reference`, either way: not a harmonic of it
/// (`2·reference`), nor it of `s`. An autostereogram's own separations span less: TIW's
/// far/near ratio `(2 − μ) / (2 − 2μ)` is 1.25 at their recommended depth of field μ = 1/3 and
/// reaches 7/4 only at μ = 0.6.
fn within_octave(s: u32, reference: u32) -> bool {
    4 * s < 7 * reference && 7 * s > 4 * reference
}

/// The most frequent value of a sorted, non-empty slice (the smallest on ties).
fn mode(sorted: &[u32]) -> u32 {
    let (mut best, mut best_n) = (sorted[0], 0usize);
    let mut i = 0;
    while i < sorted.len() {
        let j = i + sorted[i..].iter().take_while(|&&v| v == sorted[i]).count();
        if j - i > best_n {
            (best, best_n) = (sorted[i], j - i);
        }
        i = j;
    }
    best
}

/// For one strip (`rows`, a whole number of `w`-pixel rows): each column's smallest separation
/// whose cost is at most `max_cost_ratio` of the column's mean cost, `0` where no window fits
/// at any separation, `u32::MAX` where none is that cheap. The window spans the strip's rows (7, or the image's height).
fn best_per_column(
    rows: &[[u8; 4]],
    w: usize,
    s_lo: usize,
    s_hi: usize,
    hw: usize,
    opts: &SearchOptions,
) -> Vec<u32> {
    let n_rows = rows.len() / w;
    let mut sum = vec![0f32; w];
    let mut count = vec![0u32; w];
    let mut first = vec![0u32; w];
    let mut prefix = vec![0u64; w + 1];
    let mut window = vec![0u64; w];
    let area = (n_rows * (2 * hw + 1)) as f32;
    // Pass 0 sums each column's costs for its mean; pass 1 takes the smallest separation whose
    // cost is at most `max_cost_ratio` of that mean.
    for pass in 0..2 {
        for s in s_lo..=s_hi {
            // The pair (l, l + s) belongs to the column at its middle m = l + ⌊s/2⌋; the window
            // of column m holds the pairs l = m − ⌊s/2⌋ − hw ..= m − ⌊s/2⌋ + hw, all in the row.
            let half = s / 2;
            if w < s + 2 * hw + 1 {
                continue;
            }
            let (m_first, m_last) = (half + hw, w - 1 - s + half - hw);
            window[m_first..=m_last].fill(0);
            for row in rows.chunks_exact(w) {
                for l in 0..w - s {
                    let (a, b) = (row[l], row[l + s]);
                    let d: u32 = (0..3).map(|c| u32::from(a[c].abs_diff(b[c]))).sum();
                    prefix[l + 1] = prefix[l] + u64::from(d);
                }
                for (m, total) in window.iter_mut().enumerate().take(m_last + 1).skip(m_first) {
                    let l = m - half;
                    *total += prefix[l + hw + 1] - prefix[l - hw];
                }
            }
            for m in m_first..=m_last {
                let c = window[m] as f32 / area;
                if pass == 0 {
                    sum[m] += c;
                    count[m] += 1;
                } else if first[m] == 0 && c <= opts.max_cost_ratio * sum[m] / count[m] as f32 {
                    first[m] = s as u32;
                }
            }
        }
    }
    (0..w)
        .map(|i| {
            if count[i] < 2 {
                0
            } else {
                let mean = sum[i] / count[i] as f32;
                if mean > 0.0 && first[i] != 0 {
                    first[i]
                } else {
                    u32::MAX
                }
            }
        })
        .collect()
}
