//! ChromaDepth (the ChromaDepth article): texgen, ramp, the one-pass plan, per-vertex vs per-pixel, the glasses
//! simulation, terrain from scattered points, and bad input.

use std::path::Path;

use glam::{Mat4, Vec3, Vec4};
use proptest::prelude::*;
use stereolab::output;
use stereolab::plan::{Output, Pass, Plan, Shading, View};
use stereolab::render::chromadepth::{render_center_with, texgen_map};
use stereolab::render::render;
use stereolab::scene::{Scene, terrain, terrain_data};
use stereolab_core::{
    ChromaDepthSettings, Error, Eye, Ramp, RampKind, RampSampling, StereoRig, Texgen, TexgenMode,
    auto_range, eye_plane_specified_under, pixel_shift,
};

use crate::common;
use stereolab_core::{
    DEFAULT_TEXELS, channel_weights, glasses_view, hue_degrees, ramp_exact, shift_map,
};

/// A scene from TOML text with a camera at the origin looking down −Z (view = identity), so eye
/// space is world space; `meshes` are appended `[[mesh]]` tables.
fn scene(extra: &str, meshes: &str, sets: &[&str]) -> Result<Scene, Error> {
    let text = format!(
        r#"outputs = ["chromadepth"]
[image]
width = 64
height = 48
background = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.0, 0.0]
target = [0.0, 0.0, -1.0]
fov_y = 60.0
near = 0.5
far = 40.0
{extra}
{meshes}"#
    );
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::from_toml(
        &text,
        Path::new("test.toml"),
        &common::asset("scenes"),
        &sets,
    )
}

fn plane_at(distance: f32, rotate_x: f32, size: f32) -> String {
    format!(
        "[[mesh]]\nkind = \"plane\"\nsize = {size}\ndetail = 3\ntranslate = [0.0, 0.0, {}]\nrotate = [{rotate_x}, 0.0, 0.0]\n",
        -distance
    )
}

fn center_s(s: &Scene, settings: &ChromaDepthSettings) -> Vec<f32> {
    let c = StereoRig::center(&s.camera, s.aspect()).expect("valid camera");
    texgen_map(s, &c, settings).expect("renders")
}

// ---- texgen ----------------------------------------------------------------------------------

#[test]
fn texgen_maps_d1_to_zero_and_d2_to_one() {
    for (d1, d2) in [
        (5.0f32, 15.0f32),
        (0.5, 1.0),
        (2.0, 2.5),
        (10.0, 1000.0),
        (0.0, 3.0),
    ] {
        let t = Texgen::from_range(d1, d2).expect("valid range");
        // The camera looks down −Z: "D units in front of the eye" is eye z = −D.
        for (x, y) in [(0.0, 0.0), (3.0, -7.0)] {
            let at = |d: f32| t.s(Vec3::new(x, y, -d));
            assert!(at(d1).abs() < 1e-6, "s(D1={d1}) = {}", at(d1));
            assert!((at(d2) - 1.0).abs() < 1e-5, "s(D2={d2}) = {}", at(d2));
            assert!((at(0.5 * (d1 + d2)) - 0.5).abs() < 1e-5);
        }
        assert_eq!((t.plane.x, t.plane.y), (0.0, 0.0), "A = B = 0");
    }
}

#[test]
fn texgen_coefficients_match_seed_000_sample_code() {
    // The ChromaDepth article: D1 5, D2 15 → {0, 0, −1/(D2−D1), −D1/(D2−D1)} = {0, 0, −0.1, −0.5}.
    let t = Texgen::from_range(5.0, 15.0).expect("valid range");
    assert_eq!(t.plane, Vec4::new(0.0, 0.0, -0.1, -0.5));
}

proptest! {
    #[test]
    fn texgen_is_zero_at_d1_one_at_d2_and_increasing(d1 in 0.0f32..100.0, span in 0.01f32..100.0) {
        let d2 = d1 + span;
        let t = Texgen::from_range(d1, d2).expect("valid range");
        let tol = 1e-5 * (1.0 + d2 / span);
        prop_assert!(t.s(Vec3::new(0.0, 0.0, -d1)).abs() < tol);
        prop_assert!((t.s(Vec3::new(0.0, 0.0, -d2)) - 1.0).abs() < tol);
        prop_assert!(t.s(Vec3::new(0.0, 0.0, -d2)) > t.s(Vec3::new(0.0, 0.0, -d1)));
    }
}

