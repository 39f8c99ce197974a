//! The memory a render is estimated to need (`render --explain`, `--max-memory`) holds the
//! peak it reaches: the peak resident size the render reports of itself (`VmHWM`), on scenes
//! that stress each term of the estimate. The image terms are tight;
//! the geometry term is the measured worst case (every triangle keeping a set-up), so a
//! scene of many triangles that cover few pixels is overestimated, which the margin allows.

use std::path::Path;
use std::process::Command;

use crate::common::{asset, out_dir};

/// The estimate `render --explain` prints, in bytes (parsed from its MiB/GiB figure).
fn estimate(scene: &Path, args: &[&str]) -> u64 {
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .arg("render")
        .arg(scene)
        .args(args)
        .arg("--explain")
        .output()
        .expect("explain");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("memory: about "))
        .unwrap_or_else(|| panic!("no memory line in {text}"));
    bytes_of(line.split("about ").nth(1).expect("figure"))
}

/// A size as `human_bytes` writes it (`157 MiB`, `1.5 GiB`), in bytes.
fn bytes_of(figure: &str) -> u64 {
    let mut words = figure.split_whitespace();
    let value: f64 = words.next().expect("number").parse().expect("number");
    let scale = match words.next().expect("unit") {
        "GiB" => (1u64 << 30) as f64,
        "MiB" => (1u64 << 20) as f64,
        other => panic!("unit {other}"),
    };
    (value * scale) as u64
}

/// The peak resident memory `stereolab render` of `scene` with `args` reports of itself
/// (`VmHWM`: its own address space's, after `exec`; a parent's resource usage of the child
/// would count the test process's pages it was forked with).
#[cfg(target_os = "linux")]
fn peak(scene: &Path, args: &[&str], dir: &Path) -> u64 {
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .arg("render")
        .arg(scene)
        .args(args)
        .arg("--out")
        .arg(dir)
        .output()
        .expect("render");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let figure = text
        .lines()
        .find_map(|l| l.trim_start().strip_prefix("memory: peak "))
        .unwrap_or_else(|| panic!("no peak in {text}"));
    bytes_of(figure.split(" resident").next().expect("figure"))
}

