//! [`anaglyph_pixel`](super::anaglyph_pixel) on stored values, sixteen pixels at a time (AVX2
//! and FMA).
//!
//! Two ways to the same bytes. [`exact`] performs the scalar code's IEEE operations in each
//! lane in the same order — `v / 255` per channel, each row of `ML · left + MR · right` summed
//! left to right, the clamp, then `clamp(c)·255 + ½` truncated — with no fused multiply-add
//! in the sums (the division is an exactly rounded quotient by other means, [`decode`]). The
//! fused path ([`block`]) skips the divisions and the clamp: per channel `t = ½ + Σ c_j·v_j`
//! on the raw 8-bit values with fused multiply-adds, in 16.16 fixed point, the byte `⌊t⌋`
//! saturated to 0..255, and the lanes whose `t` lies within [`fused_guard`](super::fused_guard)
//! of an integer (where the two roundings could disagree) flagged; eight pixels with a flagged
//! lane are computed again by [`exact`]. `avx2_rows_match_anaglyph_pixel` and the bound's
//! tests hold every kind to the scalar function. The scalar loop stays the reference; it runs
//! where the CPU has no AVX2 and for linear light (whose `powf` has no vector form here).
//!
//! Both paths leave out the terms whose coefficient is zero where the matrix pair has one of
//! the [`SHAPES`] of the stored kinds (a loop each); the Dubois matrices use all eighteen.
//!
//! Sixteen pixel pairs equal to the last eight computed, twice over (a flat background in both
//! eyes), reuse the last result instead of computing it again: the same bytes, since a pixel's
//! result depends on its pair alone. The vector test runs only where a block's first pair
//! equals the first of those eight (two scalar compares), so rows without such runs (random
//! colours) pay next to nothing for it.
//!
//! What bounds the fused path on random colours with all eighteen coefficients (Dubois): per
//! eight pixels 18 multiply-adds, 6 channel extractions and 6 conversions in, 3 conversions and
//! about 14 shifts, blends, shuffles and compares out, with the loads, copies and stores some 60
//! instructions on the vector pipes. Measured on a Zen 3 core (loops of each instruction,
//! `asm!`): two multiply-adds a cycle, the conversions, masks and blends on two more pipes, two
//! aligned 32-byte loads a cycle: about 15 cycles at best, about 22 measured. Measured slower
//! in the release build: blocks whose input channel is the outer loop, each coefficient loaded
//! once for two, three or four groups (two groups were faster only in a build of one codegen
//! unit), each channel's sum in two shorter chains (left eye, right eye), each block's rounding
//! deferred into the next block's sums.

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

/// The 8-bit values `v` of one channel (already zero-extended to 32 bits in every lane), as
/// `v as f32 / 255` exactly rounded: `q = v·r` with `r = 1/255` rounded, its residual `e = v −
/// 255·q` (one fused multiply-add), then `q + e·r` (one more). For every `v` in 0..=255 this is
/// the quotient `/` rounds to (`decode_is_the_rounded_quotient` checks all 256), without the
/// division's latency.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn decode(v: __m256i) -> __m256 {
    let v = _mm256_cvtepi32_ps(v);
    let r = _mm256_set1_ps(1.0 / 255.0);
    let q = _mm256_mul_ps(v, r);
    let e = _mm256_fnmadd_ps(q, _mm256_set1_ps(255.0), v);
    _mm256_fmadd_ps(e, r, q)
}