#[test]
fn object_transforms_move_objects_through_the_ramp() {
    let settings = |s: &Scene| s.chromadepth.clone();
    let cd = "[chromadepth]\nd1 = 4.0\nd2 = 12.0\n";
    let mut seen = Vec::new();
    for distance in [4.0f32, 6.0, 8.0, 12.0] {
        let s = scene(cd, &plane_at(distance, 0.0, 20.0), &[]).expect("valid scene");
        let map = center_s(&s, &settings(&s));
        let mid = map[24 * 64 + 32];
        let want = (distance - 4.0) / 8.0;
        assert!(
            (mid - want).abs() < 1e-5,
            "plane at {distance}: s = {mid}, want {want}"
        );
        seen.push(mid);
    }
    assert!(
        seen.windows(2).all(|w| w[1] > w[0]),
        "s rises with distance: {seen:?}"
    );
}

#[test]
fn a_plane_specified_under_a_transform_moves_with_it() {
    let t = Texgen::from_range(5.0, 15.0).expect("valid range");
    // The ChromaDepth article: specify the plane under the identity modelview, it stays fixed in eye space.
    assert_eq!(eye_plane_specified_under(t.plane, Mat4::IDENTITY), t.plane);
    // Specified after a transform (the mistake the ChromaDepth article warns about) it is carried along: the
    // point D1 in front of the eye no longer gets s = 0.
    let moved =
        eye_plane_specified_under(t.plane, Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0)));
    let s = moved.dot(Vec4::new(0.0, 0.0, -5.0, 1.0));
    assert!((s - -0.3).abs() < 1e-6, "s = {s}, want -3/(D2-D1) = -0.3");
}

#[test]
fn auto_range_is_the_bounding_sphere_center_distance_minus_and_plus_radius() {
    let sphere =
        "[[mesh]]\nkind = \"sphere\"\nsize = 1.5\ndetail = 64\ntranslate = [0.0, 0.0, -10.0]\n";
    let s = scene("", sphere, &[]).expect("valid scene");
    let c = StereoRig::center(&s.camera, s.aspect()).expect("camera");
    let points: Vec<Vec3> = s.world_points().collect();
    let (d1, d2) = auto_range(&points, c.view, 0.5, 40.0).expect("visible");
    assert!(
        (d1 - 8.5).abs() < 1e-4 && (d2 - 11.5).abs() < 1e-4,
        "{d1} {d2}"
    );
    // Kept between the clip planes.
    let (n1, f2) = auto_range(&points, c.view, 9.0, 11.0).expect("visible");
    assert_eq!((n1, f2), (9.0, 11.0));
    // --set adjusts one end; the other stays automatic.
    let s = scene("", sphere, &["chromadepth.d1=9.5"]).expect("valid scene");
    let t = stereolab::render::chromadepth::resolve_texgen(&s, &c, &s.chromadepth)
        .expect("valid range");
    assert_eq!(t.d1, 9.5);
    assert!((t.d2 - 11.5).abs() < 1e-4);
}

// ---- ramp ------------------------------------------------------------------------------------

#[test]
fn ramp_first_texel_is_red_middle_green_last_blue() {
    let r = Ramp::new(RampKind::Hsv, DEFAULT_TEXELS).expect("valid ramp");
    let t = r.texels();
    assert_eq!(t.len(), 256);
    assert_eq!(t[0], Vec3::X, "first texel pure red");
    assert_eq!(t[255], Vec3::Z, "last texel pure blue");
    // 256 texels have no middle texel: s = 0.5 falls between texels 127 and 128 (hues 119.5°
    // and 120.5°); linear sampling there is green to 1/255.
    let mid = r.sample(0.5, RampSampling::Linear);
    assert_eq!(mid.y, 1.0);
    assert!(
        mid.x < 1.0 / 255.0 + 1e-6 && mid.z < 1.0 / 255.0 + 1e-6,
        "mid = {mid}"
    );
    let hue = hue_degrees(mid).expect("has a hue");
    assert!((hue - 120.0).abs() < 1e-3, "hue {hue}");
    // An odd texel count has a middle texel: exactly green.
    let odd = Ramp::new(RampKind::Hsv, 255).expect("valid ramp");
    assert_eq!(odd.texels()[127], Vec3::Y);
    let rwb = Ramp::new(RampKind::RedWhiteBlue, 255).expect("valid ramp");
    assert_eq!(
        [rwb.texels()[0], rwb.texels()[127], rwb.texels()[254]],
        [Vec3::X, Vec3::ONE, Vec3::Z]
    );
}

