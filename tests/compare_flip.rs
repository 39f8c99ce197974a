//! ꟻLIP in `stereolab compare`: pixels per degree from a display, the error map of identical and
//! of noisier pictures, its magma picture, agreement with ꟻLIP's own Python package, and the
//! command's report and refusals.

use std::path::Path;
use std::process::{Command, Output};

use image::{Rgb, RgbImage};
use stereolab::compare::flip::{
    DEFAULT_PPD, Display, FlipStats, error_map, magma_table, pixels_per_degree,
};
use stereolab::compare::{Comparison, Metrics, add_flip};

use crate::common::{out_dir, root};

/// A picture with edges, a gradient and flat areas: an orange box and a blue disc on a gray
/// ramp.
fn picture(w: u32, h: u32) -> RgbImage {
    RgbImage::from_fn(w, h, |x, y| {
        let (fx, fy) = (x as f32 / w as f32, y as f32 / h as f32);
        let (dx, dy) = (fx - 0.65, fy - 0.5);
        if (0.15..0.45).contains(&fx) && (0.25..0.75).contains(&fy) {
            Rgb([220, 120, 40])
        } else if dx * dx + dy * dy < 0.04 {
            Rgb([40, 80, 200])
        } else {
            let g = (40.0 + 160.0 * fx) as u8;
            Rgb([g, g, g])
        }
    })
}

/// `img` with uniform noise of ±`amplitude` levels on every channel, the same noise pattern for
/// every amplitude (a fixed xorshift sequence), clamped to 0..=255.
fn noisy(img: &RgbImage, amplitude: i32) -> RgbImage {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut out = img.clone();
    for p in out.pixels_mut() {
        for c in &mut p.0 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64; // 0..1
            let n = ((2.0 * unit - 1.0) * f64::from(amplitude)).round() as i32;
            *c = (i32::from(*c) + n).clamp(0, 255) as u8;
        }
    }
    out
}

/// A row that kept its pictures, as `compare` makes them.
fn row(name: &str, expected: RgbImage, actual: RgbImage) -> Comparison {
    Comparison {
        name: name.into(),
        metrics: Metrics {
            pixels: 0,
            coverage_mismatch: 0,
            max_channel_diff: 0,
            mean_channel_diff: 0.0,
            psnr: f64::INFINITY,
            max_depth_diff: 0.0,
        },
        has_depth: false,
        strip: None,
        max_levels_16: None,
        pictures: Some(Box::new([expected, actual])),
        flip: None,
    }
}

#[test]
fn compare_flip_ppd_of_a_07_m_3840_px_display_at_07_m_is_67() {
    let ppd = pixels_per_degree(0.7, 3840.0, 0.7);
    assert!((ppd - 67.0206).abs() < 1e-3, "{ppd}");
    assert!((ppd - DEFAULT_PPD).abs() < 0.05, "{ppd}");
    assert_eq!(Display::FLIP_DEFAULT.ppd(), ppd);
    // Twice as far, or half as wide a display of as many pixels: twice the pixels per degree.
    assert!((pixels_per_degree(1.4, 3840.0, 0.7) - 2.0 * ppd).abs() < 1e-9);
    assert!((pixels_per_degree(0.7, 3840.0, 0.35) - 2.0 * ppd).abs() < 1e-9);
}

#[test]
fn compare_flip_of_identical_pictures_is_zero_everywhere() {
    let a = picture(96, 64);
    let errors = error_map(&a, &a, DEFAULT_PPD).expect("same size");
    assert_eq!(errors.len(), 96 * 64);
    assert!(
        errors.iter().all(|&e| e == 0.0),
        "{:?}",
        FlipStats::of(&errors)
    );
}

