//! `stereolab view --images` and `stereolab inspect --view` as a person uses them: a pair that
//! stereolab itself wrote is opened under Xvfb, the ways of showing it are switched by key, the
//! image shift is measured on the window's pixels, and a picture with no stereo layout is
//! refused before any window opens. The tools and the harness are `tests/viewer.rs`'s (a
//! missing tool fails the test with the package to install).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use image::RgbaImage;

use crate::common::{asset, out_dir};
use crate::viewer::{Killed, Viewer, centroid_x, need, parse_xwd, start_xvfb, stereolab};

/// The Wuson scene rendered by `stereolab render` at 320×240 into `dir`: `left.png`,
/// `right.png`, `side_by_side.png`. The zero-parallax plane lies in front of the model, so all
/// of it is behind the screen (parallax about +6 px).
fn render_pair(dir: &Path) {
    let out = stereolab()
        .arg("render")
        .arg(asset("scenes/wuson.toml"))
        .args(["--size", "320x240", "--set", "stereo.zero_parallax=3.2"])
        .arg("--out")
        .arg(dir)
        .output()
        .expect("run stereolab render");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The horizontal shift between the red channel (the left view in `anaglyph_color`) and the
/// green channel (the right view): the parallax the window shows, in screen pixels.
fn red_green_shift(img: &image::RgbImage) -> f64 {
    let bg = img.get_pixel(2, 2).0;
    centroid_x(img, 1, bg[1]) - centroid_x(img, 0, bg[0])
}

/// The color anaglyph of the two views shifted by `shift` pixels, as the library makes it:
/// the left view loses its first `shift` columns, both are cut to the common width.
fn shifted_anaglyph(left: &RgbaImage, right: &RgbaImage, shift: u32) -> RgbaImage {
    let (w, h) = left.dimensions();
    let cut = |img: &RgbaImage, from: u32| {
        stereolab_core::rds_framebuffer(
            &image::imageops::crop_imm(img, from, 0, w - shift, h).to_image(),
        )
    };
    stereolab_core::anaglyph(
        &cut(left, shift),
        &cut(right, 0),
        stereolab_core::AnaglyphKind::Color,
        stereolab_core::AnaglyphOptions::default(),
    )
    .unwrap()
}

/// Mean absolute difference per channel of two pictures of the same size.
fn mean_difference(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let diff: u64 = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(p, q)| u64::from(p.abs_diff(*q)))
        .sum();
    diff as f64 / a.as_raw().len() as f64
}

