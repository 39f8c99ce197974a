//! Reads a finished autostereogram back: per pixel, the separation whose two windows match
//! best along the row, then depth from the separation. This is how stereolab checks that a
//! SIRDS encodes the intended scene without anyone staring at it.

use rayon::prelude::*;

use super::disparity::Disparity;
use super::search::{Search, SearchOptions};
use crate::error::{Error, Result};

/// Decoder settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecodeOptions {
    /// Smallest separation tried, pixels (≥ 1).
    pub min_separation: u32,
    /// Largest separation tried, pixels.
    pub max_separation: u32,
    /// Window half-width: the window is `2 hw + 1` pixels wide.
    pub half_width: u32,
    /// Window half-height: `2 hh + 1` rows (clipped at the image border).
    pub half_height: u32,
    /// A pixel counts as matched when its best window cost is at most this fraction of its mean
    /// cost over all separations tried. In a SIRDS the right separation matches (nearest
    /// filtering: exactly, cost 0); in noise the best of ~90 tries of a 7×7 window rarely falls
    /// below half the mean (about 1% of black/white noise pixels match, see the noise test).
    pub max_cost_ratio: f32,
}

impl DecodeOptions {
    /// Options covering the separations `d` can produce, with 2 px of margin on either side.
    pub fn for_disparity(d: &Disparity) -> DecodeOptions {
        DecodeOptions {
            min_separation: (d.min_separation().floor() as u32).saturating_sub(2).max(1),
            max_separation: d.max_separation().ceil() as u32 + 2,
            half_width: 3,
            half_height: 3,
            max_cost_ratio: 0.35,
        }
    }
}

/// The decoder's answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Decoded {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Separation per pixel (sub-pixel by a parabola through the best three costs); `NaN` where
    /// nothing matched or no window fits.
    pub separation: Vec<f32>,
    /// Share of the pixels where some window fit the image that matched.
    pub matched_share: f64,
}

/// An image is an autostereogram when at least this share of its pixels matched: a SIRDS
/// matches almost everywhere (all but its edges and occlusion borders), noise almost nowhere.
pub const AUTOSTEREOGRAM_SHARE: f64 = 0.5;

impl Decoded {
    /// Whether the image repeats consistently enough to be an autostereogram at all.
    pub fn is_autostereogram(&self) -> bool {
        self.matched_share >= AUTOSTEREOGRAM_SHARE
    }
}

/// Rows per band: bands run in parallel, each with `half_height` rows of halo.
const BAND_ROWS: usize = 16;

/// Decodes `pixels` (row-major RGBA, `width × height`). Separations are tried in steps of
/// `1/SUBSTEPS` pixel; the cost of separation `s = n + k/q` for the pair ending at right pixel
/// `r` is the smaller of `Σ_rgb |I(r) − lerp(I(r − n), I(r − n − 1), k/q)|` (a right-going
/// copy) and `Σ_rgb |I(l) − lerp(I(l + n), I(l + n + 1), k/q)|`, `l = r − ⌈s⌉` (a left-going
/// copy) — zero for the strip algorithm's bilinear copies at their true fractional separation,
/// and for nearest or TIW copies at whole pixels — averaged over a window centered on the
/// pair's middle `x = r − s/2`.
///
/// # Errors
/// `Invalid` for a size that does not match, or an empty or inverted separation range.
pub fn decode(
    pixels: &[[u8; 4]],
    width: u32,
    height: u32,
    opts: &DecodeOptions,
) -> Result<Decoded> {
    decode_reporting(pixels, width, height, opts, &|_, _| {})
}

