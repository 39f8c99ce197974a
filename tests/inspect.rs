//! `stereolab inspect` reading stereo pictures back: every layout stereolab writes, the same
//! layouts put together here by other code (plain pixel copies, nearest-neighbour squeezing,
//! a channel-merge anaglyph), and pictures that are no stereo layout at all.

use std::path::PathBuf;
use std::process::Command;

use image::{Rgba, RgbaImage};
use stereolab::inspect::{Layout, detect, read, split};
use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;

use crate::common::{asset, out_dir};

/// The Wuson scene's eyes at 320×240 and each listed output, as produced by `render`.
fn rendered(outputs: &[Output]) -> (RgbaImage, RgbaImage, Vec<Image>) {
    let mut scene = Scene::load(&asset("scenes/wuson.toml"), &[]).unwrap();
    scene.set_size(320, 240).unwrap();
    scene.blank_interval = 16;
    let mut all = vec![Output::Left, Output::Right];
    all.extend_from_slice(outputs);
    let frame = render(&scene, &Plan::new(&all)).unwrap();
    let mut images: Vec<Image> = all
        .iter()
        .map(|&o| produce(o, &frame, &scene).unwrap())
        .collect();
    let rgba = |i: Image| match i {
        Image::Rgba(i) => i,
        _ => panic!("not RGBA"),
    };
    let rest = images.split_off(2);
    let right = rgba(images.pop().unwrap());
    let left = rgba(images.pop().unwrap());
    (left, right, rest)
}

/// The largest channel difference and the mean absolute difference over all channels.
fn differ(a: &RgbaImage, b: &RgbaImage) -> (u8, f64) {
    assert_eq!(a.dimensions(), b.dimensions());
    let (mut max, mut sum) = (0u8, 0u64);
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p.0[c].abs_diff(q.0[c]);
            max = max.max(d);
            sum += u64::from(d);
        }
    }
    (max, sum as f64 / (3.0 * f64::from(a.width() * a.height())))
}

fn rgba(i: &Image) -> &RgbaImage {
    match i {
        Image::Rgba(i) => i,
        _ => panic!("not RGBA"),
    }
}

/// The random-dot scene (`rds_planes.toml` with `sets`: dots on every surface, so every
/// surface has texture to match): its left and right images, gray (the green channel) as
/// well, and the left eye's exact parallax per pixel.
struct Rds {
    left: RgbaImage,
    right: RgbaImage,
    exact: Vec<Option<f64>>,
}

impl Rds {
    fn new(sets: &[&str]) -> Rds {
        use stereolab::plan::View;
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let scene = Scene::load(&asset("scenes/rds_planes.toml"), &sets).unwrap();
        let frame = render(&scene, &Plan::new(&[Output::RdsLeft, Output::RdsRight])).unwrap();
        let img = |o: Output| rgba(&produce(o, &frame, &scene).unwrap()).clone();
        let exact = stereolab_core::parallax_map(
            frame.view(View::Left).unwrap(),
            &scene.parallax_rig().unwrap(),
        )
        .unwrap();
        Rds {
            left: img(Output::RdsLeft),
            right: img(Output::RdsRight),
            exact,
        }
    }

    fn gray(img: &RgbaImage) -> Vec<u8> {
        img.pixels().map(|p| p.0[1]).collect()
    }
}

/// [`Rds::new`]'s two images.
fn rds_images(sets: &[&str]) -> (RgbaImage, RgbaImage) {
    let rds = Rds::new(sets);
    (rds.left, rds.right)
}

/// Two images as a left/right pair.
fn pair(left: RgbaImage, right: RgbaImage) -> stereolab::inspect::Views {
    stereolab::inspect::Views {
        left,
        right,
        layout: Layout::Pair,
        evidence: String::new(),
    }
}

#[test]
fn every_layout_stereolab_writes_is_detected_and_split_back() {
    // (output, the layout detection must find, views exact?)
    let cases = [
        (Output::SideBySide, Layout::SideBySide, true),
        (Output::AboveBelow, Layout::AboveBelow, true),
        (Output::FramePacking, Layout::FramePacking, true),
        (Output::InterlacedRows, Layout::InterlacedRows, false),
        (Output::InterlacedColumns, Layout::InterlacedColumns, false),
        (Output::Checkerboard, Layout::Checkerboard, false),
        (Output::HalfSideBySide, Layout::HalfSideBySide, false),
        (Output::HalfAboveBelow, Layout::HalfAboveBelow, false),
        (
            Output::AboveBelowSquashed,
            Layout::AboveBelowSquashed,
            false,
        ),
    ];
    let outputs: Vec<Output> = cases.iter().map(|c| c.0).collect();
    let (left, right, images) = rendered(&outputs);
    for ((output, want, exact), img) in cases.iter().zip(&images) {
        let img = rgba(img);
        let (layout, evidence) = detect(img).unwrap_or_else(|e| panic!("{output:?}: {e}"));
        assert_eq!(layout, *want, "{output:?}: {evidence}");
        let (l, r) = split(img, layout).unwrap();
        let (dl, dr) = (differ(&l, &left), differ(&r, &right));
        eprintln!(
            "{output:?}: left max {} mean {:.2}, right max {} mean {:.2}",
            dl.0, dl.1, dr.0, dr.1
        );
        if *exact {
            assert_eq!((dl.0, dr.0), (0, 0), "{output:?}");
        } else {
            // Squeezed or interleaved views lose every other row or column: close on
            // average, and each view closer to its own eye than to the other.
            assert!(dl.1 < 1.5 && dr.1 < 1.5, "{output:?}: {dl:?} {dr:?}");
            assert!(
                differ(&l, &right).1 > dl.1,
                "{output:?}: left is the left eye"
            );
            assert!(
                differ(&r, &left).1 > dr.1,
                "{output:?}: right is the right eye"
            );
        }
    }
}

