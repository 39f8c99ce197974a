//! The strip pass's two per-pixel loops eight pixels at a time (AVX2), as llvmpipe runs its
//! fragment stage: [`span_sources`] mirrors [`super::span_sources`], [`resolve_row`] mirrors
//! [`super::resolve_row`].
//!
//! Each lane performs the scalar loop's IEEE operations in the same order (no fused
//! multiply-add, which would round once instead of twice), so the bytes are the same as the
//! scalar path's; the unit test `avx2_strips_match_scalar_strips` holds them equal. Lanes past
//! the end of a span are masked off, never loaded or stored.

use std::arch::x86_64::*;

use super::SpanTarget;
use crate::raster::{Plane, SetupTriangle};

/// Lane indices 0..8.
#[target_feature(enable = "avx2")]
fn lane_ids() -> __m256i {
    _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
}

/// Lanes `< remaining` set.
#[target_feature(enable = "avx2")]
fn tail_mask(remaining: usize) -> __m256i {
    _mm256_cmpgt_epi32(_mm256_set1_epi32(remaining.min(8) as i32), lane_ids())
}

/// `plane.at(fx, fy)` per lane: `(a0 + dadx·fx) + dady·fy`.
#[target_feature(enable = "avx2")]
fn plane_at(p: &Plane, fx: __m256, fy: f32) -> __m256 {
    let row = _mm256_set1_ps(p.dady * fy);
    _mm256_add_ps(
        _mm256_add_ps(
            _mm256_set1_ps(p.a0),
            _mm256_mul_ps(_mm256_set1_ps(p.dadx), fx),
        ),
        row,
    )
}

/// `v.clamp(0, 1)` per lane, NaN kept (as `f32::clamp`).
#[target_feature(enable = "avx2")]
fn clamp01(v: __m256) -> __m256 {
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let v = _mm256_blendv_ps(v, zero, _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero));
    _mm256_blendv_ps(v, one, _mm256_cmp_ps::<_CMP_GT_OQ>(v, one))
}

/// `⌊v⌋` per lane for `|v| < 2³¹`: truncate, then step down where that rounded up.
#[target_feature(enable = "avx2")]
fn floor_i32(v: __m256) -> __m256i {
    let i = _mm256_cvttps_epi32(v);
    let above = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(i), v);
    _mm256_add_epi32(i, _mm256_castps_si256(above))
}

/// One covered span of triangle `t` in row `y`, pixels `x_lo ..` (as many as `depth` holds):
/// depth test LESS, source coordinate, bounds test, and the winners' depth and source written.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn span_sources(
    t: &SetupTriangle,
    y: u32,
    x_lo: u32,
    depth: &mut [f32],
    sources: &mut [f32],
    target: &SpanTarget,
) {
    let n = depth.len().min(sources.len());
    let (ox, _) = t.origin();
    let fy = t.fy(y);
    let (zp, wp, vp) = (t.depth_plane(), t.inv_w_plane(), t.varying_plane(0));
    let (half, one) = (_mm256_set1_ps(0.5), _mm256_set1_ps(1.0));
    let toward = _mm256_set1_ps(target.toward);
    let (lo, hi) = (_mm256_set1_ps(target.lo), _mm256_set1_ps(target.hi));
    let hi_last = _mm256_set1_ps(target.hi - 1.0);
    let mut k = 0;
    while k < n {
        let mask = tail_mask(n - k);
        let x = _mm256_add_epi32(_mm256_set1_epi32((x_lo as usize + k) as i32), lane_ids());
        let xf = _mm256_cvtepi32_ps(x);
        let fx = _mm256_sub_ps(_mm256_add_ps(xf, half), _mm256_set1_ps(ox));
        let z = clamp01(plane_at(&zp, fx, fy));
        let w = if target.perspective_correct {
            _mm256_div_ps(one, plane_at(&wp, fx, fy))
        } else {
            one
        };
        let sep = _mm256_mul_ps(plane_at(&vp, fx, fy), w);
        let src = _mm256_sub_ps(xf, _mm256_mul_ps(toward, sep));
        let inside = if target.bilinear {
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(src, lo),
                _mm256_cmp_ps::<_CMP_LE_OQ>(src, hi_last),
            )
        } else {
            let q = _mm256_add_ps(src, half);
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(q, lo),
                _mm256_cmp_ps::<_CMP_LT_OQ>(q, hi),
            )
        };
        // SAFETY: the mask covers lanes k .. min(k + 8, n), inside both slices.
        unsafe {
            let (dp, sp) = (depth.as_mut_ptr().add(k), sources.as_mut_ptr().add(k));
            let d = _mm256_maskload_ps(dp, mask);
            let s = _mm256_maskload_ps(sp, mask);
            let wins = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(z, d), inside);
            _mm256_maskstore_ps(dp, mask, _mm256_blendv_ps(d, z, wins));
            _mm256_maskstore_ps(sp, mask, _mm256_blendv_ps(s, src, wins));
        }
        k += 8;
    }
}

