//! Seed 002's per-vertex strip algorithm (Petz, Goldlücke, Magnor §3–4) on stereolab's own
//! rasterizer: starting from the pattern, each iteration renders the scene with every vertex
//! shifted right by `d(v)/2` and textured from the current image `d(v)/2` to the left of the
//! vertex (Fig. 4's vertex program), the z-buffer resolving visibility.
//!
//! Each iteration finishes one vertical strip: a pixel `x` copies the pixel `x − d`, and
//! `d ≥ δ` (the front separation), so a strip narrower than `δ` reads only finished strips and
//! never changes again (§3). We therefore traverse each iteration's strip only (a scissor on
//! its columns), which is the same image as rendering the whole frame k times, for about the
//! cost of one frame; every right-going pass draws the same shifted geometry, so triangle setup
//! runs once per direction.

use std::sync::atomic::{AtomicI32, Ordering};

use glam::Vec4;
use rayon::prelude::*;

use super::depthmap::DepthRange;
use super::disparity::Disparity;
use super::pattern::Pattern;
use super::per_pixel::check_inputs;
use crate::error::{Error, Result};
use crate::math::EyeMatrices;
use crate::raster::{Band, RasterOptions, SetupTriangle, setup_triangles, traverse};
use crate::scene::Scene;
use crate::shade::{Fragment, Shader, Varyings};

/// Where the pattern strip sits (seed 002 Fig. 7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Start {
    /// At the left edge; iterations propagate right (§3).
    Left,
    /// In the center; iterations propagate right in the right half, left in the left half (§4:
    /// less blur far from the initial strip).
    #[default]
    Center,
}

/// How a fragment samples the previous image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// The nearest pixel: exact copies, separations rounded to whole pixels (discrete depth
    /// layers, Fig. 5 bottom).
    Nearest,
    /// Linear between the two nearest pixels: smooth depth, some blur (Fig. 5 top).
    #[default]
    Bilinear,
}

/// Options of the strip algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PerVertexOptions {
    /// Left or center start.
    pub start: Start,
    /// Nearest or bilinear sampling.
    pub filter: Filter,
    /// Iterations k (the strip width is ⌈W / k⌉); `None`: the fewest the geometry allows.
    pub iterations: Option<u32>,
}

/// The scene as the strip passes see it: cyclopean clip positions, each vertex's separation,
/// and the triangles, the background plane last (drawn last, most of it fails the depth test).
pub struct StripGeometry {
    clip: Vec<Vec4>,
    separation: Vec<f32>,
    triangles: Vec<[u32; 3]>,
}

