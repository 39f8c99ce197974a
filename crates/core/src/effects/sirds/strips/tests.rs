//! The strip loops' own check: reads of pixels not final yet, scalar and AVX2.

use super::*;
use crate::simd::avx2_available;

/// The strips of a `w`-pixel row `sw` pixels wide: right-going from `split` to the end, then
/// left-going from `split` to 0 (as [`plan_strips`] orders them), right-going sources allowed
/// from `split` on.
fn strips_from(w: u32, sw: u32, split: u32) -> Vec<Strip> {
    let mut strips = Vec::new();
    let mut x = split;
    while x < w {
        let width = sw.min(w - x);
        strips.push(Strip {
            x0: x,
            width,
            toward: 1.0,
            lo: split as i64,
            hi: w as i64,
        });
        x += width;
    }
    let mut x = split;
    while x > 0 {
        let width = sw.min(x);
        strips.push(Strip {
            x0: x - width,
            width,
            toward: -1.0,
            lo: 0,
            hi: w as i64,
        });
        x -= width;
    }
    strips
}

/// A source reaching into the running strip or one still to come (in real scenes only
/// past a sliver's edge) reads the pattern there, as the paper's ping-pong textures would
/// give it: resolving in place strip by strip (scalar) and the AVX2 pass over the whole row
/// equal a two-image reference, both filters, gray and color, right-going, left-going and
/// both (center start), strips wider and narrower than a vector, rows that end mid-vector,
/// sources anywhere the strip allows and runs of pixels without one.
#[test]
fn reads_of_unfinished_pixels_see_the_pattern() {
    let y = 5;
    let mut cases = 0;
    for (w, sw, split) in [
        (64u32, 8u32, 0u32),
        (64, 8, 64),
        (64, 8, 32),
        (61, 13, 0),
        (61, 13, 29),
        (61, 3, 61),
        (77, 5, 30),
    ] {
        let strips = strips_from(w, sw, split);
        let columns = Columns::new(&strips, w, split);
        // Gray (the one-channel mix) and color.
        for (bilinear, pattern) in [false, true].into_iter().flat_map(|b| {
            [
                (b, SirdsPattern::Gray { seed: 3 }),
                (b, SirdsPattern::Color { seed: 4 }),
            ]
        }) {
            let start: Vec<[u8; 4]> = (0..w).map(|x| pattern.color(x, y)).collect();
            // Pseudo-random sources inside each column's strip's bounds, every fifth pixel
            // and the first eleven without one.
            let sources: Vec<f32> = (0..w as usize)
                .map(|x| {
                    let s = &strips[columns.owner[x] as usize];
                    let r = (x as u32).wrapping_mul(2_654_435_761) >> 7;
                    let (lo, hi) = (s.lo as f32, s.hi as f32 - 1.0);
                    if x % 5 == 0 || x < 11 {
                        f32::NAN
                    } else {
                        lo + (r % 1000) as f32 / 1000.0 * (hi - lo)
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
                let mut row = vec![[0u8; 4]; w as usize];
                #[cfg(target_arch = "x86_64")]
                if simd {
                    let filter = (bilinear, pattern.is_gray());
                    let plan = (strips.as_slice(), &columns);
                    // SAFETY: AVX2 is available (checked above); every source is NaN or
                    // inside the row.
                    unsafe { avx2::resolve_sweep(&mut row, &sources, plan, filter, (y, &pattern)) };
                }
                if !simd {
                    for strip in &strips {
                        let pat = |x: usize| pattern.color(x as u32, y);
                        resolve_row(&mut row, &sources, strip, bilinear, pat);
                    }
                }
                assert!(
                    row == a,
                    "{w} px, strips of {sw} from {split}, bilinear {bilinear}, simd {simd}, \
                     {pattern:?}"
                );
                cases += 1;
            }
        }
    }
    assert!(cases >= 28, "{cases} cases");
}
