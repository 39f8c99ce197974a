//! Adversarial inputs, tried as a user would with `--set`: each must end in a refusal
//! (non-zero exit, the field and the remedy named) or a warning in the CLI output, never in a
//! silently wrong image with exit 0.

use std::process::{Command, Output};

use crate::common::{asset, out_dir};

fn stereolab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .output()
        .expect("run stereolab")
}

/// `stereolab info` of an asset scene with `--set` overrides (the checks run at load, so
/// `info` sees them as `render` does).
fn info(scene: &str, sets: &[&str]) -> Output {
    let scene = asset(&format!("scenes/{scene}"))
        .to_string_lossy()
        .into_owned();
    let mut args = vec!["info", scene.as_str()];
    for s in sets {
        args.extend(["--set", s]);
    }
    stereolab(&args)
}

/// A small `stereolab render`, whose output holds the warnings.
fn render(scene: &str, name: &str, sets: &[&str]) -> Output {
    let scene = asset(&format!("scenes/{scene}"))
        .to_string_lossy()
        .into_owned();
    let dir = out_dir(name).to_string_lossy().into_owned();
    let mut args = vec![
        "render",
        scene.as_str(),
        "--size",
        "96x64",
        "--out",
        dir.as_str(),
    ];
    for s in sets {
        args.extend(["--set", s]);
    }
    stereolab(&args)
}

/// The run failed and its message names every one of `words`.
fn assert_refused(out: &Output, words: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "must be refused, got exit 0; stderr: {err}"
    );
    for w in words {
        assert!(err.contains(w), "the refusal must name {w:?}: {err}");
    }
}

/// The run succeeded and printed a `warning:` line naming every one of `words`.
fn assert_warned(out: &Output, words: &[&str]) {
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "must succeed with a warning; stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let warning = text
        .lines()
        .find(|l| l.contains("warning:") && words.iter().all(|w| l.contains(w)));
    assert!(
        warning.is_some(),
        "expected a warning naming {words:?}:\n{text}"
    );
}

fn assert_no_warning_naming(out: &Output, word: &str) {
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        !text
            .lines()
            .any(|l| l.contains("warning:") && l.contains(word)),
        "no warning about {word} expected:\n{text}"
    );
}

#[test]
fn light_factors_that_are_nan_infinite_or_negative_are_refused_by_name() {
    for (field, value) in [
        ("ambient", "nan"),
        ("ambient", "-0.1"),
        ("specular", "inf"),
        ("specular", "-1"),
        ("shininess", "nan"),
        ("shininess", "-32"),
    ] {
        let set = format!("light.{field}={value}");
        let out = info("anaglyph.toml", &[&set]);
        assert_refused(&out, &[&format!("light.{field}"), "finite number ≥ 0"]);
    }
    // The defaults and ordinary values still load.
    assert!(
        info("anaglyph.toml", &["light.shininess=0"])
            .status
            .success()
    );
}

#[test]
fn an_eye_separation_that_overflows_the_cameras_is_refused_in_every_mode() {
    let out = info(
        "anaglyph.toml",
        &["stereo.mode=\"toe-in\"", "stereo.eye_separation=1e20"],
    );
    assert_refused(&out, &["stereo.eye_separation", "non-finite", "\"auto\""]);
    // Render refuses it too (rather than NaN cameras, empty images and exit 0).
    let out = render(
        "anaglyph.toml",
        "hard-toe-in",
        &["stereo.mode=\"toe-in\"", "stereo.eye_separation=1e20"],
    );
    assert_refused(&out, &["stereo.eye_separation"]);
    // Off-axis with a separation whose shift overflows the frustum.
    let out = info("anaglyph.toml", &["stereo.eye_separation=3e38"]);
    assert_refused(&out, &["stereo.eye_separation"]);
}

#[test]
fn a_near_plane_that_rounds_every_depth_to_one_is_refused_with_the_remedy() {
    for sets in [
        ["camera.near=1e-7", "camera.far=1e7"],
        ["camera.near=1e-9", "camera.far=20"],
    ] {
        let out = render("anaglyph.toml", "hard-near", &sets);
        assert_refused(
            &out,
            &["camera.near", "window depth 1.0", "raise camera.near"],
        );
    }
}

