//! The strip algorithm on real scenes: the fast path (the AVX2 loops where they run) gives the
//! scalar loops' and the paper's k passes' pixels and links, byte for byte.

use std::path::Path;

use crate::fixtures::table_scene;
use crate::plan::Shading;
use crate::render::render_view;
use crate::scene::Scene;
use stereolab_core::{
    Disparity, PerVertexOptions, Result, SirdsPattern, StereoRig, StripFilter, StripGeometry,
    StripResult, StripStart, depth_range, per_vertex, per_vertex_k_passes, per_vertex_reference,
    uses_avx2,
};

/// The camera of tests/sirds.rs.
const CAMERA: &str = "[camera]\neye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\n\
                      fov_y = 40.0\nnear = 1.0\nfar = 20.0\n";

/// A sphere over the background plane (tests/sirds.rs `SPHERE`): its `[sirds]` keys and
/// its mesh.
const SPHERE: (&str, &str) = (
    "back = 7.0\n",
    "[[mesh]]\nkind = \"sphere\"\nsize = 1.2\ndetail = 32\n",
);

/// The SIRDS paper's Fig. 5's ramp, a plane receding to the right (tests/sirds.rs `RAMP`).
const RAMP: (&str, &str) = (
    "",
    "[[mesh]]\nkind = \"plane\"\nsize = 20.0\ndetail = 16\nrotate = [0.0, 35.0, 0.0]\n",
);

/// The strip geometry and the disparity of `scene` at `width × height` and `dpi` (72:
/// separations of 72 to 90 px, 24: 24 to 30 px), from its cyclopean depth pass (as
/// `from_frame` builds them).
fn inputs(
    (sirds, mesh): (&str, &str),
    (width, height): (u32, u32),
    dpi: f32,
    cross_eyed: bool,
) -> (StripGeometry, Disparity) {
    let text = format!(
        "outputs = [\"sirds\"]\n[image]\nwidth = {width}\nheight = {height}\n{CAMERA}\
         [sirds]\ndpi = {dpi:.1}\n{sirds}{mesh}"
    );
    let s =
        Scene::from_toml(&text, Path::new("test.toml"), Path::new("."), &[]).expect("valid scene");
    let center = StereoRig::center(&s.camera, s.aspect()).expect("camera");
    let d = s.sirds.geometry.to_pixels().expect("geometry");
    let (fb, _) = render_view(&s, &center, Shading::DepthOnly).expect("depth pass");
    let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far).expect("range");
    let g = StripGeometry::new(&s.strip_objects(), &center, &range, &d, cross_eyed);
    (g, d)
}

/// Where two results differ: the count of differing pixels and links, and the first few
/// differing pixels as `(x, y)`.
fn differences(want: &StripResult, got: &StripResult, width: u32) -> Option<String> {
    let w = width as usize;
    let at = |i: usize| (i % w, i / w);
    let pixels: Vec<usize> = (0..want.pixels.len())
        .filter(|&i| want.pixels[i] != got.pixels[i])
        .collect();
    let links = match (&want.links, &got.links) {
        (Some(a), Some(b)) => a.iter().zip(b).filter(|(a, b)| a != b).count(),
        _ => usize::MAX,
    };
    let same = (want.iterations, want.strip_width) == (got.iterations, got.strip_width);
    if pixels.is_empty() && links == 0 && same {
        return None;
    }
    let first: Vec<_> = pixels.iter().take(5).map(|&i| at(i)).collect();
    Some(format!(
        "{} pixels differ (first at {first:?}), {links} links, k {} vs {}",
        pixels.len(),
        want.iterations,
        got.iterations
    ))
}

