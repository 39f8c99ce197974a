//! [`anaglyph_pixel`](super::anaglyph_pixel) on stored values, eight pixels at a time (AVX2
//! and FMA).
//!
//! Two ways to the same bytes. [`eight`] performs the scalar code's IEEE operations in each
//! lane in the same order — `v / 255` per channel, each row of `ML · left + MR · right` summed
//! left to right, the clamp, then `clamp(c)·255 + ½` truncated — with no fused multiply-add.
//! [`eight_fused`] skips the six divisions and the clamp: per channel `t = ½ + Σ c_j·v_j` on the
//! raw 8-bit values with fused multiply-adds, the byte `⌊t⌋` saturated to 0..255, and the lanes
//! whose `t` lies within [`fused_guard`](super::fused_guard) of an integer (where the two
//! roundings could disagree) flagged; eight pixels with a flagged lane are computed again by
//! [`eight`]. `avx2_rows_match_anaglyph_pixel` and the bound's tests hold every kind to the
//! scalar function. The scalar loop stays the reference; it runs where the CPU has no AVX2 and
//! for linear light (whose `powf` has no vector form here). Eight pixel pairs equal to the
//! previous eight (a flat background in both eyes) reuse the previous result instead of
//! computing it again: the same bytes, since a pixel's result depends on its pair alone.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::{AnaglyphMatrices, fused_guard};

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

/// The constants of [`eight_fused`] for one matrix pair: per output channel its six
/// coefficients (`ML`'s row, then `MR`'s) and its [`fused_guard`].
pub(super) struct Fused {
    coefficients: [[f32; 6]; 3],
    guard: [f32; 3],
}

impl Fused {
    /// `m`'s rows and their guards.
    pub(super) fn new(m: &AnaglyphMatrices) -> Fused {
        let coefficients = [0, 1, 2].map(|i| {
            let (l, r) = (m.left[i], m.right[i]);
            [l[0], l[1], l[2], r[0], r[1], r[2]]
        });
        Fused {
            coefficients,
            guard: coefficients.map(fused_guard),
        }
    }
}

/// [`Fused`] broadcast to every lane.
struct Lanes {
    coefficients: [[__m256; 6]; 3],
    guard: [__m256; 3],
}

impl Lanes {
    #[target_feature(enable = "avx2")]
    fn new(f: &Fused) -> Lanes {
        Lanes {
            coefficients: f.coefficients.map(|row| row.map(|c| _mm256_set1_ps(c))),
            guard: f.guard.map(|g| _mm256_set1_ps(g)),
        }
    }
}