#[cfg(target_os = "linux")]
#[test]
fn the_estimate_holds_the_measured_peak() {
    let sphere = out_dir("memory-scenes").join("sphere.toml");
    std::fs::write(
        &sphere,
        "outputs = [\"left\", \"right\"]\n[image]\nwidth = 64\nheight = 48\n[camera]\n\
         eye = [0, 0, 3]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[stereo]\n\
         eye_separation = 0.2\nzero_parallax = 5\n[[mesh]]\nkind = \"sphere\"\ndetail = 700\n",
    )
    .expect("scene");
    // Separate triangles, three vertices each: the per-vertex term.
    let soup = sphere.with_file_name("soup.toml");
    let mut obj = String::new();
    for i in 0..200_000u32 {
        let (x, y) = (
            f64::from(i % 450) / 225.0 - 1.0,
            f64::from(i / 450) / 225.0 - 1.0,
        );
        obj += &format!(
            "v {x} {y} 0\nv {} {y} 0\nv {x} {} 0\n",
            x + 0.004,
            y + 0.004
        );
    }
    for i in 0..200_000u32 {
        obj += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    std::fs::write(soup.with_file_name("soup.obj"), obj).expect("obj");
    std::fs::write(
        &soup,
        std::fs::read_to_string(&sphere).expect("scene").replace(
            "kind = \"sphere\"\ndetail = 700",
            "kind = \"obj\"\npath = \"soup.obj\"",
        ),
    )
    .expect("scene");
    // Slivers: 1024-corner stars ear-clipped, 1 024 vertices for 400 000 triangles.
    let star = sphere.with_file_name("star.toml");
    let mut obj = String::new();
    for k in 0..1024 {
        let (r, a) = (
            if k % 2 == 0 { 1.0 } else { 0.5 },
            std::f64::consts::TAU * f64::from(k) / 1024.0,
        );
        obj += &format!("v {} {} 0\n", r * a.cos(), r * a.sin());
    }
    let face: Vec<String> = (1..=1024).map(|i| i.to_string()).collect();
    obj += &format!("f {}\n", face.join(" ")).repeat(392);
    std::fs::write(star.with_file_name("star.obj"), obj).expect("obj");
    std::fs::write(
        &star,
        std::fs::read_to_string(&soup)
            .expect("scene")
            .replace("soup.obj", "star.obj"),
    )
    .expect("scene");
    let cases: [(&Path, &[&str]); 10] = [
        (&asset("scenes/anaglyph.toml"), &["--size", "2048x2048"]),
        (&asset("scenes/wuson.toml"), &["--size", "2048x1536"]),
        (&asset("scenes/sirds_fig5.toml"), &["--size", "2048x1024"]),
        (
            &asset("scenes/frame_sequential.toml"),
            &["--size", "1024x768"],
        ),
        (&sphere, &["--size", "2048x1536"]),
        (&soup, &["--size", "1024x768"]),
        (&star, &["--size", "1024x768"]),
        // The stars past the view: clipped into fans, each sliver across many bands.
        (&star, &["--size", "1024x768", "--set", "mesh.0.scale=4"]),
        // Both eyes quantised to one GIF palette, and nine views in a 3×3 grid of tiles.
        (&asset("scenes/wiggle.toml"), &["--size", "2048x1536"]),
        (
            &asset("scenes/multiview.toml"),
            &["--size", "1024x768", "--set", "multiview.views=9"],
        ),
    ];
    for (k, (scene, args)) in cases.into_iter().enumerate() {
        let dir = out_dir(&format!("memory-{k}"));
        let (est, got) = (estimate(scene, args), peak(scene, args, &dir));
        let name = scene.file_name().expect("name").to_string_lossy();
        eprintln!("{name} {args:?}: estimate {est} B, peak {got} B");
        assert!(est >= got, "{name}: estimate {est} below the peak {got}");
        // Not a wild overestimate either: within twice the peak and 64 MiB (the system allocator's
        // peaks are lower than mimalloc's, for which the estimate is made).
        assert!(
            est <= 2 * got + (64 << 20),
            "{name}: estimate {est} far above the peak {got}"
        );
    }
}

#[test]
fn a_render_over_the_budget_is_refused_before_it_starts() {
    let dir = out_dir("memory-refused");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .arg("render")
        .arg(asset("scenes/wuson.toml"))
        .args(["--size", "8192x8192", "--max-memory", "64M", "--out"])
        .arg(&dir)
        .output()
        .expect("render");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--max-memory = 64 MiB: this render needs about")
            && err.contains("raise --max-memory"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(&dir).expect("dir").count(), 0);
}

/// `compare` reads every image `render` writes: a `side_by_side.png` is twice an eye's width,
/// past the largest framebuffer side (16384) when the eye is at its widest.
#[test]
fn compare_reads_images_as_wide_as_the_widest_output() {
    let dir = out_dir("compare-widest");
    let width = 2 * stereolab_core::MAX_IMAGE_SIDE;
    let img = image::RgbaImage::from_fn(width, 16, |x, y| {
        image::Rgba([(x % 251) as u8, y as u8, 7, 255])
    });
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    img.save(&a).expect("a");
    img.save(&b).expect("b");
    let compare = || {
        let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .arg("compare")
            .arg(&a)
            .arg(&b)
            .output()
            .expect("compare");
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (ok, err) = compare();
    assert!(ok, "{err}");
    // One side past even that is still refused from the header.
    image::RgbaImage::new(width + 1, 1).save(&a).expect("a");
    let (ok, err) = compare();
    assert!(!ok && err.contains("32769x1"), "{err}");
}