#[test]
fn viewer_shows_a_side_by_side_picture_as_a_pair_and_shifts_it() {
    let x = start_xvfb();
    let out = out_dir("viewer_pair");
    let rendered = out.join("rendered");
    render_pair(&rendered);
    let sbs = rendered.join("side_by_side.png");
    let v = Viewer::start(
        &x,
        &out,
        &[
            "--images",
            sbs.to_str().unwrap(),
            "--output",
            "anaglyph_color",
        ],
    );

    // 1. The layout is detected as inspect detects it; the parallax is measured once.
    let s0 = v.wait("the measured color anaglyph", |s| {
        s["output"] == "anaglyph_color" && s["measuring"] == false
    });
    assert_eq!(s0["source"], "images", "{s0}");
    assert_eq!(s0["layout"], "side_by_side", "{s0}");
    assert_eq!(s0["view_size"], serde_json::json!([320, 240]), "{s0}");
    assert_eq!(s0["image_size"], serde_json::json!([320, 240]), "{s0}");
    assert_eq!(s0["shift_max_px"], 40, "{s0}");
    let median = s0["parallax_px"][1].as_f64().unwrap();
    assert!(
        median > 3.0 && median < 10.0,
        "the model lies behind the screen: median parallax {median} px"
    );
    let pic0 = v.picture(&s0);
    pic0.save(out.join("anaglyph_color.png")).unwrap();
    let shift0 = red_green_shift(&pic0);
    assert!(
        (shift0 - median).abs() < 1.5,
        "the window's red/green shift {shift0:.2} px, inspect's median parallax {median:.2} px"
    );

    // 2. Six presses of the right arrow: the right view moves 6 px right against the left.
    for _ in 0..6 {
        v.key("Right");
    }
    let s1 = v.wait("an image shift of 6 px", |s| s["shown_shift_px"] == 6);
    assert_eq!(s1["image_size"], serde_json::json!([314, 240]), "{s1}");
    let pic1 = v.picture(&s1);
    pic1.save(out.join("anaglyph_color_shift_6.png")).unwrap();
    let shift1 = red_green_shift(&pic1);
    assert!(
        (shift1 - shift0 - 6.0).abs() < 0.5,
        "a shift of 6 px moved the red/green shift from {shift0:.2} to {shift1:.2} px"
    );
    // The window shows the library's anaglyph of the views cut by 6 columns.
    let left = image::open(rendered.join("left.png")).unwrap().to_rgba8();
    let right = image::open(rendered.join("right.png")).unwrap().to_rgba8();
    let expected = image::DynamicImage::ImageRgba8(shifted_anaglyph(&left, &right, 6)).to_rgb8();
    let mean = mean_difference(&pic1, &expected);
    assert!(
        mean < 2.0,
        "the window differs from the shifted anaglyph by {mean:.2} per channel"
    );
    let shifted = s1["parallax_shifted_px"][1].as_f64().unwrap();
    assert!((shifted - median - 6.0).abs() < 1e-6, "{s1}");

    // 3. Z: the shift that puts the median parallax on the screen; the red and green images of
    // the model then coincide.
    v.key("z");
    let want = s1["median_shift_px"].as_i64().unwrap();
    assert_eq!(want, -(median.round() as i64));
    let s2 = v.wait("the median on the screen", |s| s["shown_shift_px"] == want);
    let pic2 = v.picture(&s2);
    pic2.save(out.join("anaglyph_color_on_screen.png")).unwrap();
    let shift2 = red_green_shift(&pic2);
    assert!(
        shift2.abs() < 1.5,
        "with the median on the screen the red/green shift is {shift2:.2} px"
    );

    // 4. The other ways to show the pair, by key, sized as each is.
    let w = 320 - want.unsigned_abs();
    for (key, mode, size) in [
        ("1", "side_by_side", [2 * w, 240]),
        ("0", "cross_eyed", [2 * w, 240]),
        ("9", "left", [w, 240]),
        ("8", "right", [w, 240]),
        ("2", "anaglyph_dubois", [w, 240]),
    ] {
        v.key(key);
        let s = v.wait(mode, |s| s["shown_output"] == mode);
        assert_eq!(s["image_size"], serde_json::json!(size), "{mode}: {s}");
        let title = window_name(&x.display, &v.window);
        assert!(
            title.contains("side_by_side.png") && title.contains(mode),
            "title: {title}"
        );
    }
    let s3 = v.wait("anaglyph_dubois", |s| {
        s["shown_output"] == "anaglyph_dubois"
    });
    v.picture(&s3)
        .save(out.join("anaglyph_dubois.png"))
        .unwrap();
    v.key("Page_Down");
    v.wait("the next anaglyph", |s| {
        s["shown_output"] == "anaglyph_dubois_lcd"
    });

    // 5. The disparity map (key 4) with its legend below: the model behind the screen is red
    // (stereolab's parallax colours), of the pair as read whatever the shift.
    v.key("4");
    let s4 = v.wait("the disparity map", |s| s["shown_output"] == "disparity");
    let size = &s4["image_size"];
    assert_eq!(size[0], 320, "{s4}");
    assert!(size[1].as_u64().unwrap() > 240, "a legend below: {s4}");
    let map = v.picture(&s4);
    map.save(out.join("disparity.png")).unwrap();
    let (red, blue) = map
        .pixels()
        .take(320 * 240)
        .fold((0, 0), |(r, b), p| match p.0 {
            [r8, g8, b8] if r8 > 180 && g8 < 150 && b8 < 150 => (r + 1, b),
            [r8, g8, b8] if b8 > 180 && r8 < 150 && g8 < 150 => (r, b + 1),
            _ => (r, b),
        });
    assert!(
        red > 2000 && blue < red / 20,
        "{red} red (behind) and {blue} blue (in front) pixels"
    );

    // 6. R: no shift; S: the picture shown as a PNG (no scene, so no TOML).
    v.key("2");
    v.key("r");
    let s5 = v.wait("no shift", |s| {
        s["shown_shift_px"] == 0 && s["shown_output"] == "anaglyph_dubois"
    });
    v.key("s");
    let s6 = v.wait("the screenshot", |s| {
        s["shots"].as_array().is_some_and(|a| !a.is_empty())
    });
    let png = PathBuf::from(s6["shots"][0].as_str().unwrap());
    assert_eq!(png, out.join("side_by_side-view-001.png"));
    assert!(!png.with_extension("toml").exists());
    let status = s6["status"].as_str().unwrap();
    assert!(
        status.contains("anaglyph_dubois") && status.contains("layout side_by_side"),
        "{status}"
    );
    let saved = image::open(&png).unwrap().to_rgb8();
    let mean = mean_difference(&v.picture(&s5), &saved);
    assert!(
        mean < 2.0,
        "the window differs from the screenshot PNG by {mean:.2} per channel"
    );
}

