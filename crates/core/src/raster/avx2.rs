//! AVX2 helpers for fragment loops eight pixels at a time, and the depth-only span of
//! [`traverse`](super::traverse). Each lane performs the scalar code's IEEE operations in the
//! same order (no fused multiply-add), so the bits are the scalar path's.

use std::arch::x86_64::*;

use super::{Band, Plane, SetupTriangle};

/// `v` unchanged, opaque to the optimizer. A lane blend of a loaded vector stored back where it
/// came from is what a masked store does, and LLVM rewrites it into one; this keeps the full
/// store. Only an instruction choice: the bytes are the same without it. On AMD Zen a 256-bit
/// masked store is microcoded and slow (in a profile of the depth pass on a Zen 3 the
/// instruction after it took the most samples of the loop); the depth pass
/// (`depth_triangle`) and the strip pass (`effects/sirds/strips/avx2.rs`) both keep their
/// full stores with it.
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub fn opaque(mut v: __m256) -> __m256 {
    // SAFETY: an empty instruction sequence; it only hides the value's origin.
    unsafe { std::arch::asm!("/* {0} */", inout(ymm_reg) v, options(pure, nomem, nostack)) };
    v
}

/// Lane indices 0..8.
#[target_feature(enable = "avx2,fma")]
pub(crate) fn lane_ids() -> __m256i {
    _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
}

/// Lanes `< remaining` set.
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
pub fn tail_mask(remaining: usize) -> __m256i {
    _mm256_cmpgt_epi32(_mm256_set1_epi32(remaining.min(8) as i32), lane_ids())
}

/// `plane.at(fx, fy)` per lane: `(a0 + dadx·fx) + dady·fy`.
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
pub fn plane_at(p: &Plane, fx: __m256, fy: f32) -> __m256 {
    let row = _mm256_set1_ps(p.dady * fy);
    _mm256_add_ps(
        _mm256_add_ps(
            _mm256_set1_ps(p.a0),
            _mm256_mul_ps(_mm256_set1_ps(p.dadx), fx),
        ),
        row,
    )
}

/// Columns `x .. x + 8` as floats, and each relative to `t`'s plane origin: the lanes of
/// [`SetupTriangle::fx`].
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub fn columns(t: &SetupTriangle, x: u32) -> (__m256, __m256) {
    let xf = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(x as i32), lane_ids()));
    let (ox, _) = t.origin();
    let fx = _mm256_sub_ps(_mm256_add_ps(xf, _mm256_set1_ps(0.5)), _mm256_set1_ps(ox));
    (xf, fx)
}

/// [`SetupTriangle::depth_at`] per lane, for the columns `xf` (as floats) of row `y`: llvmpipe's
/// `fma(dzdy, y, fma(dzdx, x, a0))` with the same two fused operations, clamped to [0, 1].
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
pub fn depth_at(t: &SetupTriangle, xf: __m256, y: u32) -> __m256 {
    let p = t.depth_plane();
    let row = _mm256_fmadd_ps(_mm256_set1_ps(p.dzdx), xf, _mm256_set1_ps(p.a0));
    clamp01(_mm256_fmadd_ps(
        _mm256_set1_ps(p.dzdy),
        _mm256_set1_ps(y as i32 as f32),
        row,
    ))
}

/// `v.clamp(0, 1)` per lane, NaN kept (as `f32::clamp`).
#[target_feature(enable = "avx2,fma")]
pub(crate) fn clamp01(v: __m256) -> __m256 {
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let v = _mm256_blendv_ps(v, zero, _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero));
    _mm256_blendv_ps(v, one, _mm256_cmp_ps::<_CMP_GT_OQ>(v, one))
}

/// `⌊v⌋` per lane for `|v| < 2³¹`: truncate, then step down where that rounded up.
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
pub fn floor_i32(v: __m256) -> __m256i {
    let i = _mm256_cvttps_epi32(v);
    let above = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(i), v);
    _mm256_add_epi32(i, _mm256_castps_si256(above))
}