#[test]
fn every_anaglyph_is_detected_with_its_glasses() {
    use stereolab_core::{AnaglyphGlasses as G, AnaglyphKind as K, AnaglyphMethod as M};
    let cases = [
        (K::True, Layout::AnaglyphRedCyan),
        (K::Gray, Layout::AnaglyphRedCyan),
        (K::Color, Layout::AnaglyphRedCyan),
        (K::HalfColor, Layout::AnaglyphRedCyan),
        (K::Optimized, Layout::AnaglyphRedCyan),
        (K::DuboisRedCyan, Layout::AnaglyphRedCyan),
        (K::DuboisRedCyanLcd, Layout::AnaglyphRedCyan),
        (
            K::ThreeJs(M::Compromise, G::RedCyan),
            Layout::AnaglyphRedCyan,
        ),
        (K::DuboisGreenMagenta, Layout::AnaglyphGreenMagenta),
        (K::DuboisAmberBlue, Layout::AnaglyphAmberBlue),
    ];
    let outputs: Vec<Output> = cases.iter().map(|c| Output::Anaglyph(c.0)).collect();
    let (left, right, images) = rendered(&outputs);
    let gray = |i: &RgbaImage| {
        let g = i.pixels().map(|p| {
            0.299 * f64::from(p.0[0]) + 0.587 * f64::from(p.0[1]) + 0.114 * f64::from(p.0[2])
        });
        g.collect::<Vec<f64>>()
    };
    for ((kind, want), img) in cases.iter().zip(&images) {
        let img = rgba(img);
        let (layout, evidence) = detect(img).unwrap_or_else(|e| panic!("{kind:?}: {e}"));
        assert_eq!(layout, *want, "{kind:?}: {evidence}");
        // Each eye's view has that eye's outline: where the eyes differ, it is nearer to
        // its own eye's luma edges than to the other's (compared as correlations).
        let (l, r) = split(img, layout).unwrap();
        let corr = |a: &[f64], b: &[f64]| {
            let n = a.len() as f64;
            let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
            let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
            let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
            let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
            cov / (va * vb).sqrt()
        };
        let (gl, gr) = (gray(&left), gray(&right));
        // Only where the two eyes differ: the parallax edges.
        let mask: Vec<bool> = gl
            .iter()
            .zip(&gr)
            .map(|(a, b)| (a - b).abs() > 20.0)
            .collect();
        let pick = |v: Vec<f64>| -> Vec<f64> {
            v.into_iter()
                .zip(&mask)
                .filter(|(_, m)| **m)
                .map(|(x, _)| x)
                .collect()
        };
        let (vl, vr) = (pick(gray(&l)), pick(gray(&r)));
        let (el, er) = (pick(gl.clone()), pick(gr.clone()));
        assert!(el.len() > 200, "the eyes differ somewhere");
        assert!(
            corr(&vl, &el) > corr(&vl, &er) && corr(&vr, &er) > corr(&vr, &el),
            "{kind:?}: each split view follows its own eye"
        );
    }
}

/// The same layouts put together by code that shares nothing with stereolab's writers.
#[test]
fn layouts_made_by_other_code_are_detected() {
    let (left, right, _) = rendered(&[]);
    let (w, h) = left.dimensions();
    let sbs = RgbaImage::from_fn(2 * w, h, |x, y| {
        if x < w {
            *left.get_pixel(x, y)
        } else {
            *right.get_pixel(x - w, y)
        }
    });
    // Nearest-neighbour squeeze (every other column), as a quick resize would do it.
    let half = RgbaImage::from_fn(w, h, |x, y| {
        if x < w / 2 {
            *left.get_pixel(2 * x, y)
        } else {
            *right.get_pixel(2 * (x - w / 2), y)
        }
    });
    let tab = RgbaImage::from_fn(w, h, |x, y| {
        if y < h / 2 {
            *left.get_pixel(x, 2 * y)
        } else {
            *right.get_pixel(x, 2 * (y - h / 2))
        }
    });
    // The plain colour anaglyph: red from the left eye, green and blue from the right.
    let ana = RgbaImage::from_fn(w, h, |x, y| {
        let (l, r) = (left.get_pixel(x, y).0, right.get_pixel(x, y).0);
        Rgba([l[0], r[1], r[2], 255])
    });
    for (img, want) in [
        (&sbs, Layout::SideBySide),
        (&half, Layout::HalfSideBySide),
        (&tab, Layout::HalfAboveBelow),
        (&ana, Layout::AnaglyphRedCyan),
    ] {
        let (layout, evidence) = detect(img).unwrap();
        assert_eq!(layout, want, "{evidence}");
    }
    // Nearest-neighbour squeezing keeps the even columns: stretched back, those are exact.
    let (l, _) = split(&half, Layout::HalfSideBySide).unwrap();
    for y in 0..h {
        for x in (0..w).step_by(2) {
            assert_eq!(l.get_pixel(x, y), left.get_pixel(x, y));
        }
    }
}