#[test]
fn compare_flip_grows_with_the_noise() {
    let a = picture(96, 64);
    let means: Vec<f64> = [2, 8, 24, 64, 128]
        .into_iter()
        .map(|amp| FlipStats::of(&error_map(&a, &noisy(&a, amp), DEFAULT_PPD).unwrap()).mean)
        .collect();
    assert!(means[0] > 0.0, "{means:?}");
    assert!(means.windows(2).all(|w| w[0] < w[1]), "{means:?}");
    assert!(means[4] < 1.0, "{means:?}");
    // The statistics are ordered as percentiles must be.
    let s = FlipStats::of(&error_map(&a, &noisy(&a, 24), DEFAULT_PPD).unwrap());
    assert!(s.p50 <= s.p95 && s.p95 <= s.p99 && s.p99 <= s.max, "{s:?}");
    // A nearer viewer (more pixels per degree) sees less of the same fine noise.
    let near = FlipStats::of(&error_map(&a, &noisy(&a, 24), 20.0).unwrap()).mean;
    let far = FlipStats::of(&error_map(&a, &noisy(&a, 24), 200.0).unwrap()).mean;
    assert!(near > far, "20 ppd {near}, 200 ppd {far}");
    // Different sizes are refused, not a panic in the C++.
    let e = error_map(&a, &picture(64, 64), DEFAULT_PPD)
        .expect_err("sizes differ")
        .to_string();
    assert!(e.contains("96x64 vs 64x64"), "{e}");
}

#[test]
fn compare_flip_writes_the_error_map_in_magma_at_the_pictures_size() {
    let dir = out_dir("compare_flip_map");
    let a = picture(80, 48);
    let mut rows = vec![
        row("left pass", a.clone(), noisy(&a, 32)),
        row("anaglyph (wgsl)", a.clone(), a.clone()),
    ];
    let skipped = add_flip(&mut rows, DEFAULT_PPD, Some(&dir), u64::MAX).expect("written");
    assert!(skipped.is_empty(), "{skipped:?}");
    let magma = magma_table();
    assert_eq!(magma.len(), 256);
    // ꟻLIP's magma runs from near black to pale yellow.
    assert_eq!((magma[0], magma[255]), ([0, 0, 4], [252, 253, 191]));
    for (r, file) in rows
        .iter()
        .zip(["left_pass.flip.png", "anaglyph_wgsl.flip.png"])
    {
        let flip = r.flip.as_ref().expect("measured");
        assert_eq!(flip.map.as_deref(), Some(dir.join(file).as_path()));
        assert!(
            r.pictures.is_none(),
            "the pictures are dropped once measured"
        );
        let map = image::open(dir.join(file)).expect("a PNG").to_rgb8();
        assert_eq!(map.dimensions(), (80, 48));
        assert!(map.pixels().all(|p| magma.contains(&p.0)), "{file}");
    }
    // Identical pictures: the whole map is magma's first color; noisy ones reach further.
    let same = image::open(dir.join("anaglyph_wgsl.flip.png"))
        .unwrap()
        .to_rgb8();
    assert!(same.pixels().all(|p| p.0 == magma[0]));
    let noise = image::open(dir.join("left_pass.flip.png"))
        .unwrap()
        .to_rgb8();
    assert!(noise.pixels().any(|p| p.0 != magma[0]));
    // Nothing else is left in the folder (no temporary files).
    assert_eq!(
        crate::common::names(&dir),
        ["anaglyph_wgsl.flip.png", "left_pass.flip.png"]
    );
}

/// [`crate::common::python_with`] for flip_evaluator, numpy, PIL.
fn python_with_flip() -> Option<String> {
    crate::common::python_with(
        "flip_evaluator, numpy, PIL",
        "pip install flip-evaluator numpy Pillow",
    )
}

