//! Fuzzing on stable Rust: arbitrary bytes and arbitrary structured values fed to
//! the scene, OBJ, CSV and image readers must give a value or a clean error, never a panic or a
//! hang. CI runs proptest's default 256 cases per reader; the long run is
//! `PROPTEST_CASES=1000000 cargo test --release --test main fuzz` (docs/reliability.md). A
//! crash found here becomes a regression case in `regressions()` below.

use std::path::Path;

use proptest::prelude::*;
use stereolab::Scene;
use stereolab::scene::parse_obj;
use stereolab::scene::terrain::{parse_csv, triangulate};

use crate::common::out_dir;

/// A valid scene's text, to mutate field by field.
const BASE: &str = "outputs = [\"left\", \"right\", \"anaglyph\"]\n[image]\nwidth = 16\nheight = 12\n[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[stereo]\neye_separation = 0.2\nzero_parallax = 5\n[[mesh]]\nkind = \"cube\"\n";

/// Keys a `--set` can reach, and values of every kind, including hostile ones.
fn set_strategy() -> impl Strategy<Value = String> {
    let keys = prop::sample::select(vec![
        "image.width",
        "image.height",
        "camera.eye",
        "camera.near",
        "camera.far",
        "camera.fov_y",
        "stereo.eye_separation",
        "stereo.zero_parallax",
        "stereo.mode",
        "mesh.0.kind",
        "mesh.0.size",
        "mesh.0.detail",
        "mesh.0.count",
        "mesh.0.scale",
        "mesh.0.rotate",
        "layout.blank_interval",
        "sirds.oversample",
        "sirds.strips",
        "chromadepth.d1",
        "light.shininess",
        "outputs",
        "raster.cull_back",
    ]);
    let values = prop::sample::select(vec![
        "0",
        "-1",
        "1e30",
        "-1e30",
        "nan",
        "inf",
        "4294967295",
        "18446744073709551615",
        "3",
        "\"auto\"",
        "\"sphere\"",
        "\"triangles\"",
        "\"toe-in\"",
        "[1, 2]",
        "[0, 0, 0]",
        "[1e38, 1e38, 1e38]",
        "true",
        "\"\"",
        "[\"sirds\", \"chromadepth\"]",
        "0.5",
    ]);
    (keys, values).prop_map(|(k, v)| format!("{k}={v}"))
}

proptest! {
    #[test]
    fn scene_text_never_panics(text in "\\PC{0,400}") {
        let _ = Scene::from_toml(&text, Path::new("fuzz.toml"), Path::new("."), &[]);
    }

    #[test]
    fn scene_fields_never_panic(sets in prop::collection::vec(set_strategy(), 0..4)) {
        let _ = Scene::from_toml(BASE, Path::new("fuzz.toml"), Path::new("."), &sets);
    }

    #[test]
    fn obj_text_never_panics(text in "\\PC{0,300}") {
        let _ = parse_obj(Path::new("fuzz.obj"), text);
    }

    #[test]
    fn obj_structure_never_panics(
        lines in prop::collection::vec(
            (prop::sample::select(vec!["v", "vt", "vn", "f", "o", "g", "usemtl", "#"]),
             prop::collection::vec(prop_oneof![
                 any::<i32>().prop_map(|i| i.to_string()),
                 any::<f32>().prop_map(|f| f.to_string()),
                 "[0-9]{1,3}/[0-9]{0,3}/[0-9]{0,3}",
                 "-?[0-9]{1,2}",
             ], 0..6)),
            0..24)
    ) {
        let text: String = lines
            .iter()
            .map(|(tag, words)| format!("{tag} {}\n", words.join(" ")))
            .collect();
        let _ = parse_obj(Path::new("fuzz.obj"), text);
    }

    #[test]
    fn terrain_csv_never_panics(
        text in "\\PC{0,200}",
        rows in prop::collection::vec((any::<f64>(), any::<f64>(), any::<f64>()), 0..40),
    ) {
        let _ = parse_csv(Path::new("fuzz.csv"), &text);
        let csv: String = std::iter::once("x,y,height\n".to_string())
            .chain(rows.iter().map(|(x, y, h)| format!("{x},{y},{h}\n")))
            .collect();
        if let Ok(points) = parse_csv(Path::new("fuzz.csv"), &csv) {
            let _ = triangulate(Path::new("fuzz.csv"), &points);
        }
    }

    #[test]
    fn image_bytes_never_panic(
        header in prop::sample::select(vec![
            &b"\x89PNG\r\n\x1a\n"[..], b"P6\n", b"P5\n", b"P7\n", b"GIF89a", b"",
        ]),
        body in prop::collection::vec(any::<u8>(), 0..200),
        dims in (0u32..70000, 0u32..70000),
    ) {
        let dir = out_dir_once();
        let path = dir.join(format!("img-{}.bin", std::process::id()));
        let mut bytes = header.to_vec();
        if header.starts_with(b"P") {
            bytes.extend(format!("{} {}\n255\n", dims.0, dims.1).bytes());
        }
        bytes.extend(&body);
        std::fs::write(&path, &bytes).unwrap();
        let _ = stereolab_core::open_image(&path, "fuzz image");
    }
}

fn out_dir_once() -> std::path::PathBuf {
    static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| out_dir("fuzz")).clone()
}
