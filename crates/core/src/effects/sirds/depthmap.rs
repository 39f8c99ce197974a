//! The depth map a SIRDS encodes: normalized nearness per pixel, from a rendered depth buffer
//! or from an image file.

use std::path::Path;

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::framebuffer::{Framebuffer, check_size};

pub use super::depthfile::{DepthMapping, DepthSamples, Near};

/// Normalized nearness per pixel, row 0 at the top: 0 = background plane (far), 1 = front of
/// the depth range (TIW's `Z`; in image files white is near, as for netpbm's `pamstereogram`).
#[derive(Clone, Debug, PartialEq)]
pub struct DepthMap {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major nearness in [0, 1].
    pub z: Vec<f32>,
}

/// Which eye-space distances (along the view axis) map to the front (`z = 1`) and to the
/// background plane (`z = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthRange {
    /// Distance mapped to `z = 1`.
    pub front: f32,
    /// Distance of the background plane, mapped to `z = 0`.
    pub back: f32,
}

impl DepthRange {
    /// Checks `0 < front < back`, both finite.
    ///
    /// # Errors
    /// `Invalid` naming `sirds.front` / `sirds.back`.
    pub fn validate(&self) -> Result<()> {
        if !(self.front.is_finite() && self.front > 0.0) {
            return Err(Error::invalid("sirds.front", self.front, "must be > 0"));
        }
        if !(self.back.is_finite() && self.back > self.front) {
            return Err(Error::invalid(
                "sirds.back",
                self.back,
                format!("must be > sirds.front ({})", self.front),
            ));
        }
        Ok(())
    }

    /// Nearness of eye-space distance `distance`: `(back − distance) / (back − front)`, clamped.
    #[inline]
    pub fn nearness(&self, distance: f32) -> f32 {
        ((self.back - distance) / (self.back - self.front)).clamp(0.0, 1.0)
    }
}

/// Eye-space distance of window depth `depth` ∈ [0, 1] under an OpenGL perspective projection
/// with clip planes `near`, `far`: `2 n f / ((f + n) − z_ndc (f − n))`, `z_ndc = 2 depth − 1`.
#[inline]
pub fn linearize(depth: f32, near: f32, far: f32) -> f32 {
    let z_ndc = 2.0 * depth - 1.0;
    2.0 * near * far / ((far + near) - z_ndc * (far - near))
}

/// The smallest and largest bit pattern of the covered (`< 1`) depths, as `i32`: depths are
/// clamped to [0, 1], where the bit patterns order like the values (−0 sorts first and means
/// 0). `(i32::MAX, i32::MIN)` when nothing is covered.
fn covered_bounds(depth: &[f32]) -> (i32, i32) {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::kernels().avx2() {
        // SAFETY: AVX2 is available (`Kernels::avx2`).
        return unsafe { covered_bounds_avx2(depth) };
    }
    covered_bounds_lanes(depth)
}

/// [`covered_bounds_lanes`] compiled for AVX2 (`vpminsd`/`vpmaxsd`; baseline x86-64 has no
/// 32-bit integer min/max and emulates each with three instructions).
///
/// # Safety
/// The CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn covered_bounds_avx2(depth: &[f32]) -> (i32, i32) {
    covered_bounds_lanes(depth)
}

/// [`covered_bounds`] as a branch-free integer min/max in 8 lanes, which the compiler
/// vectorizes (a float fold stays scalar).
#[inline(always)]
fn covered_bounds_lanes(depth: &[f32]) -> (i32, i32) {
    const ONE: i32 = 0x3f80_0000;
    let (mut lo, mut hi) = ([i32::MAX; 8], [i32::MIN; 8]);
    let chunks = depth.chunks_exact(8);
    let tail = chunks.remainder();
    let mut visit = |lane: usize, d: f32| {
        let b = d.to_bits() as i32;
        let covered = b < ONE;
        lo[lane] = lo[lane].min(if covered { b } else { i32::MAX });
        hi[lane] = hi[lane].max(if covered { b } else { i32::MIN });
    };
    for c in chunks {
        for (lane, &d) in c.iter().enumerate() {
            visit(lane, d);
        }
    }
    for (lane, &d) in tail.iter().enumerate() {
        visit(lane, d);
    }
    (
        lo.into_iter().min().unwrap_or(i32::MAX),
        hi.into_iter().max().unwrap_or(i32::MIN),
    )
}