/// stereolab's ꟻLIP (NVIDIA's C++ through nv-flip) against ꟻLIP's own Python package, at two
/// viewing conditions: the mean and every pixel of the error map agree.
#[test]
fn compare_flip_agrees_with_flips_python_package() {
    let Some(python) = python_with_flip() else {
        return;
    };
    let dir = out_dir("compare_flip_python");
    let a = picture(120, 80);
    let b = noisy(&a, 24);
    let (pa, pb) = (dir.join("reference.png"), dir.join("test.png"));
    a.save(&pa).unwrap();
    b.save(&pb).unwrap();
    for ppd in [DEFAULT_PPD, 30.0] {
        let ours = error_map(&a, &b, ppd).unwrap();
        let out = dir.join("theirs.f32");
        let run = Command::new(&python)
            .arg(root().join("tests/data/compare/flip_reference.py"))
            .args([&pa, &pb])
            .arg(ppd.to_string())
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let their_mean: f64 = String::from_utf8_lossy(&run.stdout).trim().parse().unwrap();
        let theirs: Vec<f32> = std::fs::read(&out)
            .unwrap()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        assert_eq!(theirs.len(), ours.len());
        let worst = ours
            .iter()
            .zip(&theirs)
            .map(|(o, t)| (o - t).abs())
            .fold(0.0f32, f32::max);
        let our_mean = FlipStats::of(&ours).mean;
        eprintln!("{ppd} ppd: mean {our_mean:.7} (theirs {their_mean:.7}), worst pixel {worst:e}");
        assert!(
            (our_mean - their_mean).abs() < 1e-4,
            "{our_mean} vs {their_mean}"
        );
        assert!(worst < 1e-4, "{worst}");
    }
}

fn stereolab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .output()
        .expect("run stereolab")
}

fn save(dir: &Path, name: &str, img: &RgbImage) -> String {
    let p = dir.join(name);
    img.save(&p).unwrap();
    p.display().to_string()
}

