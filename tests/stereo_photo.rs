//! The `mpo`, `jps` and `pns` outputs, read back by an independent reader
//! (ExifTool, Debian's `libimage-exiftool-perl`) and by `stereolab compare`.

use std::path::{Path, PathBuf};
use std::process::Command;

use image::RgbaImage;
use stereolab::compare::compare_stereo_photos;
use stereolab::output::stereo_photo::read_stereo;
use stereolab::output::write_all;
use stereolab::plan::Plan;
use stereolab::render::render;
use stereolab::scene::Scene;

use crate::common;

/// A toe-in rig (so the MPO's convergence angle is not 0) looking at a turned cube: the two
/// views differ clearly, so a swapped order shows.
const SCENE: &str = r#"
outputs = ["left", "right", "mpo", "jps", "pns"]
[image]
width = 96
height = 64
background = [0.1, 0.2, 0.3]
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov_y = 40.0
near = 1.0
far = 20.0
[stereo]
mode = "toe-in"
eye_separation = 1.2
zero_parallax = 5.0
[[mesh]]
kind = "cube"
size = 2.4
rotate = [25.0, 35.0, 0.0]
color = [0.9, 0.6, 0.2]
"#;

/// `2 atan((d/2)/z0)` for d = 1.2, z0 = 5, in degrees.
const CONVERGENCE_DEG: f64 = 13.685_547;

fn render_outputs(dir: &Path) -> Vec<PathBuf> {
    let scene =
        Scene::from_toml(SCENE, Path::new("photo.toml"), Path::new("."), &[]).expect("valid scene");
    let frame = render(&scene, &Plan::new(&scene.outputs)).expect("renders");
    write_all(&frame, &scene, dir).expect("writes")
}

fn exiftool(args: &[&str]) -> Vec<u8> {
    let out = Command::new("exiftool")
        .args(args)
        .output()
        .unwrap_or_else(|e| {
            panic!("exiftool could not run ({e}): install Debian's libimage-exiftool-perl (.ci/run does)")
        });
    assert!(
        out.status.success(),
        "exiftool {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Mean absolute difference per channel (RGB) of two same-sized images.
fn mean_diff(a: &RgbaImage, b: &RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: u64 = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| (0..3).map(|c| u64::from(p[c].abs_diff(q[c]))).sum::<u64>())
        .sum();
    sum as f64 / (3 * a.width() * a.height()) as f64
}

fn png(path: &Path) -> RgbaImage {
    image::open(path).expect("readable").to_rgba8()
}

/// Checks that `got` is the `want` eye (a JPEG's small error) and clearly not the other.
fn is_eye(label: &str, got: &RgbaImage, want: &RgbaImage, other: &RgbaImage) {
    let (same, swapped) = (mean_diff(got, want), mean_diff(got, other));
    assert!(
        same < 2.0 && swapped > 3.0 * same.max(0.5),
        "{label}: {same:.2} from the eye it should be, {swapped:.2} from the other"
    );
}

#[test]
fn mpo_reads_back_in_exiftool_with_both_images_and_the_tags() {
    let dir = common::out_dir("stereo_photo_mpo");
    let paths = render_outputs(&dir);
    let names: Vec<String> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        ["left.png", "right.png", "mpo.mpo", "jps.jps", "pns.pns"]
    );
    let (left, right) = (png(&dir.join("left.png")), png(&dir.join("right.png")));
    let mpo = dir.join("mpo.mpo");
    let mpo_s = mpo.to_str().unwrap();

    // The tags, numerically, with their groups: the MP index and the first image's attributes
    // (MPF0), each image's entry (MPImage1, MPImage2).
    let json: serde_json::Value =
        serde_json::from_slice(&exiftool(&["-j", "-n", "-G1", "-a", mpo_s])).expect("json");
    let tags = &json[0];
    let text = serde_json::to_string_pretty(tags).unwrap();
    assert_eq!(tags["MPF0:MPFVersion"], "0100", "{text}");
    assert_eq!(tags["MPF0:NumberOfImages"], 2, "{text}");
    assert_eq!(tags["MPF0:MPIndividualNum"], 1, "{text}");
    assert_eq!(tags["MPF0:BaseViewpointNum"], 1, "{text}");
    let convergence = tags["MPF0:ConvergenceAngle"]
        .as_f64()
        .expect("ConvergenceAngle");
    assert!((convergence - CONVERGENCE_DEG).abs() < 1e-3, "{text}");
    let baseline = tags["MPF0:BaselineLength"]
        .as_f64()
        .expect("BaselineLength");
    assert!((baseline - 1.2).abs() < 1e-4, "{text}");
    for (i, flags) in [(1, 4), (2, 0)] {
        // 0x020002: "Multi-frame Disparity"; flags bit 2 (of the top 5): representative image.
        assert_eq!(tags[format!("MPImage{i}:MPImageType")], 0x020002, "{text}");
        assert_eq!(tags[format!("MPImage{i}:MPImageFormat")], 0, "{text}");
        assert_eq!(tags[format!("MPImage{i}:MPImageFlags")], flags, "{text}");
    }
    let len2 = tags["MPImage2:MPImageLength"].as_u64().expect("length");
    let file_len = std::fs::metadata(&mpo).unwrap().len();
    let start2 = tags["MPImage2:MPImageStart"].as_u64().expect("start");
    // ExifTool reports the start from the file's beginning: the second image ends the file.
    assert_eq!(start2 + len2, file_len, "{text}");

    // Both images: the first is the file's own JPEG, the second extracted by ExifTool.
    let first = image::load_from_memory_with_format(
        &std::fs::read(&mpo).unwrap(),
        image::ImageFormat::Jpeg,
    )
    .expect("first image")
    .to_rgba8();
    let second_bytes = exiftool(&["-b", "-MPImage2", mpo_s]);
    assert_eq!(second_bytes.len() as u64, len2);
    let second = image::load_from_memory_with_format(&second_bytes, image::ImageFormat::Jpeg)
        .expect("second image")
        .to_rgba8();
    is_eye("MPO image 1", &first, &left, &right);
    is_eye("MPO image 2", &second, &right, &left);
    // Each image's own MP Attribute IFD (ExifTool reads the embedded image with -ee): left 1,
    // right 2.
    let text = String::from_utf8(exiftool(&[
        "-a",
        "-ee",
        "-s",
        "-n",
        "-MPIndividualNum",
        mpo_s,
    ]))
    .expect("text");
    let numbers: Vec<&str> = text
        .lines()
        .map(|l| l.rsplit(':').next().unwrap().trim())
        .collect();
    assert_eq!(numbers, ["1", "2"], "{text}");
}

