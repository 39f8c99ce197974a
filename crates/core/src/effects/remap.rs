//! Remapping one eye's pixels into the other eye (the exercise slides, "Remapping"), and the visibility
//! check built on it (the exercise slides, "Visibility Check").
//!
//! For a pixel of eye `this` (window coordinates from `gl_FragCoord.xy`, depth from its depth
//! texture):
//!
//! ```text
//! ndc_this = (2 x_win / W − 1, 1 − 2 y_win / H, 2 d − 1)        (row 0 at the top)
//! clip_other = MVP_other · MVP_this⁻¹ · (ndc_this, 1)
//! ndc_other  = clip_other.xyz / clip_other.w                    (the w-divide)
//! τ = ½ (ndc_other.xy + 1)                                      (texture coordinates, v up)
//! ```
//!
//! and the other eye's color and depth are fetched at τ with nearest filtering (the exercise slides set
//! `TF_NEAREST` on all four textures). [`Remapper::remap`] is the shader for one pixel; the
//! functions below it only loop.

use std::mem::MaybeUninit;

use glam::{DMat4, DVec4, Mat4, Vec4};
use image::RgbaImage;
use rayon::prelude::*;

use super::eye_input::check_same_size;
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;
use crate::simd::{Kernels, kernels};

#[cfg(target_arch = "x86_64")]
mod avx2;

/// In which precision the unproject/project chain runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// As the exercise slides' shader: `iMVP_this` (inverted in f32) and `MVP_other` as f32 uniforms, two
    /// f32 products per pixel through world space. Loses accuracy as far/near grows: the
    /// inverse projection's entries grow like 1/near and cancel. On the real model at 1024 px
    /// width the texture coordinates are off by 2.3e-4 px at near/far = 1/20 but by 1.5 px at
    /// 1e-5 (tested).
    F32,
    /// `MVP_other · MVP_this⁻¹` composed once in f64 (on the host, as a uniform), rounded to
    /// f32, and applied per pixel in f32: one product, no trip through world space. What a
    /// WGSL mirror should do: 0.07 px at near/far = 1e-5 in the same test.
    F32Composed,
    /// `MVP_other · MVP_this⁻¹` composed and applied in f64 (the reference).
    #[default]
    F64,
}

/// Where a pixel of one eye lands in the other eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Remapped {
    /// Texture coordinates τ = ½(ndc_other.xy + 1) in the other eye: u right, v up.
    pub tex: [f64; 2],
    /// The point's window depth in the other eye, `½ ndc_other.z + ½`.
    pub depth: f64,
}

impl Remapped {
    /// The other eye's window position (pixels, y down, pixel centers at +0.5).
    pub fn window(&self, width: u32, height: u32) -> [f64; 2] {
        [
            self.tex[0] * width as f64,
            (1.0 - self.tex[1]) * height as f64,
        ]
    }

    /// The texel nearest filtering fetches, or `None` outside the other eye's image.
    pub fn texel(&self, width: u32, height: u32) -> Option<(u32, u32)> {
        let [x, y] = self.window(width, height);
        let (x, y) = (x.floor(), y.floor());
        (x >= 0.0 && y >= 0.0 && x < width as f64 && y < height as f64)
            .then_some((x as u32, y as u32))
    }
}

/// The per-pixel remapping program of one eye into the other, with its uniforms.
#[derive(Clone, Copy, Debug)]
pub struct Remapper {
    precision: Precision,
    width: u32,
    height: u32,
    inverse_this: Mat4,
    other: Mat4,
    this_to_other: DMat4,
    this_to_other_f32: Mat4,
}

