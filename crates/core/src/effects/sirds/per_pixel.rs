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
    /// Links wrap around each row ([`RowLinker::link_row_cyclic`]), so the image tiles
    /// horizontally (`sirds.tileable`).
    pub tileable: bool,
    /// Depth quantised to this many planes before linking ([`plane_separation`],
    /// `sirds.planes`); `None`: continuous.
    pub planes: Option<u32>,
}

impl Default for PerPixelOptions {
    fn default() -> Self {
        PerPixelOptions {
            hidden_surface: true,
            oversample: 1,
            tileable: false,
            planes: None,
        }
    }
}

/// Largest oversampling factor accepted.
pub const MAX_OVERSAMPLE: u32 = 16;

/// Fewest and most depth planes `sirds.planes` accepts (an 8-bit depth map has 256 levels).
pub const PLANES: std::ops::RangeInclusive<u32> = 2..=255;

/// The separation of the depth plane nearest to separation `s`: `planes` planes equally spaced
/// in separation from the background's `s_far` to the front's `s_near`,
/// `s_far − round((s_far − s) / step) · step` with `step = (s_far − s_near) / (planes − 1)`.
/// Source: netpbm's pamstereogram manual (Scott Pakin), `-planes=near,far`: the separations
/// of the distinct depths are the whole pixels from near to far, "far − near + 1" of them;
/// with `planes = s_far − s_near + 1` (both whole) the planes are exactly those.
#[inline]
pub fn plane_separation(s: f32, s_near: f32, s_far: f32, planes: u32) -> f32 {
    let step = (s_far - s_near) / (planes - 1) as f32;
    s_far - ((s_far - s) / step).round() * step
}

/// Nearness `z` moved onto its depth plane ([`plane_separation`]): the nearness whose
/// separation is the plane's.
#[inline]
pub fn plane_nearness(z: f32, d: &Disparity, planes: u32) -> f32 {
    let s = plane_separation(
        d.separation(z),
        d.separation(1.0),
        d.separation(0.0),
        planes,
    );
    d.nearness_of_separation(s).clamp(0.0, 1.0)
}

/// TIW's `round(X) = (int)(X + 0.5)` for the non-negative separations.
#[inline]
fn round_half_up(v: f32) -> usize {
    // Truncation is the floor for the non-negative values we get (and saturates NaN to 0).
    (v + 0.5).max(0.0) as usize
}

/// Depth per lateral step of `scale` samples a pixel, in nearness units: `1 / (scale (t_far −
/// t_near))`.
#[inline]
fn step_scale(d: &Disparity, scale: u32) -> f32 {
    1.0 / (scale as f32 * (d.t_far - d.t_near))
}

/// What TIW needs of a point of nearness `z` on a grid of `scale` samples a pixel: its
/// separation in whole samples, and how far its rays to the eyes rise per sample
/// (`step_scale` from [`step_scale`]).
#[inline]
fn pair_params(d: &Disparity, z: f32, scale: u32, step_scale: f32) -> (usize, f32) {
    (
        round_half_up(d.separation(z) * scale as f32),
        d.ray_slope(d.depth_of(z)) * step_scale,
    )
}

/// `pair_params` of every 16-bit sample value of a depth-map file, for
/// [`RowLinker::link_row_keyed`]: one table per image instead of a division and two f64
/// depth conversions per pixel (the samples of a smooth 16-bit map differ from pixel to pixel).
pub struct SampleTable {
    /// Separation and rise of each sample value, by value.
    params: Vec<(u32, f32)>,
}

