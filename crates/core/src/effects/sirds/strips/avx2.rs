//! The strip pass's two per-pixel loops eight pixels at a time (AVX2), as llvmpipe runs its
//! fragment stage: [`triangle_sources`] mirrors [`super::span_sources`], [`resolve_row`]
//! mirrors [`super::resolve_row`].
//!
//! Each lane performs the scalar loop's IEEE operations in the same order (no fused
//! multiply-add, which would round once instead of twice), so the bytes are the same as the
//! scalar path's; the pipeline's `avx2_strips_match_scalar_strips` holds them equal on real scenes. Lanes past
//! the end of a span are masked off, never loaded or stored.

use std::arch::x86_64::*;

use super::{Region, SpanTarget, Strip};
use crate::raster::SetupTriangle;
use crate::raster::avx2::{
    columns, covered_vectors, depth_at, floor_i32, load, opaque, plane_at, store, tail_mask,
};

/// [`super::span_sources`] for every pixel of triangle `t` in region `r` of the band starting
/// at row `y0` (`rows` rows of `width` pixels), eight pixels at a time ([`covered_vectors`]:
/// small triangles a vector per row).
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn triangle_sources(
    t: &SetupTriangle,
    r: &Region,
    (width, y0, rows): (u32, u32, u32),
    depth: &mut [f32],
    sources: &mut [f32],
) {
    let w = width as usize;
    covered_vectors(t, (r.x0, y0, r.x1 - r.x0, rows), |y, x, mask| {
        let i = (y - y0) as usize * w + x as usize;
        // SAFETY: this function runs only where AVX2 is available.
        unsafe { sources_vector(t, y, x, mask, &mut depth[i..], &mut sources[i..], &r.target) };
    });
}

/// Pixels `x .. x + 8` of row `y` where `mask` is set, for triangle `t`: depth test LESS,
/// source coordinate, bounds test, and the winners' depth and source written into `depth` and
/// `sources` (both starting at pixel `x`). Hidden vectors stop after the depth test.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn sources_vector(
    t: &SetupTriangle,
    y: u32,
    x: u32,
    mask: __m256i,
    depth: &mut [f32],
    sources: &mut [f32],
    target: &SpanTarget,
) {
    let full = depth.len().min(sources.len()) >= 8;
    let fy = t.fy(y);
    let half = _mm256_set1_ps(0.5);
    let (xf, fx) = columns(t, x);
    let z = depth_at(t, xf, y);
    let (dp, sp) = (depth.as_mut_ptr(), sources.as_mut_ptr());
    // SAFETY: eight lanes fit in both when `full`; otherwise `mask` covers only covered
    // pixels, inside both.
    let d = opaque(unsafe { load(dp, mask, full) });
    let nearer = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(z, d), _mm256_castsi256_ps(mask));
    if _mm256_movemask_ps(nearer) == 0 {
        return; // hidden everywhere (the background plane behind the scene)
    }
    let w = if target.perspective_correct {
        _mm256_div_ps(_mm256_set1_ps(1.0), plane_at(&t.inv_w_plane(), fx, fy))
    } else {
        _mm256_set1_ps(1.0)
    };
    let sep = _mm256_mul_ps(plane_at(&t.varying_plane(0), fx, fy), w);
    let src = _mm256_sub_ps(xf, _mm256_mul_ps(_mm256_set1_ps(target.toward), sep));
    let (lo, hi) = (_mm256_set1_ps(target.lo), _mm256_set1_ps(target.hi));
    let inside = if target.bilinear {
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(src, lo),
            _mm256_cmp_ps::<_CMP_LE_OQ>(src, _mm256_set1_ps(target.hi - 1.0)),
        )
    } else {
        let q = _mm256_add_ps(src, half);
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(q, lo),
            _mm256_cmp_ps::<_CMP_LT_OQ>(q, hi),
        )
    };
    let wins = _mm256_and_ps(nearer, inside);
    // SAFETY: as above.
    unsafe {
        let s = opaque(load(sp, mask, full));
        store(dp, mask, full, _mm256_blendv_ps(d, z, wins));
        store(sp, mask, full, _mm256_blendv_ps(s, src, wins));
    }
}

/// `row[i0]` and `row[i1]` per lane, for `i1` = `i0` or `i0 + 1` (lanes with `i1 = i0` get
/// some pixel in `b`: the caller uses `a` there). On a smooth surface the lanes read a run of
/// nine pixels from lane 0's `i0` on: two loads and two lane permutes then replace the two
/// gathers (about 20 cycles each); at a depth edge, the gathers.
///
/// # Safety
/// The CPU must support AVX2; every lane's `i0` and `i1` lies inside `row`.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn fetch_pair(row: &[[u8; 4]], i0: __m256i, i1: __m256i) -> (__m256i, __m256i) {
    let base = row.as_ptr() as *const i32;
    let first = _mm256_cvtsi256_si32(i0);
    let (rel0, rel1) = (
        _mm256_sub_epi32(i0, _mm256_set1_epi32(first)),
        _mm256_sub_epi32(i1, _mm256_set1_epi32(first)),
    );
    // Unsigned: rel0 ≤ 7 and rel1 ≤ 8 on every lane (a negative one wraps above).
    let within = |rel: __m256i, most: i32| {
        let most = _mm256_set1_epi32(most);
        _mm256_cmpeq_epi32(_mm256_max_epu32(rel, most), most)
    };
    let run = _mm256_and_si256(within(rel0, 7), within(rel1, 8));
    let fits = first >= 0 && first as usize + 9 <= row.len();
    if fits && _mm256_movemask_ps(_mm256_castsi256_ps(run)) == 0xff {
        // SAFETY: pixels first .. first + 9 are inside `row` (checked).
        let (from0, from1) = unsafe {
            (
                _mm256_loadu_si256(base.add(first as usize) as *const __m256i),
                _mm256_loadu_si256(base.add(first as usize + 1) as *const __m256i),
            )
        };
        let a = _mm256_permutevar8x32_epi32(from0, rel0);
        let b_index = _mm256_max_epi32(
            _mm256_sub_epi32(rel1, _mm256_set1_epi32(1)),
            _mm256_setzero_si256(),
        );
        return (a, _mm256_permutevar8x32_epi32(from1, b_index));
    }
    // SAFETY: every index is inside `row` (the caller's promise).
    unsafe {
        (
            _mm256_i32gather_epi32::<4>(base, i0),
            _mm256_i32gather_epi32::<4>(base, i1),
        )
    }
}