#[test]
fn ramp_clamps_beyond_d2_and_before_d1() {
    let r = Ramp::new(RampKind::Hsv, 256).expect("valid ramp");
    for sampling in [RampSampling::Nearest, RampSampling::Linear] {
        for s in [1.0, 1.0001, 1.5, 7.0, 1e30, f32::INFINITY] {
            assert_eq!(
                r.sample(s, sampling),
                Vec3::Z,
                "s = {s} stays blue (no wrap to red)"
            );
        }
        for s in [0.0, -0.2, -1e30, f32::NEG_INFINITY, f32::NAN] {
            assert_eq!(r.sample(s, sampling), Vec3::X, "s = {s} stays red");
        }
    }
    // In a rendered scene: a plane nearer than D1 is pure red, one beyond D2 pure blue.
    for (distance, want) in [(3.0, [255, 0, 0, 255]), (30.0, [0, 0, 255, 255])] {
        let s = scene(
            "[chromadepth]\nd1 = 5.0\nd2 = 15.0\n",
            &plane_at(distance, 0.0, 100.0),
            &[],
        )
        .expect("valid scene");
        let c = StereoRig::center(&s.camera, s.aspect()).expect("camera");
        let (fb, _) = render_center_with(&s, &c, &s.chromadepth).expect("renders");
        assert!(fb.color().iter().all(|p| *p == want), "plane at {distance}");
    }
}

// ---- plan ------------------------------------------------------------------------------------

#[test]
fn chromadepth_outputs_need_one_center_pass_and_no_stereo_pair() {
    let outputs = [
        Output::ChromaDepth,
        Output::ChromaDepthLeft,
        Output::ChromaDepthRight,
        Output::ChromaDepthAnaglyph,
    ];
    let plan = Plan::new(&outputs);
    let only = Pass {
        view: View::Center,
        shading: Shading::ChromaDepth,
    };
    assert_eq!(plan.passes, vec![only]);
    let explain = plan.explain();
    assert!(explain.contains("not run: Left eye"), "{explain}");
    assert!(explain.contains("not run: Right eye"), "{explain}");
    assert!(explain.contains("passes run: 1"), "{explain}");
    // With a stereo output as well, the ChromaDepth pass stays its own pass.
    let mixed = Plan::new(&[Output::ChromaDepth, Output::Left]);
    assert_eq!(mixed.passes.len(), 2);
    assert!(mixed.passes.contains(&only));
    for name in [
        "chromadepth",
        "chromadepth_left",
        "chromadepth_right",
        "chromadepth_anaglyph",
    ] {
        assert_eq!(Output::parse(name).expect("known").name(), name);
    }
}

// ---- per-vertex vs per-pixel -----------------------------------------------------------------

fn modes(s: &Scene) -> (Vec<f32>, Vec<f32>) {
    let per = |mode| {
        center_s(
            s,
            &ChromaDepthSettings {
                texgen: mode,
                ..s.chromadepth.clone()
            },
        )
    };
    (per(TexgenMode::PerVertex), per(TexgenMode::PerPixel))
}

fn max_diff(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(
        a.iter().map(|v| v.is_finite()).collect::<Vec<_>>(),
        b.iter().map(|v| v.is_finite()).collect::<Vec<_>>(),
        "same coverage"
    );
    a.iter()
        .zip(b)
        .filter(|(x, _)| x.is_finite())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f32::max)
}

