//! Seed 002's per-vertex strip algorithm (Petz, Goldlücke, Magnor §3–4) on stereolab's own
//! rasterizer: starting from the pattern, each iteration renders the scene with every vertex
//! shifted right by `d(v)/2` and textured from the current image `d(v)/2` to the left of the
//! vertex (Fig. 4's vertex program), the z-buffer resolving visibility.
//!
//! Each iteration finishes one vertical strip: a pixel `x` copies the pixel `x − d`, and
//! `d ≥ δ` (the front separation), so a strip narrower than `δ` reads only finished strips and
//! never changes again (§3). We therefore render each iteration into its strip only — the
//! rasterizer's clipper cuts the scene to the strip — which is the same image as rendering the
//! whole frame k times, for about the cost of one frame.

use std::sync::atomic::{AtomicI32, Ordering};

use glam::Vec4;
use rayon::prelude::*;

use super::depthmap::DepthRange;
use super::disparity::Disparity;
use super::pattern::Pattern;
use super::per_pixel::check_inputs;
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;
use crate::math::EyeMatrices;
use crate::raster::{RasterOptions, rasterize};
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

/// Row bands rendered in parallel. Fixed, so the bytes never depend on the thread count.
pub const BANDS: u32 = 4;

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

    /// Number of triangles, background plane included.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Cyclopean clip positions (the GPU mirror uploads them).
    pub fn clip(&self) -> &[Vec4] {
        &self.clip
    }

    /// Per-vertex separation in pixels.
    pub fn separation(&self) -> &[f32] {
        &self.separation
    }

    /// Triangles (vertex indices), the background plane last.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
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

/// Fig. 4 as a [`Shader`]: the vertex stage shifts the cyclopean position by `±d/2` (already in
/// `clip`) and maps the strip/band to the framebuffer; the fragment stage reads the current
/// image `d` pixels back (the texture coordinate `x ∓ d/2` of the unshifted vertex).
struct StripShader<'a> {
    clip: &'a [Vec4],
    separation: &'a [f32],
    /// Window-space remap to the strip × band framebuffer: `x' = x sx + w ox`, `y' = y sy + w oy`.
    remap: [f32; 4],
    image: &'a [[u8; 4]],
    width: usize,
    strip: Strip,
    bilinear: bool,
    links: Option<&'a [AtomicI32]>,
}

impl Shader for StripShader<'_> {
    fn varying_count(&self) -> usize {
        1
    }

    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        let i = index as usize;
        out[0] = self.separation[i];
        let c = self.clip[i];
        let [sx, ox, sy, oy] = self.remap;
        Vec4::new(c.x * sx + c.w * ox, c.y * sy + c.w * oy, c.z, c.w)
    }

    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let x = f.x + self.strip.x0;
        let row = f.y as usize * self.width;
        // Source position in pixel-index units (pixel centers at integers).
        let p = x as f32 - self.strip.toward * f.varyings[0];
        let (lo, hi) = (self.strip.lo, self.strip.hi);
        let (source, color) = if self.bilinear {
            let i0 = floor(p);
            let t = p - i0 as f32;
            let i1 = if t > 0.0 { i0 + 1 } else { i0 };
            if i0 < lo || i1 >= hi {
                return None;
            }
            let (a, b) = (self.image[row + i0 as usize], self.image[row + i1 as usize]);
            let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * t + 0.5) as u8;
            (i0, [mix(0), mix(1), mix(2), 255])
        } else {
            let i = floor(p + 0.5);
            if i < lo || i >= hi {
                return None;
            }
            (i, self.image[row + i as usize])
        };
        if let Some(links) = self.links {
            links[row + x as usize].store(source as i32, Ordering::Relaxed);
        }
        Some(color)
    }
}

/// `⌊v⌋` without a libm call (the default x86-64 target has no SSE4.1 `roundss`).
#[inline]
fn floor(v: f32) -> i64 {
    let i = v as i64;
    i - ((i as f32) > v) as i64
}

