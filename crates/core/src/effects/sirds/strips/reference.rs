//! The strip algorithm as the SIRDS paper (Petz et al.) §3–4 states it: k render passes, one
//! per strip, on stereolab's rasterizer. This is the definition; the fast path
//! [`per_vertex`](super::per_vertex) (deferred texturing, strips resolved in place, AVX2) is
//! held to it byte for byte on real scenes by the pipeline's `render/strip_tests.rs`.
//!
//! Two images, as the paper's render-to-texture ping-pong (and `gpu::sirds`):
//!
//! - A, the image so far: the random-dot pattern at first;
//! - per strip, one pass renders the whole scene into B (a copy of A, depth cleared) with
//!   Fig. 4's programs (`StripPass`): every vertex shifted by `toward · d(v)/2`, every
//!   fragment textured from A at `x − toward · d`, the depth test LESS deciding visibility;
//! - B's strip is copied to A; the rest of B is dropped (a strip narrower than the front
//!   separation `δ` reads only finished strips, so it never changes again, §3).
//!
//! A pixel that no fragment covers, or whose fragment samples outside the allowed sources,
//! keeps A's value: still the pattern, since its strip has not run. A read of a pixel whose
//! strip has not run sees the pattern too, because A holds only finished strips.
//!
//! Cost: k full renders (every triangle set up and traversed over the whole frame per strip,
//! one strip kept), against about one for the fast path. For reading and testing, not for use.

use glam::Vec4;

use super::{
    PerVertexOptions, Strip, StripFilter, StripGeometry, StripResult, address, checked_strips,
    in_bounds, mix, shift, source_coordinate,
};
use crate::{
    Disparity, Fragment, Framebuffer, RasterOptions, Result, Shader, SirdsPattern, Varyings,
    rasterize,
};

/// Fig. 4's vertex and fragment programs for the pass of one strip.
struct StripPass<'a> {
    geometry: &'a StripGeometry,
    /// Image A, read as the texture.
    previous: &'a [[u8; 4]],
    width: u32,
    strip: &'a Strip,
    bilinear: bool,
}

impl StripPass<'_> {
    /// The columns a fragment at column `x` with separation `sep` reads and the weight of the
    /// second (see [`address`]), or `None` when its source `x − toward · sep` lies outside the
    /// strip's allowed sources (the fragment is discarded, the pixel keeps its value).
    fn source(&self, x: u32, sep: f32) -> Option<(usize, usize, f32)> {
        let s = self.strip;
        let p = source_coordinate(x, sep, s.toward);
        in_bounds(p, s.lo as f32, s.hi as f32, self.bilinear).then(|| address(p, self.bilinear))
    }
}

impl Shader for StripPass<'_> {
    fn varying_count(&self) -> usize {
        1
    }

    /// The vertex moved `toward · d(v)/2` pixels; its separation `d(v)` as the varying.
    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        let (c, s) = (
            self.geometry.clip[index as usize],
            self.geometry.separation[index as usize],
        );
        out[0] = s;
        shift(c, s, self.strip.toward, self.width as f32)
    }

    /// The texture read: A at `x − toward · d`, nearest or linear between two pixels.
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let (i0, i1, t) = self.source(f.x, f.varyings[0])?;
        let w = self.width as usize;
        let row = &self.previous[f.y as usize * w..][..w];
        Some(mix(row[i0], row[i1], t))
    }
}

/// The pass recording, instead of a color, the first pixel each fragment reads (its link, as
/// the little-endian bytes of an `i32`): the depth test keeps the same fragment as in the
/// colored pass.
struct RecordLink<'a>(StripPass<'a>);

impl Shader for RecordLink<'_> {
    fn varying_count(&self) -> usize {
        self.0.varying_count()
    }

    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        self.0.vertex(index, out)
    }

    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let (i0, _, _) = self.0.source(f.x, f.varyings[0])?;
        Some((i0 as i32).to_le_bytes())
    }
}

/// Makes a SIRDS with the strip algorithm as k render passes: the definition the fast
/// [`per_vertex`](super::per_vertex) is held to (same inputs, same result, byte for byte).
///
/// Per strip (the SIRDS paper's §3–4, Fig. 4): render the scene into B, a copy of A, with every vertex
/// `v` at `x + toward · d(v)/2` and every fragment at `x` colored from A at
/// `x − toward · d`; copy B's strip into A. `toward` is +1 for strips going right from the start
/// column, −1 for those going left (center start, Fig. 7).
///
/// # Errors
/// As [`per_vertex`](super::per_vertex): separations that do not fit `width`, a pattern
/// narrower than the largest separation, a bad image size, k too small for the front
/// separation.
pub fn k_passes(
    geometry: &StripGeometry,
    width: u32,
    height: u32,
    d: &Disparity,
    pattern: &SirdsPattern,
    opts: &PerVertexOptions,
    record_links: bool,
) -> Result<StripResult> {
    let strips = checked_strips(width, height, d, pattern, opts)?;
    let bilinear = opts.filter == StripFilter::Bilinear;
    let mut a = pattern.fill(width, height);
    // −1 (no link) where the pattern stays, as the fast path records.
    let mut links = record_links.then(|| vec![-1i32; a.len()]);
    for strip in &strips {
        let pass = StripPass {
            geometry,
            previous: &a,
            width,
            strip,
            bilinear,
        };
        let b = render(&pass, geometry, &a, width, height)?;
        if let Some(links) = &mut links {
            let none = vec![(-1i32).to_le_bytes(); a.len()];
            let b = render(&RecordLink(pass), geometry, &none, width, height)?;
            let b: Vec<i32> = b.iter().map(|c| i32::from_le_bytes(*c)).collect();
            copy_strip(&b, links, strip, width);
        }
        copy_strip(&b, &mut a, strip, width);
    }
    Ok(StripResult {
        pixels: a,
        iterations: strips.len() as u32,
        strip_width: strips.first().map_or(0, |s| s.width),
        links,
    })
}

/// One full render pass of `geometry` with `shader` into a target holding `start` (depth
/// cleared): its colors.
///
/// # Errors
/// An image size [`Framebuffer::new`] refuses.
fn render(
    shader: &impl Shader,
    geometry: &StripGeometry,
    start: &[[u8; 4]],
    width: u32,
    height: u32,
) -> Result<Vec<[u8; 4]>> {
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255])?;
    fb.color_mut().copy_from_slice(start);
    rasterize(
        &geometry.triangles,
        geometry.clip.len(),
        shader,
        &mut fb,
        &RasterOptions::default(),
    );
    Ok(fb.into_buffers().0)
}

/// Copies the columns of `strip` from `from` to `to`, every row (`width` pixels a row).
fn copy_strip<T: Copy>(from: &[T], to: &mut [T], strip: &Strip, width: u32) {
    let cols = strip.x0 as usize..(strip.x0 + strip.width) as usize;
    let rows = from
        .chunks_exact(width as usize)
        .zip(to.chunks_exact_mut(width as usize));
    for (src, dst) in rows {
        dst[cols.clone()].copy_from_slice(&src[cols.clone()]);
    }
}