impl Remapper {
    /// The uniforms for remapping from the eye with `this_mvp` into the eye with `other_mvp`,
    /// both rendering `width`×`height` images.
    ///
    /// # Errors
    /// `this_mvp` is not invertible (or not finite).
    pub fn new(
        this_mvp: &Mat4,
        other_mvp: &Mat4,
        width: u32,
        height: u32,
        precision: Precision,
    ) -> Result<Remapper> {
        let this64 = this_mvp.as_dmat4();
        let det = this64.determinant();
        if !(det.is_finite() && det != 0.0 && other_mvp.is_finite()) {
            return Err(Error::invalid(
                "eye matrices",
                format!("det(MVP) = {det}"),
                "the eye's MVP must be finite and invertible to unproject its pixels",
            ));
        }
        let this_to_other = other_mvp.as_dmat4() * this64.inverse();
        Ok(Remapper {
            precision,
            width,
            height,
            inverse_this: this_mvp.inverse(),
            other: *other_mvp,
            this_to_other,
            this_to_other_f32: this_to_other.as_mat4(),
        })
    }

    /// Normalized device x of column `x`'s pixel center, in f64: `2 (x + ½) / W − 1`.
    #[inline]
    fn ndc_x64(&self, x: u32) -> f64 {
        2.0 * (x as f64 + 0.5) / self.width as f64 - 1.0
    }

    /// Normalized device y of row `y`'s pixel centers, in f64 (row 0 at the top): `1 − 2 (y + ½) / H`.
    #[inline]
    fn ndc_y64(&self, y: u32) -> f64 {
        1.0 - 2.0 * (y as f64 + 0.5) / self.height as f64
    }

    /// [`Self::ndc_x64`] in f32, as the f32 shaders compute it.
    #[inline]
    fn ndc_x32(&self, x: u32) -> f32 {
        2.0 * (x as f32 + 0.5) / self.width as f32 - 1.0
    }

    /// [`Self::ndc_y64`] in f32, as the f32 shaders compute it.
    #[inline]
    fn ndc_y32(&self, y: u32) -> f32 {
        1.0 - 2.0 * (y as f32 + 0.5) / self.height as f32
    }

    /// The shader for pixel (x, y) of this eye with window depth `depth`: where its surface point
    /// lands in the other eye. `None` when the point is behind the other eye (w ≤ 0).
    #[inline]
    pub fn remap(&self, x: u32, y: u32, depth: f32) -> Option<Remapped> {
        match self.precision {
            Precision::F32 | Precision::F32Composed => {
                let ndc = Vec4::new(self.ndc_x32(x), self.ndc_y32(y), 2.0 * depth - 1.0, 1.0);
                let clip = if self.precision == Precision::F32 {
                    self.other * (self.inverse_this * ndc)
                } else {
                    self.this_to_other_f32 * ndc
                };
                (clip.w > 0.0).then(|| {
                    let n = clip.truncate() / clip.w;
                    Remapped {
                        tex: [0.5 * (n.x as f64 + 1.0), 0.5 * (n.y as f64 + 1.0)],
                        depth: 0.5 * n.z as f64 + 0.5,
                    }
                })
            }
            Precision::F64 => {
                let ndc = DVec4::new(
                    self.ndc_x64(x),
                    self.ndc_y64(y),
                    2.0 * depth as f64 - 1.0,
                    1.0,
                );
                let clip = self.this_to_other * ndc;
                (clip.w > 0.0).then(|| {
                    let n = clip.truncate() / clip.w;
                    Remapped {
                        tex: [0.5 * (n.x + 1.0), 0.5 * (n.y + 1.0)],
                        depth: 0.5 * n.z + 0.5,
                    }
                })
            }
        }
    }
}

/// Where every pixel of `this` lands in the other eye (row-major; `None` behind the other eye).
///
/// # Errors
/// A singular MVP.
pub fn remap_coordinates(
    this: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    precision: Precision,
) -> Result<Vec<Option<Remapped>>> {
    let r = Remapper::new(this_mvp, other_mvp, this.width, this.height, precision)?;
    Ok((0..this.height)
        .flat_map(|y| (0..this.width).map(move |x| (x, y)))
        .map(|(x, y)| r.remap(x, y, this.depth[this.index(x, y)]))
        .collect())
}