#[test]
fn pictures_without_a_stereo_layout_are_refused_not_guessed() {
    let (left, right, _) = rendered(&[]);
    let (w, h) = left.dimensions();
    // Seeded noise (a comb of about 1 along both axes, but no scene in its fields).
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let noise = RgbaImage::from_fn(w, h, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let b = state.to_le_bytes();
        Rgba([b[0], b[1], b[2], 255])
    });
    // One eye beside a mirror image of the other: two halves of different pictures.
    let unrelated = RgbaImage::from_fn(2 * w, h, |x, y| {
        if x < w {
            *left.get_pixel(x, y)
        } else {
            *right.get_pixel(w - 1 - (x - w), h - 1 - y)
        }
    });
    let flat = RgbaImage::from_pixel(w, h, Rgba([90, 90, 90, 255]));
    for (name, img) in [
        ("one eye", &left),
        ("noise", &noise),
        ("unrelated halves", &unrelated),
        ("flat", &flat),
    ] {
        let err = detect(img).expect_err(name).to_string();
        assert!(err.contains("no stereo layout found"), "{name}: {err}");
    }
}

#[test]
fn containers_pairs_and_wrong_layouts() {
    let dir = out_dir("inspect_files");
    let (left, right, _) = rendered(&[]);
    let (lp, rp) = (dir.join("l.png"), dir.join("r.png"));
    left.save(&lp).unwrap();
    right.save(&rp).unwrap();
    let pair = read(&[lp.clone(), rp.clone()], None).unwrap();
    assert_eq!(
        (pair.layout, &pair.left, &pair.right),
        (Layout::Pair, &left, &right)
    );
    // A pair of different sizes.
    let small = dir.join("small.png");
    image::imageops::crop_imm(&right, 0, 0, 10, 10)
        .to_image()
        .save(&small)
        .unwrap();
    let err = read(&[lp.clone(), small], None).unwrap_err().to_string();
    assert!(err.contains("the same size"), "{err}");
    // A layout that does not fit the picture, and one that needs two files.
    let err = read(std::slice::from_ref(&lp), Some(Layout::FramePacking))
        .unwrap_err()
        .to_string();
    assert!(err.contains("frame_packing"), "{err}");
    let err = read(std::slice::from_ref(&lp), Some(Layout::Pair))
        .unwrap_err()
        .to_string();
    assert!(err.contains("two files"), "{err}");
    // A single view: refused, naming the file and the way out.
    let err = read(std::slice::from_ref(&lp), None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("l.png") && err.contains("--layout"), "{err}");
    // A given layout wins over detection: cross-eyed swaps the halves of a parallel pair.
    let sbs = dir.join("sbs.png");
    RgbaImage::from_fn(640, 240, |x, y| {
        if x < 320 {
            *left.get_pixel(x, y)
        } else {
            *right.get_pixel(x - 320, y)
        }
    })
    .save(&sbs)
    .unwrap();
    let crossed = read(std::slice::from_ref(&sbs), Some(Layout::CrossEyed)).unwrap();
    assert_eq!((crossed.left, crossed.right), (right.clone(), left.clone()));
}