#[test]
fn a_near_plane_that_coarsens_the_depth_buffer_is_warned_about_with_both_resolutions() {
    for sets in [
        ["camera.near=1e-6", "camera.far=1e7"],
        ["camera.near=1e-5", "camera.far=1e5"],
    ] {
        let out = render("anaglyph.toml", "hard-near-warn", &sets);
        assert_warned(
            &out,
            &[
                "camera.near",
                "nearest surface",
                "farthest",
                "raise camera.near",
            ],
        );
    }
    // The scene as shipped has no such warning.
    assert_no_warning_naming(&render("anaglyph.toml", "hard-near-ok", &[]), "camera.near");
}

#[test]
fn per_vertex_sirds_depths_outside_the_clip_range_are_refused_by_name() {
    // sirds_sphere: near = 1, far = 20, back = 7.
    for (set, field) in [
        ("sirds.back=0.5", "sirds.back"),
        ("sirds.back=25", "sirds.back"),
        ("sirds.front=0.5", "sirds.front"),
    ] {
        let out = info("sirds_sphere.toml", &[set]);
        assert_refused(&out, &[field, "clip range", "camera.near"]);
    }
    // Inside the range it loads; the per-pixel algorithm draws no background plane and keeps
    // accepting a back beyond far.
    assert!(
        info("sirds_sphere.toml", &["sirds.back=19"])
            .status
            .success()
    );
    assert!(
        info(
            "sirds_sphere.toml",
            &["sirds.algorithm=\"per-pixel\"", "sirds.back=25"]
        )
        .status
        .success()
    );
}

#[test]
fn chromadepth_d1_d2_behind_the_eye_are_refused_and_a_scene_outside_them_is_warned_about() {
    for set in ["chromadepth.d1=-1", "chromadepth.d1=0"] {
        let out = info("chromadepth_molecule.toml", &[set, "chromadepth.d2=20"]);
        assert_refused(&out, &["chromadepth.d1", "> 0"]);
    }
    // The molecule sits around eye depth 10: a ramp from 100 to 200 paints it all red.
    let out = render(
        "chromadepth_molecule.toml",
        "hard-chroma-red",
        &["chromadepth.d1=100", "chromadepth.d2=200"],
    );
    assert_warned(&out, &["chromadepth.d1", "all red"]);
    // A ramp ending at 0.5 paints it all blue.
    let out = render(
        "chromadepth_molecule.toml",
        "hard-chroma-blue",
        &["chromadepth.d1=0.25", "chromadepth.d2=0.5"],
    );
    assert_warned(&out, &["chromadepth.d2", "all blue"]);
    assert_no_warning_naming(
        &render("chromadepth_molecule.toml", "hard-chroma-ok", &[]),
        "ChromaDepth",
    );
}

#[test]
fn a_model_far_from_the_origin_is_warned_about_with_the_precision_lost() {
    let out = info("anaglyph.toml", &["mesh.0.translate=[1e7,0,0]"]);
    assert_warned(
        &out,
        &["mesh[0]", "from the origin", "apart", "nearer the origin"],
    );
    // A thousand units away a unit-sized model keeps 1/10 000 of its size: no warning.
    assert_no_warning_naming(
        &info("anaglyph.toml", &["mesh.0.translate=[100,0,0]"]),
        "origin",
    );
}

#[test]
fn a_render_that_draws_nothing_says_so() {
    // The model moved far out of the view: every pass draws 0 fragments.
    let out = render(
        "anaglyph.toml",
        "hard-nothing",
        &["mesh.0.translate=[1000,0,0]"],
    );
    assert_warned(&out, &["no pass drew a fragment", "camera.eye"]);
    assert_no_warning_naming(&render("anaglyph.toml", "hard-something", &[]), "fragment");
}

