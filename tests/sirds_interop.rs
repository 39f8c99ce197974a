//! Autostereograms made by other tools (netpbm's `pamstereogram`) and
//! by stereolab with any set-up, decoded without being told the separations; noise stays
//! noise; an autostereogram back to a stereo pair.

use std::path::Path;
use std::process::Command;

use stereolab::output::sirds::{from_frame, scene_depth};
use stereolab_core::{
    AutoDecodedSirds, DisparityModel, PerPixelOptions, SeparationSearchOptions, SirdsAlgorithm,
    SirdsGeometry, SirdsPattern, decode_sirds_auto, per_pixel, sirds_round_trip, sirds_views,
};

use crate::common;
use crate::sirds::{SPHERE, frame, sized_scene};

/// A sphere depth map as netpbm's PGM (8-bit, white = near, as `pamstereogram` reads it):
/// `255 √(1 − r²)` inside a disc of radius 0.4 · height, 0 outside.
fn sphere_pgm(w: usize, h: usize) -> (Vec<u8>, Vec<f32>) {
    let mut depth = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let dx = (x as f32 + 0.5 - w as f32 / 2.0) / (h as f32 * 0.4);
            let dy = (y as f32 + 0.5 - h as f32 / 2.0) / (h as f32 * 0.4);
            let r2 = dx * dx + dy * dy;
            depth.push(if r2 < 1.0 { (1.0 - r2).sqrt() } else { 0.0 });
        }
    }
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend(depth.iter().map(|z| (z * 255.0).round() as u8));
    (pgm, depth)
}

/// Pearson's correlation of `a` and `b` over the pairs where `a` is finite.
fn correlation(a: &[f32], b: &[f32]) -> (f64, usize) {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(a, _)| a.is_finite())
        .map(|(&a, &b)| (a as f64, b as f64))
        .collect();
    let n = pairs.len() as f64;
    let (ma, mb) = (
        pairs.iter().map(|p| p.0).sum::<f64>() / n,
        pairs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (a, b) in &pairs {
        sab += (a - ma) * (b - mb);
        saa += (a - ma) * (a - ma);
        sbb += (b - mb) * (b - mb);
    }
    (sab / (saa * sbb).sqrt(), pairs.len())
}

fn rgba(img: image::DynamicImage) -> (Vec<[u8; 4]>, u32, u32) {
    let img = img.to_rgba8();
    let (w, h) = img.dimensions();
    (img.pixels().map(|p| p.0).collect(), w, h)
}

/// Runs netpbm's `pamstereogram` with `args` on `depth` ([`common::pamstereogram`]).
fn pamstereogram(depth: &Path, args: &[&str], out: &Path) {
    let mut all: Vec<&std::ffi::OsStr> = args.iter().map(std::ffi::OsStr::new).collect();
    all.push(depth.as_os_str());
    common::pamstereogram(&all, out);
}

/// A foreign stereogram decoded untold. `pamstereogram` (netpbm 10.x, its
/// defaults: 2.56 in eyes at 100 DPI, wall-eyed, depth of field 1/3) puts the far plane at
/// 128 px and the nearest point at 102 px ("Near pattern width: 102" with `-verbose`); the
/// decoder is told none of it. Measured here: found 102..=128 px in both, 80% (b/w) and 73%
/// (color) of the pixels matched; the decoded separation correlates with the depth map at
/// r = −0.995 (b/w) and −1.000 (color) over all matched pixels, −0.96 and −1.00 over the
/// sphere's disc alone (near, white, repeats sooner). Asserted: r < −0.9 overall, < −0.8 on
/// the disc.
#[test]
fn pamstereogram_outputs_decode_with_the_sphere_visible() {
    let dir = common::out_dir("sirds_interop_pam");
    let (w, h) = (600, 300);
    let (pgm, depth) = sphere_pgm(w, h);
    let map = dir.join("sphere.pgm");
    std::fs::write(&map, pgm).expect("write map");
    let mut report = String::new();
    for (name, args) in [("bw", &[][..]), ("color", &["-color"][..])] {
        let path = dir.join(format!("{name}.pam"));
        pamstereogram(&map, args, &path);
        let (pixels, iw, ih) = rgba(image::open(&path).expect("the image crate reads PAM"));
        assert_eq!((iw, ih), (w as u32, h as u32));
        let auto = decode_sirds_auto(&pixels, iw, ih, &SeparationSearchOptions::default())
            .expect("decodes");
        let (lo, hi) = auto.search.found.expect("a range found");
        let decoded = auto.decoded.as_ref().expect("decoded");
        let (r, n) = correlation(&decoded.separation, &depth);
        // The sphere itself: the decoded separations on the disc against its depth.
        let on_disc: Vec<f32> = decoded
            .separation
            .iter()
            .zip(&depth)
            .map(|(&s, &z)| if z > 0.0 { s } else { f32::NAN })
            .collect();
        let (r_disc, n_disc) = correlation(&on_disc, &depth);
        report += &format!(
            "{name}: found {lo}..={hi} px, matched {:.1}%, correlation {r:.3} over {n} px, \
             {r_disc:.3} over {n_disc} px of the disc\n",
            auto.matched_share() * 100.0
        );
        assert!(auto.is_autostereogram(), "{report}");
        assert!(
            (98..=106).contains(&lo) && (125..=131).contains(&hi),
            "{report}"
        );
        assert!(r < -0.9 && r_disc < -0.8, "{report}");
        // A quarter of the disc's π·120² ≈ 45 000 pixels (the rest: windows across its 27
        // depth steps; measured 55% b/w, 32% color).
        assert!(n_disc > 11_300, "the disc must decode: {report}");
    }
    eprintln!("{report}");
}

