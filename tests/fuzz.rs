//! Fuzzing on stable Rust: arbitrary bytes and arbitrary structured values fed to
//! the scene, OBJ, CSV, PDB, depth-map (PFM, PGM, PAM) and image readers must give a value or a
//! clean error, never a panic or a hang. CI runs proptest's default 256 cases per reader; the
//! long run and its counts are in docs/reliability.md. A crash found here becomes a regression
//! case in `regressions()` below.

use std::path::Path;

use proptest::prelude::*;
use stereolab::Scene;
use stereolab::scene::pdb::{atoms_mesh, parse_pdb};
use stereolab::scene::terrain::{parse_csv, triangulate};
use stereolab::scene::{parse_obj, parse_obj_within};
use stereolab_core::{DepthSamples, Near, PgmRows};

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
        obj_result_is_clean(&text, u64::MAX)?;
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
                 "-?[0-9]{1,2}(/-?[0-9]{0,2}){1,4}",
                 prop::sample::select(vec!["#", "3.1+e2", "1,5", "0x10", "1e", "nan", "-0"])
                     .prop_map(str::to_string),
             ], 0..9)),
            0..24),
        budget in 0u64..12,
    ) {
        let text: String = lines
            .iter()
            .map(|(tag, words)| format!("{tag} {}\n", words.join(" ")))
            .collect();
        obj_result_is_clean(&text, budget)?;
        obj_result_is_clean(&text, u64::MAX)?;
    }

    #[test]
    fn pdb_text_never_panics(
        lines in prop::collection::vec(prop_oneof![
            "\\PC{0,90}",
            (prop::sample::select(vec!["ATOM  ", "HETATM"]), "[ -~\\u{e9}]{0,84}")
                .prop_map(|(a, b)| format!("{a}{b}")),
            (any::<f32>(), any::<f32>(), any::<f32>(), "[A-Za-z0-9 ]{2}", "[A-Z ]{2}")
                .prop_map(|(x, y, z, name, e)| format!(
                    "ATOM      1 {name}   ALA A   1    {x:>8.3}{y:>8.3}{z:>8.3}  1.00  0.00          {e}"
                )),
        ], 0..12),
    ) {
        if let Ok(atoms) = parse_pdb(Path::new("fuzz.pdb"), &lines.join("\n")) {
            prop_assert!(!atoms.is_empty());
            let _ = atoms_mesh(&atoms, 4, 1.0);
        }
    }

    #[test]
    fn pfm_depth_maps_never_panic(
        magic in prop::sample::select(vec!["PF", "Pf", "PF4", "pf"]),
        sep in prop::sample::select(vec!["\n", " ", "\t", "\r\n", "\n#c\n", ""]),
        dims in (0u32..5, 0u32..5),
        claimed in prop::option::of((0u32..70000, 0u32..70000)),
        scale in prop::sample::select(vec!["-1.0", "1", "-0.5", "0", "nan", "-inf", "x", "1e40", ""]),
        floats in prop::collection::vec(any::<f32>(), 0..80),
        exact in any::<bool>(),
        black in any::<bool>(),
    ) {
        let (w, h) = claimed.unwrap_or(dims);
        let channels: u64 = if magic == "PF" { 3 } else { 1 };
        let mut bytes = format!("{magic}{sep}{w} {h}{sep}{scale}\n").into_bytes();
        let wanted = u64::from(w) * u64::from(h) * channels;
        let big_endian = !scale.starts_with('-');
        let sample = |i: usize| floats.get(i % floats.len().max(1)).copied().unwrap_or(0.5);
        let count = if exact && wanted <= 400 { wanted as usize } else { floats.len() };
        for i in 0..count {
            let v = sample(i);
            bytes.extend(if big_endian { v.to_be_bytes() } else { v.to_le_bytes() });
        }
        let path = fuzz_file("depth.pfm", &bytes);
        let near = if black { Near::Black } else { Near::White };
        if let Ok(d) = DepthSamples::load(&path, near) {
            prop_assert_eq!(d.samples.len() as u64, u64::from(d.width) * u64::from(d.height));
            prop_assert_eq!((d.width, d.height), (w, h));
        }
    }

    #[test]
    fn pgm_depth_maps_never_panic_and_stream_as_they_load(
        pam in any::<bool>(),
        dims in (0u32..6, 0u32..6),
        claimed in prop::option::of((0u32..70000, 0u32..70000)),
        maxval in prop::sample::select(vec![0u32, 1, 255, 256, 65535, 65536]),
        comment in any::<bool>(),
        body in prop::collection::vec(any::<u8>(), 0..160),
        exact in any::<bool>(),
        black in any::<bool>(),
    ) {
        let (w, h) = claimed.unwrap_or(dims);
        let mut bytes = if pam {
            format!(
                "P7\n{}WIDTH {w}\nHEIGHT {h}\nDEPTH 1\nMAXVAL {maxval}\nTUPLTYPE GRAYSCALE\nENDHDR\n",
                if comment { "# c\n" } else { "" }
            )
        } else {
            format!("P5\n{}{w} {h}\n{maxval}\n", if comment { "# c\n" } else { "" })
        }
        .into_bytes();
        let wanted = u64::from(w) * u64::from(h) * if maxval > 255 { 2 } else { 1 };
        let count = if exact && wanted <= 400 { wanted as usize } else { body.len() };
        bytes.extend((0..count).map(|i| body.get(i % body.len().max(1)).copied().unwrap_or(7)));
        let path = fuzz_file(if pam { "depth.pam" } else { "depth.pgm" }, &bytes);
        let near = if black { Near::Black } else { Near::White };
        let loaded = DepthSamples::load(&path, near);
        if let Some(mut rows) = PgmRows::open(&path, near).expect("a regular file opens") {
            let mut streamed = vec![0u16; rows.width as usize * rows.height as usize];
            rows.read(&mut streamed).expect("the rows it promised");
            let loaded = loaded.expect("a file PgmRows streams loads");
            prop_assert_eq!(&streamed, &loaded.samples);
            prop_assert_eq!(rows.mapping(), loaded.mapping);
        }
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

/// Parses OBJ text within `budget` triangles: a value, or an error that names the file and, for
/// anything a line holds, the line (never tobj's unlocated words).
fn obj_result_is_clean(text: &str, budget: u64) -> Result<(), TestCaseError> {
    match parse_obj_within(Path::new("fuzz.obj"), text.to_string(), budget) {
        Ok((mesh, _)) => {
            prop_assert!(mesh.triangles.len() as u64 <= budget);
            prop_assert!(!mesh.triangles.is_empty());
        }
        Err(e) => {
            let e = e.to_string();
            prop_assert!(e.starts_with("fuzz.obj"), "{}", e);
            prop_assert!(!e.contains("OBJ:"), "unlocated: {}", e);
        }
    }
    let _ = parse_obj(Path::new("fuzz.obj"), text.to_string());
    Ok(())
}

/// A file named `name` (with this process's id) in the fuzz folder, holding `bytes`.
fn fuzz_file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = out_dir_once().join(format!("{}-{name}", std::process::id()));
    std::fs::write(&path, bytes).unwrap();
    path
}

fn out_dir_once() -> std::path::PathBuf {
    static DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| out_dir("fuzz")).clone()
}

/// Cases the properties above found, kept so that they are tried on every run.
#[test]
fn regressions() {
    // Lines tobj refused without saying where (`OBJ: ...`): each must name its line.
    for (text, line) in [
        ("vt 0.5\n", 1),
        ("v 0 0 0\nv 1 2 3 4 5 6 7\n", 2),
        ("v 1 2 3 0\n", 1),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", 4),
        ("v 0 0 0 1 1 1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 0),
    ] {
        let result = parse_obj_within(Path::new("fuzz.obj"), text.to_string(), 10);
        match (result, line) {
            (Ok(_), 0) => {}
            (Err(e), line) if line > 0 => {
                let e = e.to_string();
                assert!(
                    e.starts_with(&format!("fuzz.obj:{line}: ")),
                    "{text:?}: {e}"
                );
            }
            (other, _) => panic!("{text:?}: {other:?}"),
        }
    }
}
