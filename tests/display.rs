//! The display-side outputs: Julesz's random-dot pair, frame-sequential APNG, crosstalk, the
//! above-below calibration screen, and the marks and numbers the parallax and ChromaDepth
//! outputs add. Each test measures the defining number on a shipped scene or a crafted one.

use stereolab::output::{Image, produce, report::effect_lines};
use stereolab::plan::{Output, Plan, View};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::{
    BACK_LEFT, BACK_RIGHT, CALIBRATION_ARROW_COLOR, CALIBRATION_BLANK_COLOR,
    CALIBRATION_VIEW_COLOR, CalibrationLayout, DEFAULT_GHOSTING_LEAK, PARALLAX_VIOLATION_COLOR,
    calibration_screen, ghost_risk, parallax_budget, parallax_image, parallax_map, rds_left,
    violation_band,
};

use crate::common::{asset, out_dir};

fn shipped(name: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::load(&asset(&format!("scenes/{name}.toml")), &sets)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn frame_of(scene: &Scene) -> Frame {
    render(scene, &Plan::new(&scene.outputs)).expect("render")
}

fn rgba(img: Image) -> image::RgbaImage {
    match img {
        Image::Rgba(i) => i,
        _ => panic!("expected an RGBA image"),
    }
}

/// +1 for a white dot, −1 for a black one.
fn sign(img: &image::RgbaImage, x: u32, y: u32) -> f64 {
    if img.get_pixel(x, y).0[0] > 127 {
        1.0
    } else {
        -1.0
    }
}

/// The horizontal shift s that best maps `left` onto `right` in the region (right(x) = left(x −
/// s)): the peak of the dots' correlation over integer shifts, refined by a parabola through
/// the peak and its neighbours.
fn measured_shift(
    left: &image::RgbaImage,
    right: &image::RgbaImage,
    xs: std::ops::Range<u32>,
    ys: std::ops::Range<u32>,
) -> f64 {
    let corr = |s: i32| {
        let mut sum = 0.0;
        let mut n = 0.0;
        for y in ys.clone() {
            for x in xs.clone() {
                let lx = x as i32 - s;
                sum += sign(right, x, y) * sign(left, lx as u32, y);
                n += 1.0;
            }
        }
        sum / n
    };
    let scores: Vec<(i32, f64)> = (-20..=20).map(|s| (s, corr(s))).collect();
    let &(best, peak) = scores
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .expect("shifts");
    assert!(peak > 0.5, "no correlation peak (best {best}: {peak})");
    let (a, c) = (corr(best - 1), corr(best + 1));
    let denom = a - 2.0 * peak + c;
    best as f64
        + if denom.abs() > 1e-12 {
            0.5 * (a - c) / denom
        } else {
            0.0
        }
}

#[test]
fn rds_right_is_the_left_dots_shifted_by_the_parallax_of_each_depth() {
    let scene = shipped("rds_planes", &[]);
    let frame = frame_of(&scene);
    // Only the two depth passes run: no shading at all.
    assert!(
        frame
            .passes
            .iter()
            .all(|p| p.pass.shading == stereolab::plan::Shading::DepthOnly)
    );
    assert_eq!(frame.passes.len(), 2);
    let left = rgba(produce(Output::RdsLeft, &frame, &scene).unwrap());
    let right = rgba(produce(Output::RdsRight, &frame, &scene).unwrap());
    // The left image is the texture alone: the same for any scene.
    assert_eq!(left, rds_left(scene.width, scene.height, &scene.rds));
    let rig = scene.parallax_rig().unwrap();
    // The wall at eye distance 8 (rows above everything else) and the square at 3.5.
    for (what, z, xs, ys) in [
        ("wall", 8.0, 30..290, 4..50),
        ("square", 3.5, 205..265, 90..150),
    ] {
        let p = rig.parallax(z) * rig.pixels_per_unit;
        let s = measured_shift(&left, &right, xs, ys);
        println!("{what}: p(z = {z}) = {p:+.3} px, measured shift {s:+.3} px");
        assert!(p.abs() > 5.0, "{what}: the test needs a visible parallax");
        assert!((s - p).abs() <= 0.5, "{what}: shift {s} vs p(z) {p}");
    }
    // No shape in either image alone: the square's region is as black as the wall's.
    let black = |img: &image::RgbaImage, xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
        let n = (xs.len() * ys.len()) as f64;
        ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(x, y).0[0] < 128)
            .count() as f64
            / n
    };
    for img in [&left, &right] {
        let (sq, wall) = (black(img, 205..265, 90..150), black(img, 30..290, 4..50));
        assert!(
            (sq - 0.5).abs() < 0.06 && (wall - 0.5).abs() < 0.06,
            "{sq} {wall}"
        );
    }
    // The anaglyph: left dots in red, right dots in green and blue (gray anaglyph).
    let ana = rgba(produce(Output::RdsAnaglyph, &frame, &scene).unwrap());
    for (x, y) in [(10, 10), (230, 120), (100, 200)] {
        let (a, l, r) = (
            ana.get_pixel(x, y).0,
            left.get_pixel(x, y).0,
            right.get_pixel(x, y).0,
        );
        assert_eq!((a[0], a[1], a[2]), (l[0], r[1], r[2]), "({x}, {y})");
    }
}

