//! The slides' figures draw what the renderer does: the parallax plot's curve is the parallax
//! the two eyes' matrices actually give a point, for every rig mode and balance.

use glam::Vec3;
use stereolab::scene::Scene;
use stereolab_core::project_ndc;
use stereolab_figures::parallax_curve;

use crate::common::asset;

/// Parallax in percent of the image width of the point at eye distance `z` straight ahead of
/// the camera, measured by projecting it with both eyes' MVP matrices:
/// `(x_right − x_left) / 2 · 100` in NDC.
fn projected_parallax_percent(s: &Scene, z: f32) -> f32 {
    let eyes = s.rig.eyes(&s.camera, s.aspect()).expect("rig");
    let eye = Vec3::from(s.camera.eye);
    let forward = (Vec3::from(s.camera.target) - eye).normalize();
    let p = eye + forward * z;
    let x = |i: usize| project_ndc(&eyes[i].mvp, p).expect("in front").x;
    (x(1) - x(0)) / 2.0 * 100.0
}

#[test]
fn parallax_plot_is_the_parallax_both_eyes_project() {
    for sets in [
        vec![],
        vec!["stereo.user_balance=0.6"],
        vec!["stereo.user_balance=1.5", "stereo.zero_parallax=3"],
        vec!["stereo.mode=\"parallel\""],
    ] {
        let sets: Vec<String> = sets.into_iter().map(String::from).collect();
        let s = Scene::load(&asset("scenes/wuson.toml"), &sets).expect("scene");
        let curve = parallax_curve(&s, 24).expect("curve");
        assert_eq!(curve.len(), 25);
        for (z, plotted) in curve.into_iter().skip(1) {
            let measured = projected_parallax_percent(&s, z as f32);
            // f32 projection against the f64 formula: a few ulps of a percent (measured worst
            // 2e-6 relative).
            let tol = 1e-4 * measured.abs().max(1.0);
            assert!(
                (plotted as f32 - measured).abs() <= tol,
                "{sets:?}: z = {z}: plot says {plotted}% of width, the eyes project {measured}%"
            );
        }
    }
}

/// Toe-in: `p(z) = d(1 − z0/z)` holds on the center line only to first order (the rotated image
/// planes are not the screen); measured: 0.31% of the value at z = 1.79 with wuson's rig. The
/// plot draws the formula, and says so; this pins how far off it is.
#[test]
fn toe_in_parallax_plot_is_first_order_on_the_center_line() {
    let sets = vec!["stereo.mode=\"toe-in\"".to_string()];
    let s = Scene::load(&asset("scenes/wuson.toml"), &sets).expect("scene");
    let mut worst = 0.0f32;
    for (z, plotted) in parallax_curve(&s, 24).expect("curve").into_iter().skip(1) {
        let measured = projected_parallax_percent(&s, z as f32);
        worst = worst.max((plotted as f32 - measured).abs() / measured.abs().max(1.0));
    }
    assert!(
        worst < 0.01,
        "toe-in plot {:.3}% off the projection",
        worst * 100.0
    );
}

/// The committed figures are exactly what `stereolab figures` draws now: a change to the
/// renderer, the rig or a figure that moves a pixel fails here until the figures are redrawn
/// (`cargo run --release -- figures assets/scenes/wuson.toml`) and committed.
#[test]
fn committed_figures_are_what_the_code_draws() {
    let root = crate::common::root();
    let s = Scene::load(&asset("scenes/wuson.toml"), &[]).expect("scene");
    let csv_path = root.join("slides/data/bench.csv");
    let csv = std::fs::read_to_string(&csv_path).expect("slides/data/bench.csv");
    let bench = stereolab_figures::bench::parse_csv(&csv, &csv_path).expect("bench rows");
    let ctx = stereolab_figures::Context {
        scene: &s,
        bench: &bench,
    };
    let drawn = stereolab_figures::draw_all(&ctx).expect("figures");
    let dir = root.join("slides/figures");
    let mut stale = Vec::new();
    for (name, png) in &drawn {
        let committed = std::fs::read(dir.join(name)).unwrap_or_default();
        if &committed != png {
            let out = crate::common::failure_dir().join(format!("figure_{name}"));
            std::fs::write(&out, png).expect("write the redrawn figure");
            stale.push(format!("{name} (redrawn: {})", out.display()));
        }
    }
    assert!(
        stale.is_empty(),
        "slides/figures differs from what `stereolab figures` draws: {stale:?}; redraw with \
         `cargo run --release -- figures assets/scenes/wuson.toml` and commit"
    );
    // And nothing else lies there: every PNG in slides/figures is one the command draws, or
    // a copy of an accuracy report plot (`accuracy_*.png`, held equal to docs/accuracy by
    // tests/accuracy_report.rs).
    let names: Vec<&str> = drawn.iter().map(|(n, _)| n.as_str()).collect();
    for e in std::fs::read_dir(&dir).expect("slides/figures") {
        let name = e.expect("entry").file_name().to_string_lossy().into_owned();
        assert!(
            names.contains(&name.as_str()) || name.starts_with("accuracy_"),
            "slides/figures/{name} is not drawn by `stereolab figures`: remove it"
        );
    }
}