/// The command as a user runs it: the layout and its evidence on stdout, the views written,
/// exit status 0; a single view exits non-zero with the reason.
#[test]
fn the_command_reports_the_layout_and_writes_the_views() {
    let dir = out_dir("inspect_cli");
    let (left, right, images) = rendered(&[Output::FramePacking]);
    let packed: PathBuf = dir.join("packed.png");
    rgba(&images[0]).save(&packed).unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .arg("inspect")
            .args(args)
            .output()
            .unwrap()
    };
    let views = dir.join("views");
    let out = run(&[packed.to_str().unwrap(), "--out", views.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("layout: frame_packing (490 rows = 2 × 240 + 10 black rows"),
        "{stdout}"
    );
    assert_eq!(
        image::open(views.join("left.png")).unwrap().to_rgba8(),
        left
    );
    assert_eq!(
        image::open(views.join("right.png")).unwrap().to_rgba8(),
        right
    );
    let single = dir.join("left.png");
    left.save(&single).unwrap();
    let out = run(&[single.to_str().unwrap()]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no stereo layout found"), "{stderr}");
}

/// Semi-global matching on Julesz's random-dot pair (dots everywhere: a textured scene)
/// against the exact parallax `p(z) = d(1 − z0/z)` of the left eye's depth.
#[test]
fn sgm_finds_the_exact_parallax_of_a_random_dot_pair() {
    use stereolab::inspect::disparity::{SgmSettings, sgm};
    let rds = Rds::new(&[]);
    let (l, r, exact) = (Rds::gray(&rds.left), Rds::gray(&rds.right), &rds.exact);
    let (w, h) = rds.left.dimensions();
    let range = exact
        .iter()
        .flatten()
        .fold(0f64, |m, p| m.max(p.abs()))
        .ceil() as i32
        + 4;
    let map = sgm(&l, &r, w, h, SgmSettings::symmetric(range)).unwrap();
    let mut errors: Vec<f64> = Vec::new();
    let mut visible = 0;
    for (d, p) in map.disparity.iter().zip(exact) {
        if let Some(p) = p {
            visible += 1;
            if !d.is_nan() {
                errors.push((f64::from(*d) - p).abs());
            }
        }
    }
    errors.sort_by(f64::total_cmp);
    let median = errors[errors.len() / 2];
    let within_1 = errors.iter().filter(|e| **e <= 1.0).count() as f64 / errors.len() as f64;
    let matched = errors.len() as f64 / f64::from(visible);
    eprintln!(
        "sgm on rds_planes {w}×{h}, ±{range} px: matched {:.1}% of {visible} px, median error {median:.3} px, {:.1}% within 1 px",
        100.0 * matched,
        100.0 * within_1
    );
    assert!(median <= 0.25, "median error {median}");
    assert!(within_1 >= 0.95, "{within_1}");
    assert!(matched >= 0.85, "{matched}");
}

/// [`crate::common::python_with`] for cv2, numpy, PIL.
fn python_with_opencv() -> Option<String> {
    crate::common::python_with(
        "cv2, numpy, PIL",
        "pip install opencv-python-headless numpy Pillow",
    )
}

/// stereolab's matcher against OpenCV's StereoSGBM (an independent implementation of the same
/// paper) on the random-dot pair, both held to the exact parallax too.
#[test]
fn sgm_agrees_with_opencvs_stereo_sgbm() {
    use stereolab::inspect::disparity::{SgmSettings, sgm};
    let Some(python) = python_with_opencv() else {
        return;
    };
    let dir = out_dir("inspect_opencv");
    let rds = Rds::new(&[]);
    let (lp, rp) = (dir.join("left.png"), dir.join("right.png"));
    rds.left.save(&lp).unwrap();
    rds.right.save(&rp).unwrap();
    let range = 12;
    let (w, h) = rds.left.dimensions();
    let ours = sgm(
        &Rds::gray(&rds.left),
        &Rds::gray(&rds.right),
        w,
        h,
        SgmSettings::symmetric(range),
    )
    .unwrap();
    let out = dir.join("opencv.f32");
    let run = Command::new(&python)
        .arg(crate::common::root().join("tests/data/inspect/opencv_sgbm.py"))
        .args([&lp, &rp])
        .arg(range.to_string())
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let theirs: Vec<f32> = std::fs::read(&out)
        .unwrap()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(theirs.len(), ours.disparity.len());
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut both = Vec::new();
    let (mut ours_exact, mut theirs_exact) = (Vec::new(), Vec::new());
    for ((a, b), p) in ours.disparity.iter().zip(&theirs).zip(&rds.exact) {
        if !a.is_nan() && !b.is_nan() {
            both.push(f64::from((a - b).abs()));
            if let Some(p) = p {
                ours_exact.push((f64::from(*a) - p).abs());
                theirs_exact.push((f64::from(*b) - p).abs());
            }
        }
    }
    let share = both.len() as f64 / ours.disparity.len() as f64;
    let (m, mo, mt) = (median(both), median(ours_exact), median(theirs_exact));
    eprintln!(
        "{}: both matched {:.1}%, median |stereolab − OpenCV| {m:.3} px; against the exact \
         parallax: stereolab {mo:.3} px, OpenCV {mt:.3} px",
        String::from_utf8_lossy(&run.stdout).trim(),
        100.0 * share
    );
    assert!(share > 0.8, "{share}");
    assert!(m <= 0.25, "median difference {m} px");
}

/// The measured parallax of the Wuson pair lies within the exact range of its drawn pixels, and
/// two copies of one view are reported as having no visible depth.
#[test]
fn measured_parallax_lies_in_the_exact_range_and_copies_show_no_depth() {
    use stereolab::inspect::{Views, describe, measure};
    use stereolab::plan::View;
    use stereolab_core::parallax_map;
    let mut scene = Scene::load(&asset("scenes/wuson.toml"), &[]).unwrap();
    scene.set_size(320, 240).unwrap();
    let frame = render(&scene, &Plan::new(&[Output::Left, Output::Right])).unwrap();
    let exact: Vec<f64> = parallax_map(
        frame.view(View::Left).unwrap(),
        &scene.parallax_rig().unwrap(),
    )
    .unwrap()
    .into_iter()
    .flatten()
    .collect();
    let (lo, hi) = exact
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(*p), b.max(*p)));
    let img = |o: Output| rgba(&produce(o, &frame, &scene).unwrap()).clone();
    let views = Views {
        left: img(Output::Left),
        right: img(Output::Right),
        layout: Layout::Pair,
        evidence: String::new(),
    };
    let m = measure(&views).unwrap();
    let [p5, p50, p95] = m.percentiles.unwrap();
    eprintln!(
        "wuson 320×240: exact {lo:.2}..{hi:.2} px; measured 5th {p5:.2}, median {p50:.2}, 95th {p95:.2}, matched {:.1}%",
        100.0 * m.matched
    );
    assert!(lo - 0.5 <= p5 && p95 <= hi + 0.5 && p5 < p50 && p50 < p95);
    // Where the screen lies: the share of drawn pixels in front of it, exactly and measured.
    let front = exact.iter().filter(|p| **p < 0.0).count() as f64 / exact.len() as f64;
    let measured = stereolab::inspect::in_front_share(&m);
    eprintln!("in front of the screen: exactly {front:.3}, measured {measured:.3}");
    assert!((front - measured).abs() < 0.1, "{front} against {measured}");
    // Only the model is matched: the flat background has nothing to match.
    let drawn = exact.len() as f64 / f64::from(320 * 240);
    assert!(m.matched <= drawn + 0.02, "{} of {drawn}", m.matched);
    assert!(!describe(&m).contains("finding"), "{}", describe(&m));
    let copies = Views {
        right: views.left.clone(),
        ..views
    };
    let text = describe(&measure(&copies).unwrap());
    assert!(text.contains("finding: no visible depth"), "{text}");
}