/// One strip's pixels `x0 .. x0 + out.len()` of one row: each pixel with a source takes
/// `row`'s color there (bilinear: the two neighbors mixed per channel and rounded), the others
/// the pattern. `row` is not written (the strip's old pixels stay readable).
///
/// # Safety
/// The CPU must support AVX2; every source in `sources` is NaN or inside `row` (as
/// [`super::in_bounds`] ensured).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn resolve_row(
    row: &[[u8; 4]],
    sources: &[f32],
    x0: usize,
    out: &mut [[u8; 4]],
    bilinear: bool,
    pattern: impl Fn(usize) -> [u8; 4],
) {
    let n = out.len();
    assert!(x0 + n <= row.len() && x0 + n <= sources.len());
    let base = row.as_ptr() as *const i32;
    let half = _mm256_set1_ps(0.5);
    let byte = _mm256_set1_epi32(0xff);
    let mut k = 0;
    while k < n {
        let mask = tail_mask(n - k);
        // SAFETY: the mask covers lanes k .. min(k + 8, n), inside `row`, `sources` and `out`
        // (asserted); gathered indices are in bounds (NaN lanes gather pixel 0).
        unsafe {
            let p = _mm256_maskload_ps(sources.as_ptr().add(x0 + k), mask);
            let has = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_ORD_Q>(p, p));
            let color = if bilinear {
                let i0 = _mm256_and_si256(floor_i32(p), has);
                let t = _mm256_sub_ps(p, _mm256_cvtepi32_ps(i0));
                let mixes = _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_setzero_ps());
                let i1 = _mm256_sub_epi32(i0, _mm256_castps_si256(mixes));
                let a = _mm256_i32gather_epi32::<4>(base, i0);
                let b = _mm256_i32gather_epi32::<4>(base, i1);
                // a + (b − a)·t + ½ per channel, truncated: the nearest level.
                let channel = |shift: __m128i| {
                    let ca = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(a, shift), byte));
                    let cb = _mm256_cvtepi32_ps(_mm256_and_si256(_mm256_srl_epi32(b, shift), byte));
                    let m = _mm256_add_ps(
                        _mm256_add_ps(ca, _mm256_mul_ps(_mm256_sub_ps(cb, ca), t)),
                        half,
                    );
                    _mm256_sll_epi32(_mm256_cvttps_epi32(m), shift)
                };
                let rgb = _mm256_or_si256(
                    _mm256_or_si256(channel(_mm_cvtsi32_si128(0)), channel(_mm_cvtsi32_si128(8))),
                    channel(_mm_cvtsi32_si128(16)),
                );
                let mixed = _mm256_or_si256(rgb, _mm256_set1_epi32(0xff00_0000u32 as i32));
                // A whole-pixel source copies that pixel, alpha included.
                _mm256_blendv_epi8(a, mixed, _mm256_castps_si256(mixes))
            } else {
                let i = _mm256_and_si256(floor_i32(_mm256_add_ps(p, half)), has);
                _mm256_i32gather_epi32::<4>(base, i)
            };
            _mm256_maskstore_epi32(out.as_mut_ptr().add(k) as *mut i32, mask, color);
            // Lanes without a source (the first strip, discarded fragments): the pattern.
            let missing =
                !_mm256_movemask_ps(_mm256_castsi256_ps(has)) & ((1 << (n - k).min(8)) - 1);
            if missing != 0 {
                for lane in (0..8).filter(|l| missing & (1 << l) != 0) {
                    out[k + lane] = pattern(x0 + k + lane);
                }
            }
        }
        k += 8;
    }
}
