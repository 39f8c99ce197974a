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
//! byte. Vectors of background pixels skip the arithmetic, as the scalar code does per pixel
//! (32 at a time where a whole run is background).
//!
//! Most drawn vectors do not take that division chain: [`Affine`] computes their colors eight
//! wide in f32 from the distance to the zero-parallax depth, and keeps them only where a
//! rounding-error bound proves them equal to the chain's; the rest go through the chain.

use std::arch::x86_64::*;
use std::mem::MaybeUninit;

use super::{PARALLAX_BACKGROUND, ParallaxRig};

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
/// depths below 1, `(u32::MAX, 0)` when there are none; eight depths per step, six
/// instructions each.
///
/// On values in [0, 1] the float minimum of all of them is the smallest drawn one when any is
/// drawn (the background's 1.0 is larger), and the float maximum of the drawn ones (the others
/// masked to 0) the largest; for non-negative floats the order of the bits is the order of the
/// values. −0, a window depth whose bits as unsigned exceed 1.0's, would not read as 0 here: a
/// buffer holding one is answered by the scalar fold, exactly, so the result is always the
/// fold's.
///
/// # Safety
/// The CPU must support AVX2 ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn drawn_extremes(c: &[f32]) -> (u32, u32) {
    let one = _mm256_set1_ps(1.0);
    // Four sets of accumulators, one per vector of a 32-depth step, so that the four chains
    // of minima and maxima run side by side (min and max are exact and associative on the
    // values in [0, 1] the result is kept for, so the order does not matter).
    let mut lo = [one; 4];
    let mut hi = [_mm256_setzero_ps(); 4];
    let mut bits_max = [_mm256_setzero_si256(); 4];
    let mut add = |i: usize, d: __m256| {
        lo[i] = _mm256_min_ps(lo[i], d);
        let drawn = _mm256_cmp_ps::<_CMP_LT_OQ>(d, one);
        hi[i] = _mm256_max_ps(hi[i], _mm256_and_ps(d, drawn));
        bits_max[i] = _mm256_max_epu32(bits_max[i], _mm256_castps_si256(d));
    };
    let (steps, tail) = c.as_chunks::<32>();
    let (blocks, rest) = tail.as_chunks::<8>();
    for step in steps {
        let p = step.as_ptr();
        // SAFETY: a step is 32 f32: four unaligned loads of eight in bounds.
        unsafe {
            add(0, _mm256_loadu_ps(p));
            add(1, _mm256_loadu_ps(p.add(8)));
            add(2, _mm256_loadu_ps(p.add(16)));
            add(3, _mm256_loadu_ps(p.add(24)));
        }
    }
    for block in blocks {
        // SAFETY: a block is eight f32 (32 bytes); the unaligned load needs no alignment.
        add(0, unsafe { _mm256_loadu_ps(block.as_ptr()) });
    }
    let lo = _mm256_min_ps(_mm256_min_ps(lo[0], lo[1]), _mm256_min_ps(lo[2], lo[3]));
    let hi = _mm256_max_ps(_mm256_max_ps(hi[0], hi[1]), _mm256_max_ps(hi[2], hi[3]));
    let bits_max = _mm256_max_epu32(
        _mm256_max_epu32(bits_max[0], bits_max[1]),
        _mm256_max_epu32(bits_max[2], bits_max[3]),
    );
    let most = _mm256_set1_epi32(0x3f80_0000);
    // All lanes' largest bits at most 1.0's (no −0): max(bits_max, 1.0's) == 1.0's everywhere.
    let in_unit = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
        _mm256_max_epu32(bits_max, most),
        most,
    ))) == 0xff;
    if !in_unit {
        return super::drawn_extremes_scalar(c);
    }
    let (mut l, mut h) = ([0f32; 8], [0f32; 8]);
    // SAFETY: each array holds 32 bytes; the unaligned stores need no alignment.
    unsafe {
        _mm256_storeu_ps(l.as_mut_ptr(), lo);
        _mm256_storeu_ps(h.as_mut_ptr(), hi);
    }
    let (lo, hi) = (
        l.into_iter().fold(1.0, f32::min),
        h.into_iter().fold(0.0, f32::max),
    );
    let (blocks_lo, blocks_hi) = if lo < 1.0 {
        ((lo.abs()).to_bits(), (hi.abs()).to_bits())
    } else {
        (u32::MAX, 0)
    };
    let (rl, rh) = super::drawn_extremes_scalar(rest);
    (blocks_lo.min(rl), blocks_hi.max(rh))
}

