//! The strip loops' own checks: the AVX2 loops against the scalar ones, and reads of
//! pixels not final yet.

use super::*;
use crate::fixtures::table_scene;
use crate::plan::Shading;
use crate::render::render_view;
use stereolab_core::{StereoRig, avx2_available, depth_range};

/// Whether there are AVX2 loops to compare with the scalar ones; without them (a CPU without
/// AVX2) it says so on stderr, and every path that runs is the scalar one the other tests cover.
fn avx2_to_compare(test: &str) -> bool {
    if avx2_available() {
        return true;
    }
    eprintln!("{test}: NOT RUN: no AVX2 here, nothing to compare");
    false
}

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
                    continue; // the scalar loop alone (see `avx2_to_compare`)
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

/// The AVX2 loops only change the speed: for both starts and both filters, black-white and
/// color dots (the gray and the three-channel mix), on an even and an odd size (spans and
/// strips that end mid-vector), they give the scalar loops' pixels and links, byte for byte.
#[test]
fn avx2_strips_match_scalar_strips() {
    if !avx2_to_compare("avx2_strips_match_scalar_strips") {
        return;
    }
    for (w, h, tris) in [(512, 256, 2_500), (301, 77, 400)] {
        let s = table_scene(w, h, tris, 10).expect("bench scene");
        let center = StereoRig::center(&s.camera, s.aspect()).expect("camera");
        let d = s.sirds.geometry.to_pixels().expect("geometry");
        let (fb, _) = render_view(&s, &center, Shading::DepthOnly).expect("depth pass");
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far).expect("range");
        let g = StripGeometry::new(&s, &center, &range, &d, false);
        let patterns = [s.sirds.pattern.clone(), SirdsPattern::Color { seed: 9 }];
        for (pattern, start) in patterns
            .iter()
            .flat_map(|p| [(p, StripStart::Left), (p, StripStart::Center)])
        {
            for filter in [StripFilter::Nearest, StripFilter::Bilinear] {
                let opts = PerVertexOptions {
                    start,
                    filter,
                    iterations: None,
                };
                let run = |kernels| {
                    per_vertex_on(&g, (w, h), &d, pattern, &opts, true, kernels).expect("strips")
                };
                let (fast, plain) = (run(Kernels::Avx2), run(Kernels::Scalar));
                let differ = fast
                    .pixels
                    .iter()
                    .zip(&plain.pixels)
                    .filter(|(a, b)| a != b);
                assert_eq!(
                    differ.count(),
                    0,
                    "{w}x{h} {start:?} {filter:?} {pattern:?}: pixels differ"
                );
                assert_eq!(
                    fast.links, plain.links,
                    "{w}x{h} {start:?} {filter:?}: links"
                );
            }
        }
    }
}