/// `this` eye's view recolored from the `other` eye: each pixel takes the other eye's color at
/// its remapped position. Reads this eye's depth and the other eye's color only; regions the
/// other eye cannot see show whatever the other eye sees there instead, which is what makes
/// occlusions visible (the exercise slides). Pixels where this eye drew nothing (depth 1) have no surface
/// point to remap and stay black; points outside the other image get
/// [`OUT_OF_VIEW_COLOR`](super::occlusion::OUT_OF_VIEW_COLOR).
///
/// The scalar loop over [`remap_color_pixel`]: the definition [`remap_color`] runs faster with
/// the same bytes (the benchmark times both).
///
/// # Errors
/// Different sizes, or a singular MVP.
pub fn remap_color_reference(
    this: &Framebuffer,
    other: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    precision: Precision,
) -> Result<RgbaImage> {
    remap_color_on(this, other, this_mvp, other_mvp, precision, Kernels::Scalar)
}

/// [`remap_color_reference`]'s bytes, on the AVX2 rows where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)).
///
/// # Errors
/// As [`remap_color_reference`].
pub fn remap_color(
    this: &Framebuffer,
    other: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    precision: Precision,
) -> Result<RgbaImage> {
    remap_color_on(this, other, this_mvp, other_mvp, precision, kernels())
}

/// The recolored view on the loops `kernels` names.
fn remap_color_on(
    this: &Framebuffer,
    other: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    precision: Precision,
    kernels: Kernels,
) -> Result<RgbaImage> {
    check_same_size(this, other)?;
    let r = Remapper::new(this_mvp, other_mvp, this.width, this.height, precision)?;
    let (w, h) = (this.width, this.height);
    let rows = RowProgram::new(&r, kernels);
    // Rows in parallel: every pixel is independent, so the bytes do not depend on the threads.
    let wu = w.max(1) as usize;
    let fill = |y: usize, out: &mut [MaybeUninit<[u8; 4]>]| {
        let depth = &this.depth[y * wu..y * wu + out.len()];
        rows.run(other, y as u32, depth, out);
    };
    // SAFETY: `RowProgram::run` writes one pixel per depth value of the row, and the depth row
    // is as long as the output row (a framebuffer holds width × height depths).
    let bytes = unsafe { super::par_fill_rows(this.depth.len(), wu, fill) };
    Ok(RgbaImage::from_raw(w, h, bytes).expect("4 bytes per pixel"))
}

/// [`remap_color`] one row at a time: the remapper, and each column's normalized device x
/// computed once per image instead of once per pixel (the same expression, so the same value).
struct RowProgram<'a> {
    remapper: &'a Remapper,
    /// Whether rows run on the AVX2 loops (`avx2::row_f64`, `avx2::row_f32`).
    simd: bool,
    ndc_x64: Vec<f64>,
    ndc_x32: Vec<f32>,
}

impl<'a> RowProgram<'a> {
    /// The program for `remapper` on the loops `kernels` names; the AVX2 rows run only where
    /// the CPU has AVX2 and every texel index fits an `i32`.
    fn new(remapper: &'a Remapper, kernels: Kernels) -> Self {
        let pixels = remapper.width as u64 * remapper.height as u64;
        let simd = kernels.avx2() && pixels < i32::MAX as u64;
        let (mut ndc_x64, mut ndc_x32) = (Vec::new(), Vec::new());
        if simd {
            let cols = 0..remapper.width;
            match remapper.precision {
                Precision::F64 => ndc_x64 = cols.map(|x| remapper.ndc_x64(x)).collect(),
                Precision::F32 | Precision::F32Composed => {
                    ndc_x32 = cols.map(|x| remapper.ndc_x32(x)).collect();
                }
            }
        }
        RowProgram {
            remapper,
            simd,
            ndc_x64,
            ndc_x32,
        }
    }