#[test]
fn rds_bytes_depend_only_on_the_seed() {
    let a = shipped("rds_planes", &[]);
    let b = shipped("rds_planes", &["rds.seed=3"]);
    let (fa, fb) = (frame_of(&a), frame_of(&b));
    let ra = rgba(produce(Output::RdsRight, &fa, &a).unwrap());
    assert_eq!(
        ra,
        rgba(produce(Output::RdsRight, &frame_of(&a), &a).unwrap())
    );
    assert_ne!(ra, rgba(produce(Output::RdsRight, &fb, &b).unwrap()));
    let e = Scene::load(
        &asset("scenes/rds_planes.toml"),
        &["rds.dot_size=0".to_string()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("rds.dot_size"), "{e}");
}

#[test]
fn frame_sequential_apng_alternates_back_left_and_back_right_at_the_rate() {
    let scene = shipped("frame_sequential", &["frame_sequential.eye_rate_hz=50"]);
    let frame = frame_of(&scene);
    let dir = out_dir("frame_sequential");
    let paths = stereolab::output::write_all(&frame, &scene, &dir).unwrap();
    assert_eq!(paths, vec![dir.join("frame_sequential.png")]);
    let bytes = std::fs::read(&paths[0]).unwrap();
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let actl = reader.info().animation_control.expect("an animated PNG");
    // cycles = 2 in the scene: L, R, L, R, looping forever.
    assert_eq!((actl.num_frames, actl.num_plays), (4, 0));
    let left = frame.draw_buffer(BACK_LEFT).unwrap().to_rgba_image();
    let right = frame.draw_buffer(BACK_RIGHT).unwrap().to_rgba_image();
    assert_ne!(left, right, "the eyes must differ for the order to be seen");
    assert_eq!(frame.draw_buffer(BACK_LEFT), frame.view(View::Left));
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for i in 0..4 {
        let info = reader.next_frame(&mut buf).unwrap();
        let fc = reader.info().frame_control.expect("fcTL");
        // 50 images per second per eye: each field 1/100 s.
        assert_eq!((fc.delay_num, fc.delay_den), (1, 100), "frame {i}");
        let want = if i % 2 == 0 { &left } else { &right };
        assert_eq!(
            &buf[..info.buffer_size()],
            want.as_raw().as_slice(),
            "frame {i}"
        );
    }
    let e = Scene::load(
        &asset("scenes/frame_sequential.toml"),
        &["frame_sequential.eye_rate_hz=1000".to_string()],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("frame_sequential.eye_rate_hz"), "{e}");
}

#[test]
fn ghosting_leaks_the_set_share_of_the_other_eye_in_linear_light() {
    let scene = shipped("ghosting", &["ghosting.leak=[0.1, 0.2, 0.05]"]);
    let frame = frame_of(&scene);
    let (l, r) = (
        frame.view(View::Left).unwrap(),
        frame.view(View::Right).unwrap(),
    );
    let out = rgba(produce(Output::GhostingLeft, &frame, &scene).unwrap());
    // A pixel that is background (black) in the left eye and bright in the right eye.
    let (x, y) = (0..l.height())
        .flat_map(|y| (0..l.width()).map(move |x| (x, y)))
        .find(|&(x, y)| l.pixel(x, y)[..3] == [0, 0, 0] && r.pixel(x, y)[1] > 200)
        .expect("a ghost pixel");
    let dec = |v: u8| stereolab_core::srgb_to_linear(v as f32 / 255.0);
    let enc = |v: f32| (stereolab_core::linear_to_srgb(v) * 255.0).round() as u8;
    let other = r.pixel(x, y);
    for (c, leak) in [0.1f32, 0.2, 0.05].into_iter().enumerate() {
        assert_eq!(
            out.get_pixel(x, y).0[c],
            enc(leak * dec(other[c])),
            "channel {c}"
        );
    }
    // Where the right eye is black nothing leaks.
    let (bx, by) = (0..l.height())
        .flat_map(|y| (0..l.width()).map(move |x| (x, y)))
        .find(|&(x, y)| r.pixel(x, y)[..3] == [0, 0, 0] && l.pixel(x, y)[..3] != [0, 0, 0])
        .expect("a pixel the right eye leaves black");
    assert_eq!(out.get_pixel(bx, by).0, l.pixel(bx, by));
    // The defaults put green first.
    const {
        assert!(
            DEFAULT_GHOSTING_LEAK[1] > DEFAULT_GHOSTING_LEAK[0]
                && DEFAULT_GHOSTING_LEAK[1] > DEFAULT_GHOSTING_LEAK[2]
        )
    };
}

#[test]
fn contrast_warning_on_bright_on_dark_with_parallax_and_not_on_a_dull_scene() {
    let bright = shipped("ghosting", &[]);
    let lines = effect_lines(&frame_of(&bright), &bright).unwrap();
    println!("{}", lines.join("\n"));
    let warn: Vec<&String> = lines
        .iter()
        .filter(|l| l.starts_with("warning: ghosting"))
        .collect();
    assert_eq!(warn.len(), 2, "{lines:?}");
    assert!(warn[0].contains("px wide") && warn[0].contains("gray background"));
    let f = frame_of(&bright);
    let risk = ghost_risk(f.view(View::Left).unwrap(), f.view(View::Right).unwrap()).unwrap();
    assert!(
        risk.widest_run >= risk.warn_run && risk.warn_run == 4,
        "{risk:?}"
    );
    // The same scene on the default mid-gray background: nothing is dark, no warning.
    let dull = shipped("ghosting", &["image.background=[0.5, 0.5, 0.5]"]);
    let lines = effect_lines(&frame_of(&dull), &dull).unwrap();
    assert!(!lines.iter().any(|l| l.starts_with("warning")), "{lines:?}");
    // The black background with a tenth of the parallax: the bands are too narrow to warn.
    let small = shipped("ghosting", &["stereo.eye_separation=0.04"]);
    let sf = frame_of(&small);
    let risk = ghost_risk(sf.view(View::Left).unwrap(), sf.view(View::Right).unwrap()).unwrap();
    assert!(risk.widest_run < risk.warn_run, "{risk:?}");
    let lines = effect_lines(&sf, &small).unwrap();
    assert!(!lines.iter().any(|l| l.starts_with("warning")), "{lines:?}");
}

#[test]
fn calibration_arrows_sit_on_the_middle_row_of_each_view() {
    let scene = shipped("above_below_calibration", &[]);
    let frame = frame_of(&scene);
    assert!(
        frame.passes.is_empty(),
        "the calibration screen needs no pass"
    );
    let img = rgba(produce(Output::AboveBelowCalibration, &frame, &scene).unwrap());
    let l = CalibrationLayout::new(1024, 768, 40).unwrap();
    assert_eq!(
        (l.rows, l.bottom_top, l.top_arrow_y, l.bottom_arrow_y),
        (364, 404, 182, 586)
    );
    // The blank band: rows 364..404 black, all of them.
    for y in 364..404 {
        assert!(
            (0..1024).all(|x| img.get_pixel(x, y).0 == CALIBRATION_BLANK_COLOR),
            "row {y}"
        );
    }
    for y in [363, 404] {
        assert_eq!(
            img.get_pixel(1000, y).0,
            CALIBRATION_VIEW_COLOR,
            "row {y} is a view row"
        );
    }
    // Each arrow's rows are symmetric about its centre line, and its tip meets the centre.
    for (top, bottom, cy, tip_col, tail_col) in [
        (0u32, 364u32, 182u32, 505u32, 300u32),
        (404, 768, 586, 518, 700),
    ] {
        let rows: Vec<u32> = (top..bottom)
            .filter(|&y| (0..1024).any(|x| img.get_pixel(x, y).0 == CALIBRATION_ARROW_COLOR))
            .collect();
        let (first, last) = (rows[0], *rows.last().unwrap());
        assert_eq!(
            first + last + 1,
            2 * cy,
            "arrow rows {first}..={last} about {cy}"
        );
        assert_eq!(img.get_pixel(tip_col, cy).0, CALIBRATION_ARROW_COLOR);
        assert_eq!(img.get_pixel(tail_col, cy).0, CALIBRATION_ARROW_COLOR);
    }
    // The top arrow points right (nothing right of the tip), the bottom one left.
    assert_ne!(img.get_pixel(513, 182).0, CALIBRATION_ARROW_COLOR);
    assert_ne!(img.get_pixel(510, 586).0, CALIBRATION_ARROW_COLOR);
    // Another blank interval moves the bottom arrow by the difference.
    // (30 rows: views of 369 rows, the bottom one from row 399, its arrow on row 583).
    let other = calibration_screen(1024, 768, 30).unwrap();
    let moved = CalibrationLayout::new(1024, 768, 30).unwrap();
    assert_eq!(moved.bottom_arrow_y, 583);
    assert_eq!(other.get_pixel(700, 583).0, CALIBRATION_ARROW_COLOR);
    assert_eq!(other.get_pixel(700, 573).0, CALIBRATION_ARROW_COLOR);
    assert_eq!(img.get_pixel(700, 573).0, CALIBRATION_VIEW_COLOR);
}

#[test]
fn window_violations_are_marked_on_the_parallax_image() {
    let scene = shipped("window_violation", &[]);
    let frame = frame_of(&scene);
    let fb = frame.view(View::Left).unwrap();
    let rig = scene.parallax_rig().unwrap();
    let map = parallax_map(fb, &rig).unwrap();
    let b = parallax_budget(&map, fb.width(), fb.height());
    assert!(b.window_violations[0] > 10, "{:?}", b.window_violations);
    let img = parallax_image(fb, &rig).unwrap();
    let band = violation_band(fb.width());
    let yellow = |x: u32, y: u32| img.get_pixel(x, y).0 == PARALLAX_VIOLATION_COLOR;
    let marked_rows = (0..fb.height()).filter(|&y| yellow(0, y)).count();
    assert_eq!(marked_rows, b.window_violations[0]);
    for y in (0..fb.height()).filter(|&y| map[(y * fb.width()) as usize].is_some_and(|p| p < 0.0)) {
        assert!((0..band).all(|x| yellow(x, y)), "row {y}");
    }
    // Nothing else is yellow: the far wall's rows at the left edge are not.
    let yellow_px = (0..fb.height())
        .flat_map(|y| (0..fb.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| yellow(x, y))
        .count();
    let sides: usize = b.window_violations.iter().sum();
    assert!(yellow_px <= sides * band as usize && yellow_px >= b.window_violations[0]);
    // A scene without violations (the random-dot scene: its square stays inside) has no mark.
    let clean = shipped("rds_planes", &[]);
    let cf = frame_of(&clean);
    let cfb = cf.view(View::Left).unwrap();
    let crig = clean.parallax_rig().unwrap();
    assert_eq!(
        parallax_budget(
            &parallax_map(cfb, &crig).unwrap(),
            cfb.width(),
            cfb.height()
        )
        .window_violations,
        [0; 4]
    );
    let cimg = parallax_image(cfb, &crig).unwrap();
    assert!(!cimg.pixels().any(|p| p.0 == PARALLAX_VIOLATION_COLOR));
}

#[test]
fn chromadepth_report_names_the_d1_d2_it_used() {
    let scene = shipped("window_violation", &[]);
    let frame = frame_of(&scene);
    let lines = effect_lines(&frame, &scene).unwrap();
    let line = lines
        .iter()
        .find(|l| l.starts_with("chromadepth: D1 = "))
        .unwrap_or_else(|| panic!("{lines:?}"));
    let t = stereolab::render::chromadepth::resolve_texgen(
        &scene,
        &frame.views.center,
        &scene.chromadepth,
    )
    .unwrap();
    assert!(
        line.contains(&format!("D1 = {:.4} (bounding sphere)", t.d1)),
        "{line}"
    );
    assert!(
        line.contains(&format!("D2 = {:.4} (bounding sphere)", t.d2)),
        "{line}"
    );
    let set = shipped(
        "window_violation",
        &["chromadepth.d1=2.5", "chromadepth.d2=9.0"],
    );
    let lines = effect_lines(&frame_of(&set), &set).unwrap();
    assert!(
        lines
            .iter()
            .any(|l| l.starts_with("chromadepth: D1 = 2.5000 (scene), D2 = 9.0000 (scene)")),
        "{lines:?}"
    );
}
