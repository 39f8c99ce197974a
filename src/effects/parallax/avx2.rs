//! [`parallax_pixel_color`](super::parallax_pixel_color) for a row of pixels, four at a time
//! (AVX2, f64 lanes).
//!
//! Eight pixels per step, as two vectors of four. Each lane performs the scalar code's IEEE operations in the same order, with no fused
//! multiply-add: [`ParallaxRig::eye_distance`](super::ParallaxRig::eye_distance) (`n f / (f −
//! d (f − n))`), [`ParallaxRig::parallax`](super::ParallaxRig::parallax) and the scale to
//! pixels, then [`parallax_color`](super::parallax_color): `t = clamp(p / S, −1, 1)`, the end
//! color by the sign of t, `255 + (end − 255)·|t|` per channel, rounded half away from zero
//! (`floor(v) + (v − floor(v) ≥ ½)`, exact: `v − floor(v)` is exact for v ≥ 0, and every
//! value below 0 or NaN becomes 0 as Rust's saturating `as u8` makes it) and saturated to a
//! byte. Vectors of background pixels skip the arithmetic, as the scalar code does per pixel.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::{PARALLAX_BACKGROUND, ParallaxRig};

/// Whether the CPU runs [`row`].
pub(super) fn available() -> bool {
    is_x86_feature_detected!("avx2")
}

/// `f64::clamp(v, lo, hi)` per lane, NaN kept.
#[target_feature(enable = "avx2")]
#[inline]
fn clamp(v: __m256d, lo: f64, hi: f64) -> __m256d {
    let (lo, hi) = (_mm256_set1_pd(lo), _mm256_set1_pd(hi));
    let v = _mm256_blendv_pd(v, lo, _mm256_cmp_pd::<_CMP_LT_OQ>(v, lo));
    _mm256_blendv_pd(v, hi, _mm256_cmp_pd::<_CMP_GT_OQ>(v, hi))
}

/// `v.round() as u8` per lane (round half away from zero, saturating, NaN to 0), as i32 lanes.
#[target_feature(enable = "avx2")]
#[inline]
fn round_to_byte(v: __m256d) -> __m128i {
    let f = _mm256_floor_pd(v);
    let up = _mm256_cmp_pd::<_CMP_GE_OQ>(_mm256_sub_pd(v, f), _mm256_set1_pd(0.5));
    let r = _mm256_add_pd(f, _mm256_and_pd(up, _mm256_set1_pd(1.0)));
    // `max` returns its second operand for a NaN first one: NaN becomes 0.
    let r = _mm256_min_pd(_mm256_max_pd(r, _mm256_setzero_pd()), _mm256_set1_pd(255.0));
    _mm256_cvttpd_epi32(r)
}

/// `super::drawn_extremes_scalar(c)`: the smallest and largest bits (sign cleared) of the
/// depths below 1, `(u32::MAX, 0)` when there are none, and whether all lie in [0, 1]; eight
/// depths per step.
///
/// # Safety
/// The CPU must support AVX2 ([`available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn drawn_extremes(c: &[f32]) -> (u32, u32, bool) {
    let abs = _mm256_set1_epi32(0x7fff_ffff);
    let one = _mm256_set1_epi32(0x3f80_0000);
    let negative_zero = _mm256_set1_epi32(i32::MIN);
    let (mut lo, mut hi) = (_mm256_set1_epi32(-1), _mm256_setzero_si256());
    let mut outside = _mm256_setzero_si256();
    let (blocks, rest) = c.as_chunks::<8>();
    for block in blocks {
        // SAFETY: a block is eight f32 (32 bytes); the unaligned load needs no alignment.
        let bits = unsafe { _mm256_loadu_si256(block.as_ptr().cast()) };
        // In [0, 1]: the bits at most 1.0's as unsigned (+0 .. 1), or −0's. Negative values,
        // NaN and values above 1 have larger bits.
        let in_unit = _mm256_or_si256(
            _mm256_cmpeq_epi32(_mm256_min_epu32(bits, one), bits),
            _mm256_cmpeq_epi32(bits, negative_zero),
        );
        outside = _mm256_or_si256(outside, _mm256_xor_si256(in_unit, _mm256_set1_epi32(-1)));
        let v = _mm256_and_si256(bits, abs);
        // Signed compare: with the sign cleared every value is non-negative.
        let drawn = _mm256_cmpgt_epi32(one, v);
        // Not drawn: u32::MAX for the minimum, 0 for the maximum.
        lo = _mm256_min_epu32(
            lo,
            _mm256_or_si256(v, _mm256_xor_si256(drawn, _mm256_set1_epi32(-1))),
        );
        hi = _mm256_max_epu32(hi, _mm256_and_si256(v, drawn));
    }
    let (mut l, mut h) = ([0u32; 8], [0u32; 8]);
    // SAFETY: each array holds 32 bytes; the unaligned stores need no alignment.
    unsafe {
        _mm256_storeu_si256(l.as_mut_ptr().cast(), lo);
        _mm256_storeu_si256(h.as_mut_ptr().cast(), hi);
    }
    let (rl, rh, rest_in_unit) = super::drawn_extremes_scalar(rest);
    (
        l.into_iter().fold(rl, u32::min),
        h.into_iter().fold(rh, u32::max),
        rest_in_unit && _mm256_testz_si256(outside, outside) == 1,
    )
}