/// The color-scale position of a drawn pixel as an affine function of its window depth, with
/// a bound on how far it can be from `parallax_color`'s, for the eight-wide fast path of
/// [`row`].
///
/// `parallax_color` takes `t = clamp(p(d)/scale, −1, 1)` with `p = S·(b − z0/z)`, `S` the eye
/// separation times pixels per unit, and `z = n f/(f − d(f − n))`. As `1/z` is affine in the
/// window depth d, so is t before the clamp: `t(d) = α + β·d = β·(d − d0)` with
/// `α = c(b − z0/n)`, `β = c·z0(f − n)/(n f)`, `c = S/scale` and `d0 = −α/β`, the window depth
/// of zero parallax — in exact arithmetic. The reference computes t with three divisions in
/// f64; this computes it in f32 as `β·((d − h) − l)`, with `h + l` the f64 value of d0 split
/// into two f32 (so the distance from zero parallax keeps its precision where α and β nearly
/// cancel: `d − h` is exact wherever d lies within a factor 2 of h). A pixel's color is taken
/// from that only where no rounding can make the two differ:
/// - `|t̃ − t| ≤ δ`, where t is the reference's f64 value:
///   - the form's own roundings: α, β and d0 in f64 (within `2⁻⁴⁷·m` once multiplied by β,
///     `m ≥ |α|, |β|`, for `|d0| ≤ 4`), then four f32 roundings, each within `2⁻²⁴|t|` (β to
///     f32, `d − h`, `− l`, the product) and the splitting of d0 (within `2⁻⁴⁶·m`): within
///     `2⁻²²|t| + 2⁻⁴⁴·m`, which for `|t| < 2` is at most `2⁻²¹ + 2⁻⁴⁴·m`;
///   - the reference's own: its subtraction `f − d(f − n)` loses up to `f/n` ulps to
///     cancellation, the rest a few ulps: within `2⁻⁵³(f/n + 10)·m`.
///
///   `δ = 2⁻²⁰ + m·(2⁻⁴³ + (f/n + 16)·2⁻⁴⁵)` is at least twice that sum.
/// - `s = min(|t|, 1)`, the clamped distance from white, is 1-Lipschitz in t, so `|s̃ − s| ≤ δ`
///   whatever the signs (where `|t| ≥ 2`, beyond the bound's reach, both |t̃| and |t| exceed 1
///   and both s are 1), and every channel `255 + e·s` (`−255 ≤ e ≤ 0`) of the reference lies
///   within `255·δ` plus its own rounding (≤ 2⁻⁴⁴) of the exact value at s̃; the f32
///   evaluation (a product and a sum) lies within 2⁻¹⁵ of that. So where the f32 channel value
///   is more than the margin `255·δ + 2⁻¹⁴` closer to its nearest integer than ½, the
///   reference rounds to that integer too (round-half-away and round-to-nearest agree off
///   half-integers).
/// - The end (blue or red) follows the sign of t. Where the two signs differ, `|t̃| + |t| ≤ δ`,
///   so both s are at most δ and every channel of either end lies within `255·δ < ½` below 255:
///   both round to (255, 255, 255), whichever end each took. So the end is taken from t̃'s sign
///   without a test of its own. A vector whose drawn lanes lie on both sides of zero parallax
///   (a thin contour in an image) is declined, so each vector computes one end's two varying
///   channels (the third is 255 at either end: `e = 0`).
///
/// A vector with a lane that fails the test is colored by the division chain, exactly as
/// before.
pub(super) struct Affine {
    /// d0's nearest f32.
    h: __m256,
    /// The rest of d0, `d0 − h`, to f32.
    l: __m256,
    /// β to f32.
    beta: __m256,
    /// `½ − margin`, rounded down to f32: a channel is certain where its distance to the
    /// nearest integer is below this.
    limit: __m256,
}

