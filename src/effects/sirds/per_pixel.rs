//! The classic per-pixel algorithm of Thimbleby, Inglis and Witten (IEEE Computer 27(10),
//! 1994; the SIRDS paper's reference 5) on any depth map: per scan line, link the pixel pairs each
//! visible point constrains (`same[]`), then color right to left.

use rayon::prelude::*;

use super::depthmap::DepthMap;
use super::disparity::Disparity;
use super::pattern::Pattern;
use crate::error::{Error, Result};

/// Options of the per-pixel algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PerPixelOptions {
    /// TIW's hidden-surface removal: leave a pair unlinked when something nearer blocks the
    /// ray from the point to either eye.
    pub hidden_surface: bool,
    /// Horizontal oversampling factor (1 = off): links are made on a grid this many times
    /// finer, and each output pixel averages its sub-pixels, so depth steps become sub-pixel.
    pub oversample: u32,
}

impl Default for PerPixelOptions {
    fn default() -> Self {
        PerPixelOptions {
            hidden_surface: true,
            oversample: 1,
        }
    }
}

/// Largest oversampling factor accepted.
pub const MAX_OVERSAMPLE: u32 = 16;

/// TIW's `round(X) = (int)(X + 0.5)` for the non-negative separations.
#[inline]
fn round_half_up(v: f32) -> usize {
    // Truncation is the floor for the non-negative values we get (and saturates NaN to 0).
    (v + 0.5).max(0.0) as usize
}

/// The left pixel of the pair that a point at `x` with separation `s` links. TIW: "left =
/// x − s/2"; for odd `s` the extra pixel goes left on odd rows and right on even rows, so the
/// half-pixel bias cancels between rows (the symmetric assignment).
#[inline]
pub fn left_of_pair(x: usize, s: usize, y: u32) -> isize {
    x as isize - ((s + (s & y as usize & 1)) / 2) as isize
}

/// Per-row working memory, reused across rows.
#[derive(Default)]
pub struct RowLinker {
    /// `same[x]`: `x` itself (free) or a pixel to the right that must have the same color.
    pub same: Vec<u32>,
    window_max: Vec<f32>,
}

impl RowLinker {
    /// Fills `self.same` for one (possibly oversampled) row of nearness `z`, `scale` samples per
    /// output pixel, image row `y`.
    ///
    /// Hidden-surface removal (TIW): the rays from the point to the eyes rise towards the viewer
    /// by `tan φ` depth per lateral pixel (eq. 2 under eq. 3, the constant angle under eq. 1), so
    /// at lateral offset `t` a ray is at nearness `zt = z + t · tan φ / (scale (t_far − t_near))`;
    /// the point is hidden when `Z[x − t] ≥ zt` or `Z[x + t] ≥ zt` before `zt` leaves the depth
    /// range. Block maxima over the longest such walk skip the walk where nothing around can
    /// block (the result is the same).
    pub fn link_row(&mut self, z: &[f32], y: u32, d: &Disparity, scale: u32, hidden: bool) {
        let n = z.len();
        self.same.clear();
        self.same.extend(0..n as u32);
        let depth_span = d.t_far - d.t_near;
        let step_scale = 1.0 / (scale as f32 * depth_span);
        // Longest walk: the smallest rise per step is at the front of the range.
        let min_rise = d.ray_slope(d.t_near).min(d.ray_slope(d.t_far)) * step_scale;
        let reach = ((1.0 / min_rise).ceil() as usize + 1).min(n);
        if hidden {
            self.block_max(z, reach);
        }
        // Depth maps repeat values (flat regions, 8-bit files): reuse the last separation.
        let (mut last_z, mut s, mut rise) = (f32::NAN, 0, 0.0);
        for x in 0..n {
            let zx = z[x];
            if zx != last_z {
                last_z = zx;
                s = round_half_up(d.separation(zx) * scale as f32);
                rise = d.ray_slope(d.depth_of(zx)) * step_scale;
            }
            let left = left_of_pair(x, s, y);
            let right = left + s as isize;
            if left < 0 || right >= n as isize {
                continue;
            }
            if hidden {
                // The maximum of the ≤ 3 blocks around x bounds everything the walk can meet.
                let (b0, b2) = (
                    x.saturating_sub(reach) / reach,
                    ((x + reach) / reach).min(self.window_max.len() - 1),
                );
                let around = self.window_max[b0]
                    .max(self.window_max[x / reach])
                    .max(self.window_max[b2]);
                if around >= zx + rise && !ray_clear(z, x, zx, rise) {
                    continue;
                }
            }
            let (mut l, mut r) = (left as usize, right as usize);
            let mut k = self.same[l] as usize;
            while k != l && k != r {
                if k < r {
                    l = k;
                } else {
                    l = r;
                    r = k;
                }
                k = self.same[l] as usize;
            }
            self.same[l] = r as u32;
        }
    }

    /// `window_max[b] = max z[b r .. (b + 1) r]`: block maxima, so that the three blocks
    /// around x cover the whole walk `x − r ..= x + r`.
    fn block_max(&mut self, z: &[f32], r: usize) {
        self.window_max.clear();
        self.window_max
            .extend(z.chunks(r).map(|c| c.iter().copied().fold(0.0, f32::max)));
    }
}

/// TIW's visibility walk: `true` when neither ray from the point at `x` (nearness `zx`) is
/// blocked before it leaves the depth range.
fn ray_clear(z: &[f32], x: usize, zx: f32, rise: f32) -> bool {
    let mut t = 1;
    loop {
        let zt = zx + t as f32 * rise;
        let blocked = |i: Option<usize>| i.and_then(|i| z.get(i)).is_some_and(|&v| v >= zt);
        if blocked(x.checked_sub(t)) || blocked(Some(x + t)) {
            return false;
        }
        if zt >= 1.0 {
            return true;
        }
        t += 1;
    }
}