/// Eight pixels the fast way: per channel `t = ½ + Σ c_j·v_j` (the six terms in `ML`, `MR`
/// order, each a fused multiply-add on the raw 8-bit value), the byte `⌊t⌋` saturated to 0..255
/// (alpha 255), as words like [`eight`]'s; and a mask with bit `k` set where a channel of pixel
/// `k` has `t` within its guard of an integer: [`eight`]'s bytes wherever the mask is 0
/// ([`fused_guard`] says why).
#[target_feature(enable = "avx2,fma")]
#[inline]
fn eight_fused(w: &Lanes, l: __m256i, r: __m256i) -> (__m256i, i32) {
    // Byte `k` of each word, zero-extended (`k` = 1, 2; byte 0 is a mask away).
    let byte_of = |k: i8| {
        let z = -1;
        _mm256_setr_epi8(
            k,
            z,
            z,
            z,
            k + 4,
            z,
            z,
            z,
            k + 8,
            z,
            z,
            z,
            k + 12,
            z,
            z,
            z,
            k,
            z,
            z,
            z,
            k + 4,
            z,
            z,
            z,
            k + 8,
            z,
            z,
            z,
            k + 12,
            z,
            z,
            z,
        )
    };
    let low = _mm256_set1_epi32(0xff);
    let (g, b) = (byte_of(1), byte_of(2));
    let x = [
        _mm256_and_si256(l, low),
        _mm256_shuffle_epi8(l, g),
        _mm256_shuffle_epi8(l, b),
        _mm256_and_si256(r, low),
        _mm256_shuffle_epi8(r, g),
        _mm256_shuffle_epi8(r, b),
    ]
    .map(|v| _mm256_cvtepi32_ps(v));
    let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
    let mut near = _mm256_setzero_ps();
    let mut q = [_mm256_setzero_si256(); 3];
    for (i, q) in q.iter_mut().enumerate() {
        let c = &w.coefficients[i];
        let mut t = _mm256_fmadd_ps(c[0], x[0], _mm256_set1_ps(0.5));
        for j in 1..6 {
            t = _mm256_fmadd_ps(c[j], x[j], t);
        }
        // |t − nearest integer| (exact) below the guard: flagged.
        let n = _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(t);
        let d = _mm256_and_ps(_mm256_sub_ps(t, n), abs);
        near = _mm256_or_ps(near, _mm256_cmp_ps::<_CMP_LT_OQ>(d, w.guard[i]));
        // Truncation is `⌊t⌋` for t ≥ 0; a negative t gives 0 or less, saturated to 0 below.
        *q = _mm256_cvttps_epi32(t);
    }
    // Within each 128-bit half (pixels 0–3, 4–7): R0..R3 G0..G3 as i16, B0..B3 and alpha, then
    // all sixteen saturated to u8, then reordered to R G B A per pixel.
    let rg = _mm256_packs_epi32(q[0], q[1]);
    let ba = _mm256_packs_epi32(q[2], _mm256_set1_epi32(255));
    let planar = _mm256_packus_epi16(rg, ba);
    let interleave = _mm256_setr_epi8(
        0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15, 0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10,
        14, 3, 7, 11, 15,
    );
    (
        _mm256_shuffle_epi8(planar, interleave),
        _mm256_movemask_ps(near),
    )
}