/// Planted mistakes in the random-dot pair, each named by its finding, and none on the
/// correct pair: a toe-in rig (its keystone against `info`'s largest vertical parallax), the
/// right view 2 px lower, the right view rotated by 0.4°.
#[test]
fn vertical_disparity_names_toe_in_misalignment_and_rotation() {
    use stereolab::inspect::{describe_vertical, fit_vertical, measure, vertical_samples};
    let findings = |left: RgbaImage, right: RgbaImage| {
        let (w, h) = left.dimensions();
        let views = pair(left, right);
        let m = measure(&views).unwrap();
        let fit = fit_vertical(&vertical_samples(&views, &m), w, h).unwrap();
        (fit, describe_vertical(Some(&fit), w))
    };
    let (left, right) = rds_images(&[]);
    let (w, h) = left.dimensions();
    let (fit, text) = findings(left.clone(), right.clone());
    assert!(!text.contains("finding"), "{text}");
    assert!(
        fit.offset.abs() < 0.2 && fit.keystone.abs() < 0.2,
        "{fit:?}"
    );

    // Toe-in: the keystone at the corners is the rig's largest vertical parallax (`info`
    // prints 1.006% of the height for this scene: 2.41 px).
    let (tl, tr) = rds_images(&["stereo.mode=\"toe-in\""]);
    let (fit, text) = findings(tl, tr);
    assert!(text.contains("finding: toe-in"), "{text}");
    assert!(
        (fit.keystone.abs() - 0.01006 * f64::from(h)).abs() < 0.3,
        "{fit:?}"
    );

    // Two rows lower.
    let lower = RgbaImage::from_fn(w, h, |x, y| *right.get_pixel(x, y.saturating_sub(2)));
    let (fit, text) = findings(left.clone(), lower);
    assert!(
        text.contains("finding: vertical misalignment: the right view is 2.0 px lower"),
        "{text}"
    );
    assert!(
        !text.contains("toe-in") && !text.contains("rotation between"),
        "{text}"
    );
    assert!((fit.offset - 2.0).abs() < 0.2, "{fit:?}");

    // Rotated by 0.4° about the centre (nearest pixel).
    let t = 0.4f64.to_radians();
    let (cx, cy) = (f64::from(w) / 2.0, f64::from(h) / 2.0);
    let rotated = RgbaImage::from_fn(w, h, |x, y| {
        let (dx, dy) = (f64::from(x) + 0.5 - cx, f64::from(y) + 0.5 - cy);
        let sx = (cx + dx * t.cos() - dy * t.sin())
            .floor()
            .clamp(0.0, f64::from(w - 1));
        let sy = (cy + dx * t.sin() + dy * t.cos())
            .floor()
            .clamp(0.0, f64::from(h - 1));
        *right.get_pixel(sx as u32, sy as u32)
    });
    let (fit, text) = findings(left, rotated);
    assert!(
        text.contains("finding: rotation between the views"),
        "{text}"
    );
    // The edge's shift is tan(0.4°) · W/2 = 1.12 px.
    assert!((fit.rotation.abs() - t.tan() * cx).abs() < 0.25, "{fit:?}");
    assert!(!text.contains("toe-in"), "{text}");
}

