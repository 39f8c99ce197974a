//! [`anaglyph_pixel`](super::anaglyph_pixel) on stored values, eight pixels at a time (AVX2).
//!
//! Each lane performs the scalar code's IEEE operations in the same order — `v / 255` per
//! channel, each row of `ML · left + MR · right` summed left to right, the clamp, then
//! `clamp(c)·255 + ½` truncated — with no fused multiply-add, so the bytes are the scalar
//! function's (`avx2_rows_match_anaglyph_pixel` holds every kind to it). The scalar loop stays
//! the reference; it runs where the CPU has no AVX2 and for linear light (whose `powf` has no
//! vector form here). Eight pixel pairs equal to the previous eight (a flat background in both
//! eyes) reuse the previous result instead of computing it again: the same bytes, since a
//! pixel's result depends on its pair alone.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::AnaglyphMatrices;

/// `v.clamp(0, 1)` per lane, as `f32::clamp`: `maxps`/`minps` return their second operand when
/// the operands compare equal or either is NaN, so with `v` second a NaN is kept and −0 stays
/// −0 (`f32::clamp` returns `v` unless `v < 0` or `v > 1`).
#[target_feature(enable = "avx2")]
#[inline]
fn clamp01(v: __m256) -> __m256 {
    let v = _mm256_max_ps(_mm256_setzero_ps(), v);
    _mm256_min_ps(_mm256_set1_ps(1.0), v)
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
        // `mix`'s clamp, then `to_u8`'s (a no-op on a clamped value: clamping is idempotent)
        // and its rounding; a NaN truncates to i32::MIN, whose low byte is 0, as Rust's
        // saturating `as u8` gives.
        let q = _mm256_add_ps(_mm256_mul_ps(clamp01(v), d255), _mm256_set1_ps(0.5));
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
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    let n = out.len().min(left.len()).min(right.len());
    // The last eight pixel pairs computed and their result: the output is a function of the
    // pair alone, so eight pairs equal to the last ones (a flat background, both eyes) reuse it.
    let (mut last_l, mut last_r) = (_mm256_setzero_si256(), _mm256_setzero_si256());
    let mut last = eight(m, last_l, last_r);
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: `k + 8 <= n`, so eight pixels (32 bytes) are in bounds in all three slices;
        // the unaligned forms need no alignment.
        unsafe {
            let l = _mm256_loadu_si256(left.as_ptr().add(k).cast());
            let r = _mm256_loadu_si256(right.as_ptr().add(k).cast());
            let same =
                _mm256_and_si256(_mm256_cmpeq_epi32(l, last_l), _mm256_cmpeq_epi32(r, last_r));
            if _mm256_movemask_epi8(same) != -1 {
                (last_l, last_r, last) = (l, r, eight(m, l, r));
            }
            _mm256_storeu_si256(out.as_mut_ptr().add(k).cast(), last);
        }
        k += 8;
    }
    for k in k..n {
        out[k].write(super::anaglyph_pixel(m, left[k], right[k], false));
    }
}

#[cfg(test)]
mod tests {
    use super::super::{AnaglyphKind, anaglyph_pixel};
    use super::*;

    /// `clamp01` is `f32::clamp(0, 1)` bit for bit, on the values where the two could differ.
    #[test]
    fn clamp01_is_f32_clamp() {
        if !crate::simd::avx2_available() {
            eprintln!("clamp01_is_f32_clamp: NOT RUN: no AVX2 here");
            return;
        }
        let v = [
            -0.0f32,
            0.0,
            f32::NAN,
            -1.5,
            1.0,
            1.0f32.next_up(),
            0.25,
            f32::NEG_INFINITY,
        ];
        let mut got = [0.0f32; 8];
        // SAFETY: AVX2 is available (checked above); eight lanes in and out.
        unsafe { _mm256_storeu_ps(got.as_mut_ptr(), clamp01(_mm256_loadu_ps(v.as_ptr()))) };
        for (x, g) in v.iter().zip(got) {
            assert_eq!(g.to_bits(), x.clamp(0.0, 1.0).to_bits(), "clamp({x})");
        }
    }

    /// Every kind's AVX2 row gives `anaglyph_pixel`'s bytes on runs of equal pixel pairs
    /// (where the previous result is reused), 10,003 pseudo-random pairs (a length that ends
    /// mid-vector), black, white and every gray.
    #[test]
    fn avx2_rows_match_anaglyph_pixel() {
        if !crate::simd::avx2_available() {
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
        // Runs for the reuse of the previous eight: all-zero pairs (the initial "previous"),
        // a flat run, the same left eye with a right eye that changes in one pixel (no reuse),
        // and a run that starts mid-vector.
        let runs: [([u8; 4], [u8; 4], usize); 4] = [
            ([0; 4], [0; 4], 24),
            ([24, 24, 24, 255], [24, 24, 24, 255], 40),
            ([24, 24, 24, 255], [25, 24, 24, 255], 5),
            ([200, 10, 99, 255], [3, 250, 77, 255], 37),
        ];
        let mut front = Vec::new();
        for (l, r, len) in runs {
            front.extend(std::iter::repeat_n((l, r), len));
        }
        let (fl, fr): (Vec<_>, Vec<_>) = front.into_iter().unzip();
        left.splice(0..0, fl);
        right.splice(0..0, fr);
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            let m = kind.matrices();
            let mut fast = vec![MaybeUninit::new([0u8; 4]); left.len()];
            // SAFETY: AVX2 is available (checked above).
            unsafe { row(&m, &left, &right, &mut fast) };
            for (k, ((l, r), f)) in left.iter().zip(&right).zip(&fast).enumerate() {
                // SAFETY: every element was initialized (by `MaybeUninit::new`, then `row`).
                let f = unsafe { f.assume_init() };
                assert_eq!(
                    f,
                    anaglyph_pixel(&m, *l, *r, false),
                    "{kind:?}: pixel {k}, left {l:?}, right {r:?}"
                );
            }
        }
    }
}
