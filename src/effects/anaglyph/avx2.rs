//! [`anaglyph_pixel`](super::anaglyph_pixel) on stored values, eight pixels at a time (AVX2).
//!
//! Each lane performs the scalar code's IEEE operations in the same order — `v / 255` per
//! channel, each row of `ML · left + MR · right` summed left to right, the clamp, then
//! `clamp(c)·255 + ½` truncated — with no fused multiply-add, so the bytes are the scalar
//! function's (`avx2_rows_match_anaglyph_pixel` holds every kind to it). The scalar loop stays
//! the reference; it runs where the CPU has no AVX2 and for linear light (whose `powf` has no
//! vector form here).

use std::arch::x86_64::*;

use super::AnaglyphMatrices;

/// Whether the CPU runs [`row`].
pub(super) fn available() -> bool {
    is_x86_feature_detected!("avx2")
}

/// `v.clamp(0, 1)` per lane, NaN kept (as `f32::clamp`).
#[target_feature(enable = "avx2")]
#[inline]
fn clamp01(v: __m256) -> __m256 {
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let v = _mm256_blendv_ps(v, zero, _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero));
    _mm256_blendv_ps(v, one, _mm256_cmp_ps::<_CMP_GT_OQ>(v, one))
}

/// Eight pixels: `out[k] = anaglyph_pixel(m, left[k], right[k], false)` for `k < 8`, as words
/// (RGBA in memory order, little-endian).
#[target_feature(enable = "avx2")]
#[inline]
fn eight(m: &AnaglyphMatrices, l: __m256i, r: __m256i) -> __m256i {
    let byte = _mm256_set1_epi32(0xff);
    let d255 = _mm256_set1_ps(255.0);
    // Channel `k` of every lane, decoded: `v as f32 / 255`.
    let decode = |p: __m256i, k: i32| {
        let c = match k {
            0 => p,
            1 => _mm256_srli_epi32::<8>(p),
            _ => _mm256_srli_epi32::<16>(p),
        };
        _mm256_div_ps(_mm256_cvtepi32_ps(_mm256_and_si256(c, byte)), d255)
    };
    let a = [decode(l, 0), decode(l, 1), decode(l, 2)];
    let b = [decode(r, 0), decode(r, 1), decode(r, 2)];
    let mut out = _mm256_set1_epi32(0xff00_0000_u32 as i32);
    for i in 0..3 {
        let (ml, mr) = (m.left[i], m.right[i]);
        let term = |c: f32, x: __m256| _mm256_mul_ps(_mm256_set1_ps(c), x);
        let mut v = term(ml[0], a[0]);
        v = _mm256_add_ps(v, term(ml[1], a[1]));
        v = _mm256_add_ps(v, term(ml[2], a[2]));
        v = _mm256_add_ps(v, term(mr[0], b[0]));
        v = _mm256_add_ps(v, term(mr[1], b[1]));
        v = _mm256_add_ps(v, term(mr[2], b[2]));
        // `mix`'s clamp, then `to_u8`'s (the same again) and its rounding; a NaN truncates to
        // i32::MIN, whose low byte is 0, as Rust's saturating `as u8` gives.
        let q = _mm256_add_ps(
            _mm256_mul_ps(clamp01(clamp01(v)), d255),
            _mm256_set1_ps(0.5),
        );
        let c = _mm256_and_si256(_mm256_cvttps_epi32(q), byte);
        out = _mm256_or_si256(
            out,
            match i {
                0 => c,
                1 => _mm256_slli_epi32::<8>(c),
                _ => _mm256_slli_epi32::<16>(c),
            },
        );
    }
    out
}

/// One row of the stored-value anaglyph: `out[k] = anaglyph_pixel(m, left[k], right[k],
/// false)` for every pixel (the last partial vector through the scalar function).
///
/// # Safety
/// The CPU must support AVX2 ([`available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn row(
    m: &AnaglyphMatrices,
    left: &[[u8; 4]],
    right: &[[u8; 4]],
    out: &mut [[u8; 4]],
) {
    let n = out.len().min(left.len()).min(right.len());
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: `k + 8 <= n`, so eight pixels (32 bytes) are in bounds in all three slices;
        // the unaligned forms need no alignment.
        unsafe {
            let l = _mm256_loadu_si256(left.as_ptr().add(k).cast());
            let r = _mm256_loadu_si256(right.as_ptr().add(k).cast());
            _mm256_storeu_si256(out.as_mut_ptr().add(k).cast(), eight(m, l, r));
        }
        k += 8;
    }
    for k in k..n {
        out[k] = super::anaglyph_pixel(m, left[k], right[k], false);
    }
}

#[cfg(test)]
mod tests {
    use super::super::{AnaglyphKind, anaglyph_pixel};
    use super::*;

    /// Every kind's AVX2 row gives `anaglyph_pixel`'s bytes on 10,003 pseudo-random pixel
    /// pairs (a length that ends mid-vector), black, white and every gray.
    #[test]
    fn avx2_rows_match_anaglyph_pixel() {
        if !available() {
            eprintln!("avx2_rows_match_anaglyph_pixel: NOT RUN: no AVX2 here, nothing to compare");
            return;
        }
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state.to_le_bytes()
        };
        let mut left: Vec<[u8; 4]> = (0..10_003)
            .map(|_| {
                let b = next();
                [b[0], b[1], b[2], b[3]]
            })
            .collect();
        let mut right: Vec<[u8; 4]> = left
            .iter()
            .map(|_| {
                let b = next();
                [b[4], b[5], b[6], b[7]]
            })
            .collect();
        for v in 0..=255u8 {
            left.push([v, v, v, 255]);
            right.push([255 - v, v, 0, 255]);
        }
        for kind in AnaglyphKind::ALL {
            let m = kind.matrices();
            let mut fast = vec![[0u8; 4]; left.len()];
            // SAFETY: AVX2 is available (checked above).
            unsafe { row(&m, &left, &right, &mut fast) };
            for (k, ((l, r), f)) in left.iter().zip(&right).zip(&fast).enumerate() {
                assert_eq!(
                    *f,
                    anaglyph_pixel(&m, *l, *r, false),
                    "{kind:?}: pixel {k}, left {l:?}, right {r:?}"
                );
            }
        }
    }
}
