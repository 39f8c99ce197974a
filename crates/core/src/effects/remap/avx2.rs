//! [`remap_color_pixel`](super::remap_color_pixel) for a row of pixels, four (f64) or eight
//! (f32) at a time (AVX2).
//!
//! Each lane performs [`Remapper::remap`](super::Remapper::remap)'s IEEE operations in the same
//! order, with no fused multiply-add: the matrix–vector product as glam computes it,
//! `((c₀·x + c₁·y) + c₂·z) + c₃·w` per component, the w-divide, `τ = ½ (n + 1)`, the window
//! position, `floor` and the bounds test of [`Remapped::texel`](super::Remapped::texel). The
//! per-column normalized device x comes from a table the caller fills with the scalar
//! expression, the per-row terms (`c₁·y`) are computed once per row in scalar code: the same
//! operations on the same values, so the same bits. The depth component of the w-divide is not
//! computed: `remap_color` does not read it. Vectors whose pixels are all background skip the
//! arithmetic, as the scalar code does per pixel. The tests hold every precision to the scalar
//! function on odd widths, points behind the other eye, outside its image and on its edges.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::{Precision, Remapper};
use crate::effects::occlusion::{BACKGROUND_COLOR, OUT_OF_VIEW_COLOR};
use crate::framebuffer::Framebuffer;

/// The texel part of four remapped points: `τ` (per lane, f64) to the other eye's window
/// position, `floor`, the bounds test. Returns the lanes inside the image (bit k for lane k)
/// and each lane's row-major texel index (meaningful only where inside; `W·H < 2³¹`).
#[target_feature(enable = "avx2")]
#[inline]
fn texels(tex0: __m256d, tex1: __m256d, w: f64, h: f64) -> (i32, [i32; 4]) {
    let (zero, one) = (_mm256_setzero_pd(), _mm256_set1_pd(1.0));
    let (wv, hv) = (_mm256_set1_pd(w), _mm256_set1_pd(h));
    // `Remapped::window`: [τ₀·W, (1 − τ₁)·H].
    let x = _mm256_floor_pd(_mm256_mul_pd(tex0, wv));
    let y = _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(one, tex1), hv));
    // `x >= 0 && y >= 0 && x < W && y < H`, false for NaN (ordered compares).
    let inside = _mm256_and_pd(
        _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GE_OQ>(x, zero),
            _mm256_cmp_pd::<_CMP_GE_OQ>(y, zero),
        ),
        _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_LT_OQ>(x, wv),
            _mm256_cmp_pd::<_CMP_LT_OQ>(y, hv),
        ),
    );
    // y·W + x is an integer below W·H < 2³¹ where inside: exact in f64 and in i32.
    let index = _mm256_cvttpd_epi32(_mm256_add_pd(_mm256_mul_pd(y, wv), x));
    let mut out = [0i32; 4];
    // SAFETY: `out` holds 16 bytes; the unaligned store needs no alignment.
    unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), index) };
    (_mm256_movemask_pd(inside), out)
}

/// `out[..8].fill(rgba)` as one 32-byte store (the slice fill compiles to eight 4-byte stores).
#[target_feature(enable = "avx2")]
#[inline]
fn fill8(out: &mut [MaybeUninit<[u8; 4]>], rgba: [u8; 4]) {
    assert!(out.len() >= 8);
    // SAFETY: eight pixels (32 bytes) are in bounds (asserted); the unaligned store needs no
    // alignment.
    unsafe {
        _mm256_storeu_si256(
            out.as_mut_ptr().cast(),
            _mm256_set1_epi32(i32::from_le_bytes(rgba)),
        );
    }
}

/// Writes `n` pixels from lane results: background where `background` has the lane's bit,
/// else the other eye's texel where `inside` (and `front`) has it, else the out-of-view color.
#[inline(always)]
fn store(
    out: &mut [MaybeUninit<[u8; 4]>],
    other: &[[u8; 4]],
    background: i32,
    inside: i32,
    index: &[i32],
) {
    for (j, (out, i)) in out.iter_mut().zip(index).enumerate() {
        out.write(if background >> j & 1 != 0 {
            BACKGROUND_COLOR
        } else if inside >> j & 1 != 0 {
            other[*i as usize]
        } else {
            OUT_OF_VIEW_COLOR
        });
    }
}

