//! assimp's OBJ test models (Debian/Ubuntu package `assimp-testmodels`) as a conformance
//! corpus: every valid model loads (20 of 22); the two that hold only points are refused with
//! the reason. `number_formats.obj` loads with its `3.1+e2` read as assimp reads it (3.1) and
//! a note naming each such line. The concave 64-gon (a thin ring: an outline
//! and a hole joined by a bridge edge) renders covering exactly its outline with back faces
//! culled: a fan's triangles would cover the hole and leave parts of the ring out, as some
//! of them face backwards. Every model that loads renders, framed from its bounding box, to
//! the same bytes twice.

use std::path::{Path, PathBuf};

use glam::{Vec3, Vec4};
use stereolab::plan::{Plan, View};
use stereolab::render::render;
use stereolab::scene::{Mesh, Scene, load_obj};
use stereolab_core::Framebuffer;

use crate::common::out_dir;

const CORPUS: &str = "/usr/share/assimp/models/OBJ";

/// The corpus folder; a missing one fails (no silent skip) and says how to get it.
fn corpus() -> PathBuf {
    let dir = PathBuf::from(CORPUS);
    assert!(
        dir.is_dir(),
        "{CORPUS} is missing: install the assimp test models (`apt-get install assimp-testmodels`)"
    );
    dir
}

/// What each refused model's message must hold: the reason.
fn expected_refusal(name: &str) -> Option<&'static [&'static str]> {
    match name {
        "point_cloud.obj" | "testpoints.obj" => Some(&["only points"]),
        _ => None,
    }
}

