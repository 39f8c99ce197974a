//! The SIRDS paper's per-vertex strip algorithm (Petz, Goldlücke, Magnor §3–4) on stereolab's own
//! rasterizer: starting from the pattern, each iteration renders the scene with every vertex
//! shifted right by `d(v)/2` and textured from the current image `d(v)/2` to the left of the
//! vertex (Fig. 4's vertex program), the z-buffer resolving visibility.
//!
//! Each iteration finishes one vertical strip: a pixel `x` copies the pixel `x − d`, and
//! `d ≥ δ` (the front separation), so a strip narrower than `δ` reads only finished strips and
//! never changes again (§3). Rendering each iteration's strip only (a scissor on its columns)
//! therefore gives the image of rendering the whole frame k times.
//!
//! How the CPU does it, for about the cost of one frame (the GPU mirror in `gpu::sirds` renders
//! the strips as the paper does):
//! 1. Every right-going pass draws the same shifted geometry (every left-going one the other),
//!    so triangle setup runs once per direction.
//! 2. Which fragment wins a pixel, and where it samples, depend on the geometry alone, never on
//!    the image sampled: one rasterization per band of rows finds each pixel's source
//!    coordinate (deferred texturing, `band_sources`).
//! 3. The strips then only read, in order (`resolve_strip`): each pixel takes the color at
//!    its source, as the earlier strips left the image.
//!
//! Steps 2 and 3 run eight pixels at a time on AVX2 (`strips/avx2.rs`) where the AVX2 loops
//! run ([`uses_avx2`](crate::uses_avx2)), with the scalar loops' bytes; step 3 there passes
//! over each row once for all its strips (`resolve_sweep`: every pixel a strip reads lies
//! behind the sweep, so the strips' order is kept). [`per_vertex_reference`] (and
//! `STEREOLAB_SCALAR=1`, see [`uses_avx2`](crate::uses_avx2)) runs the scalar ones, strip by
//! strip.

#[cfg(target_arch = "x86_64")]
mod avx2;
mod geometry;
pub mod reference;

use geometry::shift;
pub use geometry::{StripGeometry, StripObject};

use std::mem::MaybeUninit;

use glam::Vec4;
use rayon::prelude::*;

use crate::effects::sirds::per_pixel::check_inputs;
use crate::error::{Error, Result};
use crate::raster::{RasterOptions, SetupTriangle, bin_rows, setup_triangles};
use crate::shade::{Fragment, Shader, Varyings};
use crate::simd::{Kernels, kernels};
use crate::{Disparity, PerVertexOptions, SirdsPattern, StripFilter, StripStart};

/// What a strip run produced.
#[derive(Clone, Debug, PartialEq)]
pub struct StripResult {
    /// The autostereogram, row-major RGBA.
    pub pixels: Vec<[u8; 4]>,
    /// Iterations k (strips rendered).
    pub iterations: u32,
    /// Strip width in pixels.
    pub strip_width: u32,
    /// With `record_links`: per pixel, the source pixel it copied (bilinear: the left one of
    /// the two it mixed), −1 where it kept the pattern.
    pub links: Option<Vec<i32>>,
}

/// One iteration: a strip `[x0, x0 + width)` and the direction it copies from.
#[derive(Clone, Copy, Debug)]
pub struct Strip {
    /// The strip's first column.
    pub x0: u32,
    /// The strip's width in pixels.
    pub width: u32,
    /// +1: copies from `x − d` (right-going), −1: from `x + d` (left-going).
    pub toward: f32,
    /// Sources allowed in `[lo, hi)`; outside, the pixel keeps the pattern.
    pub lo: i64,
    /// The end of the allowed sources (exclusive).
    pub hi: i64,
}

impl Strip {
    /// Whether pixel `i` is not final while this strip runs: in this strip or one still to come
    /// (right-going strips run left to right from the start column, then left-going ones right
    /// to left).
    #[inline]
    pub(crate) fn unfinished(&self, i: usize) -> bool {
        if self.toward > 0.0 {
            i >= self.x0 as usize
        } else {
            i < (self.x0 + self.width) as usize
        }
    }
}