/// Row `y` of `remap_color` in f64 ([`Precision::F64`]): `out[x] = remap_color_pixel(r,
/// other, x, y, depth[x])`, eight pixels per step as two vectors of four (the last few through
/// the scalar function).
/// `ndc_x[x]` must be `r.ndc_x64(x)`; `other` is the other eye, `r.width × r.height` pixels
/// with `r.width · r.height < 2³¹`.
///
/// # Safety
/// The CPU must support AVX2 ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn row_f64(
    r: &Remapper,
    ndc_x: &[f64],
    y: u32,
    depth: &[f32],
    other: &Framebuffer,
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    debug_assert_eq!(r.precision, Precision::F64);
    let m = &r.this_to_other;
    let ny = r.ndc_y64(y);
    let (w, h) = (r.width as f64, r.height as f64);
    let (one, half, two) = (
        _mm256_set1_pd(1.0),
        _mm256_set1_pd(0.5),
        _mm256_set1_pd(2.0),
    );
    // Component c of `m · (nx, ny, nz, 1)`, as glam's `DMat4 * DVec4`: x_axis·nx + y_axis·ny,
    // + z_axis·nz, + w_axis·1 (= w_axis exactly).
    let coef = |c: usize| {
        (
            _mm256_set1_pd(m.x_axis[c]),
            _mm256_set1_pd(m.y_axis[c] * ny),
            _mm256_set1_pd(m.z_axis[c]),
            _mm256_set1_pd(m.w_axis[c]),
        )
    };
    let (cx, cy, cw) = (coef(0), coef(1), coef(3));
    let clip = |(a, b, c, d): (__m256d, __m256d, __m256d, __m256d), nx, nz| {
        let v = _mm256_add_pd(_mm256_mul_pd(a, nx), b);
        _mm256_add_pd(_mm256_add_pd(v, _mm256_mul_pd(c, nz)), d)
    };
    let n = out.len().min(depth.len()).min(ndc_x.len());
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: `k + 8 <= n`, so eight values are in bounds in `depth` and `ndc_x`; the
        // unaligned loads need no alignment.
        let (d8, nx) = unsafe {
            (
                _mm256_loadu_ps(depth.as_ptr().add(k)),
                [0, 4].map(|h| _mm256_loadu_pd(ndc_x.as_ptr().add(k + h))),
            )
        };
        // `depth >= 1.0`: background, no remap (as `remap_color_pixel`).
        let background = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(d8, _mm256_set1_ps(1.0)));
        let out8 = &mut out[k..k + 8];
        if background == 0xff {
            fill8(out8, BACKGROUND_COLOR);
            k += 8;
            continue;
        }
        for (part, d32) in [_mm256_castps256_ps128(d8), _mm256_extractf128_ps::<1>(d8)]
            .into_iter()
            .enumerate()
        {
            let nx = nx[part];
            let nz = _mm256_sub_pd(_mm256_mul_pd(two, _mm256_cvtps_pd(d32)), one);
            let (x, y, wc) = (clip(cx, nx, nz), clip(cy, nx, nz), clip(cw, nx, nz));
            let front = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(wc, _mm256_setzero_pd()));
            let tex0 = _mm256_mul_pd(half, _mm256_add_pd(_mm256_div_pd(x, wc), one));
            let tex1 = _mm256_mul_pd(half, _mm256_add_pd(_mm256_div_pd(y, wc), one));
            let (inside, index) = texels(tex0, tex1, w, h);
            store(
                &mut out8[4 * part..4 * part + 4],
                &other.color,
                background >> (4 * part),
                inside & front,
                &index,
            );
        }
        k += 8;
    }
    for k in k..n {
        out[k].write(super::remap_color_pixel(r, other, k as u32, y, depth[k]));
    }
}

