//! The strip pass's two per-pixel loops eight pixels at a time (AVX2), as llvmpipe runs its
//! fragment stage: [`triangle_sources`] mirrors [`super::span_sources`], [`resolve_sweep`]
//! runs [`super::resolve_row`] for every strip of a row in one pass.
//!
//! Each lane performs the scalar loop's IEEE operations in the same order (no fused
//! multiply-add, which would round once instead of twice), so the bytes are the same as the
//! scalar path's; the pipeline's `avx2_strips_match_scalar_strips` holds them equal on real
//! scenes, `reads_of_unfinished_pixels_see_the_pattern` on rows of every kind of read. Lanes
//! past the end of a span are masked off, never loaded or stored.

use std::arch::x86_64::*;

use super::{Columns, Region, SpanTarget, Strip};
use crate::SirdsPattern;
use crate::raster::SetupTriangle;
use crate::raster::avx2::{
    columns, covered_vectors, depth_at, floor_i32, load, opaque, plane_at, store,
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

/// The colors of the eight pixels whose sources are `p` (lanes `has` have one, the others are
/// ignored), each taking `row`'s color there as [`super::resolve_pixel`] does for a final
/// source (bilinear: the two neighbors mixed per channel and rounded), and the pixels each
/// lane reads, `i0` and `i1` (0 on lanes without a source).
///
/// With `gray` (every pixel `row` holds has R = G = B), a bilinear mix is computed for one
/// channel and copied to the other two: the same bytes, as the three channels' mixes are the
/// same operations on the same values.
///
/// # Safety
/// The CPU must support AVX2; the source of every lane in `has` is inside `row` (as
/// [`super::in_bounds`] ensured).
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn colors(
    row: &[[u8; 4]],
    p: __m256,
    has: __m256i,
    (bilinear, gray): (bool, bool),
) -> (__m256i, __m256i, __m256i) {
    let half = _mm256_set1_ps(0.5);
    let byte = _mm256_set1_epi32(0xff);
    let base = row.as_ptr() as *const i32;
    if bilinear {
        let i0 = _mm256_and_si256(floor_i32(p), has);
        let t = _mm256_sub_ps(p, _mm256_cvtepi32_ps(i0));
        let mixes = _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_setzero_ps());
        let i1 = _mm256_sub_epi32(i0, _mm256_castps_si256(mixes));
        // SAFETY: every lane's i0 and i1 lies inside `row` (lanes without a source read
        // pixel 0; the caller's promise for the others).
        let (a, b) = unsafe { fetch_pair(row, i0, i1) };
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
                _mm256_or_si256(channel(_mm_cvtsi32_si128(0)), channel(_mm_cvtsi32_si128(8))),
                channel(_mm_cvtsi32_si128(16)),
            )
        };
        let mixed = _mm256_or_si256(rgb, _mm256_set1_epi32(0xff00_0000u32 as i32));
        // A whole-pixel source copies that pixel, alpha included.
        let color = _mm256_blendv_epi8(a, mixed, _mm256_castps_si256(mixes));
        (color, i0, i1)
    } else {
        let i = _mm256_and_si256(floor_i32(_mm256_add_ps(p, half)), has);
        // SAFETY: as above.
        (unsafe { _mm256_i32gather_epi32::<4>(base, i) }, i, i)
    }
}