/// The strip width and strips for `width` pixels.
///
/// # Errors
/// `Invalid` naming `sirds.iterations` when k strips would be wider than `⌊δ⌋ − 1` (a strip
/// would read itself), or k is 0.
pub fn plan_strips(width: u32, d: &Disparity, opts: &PerVertexOptions) -> Result<Vec<Strip>> {
    let widest = (d.min_separation().floor() as u32).saturating_sub(1).max(1);
    let strip = match opts.iterations {
        None => widest,
        Some(0) => {
            return Err(Error::invalid("sirds.iterations", 0, "must be at least 1"));
        }
        Some(k) => {
            let s = width.div_ceil(k);
            if s > widest {
                return Err(Error::invalid(
                    "sirds.iterations",
                    k,
                    format!(
                        "gives {s} px strips, wider than the front separation allows ({widest} px): use k ≥ {}",
                        width.div_ceil(widest)
                    ),
                ));
            }
            s
        }
    };
    let (w, mut strips) = (width as i64, Vec::new());
    let center = match opts.start {
        StripStart::Left => 0,
        StripStart::Center => width / 2,
    };
    let mut x = center;
    while x < width {
        let sw = strip.min(width - x);
        strips.push(Strip {
            x0: x,
            width: sw,
            toward: 1.0,
            lo: center as i64,
            hi: w,
        });
        x += sw;
    }
    let mut x = center;
    while x > 0 {
        let sw = strip.min(x);
        strips.push(Strip {
            x0: x - sw,
            width: sw,
            toward: -1.0,
            lo: 0,
            hi: w,
        });
        x -= sw;
    }
    Ok(strips)
}

/// Fig. 4's texture coordinate for a fragment at column `x` with separation `sep`: `x ∓ sep`,
/// in pixel-index units (centers at integers).
#[inline]
fn source_coordinate(x: u32, sep: f32, toward: f32) -> f32 {
    x as i32 as f32 - toward * sep
}

/// Whether a fragment sampling at `p` stays inside `[lo, hi)`: nearest reads pixel `⌊p + ½⌋`,
/// bilinear pixels `⌊p⌋` and, when `p` is not whole, `⌊p⌋ + 1`. Outside (or NaN), the fragment
/// is discarded and the pixel keeps what was there. Plain float comparisons (`lo`, `hi` whole),
/// so a span of them vectorizes.
#[inline]
fn in_bounds(p: f32, lo: f32, hi: f32, bilinear: bool) -> bool {
    if bilinear {
        (p >= lo) & (p <= hi - 1.0)
    } else {
        let q = p + 0.5;
        (q >= lo) & (q < hi)
    }
}

/// The pixels a fragment at `p` (inside the bounds) reads, `i0` and `i1`, and the weight `t` of
/// `i1` (nearest: `i0 == i1`, `t = 0`).
#[inline]
fn address(p: f32, bilinear: bool) -> (usize, usize, f32) {
    if bilinear {
        let i0 = floor(p);
        let t = p - i0 as f32;
        let i1 = if t > 0.0 { i0 + 1 } else { i0 };
        (i0 as usize, i1 as usize, t)
    } else {
        let i = floor(p + 0.5) as usize;
        (i, i, 0.0)
    }
}

/// The color a fragment writes from the pixels `a` and `b` it reads: `a` for a whole-pixel
/// source (`t = 0`), else the two mixed linearly and rounded to the nearest level (alpha
/// opaque).
#[inline]
fn mix(a: [u8; 4], b: [u8; 4], t: f32) -> [u8; 4] {
    if t == 0.0 {
        return a;
    }
    let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * t + 0.5) as u8;
    [mix(0), mix(1), mix(2), 255]
}

/// `⌊v⌋` without a libm call (the default x86-64 target has no SSE4.1 `roundss`).
#[inline]
fn floor(v: f32) -> i64 {
    let i = v as i64;
    i - ((i as f32) > v) as i64
}

/// Fig. 4's vertex program: the shifted position and the vertex's separation as the varying.
struct StripVertices<'a> {
    clip: &'a [Vec4],
    separation: &'a [f32],
}

impl Shader for StripVertices<'_> {
    fn varying_count(&self) -> usize {
        1
    }

    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        out[0] = self.separation[index as usize];
        self.clip[index as usize]
    }

    /// Never called: this shader only feeds [`setup_triangles`].
    fn fragment(&self, _: &Fragment) -> Option<[u8; 4]> {
        None
    }
}

/// Rows per band: bands run in parallel. Fixed, so the bytes never depend on the thread count.
pub(crate) const BAND_ROWS: u32 = 32;

/// What a span of fragments needs besides its triangle: the direction (+1: copies from
/// `x − d`, −1: from `x + d`), the allowed sources `[lo, hi)`, and the filter and
/// interpolation.
pub(super) struct SpanTarget {
    toward: f32,
    lo: f32,
    hi: f32,
    bilinear: bool,
    perspective_correct: bool,
}