/// Row `y` of `remap_color` in f32 ([`Precision::F32Composed`], or [`Precision::F32`]'s two
/// products through world space): as [`row_f64`], eight pixels at a time; the w-divide in f32,
/// `τ` and the texel in f64 as `Remapper::remap` does. `ndc_x[x]` must be `r.ndc_x32(x)`.
///
/// # Safety
/// The CPU must support AVX2 ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn row_f32(
    r: &Remapper,
    ndc_x: &[f32],
    y: u32,
    depth: &[f32],
    other: &Framebuffer,
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    debug_assert_ne!(r.precision, Precision::F64);
    let ny = r.ndc_y32(y);
    let (w, h) = (r.width as f64, r.height as f64);
    let (one, two) = (_mm256_set1_ps(1.0), _mm256_set1_ps(2.0));
    // Component c of `m · (v0, v1, v2, v3)` as glam's `Mat4 * Vec4`; `row` is `Some(v1)` when
    // v1 is the same for every lane (then `m.y_axis[c]·v1` is computed once), `v3 = None`
    // stands for 1 (`w_axis·1 = w_axis` exactly).
    #[derive(Clone, Copy)]
    struct Coef {
        a: __m256,
        b: __m256,
        c: __m256,
        d: __m256,
    }
    let coef = |m: &glam::Mat4, c: usize, row: Option<f32>| Coef {
        a: _mm256_set1_ps(m.x_axis[c]),
        b: _mm256_set1_ps(row.map_or(m.y_axis[c], |v| m.y_axis[c] * v)),
        c: _mm256_set1_ps(m.z_axis[c]),
        d: _mm256_set1_ps(m.w_axis[c]),
    };
    // `((a·v0 + b·v1) + c·v2) + d·v3`; with the row term folded in, `b` is `b·v1` already.
    let apply = |k: Coef, v0: __m256, v1: Option<__m256>, v2: __m256, v3: Option<__m256>| {
        let bv = v1.map_or(k.b, |v1| _mm256_mul_ps(k.b, v1));
        let dv = v3.map_or(k.d, |v3| _mm256_mul_ps(k.d, v3));
        let s = _mm256_add_ps(_mm256_mul_ps(k.a, v0), bv);
        _mm256_add_ps(_mm256_add_ps(s, _mm256_mul_ps(k.c, v2)), dv)
    };
    let composed = r.precision == Precision::F32Composed;
    let first = if composed {
        &r.this_to_other_f32
    } else {
        &r.inverse_this
    };
    let k1 = [0, 1, 2, 3].map(|c| coef(first, c, Some(ny)));
    let k2 = [0, 1, 2, 3].map(|c| coef(&r.other, c, None));
    let half = _mm256_set1_pd(0.5);
    let one64 = _mm256_set1_pd(1.0);
    let n = out.len().min(depth.len()).min(ndc_x.len());
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: `k + 8 <= n`, so eight values are in bounds in `depth` and `ndc_x`.
        let (d, nx) = unsafe {
            (
                _mm256_loadu_ps(depth.as_ptr().add(k)),
                _mm256_loadu_ps(ndc_x.as_ptr().add(k)),
            )
        };
        let background = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(d, one));
        let out8 = &mut out[k..k + 8];
        if background == 0xff {
            fill8(out8, BACKGROUND_COLOR);
            k += 8;
            continue;
        }
        let nz = _mm256_sub_ps(_mm256_mul_ps(two, d), one);
        let first = |c: usize| apply(k1[c], nx, None, nz, None);
        let (x, y, wc) = if composed {
            (first(0), first(1), first(3))
        } else {
            // `other · (inverse_this · ndc)`: the world point first, all four components.
            let world = [0, 1, 2, 3].map(first);
            let q = |c: usize| apply(k2[c], world[0], Some(world[1]), world[2], Some(world[3]));
            (q(0), q(1), q(3))
        };
        let front = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(wc, _mm256_setzero_ps()));
        let (nx_o, ny_o) = (_mm256_div_ps(x, wc), _mm256_div_ps(y, wc));
        // τ in f64 from the f32 quotient, half a vector at a time.
        let tex = |v: __m256, hi: bool| {
            let v = if hi {
                _mm256_extractf128_ps::<1>(v)
            } else {
                _mm256_castps256_ps128(v)
            };
            _mm256_mul_pd(half, _mm256_add_pd(_mm256_cvtps_pd(v), one64))
        };
        for (hi, part) in [(false, 0), (true, 4)] {
            let (inside, index) = texels(tex(nx_o, hi), tex(ny_o, hi), w, h);
            store(
                &mut out8[part..part + 4],
                &other.color,
                background >> part,
                inside & (front >> part),
                &index,
            );
        }
        k += 8;
    }
    for k in k..n {
        out[k].write(super::remap_color_pixel(r, other, k as u32, y, depth[k]));
    }
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec3};

    use super::super::{Precision, Remapper, remap_color_pixel};
    use super::*;

    /// Two eyes of a stereo rig looking at the origin, `width`×`height`, with the other eye's
    /// colors all different (so a wrong texel shows).
    fn case(width: u32, height: u32, near: f32) -> (Framebuffer, Mat4, Mat4) {
        let proj = crate::math::perspective(50.0, width as f32 / height as f32, near, 50.0);
        let eye = |x: f32| proj * crate::math::look_at(Vec3::new(x, 0.3, 4.0), Vec3::ZERO, Vec3::Y);
        let mut other = Framebuffer::new(width, height, [0, 0, 0, 255]).unwrap();
        for (i, c) in other.color.iter_mut().enumerate() {
            *c = (i as u32).wrapping_mul(2_654_435_761).to_le_bytes();
        }
        (other, eye(-0.4), eye(0.4))
    }

    /// Every precision's AVX2 row gives `remap_color_pixel`'s bytes: odd widths (tails of
    /// every length), depths spread over [0, 1] with background (1.0), near-plane (0.0) and
    /// values whose points fall behind the other eye, outside its image and on its edges, and a
    /// rig whose other eye looks the opposite way (w ≤ 0 for most points).
    #[test]
    fn avx2_rows_match_remap_color_pixel() {
        if !crate::simd::avx2_available() {
            eprintln!(
                "avx2_rows_match_remap_color_pixel: NOT RUN: no AVX2 here, nothing to compare"
            );
            return;
        }
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut checked = 0usize;
        for (width, height, near) in [
            (1, 1, 0.1),
            (7, 5, 0.1),
            (13, 9, 1e-4),
            (67, 31, 0.5),
            (256, 3, 0.01),
        ] {
            let (other, this_mvp, other_mvp) = case(width, height, near);
            let flipped = Mat4::from_rotation_y(std::f32::consts::PI) * other_mvp;
            for (a, b) in [
                (this_mvp, other_mvp),
                (other_mvp, this_mvp),
                (this_mvp, flipped),
            ] {
                for precision in [Precision::F64, Precision::F32Composed, Precision::F32] {
                    let r = Remapper::new(&a, &b, width, height, precision).unwrap();
                    let x64: Vec<f64> = (0..width).map(|x| r.ndc_x64(x)).collect();
                    let x32: Vec<f32> = (0..width).map(|x| r.ndc_x32(x)).collect();
                    for y in 0..height {
                        let depth: Vec<f32> = (0..width)
                            .map(|_| match next() % 8 {
                                0 => 1.0,
                                1 => 0.0,
                                2 => 1.0 - (next() % 1000) as f32 * 1e-6,
                                _ => (next() % 1_000_001) as f32 / 1e6,
                            })
                            .collect();
                        let mut fast = vec![MaybeUninit::new([1u8; 4]); width as usize];
                        // SAFETY: AVX2 is available (checked above).
                        unsafe {
                            match precision {
                                Precision::F64 => row_f64(&r, &x64, y, &depth, &other, &mut fast),
                                _ => row_f32(&r, &x32, y, &depth, &other, &mut fast),
                            }
                        }
                        for (x, (f, d)) in fast.iter().zip(&depth).enumerate() {
                            let want = remap_color_pixel(&r, &other, x as u32, y, *d);
                            // SAFETY: initialized by `MaybeUninit::new`, then the row.
                            let f = unsafe { f.assume_init() };
                            assert_eq!(
                                f, want,
                                "{precision:?} {width}x{height}: pixel ({x}, {y}), depth {d}"
                            );
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked} pixels compared");
    }
}