/// Animations read as their first two frames: the wiggle GIF and APNG, and the frame-sequential
/// APNG, each as `stereolab render` writes it.
#[test]
fn animations_read_as_their_first_two_frames() {
    let dir = out_dir("inspect_animations");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let scene = asset("scenes/wiggle.toml");
    run(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        dir.to_str().unwrap(),
        "--set",
        "outputs=[\"left\",\"right\",\"wiggle_gif\",\"wiggle_apng\",\"frame_sequential\"]",
    ]);
    let open = |name: &str| image::open(dir.join(name)).unwrap().to_rgba8();
    let (left, right) = (open("left.png"), open("right.png"));
    for (file, exact) in [
        ("wiggle_apng.png", true),
        ("frame_sequential.png", true),
        ("wiggle_gif.gif", false),
    ] {
        let views = read(&[dir.join(file)], None).unwrap();
        assert_eq!(views.layout, Layout::Animation, "{file}");
        let (dl, dr) = (differ(&views.left, &left), differ(&views.right, &right));
        if exact {
            assert_eq!((dl.0, dr.0), (0, 0), "{file}");
        } else {
            // One 256-colour palette for both frames.
            assert!(
                dl.1 < 0.5 && dr.1 < 0.5 && dl.0 <= 12 && dr.0 <= 12,
                "{file}: {dl:?} {dr:?}"
            );
        }
    }
    // A still PNG is no animation: the single view is refused as before.
    let err = read(&[dir.join("left.png")], None).unwrap_err().to_string();
    assert!(err.contains("no stereo layout found"), "{err}");
}

/// The random-dot scene with its near square moved onto the left edge is named as a window
/// violation at the left edge, on about as many rows as the square covers there; the scene as
/// shipped (the square inside the frame) has none. (Random dots: every surface has texture to
/// match, where a shaded box's flat faces have none.)
#[test]
fn window_violations_are_found_at_the_edge_they_touch() {
    use stereolab::inspect::{describe, measure, window_violations};
    let views_of = |sets: &[&str]| {
        let rds = Rds::new(sets);
        // The rows whose edge pixel shows negative parallax, exactly.
        let w = rds.left.width() as usize;
        let rows = (0..rds.left.height() as usize)
            .filter(|y| rds.exact[y * w].is_some_and(|p| p < 0.0))
            .count();
        (pair(rds.left, rds.right), rows)
    };
    let (views, exact_rows) = views_of(&["mesh.2.translate=[-1.7, 0.0, 1.5]"]);
    let m = measure(&views).unwrap();
    let (left, right) = window_violations(&m);
    eprintln!(
        "window violation: {} rows found at the left edge, {exact_rows} exactly; {} at the right",
        left.len(),
        right.len()
    );
    assert!(exact_rows > 20);
    // The matcher blurs the square's top and bottom rows: within 15% of the exact count.
    assert!(
        left.len().abs_diff(exact_rows) * 100 <= 15 * exact_rows,
        "{} against {exact_rows}",
        left.len()
    );
    // A few stray matches at the right edge stay under the finding's one row in fifty.
    assert!(right.len() * 50 < 240, "{right:?}");
    let text = describe(&m);
    assert!(!text.contains("right edge"), "{text}");
    assert!(
        text.contains("finding: window violation") && text.contains("left edge"),
        "{text}"
    );
    // The square on the right edge instead.
    let (views, _) = views_of(&["mesh.2.translate=[1.7, 0.0, 1.5]"]);
    let m = measure(&views).unwrap();
    let (left, right) = window_violations(&m);
    eprintln!(
        "square at the right edge: {} rows at the left edge, {} at the right",
        left.len(),
        right.len()
    );
    let text = describe(&m);
    assert!(
        text.contains("right edge") && !text.contains("left edge"),
        "{text}"
    );
    let (views, exact_rows) = views_of(&[]);
    assert_eq!(exact_rows, 0);
    let text = describe(&measure(&views).unwrap());
    assert!(!text.contains("window violation"), "{text}");
}