/// The decks: at least 60 slides over the seven topics, every image they show exists in
/// `slides/figures/` and every figure is shown somewhere.
#[test]
fn decks_show_every_figure_and_only_existing_ones() {
    let root = crate::common::root().join("slides");
    let mut decks: Vec<_> = std::fs::read_dir(&root)
        .expect("slides/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md") && !p.ends_with("README.md"))
        .collect();
    decks.sort();
    assert_eq!(decks.len(), 7, "one deck per topic: {decks:?}");
    let (mut slides, mut shown) = (0, Vec::new());
    for deck in &decks {
        let text = std::fs::read_to_string(deck).expect("deck");
        assert!(
            text.starts_with("---\nmarp: true\n"),
            "{}: not a Marp deck",
            deck.display()
        );
        // Front matter (two separators), then one slide more than there are separators.
        let separators = text.lines().filter(|l| *l == "---").count();
        slides += separators - 1;
        for (i, _) in text.match_indices("](figures/") {
            let rest = &text[i + 2..];
            let path = &rest[..rest.find(')').expect("closing parenthesis")];
            assert!(
                root.join(path).is_file(),
                "{}: shows {path}, which does not exist",
                deck.display()
            );
            shown.push(path.trim_start_matches("figures/").to_string());
        }
    }
    assert!(slides >= 60, "{slides} slides in all, want at least 60");
    // Every exercise task is introduced on a slide: its stub's name appears in a deck.
    let all_decks: String = decks
        .iter()
        .map(|d| std::fs::read_to_string(d).expect("deck"))
        .collect();
    let exercises = crate::common::root().join("exercises");
    for ex in ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"] {
        let stubs =
            std::fs::read_to_string(exercises.join(ex).join("src/stubs.rs")).expect("stubs");
        for line in stubs.lines().filter(|l| l.starts_with("pub fn ")) {
            let name = &line[7..line.find('(').expect("fn name")];
            assert!(
                all_decks.contains(&format!("`{name}`"))
                    || all_decks.contains(&format!("::{name}`")),
                "exercise task {ex}::{name} is introduced on no slide"
            );
        }
    }
    for f in stereolab_figures::all() {
        assert!(
            shown.contains(&format!("{}.png", f.name)),
            "figure {} is drawn but no deck shows it",
            f.name
        );
    }
}

/// The parallax diagram's image points come from `ParallaxRig::parallax`; the rays the figure
/// draws from each eye through its image point must meet at the point's depth on the center
/// line, and the sign of p must say behind / on / in front of the screen.
#[test]
fn parallax_diagram_rays_meet_at_the_point() {
    let geometry = stereolab_figures::parallax_types_geometry();
    let (d, z0) = (1.0, 4.0); // the schematic rig the figure states in its caption
    for (z, xl, xr) in geometry {
        for (eye, x_screen) in [(-d / 2.0, xl), (d / 2.0, xr)] {
            // The ray (eye, 0) → (x_screen, z0) reaches x = 0 at depth z0 · (0 − eye)/(x_screen − eye).
            let at = z0 * (0.0 - eye) / (x_screen - eye);
            assert!(
                (at - z).abs() < 1e-9,
                "ray from {eye} meets the axis at {at}, point at {z}"
            );
        }
        assert_eq!(
            (xr - xl).signum() as i32,
            (z - z0).signum() as i32,
            "z = {z}"
        );
    }
}