/// Validates the inputs shared by every SIRDS algorithm.
///
/// # Errors
/// Separations that do not fit `width`, a pattern narrower than the largest separation.
pub fn check_inputs(width: u32, d: &Disparity, pattern: &Pattern) -> Result<()> {
    d.check_width(width)?;
    pattern.check(d.max_separation())
}

/// Makes a SIRDS of `depth` with TIW's algorithm: rows in parallel, each independent, so the
/// bytes do not depend on the thread count.
///
/// # Errors
/// As [`check_inputs`], or an oversampling factor outside 1..=[`MAX_OVERSAMPLE`].
pub fn per_pixel(
    depth: &DepthMap,
    d: &Disparity,
    pattern: &Pattern,
    opts: &PerPixelOptions,
) -> Result<Vec<[u8; 4]>> {
    let mut out = Vec::with_capacity(depth.z.len());
    per_pixel_streamed(
        depth.width,
        depth.height,
        |y, row| row.extend_from_slice(depth.row(y)),
        d,
        pattern,
        opts,
        |rows| {
            out.extend_from_slice(rows);
            Ok(())
        },
    )?;
    Ok(out)
}

/// Rows per chunk of [`per_pixel_streamed`]: enough to keep both cores busy, small enough that
/// a 4096-wide image needs only a megabyte of buffers.
const CHUNK_ROWS: usize = 64;

/// TIW without holding the whole image: `depth_row(y, buf)` appends row y's nearness to `buf`,
/// and `sink` receives the finished rows in order, `CHUNK_ROWS` at a time, while the next
/// chunk is computed. Rows of a chunk run in parallel; the bytes do not depend on the thread
/// count.
///
/// # Errors
/// As [`per_pixel`], or whatever `sink` returns.
#[allow(clippy::too_many_arguments)]
pub fn per_pixel_streamed(
    width: u32,
    height: u32,
    depth_row: impl Fn(u32, &mut Vec<f32>) + Sync,
    d: &Disparity,
    pattern: &Pattern,
    opts: &PerPixelOptions,
    mut sink: impl FnMut(&[[u8; 4]]) -> Result<()> + Send,
) -> Result<()> {
    check_inputs(width, d, pattern)?;
    let o = opts.oversample;
    if !(1..=MAX_OVERSAMPLE).contains(&o) {
        return Err(Error::invalid(
            "sirds.oversample",
            o,
            format!("must lie in 1..={MAX_OVERSAMPLE}"),
        ));
    }
    let w = width as usize;
    let compute = |y0: usize, chunk: &mut [[u8; 4]]| {
        chunk.par_chunks_mut(w).enumerate().for_each_init(
            || (RowLinker::default(), Vec::new(), Vec::new(), Vec::new()),
            |(linker, row, fine, colors), (dy, row_out)| {
                let y = (y0 + dy) as u32;
                row.clear();
                depth_row(y, row);
                let z: &[f32] = if o == 1 {
                    row
                } else {
                    oversample_row(row, o, fine);
                    fine
                };
                linker.link_row(z, y, d, o, opts.hidden_surface);
                color_row(&linker.same, y, o, pattern, colors);
                if o == 1 {
                    row_out.copy_from_slice(colors);
                } else {
                    average_subpixels(colors, o, row_out);
                }
            },
        );
    };
    // Double-buffered: the sink writes chunk i − 1 while chunk i is computed.
    let (mut next, mut done) = (
        vec![[0u8; 4]; w * CHUNK_ROWS],
        vec![[0u8; 4]; w * CHUNK_ROWS],
    );
    let mut done_rows = 0;
    for y0 in (0..height as usize).step_by(CHUNK_ROWS) {
        let rows = CHUNK_ROWS.min(height as usize - y0);
        let (_, written) = rayon::join(
            || compute(y0, &mut next[..rows * w]),
            || match done_rows {
                0 => Ok(()),
                n => sink(&done[..n * w]),
            },
        );
        written?;
        std::mem::swap(&mut next, &mut done);
        done_rows = rows;
    }
    if done_rows > 0 {
        sink(&done[..done_rows * w])?;
    }
    Ok(())
}

/// Samples a row `o` times per pixel, linearly between pixel centers (clamped at the ends).
fn oversample_row(row: &[f32], o: u32, fine: &mut Vec<f32>) {
    fine.clear();
    let last = row.len() - 1;
    for i in 0..row.len() * o as usize {
        let p = ((i as f32 + 0.5) / o as f32 - 0.5).max(0.0);
        let i0 = (p as usize).min(last);
        let i1 = (i0 + 1).min(last);
        let f = p - i0 as f32;
        fine.push(row[i0] * (1.0 - f) + row[i1] * f);
    }
}

/// TIW's coloring, right to left: a free pixel takes the pattern, a linked one its partner's.
fn color_row(same: &[u32], y: u32, o: u32, pattern: &Pattern, colors: &mut Vec<[u8; 4]>) {
    colors.clear();
    colors.resize(same.len(), [0; 4]);
    for x in (0..same.len()).rev() {
        let s = same[x] as usize;
        colors[x] = if s == x {
            pattern.color(x as u32 / o, y)
        } else {
            colors[s]
        };
    }
}

/// Each output pixel: the mean of its `o` sub-pixels, rounded.
fn average_subpixels(colors: &[[u8; 4]], o: u32, row_out: &mut [[u8; 4]]) {
    let o = o as usize;
    for (px, sub) in row_out.iter_mut().zip(colors.chunks_exact(o)) {
        for c in 0..4 {
            let sum: usize = sub.iter().map(|p| p[c] as usize).sum();
            px[c] = ((sum + o / 2) / o) as u8;
        }
    }
}