impl Affine {
    /// The affine form for `rig` at `scale`, or `None` where the bound is unusable (a rig
    /// outside `0 < n < f`, non-finite factors, zero parallax beyond window depth ±4 (no rig
    /// whose zero-parallax plane lies between its near and far planes), or δ above 10⁻⁵: there
    /// a vector's 16 channel tests would decline more than about one vector in eight, each then
    /// computed twice: the division chain alone is then the faster program).
    #[target_feature(enable = "avx2")]
    pub(super) fn of(rig: &ParallaxRig, scale: f64) -> Option<Affine> {
        let (n, f, z0, b) = (rig.near, rig.far, rig.zero_parallax_distance, rig.balance);
        let c = rig.eye_separation * rig.pixels_per_unit / scale;
        let slope = z0 * (f - n) / (n * f);
        let (alpha, beta) = (c * (b - z0 / n), c * slope);
        let d0 = -alpha / beta;
        let h = d0 as f32;
        // Exact in f64: h is d0's nearest f32, within a factor 2 of it.
        let l = (d0 - h as f64) as f32;
        let m = c.abs() * (b.abs() + (z0 / n).abs() + slope.abs()) + 1.0;
        let delta = 2f64.powi(-20) + m * (2f64.powi(-43) + (f / n + 16.0) * 2f64.powi(-45));
        let usable = n > 0.0
            && f > n
            && [alpha, beta, m, delta].iter().all(|v| v.is_finite())
            && (beta as f32).is_finite()
            && d0.abs() <= 4.0
            && delta < 1e-5;
        usable.then(|| Affine {
            h: _mm256_set1_ps(h),
            l: _mm256_set1_ps(l),
            beta: _mm256_set1_ps(beta as f32),
            limit: _mm256_set1_ps(round_down_f32(0.5 - (255.0 * delta + 2f64.powi(-14)))),
        })
    }

    /// The eight pixels' colors (alpha opaque) where every `drawn` lane passes the test in the
    /// type's notes and the drawn lanes share a sign of t; `None` otherwise. Lanes not drawn
    /// are meaningless.
    #[target_feature(enable = "avx2")]
    fn colors(&self, d: __m256, drawn: __m256) -> Option<__m256i> {
        let t = _mm256_mul_ps(self.beta, _mm256_sub_ps(_mm256_sub_ps(d, self.h), self.l));
        let negative = _mm256_movemask_ps(_mm256_and_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_setzero_ps()),
            drawn,
        ));
        let all_drawn = _mm256_movemask_ps(drawn);
        // The end's two varying channels: `parallax_color`'s `end[k] − 255` towards blue (red
        // −255, green −191) or towards red (green −223, blue −255).
        let (e1, e2) = match negative {
            0 => (-223.0, -255.0),
            m if m == all_drawn => (-255.0, -191.0),
            _ => return None,
        };
        let s = _mm256_min_ps(
            _mm256_andnot_ps(_mm256_set1_ps(-0.0), t),
            _mm256_set1_ps(1.0),
        );
        // One channel `255 + e·s` rounded to the nearest integer, and its distance from it.
        let channel = |e: f32| {
            let v = _mm256_add_ps(_mm256_set1_ps(255.0), _mm256_mul_ps(_mm256_set1_ps(e), s));
            let r = _mm256_round_ps::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(v);
            let off = _mm256_andnot_ps(_mm256_set1_ps(-0.0), _mm256_sub_ps(v, r));
            (_mm256_cvtps_epi32(r), off)
        };
        let (c1, off1) = channel(e1);
        let (c2, off2) = channel(e2);
        let sure = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_max_ps(off1, off2), self.limit);
        if _mm256_movemask_ps(_mm256_andnot_ps(sure, drawn)) != 0 {
            return None;
        }
        let rgba = if negative == 0 {
            // (255, c1, c2, 255)
            _mm256_or_si256(
                _mm256_or_si256(_mm256_slli_epi32::<8>(c1), _mm256_slli_epi32::<16>(c2)),
                _mm256_set1_epi32(0xff00_00ff_u32 as i32),
            )
        } else {
            // (c1, c2, 255, 255)
            _mm256_or_si256(
                _mm256_or_si256(c1, _mm256_slli_epi32::<8>(c2)),
                _mm256_set1_epi32(0xffff_0000_u32 as i32),
            )
        };
        Some(rgba)
    }
}