#[test]
fn jps_and_pns_put_the_right_eye_on_the_left() {
    let dir = common::out_dir("stereo_photo_sbs");
    render_outputs(&dir);
    let (left, right) = (png(&dir.join("left.png")), png(&dir.join("right.png")));
    let (w, h) = left.dimensions();
    let halves = |img: &RgbaImage| {
        (
            image::imageops::crop_imm(img, 0, 0, w, h).to_image(),
            image::imageops::crop_imm(img, w, 0, w, h).to_image(),
        )
    };
    // PNS: lossless, so exactly right | left.
    let pns = image::load_from_memory_with_format(
        &std::fs::read(dir.join("pns.pns")).unwrap(),
        image::ImageFormat::Png,
    )
    .expect("pns is a PNG")
    .to_rgba8();
    assert_eq!(pns.dimensions(), (2 * w, h));
    let (a, b) = halves(&pns);
    assert!(a == right && b == left, "PNS must be right | left");
    // JPS: a JPEG, right | left, and its descriptor says so to ExifTool.
    let jps = dir.join("jps.jps");
    let img = image::load_from_memory_with_format(
        &std::fs::read(&jps).unwrap(),
        image::ImageFormat::Jpeg,
    )
    .expect("jps is a JPEG")
    .to_rgba8();
    let (a, b) = halves(&img);
    is_eye("JPS left half", &a, &right, &left);
    is_eye("JPS right half", &b, &left, &right);
    let json: serde_json::Value =
        serde_json::from_slice(&exiftool(&["-j", "-G1", jps.to_str().unwrap()])).expect("json");
    let tags = &json[0];
    let text = serde_json::to_string_pretty(tags).unwrap();
    assert_eq!(tags["JPS:JPSType"], "Stereo", "{text}");
    assert_eq!(tags["JPS:JPSLayout"], "Side By Side", "{text}");
    // No "Left field first" flag: the right field comes first.
    assert!(
        !tags["JPS:JPSFlags"]
            .to_string()
            .contains("Left field first"),
        "{text}"
    );
}

#[test]
fn compare_reads_the_stereo_photos_eye_by_eye() {
    let dir = common::out_dir("stereo_photo_compare");
    render_outputs(&dir);
    let (left, right) = (png(&dir.join("left.png")), png(&dir.join("right.png")));
    for name in ["mpo.mpo", "jps.jps", "pns.pns"] {
        let (l, r) = read_stereo(&dir.join(name)).expect("reads");
        is_eye(&format!("{name} left"), &l, &left, &right);
        is_eye(&format!("{name} right"), &r, &right, &left);
    }
    // PNS against itself: identical; MPO against PNS: only the JPEG's error, in both eyes.
    let rows = compare_stereo_photos(&dir.join("pns.pns"), &dir.join("pns.pns"), None, None)
        .expect("compares");
    assert_eq!(rows.len(), 2);
    assert!(rows.iter().all(|r| r.metrics.max_channel_diff == 0));
    let rows = compare_stereo_photos(&dir.join("pns.pns"), &dir.join("mpo.mpo"), None, None)
        .expect("compares");
    let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
    assert_eq!(names, ["mpo-left", "mpo-right"]);
    assert!(rows.iter().all(|r| r.metrics.psnr > 30.0), "{rows:?}");
    // Through the command line, too.
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["compare"])
        .arg(dir.join("pns.pns"))
        .arg(dir.join("jps.jps"))
        .output()
        .expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("jps-left") && text.contains("jps-right"),
        "{text}"
    );
    // A truncated MPO is a clear error, not a panic.
    let bytes = std::fs::read(dir.join("mpo.mpo")).unwrap();
    let cut = dir.join("cut.mpo");
    std::fs::write(&cut, &bytes[..bytes.len() - 100]).unwrap();
    let err = read_stereo(&cut).expect_err("truncated").to_string();
    assert!(err.contains("cut.mpo") && err.contains("image 2"), "{err}");
}