/// [`decode`], calling `progress(bands done, bands)` as each band of rows is finished (from
/// the worker threads, in any order): what a progress bar shows.
///
/// # Errors
/// As [`decode`].
pub fn decode_reporting(
    pixels: &[[u8; 4]],
    width: u32,
    height: u32,
    opts: &DecodeOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Decoded> {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 || pixels.len() != w * h {
        return Err(Error::invalid(
            "decode image",
            format!("{} pixels", pixels.len()),
            format!("must be a non-empty {width}×{height} image"),
        ));
    }
    let (lo, hi) = (opts.min_separation.max(1), opts.max_separation);
    if lo > hi || hi as usize >= w {
        return Err(Error::invalid(
            "decode separations",
            format!("{lo}..={hi}"),
            format!("must be a non-empty range narrower than the image ({w} px)"),
        ));
    }
    let mut separation = vec![f32::NAN; w * h];
    let (bands, done) = (
        h.div_ceil(BAND_ROWS),
        std::sync::atomic::AtomicUsize::new(0),
    );
    let tested: usize = separation
        .par_chunks_mut(w * BAND_ROWS)
        .enumerate()
        .map(|(band, out)| {
            let tested = decode_band(pixels, w, h, band * BAND_ROWS, out, lo, hi, opts);
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                bands,
            );
            tested
        })
        .sum();
    let matched = separation.iter().filter(|s| s.is_finite()).count();
    Ok(Decoded {
        width,
        height,
        separation,
        matched_share: matched as f64 / tested.max(1) as f64,
    })
}

/// Sub-pixel steps per pixel of separation the decoder tries.
pub const SUBSTEPS: u32 = 4;