/// [`super::resolve_row`] eight pixels at a time: each pixel of `strip` with a source takes
/// `row`'s color there (bilinear: the two neighbors mixed per channel and rounded), in place.
/// Lanes without a source, or reading a pixel that is not final yet, go through
/// [`super::resolve_pixel`] (the pattern answers for those); a vector with no source at all
/// takes the pattern without the rest (the columns left of the nearest separation).
///
/// With `gray` (the pattern's colors, hence every pixel `row` holds or the pattern answers,
/// have R = G = B), a bilinear mix is computed for one channel and copied to the other two:
/// the same bytes, as the three channels' mixes are the same operations on the same values.
///
/// # Safety
/// The CPU must support AVX2; every source in `sources` is NaN or inside `row` (as
/// [`super::in_bounds`] ensured).
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn resolve_row(
    row: &mut [[u8; 4]],
    sources: &[f32],
    strip: &Strip,
    (bilinear, gray): (bool, bool),
    pattern: impl Fn(usize) -> [u8; 4],
) {
    let (x0, n) = (strip.x0 as usize, strip.width as usize);
    assert!(x0 + n <= row.len() && x0 + n <= sources.len());
    let half = _mm256_set1_ps(0.5);
    let byte = _mm256_set1_epi32(0xff);
    let mut k = 0;
    while k < n {
        let mask = tail_mask(n - k);
        // SAFETY: the mask covers lanes k .. min(k + 8, n), inside `sources` (asserted).
        let p = unsafe { _mm256_maskload_ps(sources.as_ptr().add(x0 + k), mask) };
        let has = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_ORD_Q>(p, p));
        if _mm256_movemask_ps(_mm256_castsi256_ps(has)) == 0 {
            // No lane has a source (the columns left of the nearest separation): the pattern,
            // as `resolve_pixel` answers for a NaN source.
            let (first, end) = (x0 + k, x0 + (k + 8).min(n));
            for (x, px) in (first..end).zip(&mut row[first..end]) {
                *px = pattern(x);
            }
            k += 8;
            continue;
        }
        // SAFETY: the mask covers lanes k .. min(k + 8, n), inside `row` and `sources`
        // (asserted); gathered indices are in bounds (NaN lanes gather pixel 0).
        let (color, i0, i1) = unsafe {
            let base = row.as_ptr() as *const i32;
            if bilinear {
                let i0 = _mm256_and_si256(floor_i32(p), has);
                let t = _mm256_sub_ps(p, _mm256_cvtepi32_ps(i0));
                let mixes = _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_setzero_ps());
                let i1 = _mm256_sub_epi32(i0, _mm256_castps_si256(mixes));
                let (a, b) = fetch_pair(row, i0, i1);
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
                let rgb = if gray {
                    // R = G = B in every pixel read: one channel's mix, copied to the others.
                    let c = channel(_mm_cvtsi32_si128(0));
                    _mm256_or_si256(
                        _mm256_or_si256(c, _mm256_slli_epi32::<8>(c)),
                        _mm256_slli_epi32::<16>(c),
                    )
                } else {
                    _mm256_or_si256(
                        _mm256_or_si256(
                            channel(_mm_cvtsi32_si128(0)),
                            channel(_mm_cvtsi32_si128(8)),
                        ),
                        channel(_mm_cvtsi32_si128(16)),
                    )
                };
                let mixed = _mm256_or_si256(rgb, _mm256_set1_epi32(0xff00_0000u32 as i32));
                // A whole-pixel source copies that pixel, alpha included.
                let color = _mm256_blendv_epi8(a, mixed, _mm256_castps_si256(mixes));
                (color, i0, i1)
            } else {
                let i = _mm256_and_si256(floor_i32(_mm256_add_ps(p, half)), has);
                (_mm256_i32gather_epi32::<4>(base, i), i, i)
            }
        };
        // Reads of pixels not final yet: at or right of x0 going right, left of the strip's
        // end going left.
        let unfinished = if strip.toward > 0.0 {
            _mm256_cmpgt_epi32(i1, _mm256_set1_epi32(x0 as i32 - 1))
        } else {
            _mm256_cmpgt_epi32(_mm256_set1_epi32((x0 + n) as i32), i0)
        };
        let plain = _mm256_andnot_si256(unfinished, has);
        let lanes = (1 << (n - k).min(8)) - 1;
        let special = !_mm256_movemask_ps(_mm256_castsi256_ps(plain)) & lanes;
        // SAFETY: as above, the mask keeps the store inside `row`.
        unsafe { _mm256_maskstore_epi32(row.as_mut_ptr().add(x0 + k) as *mut i32, mask, color) };
        for lane in (0..8).filter(|l| special & (1 << l) != 0) {
            let x = x0 + k + lane;
            row[x] = super::resolve_pixel(row, sources, x, strip, bilinear, &pattern);
        }
        k += 8;
    }
}