#[test]
fn per_vertex_and_per_pixel_texgen_agree_on_a_camera_facing_plane() {
    let s = scene(
        "[chromadepth]\nd1 = 4.0\nd2 = 12.0\n",
        &plane_at(7.3, 0.0, 3.0),
        &[],
    )
    .expect("valid scene");
    let (v, p) = modes(&s);
    let d = max_diff(&v, &p);
    eprintln!("camera-facing plane: max |s_vertex - s_pixel| = {d:e}");
    // Rounding only: reconstructing z from window depth costs a few ulps of s.
    assert!(d < 1e-5, "{d}");
    let c = StereoRig::center(&s.camera, s.aspect()).expect("camera");
    let image = |mode| {
        let settings = ChromaDepthSettings {
            texgen: mode,
            ..s.chromadepth.clone()
        };
        render_center_with(&s, &c, &settings)
            .expect("renders")
            .0
            .into_buffers()
            .0
    };
    assert_eq!(image(TexgenMode::PerVertex), image(TexgenMode::PerPixel));
}

#[test]
fn per_vertex_and_per_pixel_texgen_differ_on_a_slanted_plane_only_by_interpolation() {
    let mut s = scene(
        "[chromadepth]\nd1 = 2.0\nd2 = 9.0\n",
        &plane_at(4.0, -70.0, 4.0),
        &[],
    )
    .expect("valid scene");
    let (v, p) = modes(&s);
    let perspective = max_diff(&v, &p);
    s.raster.perspective_correct = false;
    let (va, pa) = modes(&s);
    let affine = max_diff(&va, &pa);
    eprintln!(
        "slanted plane (70 deg): max |s_vertex - s_pixel| = {perspective:e} perspective-correct \
         ({:.4} deg hue), {affine:.4} affine ({:.2} deg hue)",
        perspective * 240.0,
        affine * 240.0
    );
    // s is affine in eye space, so perspective-correct interpolation reproduces it to rounding;
    // affine (screen-space) interpolation bends it on the slanted triangles.
    assert!(perspective < 1e-4, "{perspective}");
    assert!(affine > 0.005, "{affine}");
    // Per-pixel texgen does not depend on the interpolation mode.
    assert!(max_diff(&p, &pa) < 1e-6);
}