/// What the decoder found on `pixels`, against the separations intended per pixel.
fn check_own(
    label: &str,
    pixels: &[[u8; 4]],
    w: u32,
    h: u32,
    intended: &[f32],
    floor: f64,
) -> String {
    let auto: AutoDecodedSirds =
        decode_sirds_auto(pixels, w, h, &SeparationSearchOptions::default()).expect("decodes");
    let (lo, hi) = auto.search.found.expect("a range found");
    let rt = sirds_round_trip(
        auto.decoded.as_ref().expect("decoded"),
        intended,
        &auto.options.expect("options"),
    );
    let (want_lo, want_hi) = intended
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &s| {
            (a.min(s), b.max(s))
        });
    let line = format!(
        "{label:40} intended {want_lo:.1}..{want_hi:.1} px, found {lo}..={hi} px, within ±1 px {:.1}%, matched {:.1}%\n",
        rt.within_one * 100.0,
        auto.matched_share() * 100.0
    );
    assert!(auto.is_autostereogram(), "{line}");
    assert!(
        lo as f32 <= want_lo + 3.0 && hi as f32 >= want_hi - 3.0,
        "the range found must cover the intended one: {line}"
    );
    // ... and not run far past it (a harmonic at twice the separation would; the loosest
    // measured: 55 px for 72 px, cross-eyed per-vertex eq. 3, a few chance matches).
    assert!(
        lo as f32 >= 0.7 * want_lo && hi as f32 <= 1.1 * want_hi + 3.0,
        "the range found must not reach far past the intended one: {line}"
    );
    assert!(rt.within_one >= floor, "{line}");
    line
}

/// stereolab's own, eq. 1 and eq. 3, wall-eyed and cross-eyed, both algorithms: decoded with
/// no settings at all. The floor is `tests/sirds.rs`'s for the sphere when the range is known
/// (0.78); measured here 83.6–95.0% within ±1 px.
#[test]
fn own_sirds_decode_without_being_told_the_setup() {
    let mut report = String::new();
    for model in [DisparityModel::EyeDistance, DisparityModel::ViewAngle] {
        for cross_eyed in [false, true] {
            for algorithm in [SirdsAlgorithm::PerVertex, SirdsAlgorithm::PerPixel] {
                let mut s = sized_scene(SPHERE, 320, 96);
                s.sirds.geometry.model = model;
                s.sirds.cross_eyed = cross_eyed;
                s.sirds.algorithm = algorithm;
                let f = frame(&s);
                let sirds = from_frame(&f, &s).expect("sirds");
                let (depth, _) = scene_depth(&f, &s).expect("depth");
                let d = sirds.disparity;
                let intended: Vec<f32> = depth
                    .z
                    .iter()
                    .map(|&z| d.separation(if cross_eyed { 1.0 - z } else { z }))
                    .collect();
                let label = format!("{model:?} cross-eyed={cross_eyed} {algorithm:?}");
                report += &check_own(
                    &label,
                    &sirds.pixels,
                    sirds.width,
                    sirds.height,
                    &intended,
                    0.78,
                );
            }
        }
    }
    // A wide image: searched in 13 of its 17 strips of 7 rows (the work budget).
    let map = stereolab::fixtures::sphere_over_ramp(2100, 120);
    let d = SirdsGeometry {
        dpi: 144.0,
        ..SirdsGeometry::default()
    }
    .to_pixels()
    .expect("valid");
    let pixels = per_pixel(
        &map,
        &d,
        &SirdsPattern::Color { seed: 5 },
        &PerPixelOptions::default(),
    )
    .expect("sirds");
    let intended: Vec<f32> = map.z.iter().map(|&z| d.separation(z)).collect();
    report += &check_own(
        "per-pixel 2100x120 at 144 DPI",
        &pixels,
        2100,
        120,
        &intended,
        0.78,
    );
    eprintln!("{report}");
}