/// The constants of both paths for one matrix pair.
pub(super) struct Fused {
    /// The fused path's coefficients, per output channel `ML`'s row then `MR`'s: `c_j·2¹⁶` for
    /// the red inputs, `c_j·2⁸` for green and `c_j` for blue, whose lanes hold `v·2⁰`, `v·2⁸`
    /// and `v·2¹⁶` (each channel masked in place), so every product is `c_j·v_j·2¹⁶` exactly
    /// and `t` comes out in 16.16 fixed point.
    scaled: [[f32; 6]; 3],
    /// Per output channel `G = ⌈g·2¹⁶ + ½⌉`, its [`fused_guard`] `g` in units of 2⁻¹⁶ with room
    /// for the conversion's rounding ([`finish`]).
    units: [i32; 3],
    /// Whether the fused path's conditions hold: every `|t| < 2¹⁵`, every `G` below 2¹⁴, every
    /// scaled coefficient exact. Where they do not (no kind here), every pixel takes [`exact`].
    fused: bool,
    /// Per output channel its six coefficients, `ML`'s row then `MR`'s ([`exact`]'s).
    coefficients: [[f32; 6]; 3],
    /// Which coefficients are not zero ([`shape`]).
    shape: u32,
}

impl Fused {
    /// `m`'s rows, their guards and scaled forms.
    pub(super) fn new(m: &AnaglyphMatrices) -> Fused {
        let coefficients = [0, 1, 2].map(|i| {
            let (l, r) = (m.left[i], m.right[i]);
            [l[0], l[1], l[2], r[0], r[1], r[2]]
        });
        let scale = [65536.0f32, 256.0, 1.0, 65536.0, 256.0, 1.0];
        let scaled = coefficients.map(|c| [0, 1, 2, 3, 4, 5].map(|j| c[j] * scale[j]));
        let units = coefficients.map(|c| (f64::from(fused_guard(c)) * 65536.0 + 0.5).ceil() as i32);
        let exact_scaling = (0..3).all(|i| {
            (0..6).all(|j| {
                let s = scaled[i][j];
                s / scale[j] == coefficients[i][j] && (s == 0.0 || s.is_normal())
            })
        });
        let in_range = coefficients
            .iter()
            .all(|c| c.iter().map(|c| c.abs()).sum::<f32>() * 255.0 + 1.0 < 32768.0);
        let shape = (0..18)
            .filter(|&b| coefficients[b / 6][b % 6] != 0.0)
            .fold(0, |shape, b| shape | 1 << b);
        Fused {
            shape,
            scaled,
            units,
            fused: exact_scaling && in_range && units.iter().all(|&g| g < 16384),
            coefficients,
        }
    }
}

/// [`Fused`] broadcast to every lane, and the flag test's constants.
struct Lanes {
    /// The scaled coefficients, once per group of a block: each load then feeds one
    /// multiply-add as its memory operand (a reload into a register shared by the two groups
    /// would be one more instruction each).
    scaled: [[[__m256; 6]; 3]; 2],
    /// The coefficients as [`exact`] multiplies them.
    coefficients: [[__m256; 6]; 3],
    /// Per 16-bit word of a group's red-green fractions (red low, green high) and of its blue
    /// lanes (fraction low, integer part high): `G + 2¹⁵` and `2G − 2¹⁵ − 1`, so that
    /// `frac + G + 2¹⁵ > 2G − 2¹⁵ − 1` as i16 exactly where `frac` lies in `G..2¹⁶ − G`. The
    /// blue integer part's word adds 0 and compares with −2¹⁵ (true for every part in range).
    off_rg: __m256i,
    lim_rg: __m256i,
    off_b: __m256i,
    lim_b: __m256i,
}

impl Lanes {
    #[target_feature(enable = "avx2")]
    fn new(f: &Fused) -> Lanes {
        let mut scaled = [[_mm256_setzero_ps(); 6]; 3];
        let mut coefficients = [[_mm256_setzero_ps(); 6]; 3];
        for i in 0..3 {
            for j in 0..6 {
                scaled[i][j] = _mm256_set1_ps(f.scaled[i][j]);
                coefficients[i][j] = _mm256_set1_ps(f.coefficients[i][j]);
            }
        }
        let [r, g, b] = f.units;
        // `G + 2¹⁵` and `2G − 2¹⁵ − 1` as 16-bit words, the first of a lane low.
        let words = |lo: i32, hi: i32| _mm256_set1_epi32((lo & 0xffff) | (hi << 16));
        let (off, lim) = (|g: i32| g + 0x8000, |g: i32| 2 * g - 0x8000 - 1);
        Lanes {
            scaled: [scaled, scaled],
            coefficients,
            off_rg: words(off(r), off(g)),
            lim_rg: words(lim(r), lim(g)),
            off_b: words(off(b), 0),
            lim_b: words(lim(b), -0x8000),
        }
    }
}