#[test]
fn every_assimp_obj_model_loads_or_is_refused_with_the_reason() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(corpus())
        .expect("read the corpus folder")
        .map(|e| e.expect("a folder entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    assert_eq!(paths.len(), 22, "the package's OBJ models: {paths:?}");
    let mut failures = Vec::new();
    for path in &paths {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let result = load_obj(path);
        // Loading is deterministic: a second load gives the same mesh.
        if let (Ok(a), Ok(b)) = (&result, &load_obj(path))
            && (a.positions != b.positions || a.triangles != b.triangles)
        {
            failures.push(format!("{name}: two loads differ"));
        }
        match (result, expected_refusal(&name)) {
            (Ok(mesh), None) => {
                if mesh.triangles.is_empty() {
                    failures.push(format!("{name}: loaded without triangles"));
                }
            }
            (Ok(_), Some(_)) => failures.push(format!("{name}: loaded, expected a refusal")),
            (Err(e), None) => failures.push(format!("{name}: refused: {e}")),
            (Err(e), Some(needles)) => {
                let msg = e.to_string();
                for needle in needles {
                    if !msg.contains(needle) {
                        failures.push(format!("{name}: message lacks '{needle}': {msg}"));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn number_formats_are_read_as_assimp_reads_them_with_a_note_per_unusual_number() {
    let path = corpus().join("number_formats.obj");
    let (_, notes) = stereolab::scene::load_obj_with_notes(&path).expect("it loads");
    // Lines 11-13 hold `3.1+e2`, lines 15-17 `3.1-e2`: assimp's fast_atof stops at the sign.
    let lines: Vec<String> = notes
        .iter()
        .map(|n| n.split(':').nth(1).unwrap_or_default().to_string())
        .collect();
    assert_eq!(lines, ["11", "12", "13", "15", "16", "17"], "{notes:#?}");
    assert!(
        notes[0].ends_with(
            "'v' coordinate '3.1+e2' read as 3.1, as assimp reads it: it stops before '+e2' \
             (if 3.1e+2 was meant, write that)"
        ),
        "{}",
        notes[0]
    );
    // The file's only face uses vertices 1, 2 and 4; a face over vertices 8-13 (lines 11-17)
    // shows the values read: what assimp's importer gives for them.
    let text = std::fs::read_to_string(&path).unwrap() + "f 8 9 10\nf 11 12 13\n";
    let mesh = stereolab::scene::parse_obj(&path, text).expect("it loads");
    for expected in [
        Vec3::new(100.0, 20.0, 3.1),
        Vec3::new(-100.0, -20.0, -3.1),
        Vec3::new(0.01, 0.2, 3.1),
        Vec3::new(-0.01, -0.2, -3.1),
    ] {
        assert!(
            mesh.positions.contains(&expected),
            "{expected} not among {:?}",
            mesh.positions
        );
    }
}

/// A scene in `dir` looking at `model` (copied there) from `eye` towards `target`.
fn scene_for(
    dir: &Path,
    model: &Path,
    eye: Vec3,
    target: Vec3,
    size: (u32, u32),
    cull: bool,
    outputs: &[&str],
) -> Scene {
    let name = model.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::copy(model, dir.join(&name)).unwrap();
    let scene_path = dir.join(format!("{name}.toml"));
    let outputs: Vec<String> = outputs.iter().map(|o| format!("\"{o}\"")).collect();
    let toml = format!(
        "outputs = [{}]\n[image]\nwidth = {}\nheight = {}\n[camera]\n\
         eye = [{}, {}, {}]\ntarget = [{}, {}, {}]\nfov_y = 40.0\nnear = {}\nfar = {}\n\
         [raster]\ncull_back = {cull}\n\
         [[mesh]]\nkind = \"obj\"\npath = \"{name}\"\ncolor = [0.9, 0.55, 0.2]\n",
        outputs.join(", "),
        size.0,
        size.1,
        eye.x,
        eye.y,
        eye.z,
        target.x,
        target.y,
        target.z,
        eye.distance(target) / 10.0,
        eye.distance(target) * 10.0,
    );
    std::fs::write(&scene_path, toml).unwrap();
    Scene::load(&scene_path, &[]).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Every model of the corpus that loads, sorted by name, with its mesh.
fn loadable_models() -> Vec<(String, PathBuf, Mesh)> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    paths
        .into_iter()
        .filter_map(|path| {
            let mesh = load_obj(&path).ok()?;
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            Some((name, path, mesh))
        })
        .collect()
}

/// Automatic framing: the camera looks at the bounding box's centre from its corner
/// direction, twice its diagonal away.
fn framing(mesh: &Mesh) -> (Vec3, Vec3) {
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let center = (lo + hi) / 2.0;
    let eye = center + Vec3::new(0.6, 0.5, 1.0).normalize() * 2.0 * (hi - lo).length().max(1e-3);
    (eye, center)
}

/// Whether every triangle of the mesh has zero area (then it draws nothing on any path).
fn all_degenerate(mesh: &Mesh) -> bool {
    mesh.triangles.iter().all(|t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        (b - a).cross(c - a) == Vec3::ZERO
    })
}

#[test]
fn every_loadable_assimp_model_renders_the_same_bytes_twice() {
    let dir = out_dir("obj_corpus_all");
    let mut names = Vec::new();
    for (name, path, mesh) in loadable_models() {
        let (eye, center) = framing(&mesh);
        let scene = scene_for(&dir, &path, eye, center, (64, 48), false, &["left"]);
        let plan = Plan::new(&scene.outputs);
        let a = render(&scene, &plan).unwrap_or_else(|e| panic!("{name}: {e}"));
        let b = render(&scene, &plan).unwrap();
        let (fa, fb) = (a.view(View::Left).unwrap(), b.view(View::Left).unwrap());
        assert!(
            fa.color() == fb.color() && fa.depth() == fb.depth(),
            "{name}: two renders differ"
        );
        let drawn = fa.depth().iter().filter(|&&d| d < 1.0).count();
        // number_formats.obj's one face, (0,0,0) (1,2,3) (-1,-2,-3), is a line: nothing shows.
        if all_degenerate(&mesh) {
            assert_eq!(drawn, 0, "{name}: a zero-area face drew pixels");
        } else {
            assert!(drawn > 0, "{name}: nothing drawn (framing is off)");
        }
        names.push(name);
    }
    assert_eq!(names.len(), 20, "the models that load: {names:?}");
}

/// `stereolab compare`'s parity thresholds (its defaults) on every corpus model, both eyes and
/// a Dubois anaglyph, CPU against lavapipe; and how much of the depth is the same bit for bit.
/// 160×120 keeps it to seconds.
#[cfg(feature = "gpu")]
#[test]
fn every_loadable_assimp_model_passes_compare_against_lavapipe() {
    use stereolab::compare::Thresholds;
    use stereolab_gpu::GpuScene;
    use stereolab_gpu::parity::{compare_finalize, compare_frames, depth_identity};
    let Some(r) = crate::gpu_parity::gpu() else {
        return;
    };
    let dir = out_dir("obj_corpus_gpu");
    let limits = Thresholds::default();
    let (mut failures, mut compared) = (Vec::new(), 0);
    let (mut same, mut both) = (0, 0);
    for (name, path, mesh) in loadable_models() {
        let (eye, center) = framing(&mesh);
        let outputs = ["left", "right", "anaglyph_dubois"];
        let scene = scene_for(&dir, &path, eye, center, (160, 120), false, &outputs);
        let plan = Plan::new(&scene.outputs);
        // `compare_scene`'s rows (raster parity, then the WGSL anaglyph on the CPU's eyes),
        // from frames kept for the depth count.
        let cpu = render(&scene, &plan).unwrap_or_else(|e| panic!("{name}: {e}"));
        let gpu = r
            .render(&GpuScene::upload(r, &scene).unwrap(), &plan)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut rows = compare_frames(&cpu, &gpu, &scene, None).unwrap();
        rows.extend(compare_finalize(r, &cpu, &scene, None).unwrap());
        assert_eq!(
            rows.len(),
            4,
            "{name}: two passes, the anaglyph, its WGSL row"
        );
        for v in limits.violations(&rows) {
            failures.push(format!("{name}: {v}"));
        }
        let (s, b) = depth_identity(&cpu, &gpu).unwrap();
        eprintln!(
            "{name}: depth bit-identical on {s} of {b} pixels both cover ({:.2}%)",
            100.0 * s as f64 / b.max(1) as f64
        );
        (same, both) = (same + s, both + b);
        compared += 1;
    }
    assert_eq!(compared, 20);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    let share = 100.0 * same as f64 / both.max(1) as f64;
    eprintln!("corpus: depth bit-identical on {same} of {both} pixels both cover ({share:.2}%)");
    assert!(
        share >= CORPUS_DEPTH_IDENTICAL_PERCENT,
        "depth bit-identical on {share:.2}% < {CORPUS_DEPTH_IDENTICAL_PERCENT}%"
    );
}

/// Share of the pixels both paths cover whose depth is the same `f32` on both (the
/// target: 99%). Measured: 100%, since the CPU evaluates depth as llvmpipe does (43.84%
/// otherwise); docs/gpu-parity.md.
#[cfg(feature = "gpu")]
const CORPUS_DEPTH_IDENTICAL_PERCENT: f64 = 99.0;

/// Even-odd point-in-polygon; a bridge edge walked both ways cancels itself.
fn inside(p: (f32, f32), poly: &[(f32, f32)]) -> bool {
    let mut inside = false;
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        if (a.1 > p.1) != (b.1 > p.1) && p.0 < a.0 + (p.1 - a.1) / (b.1 - a.1) * (b.0 - a.0) {
            inside = !inside;
        }
    }
    inside
}

fn distance_to_segment(p: (f32, f32), a: (f32, f32), b: (f32, f32)) -> f32 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = (dx * dx + dy * dy).max(1e-12);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / len2).clamp(0.0, 1.0);
    ((p.0 - a.0 - t * dx).powi(2) + (p.1 - a.1 - t * dy).powi(2)).sqrt()
}

/// The corners of the file's one face, in order, from its `f` line.
fn face_corners(path: &Path) -> Vec<Vec3> {
    let text = std::fs::read_to_string(path).unwrap();
    let v: Vec<Vec3> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<f32> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            Vec3::new(c[0], c[1], c[2])
        })
        .collect();
    let face = text.lines().find_map(|l| l.strip_prefix("f ")).unwrap();
    face.split_whitespace()
        .map(|c| v[c.split('/').next().unwrap().parse::<usize>().unwrap() - 1])
        .collect()
}

#[test]
fn the_concave_64_gon_renders_as_exactly_its_outline_facing_forward() {
    // The same face in both files; the second names a material with spaces.
    for name in ["concave_polygon.obj", "space_in_material_name.obj"] {
        let (scene, outline) = concave_64_gon_scene(name);
        let frame = render(&scene, &Plan::new(&scene.outputs)).expect("it renders");
        let fb = frame.view(View::Left).expect("the left view");
        assert_is_the_outline(&format!("{name} (CPU)"), fb, &outline);
        if name == "concave_polygon.obj" {
            crate::golden::check_golden("concave_polygon_320x240", fb);
        }
    }
}

/// The same on lavapipe: the GPU image is the outline too, and `compare`'s thresholds hold.
#[cfg(feature = "gpu")]
#[test]
fn the_concave_64_gon_renders_as_its_outline_on_lavapipe_too() {
    use stereolab::compare::Thresholds;
    use stereolab_gpu::GpuScene;
    use stereolab_gpu::parity::compare_frames;
    let Some(r) = crate::gpu_parity::gpu() else {
        return;
    };
    let (scene, outline) = concave_64_gon_scene("concave_polygon.obj");
    let plan = Plan::new(&scene.outputs);
    let gpu = r
        .render(&GpuScene::upload(r, &scene).expect("upload"), &plan)
        .expect("it renders on the GPU");
    assert_is_the_outline(
        "concave_polygon.obj (GPU)",
        gpu.view(View::Left).unwrap(),
        &outline,
    );
    let cpu = render(&scene, &plan).unwrap();
    let rows = compare_frames(&cpu, &gpu, &scene, None).unwrap();
    let violations = Thresholds::default().violations(&rows);
    assert!(violations.is_empty(), "{violations:?}");
}

/// The 64-gon's scene (framed along the face's normal, back faces culled, 320×240) and its
/// outline in pixels.
fn concave_64_gon_scene(name: &str) -> (Scene, Vec<(f32, f32)>) {
    let model = corpus().join(name);
    let corners = face_corners(&model);
    assert_eq!(
        corners.len(),
        66,
        "64 corners, two walked twice by the bridge"
    );
    // Frame the face automatically: look at its centre along its normal (Newell), from the
    // side it faces, so that with back-face culling only front-facing triangles show.
    let mut normal = Vec3::ZERO;
    for (i, a) in corners.iter().enumerate() {
        normal += a.cross(corners[(i + 1) % corners.len()]);
    }
    let normal = normal.normalize();
    let (lo, hi) = corners.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &c| {
        (lo.min(c), hi.max(c))
    });
    let center = (lo + hi) / 2.0;
    let eye = center + normal * 1.45 * (hi - lo).max_element();
    let (w, h) = (320, 240);
    let dir = out_dir(&format!("obj_corpus_{name}"));
    let scene = scene_for(&dir, &model, eye, center, (w, h), true, &["left"]);
    let frame = render(&scene, &Plan::new(&scene.outputs)).expect("it renders");
    let mvp = frame.matrices(View::Left).mvp;
    // The outline in pixels (row 0 at the top, pixel centres at +0.5).
    let outline: Vec<(f32, f32)> = corners
        .iter()
        .map(|c| {
            let clip = mvp * Vec4::new(c.x, c.y, c.z, 1.0);
            let ndc = clip / clip.w;
            (
                (ndc.x + 1.0) / 2.0 * w as f32,
                (1.0 - ndc.y) / 2.0 * h as f32,
            )
        })
        .collect();
    (scene, outline)
}