/// Window-space bounds `[x0, x1, y0, y1]` of each triangle after the horizontal shift; the
/// whole image for a triangle with a vertex behind the eye (the clipper sorts it out).
fn triangle_bounds(clip: &[Vec4], triangles: &[[u32; 3]], w: f32, h: f32) -> Vec<[f32; 4]> {
    triangles
        .iter()
        .map(|t| {
            let mut b = [
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::INFINITY,
                f32::NEG_INFINITY,
            ];
            for &i in t {
                let c = clip[i as usize];
                if c.w.is_nan() || c.w <= 0.0 {
                    return [
                        f32::NEG_INFINITY,
                        f32::INFINITY,
                        f32::NEG_INFINITY,
                        f32::INFINITY,
                    ];
                }
                let (x, y) = ((c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h);
                b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
            }
            b
        })
        .collect()
}

/// Makes a SIRDS with the strip algorithm: `BANDS` row bands in parallel (rows never interact),
/// each band's strips in order.
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
    let strips = plan_strips(width, d, opts)?;
    let (wf, hf) = (width as f32, height as f32);
    // Both shifted copies of the vertices: right-going (+d/2) and left-going (−d/2).
    let shifted = |toward: f32| -> Vec<Vec4> {
        geometry
            .clip
            .iter()
            .zip(&geometry.separation)
            .map(|(c, s)| Vec4::new(c.x + toward * s * c.w / wf, c.y, c.z, c.w))
            .collect()
    };
    let right = shifted(1.0);
    let left = if strips.iter().any(|s| s.toward < 0.0) {
        shifted(-1.0)
    } else {
        Vec::new()
    };
    let bounds_right = triangle_bounds(&right, &geometry.triangles, wf, hf);
    let bounds_left = if left.is_empty() {
        Vec::new()
    } else {
        triangle_bounds(&left, &geometry.triangles, wf, hf)
    };
    let band_rows = height.div_ceil(BANDS);
    let raster = RasterOptions::default();
    let bands: Vec<(u32, u32)> = (0..height)
        .step_by(band_rows as usize)
        .map(|y0| (y0, band_rows.min(height - y0)))
        .collect();
    let results = bands
        .par_iter()
        .map(|&(y0, bh)| -> Result<(Vec<[u8; 4]>, Vec<AtomicI32>)> {
            let w = width as usize;
            let mut image: Vec<[u8; 4]> = (y0..y0 + bh)
                .flat_map(|y| (0..width).map(move |x| (x, y)))
                .map(|(x, y)| pattern.color(x, y))
                .collect();
            let links: Vec<AtomicI32> = if record_links {
                (0..image.len()).map(|_| AtomicI32::new(-1)).collect()
            } else {
                Vec::new()
            };
            let (y_lo, y_hi) = (y0 as f32 - 1.0, (y0 + bh) as f32 + 1.0);
            let n = geometry.clip.len();
            let (mut seen, mut remap, mut stamp) = (vec![0u32; n], vec![0u32; n], 0u32);
            let (mut tris, mut local_clip, mut local_sep) = (Vec::new(), Vec::new(), Vec::new());
            for strip in &strips {
                let (clip, bounds) = if strip.toward > 0.0 {
                    (&right, &bounds_right)
                } else {
                    (&left, &bounds_left)
                };
                let (x_lo, x_hi) = (strip.x0 as f32 - 1.0, (strip.x0 + strip.width) as f32 + 1.0);
                // Only the triangles that reach this strip × band, with their vertices
                // compacted, so the vertex stage runs on those alone.
                tris.clear();
                local_clip.clear();
                local_sep.clear();
                stamp += 1;
                for (t, b) in geometry.triangles.iter().zip(bounds) {
                    if !(b[1] >= x_lo && b[0] <= x_hi && b[3] >= y_lo && b[2] <= y_hi) {
                        continue;
                    }
                    tris.push(t.map(|i| {
                        let i = i as usize;
                        if seen[i] != stamp {
                            seen[i] = stamp;
                            remap[i] = local_clip.len() as u32;
                            local_clip.push(clip[i]);
                            local_sep.push(geometry.separation[i]);
                        }
                        remap[i]
                    }));
                }
                let sw = strip.width as f32;
                let bhf = bh as f32;
                let remap = [
                    wf / sw,
                    (wf - 2.0 * strip.x0 as f32 - sw) / sw,
                    hf / bhf,
                    -(hf - 2.0 * y0 as f32 - bhf) / bhf,
                ];
                let mut fb = Framebuffer::new(strip.width, bh, [0, 0, 0, 255])?;
                for (r, row) in fb.color.chunks_exact_mut(strip.width as usize).enumerate() {
                    let start = r * w + strip.x0 as usize;
                    row.copy_from_slice(&image[start..start + strip.width as usize]);
                }
                let shader = StripShader {
                    clip: &local_clip,
                    separation: &local_sep,
                    remap,
                    image: &image,
                    width: w,
                    strip: *strip,
                    bilinear: opts.filter == Filter::Bilinear,
                    links: record_links.then_some(links.as_slice()),
                };
                rasterize(&tris, local_clip.len(), &shader, &mut fb, &raster);
                for (r, row) in fb.color.chunks_exact(strip.width as usize).enumerate() {
                    let start = r * w + strip.x0 as usize;
                    image[start..start + strip.width as usize].copy_from_slice(row);
                }
            }
            Ok((image, links))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut pixels = Vec::with_capacity(width as usize * height as usize);
    let mut links = record_links.then(Vec::new);
    for (img, l) in results {
        pixels.extend(img);
        if let Some(all) = links.as_mut() {
            all.extend(l.into_iter().map(AtomicI32::into_inner));
        }
    }
    Ok(StripResult {
        pixels,
        iterations: strips.len() as u32,
        strip_width: strips.first().map_or(0, |s| s.width),
        links,
    })
}