/// Catalogue: near/far ratios from 10 to 1e12, each depth mode against the f64 reference
/// (`stereolab_core::visible_f64`), on the depth benchmark's decal scene (pairs of squares 1/10 000
/// of their depth apart). Tolerance: zero wrong or lost pixels (of those the reference decides)
/// wherever the mode's predicted resolution `resolution_of` at the farthest pair (eye depth 90)
/// is under a quarter of that pair's gap; reason: a resolution finer than the gap separates
/// the two squares everywhere, and coverage is compared only away from edges. Where it is not,
/// the scene loader warns (`a_near_plane_that_coarsens…`, the refusal above).
#[test]
fn catalogue_near_far_ratios_within_the_predicted_resolution_of_each_depth_mode() {
    use stereolab::scene::resolution_of;
    use stereolab_bench::depth::{FAR, measure, modes};
    let rows = measure(96, 64, 1).expect("measure");
    let gap = 90.0 * 1e-4;
    let mut standard_failed_somewhere = false;
    for r in &rows {
        let near = (f64::from(FAR) / r.ratio) as f32;
        let mode = modes(near)
            .into_iter()
            .find(|m| m.name() == r.setting)
            .expect("mode");
        let dz = resolution_of(mode, 90.0, f64::from(near), f64::from(FAR));
        if dz < gap / 4.0 {
            assert_eq!(
                r.error, 0.0,
                "{} at near/far 1/{:e}: {}% wrong with resolution {dz:e} < gap/4",
                r.setting, r.ratio, r.error
            );
        }
        if r.setting == "standard" && r.error > 0.0 {
            standard_failed_somewhere = true;
        }
        if r.setting.starts_with("reversed-z, infinite") || r.setting == "f64" {
            assert_eq!(r.error, 0.0, "{} at 1/{:e}", r.setting, r.ratio);
        }
    }
    assert!(
        standard_failed_somewhere,
        "the standard f32 depth must lose the decals at 1e12 (else the measurement measures nothing)"
    );
}

/// Catalogue: `sirds.depth_far_in = 1e8` keeps the front separation at eq. 3's 72 px
/// (a = 180 px, f = 864 px, t_near = 576 px: 180·576/1440); tolerance 1e-3 px, the f32
/// rounding of the formula. Before: 67 px (t_far − t_near rounded in f32).
#[test]
fn catalogue_sirds_depth_far_in_1e8_keeps_the_front_separation() {
    use stereolab_core::SirdsGeometry;
    let g = SirdsGeometry {
        depth_far_in: 1e8,
        ..SirdsGeometry::default()
    };
    let d = g.to_pixels().expect("valid");
    assert!(
        (d.min_separation() - 72.0).abs() < 1e-3,
        "{}",
        d.min_separation()
    );
}

/// Catalogue: per-vertex SIRDS back plane at the far clip plane (its f32 window depth is 1.0,
/// so it would lose against the cleared depth) is refused by name.
#[test]
fn catalogue_sirds_back_at_the_far_plane_is_refused() {
    let out = info("sirds_sphere.toml", &["sirds.back=20"]);
    assert_refused(&out, &["sirds.back", "window depth is 1.0"]);
}

/// `raster.depth` names and `infinite_far` without reversed-Z are checked by name.
#[test]
fn depth_mode_values_are_checked_by_name() {
    assert_refused(
        &info("anaglyph.toml", &["raster.depth=\"w-buffer\""]),
        &["raster.depth", "reversed-z"],
    );
    assert_refused(
        &info("anaglyph.toml", &["raster.infinite_far=true"]),
        &["raster.infinite_far", "reversed-z"],
    );
    assert!(
        info(
            "anaglyph.toml",
            &["raster.depth=\"reversed-z\"", "raster.infinite_far=true"]
        )
        .status
        .success()
    );
}

/// Draws `triangles` through `mvp` on the CPU, as triangle ids, and compares each pixel the
/// f64 reference decides (the same f32 vertices through `mvp64`) with the reference's winner
/// (`stereolab_core::visible_f64`).
fn against_reference_through(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
    (mvp, mvp64): (glam::Mat4, glam::DMat4),
    (width, height): (u32, u32),
) -> stereolab_core::Mismatch {
    use stereolab_core::{
        Framebuffer, IdShader, RasterOptions, compare_with_reference, rasterize, triangle_soup,
        visible_f64,
    };
    let world: Vec<glam::DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let reference = visible_f64(&world, triangles, &mvp64, width, height);
    let soup_positions = triangle_soup(positions, triangles);
    let soup_triangles: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let shader = IdShader {
        positions: &soup_positions,
        mvp,
    };
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255]).expect("framebuffer");
    rasterize(
        &soup_triangles,
        soup_positions.len(),
        &shader,
        &mut fb,
        &RasterOptions::default(),
    );
    compare_with_reference(&fb, &reference)
}