/// The fast path (scalar and AVX2 loops) gives the k passes' pixels and links byte for byte:
/// a sphere and a ramp, both starts, both filters, odd sizes, the fewest strips the
/// geometry allows (71 px), strips narrower than one AVX2 vector (6 px), 43 and 96 strips,
/// 1 px strips, and a cross-eyed geometry.
#[test]
fn fast_strips_are_the_k_passes_byte_for_byte() {
    let test = "fast_strips_are_the_k_passes_byte_for_byte";
    if !uses_avx2() {
        eprintln!(
            "{test}: the AVX2 loops do not run here (no AVX2, or STEREOLAB_SCALAR set): the \
             fast path runs the scalar loops"
        );
    }
    let pattern = SirdsPattern::Color { seed: 11 };
    // (name, scene, size, dpi, k, cross-eyed): k `None` gives the widest strips
    // (⌊δ⌋ − 1: 71 px at 72 dpi, 23 px at 24 dpi), 96 px at k 16 strips of 6 px, narrower
    // than one AVX2 vector, at k 96 strips of 1 px, 257 px at k 43 strips of 6 px.
    let cases = [
        ("sphere", SPHERE, (257, 131), 72.0, None, false),
        ("ramp", RAMP, (257, 131), 72.0, None, false),
        ("sphere", SPHERE, (96, 67), 24.0, None, false),
        ("sphere", SPHERE, (96, 67), 24.0, Some(16), false),
        ("ramp", RAMP, (96, 67), 24.0, Some(96), false),
        ("sphere", SPHERE, (257, 131), 36.0, Some(43), false),
        ("ramp", RAMP, (96, 67), 24.0, Some(16), true),
    ];
    let mut failures = Vec::new();
    let mut compared = 0;
    for (name, scene, (w, h), dpi, iterations, cross_eyed) in cases {
        let (g, d) = inputs(scene, (w, h), dpi, cross_eyed);
        for start in [StripStart::Left, StripStart::Center] {
            for filter in [StripFilter::Nearest, StripFilter::Bilinear] {
                let opts = PerVertexOptions {
                    start,
                    filter,
                    iterations,
                };
                let want =
                    per_vertex_k_passes(&g, w, h, &d, &pattern, &opts, true).expect("k passes");
                // Not vacuous: most pixels copy another one.
                let linked = want.links.iter().flatten().filter(|&&l| l >= 0).count();
                assert!(
                    linked * 2 > want.pixels.len(),
                    "{name} {w}x{h} {start:?}: only {linked} pixels linked"
                );
                for (loops, run) in [
                    ("scalar", per_vertex_reference as Strips),
                    ("fast", per_vertex),
                ] {
                    let got = run(&g, w, h, &d, &pattern, &opts, true).expect("fast strips");
                    compared += 1;
                    if let Some(diff) = differences(&want, &got, w) {
                        failures.push(format!(
                            "{name} {w}x{h} {dpi} dpi k {iterations:?} cross-eyed \
                             {cross_eyed} {start:?} {filter:?} {loops}: {diff}"
                        ));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {compared} runs differ from the k passes:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// Bad inputs: the k passes refuse what the fast path refuses, with the same message.
#[test]
fn k_passes_refuse_what_the_fast_path_refuses() {
    let (g, d) = inputs(SPHERE, (96, 67), 72.0, false);
    let pattern = SirdsPattern::Gray { seed: 1 };
    for (w, iterations) in [(96, Some(0)), (96, Some(1)), (80, None)] {
        let opts = PerVertexOptions {
            iterations,
            ..Default::default()
        };
        let want = per_vertex_reference(&g, w, 67, &d, &pattern, &opts, false);
        let got = per_vertex_k_passes(&g, w, 67, &d, &pattern, &opts, false);
        let message = |r: Result<StripResult>| r.err().map(|e| e.to_string());
        let (want, got) = (message(want), message(got));
        assert!(want.is_some(), "w {w}, k {iterations:?}: accepted");
        assert_eq!(got, want, "w {w}, k {iterations:?}");
    }
}

/// The AVX2 loops only change the speed: for both starts and both filters, black-white and
/// color dots (the gray and the three-channel mix), on an even and an odd size (spans and
/// strips that end mid-vector), they give the scalar loops' pixels and links, byte for byte.
#[test]
fn avx2_strips_match_scalar_strips() {
    if !uses_avx2() {
        eprintln!(
            "avx2_strips_match_scalar_strips: NOT RUN: the AVX2 loops do not run here (no AVX2, \
             or STEREOLAB_SCALAR set), nothing to compare"
        );
        return;
    }
    for (w, h, tris) in [(512, 256, 2_500), (301, 77, 400)] {
        let s = table_scene(w, h, tris, 10).expect("bench scene");
        let center = StereoRig::center(&s.camera, s.aspect()).expect("camera");
        let d = s.sirds.geometry.to_pixels().expect("geometry");
        let (fb, _) = render_view(&s, &center, Shading::DepthOnly).expect("depth pass");
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far).expect("range");
        let g = StripGeometry::new(&s.strip_objects(), &center, &range, &d, false);
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
                let run =
                    |strips: Strips| strips(&g, w, h, &d, pattern, &opts, true).expect("strips");
                let (fast, plain) = (run(per_vertex), run(per_vertex_reference));
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

/// The signature [`per_vertex`] and [`per_vertex_reference`] share.
type Strips = fn(
    &StripGeometry,
    u32,
    u32,
    &Disparity,
    &SirdsPattern,
    &PerVertexOptions,
    bool,
) -> Result<StripResult>;