#[allow(clippy::too_many_arguments)]
fn decode_band(
    pixels: &[[u8; 4]],
    w: usize,
    h: usize,
    y0: usize,
    out: &mut [f32],
    lo: u32,
    hi: u32,
    opts: &DecodeOptions,
) -> usize {
    let q = SUBSTEPS as usize;
    let rows = out.len() / w;
    let hh = opts.half_height as usize;
    let hw = opts.half_width as usize;
    let (r0, r1) = (y0.saturating_sub(hh), (y0 + rows + hh).min(h));
    let n_px = rows * w;
    let mut best = vec![f32::INFINITY; n_px];
    let mut best_step = vec![usize::MAX; n_px];
    let mut before = vec![f32::NAN; n_px];
    let mut after = vec![f32::NAN; n_px];
    let mut sum = vec![0f32; n_px];
    let mut count = vec![0u32; n_px];
    let mut prev = vec![f32::NAN; n_px];
    let mut cost = vec![f32::NAN; n_px];
    let mut row_sums = vec![0u32; (r1 - r0) * w];
    let mut prefix = vec![0u32; w + 1];
    let steps = (hi - lo) as usize * q;
    for step in 0..=steps {
        let (n, k) = (lo as usize + step / q, step % q);
        // The window of pair middle x covers right pixels r = x + half ± hw.
        let half = (2 * (n * q + k) + q) / (4 * q); // round(s / 2)
        // Windows of right pixels r = x + half ± hw, each pair reaching back to r − n − 1.
        let x_first = (n + 1 + hw).saturating_sub(half);
        cost.fill(f32::NAN);
        let Some(x_last) = (w - 1).checked_sub(hw + half).filter(|&l| l >= x_first) else {
            std::mem::swap(&mut prev, &mut cost);
            continue;
        };
        let mix = |a: [u8; 4], b: [u8; 4], c: [u8; 4]| -> u32 {
            (0..3)
                .map(|ch| {
                    let mixed = (q - k) as i32 * b[ch] as i32 + k as i32 * c[ch] as i32;
                    (q as i32 * a[ch] as i32 - mixed).unsigned_abs()
                })
                .sum()
        };
        let reach = n + (k > 0) as usize; // ⌈s⌉: the left pixel of the pair ending at r
        for (r, rs) in (r0..r1).zip(row_sums.chunks_exact_mut(w)) {
            let row = &pixels[r * w..(r + 1) * w];
            for x in 0..w {
                let diff = if x > n {
                    // Right-going copies (left start, right half): I(r) = lerp(I(r−n), I(r−n−1)).
                    let right = mix(row[x], row[x - n], row[x - n - 1]);
                    // Left-going copies (center start, left half): I(l) = lerp(I(l+n), I(l+n+1)).
                    let l = x - reach;
                    let left = mix(row[l], row[l + n], row[(l + n + 1).min(w - 1)]);
                    right.min(left)
                } else {
                    0
                };
                prefix[x + 1] = prefix[x] + diff;
            }
            for (x, sum) in rs.iter_mut().enumerate().take(x_last + 1).skip(x_first) {
                let rc = x + half;
                *sum = prefix[rc + hw + 1] - prefix[rc - hw];
            }
        }
        for y in 0..rows {
            let (ya, yb) = ((y0 + y).saturating_sub(hh), (y0 + y + hh + 1).min(h));
            let area = ((yb - ya) * (2 * hw + 1) * 3 * q) as f32;
            for x in x_first..=x_last {
                let total: u32 = (ya..yb).map(|r| row_sums[(r - r0) * w + x]).sum();
                let i = y * w + x;
                let c = total as f32 / area;
                cost[i] = c;
                sum[i] += c;
                count[i] += 1;
                if best_step[i].wrapping_add(1) == step {
                    after[i] = c;
                }
                if c < best[i] {
                    best[i] = c;
                    best_step[i] = step;
                    before[i] = prev[i];
                    after[i] = f32::NAN;
                }
            }
        }
        std::mem::swap(&mut prev, &mut cost);
    }
    let mut tested = 0;
    for i in 0..n_px {
        if count[i] < 2 {
            continue;
        }
        tested += 1;
        let mean = sum[i] / count[i] as f32;
        if !(mean > 0.0 && best[i] <= opts.max_cost_ratio * mean) {
            continue;
        }
        let (cm, c0, cp) = (before[i], best[i], after[i]);
        let denom = cm - 2.0 * c0 + cp;
        let offset = if c0 > 0.0 && denom > 0.0 {
            (0.5 * (cm - cp) / denom).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        out[i] = lo as f32 + (best_step[i] as f32 + offset) / q as f32;
    }
    tested
}

/// Share of pixels matched among those where a pair of every separation in `opts`' range
/// fits the image (`x ± (max_separation / 2 + half_width)` inside it): the region where an
/// autostereogram of a known set-up has a pair at every depth. A decoder told the set-up
/// judges the image there; [`Decoded::matched_share`] also counts pixels near the sides,
/// where only the smaller separations fit, which a SIRDS with separations wider than a third
/// of the image has many of.
pub fn matched_share_where_all_fit(decoded: &Decoded, opts: &DecodeOptions) -> f64 {
    let w = decoded.width as usize;
    let margin = (opts.max_separation as usize).div_ceil(2) + opts.half_width as usize;
    if 2 * margin >= w {
        return 0.0;
    }
    let (mut tested, mut matched) = (0usize, 0usize);
    for row in decoded.separation.chunks_exact(w) {
        for s in &row[margin..w - margin] {
            tested += 1;
            matched += s.is_finite() as usize;
        }
    }
    matched as f64 / tested.max(1) as f64
}

/// How well decoded separations agree with the intended ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoundTrip {
    /// Pixels compared (those where a window of the intended separation fits the image).
    pub compared: usize,
    /// Share of compared pixels decoded within ±1 px of the intended separation.
    pub within_one: f64,
    /// Root-mean-square error over compared pixels that matched, pixels.
    pub rms: f64,
    /// Share of compared pixels that matched at all.
    pub matched: f64,
}

/// Compares `decoded` with the intended separation per pixel (`intended[i]`, pixels).
pub fn round_trip(decoded: &Decoded, intended: &[f32], opts: &DecodeOptions) -> RoundTrip {
    let w = decoded.width as usize;
    let (mut compared, mut within, mut matched, mut sq) = (0usize, 0usize, 0usize, 0f64);
    for (i, (&got, &want)) in decoded.separation.iter().zip(intended).enumerate() {
        let x = i % w;
        let half = (want / 2.0).ceil() as usize + opts.half_width as usize;
        if x < half || x + half >= w {
            continue;
        }
        compared += 1;
        if got.is_finite() {
            matched += 1;
            let e = (got - want) as f64;
            sq += e * e;
            if e.abs() <= 1.0 {
                within += 1;
            }
        }
    }
    let share = |k: usize| k as f64 / compared.max(1) as f64;
    RoundTrip {
        compared,
        within_one: share(within),
        rms: (sq / matched.max(1) as f64).sqrt(),
        matched: share(matched),
    }
}