/// One direction's part of a band: columns `[x0, x1)`, drawn with `setups` (already filtered
/// to the band's rows).
struct Region<'a> {
    x0: u32,
    x1: u32,
    target: SpanTarget,
    setups: &'a [&'a SetupTriangle],
}

/// Fig. 4's vertex and fragment programs up to the texture read, for one band: per pixel, the
/// source coordinate of the fragment that wins the depth test (NaN: no fragment, the pixel
/// keeps the pattern). A discarded fragment writes no depth, as on a GPU.
///
/// Which fragment wins a pixel and where it samples depend on the geometry alone, never on the
/// image it samples, so they are found once per band (deferred texturing) rather than once per
/// strip; the strips then only read ([`resolve_row`]).
fn band_sources(regions: &[Region], width: u32, y0: u32, rows: u32, kernels: Kernels) -> Vec<f32> {
    let simd = kernels.avx2();
    let w = width as usize;
    let mut sources = vec![f32::NAN; w * rows as usize];
    let mut depth = vec![1.0f32; w * rows as usize];
    for r in regions {
        for t in r.setups {
            #[cfg(target_arch = "x86_64")]
            if simd {
                let band = (width, y0, rows);
                // SAFETY: `simd` is only set where `Kernels::avx2` found AVX2.
                unsafe { avx2::triangle_sources(t, r, band, &mut depth, &mut sources) };
                continue;
            }
            let _ = simd;
            t.spans(r.x0, y0, r.x1 - r.x0, rows, |py, x_lo, x_hi| {
                let i = (py - y0) as usize * w + x_lo as usize;
                let n = (x_hi - x_lo) as usize + 1;
                let (d, p) = (&mut depth[i..i + n], &mut sources[i..i + n]);
                span_sources(t, py, x_lo, d, p, &r.target);
            });
        }
    }
    sources
}

/// One covered span of triangle `t` in row `y`, pixels `x_lo ..` (as many as `depth` holds):
/// the fragment stage of [`traverse`](crate::traverse) (same expressions, same order)
/// up to the source coordinate; a fragment wins when it passes the depth test LESS and its
/// source is in bounds.
fn span_sources(
    t: &SetupTriangle,
    y: u32,
    x_lo: u32,
    depth: &mut [f32],
    sources: &mut [f32],
    target: &SpanTarget,
) {
    let fy = t.fy(y);
    for (k, (d, p)) in depth.iter_mut().zip(sources).enumerate() {
        let x = x_lo + k as u32;
        let fx = t.fx(x);
        let z = t.depth_at(x, y);
        let sep = t.varying_at(0, fx, fy, target.perspective_correct);
        let src = source_coordinate(x, sep, target.toward);
        // Branch-free, so the compiler can vectorize the span (SSE2, NEON).
        let wins = (z < *d) & in_bounds(src, target.lo, target.hi, target.bilinear);
        *d = if wins { z } else { *d };
        *p = if wins { src } else { *p };
    }
}

/// Fig. 4's texture read for pixel `x` of `strip` in one row: with a source, the color there
/// as the image stood when the strip began, else the pattern (`pattern(x)`).
///
/// The image a strip reads is the previous iteration's (a ping-pong pair of textures): the
/// earlier strips finished, this strip's pixels and those of strips not yet run still the
/// pattern. Reads of those are answered from the pattern, so writing the strip in place is
/// exact. (With `d ≥ δ` wider than the strip they do not happen, save for extrapolation
/// slightly past a sliver's edge.)
#[inline]
fn resolve_pixel(
    row: &[[u8; 4]],
    sources: &[f32],
    x: usize,
    strip: &Strip,
    bilinear: bool,
    pattern: &impl Fn(usize) -> [u8; 4],
) -> [u8; 4] {
    let p = sources[x];
    if p.is_nan() {
        return pattern(x);
    }
    let (i0, i1, t) = address(p, bilinear);
    let read = |i: usize| {
        if strip.unfinished(i) {
            pattern(i)
        } else {
            row[i]
        }
    };
    mix(read(i0), read(i1), t)
}

/// [`resolve_pixel`] for every pixel of `strip` in one row, written in place.
fn resolve_row(
    row: &mut [[u8; 4]],
    sources: &[f32],
    strip: &Strip,
    bilinear: bool,
    pattern: impl Fn(usize) -> [u8; 4],
) {
    for x in strip.x0 as usize..(strip.x0 + strip.width) as usize {
        row[x] = resolve_pixel(row, sources, x, strip, bilinear, &pattern);
    }
}

