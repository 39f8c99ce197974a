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
