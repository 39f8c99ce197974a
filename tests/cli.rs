//! The `stereolab` binary: renders what a scene asks for; bad input gets a clear error, exit
//! code 1, never a panic.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{asset, out_dir, root};

fn stereolab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .output()
        .expect("run stereolab")
}

/// Runs a command that must fail; returns stderr after checking it is a clean error.
fn fails(args: &[&str]) -> String {
    let out = stereolab(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(
        out.status.code(),
        Some(1),
        "{args:?} should fail with exit 1; stderr: {err}"
    );
    assert!(err.starts_with("error: "), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    err
}

fn wuson() -> String {
    asset("scenes/wuson.toml").display().to_string()
}

/// Writes a scene that renders one OBJ file.
fn obj_scene(dir: &Path, obj: &Path) -> String {
    let scene = dir.join("obj.toml");
    // A scene reads only files in its own folder tree: the model is copied next to it.
    let local = dir.join(obj.file_name().expect("a file"));
    if !obj.starts_with(dir) {
        std::fs::copy(obj, &local).expect("copy the model");
    }
    let obj = local.as_path();
    let text = format!(
        "outputs = [\"left\"]\n[image]\nwidth = 32\nheight = 24\n[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[[mesh]]\nkind = \"obj\"\npath = \"{}\"\n",
        obj.display()
    );
    std::fs::write(&scene, text).unwrap();
    scene.display().to_string()
}

#[test]
fn render_writes_the_requested_pngs_and_explain_lists_the_passes() {
    let dir = out_dir("cli_render");
    let out = stereolab(&[
        "render",
        &wuson(),
        "--out",
        dir.to_str().unwrap(),
        "--size",
        "160x120",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (name, w) in [("left", 160), ("right", 160), ("side_by_side", 320)] {
        let img = image::open(dir.join(format!("{name}.png"))).unwrap();
        assert_eq!((img.width(), img.height()), (w, 120), "{name}");
    }
    let explain = stereolab(&[
        "render",
        &wuson(),
        "--explain",
        "--set",
        "outputs=[\"left_depth\"]",
    ]);
    let text = String::from_utf8_lossy(&explain.stdout);
    assert!(text.contains("pass Left eye, depth only"), "{text}");
    assert!(text.contains("not run: Right eye"), "{text}");
    assert!(text.contains("passes run: 1"), "{text}");
}

#[test]
fn info_prints_both_frusta_and_the_parallax_range() {
    let out = stereolab(&["info", &wuson()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    for needle in [
        "left   eye",
        "right  eye",
        "zero-parallax distance z0 = 4.8",
        "% of image width",
    ] {
        assert!(text.contains(needle), "missing {needle:?} in\n{text}");
    }
    let wide = stereolab(&[
        "info",
        &wuson(),
        "--set",
        "stereo.user_offset=2",
        "--set",
        "stereo.zero_parallax=2",
    ]);
    assert!(String::from_utf8_lossy(&wide.stdout).contains("warning: parallax exceeds"));
}

#[test]
fn malformed_obj_files_name_file_line_and_value() {
    let dir = out_dir("cli_obj");
    let err = fails(&[
        "render",
        &obj_scene(&dir, &asset("scenes/models/invalid/malformed.obj")),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        err.contains("malformed.obj:") && err.contains("out of range"),
        "{err}"
    );
    let err = fails(&[
        "render",
        &obj_scene(&dir, &asset("scenes/models/invalid/empty.obj")),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        err.contains("empty.obj") && err.contains("no triangles"),
        "{err}"
    );
    let nan = dir.join("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    let err = fails(&[
        "render",
        &obj_scene(&dir, &nan),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(err.contains("nan.obj:3") && err.contains("'nan'"), "{err}");
    let err = fails(&[
        "render",
        &obj_scene(&dir, &dir.join("missing.obj")),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(err.contains("missing.obj"), "{err}");
}

#[test]
fn obj_with_missing_material_library_renders_but_an_empty_face_does_not() {
    // assimp's malformed2.obj references a material that does not exist (not an error for us:
    // colors come from the scene) and has an empty `f` line on line 23 (an error).
    let dir = out_dir("cli_obj_material");
    let err = fails(&[
        "render",
        &obj_scene(&dir, &asset("scenes/models/invalid/malformed2.obj")),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        err.contains("malformed2.obj:23") && err.contains("found 0"),
        "{err}"
    );
    let fixed = dir.join("material.obj");
    let text = std::fs::read_to_string(asset("scenes/models/invalid/malformed2.obj"))
        .unwrap()
        .replace("\nf\n", "\n");
    std::fs::write(&fixed, text).unwrap();
    let out = stereolab(&[
        "render",
        &obj_scene(&dir, &fixed),
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn bad_scene_values_name_the_field_and_value() {
    let s = wuson();
    let cases: &[(&[&str], &[&str])] = &[
        (&["--size", "0x10"], &["--size = 0x10", "at least 1 pixel"]),
        (
            &["--size", "100000x100000"],
            &["--size = 100000", "at most 16384"],
        ),
        (&["--size", "12by7"], &["--size = 12by7"]),
        (
            &["--size", "16000x16000"],
            &["--size = 16000x16000", "pixels"],
        ),
        (&["--set", "camera.near=0"], &["camera.near = 0"]),
        (&["--set", "camera.far=0.5"], &["camera.far = 0.5"]),
        (
            &["--set", "stereo.zero_parallax=30"],
            &["stereo.zero_parallax = 30"],
        ),
        (
            &["--set", "stereo.eye_separation=-0.1"],
            &["stereo.eye_separation = -0.1"],
        ),
        (
            &["--set", "stereo.eye_separation=\"wide\""],
            &["stereo.eye_separation"],
        ),
        (
            &["--set", "outputs=[\"left\",\"holo\"]"],
            &["\"holo\"", "known: left"],
        ),
        (
            &["--set", "mesh.0.kind=\"teapot\""],
            &["mesh[0].kind = \"teapot\""],
        ),
        (&["--set", "mesh.0.scale=nan"], &["mesh[0].scale = NaN"]),
        (
            &[
                "--set",
                "camera.eye=[0,1,2]",
                "--set",
                "camera.target=[0,1,2]",
            ],
            &["camera.target"],
        ),
    ];
    for (args, needles) in cases {
        let mut full = vec!["render", &s, "--out", "target/test-out/never"];
        full.extend_from_slice(args);
        let err = fails(&full);
        let from_scene = args[0] == "--set";
        assert!(
            !from_scene || err.contains("wuson.toml"),
            "{args:?}: error should name the scene file: {err}"
        );
        for n in *needles {
            assert!(err.contains(n), "{args:?}: expected {n:?} in {err}");
        }
    }
}

#[test]
fn scene_syntax_errors_and_unknown_fields_give_the_line() {
    let dir = out_dir("cli_toml");
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "outputs = [\"left\"]\n[image]\nwidth = 32\nheight = = 24\n",
    )
    .unwrap();
    let err = fails(&["render", bad.to_str().unwrap()]);
    assert!(err.contains("bad.toml:4"), "{err}");
    std::fs::write(&bad, "outputs = [\"left\"]\n[image]\nwidth = 32\nheight = 24\ncolour = 3\n[camera]\neye=[0,0,1]\ntarget=[0,0,0]\nnear=1\nfar=2\n").unwrap();
    let err = fails(&["render", bad.to_str().unwrap()]);
    assert!(
        err.contains("bad.toml:5") && err.contains("colour"),
        "{err}"
    );
    let err = fails(&["render", dir.join("nope.toml").to_str().unwrap()]);
    assert!(err.contains("nope.toml"), "{err}");
}

#[test]
fn figures_draws_every_figure_and_names_a_missing_bench_file() {
    let dir = out_dir("cli_figures");
    let bench = stereolab_figures::all();
    let csv = root().join("slides/data/bench.csv");
    let out = stereolab(&[
        "figures",
        &wuson(),
        "--out",
        dir.to_str().unwrap(),
        "--bench",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in &bench {
        assert!(dir.join(format!("{}.png", f.name)).is_file(), "{}", f.name);
    }
    let top = image::open(dir.join("rig_off_axis.png"))
        .unwrap()
        .to_rgba8();
    let has = |rgb: [u8; 3]| top.pixels().any(|p| p.0[..3] == rgb);
    assert!(
        has([210, 40, 40]) && has([20, 140, 190]),
        "left (red) and right (cyan) frusta must both be drawn"
    );
    let err = fails(&[
        "figures",
        &wuson(),
        "--out",
        dir.to_str().unwrap(),
        "--bench",
        dir.join("nope.csv").to_str().unwrap(),
    ]);
    assert!(err.contains("nope.csv"), "{err}");
}

#[test]
fn bench_runs_one_group_and_refuses_an_unknown_one() {
    let err = fails(&["bench", "--only", "nonsense"]);
    assert!(
        err.contains("bench.only") && err.contains("nonsense"),
        "{err}"
    );
    let out = stereolab(&["bench", "--only", "raster", "--iterations", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(text.contains("subpixel"), "{text}");
    assert!(!text.contains("sirds"), "only the raster group ran: {text}");
}

#[test]
fn render_notes_a_number_read_as_assimp_reads_it_with_its_line() {
    let dir = out_dir("cli_obj_note");
    let obj = dir.join("junk_exponent.obj");
    std::fs::write(&obj, "v -1 -1 0\nv 1 -1 0.1+e2\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = obj_scene(&dir, &obj);
    let out = stereolab(&["render", &scene, "--out", dir.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains(
            "  note: {}:2: 'v' coordinate '0.1+e2' read as 0.1, as assimp reads it: it stops \
             before '+e2' (if 0.1e+2 was meant, write that)"
                .replace("{}", &obj.display().to_string())
                .as_str()
        ),
        "{stdout}"
    );
}