/// Noise searched over the whole plausible range (about 100 to 700 separations) is still
/// noise: no region repeats, or too little to call it an autostereogram.
#[test]
fn noise_over_the_full_range_is_still_noise() {
    for (w, h) in [(320, 64), (2100, 96)] {
        for noise in [
            SirdsPattern::BlackWhite { seed: 21 },
            SirdsPattern::Gray { seed: 22 },
            SirdsPattern::Color { seed: 23 },
        ] {
            let pixels = noise.fill(w, h);
            let auto = decode_sirds_auto(&pixels, w, h, &SeparationSearchOptions::default())
                .expect("runs");
            assert!(
                !auto.is_autostereogram() && auto.search.matched_share < 0.05,
                "{w}x{h} {noise:?}: matched {:.2}% of cells, {} regions, found {:?}",
                auto.search.matched_share * 100.0,
                auto.search.regions.len(),
                auto.search.found
            );
        }
    }
}

/// The two views of a decoded SIRDS: block matching between them finds the sphere in front
/// of the background by about its separation difference (crossed parallax), the background on
/// the screen.
#[test]
fn autostereogram_to_stereo_pair_puts_the_sphere_in_front() {
    for cross_eyed in [false, true] {
        let mut s = sized_scene(SPHERE, 320, 96);
        s.sirds.cross_eyed = cross_eyed;
        s.sirds.algorithm = SirdsAlgorithm::PerPixel;
        let f = frame(&s);
        let sirds = from_frame(&f, &s).expect("sirds");
        let (depth, _) = scene_depth(&f, &s).expect("depth");
        let auto = decode_sirds_auto(
            &sirds.pixels,
            sirds.width,
            sirds.height,
            &SeparationSearchOptions::default(),
        )
        .expect("decodes");
        let v =
            sirds_views(&sirds.pixels, auto.decoded.as_ref().unwrap(), cross_eyed).expect("views");
        let w = sirds.width as usize;
        // Horizontal shift of right against left that matches best at (x, y): a 9×9 SAD.
        let parallax = |x: usize, y: usize| -> i32 {
            (-30i32..=30)
                .min_by_key(|&p| {
                    let mut sad = 0u32;
                    for dy in 0..9 {
                        for dx in 0..9 {
                            let (yy, xl) = (y + dy - 4, x + dx - 4);
                            let xr = (xl as i32 + p) as usize;
                            for c in 0..3 {
                                sad +=
                                    v.left[yy * w + xl][c].abs_diff(v.right[yy * w + xr][c]) as u32;
                            }
                        }
                    }
                    sad
                })
                .unwrap()
        };
        let d = sirds.disparity;
        let z_center = depth.at(160, 48);
        let want = -(d.separation(0.0) - d.separation(z_center)).abs();
        let (center, background) = (parallax(160, 48), parallax(290, 20));
        assert!(
            (center as f32 - want).abs() <= 2.0 && background.abs() <= 1,
            "cross-eyed {cross_eyed}: parallax at the sphere {center} px (want {want:.1}), background {background} px"
        );
    }
}