/// Calls `f(y, x, mask)` for every vector of eight pixels (`x .. x + 8` of row `y`) holding
/// pixels of `t` covered within the tile (columns `x0 .. x0 + width`, rows `y0 .. y0 + rows`),
/// `mask` marking the covered lanes. A triangle at most eight columns wide there takes one
/// vector per row, at most sixteen two (the left eight columns' rows, then the right eight's),
/// its coverage from the edge functions in `i32` lanes ([`SmallBox`]: the per-row span search
/// and its branches cost more than the pixels of a small triangle); larger ones go span by
/// span ([`SetupTriangle::spans`]). Both give the same coverage; each covered pixel is passed
/// once, so a pass whose pixels do not interact within one triangle (the depth test, the strip
/// sources) does not depend on the order.
///
/// [`SmallBox`]: super::SmallBox
///
/// # Safety
/// The CPU must have AVX2 and FMA ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2,fma")]
#[inline]
pub fn covered_vectors(
    t: &SetupTriangle,
    (x0, y0, width, rows): (u32, u32, u32, u32),
    mut f: impl FnMut(u32, u32, __m256i),
) {
    // One vector per row for boxes up to eight columns, two up to sixteen. (Four up to 32 was
    // measured too: the SIRDS paper's Table 1 row 4, triangles ~38 columns wide, took 13% more
    // time, half of each box's vectors empty.)
    let small = [1, 2]
        .into_iter()
        .find_map(|v| t.small_box(x0, y0, width, rows, 8 * v).map(|b| (b, v)));
    if let Some((b, vectors)) = small {
        let lanes = lane_ids();
        let below = _mm256_set1_epi32(-1);
        let dy = b.dy.map(|d| _mm256_set1_epi32(d));
        for v in 0..vectors {
            // Lanes 8v .. 8v + 8 of the box: the edge values there fit in i32, as every lane's
            // do (`small_box` checked the corners of all `8 · vectors` lanes).
            let first = _mm256_add_epi32(lanes, _mm256_set1_epi32(8 * v as i32));
            let in_box = _mm256_cmpgt_epi32(_mm256_set1_epi32(b.columns as i32), first);
            let mut e = [0, 1, 2].map(|i| {
                _mm256_add_epi32(
                    _mm256_set1_epi32(b.e[i]),
                    _mm256_mullo_epi32(_mm256_set1_epi32(b.dx[i]), first),
                )
            });
            let x = b.x + 8 * v;
            for y in b.y0..=b.y1 {
                let inside = _mm256_and_si256(
                    _mm256_cmpgt_epi32(e[0], below),
                    _mm256_and_si256(
                        _mm256_cmpgt_epi32(e[1], below),
                        _mm256_cmpgt_epi32(e[2], below),
                    ),
                );
                let covered = _mm256_and_si256(inside, in_box);
                if _mm256_movemask_ps(_mm256_castsi256_ps(covered)) != 0 {
                    f(y, x, covered);
                }
                e = [0, 1, 2].map(|i| _mm256_add_epi32(e[i], dy[i]));
            }
        }
        return;
    }
    t.spans(x0, y0, width, rows, |y, x_lo, x_hi| {
        let n = (x_hi - x_lo) as usize + 1;
        for k in (0..n).step_by(8) {
            f(y, x_lo + k as u32, tail_mask(n - k));
        }
    });
}

/// Loads eight values from `p`: unmasked when `full` (eight fit), else the `mask` lanes.
///
/// # Safety
/// `p` points at eight readable values when `full`, else at the `mask` lanes.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub unsafe fn load(p: *const f32, mask: __m256i, full: bool) -> __m256 {
    // SAFETY: as the caller promises.
    unsafe {
        if full {
            _mm256_loadu_ps(p)
        } else {
            _mm256_maskload_ps(p, mask)
        }
    }
}

/// Stores eight values at `p`: unmasked when `full` (the lanes outside `mask` must then hold
/// what was loaded there), else the `mask` lanes. A masked store is slow, and a masked load of
/// one just stored cannot be forwarded, hence the full form wherever eight fit.
///
/// # Safety
/// As [`load`], writable.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub unsafe fn store(p: *mut f32, mask: __m256i, full: bool, v: __m256) {
    // SAFETY: as the caller promises.
    unsafe {
        if full {
            _mm256_storeu_ps(p, v)
        } else {
            _mm256_maskstore_ps(p, mask, v)
        }
    }
}

/// [`traverse`](super::traverse) of one triangle in a depth-only pass over `band`: depth test
/// LESS with depth writes, eight pixels at a time. Returns the fragments that passed.
///
/// # Safety
/// The CPU must support AVX2 and POPCNT ([`available`]).
#[target_feature(enable = "avx2,fma,popcnt")]
pub(crate) unsafe fn depth_triangle(t: &SetupTriangle, band: &mut Band) -> usize {
    let rows = (band.depth.len() / band.width.max(1) as usize) as u32;
    let (x0, y0, w) = (band.x0, band.y0, band.width as usize);
    let mut passed = 0;
    covered_vectors(t, (x0, y0, band.width, rows), |y, x, mask| {
        let i = (y - y0) as usize * w + (x - x0) as usize;
        // SAFETY: this function runs only where AVX2 is available.
        passed += unsafe { depth_vector(t, y, x, mask, &mut band.depth[i..]) };
    });
    passed
}

/// One vector of a depth-only pass: pixels `x .. x + 8` of row `y` where `mask` is set, depth
/// test LESS with depth writes into `depth` (starting at pixel `x`). Returns how many passed.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2,fma,popcnt")]
#[inline]
unsafe fn depth_vector(
    t: &SetupTriangle,
    y: u32,
    x: u32,
    mask: __m256i,
    depth: &mut [f32],
) -> usize {
    let full = depth.len() >= 8;
    let (xf, _) = columns(t, x);
    let z = depth_at(t, xf, y);
    // SAFETY: eight lanes fit when `full`; otherwise `mask` covers only the span's pixels,
    // inside `depth`.
    unsafe {
        let dp = depth.as_mut_ptr();
        let d = opaque(load(dp, mask, full));
        let pass = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(z, d), _mm256_castsi256_ps(mask));
        store(dp, mask, full, _mm256_blendv_ps(d, z, pass));
        _mm256_movemask_ps(pass).count_ones() as usize
    }
}