    /// Row `y` of [`remap_color`]: `out[x] = remap_color_pixel(r, other, x, y, depth[x])` for
    /// every `x < min(out.len(), depth.len())`.
    fn run(&self, other: &Framebuffer, y: u32, depth: &[f32], out: &mut [MaybeUninit<[u8; 4]>]) {
        #[cfg(target_arch = "x86_64")]
        if self.simd {
            let r = self.remapper;
            // SAFETY: `simd` is set only where `Kernels::avx2` found AVX2, the rows' only
            // safety condition. The same bytes as the loop below
            // (`avx2_rows_match_remap_color_pixel`).
            unsafe {
                match r.precision {
                    Precision::F64 => avx2::row_f64(r, &self.ndc_x64, y, depth, other, out),
                    Precision::F32 | Precision::F32Composed => {
                        avx2::row_f32(r, &self.ndc_x32, y, depth, other, out)
                    }
                }
            }
            return;
        }
        for (x, (out, d)) in out.iter_mut().zip(depth).enumerate() {
            out.write(remap_color_pixel(self.remapper, other, x as u32, y, *d));
        }
    }
}

/// One pixel of [`remap_color`]: the other eye's color at the remapped texel.
#[inline]
pub fn remap_color_pixel(r: &Remapper, other: &Framebuffer, x: u32, y: u32, depth: f32) -> [u8; 4] {
    if depth >= 1.0 {
        return super::occlusion::BACKGROUND_COLOR;
    }
    r.remap(x, y, depth)
        .and_then(|m| m.texel(other.width, other.height))
        .map_or(super::occlusion::OUT_OF_VIEW_COLOR, |(tx, ty)| {
            other.pixel(tx, ty)
        })
}

/// What the other eye sees of a surface point this eye sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Visibility {
    /// This eye sees nothing here (depth 1: the cleared far plane).
    Background,
    /// The other eye sees the same surface point.
    Visible,
    /// Something nearer hides the point from the other eye.
    Occluded,
    /// The point lies outside the other eye's image (or behind it).
    OutOfView,
    /// The other eye's depth there is *farther* than the point. Impossible for exact geometry
    /// (the exercise slides: "if violated, only d₁ < d₀ possible"); it happens only where nearest
    /// sampling at a silhouette fetches the background next to the surface.
    Farther,
}

/// Depth-precision part of the visibility tolerance, in window-depth units: 8·2⁻²⁴.
///
/// A window depth is an f32 in [0, 1]; near 1 (where every depth of a scene with a large
/// far/near ratio crowds) one unit in the last place is 2⁻²⁴. Each eye's depth comes from the
/// rasterizer's plane equation `z0 + dz/dx·Δx + dz/dy·Δy` (terms up to ~1, three roundings)
/// and one store, so each is within ~4 ulps of the exact window depth; the two eyes together
/// give 8. The remapped depth itself (computed in f64 by default) adds nothing measurable.
pub const DEPTH_PRECISION: f64 = 8.0 / 16_777_216.0;

/// The local depth slope of `fb` at (x, y), in window depth per pixel: for each axis the
/// smaller of the two one-sided differences (so a silhouette on one side does not widen the
/// tolerance), summed over x and y. A shader reads the same four neighbours with `texelFetch`.
#[inline]
pub fn depth_slope(fb: &Framebuffer, x: u32, y: u32) -> f64 {
    let d = |x: u32, y: u32| fb.depth[fb.index(x, y)] as f64;
    let c = d(x, y);
    let one_sided = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) => (a - c).abs().min((b - c).abs()),
        (Some(v), None) | (None, Some(v)) => (v - c).abs(),
        (None, None) => 0.0,
    };
    let gx = one_sided(
        x.checked_sub(1).map(|x| d(x, y)),
        (x + 1 < fb.width).then(|| d(x + 1, y)),
    );
    let gy = one_sided(
        y.checked_sub(1).map(|y| d(x, y)),
        (y + 1 < fb.height).then(|| d(x, y + 1)),
    );
    gx + gy
}