/// Nearness per pixel from decoded separations (`NaN` stays `NaN`).
pub fn depth_from_separation(decoded: &Decoded, d: &Disparity) -> Vec<f32> {
    decoded
        .separation
        .iter()
        .map(|&s| d.nearness_of_separation(s))
        .collect()
}

/// An autostereogram decoded without knowing its viewing set-up: the separations found by
/// [`search`](super::search::search), then [`decode`] over that range.
#[derive(Clone, Debug, PartialEq)]
pub struct AutoDecoded {
    /// What the search over the full plausible range found.
    pub search: Search,
    /// The decoder's options over the range found (`None` when nothing repeats).
    pub options: Option<DecodeOptions>,
    /// The decoded separations (`None` when nothing repeats).
    pub decoded: Option<Decoded>,
}

impl AutoDecoded {
    /// Share of pixels matched: the decoder's where it ran, else the search's.
    pub fn matched_share(&self) -> f64 {
        self.decoded
            .as_ref()
            .map_or(self.search.matched_share, |d| d.matched_share)
    }

    /// Whether the image is an autostereogram: the search found a range and the decoder
    /// matched at least [`AUTOSTEREOGRAM_SHARE`] of the pixels in it.
    pub fn is_autostereogram(&self) -> bool {
        self.decoded
            .as_ref()
            .is_some_and(Decoded::is_autostereogram)
    }
}

/// Finds the separations of `pixels` (row-major RGBA) over the full plausible range
/// ([`search`](super::search::search): a few pixels to a third of the width, bounded cost),
/// then decodes in quarter pixels over the range found, widened by 2 px on each side.
///
/// # Errors
/// As [`search`](super::search::search) and [`decode`].
pub fn decode_auto(
    pixels: &[[u8; 4]],
    width: u32,
    height: u32,
    opts: &SearchOptions,
) -> Result<AutoDecoded> {
    decode_auto_reporting(pixels, width, height, opts, &|_, _| {})
}

/// [`decode_auto`], reporting the decoding's progress as [`decode_reporting`] does (the
/// search before it has a bounded cost).
///
/// # Errors
/// As [`decode_auto`].
pub fn decode_auto_reporting(
    pixels: &[[u8; 4]],
    width: u32,
    height: u32,
    opts: &SearchOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<AutoDecoded> {
    let search = super::search::search(pixels, width, height, opts)?;
    let Some((lo, hi)) = search.found else {
        return Ok(AutoDecoded {
            search,
            options: None,
            decoded: None,
        });
    };
    let margin = 2;
    let options = DecodeOptions {
        min_separation: lo.saturating_sub(margin).max(1),
        max_separation: (hi + margin).min(width - 1),
        half_width: 3,
        half_height: 3,
        max_cost_ratio: opts.max_cost_ratio,
    };
    let decoded = decode_reporting(pixels, width, height, &options, progress)?;
    Ok(AutoDecoded {
        search,
        options: Some(options),
        decoded: Some(decoded),
    })
}

/// Nearness from separation without a viewing model: linear between the separations
/// `near` (nearness 1) and `far` (nearness 0), clamped; `NaN` stays `NaN`. For a wall-eyed
/// autostereogram `near < far` (near points repeat sooner), for a cross-eyed one `near > far`.
/// One separation only (`near == far`): a flat picture, all background (0).
pub fn nearness_linear(decoded: &Decoded, near: f32, far: f32) -> Vec<f32> {
    decoded
        .separation
        .iter()
        .map(|&s| {
            if s.is_nan() {
                s
            } else if far == near {
                0.0
            } else {
                ((far - s) / (far - near)).clamp(0.0, 1.0)
            }
        })
        .collect()
}