/// The largest f32 at or below `v` (v finite and positive).
fn round_down_f32(v: f64) -> f32 {
    let r = v as f32;
    if (r as f64) > v { r.next_down() } else { r }
}

/// One row of the parallax image before the window marks: `out[k] =
/// parallax_pixel_color(rig, depth[k], scale)` (the last pixels through the scalar function).
/// `affine` is [`Affine::of`]`(rig, scale)`, made once per image; with `None` every drawn
/// vector goes through the division chain.
///
/// # Safety
/// The CPU must support AVX2 ([`crate::simd::avx2_available`]).
#[target_feature(enable = "avx2")]
pub(super) unsafe fn row(
    rig: &ParallaxRig,
    scale: f64,
    affine: Option<&Affine>,
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
    let background8 = _mm256_set_m128i(background, background);
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
    let one = _mm256_set1_ps(1.0);
    let mut k = 0;
    while k + 8 <= len {
        // Thirty-two background pixels at once (most of an image is background): one test and
        // four stores instead of four tests.
        if k + 32 <= len {
            // SAFETY: `k + 32 <= len`: 32 depths and pixels in bounds; unaligned forms.
            unsafe {
                let p = depth.as_ptr().add(k);
                let drawn = |i: usize| _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_loadu_ps(p.add(i)), one);
                let any = _mm256_or_ps(
                    _mm256_or_ps(drawn(0), drawn(8)),
                    _mm256_or_ps(drawn(16), drawn(24)),
                );
                if _mm256_movemask_ps(any) == 0 {
                    let dst = out.as_mut_ptr().add(k).cast::<__m256i>();
                    for i in 0..4 {
                        _mm256_storeu_si256(dst.add(i), background8);
                    }
                    k += 32;
                    continue;
                }
            }
        }
        // SAFETY: `k + 8 <= len`: eight depths and eight pixels (32 bytes) in bounds; the
        // unaligned forms need no alignment.
        unsafe {
            let d8 = _mm256_loadu_ps(depth.as_ptr().add(k));
            // `parallax_pixels`: drawn where `d < 1`.
            let drawn = _mm256_cmp_ps::<_CMP_LT_OQ>(d8, one);
            let dst = out.as_mut_ptr().add(k);
            if _mm256_movemask_ps(drawn) == 0 {
                _mm256_storeu_si256(dst.cast(), background8);
            } else if let Some(rgba) = affine.and_then(|a| a.colors(d8, drawn)) {
                let px = _mm256_blendv_epi8(background8, rgba, _mm256_castps_si256(drawn));
                _mm256_storeu_si256(dst.cast(), px);
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
        if !crate::simd::avx2_available() {
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
                let rig = super::super::tests::rig(near, far, z0, balance, 1024, 768);
                for len in [0usize, 1, 3, 4, 5, 7, 8, 9, 31, 1000] {
                    let depth: Vec<f32> = (0..len)
                        .map(|_| match next() % 8 {
                            0 => 1.0,
                            1 => 0.0,
                            2 => 1.0 - (next() % 1000) as f32 * 1e-7,
                            _ => (next() % 1_000_001) as f32 / 1e6,
                        })
                        .collect();
                    // SAFETY: AVX2 is available (checked above).
                    let affine = unsafe { Affine::of(&rig, scale) };
                    // The division chain alone, and with the affine form where the rig has one.
                    for affine in [None, affine.as_ref()] {
                        let mut fast = vec![MaybeUninit::new([1u8; 4]); len];
                        // SAFETY: AVX2 is available (checked above).
                        unsafe { row(&rig, scale, affine, &depth, &mut fast) };
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
        }
        assert!(checked > 10_000, "{checked} pixels compared");
    }

    /// The affine fast path gives `parallax_pixel_color`'s bytes on every float of dense
    /// intervals of window depth (each 2¹⁶ consecutive f32 values, so every color step inside
    /// them is crossed, rounding boundaries included), for rigs near and far from their near
    /// plane and scales that clamp much or nothing, and across zero parallax (where the end
    /// changes); and it is taken for nearly every vector of
    /// an ordinary rig, and declined near color steps (both counted, so a path that never ran
    /// cannot pass).
    #[test]
    fn affine_colors_match_parallax_color_on_dense_intervals() {
        if !crate::simd::avx2_available() {
            eprintln!("affine_colors_match_parallax_color_on_dense_intervals: NOT RUN: no AVX2");
            return;
        }
        let (mut fast, mut declined, mut crossings) = (0usize, 0usize, 0usize);
        let mut ordinary_fast = (0usize, 0usize);
        for (near, far, z0, balance, ordinary) in [
            (1.0, 20.0, 4.0, 1.0, true),
            (0.1, 50.0, 4.0, 1.0, false),
            (1e-5, 1.0, 0.5, 0.5, false),
            (0.5, 1e5, 2.0, 0.0, false),
        ] {
            let rig = super::super::tests::rig(near, far, z0, balance, 1024, 768);
            for scale in [0.5, 3.7, 40.0, 1e4] {
                // SAFETY: AVX2 is available (checked above).
                let Some(affine) = (unsafe { Affine::of(&rig, scale) }) else {
                    continue;
                };
                // The window depth of zero parallax (z = z0/b), where the end changes: an
                // interval centred on it, beside the fixed ones.
                let zero = (far / (far - near) * (1.0 - near * balance / z0)) as f32;
                let centred = (balance > 0.0 && zero > 0.001 && zero < 0.999)
                    .then(|| f32::from_bits(zero.to_bits() - (1 << 15)));
                for start in [0.0f32, 0.5, 0.9, 0.99, 0.999_9].into_iter().chain(centred) {
                    crossings += usize::from(centred == Some(start));
                    let mut d = [0f32; 8];
                    let mut bits = start.to_bits();
                    for _ in 0..(1 << 16) / 8 {
                        for v in &mut d {
                            *v = f32::from_bits(bits);
                            bits += 1;
                        }
                        // SAFETY: AVX2 is available; `d` holds eight floats.
                        let got = unsafe {
                            let d8 = _mm256_loadu_ps(d.as_ptr());
                            let drawn = _mm256_cmp_ps::<_CMP_LT_OQ>(d8, _mm256_set1_ps(1.0));
                            affine.colors(d8, drawn).map(|v| {
                                let mut out = [[0u8; 4]; 8];
                                _mm256_storeu_si256(out.as_mut_ptr().cast(), v);
                                out
                            })
                        };
                        let tracked = ordinary && scale == 40.0;
                        ordinary_fast.1 += usize::from(tracked);
                        let Some(got) = got else {
                            declined += 1;
                            continue;
                        };
                        fast += 1;
                        ordinary_fast.0 += usize::from(tracked);
                        for (g, v) in got.iter().zip(&d) {
                            if *v < 1.0 {
                                assert_eq!(
                                    *g,
                                    parallax_pixel_color(&rig, *v, scale),
                                    "near {near} far {far} z0 {z0} scale {scale}: depth {v}"
                                );
                            }
                        }
                    }
                }
            }
        }
        assert!(
            fast > 10_000 && declined > 100 && crossings >= 8,
            "{fast} fast, {declined} declined, {crossings} intervals across zero parallax"
        );
        eprintln!("{fast} fast, {declined} declined, {crossings} intervals across zero parallax");
        let (taken, all) = ordinary_fast;
        assert!(
            taken * 10 >= all * 9,
            "ordinary rig: {taken} of {all} vectors fast"
        );
    }

    /// The AVX2 extremes are the scalar fold's on depths with and without drawn values, −0,
    /// exact 1s, and lengths that end mid-vector, and on values no framebuffer holds (NaN, a
    /// negative, just above 1, +∞) wherever they lie.
    #[test]
    fn avx2_drawn_extremes_match_scalar() {
        if !crate::simd::avx2_available() {
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
        for len in [0usize, 1, 7, 8, 9, 45, 100, 4099] {
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
                // One value outside [0, 1] anywhere (in a block or the scalar rest).
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
        if !crate::simd::avx2_available() {
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