#[test]
fn lit_chromadepth_keeps_the_hue() {
    let sphere =
        "[[mesh]]\nkind = \"sphere\"\nsize = 2.0\ndetail = 48\ntranslate = [0.0, 0.0, -8.0]\n";
    let unlit = scene("", sphere, &[]).expect("valid scene");
    let lit = scene("[chromadepth]\nlit = true\n", sphere, &[]).expect("valid scene");
    let c = StereoRig::center(&lit.camera, lit.aspect()).expect("camera");
    let a = render_center_with(&unlit, &c, &unlit.chromadepth)
        .expect("renders")
        .0;
    let b = render_center_with(&lit, &c, &lit.chromadepth)
        .expect("renders")
        .0;
    let (mut compared, mut darker) = (0, 0);
    for (u, l) in a.color().iter().zip(b.color()) {
        let hue = |p: &[u8; 4]| hue_degrees(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
        // Dim pixels lose hue precision to 8-bit rounding: compare where a channel is ≥ 64.
        if u[..3] == [0, 0, 0] || *l[..3].iter().max().expect("3") < 64 {
            continue;
        }
        let (hu, hl) = (hue(u).expect("ramp color"), hue(l).expect("lit ramp color"));
        // 8-bit rounding of a color whose largest channel is ≥ 64 moves its hue ≤ 60°·1/64.
        assert!((hu - hl).abs() <= 1.0, "hue {hu} unlit vs {hl} lit");
        compared += 1;
        darker += (l[..3].iter().map(|&c| c as u32).sum::<u32>()
            < u[..3].iter().map(|&c| c as u32).sum::<u32>()) as usize;
    }
    assert!(
        compared > 200 && darker > compared / 4,
        "{compared} compared, {darker} darker"
    );
}

// ---- glasses ---------------------------------------------------------------------------------

#[test]
fn redder_pixels_get_larger_inward_shifts() {
    for kind in [RampKind::Hsv, RampKind::RedWhiteBlue] {
        let mut last = f32::INFINITY;
        for k in 0..=200 {
            let c = ramp_exact(kind, k as f32 / 200.0);
            let rgba = stereolab_core::to_rgba8(c);
            let shift = pixel_shift(rgba, 10.0);
            assert!(
                shift <= last,
                "{kind:?} s = {}: shift {shift} > {last}",
                k as f32 / 200.0
            );
            last = shift;
        }
        assert_eq!(
            pixel_shift([255, 0, 0, 255], 10.0),
            10.0,
            "red moves the most"
        );
        assert_eq!(pixel_shift([0, 0, 255, 255], 10.0), 0.0, "blue stays");
        assert_eq!(pixel_shift([0, 0, 0, 255], 10.0), 0.0, "black stays");
    }
    let w = channel_weights();
    assert!(w[0] > w[1] && w[1] > w[2], "red bent most: {w:?}");
}

/// Three camera-facing squares side by side at distances 5, 9 and 13 (D1 4, D2 14).
fn three_squares() -> Scene {
    let meshes: String = [(-4.5f32, 5.0f32), (0.0, 9.0), (4.5, 13.0)]
        .iter()
        .map(|(x, d)| {
            let scale = d / 5.0; // same size on screen
            format!(
                "[[mesh]]\nkind = \"plane\"\nsize = 1.6\ndetail = 3\nscale = {scale}\ntranslate = [{}, 0.0, {}]\n",
                x * scale,
                -d
            )
        })
        .collect();
    let mut s = scene(
        "[chromadepth]\nd1 = 4.0\nd2 = 14.0\nglasses_shift = 0.05\n",
        &meshes,
        &[],
    )
    .expect("valid scene");
    s.set_size(320, 120).expect("valid size");
    s
}

#[test]
fn glasses_disparity_order_matches_depth_order() {
    let s = three_squares();
    let frame = render(&s, &Plan::new(&[Output::ChromaDepth])).expect("renders");
    let center =
        stereolab::output::chromadepth::produce(Output::ChromaDepth, &frame, &s.chromadepth)
            .expect("center");
    let left =
        stereolab::output::chromadepth::produce(Output::ChromaDepthLeft, &frame, &s.chromadepth)
            .expect("left");
    let right =
        stereolab::output::chromadepth::produce(Output::ChromaDepthRight, &frame, &s.chromadepth)
            .expect("right");
    // Each square is one color (camera-facing): find its columns on the middle row.
    let row = s.height / 2;
    let mean_x = |fb: &stereolab_core::Framebuffer, color: [u8; 4]| {
        let xs: Vec<u32> = (0..fb.width())
            .filter(|&x| fb.pixel(x, row) == color)
            .collect();
        assert!(!xs.is_empty(), "color {color:?} visible");
        xs.iter().sum::<u32>() as f32 / xs.len() as f32
    };
    let mut disparities = Vec::new();
    for x in [s.width / 2 - 94, s.width / 2, s.width / 2 + 94] {
        let color = center.pixel(x, row);
        assert_ne!(color, [0, 0, 0, 255], "square at column {x}");
        let d = mean_x(&right, color) - mean_x(&left, color);
        let expected = -2.0 * pixel_shift(color, s.chromadepth.max_shift_px(s.width));
        eprintln!("square color {color:?}: disparity x_R - x_L = {d:.2} px (model {expected:.2})");
        // Each eye rounds its shift to whole pixels (≤ ½ px each): ≤ 1 px off the model.
        assert!((d - expected).abs() <= 1.0, "{d} vs {expected}");
        disparities.push(d);
    }
    // Nearer → more negative (crossed) disparity → seen in front.
    assert!(
        disparities[0] < disparities[1] && disparities[1] < disparities[2],
        "{disparities:?}"
    );
    // The anaglyph of the pair comes from the shared anaglyph module, kind chosen in the scene.
    let mut color = s.chromadepth.clone();
    color.anaglyph = "color".into();
    let anaglyph =
        stereolab::output::chromadepth::produce(Output::ChromaDepthAnaglyph, &frame, &color)
            .expect("ok");
    for (i, p) in anaglyph.color().iter().enumerate() {
        assert_eq!(p[0], left.color()[i][0]);
        assert_eq!(p[1..3], right.color()[i][1..3]);
    }
    let gray = stereolab::output::chromadepth::produce(
        Output::ChromaDepthAnaglyph,
        &frame,
        &s.chromadepth,
    )
    .expect("ok");
    let expected = stereolab_core::anaglyph(
        &left,
        &right,
        stereolab_core::AnaglyphKind::Gray,
        Default::default(),
    )
    .expect("same size");
    assert!(
        gray.color()
            .iter()
            .zip(expected.pixels())
            .all(|(a, b)| *a == b.0),
        "default is the gray anaglyph"
    );
    color.anaglyph = "plaid".into();
    let err = stereolab::output::chromadepth::produce(Output::ChromaDepthAnaglyph, &frame, &color)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("chromadepth.anaglyph") && err.contains("plaid"),
        "{err}"
    );
}

