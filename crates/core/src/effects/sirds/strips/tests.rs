//! The strip loops' own check: reads of pixels not final yet, scalar and AVX2.

use super::*;
use crate::simd::avx2_available;

/// A source reaching into the running strip or one still to come (in real scenes only
/// past a sliver's edge) reads the pattern there, as the paper's ping-pong textures would
/// give it: resolving in place, scalar and AVX2, equals a two-image reference, both
/// filters, both directions, sources anywhere in the row.
#[test]
fn reads_of_unfinished_pixels_see_the_pattern() {
    let (w, sw) = (64usize, 8u32);
    let y = 5;
    // Gray (the one-channel mix) and color.
    for (bilinear, pattern) in [false, true].into_iter().flat_map(|b| {
        [
            (b, SirdsPattern::Gray { seed: 3 }),
            (b, SirdsPattern::Color { seed: 4 }),
        ]
    }) {
        let start: Vec<[u8; 4]> = (0..w as u32).map(|x| pattern.color(x, y)).collect();
        for toward in [1.0f32, -1.0] {
            // Pseudo-random sources over the whole row, every fifth pixel without one.
            let sources: Vec<f32> = (0..w)
                .map(|x| {
                    let r = (x as u32).wrapping_mul(2_654_435_761) >> 7;
                    if x % 5 == 0 {
                        f32::NAN
                    } else {
                        (r % 6200) as f32 / 100.0
                    }
                })
                .collect();
            let strips: Vec<Strip> = (0..w as u32 / sw)
                .map(|k| {
                    let x0 = if toward > 0.0 {
                        k * sw
                    } else {
                        w as u32 - (k + 1) * sw
                    };
                    Strip {
                        x0,
                        width: sw,
                        toward,
                        lo: 0,
                        hi: w as i64,
                    }
                })
                .collect();
            // Reference: each strip reads image A (as the earlier strips left it) and
            // writes B, then B becomes A.
            let mut a = start.clone();
            for strip in &strips {
                let mut b = a.clone();
                for x in strip.x0 as usize..(strip.x0 + strip.width) as usize {
                    let p = sources[x];
                    if !p.is_nan() {
                        let (i0, i1, t) = address(p, bilinear);
                        b[x] = mix(a[i0], a[i1], t);
                    }
                }
                a = b;
            }
            for simd in [false, true] {
                if simd && !avx2_available() {
                    continue; // no AVX2 here: the scalar loop alone
                }
                let mut row = vec![[0u8; 4]; w];
                for strip in &strips {
                    let pat = |x: usize| pattern.color(x as u32, y);
                    #[cfg(target_arch = "x86_64")]
                    if simd {
                        let filter = (bilinear, pattern.is_gray());
                        unsafe { avx2::resolve_row(&mut row, &sources, strip, filter, pat) };
                        continue;
                    }
                    resolve_row(&mut row, &sources, strip, bilinear, pat);
                }
                assert!(
                    row == a,
                    "bilinear {bilinear}, toward {toward}, simd {simd}, {pattern:?}"
                );
            }
        }
    }
}
