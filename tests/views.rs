//! Wiggle animations and N-view rendering: the wiggle files as an independent reader (Pillow)
//! decodes them, the N cameras against the parallax formula, the two-view case against the
//! stereo pair byte for byte, the layouts against an independent layout, and the refusals.

use std::process::Command;

use stereolab::memory::estimate;
use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan, View};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;

use crate::common::{asset, out_dir};

fn shipped(name: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::load(&asset(&format!("scenes/{name}.toml")), &sets)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn load_error(name: &str, sets: &[&str]) -> String {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    match Scene::load(&asset(&format!("scenes/{name}.toml")), &sets) {
        Ok(_) => panic!("{name} with {sets:?} should be refused"),
        Err(e) => e.to_string(),
    }
}

fn rgba(img: Image) -> image::RgbaImage {
    match img {
        Image::Rgba(i) => i,
        _ => panic!("expected an RGBA image"),
    }
}

/// Decodes a GIF and an APNG with Pillow and prints, per frame, its duration and its largest
/// and mean channel difference from the PNG of the view it should show, and the loop counts.
const PILLOW_CHECK: &str = r#"
import json, sys
import numpy as np
from PIL import Image
gif_path, apng_path, left_path, right_path, first = sys.argv[1:6]
views = {"left": np.asarray(Image.open(left_path).convert("RGBA"), dtype=np.int16),
         "right": np.asarray(Image.open(right_path).convert("RGBA"), dtype=np.int16)}
order = [first, "right" if first == "left" else "left"]
out = {}
for kind, path in (("gif", gif_path), ("apng", apng_path)):
    im = Image.open(path)
    frames = []
    for i in range(im.n_frames):
        im.seek(i)
        want = views[order[i % 2]]
        if kind == "gif":
            got = np.asarray(im.convert("RGB"), dtype=np.int16)
            diff = np.abs(got - want[:, :, :3])
        else:
            got = np.asarray(im.convert("RGBA"), dtype=np.int16)
            diff = np.abs(got - want)
        frames.append({"duration": float(im.info.get("duration", -1)),
                       "max": int(diff.max()), "mean": float(diff.mean())})
    if kind == "gif":
        im.seek(0)
        a = np.asarray(im.convert("RGB"), dtype=np.int16)
        im.seek(1)
        b = np.asarray(im.convert("RGB"), dtype=np.int16)
        same = np.all(views["left"][:, :, :3] == views["right"][:, :, :3], axis=2)
        out["gif_same_pixels"] = int(same.sum())
        out["gif_same_pixels_changed"] = int(np.any(a != b, axis=2)[same].sum())
    out[kind] = {"format": im.format, "frames": frames, "loop": im.info.get("loop")}
print(json.dumps(out))
"#;

fn pillow(args: &[&std::path::Path], first: &str) -> serde_json::Value {
    let out = Command::new("python3")
        .arg("-c")
        .arg(PILLOW_CHECK)
        .args(args)
        .arg(first)
        .output()
        .expect("python3 runs (this test needs python3 with Pillow and numpy)");
    assert!(
        out.status.success(),
        "Pillow's check failed (needs `pip install pillow numpy`): {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON from the check")
}

/// The largest channel difference a GIF frame of the shipped wiggle scene may have from its
/// view, and the mean over all pixels and channels: NeuQuant's 256 colours for both views
/// (measured: 9 and 0.18).
const GIF_MAX_ERROR: i64 = 12;
const GIF_MEAN_ERROR: f64 = 0.5;

#[test]
fn wiggle_files_alternate_the_eyes_as_pillow_reads_them() {
    for (sets, first, ms) in [
        (&[][..], "left", 120.0),
        (
            &["wiggle.frame_ms=70", "wiggle.start=\"right\""][..],
            "right",
            70.0,
        ),
    ] {
        let scene = shipped("wiggle", sets);
        let frame = render(&scene, &Plan::new(&scene.outputs)).unwrap();
        let dir = out_dir(&format!("wiggle_{first}"));
        let paths = stereolab::output::write_all(&frame, &scene, &dir).unwrap();
        assert_eq!(
            paths,
            vec![dir.join("wiggle_gif.gif"), dir.join("wiggle_apng.png")]
        );
        let (left, right) = (dir.join("left.png"), dir.join("right.png"));
        produce(Output::Left, &frame, &scene)
            .unwrap()
            .save_png(&left)
            .unwrap();
        produce(Output::Right, &frame, &scene)
            .unwrap()
            .save_png(&right)
            .unwrap();
        let v = pillow(&[&paths[0], &paths[1], &left, &right], first);
        eprintln!("{first}: {v}");
        assert_eq!(v["gif"]["format"], "GIF");
        assert_eq!(v["apng"]["format"], "PNG");
        for kind in ["gif", "apng"] {
            let frames = v[kind]["frames"].as_array().unwrap();
            assert_eq!(frames.len(), 2, "{kind}: one frame per view");
            // Pillow reports both formats' loop count 0: forever.
            assert_eq!(v[kind]["loop"], 0, "{kind}");
            for (i, f) in frames.iter().enumerate() {
                assert_eq!(f["duration"].as_f64().unwrap(), ms, "{kind} frame {i}");
                if kind == "apng" {
                    assert_eq!(f["max"], 0, "APNG frame {i} is its view exactly");
                } else {
                    let (max, mean) = (f["max"].as_i64().unwrap(), f["mean"].as_f64().unwrap());
                    assert!(
                        max <= GIF_MAX_ERROR && mean <= GIF_MEAN_ERROR,
                        "GIF frame {i}: max {max}, mean {mean}"
                    );
                }
            }
        }
        // One palette for both frames: a pixel both views share is the same colour in both.
        assert!(v["gif_same_pixels"].as_i64().unwrap() > 10_000);
        assert_eq!(v["gif_same_pixels_changed"], 0);
    }
}

/// The N views of a scene with `sets`, and the frame that rendered them beside the pair.
fn views_and_pair(sets: &[&str]) -> (Scene, Frame) {
    let scene = shipped("multiview", sets);
    let n = scene.views;
    let plan = Plan::new(&[Output::ViewTiles(n), Output::Left, Output::Right]);
    (scene.clone(), render(&scene, &plan).unwrap())
}

#[test]
fn two_views_are_the_left_and_right_images_byte_for_byte() {
    for extra in [
        &[][..],
        &["stereo.mode=\"toe-in\""][..],
        &["stereo.mode=\"parallel\""][..],
        &["stereo.lighting=\"cyclopic\""][..],
        &["stereo.viewer=\"left-eye\""][..],
        &["stereo.eye_separation=\"auto\"", "stereo.user_balance=0.7"][..],
        &["stereo.mode=\"image-shift\""][..],
    ] {
        let mut sets = vec!["multiview.views=2"];
        sets.extend_from_slice(extra);
        let (_, frame) = views_and_pair(&sets);
        for (i, eye) in [View::Left, View::Right].into_iter().enumerate() {
            let (multi, pair) = (
                frame.view(View::Multi(i as u8)).unwrap(),
                frame.view(eye).unwrap(),
            );
            assert_eq!(multi, pair, "{extra:?}: view {i} against {eye:?}");
            assert_eq!(frame.views.multi[i], *frame.matrices(eye), "{extra:?}");
        }
        let scene = shipped("multiview", &sets);
        let frame = render(
            &scene,
            &Plan::new(&[Output::ViewTiles(2), Output::SideBySide]),
        )
        .unwrap();
        assert_eq!(
            rgba(produce(Output::ViewTiles(2), &frame, &scene).unwrap()),
            rgba(produce(Output::SideBySide, &frame, &scene).unwrap()),
            "{extra:?}: two tiles are left | right"
        );
    }
}

#[test]
fn adjacent_views_have_the_parallax_of_one_separation() {
    let (scene, frame) = views_and_pair(&[]);
    let n = usize::from(scene.views);
    assert_eq!(n, 5);
    // The scene's numbers, written here again: d = 0.15, z0 = 5, fov 40°, 320×240.
    let (d, z0, w) = (0.15f64, 5.0f64, 320.0f64);
    let xrange = 2.0 * z0 * (20f64.to_radians()).tan() * (320.0 / 240.0);
    let cams = &frame.views.multi;
    // The cameras sit d apart on the camera's x axis, centred on it.
    let right = scene
        .camera
        .view()
        .inverse()
        .transform_vector3(glam::Vec3::X);
    for (i, c) in cams.iter().enumerate() {
        let want = glam::Vec3::from(scene.camera.eye) + right * ((i as f32 - 2.0) * d as f32);
        assert!((c.eye_world - want).length() < 1e-5, "{i}");
    }
    let inverse = scene.camera.view().inverse();
    for z in [2.5f64, 5.0, 8.0, 15.0] {
        // A point straight ahead of the camera at eye depth z.
        let p = inverse.transform_point3(glam::Vec3::new(0.1, -0.2, -z as f32));
        let px: Vec<f64> = cams
            .iter()
            .map(|c| {
                let q = c.mvp.project_point3(p);
                (f64::from(q.x) + 1.0) * 0.5 * w
            })
            .collect();
        // The exercise slides' parallax between adjacent cameras, in pixels.
        let want = d * (1.0 - z0 / z) * w / xrange;
        for i in 1..n {
            let got = px[i] - px[i - 1];
            assert!(
                (got - want).abs() < 2e-3,
                "z {z}: views {} and {i}: {got} px, the formula {want} px",
                i - 1
            );
        }
    }
}

#[test]
fn view_tiles_and_interleave_match_an_independent_layout() {
    let scene = shipped("multiview", &[]);
    let frame = render(&scene, &Plan::new(&scene.outputs)).unwrap();
    let n = usize::from(scene.views);
    assert_eq!(frame.plan.passes.len(), n, "only the N views run");
    let fb: Vec<image::RgbaImage> = (0..n)
        .map(|i| frame.view(View::Multi(i as u8)).unwrap().to_rgba_image())
        .collect();
    for i in 1..n {
        assert_ne!(fb[i - 1], fb[i], "views {} and {i} must differ", i - 1);
    }
    let (w, h) = (scene.width, scene.height);
    // 5 views: 3 columns (the smallest square holding them is 3×3), 2 rows.
    let columns = (n as f64).sqrt().ceil() as u32;
    let rows = (n as u32).div_ceil(columns);
    assert_eq!((columns, rows), (3, 2));
    let tiles = rgba(produce(Output::ViewTiles(5), &frame, &scene).unwrap());
    assert_eq!(tiles.dimensions(), (3 * w, 2 * h));
    for ty in 0..rows {
        for tx in 0..columns {
            let view = (ty * columns + tx) as usize;
            let tile = image::imageops::crop_imm(&tiles, tx * w, ty * h, w, h).to_image();
            if view < n {
                assert_eq!(tile, fb[view], "tile ({tx}, {ty})");
            } else {
                assert!(tile.pixels().all(|p| p.0 == [0, 0, 0, 255]), "empty tile");
            }
        }
    }
    let inter = rgba(produce(Output::ViewInterleaved(5), &frame, &scene).unwrap());
    assert_eq!(inter.dimensions(), (w, h));
    // Under each lenticule (5 columns), the rightmost view (4) first, the leftmost (0) last.
    for x in 0..w {
        let lenticule_column = x as usize % n;
        let view = n - 1 - lenticule_column;
        for y in 0..h {
            assert_eq!(
                inter.get_pixel(x, y),
                fb[view].get_pixel(x, y),
                "({x}, {y})"
            );
        }
    }
    let dir = out_dir("multiview");
    let paths = stereolab::output::write_all(&frame, &scene, &dir).unwrap();
    assert_eq!(
        paths,
        vec![dir.join("view_tiles.png"), dir.join("view_interleaved.png")]
    );
    // The memory estimate counts one framebuffer for each of the N passes.
    let pixels = u64::from(w) * u64::from(h);
    assert_eq!(estimate(&scene, &frame.plan).framebuffers, 5 * pixels * 8);
}

#[test]
fn explain_lists_the_n_view_passes_only() {
    let dir = out_dir("multiview_explain");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["render"])
        .arg(asset("scenes/multiview.toml"))
        .args([
            "--set",
            "multiview.views=7",
            "--size",
            "64x48",
            "--explain",
            "--out",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let passes: Vec<&str> = text.lines().filter(|l| l.contains("pass Multi(")).collect();
    assert_eq!(passes.len(), 7, "{text}");
    for (i, line) in passes.iter().enumerate() {
        assert!(line.contains(&format!("Multi({i})")), "{line}");
        assert!(line.contains("view_tiles, view_interleaved"), "{line}");
    }
    assert!(text.contains("passes run: 7"), "{text}");
    assert!(
        !text.contains("pass Left") && !text.contains("pass Right"),
        "{text}"
    );
}

#[test]
fn bad_wiggle_and_multiview_values_name_their_field() {
    for (scene, sets, field, remedy) in [
        (
            "multiview",
            &["multiview.views=1"][..],
            "multiview.views",
            "2 to 64",
        ),
        (
            "multiview",
            &["multiview.views=65"][..],
            "multiview.views",
            "2 to 64",
        ),
        (
            "multiview",
            &["multiview.views=300"][..],
            "multiview.views",
            "2 to 64",
        ),
        (
            "multiview",
            &["stereo.mode=\"image-shift\""][..],
            "stereo.mode",
            "multiview.views = 2, not 5",
        ),
        (
            "multiview",
            &[
                "multiview.views=64",
                "image.width=8192",
                "image.height=8192",
            ][..],
            "multiview.views",
            "fewer views or a smaller image",
        ),
        ("multiview", &["multiview.cameras=3"][..], "cameras", ""),
        (
            "wiggle",
            &["wiggle.frame_ms=125"][..],
            "wiggle.frame_ms",
            "use 120 or 130",
        ),
        (
            "wiggle",
            &["wiggle.frame_ms=10"][..],
            "wiggle.frame_ms",
            "20 to 5000",
        ),
        (
            "wiggle",
            &["wiggle.frame_ms=60000"][..],
            "wiggle.frame_ms",
            "20 to 5000",
        ),
        ("wiggle", &["wiggle.start=\"middle\""][..], "middle", ""),
    ] {
        let e = load_error(scene, sets);
        assert!(e.contains(field) && e.contains(remedy), "{sets:?}: {e}");
    }
    // A scene without [multiview] renders the rig's own pair as its two views.
    let scene = shipped("wuson", &["outputs=[\"view_interleaved\"]"]);
    assert_eq!(scene.outputs, vec![Output::ViewInterleaved(2)]);
}