#[test]
fn glasses_shift_falls_with_depth_on_the_fault_valley() {
    let mut s = Scene::load(&common::asset("scenes/chromadepth_fault.toml"), &[]).expect("loads");
    s.set_size(160, 120).expect("valid size");
    let c = StereoRig::center(&s.camera, s.aspect()).expect("camera");
    let (fb, _) = render_center_with(&s, &c, &s.chromadepth).expect("renders");
    let shifts = shift_map(&fb, 10.0);
    // Mean shift per depth decile of the covered pixels must fall from near to far.
    let mut covered: Vec<(f32, f32)> = fb
        .depth()
        .iter()
        .zip(&shifts)
        .filter(|(d, _)| **d < 1.0)
        .map(|(d, s)| (*d, *s))
        .collect();
    covered.sort_by(|a, b| a.0.total_cmp(&b.0));
    let deciles: Vec<f32> = covered
        .chunks(covered.len().div_ceil(10))
        .map(|c| c.iter().map(|p| p.1).sum::<f32>() / c.len() as f32)
        .collect();
    eprintln!("mean shift per depth decile (near → far): {deciles:.2?}");
    assert!(deciles.windows(2).all(|w| w[1] < w[0]), "{deciles:?}");
}

#[test]
fn glasses_views_move_inward() {
    // One red pixel column on black: the left view moves it right, the right view left.
    let mut fb = stereolab_core::Framebuffer::new(21, 1, [0, 0, 0, 255]).expect("size");
    fb.color_mut()[10] = [255, 0, 0, 255];
    let l = glasses_view(&fb, Eye::Left, 3.0);
    let r = glasses_view(&fb, Eye::Right, 3.0);
    let at = |f: &stereolab_core::Framebuffer| f.color().iter().position(|p| p[0] == 255);
    assert_eq!(at(&l), Some(13));
    assert_eq!(at(&r), Some(7));
}

// ---- terrain ---------------------------------------------------------------------------------

fn csv_points(text: &str) -> Result<terrain::Terrain, Error> {
    let p = Path::new("points.csv");
    terrain::triangulate(p, &terrain::parse_csv(p, text)?)
}

#[test]
fn every_input_point_is_a_terrain_vertex() {
    let path = common::asset("scenes/terrain/island.csv");
    let text = std::fs::read_to_string(&path).expect("shipped");
    let points = terrain::parse_csv(&path, &text).expect("parses");
    let t = terrain::triangulate(&path, &points).expect("triangulates");
    assert_eq!(t.vertex_of_point.len(), points.len());
    assert_eq!(t.mesh.positions.len() + t.duplicates, points.len());
    for (p, &v) in points.iter().zip(&t.vertex_of_point) {
        let got = t.mesh.positions[v as usize];
        let want = terrain::map_to_world(p.x, p.y, p.height);
        assert_eq!((got.x, got.z), (want.x, want.z), "line {}", p.line);
    }
    let mut used = vec![false; t.mesh.positions.len()];
    t.mesh
        .triangles
        .iter()
        .flatten()
        .for_each(|&i| used[i as usize] = true);
    assert!(used.iter().all(|u| *u), "every vertex is in a triangle");
    // Counter-clockwise seen from above: normals point up.
    assert!(t.mesh.normals.iter().all(|n| n.y > 0.0));
}