/// [`against_reference_through`] for triangles in eye space (the camera at the origin looking
/// down −Z) through a symmetric frustum.
fn against_reference(
    positions: &[glam::Vec3],
    triangles: &[[u32; 3]],
    (near, far): (f32, f32),
    (width, height): (u32, u32),
) -> stereolab_core::Mismatch {
    let aspect = width as f32 / height as f32;
    let (a, b) = (near * aspect, near);
    let mvp = stereolab_core::frustum(-a, a, -b, b, near, far);
    let mvp64 = stereolab_core::frustum_f64(
        -f64::from(a),
        f64::from(a),
        -f64::from(b),
        f64::from(b),
        f64::from(near),
        f64::from(far),
    );
    against_reference_through(positions, triangles, (mvp, mvp64), (width, height))
}

/// Catalogue: triangles crossing w = 0 (a vertex behind the eye) and the near plane. The CPU
/// clips them in f32 against the near plane, the reference in f64. Tolerance: no pixel the
/// reference decides may differ, because clipping moves the new vertices by about 1e-7
/// of their size, far below the reference's undecided band of 2/256 px around each edge.
/// (Measured: 7220 covered pixels, 0 differ; with 2 subpixel bits instead of 8, 2 differ.)
#[test]
fn catalogue_triangles_crossing_w_zero_match_the_f64_reference() {
    use glam::Vec3;
    // Floors and walls reaching from 5 units in front of the eye to 2 units behind it, at
    // several slants, and one triangle with two vertices behind the eye.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (k, slant) in [-1.5f32, -0.7, 0.4, 1.1].into_iter().enumerate() {
        let base = positions.len() as u32;
        let x = -2.0 + k as f32 * 1.2;
        positions.extend([
            Vec3::new(x, slant, -5.0),
            Vec3::new(x + 0.9, slant, -5.0),
            Vec3::new(x + 0.4, slant * 0.3, 2.0),
        ]);
        triangles.push([base, base + 1, base + 2]);
    }
    let base = positions.len() as u32;
    positions.extend([
        Vec3::new(0.2, 0.1, -3.0),
        Vec3::new(-1.0, -0.5, 1.0),
        Vec3::new(1.0, -0.8, 4.0),
    ]);
    triangles.push([base, base + 1, base + 2]);
    let m = against_reference(&positions, &triangles, (0.1, 50.0), (160, 120));
    eprintln!("w = 0 crossing against the reference: {m:?}");
    assert!(m.covered > 2000, "the triangles must show: {m:?}");
    assert_eq!(
        m.total(),
        0,
        "w = 0 crossing differs from the reference: {m:?}"
    );
}

/// Catalogue: edge-on slivers, triangles whose width across is a few thousandths of a pixel
/// to a few pixels, long and short, at every angle, and triangles in planes through the eye.
/// Tolerance: no decided pixel differs. The CPU snaps vertices to 1/256 px (lavapipe's 8
/// subpixel bits), at most 1/512 px from the exact position, inside the reference's undecided
/// band of 2/256 px; a sliver that covers no pixel centre must draw nothing, and one that does
/// must draw exactly those. (Measured: 778 covered pixels, 0 differ; with 2 subpixel bits, 28.)
#[test]
fn catalogue_edge_on_slivers_match_the_f64_reference() {
    use glam::Vec3;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let z = -4.0f32;
    for i in 0..24 {
        let angle = i as f32 * 0.27;
        let (s, c) = angle.sin_cos();
        // Width across: from 1e-3 px to about 3 px at this view (1 unit ≈ 15 px here).
        let width = 1e-4 * 3.0f32.powi(i % 9);
        let len = 0.5 + (i % 5) as f32 * 0.6;
        let centre = Vec3::new((i % 6) as f32 * 0.9 - 2.2, (i / 6) as f32 * 0.7 - 1.1, z);
        let along = Vec3::new(c, s, 0.0) * len;
        let across = Vec3::new(-s, c, 0.0) * width;
        let base = positions.len() as u32;
        positions.extend([centre - along, centre + along, centre + across]);
        triangles.push([base, base + 1, base + 2]);
        // The same sliver turned edge-on to the eye: a triangle in a plane through the eye.
        let base = positions.len() as u32;
        let p = centre + Vec3::new(0.0, 0.0, -1.0);
        positions.extend([
            centre,
            p,
            centre + (p - centre).cross(along).normalize() * 1e-6,
        ]);
        triangles.push([base, base + 1, base + 2]);
    }
    let m = against_reference(&positions, &triangles, (0.5, 20.0), (160, 120));
    eprintln!("slivers against the reference: {m:?}");
    assert!(
        m.covered > 50,
        "some slivers must cover pixel centres: {m:?}"
    );
    assert_eq!(m.total(), 0, "slivers differ from the reference: {m:?}");
}