/// Fig. 4's texture read for one strip of one band, row by row (see [`resolve_row`]).
fn resolve_strip(
    image: &mut [[u8; 4]],
    sources: &[f32],
    (width, y0): (usize, u32),
    strip: &Strip,
    bilinear: bool,
    pattern: &SirdsPattern,
) {
    let rows = image
        .chunks_exact_mut(width)
        .zip(sources.chunks_exact(width));
    for (y, (row, src)) in (y0..).zip(rows) {
        resolve_row(row, src, strip, bilinear, |x| pattern.color(x as u32, y));
    }
}

/// Per column, the strip that writes it: what the AVX2 loops' one pass over a row
/// (`avx2::resolve_sweep`) needs to read each pixel as its own strip does.
pub(super) struct Columns {
    /// The index (into the strips) of the strip writing each column.
    owner: Vec<u32>,
    /// Per column, where its strip's final pixels begin: right-going, the strip's first
    /// column (sources left of it are final); left-going, the strip's end (sources at or
    /// right of it are final).
    bound: Vec<i32>,
    /// The first column of the right-going strips (those left of it go left).
    split: u32,
}

impl Columns {
    /// The columns of `strips` (every column of a `width`-pixel row written by one of them,
    /// as [`plan_strips`] makes them), the right-going ones from `split` on.
    fn new(strips: &[Strip], width: u32, split: u32) -> Columns {
        let mut owner = vec![0; width as usize];
        let mut bound = vec![0; width as usize];
        for (k, s) in strips.iter().enumerate() {
            let b = if s.toward > 0.0 { s.x0 } else { s.x0 + s.width };
            for x in s.x0 as usize..(s.x0 + s.width) as usize {
                owner[x] = k as u32;
                bound[x] = b as i32;
            }
        }
        Columns {
            owner,
            bound,
            split,
        }
    }
}

/// Fig. 4's texture read for every strip of one band: the strips in order, each row by row
/// ([`resolve_strip`]), or, on the AVX2 loops, each row once for all its strips
/// (`avx2::resolve_sweep`, the same bytes).
fn resolve_band(
    image: &mut [[u8; 4]],
    sources: &[f32],
    (width, y0): (usize, u32),
    (strips, columns): (&[Strip], &Columns),
    bilinear: bool,
    kernels: Kernels,
    pattern: &SirdsPattern,
) {
    #[cfg(target_arch = "x86_64")]
    if kernels.avx2() {
        let gray = pattern.is_gray();
        let rows = image
            .chunks_exact_mut(width)
            .zip(sources.chunks_exact(width));
        for (y, (row, src)) in (y0..).zip(rows) {
            // SAFETY: `Kernels::avx2` found AVX2; `band_sources` stored only NaN or in-bounds
            // sources.
            unsafe {
                avx2::resolve_sweep(row, src, (strips, columns), (bilinear, gray), (y, pattern))
            };
        }
        return;
    }
    let _ = (kernels, columns);
    for strip in strips {
        resolve_strip(image, sources, (width, y0), strip, bilinear, pattern);
    }
}

/// `slots` filled with `value`, as the initialized slice they then are.
fn fill<T: Copy>(slots: &mut [MaybeUninit<T>], value: T) -> &mut [T] {
    for slot in slots.iter_mut() {
        slot.write(value);
    }
    // SAFETY: every element was just written; `MaybeUninit<T>` has `T`'s layout.
    unsafe { &mut *(slots as *mut [MaybeUninit<T>] as *mut [T]) }
}

/// The inputs of a strip run checked (separations that fit `width`, a pattern wide enough,
/// an image size any framebuffer accepts) and its strips planned: what [`per_vertex`],
/// [`per_vertex_reference`] and [`reference::k_passes`] start with.
///
/// # Errors
/// As [`check_inputs`], [`check_size`](crate::check_size) and [`plan_strips`].
fn checked_strips(
    width: u32,
    height: u32,
    d: &Disparity,
    pattern: &SirdsPattern,
    opts: &PerVertexOptions,
) -> Result<Vec<Strip>> {
    check_inputs(width, d, pattern)?;
    crate::check_size(width, height)?;
    plan_strips(width, d, opts)
}

/// Makes a SIRDS with the strip algorithm, on the scalar loops: the readable program
/// [`per_vertex`] runs faster with the same bytes (the benchmark times both).
///
/// Triangle setup once per direction; then, per band of `BAND_ROWS` rows (in parallel: rows
/// never interact), the winning fragment's source per pixel (`band_sources`) and the strips
/// in order, each reading the image the earlier strips finished (`resolve_strip`). The
/// result is the paper's k render passes, byte for byte (see the module notes).
///
/// # Errors
/// As [`check_inputs`], and k too small for the front separation.
pub fn per_vertex_reference(
    geometry: &StripGeometry,
    width: u32,
    height: u32,
    d: &Disparity,
    pattern: &SirdsPattern,
    opts: &PerVertexOptions,
    record_links: bool,
) -> Result<StripResult> {
    let size = (width, height);
    per_vertex_on(
        geometry,
        size,
        d,
        pattern,
        opts,
        record_links,
        Kernels::Scalar,
    )
}