/// One row of the parallax image before the window marks: `out[k] =
/// parallax_pixel_color(rig, depth[k], scale)` (the last pixels through the scalar function).
///
/// # Safety
/// The CPU must support AVX2 ([`available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn row(
    rig: &ParallaxRig,
    scale: f64,
    depth: &[f32],
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    let (n, f) = (rig.near, rig.far);
    let (nf, fmn) = (_mm256_set1_pd(n * f), _mm256_set1_pd(f - n));
    let fv = _mm256_set1_pd(f);
    let (sep, balance) = (
        _mm256_set1_pd(rig.eye_separation),
        _mm256_set1_pd(rig.balance),
    );
    let (z0, ppu) = (
        _mm256_set1_pd(rig.zero_parallax_distance),
        _mm256_set1_pd(rig.pixels_per_unit),
    );
    let scale_v = _mm256_set1_pd(scale);
    // `parallax_color`'s `end[k] − 255` for t < 0 (towards blue) and t ≥ 0 (towards red).
    let negative_end = [0.0f64, 64.0, 255.0].map(|e| _mm256_set1_pd(e - 255.0));
    let positive_end = [255.0f64, 32.0, 0.0].map(|e| _mm256_set1_pd(e - 255.0));
    let background = _mm_set1_epi32(i32::from_le_bytes(PARALLAX_BACKGROUND));
    let alpha = _mm_set1_epi32(0xff00_0000_u32 as i32);
    let len = out.len().min(depth.len());
    // Four pixels from their depths and `drawn` mask (lanes with d < 1 set).
    let four = |d32: __m128, drawn: __m128| {
        let d = _mm256_cvtps_pd(d32);
        let z = _mm256_div_pd(nf, _mm256_sub_pd(fv, _mm256_mul_pd(d, fmn)));
        let p = _mm256_mul_pd(sep, _mm256_sub_pd(balance, _mm256_div_pd(z0, z)));
        let p = _mm256_mul_pd(p, ppu);
        let t = clamp(_mm256_div_pd(p, scale_v), -1.0, 1.0);
        let neg = _mm256_cmp_pd::<_CMP_LT_OQ>(t, _mm256_setzero_pd());
        // `-t` flips the sign bit, as the scalar negation does.
        let s = _mm256_blendv_pd(t, _mm256_xor_pd(t, _mm256_set1_pd(-0.0)), neg);
        let channel = |c: usize| {
            let e = _mm256_blendv_pd(positive_end[c], negative_end[c], neg);
            round_to_byte(_mm256_add_pd(_mm256_set1_pd(255.0), _mm256_mul_pd(e, s)))
        };
        let rgba = _mm_or_si128(
            _mm_or_si128(channel(0), _mm_slli_epi32::<8>(channel(1))),
            _mm_or_si128(_mm_slli_epi32::<16>(channel(2)), alpha),
        );
        _mm_blendv_epi8(background, rgba, _mm_castps_si128(drawn))
    };
    let mut k = 0;
    while k + 8 <= len {
        // SAFETY: `k + 8 <= len`: eight depths and eight pixels (32 bytes) in bounds; the
        // unaligned forms need no alignment.
        unsafe {
            let d8 = _mm256_loadu_ps(depth.as_ptr().add(k));
            // `parallax_pixels`: drawn where `d < 1`.
            let drawn = _mm256_cmp_ps::<_CMP_LT_OQ>(d8, _mm256_set1_ps(1.0));
            let dst = out.as_mut_ptr().add(k);
            if _mm256_movemask_ps(drawn) == 0 {
                _mm256_storeu_si256(dst.cast(), _mm256_set_m128i(background, background));
            } else {
                let lo = four(_mm256_castps256_ps128(d8), _mm256_castps256_ps128(drawn));
                let hi = four(
                    _mm256_extractf128_ps::<1>(d8),
                    _mm256_extractf128_ps::<1>(drawn),
                );
                _mm256_storeu_si256(dst.cast(), _mm256_set_m128i(hi, lo));
            }
        }
        k += 8;
    }
    for k in k..len {
        out[k].write(super::parallax_pixel_color(rig, depth[k], scale));
    }
}

#[cfg(test)]
mod tests {
    use super::super::parallax_pixel_color;
    use super::*;