/// Every pixel at least a pixel away from the outline is drawn exactly when it lies inside.
fn assert_is_the_outline(what: &str, fb: &Framebuffer, outline: &[(f32, f32)]) {
    let (w, h) = (fb.width(), fb.height());
    let (mut covered, mut wrong) = (0, Vec::new());
    for row in 0..h {
        for col in 0..w {
            let p = (col as f32 + 0.5, row as f32 + 0.5);
            let near_edge = (0..outline.len()).any(|i| {
                distance_to_segment(p, outline[i], outline[(i + 1) % outline.len()]) < 1.0
            });
            if near_edge {
                continue; // rasterization rules decide these; not this test's business
            }
            let k = (row * w + col) as usize;
            let drawn = fb.depth()[k] < 1.0;
            if drawn != inside(p, outline) {
                wrong.push((col, row, drawn));
            }
            covered += usize::from(drawn);
        }
    }
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(fb.color()[(y * w + x) as usize]));
    let file = what.replace([' ', '(', ')'], "_");
    img.save(out_dir(&format!("obj_corpus_outline_{file}")).join("left.png"))
        .unwrap(); // to look at when this fails
    assert!(
        covered > 1000,
        "{what}: the face covers {covered} pixels: framing is off"
    );
    assert!(
        wrong.is_empty(),
        "{what}: {} pixels away from the outline disagree with it (col, row, drawn): {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(20)]
    );
}