/// The window's title (xdotool getwindowname).
fn window_name(display: &str, window: &str) -> String {
    let name = Command::new(need("xdotool", "xdotool"))
        .args(["getwindowname", window])
        .env("DISPLAY", display)
        .output()
        .expect("run xdotool");
    String::from_utf8_lossy(&name.stdout).trim().to_string()
}

#[test]
fn inspect_view_opens_the_pair_just_inspected() {
    let x = start_xvfb();
    let out = out_dir("viewer_pair_inspect");
    render_pair(&out);
    let log_path = out.join("inspect.log");
    let log = std::fs::File::create(&log_path).unwrap();
    let mut child = Killed(
        stereolab()
            .arg("inspect")
            .arg(out.join("left.png"))
            .arg(out.join("right.png"))
            .arg("--view")
            .env("DISPLAY", &x.display)
            .env_remove("WAYLAND_DISPLAY")
            .env("LIBGL_ALWAYS_SOFTWARE", "1")
            .stdout(log.try_clone().unwrap())
            .stderr(log)
            .spawn()
            .expect("start stereolab inspect --view"),
    );
    let xdotool = need("xdotool", "xdotool");
    let start = Instant::now();
    let window = loop {
        let found = Command::new(&xdotool)
            .args(["search", "--name", "stereolab view"])
            .env("DISPLAY", &x.display)
            .output()
            .expect("run xdotool");
        let text = String::from_utf8_lossy(&found.stdout).to_string();
        if let Some(id) = text.lines().next().filter(|l| !l.trim().is_empty()) {
            break id.trim().to_string();
        }
        let log = std::fs::read_to_string(&log_path).unwrap_or_default();
        assert!(
            child.0.try_wait().unwrap().is_none(),
            "inspect --view exited without a window; its output: {log}"
        );
        assert!(
            start.elapsed() < Duration::from_secs(90),
            "no viewer window after 90 s; its output: {log}"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    let title = window_name(&x.display, &window);
    assert!(
        title.contains("left.png + right.png") && title.contains("anaglyph_dubois"),
        "title: {title}"
    );
    // The report came first, then the window; the window shows a picture: the Dubois
    // anaglyph of the model on its gray background (which the Dubois matrices keep gray).
    let start = Instant::now();
    loop {
        let dump = Command::new(need("xwd", "x11-apps"))
            .args(["-silent", "-id", &window])
            .env("DISPLAY", &x.display)
            .output()
            .expect("run xwd");
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no pair's gray background in the window after 60 s"
        );
        if !dump.status.success() || dump.stdout.len() < 1024 {
            // The window exists but is not mapped yet.
            std::thread::sleep(Duration::from_millis(300));
            continue;
        }
        let shot = parse_xwd(&dump.stdout);
        let gray = shot
            .pixels()
            .filter(|p| p.0.iter().all(|&c| c.abs_diff(p.0[0]) < 3) && (110..150).contains(&p.0[0]))
            .count();
        if gray > 20_000 {
            shot.save(out.join("window.png")).unwrap();
            break;
        }
        std::thread::sleep(Duration::from_millis(300));
    }
    for args in [
        vec!["windowfocus", "--sync", &window],
        vec!["key", "--clearmodifiers", "q"],
    ] {
        let ok = Command::new(&xdotool)
            .args(&args)
            .env("DISPLAY", &x.display)
            .stdout(Stdio::null())
            .status()
            .unwrap()
            .success();
        assert!(ok, "xdotool {args:?}");
    }
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.0.try_wait().unwrap() {
            break s;
        }
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "inspect --view still running 30 s after Q"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    let log = std::fs::read_to_string(&log_path).unwrap();
    assert!(status.success(), "{log}");
    assert!(
        log.contains("layout: pair") && log.contains("parallax:"),
        "{log}"
    );
}

#[test]
fn viewer_refuses_a_picture_with_no_stereo_layout_before_any_window() {
    let out = out_dir("viewer_pair_refused");
    render_pair(&out);
    let text = out.join("notes.png");
    std::fs::write(&text, "not a picture").unwrap();
    // Without a display: the inspect error comes first, so the pictures are read before any
    // window could open (a display error here would mean the window came first).
    let run = |args: &[&Path]| {
        let out = stereolab()
            .args(["view", "--images"])
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("run stereolab view");
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.starts_with("error: "), "{err}");
        assert!(
            !err.contains("DISPLAY") && !err.contains("panicked"),
            "{err}"
        );
        err
    };
    // One eye alone is no stereo picture: inspect's own words, and what to do.
    let err = run(&[&out.join("left.png")]);
    assert!(
        err.contains("left.png")
            && err.contains("no stereo layout found")
            && err.contains("--layout"),
        "{err}"
    );
    let err = run(&[&text]);
    assert!(err.contains("notes.png"), "{err}");
    let small = out.join("small.png");
    image::RgbaImage::new(100, 50).save(&small).unwrap();
    let err = run(&[&out.join("left.png"), &small]);
    assert!(err.contains("320×240") && err.contains("100×50"), "{err}");

    // Neither a scene nor --images, or both: clap's usage error, exit 2.
    let neither = stereolab().arg("view").output().unwrap();
    let err = String::from_utf8_lossy(&neither.stderr);
    assert_eq!(neither.status.code(), Some(2), "{err}");
    assert!(err.contains("<SCENE|--images <IMAGE>...>"), "{err}");
    let both = stereolab()
        .arg("view")
        .arg(asset("scenes/wuson.toml"))
        .arg("--images")
        .arg(out.join("side_by_side.png"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&both.stderr);
    assert_eq!(both.status.code(), Some(2), "{err}");
    assert!(err.contains("cannot be used with"), "{err}");
    // A scene's output is no way to show a pair.
    let chroma = stereolab()
        .arg("view")
        .arg("--images")
        .arg(out.join("side_by_side.png"))
        .args(["--output", "chromadepth"])
        .env_remove("DISPLAY")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&chroma.stderr);
    assert_eq!(chroma.status.code(), Some(1), "{err}");
    assert!(err.contains("need a scene"), "{err}");
}