/// Toe-in's vertical parallax map is what the eyes' matrices give, measured independently here
/// on a rendered point; off-axis has none.
#[test]
fn vertical_parallax_map_is_zero_for_off_axis_and_not_for_toe_in() {
    use stereolab_core::CameraMode;
    use stereolab_figures::vertical_parallax_grid;
    let s = Scene::load(&asset("scenes/wuson.toml"), &[]).expect("scene");
    let toe = vertical_parallax_grid(&s, CameraMode::ToeIn, 8, 6).expect("grid");
    let off = vertical_parallax_grid(&s, CameraMode::OffAxis, 8, 6).expect("grid");
    assert!(off.iter().all(|v| v.abs() < 1e-3), "{off:?}");
    let worst = toe.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    assert!(
        worst > 1.0,
        "toe-in corners should show pixels of vertical parallax: {worst}"
    );
    // Opposite corners have opposite signs; the center cross has none.
    assert!(toe[0] * toe[7] < 0.0 && toe[0] * toe[47] > 0.0, "{toe:?}");
}

/// The SIRDS curves are `Disparity::separation`, and the linked-pixel diagram's d is the one the
/// strips use: both models meet at the background, and eq. 3's front separation is δ.
#[test]
fn sirds_figure_models_agree_at_the_background() {
    use stereolab_core::{DisparityModel, SirdsGeometry};
    let g = SirdsGeometry::default();
    let eq3 = g.to_pixels().expect("eq. 3");
    let eq1 = SirdsGeometry {
        model: DisparityModel::ViewAngle,
        ..g
    }
    .to_pixels()
    .expect("eq. 1");
    assert!((eq3.separation(0.0) - eq1.separation(0.0)).abs() < 1e-3);
    assert!(eq3.separation(1.0) < eq3.separation(0.0));
}

/// One deck page rendered by headless Chromium is not blank and shows its figure. Needs
/// Debian's `chromium` and the decks built to HTML (`npm ci && npm run build` in `slides/`),
/// as `.ci/run` does; without them it fails and says so.
#[test]
fn a_deck_page_renders_in_headless_chromium() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let root = crate::common::root();
    let html = root.join("slides/build/01-perception.html");
    assert!(
        html.is_file(),
        "{} is missing: build the decks first (`cd slides && npm ci && npm run build`, Node ≥ 18)",
        html.display()
    );
    let out = crate::common::out_dir("chromium_slide");
    let shot = out.join("slide.png");
    let profile = out.join("profile");
    // Page 3: the parallax figure.
    let url = format!("file://{}#3", html.display());
    let child = Command::new("chromium")
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--hide-scrollbars",
            "--window-size=1280,720",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("--screenshot={}", shot.display()))
        .arg(&url)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => panic!("cannot run `chromium` ({e}): install it (`apt-get install chromium`)"),
    };
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait for chromium").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("chromium did not finish within 120 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let img = image::open(&shot)
        .unwrap_or_else(|e| panic!("no screenshot at {}: {e}", shot.display()))
        .to_rgba8();
    assert_eq!(img.dimensions(), (1280, 720));
    let mut counts = std::collections::HashMap::new();
    for p in img.pixels() {
        *counts.entry(p.0).or_insert(0usize) += 1;
    }
    let most = counts.values().copied().max().unwrap_or(0);
    let inked = img.pixels().count() - most;
    assert!(
        inked > img.pixels().count() / 50 && counts.len() > 100,
        "blank slide: {inked} pixels off the background, {} colors",
        counts.len()
    );
    // The figure is there: the left eye's red (210, 40, 40) from parallax_types.png.
    let red = img
        .pixels()
        .filter(|p| p[0] > 180 && p[1] < 80 && p[2] < 80)
        .count();
    assert!(
        red > 30,
        "the slide's figure did not load ({red} red pixels)"
    );
}
