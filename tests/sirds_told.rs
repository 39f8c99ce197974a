//! The SIRDS decoder told the viewing set-up by a scene or flags
//! (an eq. 1 autostereogram beyond the searched range decodes); and measured properties of
//! what worked untested: parallel cameras, guide dots, cross-eyed SIRDS, a pattern image.

use std::path::Path;
use std::sync::Arc;

use stereolab::output::sirds::{from_frame, scene_depth};
use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{SirdsDecodeOptions, SirdsPattern, decode_sirds, sirds_round_trip};

use crate::common::{asset, out_dir};
use crate::sirds::{SPHERE, frame, sized_scene};

fn run(args: &[&str]) -> (bool, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .output()
        .expect("runs");
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// Mean of the 16-bit depth image (white = near) over a square of half-size 6 at `(x, y)`.
fn mean_depth(path: &Path, x: u32, y: u32) -> f64 {
    let img = image::open(path).expect("depth readable").into_luma16();
    let mut sum = 0.0;
    for yy in y - 6..=y + 6 {
        for xx in x - 6..=x + 6 {
            sum += f64::from(img.get_pixel(xx, yy).0[0]) / 65535.0;
        }
    }
    sum / 169.0
}

/// Item 11. `sirds_view_angle.toml` is an eq. 1 SIRDS with separations of 101..151 px in a
/// 256 px image: beyond the third of the width the untold decoder searches, so it finds no
/// consistent repetition. Told by the scene, or by `--set` flags, it decodes over the model's
/// range: the sphere comes out near, the background far. Cross-eyed is read too: the same
/// image decoded as cross-eyed inverts the depth.
#[test]
fn the_decoder_told_the_model_by_scene_or_flags_decodes_an_eq1_sirds() {
    let dir = out_dir("sirds_told");
    let scene = asset("scenes/sirds_view_angle.toml");
    let (s, o) = (scene.to_str().unwrap(), dir.to_str().unwrap());
    let (ok, text) = run(&["render", s, "--out", o]);
    assert!(ok, "{text}");
    let sirds = dir.join("sirds.png");
    let sirds = sirds.to_str().unwrap();
    let (ok, text) = run(&[
        "sirds",
        "--decode",
        sirds,
        "--out",
        &format!("{o}/untold.png"),
    ]);
    assert!(text.contains("not an autostereogram"), "{ok} {text}");
    let told = [
        ("scene", vec![s]),
        (
            "flags",
            vec![
                "--set",
                "sirds.model=view-angle",
                "--set",
                "sirds.view_angle_deg=85",
            ],
        ),
    ];
    for (how, extra) in told {
        let depth = format!("{o}/depth_{how}.png");
        let mut args = vec!["sirds"];
        args.extend(&extra);
        args.extend(["--decode", sirds, "--out", &depth]);
        let (ok, text) = run(&args);
        assert!(ok && text.contains(": an autostereogram"), "{how}: {text}");
        assert!(
            text.contains("eq. 1") && text.contains("wall-eyed"),
            "{how}: {text}"
        );
        let (sphere, background) = (
            mean_depth(Path::new(&depth), 128, 64),
            mean_depth(Path::new(&depth), 128, 12),
        );
        assert!(
            sphere > 0.6 && background < 0.1,
            "{how}: {sphere} {background}"
        );
    }
    // Told cross-eyed, the same image reads inside out: the sphere far, the background near.
    let depth = format!("{o}/depth_cross.png");
    let (ok, text) = run(&[
        "sirds",
        s,
        "--set",
        "sirds.cross_eyed=true",
        "--decode",
        sirds,
        "--out",
        &depth,
    ]);
    assert!(ok && text.contains("cross-eyed"), "{text}");
    let (sphere, background) = (
        mean_depth(Path::new(&depth), 128, 64),
        mean_depth(Path::new(&depth), 128, 12),
    );
    assert!(sphere < 0.4 && background > 0.9, "{sphere} {background}");
}

/// Centroid x of the pixels of `img` that differ from `background`.
fn centroid_x(img: &image::RgbaImage, background: [u8; 4]) -> f64 {
    let (mut sx, mut n) = (0.0, 0.0);
    for (x, _, p) in img.enumerate_pixels() {
        if p.0 != background {
            sx += f64::from(x) + 0.5;
            n += 1.0;
        }
    }
    assert!(n > 50.0, "the sphere must be seen");
    sx / n
}

/// Item 13, parallel cameras: both eyes look straight ahead, so a point at distance z has the
/// screen disparity `d · (W / 2) / (z · tan(fov_x / 2))` — never zero at a finite distance,
/// always crossed (the left eye sees it right of the right eye's image). Measured on a small
/// sphere at two distances: within half a pixel of the formula.
#[test]
fn parallel_cameras_give_the_disparity_of_parallel_axes() {
    let (w, h) = (320u32, 240u32);
    let d = 0.5f64;
    for z in [4.0f64, 8.0] {
        let text = format!(
            "outputs = [\"left\", \"right\"]\n[image]\nwidth = {w}\nheight = {h}\n\
             background = [0.0, 0.0, 0.0]\n[camera]\neye = [0.0, 0.0, 0.0]\n\
             target = [0.0, 0.0, -1.0]\nfov_y = 40.0\nnear = 0.5\nfar = 50.0\n\
             [stereo]\nmode = \"parallel\"\neye_separation = {d}\n\
             [[mesh]]\nkind = \"sphere\"\nsize = 0.2\ndetail = 48\ntranslate = [0.0, 0.0, -{z}]\n"
        );
        let s = Scene::from_toml(&text, Path::new("p.toml"), Path::new("."), &[]).unwrap();
        let f = render(&s, &Plan::new(&s.outputs)).unwrap();
        let img = |o| match produce(o, &f, &s).unwrap() {
            Image::Rgba(i) => i,
            _ => panic!("rgba"),
        };
        let bg = [0, 0, 0, 255];
        let disparity = centroid_x(&img(Output::Left), bg) - centroid_x(&img(Output::Right), bg);
        let tan_x = (20f64.to_radians()).tan() * f64::from(w) / f64::from(h);
        let want = d * f64::from(w) / 2.0 / (z * tan_x);
        assert!(
            (disparity - want).abs() < 0.5,
            "z = {z}: measured {disparity:.3} px, parallel axes give {want:.3} px"
        );
    }
}

/// Item 13, guide dots: the only pixels they change are two discs centred on the image's
/// middle column, the background plane's separation apart, near the top.
#[test]
fn guide_dots_are_the_background_separation_apart_about_the_centre() {
    let mut s = sized_scene(SPHERE, 320, 96);
    s.sirds.guide_dots = false;
    let plain = from_frame(&frame(&s), &s).expect("sirds");
    s.sirds.guide_dots = true;
    let dotted = from_frame(&frame(&s), &s).expect("sirds");
    let (w, cx) = (320usize, 160.0f64);
    let (mut left, mut right) = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0));
    for (i, (a, b)) in plain.pixels.iter().zip(&dotted.pixels).enumerate() {
        if a != b {
            let (x, y) = ((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
            let side = if x < cx { &mut left } else { &mut right };
            *side = (side.0 + x, side.1 + y, side.2 + 1.0);
        }
    }
    assert!(
        left.2 > 10.0 && right.2 > 10.0,
        "two dots: {left:?} {right:?}"
    );
    let (lx, rx) = (left.0 / left.2, right.0 / right.2);
    let (ly, ry) = (left.1 / left.2, right.1 / right.2);
    let want = f64::from(dotted.disparity.max_separation());
    assert!((rx - lx - want).abs() < 0.5, "{lx} {rx}: want {want} apart");
    assert!(((lx + rx) / 2.0 - cx).abs() < 0.5, "centred: {lx} {rx}");
    assert!(
        ly < 12.0 && (ly - ry).abs() < 0.1,
        "near the top, level: {ly} {ry}"
    );
}

/// Item 13, cross-eyed: the decoded separation on the sphere is larger than on the
/// background (near points repeat later when the eyes cross), the reverse of wall-eyed, and
/// equals the separation of the inverted depth `1 − z`.
#[test]
fn a_cross_eyed_sirds_repeats_near_points_later() {
    for cross_eyed in [false, true] {
        let mut s = sized_scene(SPHERE, 320, 96);
        s.sirds.cross_eyed = cross_eyed;
        let f = frame(&s);
        let sirds = from_frame(&f, &s).expect("sirds");
        let (depth, _) = scene_depth(&f, &s).expect("depth");
        let d = sirds.disparity;
        let opts = SirdsDecodeOptions::for_disparity(&d);
        let decoded = decode_sirds(&sirds.pixels, 320, 96, &opts).expect("decodes");
        let at = |x: usize, y: usize| decoded.separation[y * 320 + x];
        let (sphere, background) = (at(160, 48), at(160, 8));
        if cross_eyed {
            assert!(
                sphere > background + 5.0,
                "cross-eyed: {sphere} vs {background}"
            );
        } else {
            assert!(
                sphere < background - 5.0,
                "wall-eyed: {sphere} vs {background}"
            );
        }
        let z = depth.z[48 * 320 + 160];
        let want = d.separation(if cross_eyed { 1.0 - z } else { z });
        assert!(
            (sphere - want).abs() <= 1.0,
            "{cross_eyed}: {sphere} want {want}"
        );
    }
}

/// Item 13, a pattern image: every pixel of the SIRDS is a pixel of the pattern (each of its
/// colors is unique), and it still decodes to the scene's separations.
#[test]
fn a_pattern_image_fills_the_sirds_and_it_decodes() {
    // Scrambled, so windows match only at the true shift; (R, G) unique per pattern pixel.
    let pattern = image::RgbaImage::from_fn(200, 50, |x, y| {
        image::Rgba([x as u8, ((y * 53 + x * x * 7) % 256) as u8, 77, 255])
    });
    let from_pattern: std::collections::HashSet<[u8; 4]> = pattern.pixels().map(|p| p.0).collect();
    for algorithm in ["per-pixel", "per-vertex"] {
        let mut s = sized_scene(
            &format!(
                "[sirds]\nalgorithm = \"{algorithm}\"\nfilter = \"nearest\"\nback = 7.0\n[[mesh]]\nkind = \"sphere\"\nsize = 1.2\ndetail = 32\n"
            ),
            320,
            96,
        );
        s.sirds.pattern = SirdsPattern::Image(Arc::new(pattern.clone()));
        let f = frame(&s);
        let sirds = from_frame(&f, &s).expect("sirds");
        let foreign = sirds
            .pixels
            .iter()
            .filter(|p| !from_pattern.contains(*p))
            .count();
        assert_eq!(foreign, 0, "{algorithm}: pixels not from the pattern");
        // More than a handful of distinct pattern pixels: the image, not one color.
        let mut distinct: Vec<[u8; 4]> = sirds.pixels.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(
            distinct.len() > 2000,
            "{algorithm}: {} colors",
            distinct.len()
        );
        let (depth, _) = scene_depth(&f, &s).expect("depth");
        let d = sirds.disparity;
        let intended: Vec<f32> = depth.z.iter().map(|&z| d.separation(z)).collect();
        let opts = SirdsDecodeOptions::for_disparity(&d);
        let decoded = decode_sirds(&sirds.pixels, 320, 96, &opts).expect("decodes");
        let rt = sirds_round_trip(&decoded, &intended, &opts);
        assert!(rt.within_one > 0.7, "{algorithm}: {rt:?}");
    }
}
