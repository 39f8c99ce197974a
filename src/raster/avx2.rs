//! AVX2 helpers for fragment loops eight pixels at a time, and the depth-only span of
//! [`traverse`](super::traverse). Each lane performs the scalar code's IEEE operations in the
//! same order (no fused multiply-add), so the bits are the scalar path's.

use std::arch::x86_64::*;

use super::{Plane, SetupTriangle};

/// Whether this CPU runs the AVX2 loops; the bytes are the same either way.
pub fn available() -> bool {
    is_x86_feature_detected!("avx2")
}

/// Lane indices 0..8.
#[target_feature(enable = "avx2")]
pub(crate) fn lane_ids() -> __m256i {
    _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
}

/// Lanes `< remaining` set.
#[target_feature(enable = "avx2")]
pub(crate) fn tail_mask(remaining: usize) -> __m256i {
    _mm256_cmpgt_epi32(_mm256_set1_epi32(remaining.min(8) as i32), lane_ids())
}

/// `plane.at(fx, fy)` per lane: `(a0 + dadx·fx) + dady·fy`.
#[target_feature(enable = "avx2")]
pub(crate) fn plane_at(p: &Plane, fx: __m256, fy: f32) -> __m256 {
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
pub(crate) fn clamp01(v: __m256) -> __m256 {
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let v = _mm256_blendv_ps(v, zero, _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero));
    _mm256_blendv_ps(v, one, _mm256_cmp_ps::<_CMP_GT_OQ>(v, one))
}

/// `⌊v⌋` per lane for `|v| < 2³¹`: truncate, then step down where that rounded up.
#[target_feature(enable = "avx2")]
pub(crate) fn floor_i32(v: __m256) -> __m256i {
    let i = _mm256_cvttps_epi32(v);
    let above = _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_cvtepi32_ps(i), v);
    _mm256_add_epi32(i, _mm256_castps_si256(above))
}

/// The depth-only span of triangle `t` in row `y`, pixels `x_lo ..` (as many as `depth`
/// holds): depth test LESS with depth writes. Returns the fragments that passed.
///
/// # Safety
/// The CPU must support AVX2.
#[target_feature(enable = "avx2")]
pub(crate) unsafe fn depth_span(t: &SetupTriangle, y: u32, x_lo: u32, depth: &mut [f32]) -> usize {
    let n = depth.len();
    let (ox, _) = t.origin();
    let fy = t.fy(y);
    let zp = t.depth_plane();
    let half = _mm256_set1_ps(0.5);
    let mut passed = 0;
    let mut k = 0;
    while k < n {
        let mask = tail_mask(n - k);
        let x = _mm256_add_epi32(_mm256_set1_epi32((x_lo as usize + k) as i32), lane_ids());
        let fx = _mm256_sub_ps(
            _mm256_add_ps(_mm256_cvtepi32_ps(x), half),
            _mm256_set1_ps(ox),
        );
        let z = clamp01(plane_at(&zp, fx, fy));
        // SAFETY: the mask covers lanes k .. min(k + 8, n), inside `depth`.
        unsafe {
            let dp = depth.as_mut_ptr().add(k);
            let d = _mm256_maskload_ps(dp, mask);
            let pass = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(z, d), _mm256_castsi256_ps(mask));
            _mm256_maskstore_ps(dp, mask, _mm256_blendv_ps(d, z, pass));
            passed += _mm256_movemask_ps(pass).count_ones() as usize;
        }
        k += 8;
    }
    passed
}