/// Makes a SIRDS with the strip algorithm: [`per_vertex_reference`]'s bytes, steps 2 and 3
/// eight pixels at a time on AVX2 where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)).
///
/// # Errors
/// As [`per_vertex_reference`].
pub fn per_vertex(
    geometry: &StripGeometry,
    width: u32,
    height: u32,
    d: &Disparity,
    pattern: &SirdsPattern,
    opts: &PerVertexOptions,
    record_links: bool,
) -> Result<StripResult> {
    let size = (width, height);
    per_vertex_on(geometry, size, d, pattern, opts, record_links, kernels())
}

/// The strip algorithm on the loops `kernels` names.
fn per_vertex_on(
    geometry: &StripGeometry,
    (width, height): (u32, u32),
    d: &Disparity,
    pattern: &SirdsPattern,
    opts: &PerVertexOptions,
    record_links: bool,
    kernels: Kernels,
) -> Result<StripResult> {
    let strips = checked_strips(width, height, d, pattern, opts)?;
    let w = width as usize;
    let raster = RasterOptions::default();
    let setups = |toward: f32| {
        let clip = geometry.shifted(toward, width);
        let vertices = StripVertices {
            clip: &clip,
            separation: &geometry.separation,
        };
        setup_triangles(
            &geometry.triangles,
            clip.len(),
            &vertices,
            width,
            height,
            &raster,
        )
        .0
    };
    let right = setups(1.0);
    // Center start only.
    let left = strips.iter().any(|s| s.toward < 0.0).then(|| setups(-1.0));
    let right = bin_rows(&right, BAND_ROWS, height);
    let left = left
        .as_ref()
        .map_or_else(Vec::new, |l| bin_rows(l, BAND_ROWS, height));
    let bilinear = opts.filter == StripFilter::Bilinear;
    // Each direction covers the columns of its strips: right-going from the start column on,
    // left-going before it.
    let split = strips
        .iter()
        .filter(|s| s.toward > 0.0)
        .map(|s| s.x0)
        .min()
        .unwrap_or(width);
    let columns = Columns::new(&strips, width, split);
    let len = w * height as usize;
    let band_len = w * BAND_ROWS as usize;
    // Each band fills its own part of the image (in its thread's cache), then the strips
    // write every pixel.
    let mut pixels: Vec<[u8; 4]> = Vec::with_capacity(len);
    let band_links: Vec<Vec<i32>> = pixels.spare_capacity_mut()[..len]
        .par_chunks_mut(band_len)
        .enumerate()
        .with_max_len(1)
        .map(|(b, image)| {
            let image = fill(image, [0, 0, 0, 255]);
            let y0 = b as u32 * BAND_ROWS;
            let rows = (image.len() / w) as u32;
            let mut regions = Vec::with_capacity(2);
            for (x0, x1, toward, list) in [(split, width, 1.0, &right), (0, split, -1.0, &left)] {
                if let Some(s) = strips.iter().find(|s| s.toward == toward && x0 < x1) {
                    regions.push(Region {
                        x0,
                        x1,
                        target: SpanTarget {
                            toward,
                            lo: s.lo as f32,
                            hi: s.hi as f32,
                            bilinear,
                            perspective_correct: raster.perspective_correct,
                        },
                        setups: &list[b],
                    });
                }
            }
            let sources = band_sources(&regions, width, y0, rows, kernels);
            let plan = (strips.as_slice(), &columns);
            resolve_band(image, &sources, (w, y0), plan, bilinear, kernels, pattern);
            // Which pixel each one copied depends on its source alone, not on the strip.
            let link = |p: f32| {
                if p.is_nan() {
                    -1
                } else {
                    address(p, bilinear).0 as i32
                }
            };
            if record_links {
                sources.into_iter().map(link).collect()
            } else {
                Vec::new()
            }
        })
        .collect();
    // SAFETY: the bands, which together are the first `len` elements, each filled its own.
    unsafe { pixels.set_len(len) };
    Ok(StripResult {
        pixels,
        iterations: strips.len() as u32,
        strip_width: strips.first().map_or(0, |s| s.width),
        links: record_links.then(|| band_links.concat()),
    })
}

#[cfg(test)]
mod tests;