impl DepthMap {
    /// A depth map from raw nearness values.
    ///
    /// # Errors
    /// `Invalid` for a zero or oversized side, a length that does not match, or a value that is
    /// NaN or outside [0, 1] (naming the pixel).
    pub fn new(width: u32, height: u32, z: Vec<f32>) -> Result<DepthMap> {
        check_size(width, height).map_err(|e| match e {
            Error::Invalid {
                field,
                value,
                reason,
            } => Error::Invalid {
                field: field.replace("image.", "depth map "),
                value,
                reason,
            },
            other => other,
        })?;
        if z.len() != width as usize * height as usize {
            return Err(Error::invalid(
                "depth map",
                z.len(),
                format!("needs {width}×{height} values"),
            ));
        }
        if let Some(i) = z.iter().position(|v| !(0.0..=1.0).contains(v)) {
            let (x, y) = (i % width as usize, i / width as usize);
            return Err(Error::invalid(
                format!("depth map pixel ({x}, {y})"),
                z[i],
                "must be a number in [0, 1] (NaN found or out of range)",
            ));
        }
        Ok(DepthMap { width, height, z })
    }

    /// Reads a depth-map file, white = near (see [`DepthSamples::load`]).
    ///
    /// # Errors
    /// As [`DepthSamples::load`].
    pub fn load(path: &Path) -> Result<DepthMap> {
        Ok(DepthMap::load_with(path, Near::White)?.0)
    }

    /// Reads a depth-map file with either end near, and says how its values were mapped.
    ///
    /// # Errors
    /// As [`DepthSamples::load`].
    pub fn load_with(path: &Path, near: Near) -> Result<(DepthMap, DepthMapping)> {
        let d = DepthSamples::load(path, near)?;
        let z = d.samples.iter().map(|&v| v as f32 / 65535.0).collect();
        let map = DepthMap::new(d.width, d.height, z).map_err(|e| e.in_file(path))?;
        Ok((map, d.mapping))
    }

    /// The nearness of a rendered depth buffer: covered pixels by their eye-space distance,
    /// uncovered pixels (depth 1.0, the clear value) on the background plane (`z = 0`).
    pub fn from_framebuffer(fb: &Framebuffer, near: f32, far: f32, range: &DepthRange) -> Self {
        let z = fb
            .depth
            .iter()
            .map(|&d| {
                if d >= 1.0 {
                    0.0
                } else {
                    range.nearness(linearize(d, near, far))
                }
            })
            .collect();
        DepthMap {
            width: fb.width,
            height: fb.height,
            z,
        }
    }

    /// The range a depth buffer spans: `front` at the nearest covered pixel, the background
    /// plane 10% of the covered span behind the farthest one (the SIRDS paper's §3: "a certain distance
    /// behind the geometry"), kept inside the far clip plane. `None` when nothing is covered.
    pub fn auto_range(fb: &Framebuffer, near: f32, far: f32) -> Option<DepthRange> {
        // The rasterizer's bands in parallel (min and max do not care about the order): split
        // as the depth pass split them, each thread tends to read what it just wrote.
        let band = fb.width as usize * crate::raster::BAND_ROWS;
        let (lo, hi) = fb
            .depth
            .par_chunks(band.max(1))
            .map(covered_bounds)
            .reduce(|| (i32::MAX, i32::MIN), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        if lo > hi {
            return None;
        }
        let (lo, hi) = (f32::from_bits(lo as u32), f32::from_bits(hi as u32));
        let (front, last) = (linearize(lo, near, far), linearize(hi, near, far));
        let span = (last - front).max(front * 0.05);
        Some(DepthRange {
            front,
            back: (last + 0.1 * span).min(far * 0.999),
        })
    }

    /// Nearness at pixel (x, y).
    #[inline]
    pub fn at(&self, x: u32, y: u32) -> f32 {
        self.z[y as usize * self.width as usize + x as usize]
    }

    /// One row.
    #[inline]
    pub fn row(&self, y: u32) -> &[f32] {
        let w = self.width as usize;
        &self.z[y as usize * w..(y as usize + 1) * w]
    }

    /// Near and far swapped (`z → 1 − z`): what a cross-eyed viewer needs.
    pub fn inverted(&self) -> DepthMap {
        DepthMap {
            width: self.width,
            height: self.height,
            z: self.z.iter().map(|z| 1.0 - z).collect(),
        }
    }

    /// As a 16-bit grayscale image, white = near (the format [`DepthMap::load`] reads).
    pub fn to_image(&self) -> image::ImageBuffer<image::Luma<u16>, Vec<u16>> {
        let data = self
            .z
            .iter()
            .map(|z| (z.clamp(0.0, 1.0) * 65535.0).round() as u16)
            .collect();
        image::ImageBuffer::from_raw(self.width, self.height, data).expect("buffer size matches")
    }
}