    /// The AVX2 row gives `parallax_pixel_color`'s bytes for rigs with positive and negative
    /// parallax, balances 0, 1 and ½, tiny and huge scales (so the color saturates), depths
    /// across [0, 1] with the background, on rows of every tail length.
    #[test]
    fn avx2_rows_match_parallax_color() {
        if !available() {
            eprintln!("avx2_rows_match_parallax_color: NOT RUN: no AVX2 here, nothing to compare");
            return;
        }
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut checked = 0;
        for (near, far, z0, balance) in [
            (0.1, 50.0, 4.0, 1.0),
            (1.0, 20.0, 19.0, 0.0),
            (1e-5, 1.0, 0.5, 0.5),
            (0.5, 1e5, 2.0, 1.0),
        ] {
            for scale in [0.5, 3.7, 40.0, 1e4] {
                let rig = ParallaxRig {
                    eye_separation: 0.065,
                    zero_parallax_distance: z0,
                    balance,
                    near,
                    far,
                    pixels_per_unit: 731.3,
                    width: 1024,
                    height: 768,
                };
                for len in [0usize, 1, 3, 4, 5, 7, 8, 9, 31, 1000] {
                    let depth: Vec<f32> = (0..len)
                        .map(|_| match next() % 8 {
                            0 => 1.0,
                            1 => 0.0,
                            2 => 1.0 - (next() % 1000) as f32 * 1e-7,
                            _ => (next() % 1_000_001) as f32 / 1e6,
                        })
                        .collect();
                    let mut fast = vec![MaybeUninit::new([1u8; 4]); len];
                    // SAFETY: AVX2 is available (checked above).
                    unsafe { row(&rig, scale, &depth, &mut fast) };
                    for (k, (f, d)) in fast.iter().zip(&depth).enumerate() {
                        // SAFETY: initialized by `MaybeUninit::new`, then the row.
                        let f = unsafe { f.assume_init() };
                        assert_eq!(
                            f,
                            parallax_pixel_color(&rig, *d, scale),
                            "near {near} far {far} z0 {z0} scale {scale}: pixel {k}, depth {d}"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 10_000, "{checked} pixels compared");
    }

    /// The AVX2 extremes are the scalar fold's on depths with and without drawn values, −0,
    /// exact 1s, and lengths that end mid-vector; both find a value outside [0, 1] (NaN, a
    /// negative, just above 1, +∞) wherever it lies.
    #[test]
    fn avx2_drawn_extremes_match_scalar() {
        if !available() {
            eprintln!("avx2_drawn_extremes_match_scalar: NOT RUN: no AVX2 here");
            return;
        }
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for len in [0usize, 1, 7, 8, 9, 100, 4099] {
            for background_share in [0, 1, 2, 7, 8] {
                let c: Vec<f32> = (0..len)
                    .map(|_| match next() % 8 {
                        k if k < background_share => 1.0,
                        0 => -0.0,
                        _ => (next() % 1_000_000) as f32 / 1e6,
                    })
                    .collect();
                // SAFETY: AVX2 is available (checked above).
                let fast = unsafe { drawn_extremes(&c) };
                assert_eq!(fast, super::super::drawn_extremes_scalar(&c), "len {len}");
                assert!(fast.2, "len {len}: all in [0, 1]");
                // One value outside [0, 1] anywhere (in a block or the scalar rest) is found.
                for bad in [
                    f32::NAN,
                    -f32::MIN_POSITIVE,
                    1.0f32.next_up(),
                    f32::INFINITY,
                ] {
                    for at in [0, len / 2, len.saturating_sub(1)] {
                        if len == 0 {
                            continue;
                        }
                        let mut d = c.clone();
                        d[at] = bad;
                        // SAFETY: AVX2 is available (checked above).
                        let fast = unsafe { drawn_extremes(&d) };
                        assert!(!fast.2, "len {len}: {bad} at {at}");
                        assert_eq!(fast, super::super::drawn_extremes_scalar(&d), "len {len}");
                    }
                }
            }
        }
    }

    /// The rounding helper on the values where rounding is delicate: exact halves, the
    /// largest double below ½, the ends of the byte, values beyond it and NaN.
    #[test]
    fn round_to_byte_is_round_as_u8() {
        if !available() {
            eprintln!("round_to_byte_is_round_as_u8: NOT RUN: no AVX2 here");
            return;
        }
        let below_half = 0.5f64.next_down();
        let values = [
            0.0,
            -0.0,
            below_half,
            0.5,
            1.5,
            2.5,
            254.5,
            254.49999999999997,
            255.0,
            255.4,
            255.5,
            300.0,
            -0.4,
            -0.5,
            -3.7,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            127.5 + 1e-12,
            3.0 - 1e-13,
        ];
        for chunk in values.chunks(4) {
            let mut v = [0.0f64; 4];
            v[..chunk.len()].copy_from_slice(chunk);
            let mut got = [0i32; 4];
            // SAFETY: AVX2 is available (checked above); four lanes in and out.
            unsafe {
                let r = round_to_byte(_mm256_loadu_pd(v.as_ptr()));
                _mm_storeu_si128(got.as_mut_ptr().cast(), r);
            }
            for (x, g) in v.iter().zip(got) {
                assert_eq!(g, x.round() as u8 as i32, "round({x})");
            }
        }
    }
}