/// [`super::resolve_row`] for every strip of one row in one pass, eight pixels at a time, in
/// place: the right-going strips' columns left to right from the start column, then the
/// left-going strips' right to left, which is the order the strips run in. Row `y` of the
/// band; `sources` is the row's, `columns` says which strip writes each column.
///
/// A pixel reads only pixels final before its strip runs (else the pattern answers), and
/// every such pixel lies behind the sweep, so each pixel comes out as its strip makes it.
/// Lanes whose reads are all behind the vector and final take the vector's color; the others
/// (no source, a read of a pixel not final yet, or of a lane of the same vector) then go
/// through [`super::resolve_pixel`] one by one in sweep order. A vector with no source at all
/// takes the pattern without the rest (the columns left of the nearest separation). The
/// columns past the last whole vector go through [`super::resolve_pixel`] too.
///
/// # Safety
/// The CPU must support AVX2; every source in `sources` is NaN or inside `row` (as
/// [`super::in_bounds`] ensured).
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn resolve_sweep(
    row: &mut [[u8; 4]],
    sources: &[f32],
    (strips, columns): (&[Strip], &Columns),
    (bilinear, gray): (bool, bool),
    (y, pattern): (u32, &SirdsPattern),
) {
    let w = row.len();
    assert!(sources.len() == w && columns.owner.len() == w && columns.bound.len() == w);
    let split = columns.split as usize;
    let one = |row: &mut [[u8; 4]], x: usize| {
        let strip = &strips[columns.owner[x] as usize];
        let pattern = |i: usize| pattern.color(i as u32, y);
        row[x] = super::resolve_pixel(row, sources, x, strip, bilinear, &pattern);
    };
    // One vector at `k`: its sources, and the lanes that have one (`None`: no lane has one,
    // and the vector took the pattern).
    let load = |row: &mut [[u8; 4]], k: usize| {
        // SAFETY: k + 8 ≤ w (the callers' loop bounds), inside `sources` (asserted).
        let p = unsafe { _mm256_loadu_ps(sources.as_ptr().add(k)) };
        let has = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_ORD_Q>(p, p));
        if _mm256_movemask_ps(_mm256_castsi256_ps(has)) == 0 {
            // SAFETY: AVX2 (this function's condition).
            unsafe { pattern.fill_span_avx2(k as u32, y, &mut row[k..k + 8]) };
            return None;
        }
        Some((p, has))
    };
    // SAFETY: k + 8 ≤ w (the callers' loop bounds), inside `columns.bound` (asserted).
    let bound_at =
        |k: usize| unsafe { _mm256_loadu_si256(columns.bound.as_ptr().add(k) as *const __m256i) };
    // Right-going: a read of `i` is final when `i` < the lane's strip start, and behind the
    // sweep when `i` < k.
    let mut k = split;
    while k + 8 <= w {
        if let Some((p, has)) = load(row, k) {
            // SAFETY: AVX2 (this function's condition); the sources are NaN or inside `row`
            // (the caller's promise).
            let (color, _, i1) = unsafe { colors(row, p, has, (bilinear, gray)) };
            let done = _mm256_min_epi32(bound_at(k), _mm256_set1_epi32(k as i32));
            let safe = _mm256_and_si256(_mm256_cmpgt_epi32(done, i1), has);
            // SAFETY: pixels k .. k + 8 lie inside `row` (k + 8 ≤ w).
            unsafe { _mm256_storeu_si256(row.as_mut_ptr().add(k) as *mut __m256i, color) };
            let mut special = !_mm256_movemask_ps(_mm256_castsi256_ps(safe)) & 0xff;
            while special != 0 {
                one(row, k + special.trailing_zeros() as usize);
                special &= special - 1;
            }
        }
        k += 8;
    }
    for x in k..w {
        one(row, x);
    }
    // Left-going: a read of `i` is final when `i` ≥ the lane's strip end, and behind the
    // sweep when `i` ≥ the vector's end.
    let mut end = split;
    while end >= 8 {
        let k = end - 8;
        if let Some((p, has)) = load(row, k) {
            // SAFETY: AVX2 (this function's condition); the sources are NaN or inside `row`
            // (the caller's promise).
            let (color, i0, _) = unsafe { colors(row, p, has, (bilinear, gray)) };
            let done = _mm256_max_epi32(bound_at(k), _mm256_set1_epi32(end as i32));
            let below = _mm256_sub_epi32(done, _mm256_set1_epi32(1));
            let safe = _mm256_and_si256(_mm256_cmpgt_epi32(i0, below), has);
            // SAFETY: pixels k .. k + 8 lie inside `row` (k + 8 ≤ w).
            unsafe { _mm256_storeu_si256(row.as_mut_ptr().add(k) as *mut __m256i, color) };
            let mut special = !_mm256_movemask_ps(_mm256_castsi256_ps(safe)) & 0xff;
            while special != 0 {
                let lane = 31 - special.leading_zeros();
                one(row, k + lane as usize);
                special &= !(1 << lane);
            }
        }
        end = k;
    }
    for x in (0..end).rev() {
        one(row, x);
    }
}