/// Lanes where both pairs equal the last ones, all ones, as [`_mm256_cmpeq_epi32`] gives them.
#[target_feature(enable = "avx2")]
#[inline]
fn same(l: __m256i, r: __m256i, last_l: __m256i, last_r: __m256i) -> __m256i {
    _mm256_and_si256(_mm256_cmpeq_epi32(l, last_l), _mm256_cmpeq_epi32(r, last_r))
}

/// Eight pixels: `out[k] = anaglyph_pixel(m, left[k], right[k], false)` for `k < 8`, as words
/// (RGBA in memory order, little-endian), `SHAPE` holding every nonzero coefficient. Terms
/// outside it are left out: the scalar sum adds their product `+0` (or `−0`), which leaves a
/// sum unchanged but for the sign of a zero, and a zero of either sign gives the byte 0.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn exact<const SHAPE: u32>(w: &Lanes, l: __m256i, r: __m256i) -> __m256i {
    let mut d = [_mm256_setzero_ps(); 6];
    for (j, d) in d.iter_mut().enumerate() {
        if SHAPE & (0b1_000001_000001 << j) != 0 {
            let p = if j < 3 { l } else { r };
            let c = match j % 3 {
                0 => p,
                1 => _mm256_srli_epi32::<8>(p),
                _ => _mm256_srli_epi32::<16>(p),
            };
            *d = decode(_mm256_and_si256(c, _mm256_set1_epi32(0xff)));
        }
    }
    let mut out = _mm256_set1_epi32(0xff00_0000_u32 as i32);
    for i in 0..3 {
        // `+0 + p` is `p` (a `−0` becomes `+0`), so starting from zero changes no sum.
        let mut v = _mm256_setzero_ps();
        for (j, d) in d.iter().enumerate() {
            if SHAPE & (1 << (6 * i + j)) != 0 {
                v = _mm256_add_ps(v, _mm256_mul_ps(w.coefficients[i][j], *d));
            }
        }
        // `mix`'s clamp, then `to_u8`'s (a no-op on a clamped value: clamping is idempotent)
        // and its rounding; a NaN truncates to i32::MIN, whose low byte is 0, as Rust's
        // saturating `as u8` gives.
        let d255 = _mm256_set1_ps(255.0);
        let q = _mm256_add_ps(_mm256_mul_ps(clamp01(v), d255), _mm256_set1_ps(0.5));
        let c = _mm256_and_si256(_mm256_cvttps_epi32(q), _mm256_set1_epi32(0xff));
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

/// Eight pixels the fast way, from their three channel sums `q` in 16.16 fixed point (the
/// nearest integers to `2¹⁶·t`): the bytes `⌊t⌋` saturated to 0..255 (alpha 255), as words like
/// [`exact`]'s, and a mask whose bytes are all ones where every channel's fraction lies in
/// `G..2¹⁶ − G`: [`exact`]'s bytes there.
///
/// Why: `q` is within ½ of `2¹⁶·t`, so a fraction in that range puts `t` at least
/// `(G − ½)·2⁻¹⁶ ≥ g` from every integer ([`fused_guard`]), and `⌊t⌋ = q >> 16` (no multiple
/// of 2¹⁶ lies between `2¹⁶·t` and `q`).
#[target_feature(enable = "avx2")]
#[inline]
fn finish(w: &Lanes, q: [__m256i; 3]) -> (__m256i, __m256i) {
    // Per 32-bit lane, as 16-bit words: R and G integer parts, R and G fractions, B integer
    // part and alpha.
    let rg = _mm256_blend_epi16::<0xAA>(_mm256_srli_epi32::<16>(q[0]), q[1]);
    let rg_frac = _mm256_blend_epi16::<0xAA>(q[0], _mm256_slli_epi32::<16>(q[1]));
    let ba =
        _mm256_blend_epi16::<0xAA>(_mm256_srli_epi32::<16>(q[2]), _mm256_set1_epi32(255 << 16));
    let ok_rg = _mm256_cmpgt_epi16(_mm256_add_epi16(rg_frac, w.off_rg), w.lim_rg);
    let ok_b = _mm256_cmpgt_epi16(_mm256_add_epi16(q[2], w.off_b), w.lim_b);
    // Within each 128-bit half (pixels 0–3, 4–7): R0 G0 R1 G1 … B0 A B1 A … saturated to u8,
    // then reordered to R G B A per pixel.
    let planar = _mm256_packus_epi16(rg, ba);
    let order = _mm256_setr_epi8(
        0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12, 13, 6, 7, 14, 15, 0, 1, 8, 9, 2, 3, 10, 11, 4, 5, 12,
        13, 6, 7, 14, 15,
    );
    (
        _mm256_shuffle_epi8(planar, order),
        _mm256_and_si256(ok_rg, ok_b),
    )
}

/// Bit `6·i + j` of a matrix pair's shape: coefficient `j` (`ML`'s row, then `MR`'s) of output
/// channel `i` is not zero.
const fn shape(terms: &[(usize, usize)]) -> u32 {
    let mut bits = 0;
    let mut k = 0;
    while k < terms.len() {
        bits |= 1 << (6 * terms[k].0 + terms[k].1);
        k += 1;
    }
    bits
}

/// Every coefficient in use.
const DENSE: u32 = (1 << 18) - 1;
/// The shapes [`row`] has a loop of its own for (the fused path leaves out the other terms
/// and inputs): luma to red from the left eye and to blue from the right (`True`); to red, and
/// to green and blue (`Gray`); red from the left eye, green and blue from the right (`Color`);
/// luma to red, green and blue from the right (`HalfColor`); green and blue of the left eye to
/// red, green and blue from the right (`Optimized`). Any other shape takes the dense loop.
const SHAPES: [u32; 5] = [
    shape(&[(0, 0), (0, 1), (0, 2), (2, 3), (2, 4), (2, 5)]),
    shape(&[
        (0, 0),
        (0, 1),
        (0, 2),
        (1, 3),
        (1, 4),
        (1, 5),
        (2, 3),
        (2, 4),
        (2, 5),
    ]),
    shape(&[(0, 0), (1, 4), (2, 5)]),
    shape(&[(0, 0), (0, 1), (0, 2), (1, 4), (2, 5)]),
    shape(&[(0, 1), (0, 2), (1, 4), (2, 5)]),
];

/// Sixteen pixels the fast way (two groups of eight, `left`/`right` pointing at the first):
/// per group and channel `t = ½ + Σ c_j·v_j`, the terms in `ML`, `MR` order, each a fused
/// multiply-add, all scaled by 2¹⁶ ([`Fused::scaled`], exact), rounded to integers and
/// [`finish`]ed. Terms outside `SHAPE` are left out (their coefficient is zero, and a fused
/// multiply-add of zero returns its addend).
///
/// # Safety
/// Sixteen pixels must be readable at `left` and `right`.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn block<const SHAPE: u32>(
    w: &Lanes,
    left: *const [u8; 4],
    right: *const [u8; 4],
) -> [(__m256i, __m256i); 2] {
    let masks = [
        _mm256_set1_epi32(0xff),
        _mm256_set1_epi32(0xff00),
        _mm256_set1_epi32(0xff_0000),
    ];
    let half = _mm256_set1_ps(32768.0);
    let mut t = [[half; 3]; 2];
    for j in 0..6 {
        if SHAPE & (0b1_000001_000001 << j) == 0 {
            continue;
        }
        let eye = if j < 3 { left } else { right };
        for (g, t) in t.iter_mut().enumerate() {
            // SAFETY: the caller's sixteen pixels; the unaligned load needs no alignment.
            let p = unsafe { _mm256_loadu_si256(eye.add(8 * g).cast()) };
            let x = _mm256_cvtepi32_ps(_mm256_and_si256(p, masks[j % 3]));
            for (i, t) in t.iter_mut().enumerate() {
                if SHAPE & (1 << (6 * i + j)) != 0 {
                    *t = _mm256_fmadd_ps(w.scaled[g][i][j], x, *t);
                }
            }
        }
    }
    let mut out = [(_mm256_setzero_si256(), _mm256_setzero_si256()); 2];
    for (out, t) in out.iter_mut().zip(t) {
        *out = finish(
            w,
            [
                _mm256_cvtps_epi32(t[0]),
                _mm256_cvtps_epi32(t[1]),
                _mm256_cvtps_epi32(t[2]),
            ],
        );
    }
    out
}