#[test]
fn compare_cli_prints_flip_and_writes_its_map() {
    let dir = out_dir("compare_flip_cli");
    let a = picture(96, 64);
    let (pa, pb) = (save(&dir, "a.png", &a), save(&dir, "b.png", &noisy(&a, 2)));
    let maps = dir.join("out");
    let out = stereolab(&[
        "compare",
        &pa,
        &pb,
        "--threshold",
        "coverage=100",
        "--out",
        maps.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("ꟻLIP at 67.00 pixels per degree"),
        "{stdout}"
    );
    assert!(stdout.contains("ꟻLIP mean "), "{stdout}");
    for stat in ["median", "95%", "99%", "max"] {
        assert!(stdout.contains(stat), "{stat}: {stdout}");
    }
    assert!(maps.join("b.flip.png").exists(), "{stdout}");
    assert!(
        stdout.contains("b.flip.png (ꟻLIP error map, magma)"),
        "{stdout}"
    );

    // A display's pixels per degree, and the opt-in limit on the mean.
    let out = stereolab(&[
        "compare",
        &pa,
        &pb,
        "--threshold",
        "coverage=100",
        "--display-width",
        "0.5",
        "--display-distance",
        "0.6",
        "--display-resolution",
        "1920",
        "--threshold",
        "flip=0.000001",
    ]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stdout.contains("ꟻLIP at 40.21 pixels per degree (a 0.5 m wide display of 1920 pixels"),
        "{stdout}"
    );
    assert!(
        stderr.contains("mean ꟻLIP error") && stderr.contains("(flip=)"),
        "{stderr}"
    );
}

#[test]
fn compare_cli_refuses_bad_display_values_by_flag() {
    let dir = out_dir("compare_flip_bad");
    let a = picture(32, 32);
    let (pa, pb) = (save(&dir, "a.png", &a), save(&dir, "b.png", &a));
    for (args, flag) in [
        (&["--display-width", "0"][..], "--display-width"),
        (&["--display-width=-0.7"], "--display-width"),
        (&["--display-width", "NaN"], "--display-width"),
        (&["--display-distance", "inf"], "--display-distance"),
        (&["--display-distance", "1e9"], "--display-distance"),
        (&["--display-resolution", "0"], "--display-resolution"),
        (&["--display-resolution", "1e12"], "--display-resolution"),
        (&["--ppd", "0"], "--ppd"),
        (&["--ppd", "5000"], "--ppd"),
        (&["--ppd", "67", "--display-width", "0.7"], "--ppd"),
        (&["--threshold", "flip=2"], "--threshold"),
        // Sane values each, but a 0.01 m wide display of 16 px seen from 0.01 m: 0.28 ppd.
        (
            &[
                "--display-width",
                "0.01",
                "--display-distance",
                "0.01",
                "--display-resolution",
                "16",
            ],
            "--display-width",
        ),
    ] {
        let mut argv = vec!["compare", &pa, &pb];
        argv.extend_from_slice(args);
        let out = stereolab(&argv);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.starts_with("error: ") && stderr.contains(flag),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // Not a number at all: clap's own error, naming the flag.
    let out = stereolab(&["compare", &pa, &pb, "--display-width", "wide"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--display-width"), "{stderr}");
}

/// Two side-by-side pictures that differ in the right eye only: `--layout` compares them eye by
/// eye, and only the right eye's ꟻLIP is above zero.
#[test]
fn compare_cli_splits_a_layout_into_eyes_for_flip() {
    let dir = out_dir("compare_flip_layout");
    let eye = picture(64, 48);
    let side_by_side = |right: &RgbImage| {
        let mut img = RgbImage::new(128, 48);
        image::imageops::replace(&mut img, &eye, 0, 0);
        image::imageops::replace(&mut img, right, 64, 0);
        img
    };
    let pa = save(&dir, "expected.png", &side_by_side(&eye));
    let pb = save(&dir, "actual.png", &side_by_side(&noisy(&eye, 16)));
    let maps = dir.join("out");
    let out = stereolab(&[
        "compare",
        &pa,
        &pb,
        "--layout",
        "side_by_side",
        "--threshold",
        "coverage=100",
        "--threshold",
        "psnr=0",
        "--threshold",
        "mean=255",
        "--out",
        maps.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let flip_line = |row: &str| {
        let mut lines = stdout.lines().skip_while(|l| !l.starts_with(row));
        lines.nth(1).unwrap_or_default().to_string()
    };
    assert!(
        flip_line("actual-left ").contains("ꟻLIP mean 0.0000"),
        "{stdout}"
    );
    let right = flip_line("actual-right ");
    assert!(
        right.contains("ꟻLIP mean 0.0") && !right.contains("mean 0.0000"),
        "{stdout}"
    );
    for f in ["actual-left.flip.png", "actual-right.flip.png"] {
        let map = image::open(maps.join(f)).expect(f).to_rgb8();
        assert_eq!(map.dimensions(), (64, 48), "{f}: one eye's size");
    }
    // A layout that does not fit the picture, or is not a layout of one picture, is refused.
    for (layout, why) in [
        ("pair", "not a layout of one picture"),
        ("sideways", "known layouts"),
    ] {
        let out = stereolab(&["compare", &pa, &pb, "--layout", layout]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains("--layout") && stderr.contains(why),
            "{stderr}"
        );
    }
}

/// A pair larger than the memory ꟻLIP may take is not measured, and the note says why; the
/// other rows are.
#[test]
fn compare_flip_skips_a_pair_past_its_memory_budget() {
    let a = picture(64, 48);
    let small = picture(8, 8);
    let mut rows = vec![
        row("large", a.clone(), a.clone()),
        row("small", small.clone(), small),
    ];
    let budget = 64 * 48 * stereolab::compare::FLIP_BYTES_PER_PIXEL - 1;
    let skipped = add_flip(&mut rows, DEFAULT_PPD, None, budget).expect("measured");
    assert_eq!(skipped.len(), 1, "{skipped:?}");
    assert!(
        skipped[0].starts_with("large: ꟻLIP not measured: a 64×48 pair"),
        "{skipped:?}"
    );
    assert!(rows[0].flip.is_none() && rows[0].pictures.is_none());
    assert!(rows[1].flip.is_some());
    let table = stereolab::compare::table(&rows);
    assert_eq!(table.matches("ꟻLIP mean").count(), 1, "{table}");
}