/// Catalogue: D1 = D2 is refused by name; D2 one ulp beyond D1, inside the scene's depth range,
/// is a legal ramp one ulp long: the image must be the ramp's two ends only (a step from red to
/// blue at D1), with no NaN or infinity turning into black or green pixels. Tolerance: every
/// lit pixel red or blue by hue, both present. A scene wholly beyond such a thin range is
/// warned about (the all-outside warning).
#[test]
fn catalogue_chromadepth_d1_equal_to_d2_within_an_ulp() {
    let out = render(
        "chromadepth_molecule.toml",
        "hard_cases_d1_d2_equal",
        &["chromadepth.d1=10", "chromadepth.d2=10"],
    );
    assert_refused(&out, &["chromadepth.d2", "chromadepth.d1"]);
    let d2 = format!("chromadepth.d2={}", 10.0f32.next_up());
    let out = render(
        "chromadepth_molecule.toml",
        "hard_cases_d1_d2_ulp",
        &["chromadepth.d1=10", &d2, "outputs=[\"chromadepth\"]"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // `render` made this folder (`out_dir` would empty it again).
    let dir = crate::common::root().join("target/test-out/hard_cases_d1_d2_ulp");
    let img = image::open(dir.join("chromadepth.png"))
        .expect("chromadepth.png")
        .to_rgb8();
    let (mut red, mut blue) = (0, 0);
    for p in img.pixels() {
        let [r, g, b] = p.0;
        if r.max(g).max(b) < 24 {
            continue; // background or a pixel lit too dimly to have a hue
        }
        assert!(
            g < r.max(b),
            "a pixel that is neither end of the ramp: {:?}",
            p.0
        );
        if r > b { red += 1 } else { blue += 1 }
    }
    assert!(
        red > 20 && blue > 20,
        "red {red}, blue {blue}: the step must show both ends"
    );
    let beyond = render(
        "chromadepth_molecule.toml",
        "hard_cases_d1_d2_ulp_beyond",
        &["chromadepth.d1=5", "chromadepth.d2=5.0000005"],
    );
    assert_warned(&beyond, &["beyond chromadepth.d2"]);
}

/// Catalogue: the SIRDS paper's eq. 3, `d = a t / (t + f)`, near its pole `t + f ≈ 0` (a point
/// almost at the eyes). Sterbenz's lemma makes `t + f` exact in f32 when t is within a factor 2
/// of −f, so only the product and the quotient round: tolerance 4 ulp relative to the same
/// formula in f64 on the same inputs. At and behind the pole (`t + f ≤ 0`) the result is a
/// refusal naming `t + f`, never an infinity or NaN passed on.
#[test]
fn catalogue_sirds_eq3_near_the_pole_stays_within_ulps_or_is_refused() {
    use stereolab_core::separation_eye_distance;
    let (a, f) = (180.0f32, 864.0f32);
    let mut t = -f + 1.0;
    let mut checked = 0;
    let mut last_gap = f32::NAN;
    while t + f > 0.0 {
        last_gap = t + f;
        let d = separation_eye_distance(t, a, f).expect("in front of the pole");
        let exact = f64::from(a) * f64::from(t) / (f64::from(t) + f64::from(f));
        assert!(d.is_finite(), "t + f = {:e}: {d}", t + f);
        let rel = ((f64::from(d) - exact) / exact).abs();
        assert!(
            rel <= 4.0 * f64::from(f32::EPSILON),
            "t + f = {:e}: {d} against {exact} ({rel:e} relative)",
            t + f
        );
        checked += 1;
        // Halve the distance to the pole, down to its last representable step.
        let next = -f + (t + f) * 0.5;
        if next == t {
            break;
        }
        t = next;
    }
    // From t + f = 1 down to f32's last step below 864 (2^-14): 15 halvings.
    assert!(checked >= 15, "{checked} steps towards the pole");
    assert_eq!(
        last_gap,
        2f32.powi(-14),
        "the walk must reach the last step before the pole"
    );
    for t in [-f, -f - 1.0, (-f).next_down()] {
        let err = separation_eye_distance(t, a, f).expect_err("at or behind the pole");
        assert!(err.to_string().contains("t + f"), "{err}");
    }
}

/// Catalogue: toe-in at extreme separations, from 1e-6 to 1e6 times the model's size. Each
/// eye's f32 matrix (`StereoRig::eyes_for_image`, what every render uses) against the f64
/// reference rig (`stereolab_core::eye_matrices_f64`) on the model's bounding-box corners and
/// centre. Tolerance: 0.01 px on a 320×240 image for every point in front of the eye; a
/// separation whose cameras overflow is refused by name instead (`1e20`, tested above).
#[test]
fn catalogue_toe_in_at_extreme_separations_matches_the_f64_rig() {
    use glam::{DVec3, Vec3};
    use stereolab_core::CameraMode;
    let path = asset("scenes/anaglyph.toml");
    let (w, h) = (320u32, 240u32);
    let mut worst = 0.0f64;
    let mut checked = 0;
    for exp in -6..=6 {
        let sep = 10f64.powi(exp);
        let sets = vec![
            "stereo.mode=\"toe-in\"".to_string(),
            format!("stereo.eye_separation={sep:e}"),
        ];
        let scene = stereolab::scene::Scene::load(&path, &sets).expect("scene");
        assert_eq!(scene.rig.mode, CameraMode::ToeIn);
        let aspect = f64::from(w) / f64::from(h);
        let resolved = scene
            .rig
            .resolve(&scene.camera, aspect as f32)
            .expect("resolve");
        let eyes = scene
            .rig
            .eyes_for_image(&scene.camera, w, h)
            .expect("toe-in eyes");
        let target = DVec3::from(scene.camera.target.map(f64::from));
        let mut points: Vec<DVec3> = Vec::new();
        for dx in [-1.0, 1.0] {
            for dy in [-1.0, 1.0] {
                for dz in [-1.0, 1.0] {
                    points.push(target + DVec3::new(dx, dy, dz));
                }
            }
        }
        points.push(target);
        for (side, eye) in stereolab_core::Eye::BOTH.into_iter().zip(&eyes) {
            let m64 = stereolab_core::eye_matrices_f64(
                &scene.rig,
                &scene.camera,
                aspect,
                f64::from(resolved.eye_separation),
                f64::from(resolved.zero_parallax_distance),
                side,
            );
            for p in &points {
                let c64 = m64 * p.extend(1.0);
                if c64.w <= 0.0 {
                    continue;
                }
                let c32 = (eye.mvp * Vec3::new(p.x as f32, p.y as f32, p.z as f32).extend(1.0))
                    .as_dvec4();
                let px = |c: glam::DVec4| {
                    (
                        (c.x / c.w + 1.0) * 0.5 * f64::from(w),
                        (c.y / c.w + 1.0) * 0.5 * f64::from(h),
                    )
                };
                let (a, b) = (px(c32), px(c64));
                let err = (a.0 - b.0).hypot(a.1 - b.1);
                assert!(
                    err <= 0.01,
                    "separation {sep:e}, {side:?} eye: {p:?} lands {err:e} px from the f64 rig"
                );
                worst = worst.max(err);
                checked += 1;
            }
        }
    }
    // 13 separations × 2 eyes × 9 points, every one in front of its eye.
    assert_eq!(checked, 13 * 2 * 9);
    eprintln!("toe-in 1e-6 … 1e6: worst {worst:e} px from the f64 rig");
}

/// Catalogue: the remap (right eye's pixel for each left-eye pixel, `effects::remap`) with the
/// near plane at 1e-6 of the far plane, where window depth crowds against 1.0, on every pixel
/// the left eye draws. The CPU outputs remap in f64 (`Precision::default()`), the reference
/// itself. The WGSL mirror's way (`F32Composed`: composed in f64, applied in f32) must stay
/// within 0.5 px, half a texel (a remap that lands in the wrong texel fetches the wrong
/// color). The exercise slides' way (`F32`, through world space) is measured and printed; at
/// this ratio the near plane is warned about, naming `camera.near`.
#[test]
fn catalogue_remap_at_near_far_1e_minus_6_stays_within_half_a_pixel() {
    use stereolab::plan::{Output as Out, Plan, View};
    use stereolab_core::{Precision, remap_coordinates};
    let (w, h) = (160u32, 120u32);
    let sets = vec!["camera.near=2e-5".to_string()];
    let mut scene =
        stereolab::scene::Scene::load(&asset("scenes/anaglyph.toml"), &sets).expect("scene");
    scene.set_size(w, h).expect("size");
    assert!(scene.camera.near / scene.camera.far <= 1e-6);
    assert_eq!(
        Precision::default(),
        Precision::F64,
        "the outputs remap in f64"
    );
    let frame = stereolab::render::render(&scene, &Plan::new(&[Out::RemapLeft])).expect("render");
    let left = frame.view(View::Left).expect("left pass");
    let (ml, mr) = (frame.views.eyes[0].mvp, frame.views.eyes[1].mvp);
    let exact = remap_coordinates(left, &ml, &mr, Precision::F64).expect("f64");
    let worst_of = |p: Precision| {
        let got = remap_coordinates(left, &ml, &mr, p).expect("remap");
        let (mut drawn, mut worst) = (0, 0.0f64);
        for ((a, b), d) in exact.iter().zip(&got).zip(left.depth()) {
            if *d >= 1.0 {
                continue;
            }
            drawn += 1;
            let Some(a) = a else { continue };
            let e = b.map_or(f64::INFINITY, |b| {
                let (pa, pb) = (a.window(w, h), b.window(w, h));
                (pa[0] - pb[0]).hypot(pa[1] - pb[1])
            });
            worst = worst.max(e);
        }
        (drawn, worst)
    };
    let (drawn, composed) = worst_of(Precision::F32Composed);
    let (_, slides) = worst_of(Precision::F32);
    eprintln!(
        "remap at near/far 1e-6 on {drawn} pixels: f32 composed {composed:e} px, \
         f32 through world space {slides:e} px from f64"
    );
    assert!(drawn > 1000, "{drawn} pixels drawn");
    assert!(
        composed <= 0.5,
        "f32 composed remap is {composed} px off f64"
    );
    let out = info("anaglyph.toml", &["camera.near=2e-5"]);
    assert_warned(&out, &["camera.near"]);
}

/// Catalogue: a model of size 2 at distance `t` from the origin, the camera 6 units from it.
/// The renderer's f32 view (`stereolab_core::look_at`, `stereolab_core::frustum`) against the f64 rig on the same
/// f32 vertices, so only the transform's precision is measured. Tolerance: no decided pixel
/// differs while f32 spaces coordinates there at most 1e-4 of the model's size (where the
/// scene check stays silent, `ORIGIN_PRECISION_WARN`); beyond, the check warns (tested in
/// `a_model_far_from_the_origin_is_warned_about_with_the_precision_lost`), and at 1e7 the
/// image is visibly wrong, which is why it must.
#[test]
fn catalogue_coordinates_far_from_the_origin_against_the_f64_reference() {
    use glam::{DVec3, Vec3};
    let (w, h) = (160u32, 120u32);
    let (near, far) = (0.5f32, 20.0f32);
    let aspect = w as f32 / h as f32;
    let mut shares = Vec::new();
    for t in [0.0f64, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7] {
        let c = DVec3::new(t, 0.0, 0.0);
        // Three overlapping squares 0.3 apart in depth, and a slanted one through them.
        let mut world = Vec::new();
        let mut triangles = Vec::new();
        for (k, (dx, dy, dz)) in [(-0.3, -0.2, 0.0), (0.0, 0.1, -0.3), (0.3, -0.1, -0.6)]
            .into_iter()
            .enumerate()
        {
            let base = (4 * k) as u32;
            for (sx, sy) in [(-0.7, -0.7), (0.7, -0.7), (0.7, 0.7), (-0.7, 0.7)] {
                world.push(c + DVec3::new(dx + sx, dy + sy, dz));
            }
            triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
        let base = world.len() as u32;
        world.extend([
            c + DVec3::new(-1.0, -1.0, 0.4),
            c + DVec3::new(1.0, -1.0, -1.0),
            c + DVec3::new(0.0, 1.0, -0.3),
        ]);
        triangles.push([base, base + 1, base + 2]);
        // The vertices as the renderer holds them (f32); the reference reads the same values.
        let positions: Vec<Vec3> = world.iter().map(|p| p.as_vec3()).collect();
        let eye = c + DVec3::new(0.5, 0.8, 6.0);
        // A 34° vertical field of view: the model fills most of the image.
        let (x, y) = (0.15 * near * aspect, 0.15 * near);
        let mvp = stereolab_core::frustum(-x, x, -y, y, near, far)
            * stereolab_core::look_at(eye.as_vec3(), c.as_vec3(), Vec3::Y);
        let (n, f, a) = (f64::from(near), f64::from(far), f64::from(aspect));
        let (x, y) = (0.15 * n * a, 0.15 * n);
        let mvp64 = stereolab_core::frustum_f64(-x, x, -y, y, n, f)
            * stereolab_core::look_at_f64(eye, c, DVec3::Y);
        let m = against_reference_through(&positions, &triangles, (mvp, mvp64), (w, h));
        assert!(m.covered > 2000, "t = {t:e}: {m:?}");
        let share = m.total() as f64 / m.covered as f64;
        let spacing = f64::from((t as f32 + 1.0).next_up() - (t as f32 + 1.0));
        let silent = spacing <= 1e-4 * 2.0;
        eprintln!("t = {t:e}: {m:?}, spacing {spacing:e}, warned {}", !silent);
        if silent {
            assert_eq!(
                m.total(),
                0,
                "t = {t:e}: differs from the f64 reference: {m:?}"
            );
        }
        shares.push(share);
    }
    assert!(
        shares[7] > 0.05,
        "at 1e7 the f32 view must go visibly wrong (else the warning warns of nothing): {shares:?}"
    );
}

/// The parallax budget is read back from the depth buffer; where one depth step is worth
/// more than 0.1 px of parallax (`info::DEPTH_STEP_PARALLAX_WARN`), its figures are uncertain
/// by that much and the report says so (at near 1e-6 / far 1e7 the budget reads
/// −0.86 px where the vertices give −0.5 px). A well-set near plane stays silent.
#[test]
fn a_budget_read_from_a_too_coarse_depth_buffer_says_it_is_uncertain() {
    let out = render(
        "wuson.toml",
        "hard_cases_budget_uncertain",
        &["camera.near=1e-5", "camera.far=1e5"],
    );
    assert_warned(&out, &["parallax figures", "uncertain", "camera.near"]);
    let out = render(
        "wuson.toml",
        "hard_cases_budget_certain",
        &["camera.near=1", "camera.far=20"],
    );
    assert_no_warning_naming(&out, "uncertain");
}

/// Catalogue, large coordinates (docs/reliability.md "Large coordinates"): a plane of extent
/// 1e30 covering the view is drawn whole but its coordinates are beyond the clipper's range,
/// and `render` says so with the largest coordinate and the limit; at 1e10 it is in range and
/// nothing is said.
#[test]
fn coordinates_beyond_the_clippers_range_are_warned_about() {
    let dir = out_dir("hard-large-coordinates");
    std::fs::create_dir_all(&dir).expect("folder");
    let scene = dir.join("large.toml");
    let run = |scale: &str| {
        let text = format!(
            "outputs = [\"left\"]\n[image]\nwidth = 96\nheight = 64\n\
             [camera]\neye = [0, 0, 3]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n\
             [[mesh]]\nkind = \"plane\"\nscale = {scale}\n"
        );
        std::fs::write(&scene, text).expect("scene written");
        let (s, o) = (scene.to_string_lossy(), dir.join("out"));
        stereolab(&["render", &s, "--out", &o.to_string_lossy()])
    };
    let out = run("1e30");
    assert_warned(
        &out,
        &[
            "beyond the clipper's range",
            "largest 6.70",
            "e28",
            "limit 2.74",
            "e11",
        ],
    );
    assert_no_warning_naming(&run("1e10"), "clipper");
}