/// `inspect PAIR --scene SCENE`: pairs rendered with a planted mistake, each compared with the
/// right scene, are named by that mistake and by no other; the right pair agrees. (The
/// random-dot scene: every surface has texture to match.)
#[test]
fn planted_mistakes_are_named_against_the_scene() {
    use stereolab::inspect::{
        compare_reference, describe_reference, describe_vertical, fit_vertical, measure,
        reference_parallax, vertical_samples,
    };
    let right_scene = Scene::load(&asset("scenes/rds_planes.toml"), &[]).unwrap();
    let (w, h) = (right_scene.width, right_scene.height);
    let (reference, at_infinity) = reference_parallax(&right_scene, w, h).unwrap();
    let report = |left: RgbaImage, right: RgbaImage| {
        let views = pair(left, right);
        let m = measure(&views).unwrap();
        let fit = compare_reference(&m, &reference, at_infinity).unwrap();
        let vertical = fit_vertical(&vertical_samples(&views, &m), w, h);
        (
            fit,
            describe_reference(&fit) + &describe_vertical(vertical.as_ref(), w),
        )
    };
    let names = [
        "eyes swapped",
        "wrong eye separation",
        "wrong zero-parallax distance",
        "half a pixel",
        "toe-in",
    ];
    let only = |text: &str, want: Option<&str>| {
        for n in names {
            assert_eq!(text.contains(n), Some(n) == want, "{want:?}: {text}");
        }
    };
    let (left, right) = rds_images(&[]);
    let (fit, text) = report(left.clone(), right.clone());
    eprintln!("right pair: {fit:?}");
    assert!(text.contains("agrees with the scene's rig"), "{text}");
    only(&text, None);

    let (_, text) = report(right.clone(), left.clone());
    only(&text, Some("eyes swapped"));

    let (l, r) = rds_images(&["stereo.eye_separation=0.375"]);
    let (fit, text) = report(l, r);
    only(&text, Some("wrong eye separation"));
    assert!((fit.factors().0 - 1.5).abs() < 0.05, "{fit:?}");

    let (l, r) = rds_images(&["stereo.zero_parallax=6.0"]);
    let (fit, text) = report(l, r);
    only(&text, Some("wrong zero-parallax distance"));
    assert!((fit.factors().1 - 1.2).abs() < 0.05, "{fit:?}");

    // The right view moved half a pixel left: each pixel the mean of itself and its right
    // neighbour.
    let half = RgbaImage::from_fn(w, h, |x, y| {
        let (a, b) = (
            right.get_pixel(x, y).0,
            right.get_pixel((x + 1).min(w - 1), y).0,
        );
        image::Rgba(std::array::from_fn(|c| {
            (u16::from(a[c]) + u16::from(b[c])).div_ceil(2) as u8
        }))
    });
    let (fit, text) = report(left, half);
    only(&text, Some("half a pixel"));
    assert!((fit.offset + 0.5).abs() < 0.15, "{fit:?}");

    // Toe-in is named by its keystone; the rig's horizontal parallax moves a little too
    // (separation 0.94×), which is no other mistake's name.
    let (l, r) = rds_images(&["stereo.mode=\"toe-in\""]);
    let (_, text) = report(l, r);
    assert!(text.contains("toe-in"), "{text}");
    for n in [
        "eyes swapped",
        "half a pixel",
        "wrong zero-parallax distance",
    ] {
        assert!(!text.contains(n), "{n}: {text}");
    }
}

/// Pairs made by another program: `tests/data/inspect/threejs_pairs.py` ray casts a textured
/// sphere and box before a textured wall in numpy through three.js's StereoCamera matrices,
/// correct and with planted mistakes. The command names each mistake, exits 3 on an error and
/// 0 on the correct pair (and on a warning alone, unless `--strict`). The eyes' order comes
/// from the occlusions alone: no scene is given.
#[test]
fn pairs_made_outside_stereolab_are_named_by_their_mistakes() {
    let Some(python) = python_with_opencv() else {
        return;
    };
    let dir = out_dir("inspect_threejs");
    let made = Command::new(&python)
        .arg(crate::common::root().join("tests/data/inspect/threejs_pairs.py"))
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let inspect = |name: &str, extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .arg("inspect")
            .arg(dir.join(format!("{name}_left.png")))
            .arg(dir.join(format!("{name}_right.png")))
            .args(extra)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        (out.status.code(), text)
    };
    let errors = [
        "eyes swapped",
        "toe-in",
        "vertical misalignment",
        "rotation between the views",
        "one view is larger",
        "no visible depth",
    ];
    let expect = |name: &str, want: Option<&str>| {
        let (code, text) = inspect(name, &[]);
        eprintln!("{name}:\n{text}");
        for e in errors {
            assert_eq!(
                text.contains(&format!("finding: {e}")),
                Some(e) == want,
                "{name}, {e}: {text}"
            );
        }
        assert_eq!(code, Some(if want.is_some() { 3 } else { 0 }), "{text}");
        text
    };
    let text = expect("correct", None);
    assert!(text.contains("eye order: left, then right"), "{text}");
    assert!(text.contains("result: 0 errors, 0 warnings"), "{text}");
    let text = expect("swapped", Some("eyes swapped"));
    assert!(text.contains("eye order: swapped"), "{text}");
    expect("toe_in", Some("toe-in"));
    let text = expect("misaligned", Some("vertical misalignment"));
    // A 0.4° pitch at 360 rows and a 50° field of view: 360/2 · tan 0.4° / tan 25° ≈ 2.7 px.
    assert!(text.contains("the right view is 2.9 px lower"), "{text}");
    let text = expect("rotated", Some("rotation between the views"));
    assert!(text.contains("+0.37°") || text.contains("+0.36°"), "{text}");
    expect("flat", Some("no visible depth"));
    // A window violation is a warning: exit 0, and 3 with --strict.
    let text = expect("window", None);
    assert!(
        text.contains("finding: window violation (warning)") && text.contains("left edge"),
        "{text}"
    );
    let (code, text) = inspect("window", &["--strict"]);
    assert_eq!(code, Some(3), "{text}");
    assert!(text.contains("fails (--strict)"), "{text}");
    // The picture beside the report: the view with the findings drawn, and the map. A yellow
    // arrow points at the left edge where the sphere violates the window, none at the right.
    let pictures = dir.join("window_out");
    let (code, _) = inspect("window", &["--out", pictures.to_str().unwrap()]);
    assert_eq!(code, Some(0));
    let img = image::open(pictures.join("inspect.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(img.width(), 2 * 480 + 8);
    let yellow = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (0..360).map(move |y| (x, y)))
            .filter(|&(x, y)| {
                let p = img.get_pixel(x, y).0;
                p[0] > 230 && p[1] > 200 && p[2] < 60
            })
            .count()
    };
    assert!(yellow(0, 40) > 20, "{}", yellow(0, 40));
    assert_eq!(yellow(440, 480), 0);
}