#[test]
fn terrain_triangles_have_empty_circumcircles() {
    let path = common::asset("scenes/terrain/fault_valley.csv");
    let text = std::fs::read_to_string(&path).expect("shipped");
    let points = terrain::parse_csv(&path, &text).expect("parses");
    let t = terrain::triangulate(&path, &points).expect("triangulates");
    let xy: Vec<[f64; 2]> = t
        .mesh
        .positions
        .iter()
        .map(|p| [p.x as f64, -p.z as f64])
        .collect();
    let step = t.mesh.triangles.len() / 40;
    let mut checked = 0;
    for tri in t.mesh.triangles.iter().step_by(step) {
        let [a, b, c] = tri.map(|i| xy[i as usize]);
        // Circumcenter from the perpendicular bisectors.
        let d = 2.0 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]));
        let sq = |p: [f64; 2]| p[0] * p[0] + p[1] * p[1];
        let ux = (sq(a) * (b[1] - c[1]) + sq(b) * (c[1] - a[1]) + sq(c) * (a[1] - b[1])) / d;
        let uy = (sq(a) * (c[0] - b[0]) + sq(b) * (a[0] - c[0]) + sq(c) * (b[0] - a[0])) / d;
        let r2 = (a[0] - ux).powi(2) + (a[1] - uy).powi(2);
        for (i, p) in xy.iter().enumerate() {
            if tri.contains(&(i as u32)) {
                continue;
            }
            let d2 = (p[0] - ux).powi(2) + (p[1] - uy).powi(2);
            // Tolerance: f32 storage of the positions (1e-5 relative on coordinates ≤ 100).
            assert!(
                d2 >= r2 * (1.0 - 1e-6),
                "vertex {i} inside circumcircle of {tri:?}"
            );
        }
        checked += 1;
    }
    assert!(checked >= 40, "{checked}");
}

#[test]
fn duplicate_terrain_points_merge_into_one_vertex() {
    let t = csv_points("x,y,height\n0,0,1\n1,0,2\n0,1,3\n1,1,4\n1,0,6\n0,0,1\n").expect("ok");
    assert_eq!(t.mesh.positions.len(), 4);
    assert_eq!(t.duplicates, 2);
    assert_eq!(t.vertex_of_point, vec![0, 1, 2, 3, 1, 0]);
    assert_eq!(
        t.mesh.positions[1],
        Vec3::new(1.0, 4.0, 0.0),
        "height is the mean (2+6)/2"
    );
    assert_eq!(t.mesh.triangles.len(), 2);
}

#[test]
fn terrain_csv_header_may_reorder_columns() {
    let t = csv_points("# comment\nheight, x, y, name\n5,0,0,a\n\n6,2,0,b\n7,0,2,c\n").expect("ok");
    assert_eq!(t.mesh.positions[1], Vec3::new(2.0, 6.0, 0.0));
    let t = csv_points("0,0,1\n2,0,1\n0,2,1\n").expect("no header");
    assert_eq!(t.mesh.positions[2], Vec3::new(0.0, 1.0, -2.0));
}

#[test]
fn shipped_terrain_data_matches_its_generator() {
    for (file, title, points) in terrain_data::shipped() {
        let path = common::asset(&format!("scenes/terrain/{file}"));
        let csv = terrain_data::to_csv(title, &points);
        if std::env::var_os("UPDATE_ASSETS").is_some() {
            std::fs::write(&path, &csv).expect("write asset");
        }
        let shipped =
            std::fs::read_to_string(&path).expect("shipped CSV (UPDATE_ASSETS=1 writes it)");
        assert!(
            shipped == csv,
            "{file} differs from its generator; UPDATE_ASSETS=1 rewrites it"
        );
    }
}

// ---- scenes and outputs ----------------------------------------------------------------------