/// The visibility tolerance at a pixel: `DEPTH_PRECISION + slope_x + slope_y`.
///
/// Why the slope: nearest filtering fetches the other eye's texel center, up to half a pixel
/// from the remapped point in x and in y, so on a sloped surface the fetched depth differs
/// from the remapped one by up to ½·(|∂d/∂x| + |∂d/∂y|). The slope is measured in this eye;
/// the other eye sees the surface stretched or squeezed horizontally by the parallax gradient,
/// so a full pixel's worth (a factor 2) is allowed.
#[inline]
pub fn tolerance(slope: f64) -> f64 {
    DEPTH_PRECISION + slope
}

/// The visibility check for one pixel (the exercise slides): the other eye's depth `other_depth` at the
/// remapped texel against the remapped depth, within `tolerance`. `target` is `None` when the
/// point falls outside the other image.
#[inline]
pub fn classify(this_depth: f32, target: Option<(Remapped, f32)>, tolerance: f64) -> Visibility {
    if this_depth >= 1.0 {
        return Visibility::Background;
    }
    let Some((r, other_depth)) = target else {
        return Visibility::OutOfView;
    };
    let diff = other_depth as f64 - r.depth;
    if diff.abs() <= tolerance {
        Visibility::Visible
    } else if diff < 0.0 {
        Visibility::Occluded
    } else {
        Visibility::Farther
    }
}

/// The visibility of every pixel of `this` in `other` (row-major). Reads both depth buffers only.
///
/// # Errors
/// Different sizes, or a singular MVP.
pub fn visibility_map(
    this: &Framebuffer,
    other: &Framebuffer,
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    precision: Precision,
) -> Result<Vec<Visibility>> {
    check_same_size(this, other)?;
    let r = Remapper::new(this_mvp, other_mvp, this.width, this.height, precision)?;
    let (w, h) = (this.width, this.height);
    // Rows in parallel, collected in order: the same map for any thread count.
    let out = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            let r = &r;
            (0..w).map(move |x| {
                let d = this.depth[this.index(x, y)];
                if d >= 1.0 {
                    return Visibility::Background; // what `classify` says, without the remap
                }
                let target = r.remap(x, y, d).and_then(|m| {
                    m.texel(w, h)
                        .map(|(tx, ty)| (m, other.depth[other.index(tx, ty)]))
                });
                classify(d, target, tolerance(depth_slope(this, x, y)))
            })
        })
        .collect();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// `remap_color` gives the same bytes on the AVX2 rows and on the scalar loop, for every
    /// precision, on an odd-sized pair with background, near-plane and scattered depths.
    #[test]
    fn remap_color_rows_agree() {
        let (w, h) = (37, 23);
        let proj = crate::math::perspective(50.0, w as f32 / h as f32, 0.1, 50.0);
        let eye = |x: f32| proj * crate::math::look_at(Vec3::new(x, 0.3, 4.0), Vec3::ZERO, Vec3::Y);
        let mut this = Framebuffer::new(w, h, [0, 0, 0, 255]).unwrap();
        let mut other = Framebuffer::new(w, h, [0, 0, 0, 255]).unwrap();
        let mut state = 0x1234_5678_9abc_def1_u64;
        for (i, (d, c)) in this.depth.iter_mut().zip(&mut other.color).enumerate() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            *d = match state % 5 {
                0 => 1.0,
                1 => 0.0,
                _ => (state >> 20) as f32 / (1u64 << 44) as f32,
            };
            *c = (i as u32).wrapping_mul(2_654_435_761).to_le_bytes();
        }
        for precision in [Precision::F64, Precision::F32Composed, Precision::F32] {
            let run = |kernels| {
                remap_color_on(&this, &other, &eye(-0.3), &eye(0.3), precision, kernels).unwrap()
            };
            assert_eq!(run(Kernels::Avx2), run(Kernels::Scalar), "{precision:?}");
        }
    }
}