/// The rest of a row on [`exact`] alone, from pixel `k` on in groups of eight (eight pairs equal
/// to the last eight reuse their result); returns where the groups end.
///
/// # Safety
/// `n` pixels must be readable at `left` and `right` and writable at `out`.
#[inline(never)]
#[target_feature(enable = "avx2,fma")]
unsafe fn exact_rest<const SHAPE: u32>(
    w: &Lanes,
    left: *const [u8; 4],
    right: *const [u8; 4],
    out: *mut MaybeUninit<[u8; 4]>,
    mut k: usize,
    n: usize,
) -> usize {
    let (mut last_l, mut last_r) = (_mm256_set1_epi32(-1), _mm256_set1_epi32(-1));
    let mut last = _mm256_setzero_si256();
    let mut fresh = true;
    while k + 8 <= n {
        // SAFETY: `k + 8 <= n`, so eight pixels (32 bytes) are in bounds; the unaligned forms
        // need no alignment.
        unsafe {
            let l = _mm256_loadu_si256(left.add(k).cast());
            let r = _mm256_loadu_si256(right.add(k).cast());
            if fresh || _mm256_movemask_epi8(same(l, r, last_l, last_r)) != -1 {
                (last_l, last_r, last, fresh) = (l, r, exact::<SHAPE>(w, l, r), false);
            }
            _mm256_storeu_si256(out.add(k).cast(), last);
        }
        k += 8;
    }
    k
}