/// The anaglyph method estimated from the channels of a picture whose views are unknown: on the
/// TV-formats scene (coloured spheres on gray), each of stereolab's anaglyphs is either named
/// most likely (the gray, true and optimized methods, whose colours span a line or a plane) or
/// is among the methods that produce its colours, and the narrow methods are never claimed for
/// a full-colour anaglyph.
#[test]
fn the_anaglyph_method_is_estimated_from_the_channels() {
    use stereolab::inspect::anaglyph::estimate;
    let mut scene = Scene::load(&asset("scenes/tv_formats.toml"), &[]).unwrap();
    scene.set_size(640, 360).unwrap();
    let kinds = stereolab_core::AnaglyphKind::ALL;
    let outputs: Vec<Output> = kinds
        .iter()
        .map(|k| Output::parse(k.output_name()).unwrap())
        .collect();
    let frame = render(&scene, &Plan::new(&outputs)).unwrap();
    let mut estimated = 0;
    for (kind, output) in kinds.iter().zip(&outputs) {
        let img = rgba(&produce(*output, &frame, &scene).unwrap()).clone();
        let name = kind.output_name();
        let layout = match name {
            "anaglyph_green_magenta" => Layout::AnaglyphGreenMagenta,
            "anaglyph_amber_blue" => Layout::AnaglyphAmberBlue,
            _ => Layout::AnaglyphRedCyan,
        };
        // The reach the command passes: the measured parallax of the views split back.
        let (left, right) = split(&img, layout).unwrap();
        let m = stereolab::inspect::measure(&stereolab::inspect::Views {
            left,
            right,
            layout,
            evidence: String::new(),
        })
        .unwrap();
        let reach = stereolab::inspect::reach(&m);
        let e = estimate(&img, layout, reach);
        let text = e.describe();
        eprintln!("{name}: {text}");
        let explaining: Vec<String> = e.explaining().iter().map(|f| f.name()).collect();
        if text.contains("too few uniform areas") {
            continue;
        }
        estimated += 1;
        assert!(explaining.contains(&name.to_string()), "{name}: {text}");
        let narrow = ["anaglyph_true", "anaglyph_gray", "anaglyph_optimized"];
        if narrow.contains(&name) {
            assert!(
                text.contains(&format!("most likely {name}")),
                "{name}: {text}"
            );
        } else {
            assert!(!text.contains("most likely"), "{name}: {text}");
        }
    }
    // Only the colour anaglyph (whose three channels all vary over the shading) lacks uniform
    // areas on this scene: the others are all estimated, none skipped.
    assert_eq!(estimated, kinds.len() - 1);
    // The gray anaglyph's colours (green equals blue) rule out the colour-keeping methods'
    // narrow cousins: the true anaglyph (green 0) cannot produce them.
    let gray = rgba(&produce(outputs[1], &frame, &scene).unwrap()).clone();
    let e = estimate(&gray, Layout::AnaglyphRedCyan, 12);
    let true_fit = e
        .fits
        .iter()
        .find(|f| f.kind == stereolab_core::AnaglyphKind::True && !f.linear_light)
        .unwrap();
    assert!(true_fit.explained < 0.5, "{true_fit:?}");
}

/// No mistake named on a correct pair: every shipped scene's left and right views (at 480
/// pixels across, the scene's aspect kept) inspected with the findings that are errors. Smooth,
/// untextured shading gives the matchers little to hold on to; the findings must then stay
/// silent rather than guess.
#[test]
fn shipped_scenes_pairs_show_no_mistake() {
    use stereolab::inspect::{
        eyes::eye_order, findings, fit_vertical, measure, vertical_findings, vertical_samples,
    };
    let dir = crate::common::root().join("assets/scenes");
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 30, "{}", names.len());
    let mut inspected = 0;
    for path in &names {
        let mut scene = Scene::load(path, &[]).unwrap();
        let h = (480 * scene.height / scene.width).max(16);
        scene.set_size(480, h).unwrap();
        let frame = render(&scene, &Plan::new(&[Output::Left, Output::Right])).unwrap();
        let views = pair(
            rgba(&produce(Output::Left, &frame, &scene).unwrap()).clone(),
            rgba(&produce(Output::Right, &frame, &scene).unwrap()).clone(),
        );
        let m = measure(&views).unwrap();
        let fit = fit_vertical(&vertical_samples(&views, &m), 480, h);
        let mut found = findings(&m);
        found.extend(vertical_findings(fit.as_ref(), 480));
        found.extend(eye_order(&views, &m).findings());
        let errors: Vec<&str> = found
            .iter()
            .filter(|f| f.severity == stereolab::inspect::Severity::Error)
            .map(|f| f.name)
            .collect();
        assert!(errors.is_empty(), "{}: {errors:?} {fit:?}", path.display());
        inspected += 1;
    }
    assert_eq!(inspected, names.len());
}