/// One row of the stored-value anaglyph: `out[k] = anaglyph_pixel(m, left[k], right[k],
/// false)` for every pixel, `fused` being `Fused::new(m)` (the last partial vector through the
/// scalar function).
///
/// # Safety
/// The CPU must support AVX2 and FMA ([`avx2_available`](crate::simd::avx2_available)).
#[target_feature(enable = "avx2,fma")]
pub(super) unsafe fn row(
    m: &AnaglyphMatrices,
    fused: &Fused,
    left: &[[u8; 4]],
    right: &[[u8; 4]],
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    let w = Lanes::new(fused);
    let n = out.len().min(left.len()).min(right.len());
    // The last eight pixel pairs computed and their result: the output is a function of the
    // pair alone, so eight pairs equal to the last ones (a flat background, both eyes) reuse it.
    let (mut last_l, mut last_r) = (_mm256_setzero_si256(), _mm256_setzero_si256());
    let mut last = eight(m, last_l, last_r);
    // Groups the fused path computed, and those it had to compute again. A matrix whose sums
    // often land on a tie (Optimized's 0.7·G + 0.3·B ends in .5 for one pair in ten, an exact
    // tie the f32 roundings decide) would compute most groups twice: once over a quarter of a
    // row's groups are recomputed, the rest of the row runs on the exact lanes alone. The bytes
    // are the same either way.
    let (mut groups, mut redone, mut exact_only) = (0u32, 0u32, false);
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
                last = if exact_only {
                    eight(m, l, r)
                } else {
                    groups += 1;
                    let (px, near) = eight_fused(&w, l, r);
                    if near == 0 {
                        px
                    } else {
                        redone += 1;
                        exact_only = redone > 4 && 4 * redone > groups;
                        eight(m, l, r)
                    }
                };
                (last_l, last_r) = (l, r);
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

    /// A xorshift64 stream of 8-byte words, from `seed`.
    fn words(seed: u64) -> impl FnMut() -> [u8; 8] {
        let mut state = seed;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state.to_le_bytes()
        }
    }

    /// `row`'s bytes for every kind against `anaglyph_pixel`'s.
    fn assert_rows_match(left: &[[u8; 4]], right: &[[u8; 4]]) {
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            let m = kind.matrices();
            let mut fast = vec![MaybeUninit::new([0u8; 4]); left.len()];
            // SAFETY: the callers checked that AVX2 and FMA are available.
            unsafe { row(&m, &Fused::new(&m), left, right, &mut fast) };
            for (k, ((l, r), f)) in left.iter().zip(right).zip(&fast).enumerate() {
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

    /// Every kind's AVX2 row gives `anaglyph_pixel`'s bytes on runs of equal pixel pairs
    /// (where the previous result is reused), 100,003 pseudo-random pairs (a length that ends
    /// mid-vector), black, white and every gray.
    #[test]
    fn avx2_rows_match_anaglyph_pixel() {
        if !crate::simd::avx2_available() {
            eprintln!("avx2_rows_match_anaglyph_pixel: NOT RUN: no AVX2 here, nothing to compare");
            return;
        }
        let mut next = words(0x2545_f491_4f6c_dd1d);
        let (mut left, mut right): (Vec<[u8; 4]>, Vec<[u8; 4]>) = (0..100_003)
            .map(|_| {
                let b = next();
                ([b[0], b[1], b[2], b[3]], [b[4], b[5], b[6], b[7]])
            })
            .unzip();
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
        assert_rows_match(&left, &right);
    }

    /// The bounds `fused_guard` rests on, checked on 2¹⁷ pseudo-random pairs per kind and
    /// channel against the exact `t* = ½ + Σ c_j·v_j` (exact in f64: each product has at most
    /// 32 significant bits and the sum spans less than 2⁵³): the fused chain within
    /// `E_fused`, the pixel function's `clamp(s)·255 + ½` within `E_pixel` where the clamp
    /// does not act, and the guard at least twice their sum. Then the pairs with `t*` within
    /// four guards of an integer in some channel, where the fused path is flagged or only just
    /// not, go through `row` for every kind.
    #[test]
    fn the_fused_bounds_hold_and_near_ties_give_anaglyph_pixel() {
        let u = 2f64.powi(-24);
        let mut next = words(0x9e37_79b9_7f4a_7c15);
        let (mut near_l, mut near_r) = (Vec::new(), Vec::new());
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            let m = kind.matrices();
            let fused = Fused::new(&m);
            for _ in 0..1 << 17 {
                let b = next();
                let (l, r) = ([b[0], b[1], b[2], 255], [b[3], b[4], b[5], 255]);
                let v = [l[0], l[1], l[2], r[0], r[1], r[2]];
                let mut near = false;
                for (c, g) in fused.coefficients.iter().zip(fused.guard) {
                    let k: f64 = c.iter().map(|c| f64::from(c.abs())).sum();
                    let (e_fused, e_pixel) = (
                        6.0001 * u * (255.0 * k + 0.5),
                        u * (7.0001 * 255.0 * k + 511.0),
                    );
                    assert!(f64::from(g) >= 2.0 * (e_fused + e_pixel), "{kind:?}");
                    let exact = 0.5
                        + c.iter()
                            .zip(v)
                            .map(|(c, v)| f64::from(*c) * f64::from(v))
                            .sum::<f64>();
                    let mut t = c[0].mul_add(f32::from(v[0]), 0.5);
                    for j in 1..6 {
                        t = c[j].mul_add(f32::from(v[j]), t);
                    }
                    assert!((f64::from(t) - exact).abs() <= e_fused, "{kind:?} {v:?}");
                    let d = v.map(|v| f32::from(v) / 255.0);
                    let s = c[0] * d[0]
                        + c[1] * d[1]
                        + c[2] * d[2]
                        + c[3] * d[3]
                        + c[4] * d[4]
                        + c[5] * d[5];
                    if (0.0..=1.0).contains(&s) {
                        let pixel = s * 255.0 + 0.5;
                        assert!(
                            (f64::from(pixel) - exact).abs() <= e_pixel,
                            "{kind:?} {v:?}"
                        );
                    }
                    near |= (exact - exact.round()).abs() < 4.0 * f64::from(g);
                }
                if near {
                    near_l.push(l);
                    near_r.push(r);
                }
            }
        }
        assert!(near_l.len() > 1000, "{} near ties", near_l.len());
        if !crate::simd::avx2_available() {
            eprintln!("the_fused_bounds_hold…: rows NOT RUN: no AVX2 here");
            return;
        }
        assert_rows_match(&near_l, &near_r);
    }
}