/// The groups of the block at pixel `k` whose mask (`ok0`, `ok1`) is not all ones, again on
/// [`exact`]; returns how many. Out of line: the fused loop keeps its registers.
///
/// # Safety
/// Sixteen pixels must be readable at `left + k` and `right + k` and writable at `out + k`.
#[cold]
#[inline(never)]
#[target_feature(enable = "avx2,fma")]
unsafe fn redo<const SHAPE: u32>(
    w: &Lanes,
    left: *const [u8; 4],
    right: *const [u8; 4],
    out: *mut MaybeUninit<[u8; 4]>,
    k: usize,
    ok: [__m256i; 2],
) -> u32 {
    let mut redone = 0;
    for (g, ok) in ok.into_iter().enumerate() {
        if _mm256_movemask_epi8(ok) != -1 {
            let at = k + 8 * g;
            // SAFETY: the caller's sixteen pixels; the unaligned forms need no alignment.
            unsafe {
                let l = _mm256_loadu_si256(left.add(at).cast());
                let r = _mm256_loadu_si256(right.add(at).cast());
                _mm256_storeu_si256(out.add(at).cast(), exact::<SHAPE>(w, l, r));
            }
            redone += 1;
        }
    }
    redone
}

/// One row of the stored-value anaglyph: `out[k] = anaglyph_pixel(m, left[k], right[k],
/// false)` for every pixel, `fused` being `Fused::new(m)` (the last partial block through the
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
    // SAFETY (all arms): the caller's promise, passed on.
    unsafe {
        match fused.shape {
            s if s == SHAPES[0] => row_on::<{ SHAPES[0] }>(m, fused, left, right, out),
            s if s == SHAPES[1] => row_on::<{ SHAPES[1] }>(m, fused, left, right, out),
            s if s == SHAPES[2] => row_on::<{ SHAPES[2] }>(m, fused, left, right, out),
            s if s == SHAPES[3] => row_on::<{ SHAPES[3] }>(m, fused, left, right, out),
            s if s == SHAPES[4] => row_on::<{ SHAPES[4] }>(m, fused, left, right, out),
            _ => row_on::<DENSE>(m, fused, left, right, out),
        }
    }
}