impl SampleTable {
    /// The table for samples whose nearness is `z_of(sample)`, at one sample a pixel.
    pub fn new(d: &Disparity, z_of: impl Fn(u16) -> f32 + Sync) -> SampleTable {
        let step_scale = step_scale(d, 1);
        let params = (0..=u16::MAX)
            .into_par_iter()
            .map(|v| {
                let (s, rise) = pair_params(d, z_of(v), 1, step_scale);
                (s as u32, rise)
            })
            .collect();
        SampleTable { params }
    }
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
        let step_scale = step_scale(d, scale);
        // Depth maps repeat values (flat regions, 8-bit files): reuse the last separation.
        let (mut last_z, mut params) = (f32::NAN, (0, 0.0));
        self.link_with(z, y, d, scale, hidden, |x| {
            if z[x] != last_z {
                last_z = z[x];
                params = pair_params(d, z[x], scale, step_scale);
            }
            params
        });
    }

    /// [`Self::link_row`] (scale 1) for a row of 16-bit samples `keys` whose nearness is `z`
    /// (`z[x] = table`'s `z_of(keys[x])`): each pixel's separation and ray rise are looked up
    /// in `table` instead of computed, the same numbers (`table` holds `pair_params` of every
    /// sample value), so the same links. `link_row_keyed_matches_link_row` holds them equal.
    pub fn link_row_keyed(
        &mut self,
        z: &[f32],
        keys: &[u16],
        table: &SampleTable,
        y: u32,
        d: &Disparity,
        hidden: bool,
    ) {
        assert_eq!(z.len(), keys.len(), "one key per pixel");
        self.link_with(z, y, d, 1, hidden, |x| {
            let (s, rise) = table.params[usize::from(keys[x])];
            (s as usize, rise)
        });
    }

    /// [`Self::link_row`] with the links wrapping around the row (`sirds.tileable`): the pair a
    /// point at `x` constrains is `l = (x − ⌈s/2⌉) mod n` and `(l + s) mod n` (the same split
    /// as [`left_of_pair`]), so the row is a ring and the image tiles horizontally without a
    /// seam. The sets of pixels that must share a color are kept in `parent` (union–find; each
    /// set's root is its leftmost pixel); `self.same` is not used. Hidden-surface removal walks
    /// the row without wrapping.
    pub fn link_row_cyclic(&mut self, z: &[f32], y: u32, d: &Disparity, scale: u32, hidden: bool) {
        let n = z.len();
        let step_scale = step_scale(d, scale);
        self.same.clear();
        self.same.extend(0..n as u32);
        for x in 0..n {
            let (s, rise) = pair_params(d, z[x], scale, step_scale);
            if s == 0 || s >= n || (hidden && !ray_clear(z, x, z[x], rise)) {
                continue;
            }
            let left = left_of_pair(x, s, y).rem_euclid(n as isize) as usize;
            let right = (left + s) % n;
            let (a, b) = (find(&mut self.same, left), find(&mut self.same, right));
            let (lo, hi) = (a.min(b), a.max(b));
            self.same[hi] = lo as u32;
        }
        for x in 0..n {
            let root = find(&mut self.same, x);
            self.same[x] = root as u32;
        }
    }

    /// TIW's linking of one row with `params(x)` giving pixel x's separation (whole samples)
    /// and ray rise per step.
    fn link_with(
        &mut self,
        z: &[f32],
        y: u32,
        d: &Disparity,
        scale: u32,
        hidden: bool,
        mut params: impl FnMut(usize) -> (usize, f32),
    ) {
        let n = z.len();
        self.same.clear();
        self.same.extend(0..n as u32);
        let step_scale = step_scale(d, scale);
        // Longest walk: the smallest rise per step is at the front of the range.
        let min_rise = d.ray_slope(d.t_near).min(d.ray_slope(d.t_far)) * step_scale;
        let reach = ((1.0 / min_rise).ceil() as usize + 1).min(n);
        if hidden {
            self.block_max(z, reach);
        }
        // x's block `x / reach`, kept without dividing: `block` and `x − block · reach`.
        let (mut block, mut in_block) = (0usize, 0usize);
        for x in 0..n {
            let bx = block;
            in_block += 1;
            if in_block == reach {
                (block, in_block) = (block + 1, 0);
            }
            let zx = z[x];
            let (s, rise) = params(x);
            let left = left_of_pair(x, s, y);
            let right = left + s as isize;
            if left < 0 || right >= n as isize {
                continue;
            }
            if hidden {
                // The maximum of the ≤ 3 blocks around x bounds everything the walk can meet:
                // blocks (x − reach) / reach = bx − 1 (or 0) to (x + reach) / reach = bx + 1.
                let (b0, b2) = (
                    bx.saturating_sub(1),
                    (bx + 1).min(self.window_max.len() - 1),
                );
                let around = self.window_max[b0]
                    .max(self.window_max[bx])
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

/// The root of `x`'s set in the union–find `parent`, halving the path on the way.
fn find(parent: &mut [u32], mut x: usize) -> usize {
    while parent[x] as usize != x {
        let up = parent[parent[x] as usize];
        parent[x] = up;
        x = up as usize;
    }
    x
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
    sink: impl FnMut(&[[u8; 4]]) -> Result<()> + Send,
) -> Result<()> {
    check_options(width, d, pattern, opts)?;
    let w = width as usize;
    let compute = |y0: usize, _: &[()], chunk: &mut [[u8; 4]]| {
        chunk.par_chunks_mut(w).enumerate().for_each_init(
            || (RowWork::default(), Vec::new()),
            |(work, row), (dy, row_out)| {
                let y = (y0 + dy) as u32;
                row.clear();
                depth_row(y, row);
                work.row(row, None, y, d, pattern, opts, row_out);
            },
        );
    };
    pipelined(width, height, |_: &mut [()]| Ok(()), compute, sink)
}

/// As [`check_inputs`], and an oversampling factor in 1..=[`MAX_OVERSAMPLE`].
fn check_options(
    width: u32,
    d: &Disparity,
    pattern: &Pattern,
    opts: &PerPixelOptions,
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
    Ok(())
}

/// One thread's working memory for TIW rows, reused from row to row.
#[derive(Default)]
struct RowWork {
    linker: RowLinker,
    fine: Vec<f32>,
    colors: Vec<[u8; 4]>,
    planes: Vec<f32>,
    roots: Vec<u32>,
    sums: Vec<[u32; 4]>,
}

impl RowWork {
    /// TIW on image row `y` of nearness `z` into `row_out`; with `keys` (the row's 16-bit
    /// samples and their table, one sample a pixel only) the links come from
    /// [`RowLinker::link_row_keyed`], the same as [`RowLinker::link_row`]'s.
    #[allow(clippy::too_many_arguments)]
    fn row(
        &mut self,
        z: &[f32],
        keys: Option<(&[u16], &SampleTable)>,
        y: u32,
        d: &Disparity,
        pattern: &Pattern,
        opts: &PerPixelOptions,
        row_out: &mut [[u8; 4]],
    ) {
        let o = opts.oversample;
        if opts.tileable || matches!(pattern, Pattern::Textured(_)) || opts.planes.is_some() {
            let mut planes = std::mem::take(&mut self.planes);
            let z = match opts.planes {
                Some(n) => {
                    planes.clear();
                    planes.extend(z.iter().map(|&v| plane_nearness(v, d, n)));
                    &planes[..]
                }
                None => z,
            };
            self.row_by_sets(z, y, d, pattern, opts, row_out);
            self.planes = planes;
            return;
        }
        match keys {
            Some((keys, table)) if o == 1 => {
                self.linker
                    .link_row_keyed(z, keys, table, y, d, opts.hidden_surface);
            }
            _ if o == 1 => self.linker.link_row(z, y, d, 1, opts.hidden_surface),
            _ => {
                oversample_row(z, o, &mut self.fine);
                self.linker
                    .link_row(&self.fine, y, d, o, opts.hidden_surface);
            }
        }
        if o == 1 {
            color_row(&self.linker.same, y, o, pattern, row_out);
        } else {
            self.colors.resize(self.linker.same.len(), [0; 4]);
            color_row(&self.linker.same, y, o, pattern, &mut self.colors);
            average_subpixels(&self.colors, o, row_out);
        }
    }

    /// [`Self::row`] for tileable rows, depth planes and textures: links (wrapping or not), then
    /// each set of linked samples colored as a whole ([`color_sets`]).
    fn row_by_sets(
        &mut self,
        z: &[f32],
        y: u32,
        d: &Disparity,
        pattern: &Pattern,
        opts: &PerPixelOptions,
        row_out: &mut [[u8; 4]],
    ) {
        let o = opts.oversample;
        let z = if o == 1 {
            z
        } else {
            oversample_row(z, o, &mut self.fine);
            &self.fine[..]
        };
        self.roots.clear();
        if opts.tileable {
            self.linker.link_row_cyclic(z, y, d, o, opts.hidden_surface);
            self.roots.extend_from_slice(&self.linker.same);
        } else {
            self.linker.link_row(z, y, d, o, opts.hidden_surface);
            // TIW's chains point right; a set's root is its rightmost sample.
            self.roots.resize(z.len(), 0);
            for x in (0..z.len()).rev() {
                let s = self.linker.same[x] as usize;
                self.roots[x] = if s == x { x as u32 } else { self.roots[s] };
            }
        }
        if o == 1 {
            color_sets(&self.roots, y, o, pattern, &mut self.sums, row_out);
        } else {
            self.colors.resize(z.len(), [0; 4]);
            color_sets(&self.roots, y, o, pattern, &mut self.sums, &mut self.colors);
            average_subpixels(&self.colors, o, row_out);
        }
    }
}

/// Colors each set of linked samples (`roots[x]`: the root sample of x's set) as one: the
/// pattern at the root, or for a mapped texture the rounded mean of the set's texels that are
/// not the background color ([`Textured`](super::pattern::Textured)), the base pattern at the
/// root where all are background.
fn color_sets(
    roots: &[u32],
    y: u32,
    o: u32,
    pattern: &Pattern,
    sums: &mut Vec<[u32; 4]>,
    colors: &mut [[u8; 4]],
) {
    assert_eq!(colors.len(), roots.len(), "one color per sample");
    let Pattern::Textured(t) = pattern else {
        for (c, &r) in colors.iter_mut().zip(roots) {
            *c = pattern.color(r / o, y);
        }
        return;
    };
    sums.clear();
    sums.resize(roots.len(), [0; 4]);
    for (x, &r) in roots.iter().enumerate() {
        let texel = t.texel(x as u32 / o, y);
        if texel != t.background {
            let sum = &mut sums[r as usize];
            for c in 0..3 {
                sum[c] += u32::from(texel[c]);
            }
            sum[3] += 1;
        }
    }
    for (c, &r) in colors.iter_mut().zip(roots) {
        let [red, green, blue, n] = sums[r as usize];
        *c = if n == 0 {
            t.base.color(r / o, y)
        } else {
            let mean = |v: u32| ((v + n / 2) / n) as u8;
            [mean(red), mean(green), mean(blue), 255]
        };
    }
}

/// Images of at least this many pixels look separations up in a [`SampleTable`] (65 536
/// entries) in [`per_pixel_samples`]; smaller ones compute them.
const TABLE_FROM_PIXELS: u64 = 1 << 20;

/// TIW streamed from 16-bit samples (a depth-map file) to `sink`: `read(buf)` fills `buf` with
/// the next whole rows' samples, in order, and runs while the chunk before is computed, so the
/// map is never held whole; `z_of(sample)` is a sample's nearness. With one sample a pixel and
/// a large image, each pixel's separation and ray rise come from a [`SampleTable`]: the same
/// numbers as computing them, so the same bytes as [`per_pixel_streamed`] on the same nearness
/// (`per_pixel_samples_matches_per_pixel`). The bytes do not depend on the thread count.
///
/// # Errors
/// As [`per_pixel_streamed`], or whatever `read` returns.
#[allow(clippy::too_many_arguments)]
pub fn per_pixel_samples(
    width: u32,
    height: u32,
    read: impl FnMut(&mut [u16]) -> Result<()> + Send,
    z_of: impl Fn(u16) -> f32 + Sync,
    d: &Disparity,
    pattern: &Pattern,
    opts: &PerPixelOptions,
    sink: impl FnMut(&[[u8; 4]]) -> Result<()> + Send,
) -> Result<()> {
    check_options(width, d, pattern, opts)?;
    let w = width as usize;
    let big = u64::from(width) * u64::from(height) >= TABLE_FROM_PIXELS;
    let table = (big && opts.oversample == 1).then(|| SampleTable::new(d, &z_of));
    let compute = |y0: usize, input: &[u16], chunk: &mut [[u8; 4]]| {
        chunk
            .par_chunks_mut(w)
            .zip(input.par_chunks(w))
            .enumerate()
            .for_each_init(
                || (RowWork::default(), Vec::new()),
                |(work, row), (dy, (row_out, keys))| {
                    row.clear();
                    row.extend(keys.iter().map(|&v| z_of(v)));
                    let keys = table.as_ref().map(|t| (keys, t));
                    work.row(row, keys, (y0 + dy) as u32, d, pattern, opts, row_out);
                },
            );
    };
    pipelined(width, height, read, compute, sink)
}

/// Rows in chunks of `CHUNK_ROWS`, double-buffered both ways: chunk i is computed from its
/// input while chunk i − 1 goes to `sink` and chunk i + 1's input is `read` (`I = ()`: there
/// is nothing to read).
fn pipelined<I: Copy + Default + Send + Sync>(
    width: u32,
    height: u32,
    mut read: impl FnMut(&mut [I]) -> Result<()> + Send,
    compute: impl Fn(usize, &[I], &mut [[u8; 4]]) + Sync,
    mut sink: impl FnMut(&[[u8; 4]]) -> Result<()> + Send,
) -> Result<()> {
    let w = width as usize;
    let chunk_rows = |y0: usize| CHUNK_ROWS.min((height as usize).saturating_sub(y0));
    let (mut input, mut input_next) = (
        vec![I::default(); w * CHUNK_ROWS],
        vec![I::default(); w * CHUNK_ROWS],
    );
    let (mut next, mut done) = (
        vec![[0u8; 4]; w * CHUNK_ROWS],
        vec![[0u8; 4]; w * CHUNK_ROWS],
    );
    read(&mut input[..chunk_rows(0) * w])?;
    let mut done_rows = 0;
    for y0 in (0..height as usize).step_by(CHUNK_ROWS) {
        let (rows, after) = (chunk_rows(y0), chunk_rows(y0 + CHUNK_ROWS));
        let (_, io) = rayon::join(
            || compute(y0, &input[..rows * w], &mut next[..rows * w]),
            || -> Result<()> {
                if done_rows > 0 {
                    sink(&done[..done_rows * w])?;
                }
                if after > 0 {
                    read(&mut input_next[..after * w])?;
                }
                Ok(())
            },
        );
        io?;
        std::mem::swap(&mut next, &mut done);
        std::mem::swap(&mut input, &mut input_next);
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
fn color_row(same: &[u32], y: u32, o: u32, pattern: &Pattern, colors: &mut [[u8; 4]]) {
    assert_eq!(colors.len(), same.len(), "one color per sample");
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::sirds::{DisparityModel, Geometry};

    /// Rows of 16-bit samples with smooth runs, flat runs and steps, from a fixed LCG.
    fn sample_rows(width: usize, height: usize) -> Vec<u16> {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as u32
        };
        let mut v = Vec::with_capacity(width * height);
        for _ in 0..height {
            let mut level = next() % 65536;
            for _ in 0..width {
                level = match next() % 64 {
                    0 => next() % 65536,                            // a step
                    1..=20 => level,                                // flat
                    _ => (level + next() % 200).saturating_sub(99), // smooth
                }
                .min(65535);
                v.push(level as u16);
            }
        }
        v
    }

    fn disparities() -> Vec<Disparity> {
        let view_angle = Geometry {
            model: DisparityModel::ViewAngle,
            ..Geometry::default()
        };
        let deep = Geometry {
            depth_near_in: 2.0,
            depth_far_in: 30.0,
            dpi: 40.0,
            ..Geometry::default()
        };
        [Geometry::default(), view_angle, deep]
            .iter()
            .map(|g| g.to_pixels().expect("valid set-up"))
            .collect()
    }

    /// The table's separations and rises are the computed ones: the same links for 8- and
    /// 16-bit-like rows, nearness straight and inverted, with and without hidden-surface
    /// removal, on even and odd rows (the odd-separation split), under both models.
    #[test]
    fn link_row_keyed_matches_link_row() {
        let width = 900;
        let rows = sample_rows(width, 6);
        for d in disparities() {
            for invert in [false, true] {
                let z_of = |v: u16| {
                    let z = v as f32 / 65535.0;
                    if invert { 1.0 - z } else { z }
                };
                let table = SampleTable::new(&d, z_of);
                for (y, keys) in rows.chunks_exact(width).enumerate() {
                    let z: Vec<f32> = keys.iter().map(|&v| z_of(v)).collect();
                    for hidden in [false, true] {
                        let (mut a, mut b) = (RowLinker::default(), RowLinker::default());
                        a.link_row(&z, y as u32, &d, 1, hidden);
                        b.link_row_keyed(&z, keys, &table, y as u32, &d, hidden);
                        let linked = a.same.iter().enumerate().filter(|&(x, &s)| s as usize != x);
                        // Rough rows: hidden-surface removal leaves many points unlinked, not all.
                        assert!(
                            linked.count() > width / 8,
                            "row {y}, hidden {hidden}: too few links to compare"
                        );
                        assert_eq!(
                            a.same, b.same,
                            "row {y}, hidden {hidden}, invert {invert}, {d:?}"
                        );
                    }
                }
            }
        }
    }

    /// TIW streamed from samples gives [`per_pixel`]'s bytes on the same nearness: a small
    /// map (computed separations, a last chunk of 7 rows) and one of 2^20 pixels (the table),
    /// hidden-surface removal on and off, with oversampling (no table), tileable rows with
    /// depth planes or oversampling (the linked sets' coloring), and reads of
    /// arbitrary sizes come in whole rows, in order.
    #[test]
    fn per_pixel_samples_matches_per_pixel() {
        let d = Geometry::default().to_pixels().expect("valid set-up");
        let pattern = Pattern::Gray { seed: 3 };
        for (width, height) in [(400, 2 * CHUNK_ROWS + 7), (1024, 1024)] {
            let samples = sample_rows(width, height);
            let z_of = |v: u16| v as f32 / 65535.0;
            let map = DepthMap {
                width: width as u32,
                height: height as u32,
                z: samples.iter().map(|&v| z_of(v)).collect(),
            };
            for opts in [
                PerPixelOptions::default(),
                PerPixelOptions {
                    hidden_surface: false,
                    oversample: 1,
                    ..PerPixelOptions::default()
                },
                PerPixelOptions {
                    hidden_surface: true,
                    oversample: 3,
                    ..PerPixelOptions::default()
                },
                PerPixelOptions {
                    tileable: true,
                    planes: Some(7),
                    ..PerPixelOptions::default()
                },
                PerPixelOptions {
                    oversample: 2,
                    tileable: true,
                    ..PerPixelOptions::default()
                },
            ] {
                let want = per_pixel(&map, &d, &pattern, &opts).expect("tiw");
                let (mut got, mut taken) = (Vec::new(), 0);
                per_pixel_samples(
                    width as u32,
                    height as u32,
                    |buf| {
                        assert_eq!(buf.len() % width, 0, "whole rows");
                        buf.copy_from_slice(&samples[taken..taken + buf.len()]);
                        taken += buf.len();
                        Ok(())
                    },
                    z_of,
                    &d,
                    &pattern,
                    &opts,
                    |rows| {
                        got.extend_from_slice(rows);
                        Ok(())
                    },
                )
                .expect("streamed tiw");
                assert_eq!(taken, samples.len(), "every sample read once");
                assert!(got == want, "{width}x{height} {opts:?}: bytes differ");
            }
        }
    }
}