impl StripGeometry {
    /// Transforms every object with the cyclopean `center` matrices, gives each vertex the
    /// separation of its eye-space distance (`clip.w`) mapped through `range`, and adds the
    /// background plane at `range.back` covering the whole view (seed 002 §3).
    pub fn new(
        scene: &Scene,
        center: &EyeMatrices,
        range: &DepthRange,
        d: &Disparity,
        cross_eyed: bool,
    ) -> StripGeometry {
        let nearness = |distance: f32| {
            let z = range.nearness(distance);
            if cross_eyed { 1.0 - z } else { z }
        };
        let mut g = StripGeometry {
            clip: Vec::new(),
            separation: Vec::new(),
            triangles: Vec::new(),
        };
        for o in &scene.objects {
            let mvp = center.mvp * o.model;
            let base = g.clip.len() as u32;
            for p in &o.mesh.positions {
                let c = mvp * p.extend(1.0);
                g.clip.push(c);
                g.separation.push(d.separation(nearness(c.w)));
            }
            g.triangles
                .extend(o.mesh.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        // The plane, 5% larger than the frustum's cross-section at its distance.
        let [_, r, _, t, n, _] = center.frustum;
        let (hx, hy) = (r * range.back / n * 1.05, t * range.back / n * 1.05);
        let base = g.clip.len() as u32;
        for (x, y) in [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)] {
            let c = center.projection * Vec4::new(x, y, -range.back, 1.0);
            g.clip.push(c);
            g.separation.push(d.separation(nearness(c.w)));
        }
        g.triangles.push([base, base + 1, base + 2]);
        g.triangles.push([base, base + 2, base + 3]);
        g
    }

    /// Per-vertex separation in pixels.
    pub fn separation(&self) -> &[f32] {
        &self.separation
    }

    /// Triangles (vertex indices), the background plane last.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Fig. 4's vertex shift for a `width`-pixel image: every clip position moved
    /// `toward · s/2` pixels, i.e. `x + toward · s · w / W` in clip space (+1: right-going strips,
    /// −1: left-going). The CPU and GPU strips both take their vertices from here.
    pub fn shifted(&self, toward: f32, width: u32) -> Vec<Vec4> {
        let wf = width as f32;
        self.clip
            .iter()
            .zip(&self.separation)
            .map(|(c, s)| Vec4::new(c.x + toward * s * c.w / wf, c.y, c.z, c.w))
            .collect()
    }
}

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
pub(crate) struct Strip {
    pub(crate) x0: u32,
    pub(crate) width: u32,
    /// +1: copies from `x − d` (right-going), −1: from `x + d` (left-going).
    pub(crate) toward: f32,
    /// Sources allowed in `[lo, hi)`; outside, the pixel keeps the pattern.
    pub(crate) lo: i64,
    pub(crate) hi: i64,
}

/// The strip width and strips for `width` pixels.
///
/// # Errors
/// `Invalid` naming `sirds.iterations` when k strips would be wider than `⌊δ⌋ − 1` (a strip
/// would read itself), or k is 0.
pub(crate) fn plan_strips(
    width: u32,
    d: &Disparity,
    opts: &PerVertexOptions,
) -> Result<Vec<Strip>> {
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
        Start::Left => 0,
        Start::Center => width / 2,
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

/// Where a fragment at column `x` with separation `sep` samples the image (Fig. 4's texture
/// coordinate `x ∓ d/2` of the unshifted vertex, in pixel-index units, centers at integers):
/// the pixels `i0` and `i1` and the weight `t` of `i1` (nearest: `i0 == i1`, `t = 0`). `None`
/// when a source falls outside `[lo, hi)`: the fragment is discarded and the pixel keeps what
/// was there.
#[inline]
fn source(x: u32, sep: f32, strip: &Strip, bilinear: bool) -> Option<(usize, usize, f32)> {
    let p = x as f32 - strip.toward * sep;
    let (lo, hi) = (strip.lo, strip.hi);
    if bilinear {
        let i0 = floor(p);
        let t = p - i0 as f32;
        let i1 = if t > 0.0 { i0 + 1 } else { i0 };
        (i0 >= lo && i1 < hi).then_some((i0 as usize, i1 as usize, t))
    } else {
        let i = floor(p + 0.5);
        (i >= lo && i < hi).then_some((i as usize, i as usize, 0.0))
    }
}

/// The color a fragment writes: the source pixel, or the two mixed linearly and rounded to
/// the nearest level (alpha opaque).
#[inline]
fn sample(row: &[[u8; 4]], (i0, i1, t): (usize, usize, f32)) -> [u8; 4] {
    let (a, b) = (row[i0], row[i1]);
    if i0 == i1 {
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

/// Fig. 4's fragment program over one band of rows: reads the band's current image `d` pixels
/// toward the start. [`traverse`] calls only the fragment stage.
struct StripSampler<'a> {
    /// The band's rows as they stand (finished strips final).
    image: &'a [[u8; 4]],
    width: usize,
    y0: u32,
    strip: Strip,
    bilinear: bool,
    /// Per band pixel, the source it copied (bilinear: the left one of the two).
    links: Option<&'a [AtomicI32]>,
}

impl Shader for StripSampler<'_> {
    fn varying_count(&self) -> usize {
        1
    }

    /// Never called: the vertices went through [`StripVertices`].
    fn vertex(&self, _: u32, _: &mut Varyings) -> Vec4 {
        Vec4::ZERO
    }

    #[inline]
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let row_start = (f.y - self.y0) as usize * self.width;
        let src = source(f.x, f.varyings[0], &self.strip, self.bilinear)?;
        if let Some(links) = self.links {
            links[row_start + f.x as usize].store(src.0 as i32, Ordering::Relaxed);
        }
        Some(sample(&self.image[row_start..row_start + self.width], src))
    }
}

/// Rows per band: bands run in parallel. Fixed, so the bytes never depend on the thread count.
pub const BAND_ROWS: u32 = 16;

/// Makes a SIRDS with the strip algorithm.
///
/// Every right-going pass draws the same shifted geometry (and every left-going one the
/// other), so triangle setup runs once per direction; each strip is then traversed with a
/// scissor on its columns, in strip order, its fragments sampling the image the earlier strips
/// finished, with its own depth buffer (each pixel belongs to one strip). Bands of
/// [`BAND_ROWS`] rows run in parallel: rows never interact.
///
/// # Errors
/// As [`check_inputs`], and k too small for the front separation.
pub fn per_vertex(
    geometry: &StripGeometry,
    width: u32,
    height: u32,
    d: &Disparity,
    pattern: &Pattern,
    opts: &PerVertexOptions,
    record_links: bool,
) -> Result<StripResult> {
    check_inputs(width, d, pattern)?;
    // The same size checks as any framebuffer.
    crate::framebuffer::check_size(width, height)?;
    let strips = plan_strips(width, d, opts)?;
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
    let left = if strips.iter().any(|s| s.toward < 0.0) {
        setups(-1.0)
    } else {
        Vec::new()
    };
    let widest = strips.iter().map(|s| s.width as usize).max().unwrap_or(0);
    let mut pixels = vec![[0u8, 0, 0, 255]; w * height as usize];
    let links: Vec<AtomicI32> = if record_links {
        (0..pixels.len()).map(|_| AtomicI32::new(-1)).collect()
    } else {
        Vec::new()
    };
    let band_len = w * BAND_ROWS as usize;
    pixels
        .par_chunks_mut(band_len)
        .enumerate()
        .for_each(|(b, image)| {
            let y0 = b as u32 * BAND_ROWS;
            let rows = image.len() / w;
            let y1 = y0 + rows as u32 - 1;
            for (r, row) in image.chunks_exact_mut(w).enumerate() {
                pattern.fill_row(y0 + r as u32, row);
            }
            let in_band = |list: &[SetupTriangle]| -> Vec<usize> {
                (0..list.len())
                    .filter(|&i| {
                        let (r0, r1) = list[i].rows();
                        r0 <= y1 && r1 >= y0
                    })
                    .collect()
            };
            let (right_here, left_here) = (in_band(&right), in_band(&left));
            let band_links = record_links.then(|| &links[b * band_len..b * band_len + image.len()]);
            let mut color = vec![[0u8; 4]; widest * rows];
            let mut depth = vec![1.0f32; widest * rows];
            for strip in &strips {
                let (x0, sw) = (strip.x0 as usize, strip.width as usize);
                let (list, here) = if strip.toward > 0.0 {
                    (&right, &right_here)
                } else {
                    (&left, &left_here)
                };
                let color = &mut color[..sw * rows];
                let depth = &mut depth[..sw * rows];
                for (r, c) in color.chunks_exact_mut(sw).enumerate() {
                    c.copy_from_slice(&image[r * w + x0..r * w + x0 + sw]);
                }
                depth.fill(1.0);
                let sampler = StripSampler {
                    image,
                    width: w,
                    y0,
                    strip: *strip,
                    bilinear: opts.filter == Filter::Bilinear,
                    links: band_links,
                };
                let mut tile = Band {
                    width: strip.width,
                    x0: strip.x0,
                    y0,
                    color,
                    depth,
                };
                let (c0, c1) = (strip.x0, strip.x0 + strip.width - 1);
                for &i in here {
                    let (a, z) = list[i].columns();
                    if a <= c1 && z >= c0 {
                        traverse(&list[i], &sampler, &mut tile, &raster);
                    }
                }
                for (r, c) in tile.color.chunks_exact(sw).enumerate() {
                    image[r * w + x0..r * w + x0 + sw].copy_from_slice(c);
                }
            }
        });
    Ok(StripResult {
        pixels,
        iterations: strips.len() as u32,
        strip_width: strips.first().map_or(0, |s| s.width),
        links: record_links.then(|| links.into_iter().map(AtomicI32::into_inner).collect()),
    })
}