/// A PFM file: `Pf` (one channel) or `PF` (three), rows given top first and written bottom
/// first, as the format stores them.
fn pfm(channels: usize, w: usize, rows_top_first: &[Vec<f32>], little: bool) -> Vec<u8> {
    let magic = if channels == 1 { "Pf" } else { "PF" };
    let scale = if little { "-1.0" } else { "1.0" };
    let mut bytes = format!("{magic}\n{w} {}\n{scale}\n", rows_top_first.len()).into_bytes();
    for row in rows_top_first.iter().rev() {
        for v in row {
            bytes.extend(if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
    }
    bytes
}

/// Every format maps as docs/interop.md says, both ways round.
#[test]
fn depth_maps_from_any_format_map_as_documented() {
    use stereolab_core::{DepthSamples, Near};
    let dir = common::out_dir("sirds_interop_depth");
    let z =
        |d: &DepthSamples| -> Vec<f32> { d.samples.iter().map(|&v| v as f32 / 65535.0).collect() };
    let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4);
    // Integers: full scale. 0, 51, 255 of 8 bits; 0, 13107, 65535 of 16 bits (0, 0.2, 1).
    let want = [0.0, 0.2, 1.0];
    let png8 = dir.join("d8.png");
    image::GrayImage::from_raw(3, 1, vec![0, 51, 255])
        .unwrap()
        .save(&png8)
        .unwrap();
    let png16 = dir.join("d16.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(3, 1, vec![0u16, 13107, 65535])
        .unwrap()
        .save(&png16)
        .unwrap();
    let pgm = dir.join("d.pgm");
    std::fs::write(&pgm, b"P5\n3 1\n255\n\x00\x33\xff").unwrap();
    let pgm16 = dir.join("d16.pgm");
    std::fs::write(&pgm16, b"P5\n3 1\n65535\n\x00\x00\x33\x33\xff\xff").unwrap();
    let pam = dir.join("d.pam");
    std::fs::write(
        &pam,
        b"P7\nWIDTH 3\nHEIGHT 1\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n\x00\x33\xff",
    )
    .unwrap();
    for path in [&png8, &png16, &pgm, &pgm16, &pam] {
        let white = DepthSamples::load(path, Near::White).expect("reads");
        assert!(
            close(&z(&white), &want),
            "{}: {:?}",
            path.display(),
            z(&white)
        );
        assert!(white.mapping.full_scale);
        let black = DepthSamples::load(path, Near::Black).expect("reads");
        let flipped: Vec<f32> = want.iter().map(|v| 1.0 - v).collect();
        assert!(
            close(&z(&black), &flipped),
            "{}: {:?}",
            path.display(),
            z(&black)
        );
    }
    // PFM: the file's own range (2..10), rows stored bottom first, either byte order, the
    // color one by its luma; infinity is background.
    let rows = vec![vec![2.0, 4.0], vec![10.0, f32::INFINITY]];
    for little in [true, false] {
        let path = dir.join(format!("d-{little}.pfm"));
        std::fs::write(&path, pfm(1, 2, &rows, little)).unwrap();
        let white = DepthSamples::load(&path, Near::White).expect("reads");
        assert!(close(&z(&white), &[0.0, 0.25, 1.0, 0.0]), "{:?}", z(&white));
        assert_eq!(white.mapping.non_finite, 1);
        assert!(!white.mapping.full_scale && white.mapping.found == (2.0, 10.0));
        let black = DepthSamples::load(&path, Near::Black).expect("reads");
        assert!(close(&z(&black), &[1.0, 0.75, 0.0, 0.0]), "{:?}", z(&black));
    }
    let color: Vec<Vec<f32>> = vec![vec![1.0, 1.0, 1.0, 0.0, 0.0, 0.0]];
    let path = dir.join("c.pfm");
    std::fs::write(&path, pfm(3, 2, &color, true)).unwrap();
    let c = DepthSamples::load(&path, Near::White).expect("reads");
    assert!(close(&z(&c), &[1.0, 0.0]), "{:?}", z(&c));
    // Broken files: clear errors naming the file, nothing allocated for a huge claim.
    let mut truncated = pfm(1, 2, &rows, true);
    truncated.truncate(truncated.len() - 3);
    let huge = b"Pf\n100000 100000\n-1.0\n".to_vec();
    let cases: [(&str, Vec<u8>, &str); 5] = [
        ("cut.pfm", truncated, "PFM body"),
        ("huge.pfm", huge, "at most"),
        (
            "scale.pfm",
            b"Pf\n2 1\n0\n\0\0\0\0\0\0\0\0".to_vec(),
            "scale",
        ),
        ("width.pfm", b"Pf\nx 1\n-1\n".to_vec(), "width"),
        (
            "garbage.png",
            b"not an image at all".to_vec(),
            "garbage.png",
        ),
    ];
    for (name, bytes, want) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let err = DepthSamples::load(&path, Near::White)
            .expect_err(name)
            .to_string();
        assert!(err.contains(name) && err.contains(want), "{name}: {err}");
    }
    // The command prints the mapping it used.
    let map = dir.join("sphere.pfm");
    let rows: Vec<Vec<f32>> = (0..64)
        .map(|y| {
            (0..256)
                .map(|x| {
                    let (dx, dy) = (x as f32 - 128.0, y as f32 - 32.0);
                    // A distance map: 3 m at the sphere's front, 5 m behind.
                    if dx * dx + dy * dy < 400.0 { 3.0 } else { 5.0 }
                })
                .collect()
        })
        .collect();
    std::fs::write(&map, pfm(1, 256, &rows, true)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["sirds", "--depth"])
        .arg(&map)
        .args(["--near", "black", "-o"])
        .arg(dir.join("sirds.png"))
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("PFM") && text.contains("5 → background") && text.contains("3 → front"),
        "{text}"
    );
}