/// [`row`] with the fused path's terms limited to `SHAPE` (which holds every nonzero
/// coefficient of `fused`).
///
/// # Safety
/// As [`row`].
#[target_feature(enable = "avx2,fma")]
unsafe fn row_on<const SHAPE: u32>(
    m: &AnaglyphMatrices,
    fused: &Fused,
    left: &[[u8; 4]],
    right: &[[u8; 4]],
    out: &mut [MaybeUninit<[u8; 4]>],
) {
    let w = Lanes::new(fused);
    let n = out.len().min(left.len()).min(right.len());
    let (pl, pr, po) = (left.as_ptr(), right.as_ptr(), out.as_mut_ptr());
    // Where the last eight pixel pairs computed start, and their result: the output is a
    // function of the pair alone, so pairs equal to them (a flat background, both eyes) reuse
    // it. A block whose first pair differs from the first of those (two scalar compares) is
    // computed without the vector test.
    let mut last_at = None;
    let mut last = _mm256_setzero_si256();
    // Groups the fused path computed, and those it had to compute again. A matrix whose sums
    // often land on a tie (Optimized's 0.7·G + 0.3·B ends in .5 for one pair in ten, an exact
    // tie the f32 roundings decide) would compute most groups twice: once over a quarter of a
    // row's groups are recomputed, the rest of the row runs on the exact lanes alone. The bytes
    // are the same either way.
    let (mut groups, mut redone) = (0u32, 0u32);
    let mut k = 0;
    if !fused.fused {
        // SAFETY: `n` pixels are in bounds in all three slices.
        k = unsafe { exact_rest::<SHAPE>(&w, pl, pr, po, k, n) };
    }
    while k + 16 <= n {
        // SAFETY: `k + 16 <= n` and `at + 8 <= k`, so the sixteen pixels (64 bytes) at `k` and
        // the eight at `at` are in bounds in all three slices; the unaligned forms need no
        // alignment.
        unsafe {
            if let Some(at) = last_at
                && *pl.add(k) == *pl.add(at)
                && *pr.add(k) == *pr.add(at)
            {
                let ll = _mm256_loadu_si256(pl.add(at).cast());
                let lr = _mm256_loadu_si256(pr.add(at).cast());
                let (l0, r0) = (pl.add(k).cast(), pr.add(k).cast());
                let (l1, r1) = (pl.add(k + 8).cast(), pr.add(k + 8).cast());
                let both = _mm256_and_si256(
                    same(_mm256_loadu_si256(l0), _mm256_loadu_si256(r0), ll, lr),
                    same(_mm256_loadu_si256(l1), _mm256_loadu_si256(r1), ll, lr),
                );
                if _mm256_movemask_epi8(both) == -1 {
                    _mm256_storeu_si256(po.add(k).cast(), last);
                    _mm256_storeu_si256(po.add(k + 8).cast(), last);
                    k += 16;
                    continue;
                }
            }
            groups += 2;
            let [(p0, ok0), (p1, ok1)] = block::<SHAPE>(&w, pl.add(k), pr.add(k));
            _mm256_storeu_si256(po.add(k).cast(), p0);
            _mm256_storeu_si256(po.add(k + 8).cast(), p1);
            (last_at, last) = (Some(k + 8), p1);
            if _mm256_movemask_epi8(_mm256_and_si256(ok0, ok1)) != -1 {
                redone += redo::<SHAPE>(&w, pl, pr, po, k, [ok0, ok1]);
                last = _mm256_loadu_si256(po.add(k + 8).cast());
            }
        }
        k += 16;
        if redone > 4 && 4 * redone > groups {
            // SAFETY: as above.
            k = unsafe { exact_rest::<SHAPE>(&w, pl, pr, po, k, n) };
        }
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

    /// `row`'s bytes against `anaglyph_pixel`'s for one matrix pair.
    fn assert_row_matches(m: &AnaglyphMatrices, left: &[[u8; 4]], right: &[[u8; 4]], label: &str) {
        let mut fast = vec![MaybeUninit::new([0u8; 4]); left.len()];
        // SAFETY: the callers checked that AVX2 and FMA are available.
        unsafe { row(m, &Fused::new(m), left, right, &mut fast) };
        for (k, ((l, r), f)) in left.iter().zip(right).zip(&fast).enumerate() {
            // SAFETY: every element was initialized (by `MaybeUninit::new`, then `row`).
            let f = unsafe { f.assume_init() };
            assert_eq!(
                f,
                anaglyph_pixel(m, *l, *r, false),
                "{label}: pixel {k}, left {l:?}, right {r:?}"
            );
        }
    }

    /// `row`'s bytes for every kind against `anaglyph_pixel`'s.
    fn assert_rows_match(left: &[[u8; 4]], right: &[[u8; 4]]) {
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            assert_row_matches(&kind.matrices(), left, right, &format!("{kind:?}"));
        }
    }

    /// Every kind `AnaglyphKind::ALL` lists has a loop of its own: its shape is one of
    /// `SHAPES`, or dense.
    #[test]
    fn every_stored_kind_has_its_own_loop() {
        for kind in AnaglyphKind::ALL {
            let shape = Fused::new(&kind.matrices()).shape;
            assert!(
                shape == DENSE || SHAPES.contains(&shape),
                "{kind:?}: {shape:018b}"
            );
        }
    }

    /// `decode` is `v as f32 / 255` bit for bit for every 8-bit `v`.
    #[test]
    fn decode_is_the_rounded_quotient() {
        if !crate::simd::avx2_available() {
            eprintln!("decode_is_the_rounded_quotient: NOT RUN: no AVX2 here");
            return;
        }
        for first in (0..256).step_by(8) {
            let v: [i32; 8] = std::array::from_fn(|k| first + k as i32);
            let mut got = [0.0f32; 8];
            // SAFETY: AVX2 and FMA are available (checked above); eight lanes in and out.
            unsafe {
                let d = decode(_mm256_loadu_si256(v.as_ptr().cast()));
                _mm256_storeu_ps(got.as_mut_ptr(), d);
            }
            for (v, g) in v.iter().zip(got) {
                assert_eq!(g.to_bits(), (*v as f32 / 255.0).to_bits(), "{v} / 255");
            }
        }
    }

    /// Matrices outside the fused path's conditions (a sum beyond ±2¹⁵, a blue coefficient, which
    /// is not scaled, that is subnormal) run on the exact lanes alone, with `anaglyph_pixel`'s
    /// bytes.
    #[test]
    fn rows_outside_the_fused_range_give_anaglyph_pixel() {
        if !crate::simd::avx2_available() {
            eprintln!("rows_outside_the_fused_range…: NOT RUN: no AVX2 here");
            return;
        }
        let mut next = words(0x6a09_e667_f3bc_c908);
        let (left, right): (Vec<[u8; 4]>, Vec<[u8; 4]>) = (0..4099)
            .map(|_| {
                let b = next();
                ([b[0], b[1], b[2], b[3]], [b[4], b[5], b[6], b[7]])
            })
            .unzip();
        let large = AnaglyphMatrices {
            left: [[200.0, -150.0, 3.0], [0.5, 0.25, 0.0], [0.0, 0.0, 1.0]],
            right: [[-60.0, 0.0, 0.0], [0.0, 0.25, 0.0], [0.1, 0.2, 0.3]],
        };
        let tiny = AnaglyphMatrices {
            left: [[0.0, 0.5, 1e-40], [0.3, 0.3, 0.4], [0.0, 0.0, 0.0]],
            right: [[0.0, 0.5, 0.0], [0.0, 0.0, 0.0], [0.2, 0.7, 0.1]],
        };
        for (m, label) in [(large, "large"), (tiny, "tiny")] {
            assert!(!Fused::new(&m).fused, "{label}");
            assert_row_matches(&m, &left, &right, label);
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
        // Runs for the reuse of the last eight computed: all-zero pairs, a flat run, the same
        // left eye with a right eye that changes in one pixel (no reuse), a block whose first
        // pair equals the first of the last eight computed but whose eleventh does not, and a
        // run that starts mid-block.
        let (a, b) = ([24, 24, 24, 255], [25, 24, 24, 255]);
        let runs: [([u8; 4], [u8; 4], usize); 7] = [
            ([0; 4], [0; 4], 24),
            (a, a, 40),
            (a, b, 5),
            (a, a, 37),
            (a, b, 1),
            (a, a, 10),
            ([200, 10, 99, 255], [3, 250, 77, 255], 37),
        ];
        let mut front = Vec::new();
        for (l, r, len) in runs {
            front.extend(std::iter::repeat_n((l, r), len));
        }
        let (fl, fr): (Vec<_>, Vec<_>) = front.iter().copied().unzip();
        left.splice(0..0, fl.iter().copied());
        right.splice(0..0, fr.iter().copied());
        // The same runs after the random pairs, where a row of many ties (Optimized) already
        // runs on the exact lanes alone.
        left.extend(&fl);
        right.extend(&fr);
        assert_rows_match(&left, &right);
    }

    /// The bounds `fused_guard` rests on, checked on 2¹⁷ pseudo-random pairs per kind and
    /// channel against the exact `t* = ½ + Σ c_j·v_j` (exact in f64: each product has at most
    /// 32 significant bits and the sum spans less than 2⁵³): the fused chain within
    /// `E_fused`, the pixel function's `clamp(s)·255 + ½` within `E_pixel` where the clamp
    /// does not act, and the guard at least their sum. Then the pairs with `t*` within
    /// four guards of an integer in some channel, where the fused path is flagged or only just
    /// not, go through `row` for every kind.
    #[test]
    fn the_fused_bounds_hold_and_near_ties_give_anaglyph_pixel() {
        let u = 2f64.powi(-24);
        let mut next = words(0x9e37_79b9_7f4a_7c15);
        let (mut near_l, mut near_r) = (Vec::new(), Vec::new());
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            let m = kind.matrices();
            let coefficients = [0, 1, 2].map(|i| {
                let (l, r) = (m.left[i], m.right[i]);
                [l[0], l[1], l[2], r[0], r[1], r[2]]
            });
            for _ in 0..1 << 17 {
                let b = next();
                let (l, r) = ([b[0], b[1], b[2], 255], [b[3], b[4], b[5], 255]);
                let v = [l[0], l[1], l[2], r[0], r[1], r[2]];
                let mut near = false;
                for c in &coefficients {
                    let g = fused_guard(*c);
                    let k: f64 = c.iter().map(|c| f64::from(c.abs())).sum();
                    let (e_fused, e_pixel) = (
                        6.0001 * u * (255.0 * k + 0.5),
                        u * (7.0001 * 255.0 * k + 511.0),
                    );
                    assert!(f64::from(g) >= e_fused + e_pixel, "{kind:?}");
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