#[test]
fn shipped_chromadepth_scenes_render_every_output() {
    let dir = common::out_dir("chromadepth");
    for name in [
        "chromadepth_fault",
        "chromadepth_island",
        "chromadepth_molecule",
    ] {
        let mut s =
            Scene::load(&common::asset(&format!("scenes/{name}.toml")), &[]).expect("loads");
        s.set_size(128, 96).expect("size");
        let plan = Plan::new(&s.outputs);
        assert_eq!(plan.passes.len(), 1, "{name}: one pass");
        let frame = render(&s, &plan).expect("renders");
        let paths = output::write_all(&frame, &s, &dir.join(name)).expect("writes");
        assert_eq!(paths.len(), 4, "{name}");
        // The automatic range spans the ramp: both strong reds and strong blues appear.
        let fb = &frame.passes[0].framebuffer;
        let hues: Vec<f32> = fb
            .color()
            .iter()
            .filter_map(|p| hue_degrees(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)))
            .collect();
        let (lo, hi) = hues
            .iter()
            .fold((360.0f32, 0.0f32), |(a, b), h| (a.min(*h), b.max(*h)));
        eprintln!("{name}: hue range {lo:.1} .. {hi:.1} deg");
        assert!(lo < 40.0 && hi > 200.0, "{name}: hues {lo} .. {hi}");
    }
}

// ---- bad input -------------------------------------------------------------------------------

fn message(r: Result<impl std::fmt::Debug, Error>) -> String {
    r.expect_err("must be refused").to_string()
}

#[test]
fn equal_or_reversed_d1_d2_are_refused_naming_the_field() {
    let m = message(scene(
        "[chromadepth]\nd1 = 5.0\nd2 = 5.0\n",
        &plane_at(6.0, 0.0, 1.0),
        &[],
    ));
    assert!(
        m.contains("test.toml") && m.contains("chromadepth.d2 = 5") && m.contains("D2 - D1"),
        "{m}"
    );
    let m = message(scene(
        "",
        &plane_at(6.0, 0.0, 1.0),
        &["chromadepth.d1=9", "chromadepth.d2=3"],
    ));
    assert!(
        m.contains("chromadepth.d1 = 9") && m.contains("swap"),
        "{m}"
    );
    let m = message(scene("", &plane_at(6.0, 0.0, 1.0), &["chromadepth.d1=nan"]));
    assert!(m.contains("chromadepth.d1 = NaN"), "{m}");
    // Automatic D2 behind a given D1.
    let s = scene("[chromadepth]\nd1 = 30.0\n", &plane_at(6.0, 0.0, 1.0), &[]).expect("valid");
    let c = StereoRig::center(&s.camera, s.aspect()).expect("camera");
    let m = message(render_center_with(&s, &c, &s.chromadepth).map(|_| ()));
    assert!(m.contains("chromadepth.d1 = 30"), "{m}");
    let m = message(scene(
        "[chromadepth]\ntexels = 1\n",
        &plane_at(6.0, 0.0, 1.0),
        &[],
    ));
    assert!(m.contains("chromadepth.texels = 1"), "{m}");
}

#[test]
fn bad_terrain_csv_is_refused_naming_file_line_and_value() {
    let cases = [
        (
            "x,y,height\n0,0,1\n1,0,NaN\n0,1,1\n",
            "points.csv:3: column height = NaN",
        ),
        (
            "x,y,height\n0,0,1\n1,0,inf\n0,1,1\n",
            "points.csv:3: column height = inf",
        ),
        (
            "x,y\n0,0\n1,0\n0,1\n",
            "points.csv:1: missing column \"height\"",
        ),
        ("0,0,1\n1,0\n0,1,1\n", "points.csv:2: expected 3 columns"),
        (
            "0,0,1\n1,zero,2\n0,1,1\n",
            "points.csv:2: column y: \"zero\" is not a number",
        ),
        (
            "0,0,1\n1,0,2\n",
            "at least 3 distinct (x, y) points, found 2",
        ),
        (
            "0,0,1\n1,1,2\n0,0,5\n",
            "at least 3 distinct (x, y) points, found 2 in 3 rows",
        ),
        (
            "0,0,1\n1,1,2\n2,2,3\n3,3,3\n",
            "all 4 distinct points lie on one line",
        ),
        ("", "found 0"),
    ];
    for (text, want) in cases {
        let m = message(csv_points(text));
        assert!(m.contains(want), "{text:?}: {m}");
    }
    let m = message(scene("", "[[mesh]]\nkind = \"terrain\"\n", &[]));
    assert!(m.contains("mesh[0].path") && m.contains("CSV"), "{m}");
    let m = message(scene(
        "",
        "[[mesh]]\nkind = \"terrain\"\npath = \"terrain/nope.csv\"\n",
        &[],
    ));
    assert!(m.contains("nope.csv"), "{m}");
}