/// `sirds --decode X --pair DIR` through the command line, on a pamstereogram.
#[test]
fn cli_decodes_a_foreign_stereogram_into_a_pair() {
    let dir = common::out_dir("sirds_interop_cli");
    let (pgm, _) = sphere_pgm(400, 160);
    let map = dir.join("sphere.pgm");
    std::fs::write(&map, pgm).unwrap();
    let sirds = dir.join("pam.pam");
    pamstereogram(&map, &[], &sirds);
    let pair = dir.join("pair");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["sirds", "--decode"])
        .arg(&sirds)
        .arg("-o")
        .arg(dir.join("depth.png"))
        .arg("--pair")
        .arg(&pair)
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("found 10") && text.contains(": an autostereogram"),
        "{text}"
    );
    for name in ["left.png", "right.png", "anaglyph.png"] {
        let img = image::open(pair.join(name)).expect(name);
        assert_eq!((img.width(), img.height()), (400, 160), "{name}");
    }
    // Noise is refused with a clear word, and nothing is written.
    let noise = dir.join("noise.png");
    let pixels = SirdsPattern::BlackWhite { seed: 3 }.fill(400, 160);
    image::RgbaImage::from_raw(400, 160, pixels.into_iter().flatten().collect())
        .unwrap()
        .save(&noise)
        .unwrap();
    let depth = dir.join("noise-depth.png");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["sirds", "--decode"])
        .arg(&noise)
        .arg("-o")
        .arg(&depth)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not an autostereogram"),
        "{err}"
    );
    assert!(!depth.exists());
}

/// stereolab's own `left_depth.png` (window depth: black near) carries a PNG text chunk that
/// ExifTool reads and `sirds --depth` follows: the SIRDS is the one `--near black` makes,
/// not the inverted one `--near white` makes.
#[test]
fn stereolabs_window_depth_is_read_the_right_way_round() {
    let dir = common::out_dir("sirds_window_depth");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .args(args)
            .output()
            .expect("runs");
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let scene = common::asset("scenes/wuson.toml");
    let d = dir.to_string_lossy().into_owned();
    run(&[
        "render",
        &scene.to_string_lossy(),
        "--size",
        "320x240",
        "--set",
        "outputs=[\"left_depth\"]",
        "--out",
        &d,
    ]);
    let depth = dir.join("left_depth.png");
    let exif = Command::new("exiftool")
        .args(["-s", "-PNG:all"])
        .arg(&depth)
        .output()
        .expect("exiftool (libimage-exiftool-perl) runs");
    let tags = String::from_utf8_lossy(&exif.stdout);
    assert!(
        tags.contains("StereolabWindowDepth") && tags.contains("0 = near plane (black)"),
        "{tags}"
    );
    let depth = depth.to_string_lossy().into_owned();
    let sirds = |name: &str, near: Option<&str>| {
        let out = dir.join(name).to_string_lossy().into_owned();
        let mut args = vec!["sirds", "--depth", &depth, "-o", &out];
        if let Some(n) = near {
            args.extend(["--near", n]);
        }
        let report = run(&args);
        (std::fs::read(&out).expect("sirds"), report)
    };
    let (found, report) = sirds("found.png", None);
    assert!(
        report.contains("stereolab's window depth (black near)"),
        "{report}"
    );
    assert_eq!(found, sirds("black.png", Some("black")).0);
    assert_ne!(found, sirds("white.png", Some("white")).0);
}
