//! assimp's OBJ test models (Debian/Ubuntu package `assimp-testmodels`) as a conformance
//! corpus: every valid model loads; the two that hold only points, and `number_formats.obj`
//! with its `3.1+e2`, are refused with the reason. The concave 64-gon (a thin ring: an outline
//! and a hole joined by a bridge edge) renders covering exactly its outline with back faces
//! culled: a fan's triangles would cover the hole and leave parts of the ring out, as some
//! of them face backwards. Every model that loads renders, framed from its bounding box, to
//! the same bytes twice.

use std::path::{Path, PathBuf};

use glam::{Vec3, Vec4};
use stereolab::plan::{Plan, View};
use stereolab::render::render;
use stereolab::scene::{Scene, load_obj};

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

/// What each refused model's message must hold: the reason, and for a bad number its line.
fn expected_refusal(name: &str) -> Option<&'static [&'static str]> {
    match name {
        "point_cloud.obj" | "testpoints.obj" => Some(&["only points"]),
        "number_formats.obj" => Some(&[
            "number_formats.obj:11:",
            "'3.1+e2'",
            "only '3.1' is a number",
        ]),
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

/// A scene in `dir` looking at `model` (copied there) from `eye` towards `target`.
fn scene_for(
    dir: &Path,
    model: &Path,
    eye: Vec3,
    target: Vec3,
    size: (u32, u32),
    cull: bool,
) -> Scene {
    let name = model.file_name().unwrap().to_string_lossy().into_owned();
    std::fs::copy(model, dir.join(&name)).unwrap();
    let scene_path = dir.join(format!("{name}.toml"));
    let toml = format!(
        "outputs = [\"left\"]\n[image]\nwidth = {}\nheight = {}\n[camera]\n\
         eye = [{}, {}, {}]\ntarget = [{}, {}, {}]\nfov_y = 40.0\nnear = {}\nfar = {}\n\
         [raster]\ncull_back = {cull}\n\
         [[mesh]]\nkind = \"obj\"\npath = \"{name}\"\n",
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

#[test]
fn every_loadable_assimp_model_renders_the_same_bytes_twice() {
    let dir = out_dir("obj_corpus_all");
    let mut names = Vec::new();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    paths.sort();
    for path in paths {
        let Ok(mesh) = load_obj(&path) else { continue };
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        // Framed automatically: from the bounding box's corner direction, far enough for all.
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let center = (lo + hi) / 2.0;
        let eye =
            center + Vec3::new(0.6, 0.5, 1.0).normalize() * 2.0 * (hi - lo).length().max(1e-3);
        let scene = scene_for(&dir, &path, eye, center, (64, 48), false);
        let plan = Plan::new(&scene.outputs);
        let a = render(&scene, &plan).unwrap_or_else(|e| panic!("{name}: {e}"));
        let b = render(&scene, &plan).unwrap();
        let (fa, fb) = (a.view(View::Left).unwrap(), b.view(View::Left).unwrap());
        assert!(
            fa.color == fb.color && fa.depth == fb.depth,
            "{name}: two renders differ"
        );
        let drawn = fa.depth.iter().filter(|&&d| d < 1.0).count();
        assert!(drawn > 0, "{name}: nothing drawn (framing is off)");
        names.push(name);
    }
    assert_eq!(names.len(), 19, "the models that load: {names:?}");
}

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
        concave_64_gon_renders_as_its_outline(name);
    }
}

fn concave_64_gon_renders_as_its_outline(name: &str) {
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
    let scene = scene_for(&dir, &model, eye, center, (w, h), true);
    let frame = render(&scene, &Plan::new(&scene.outputs)).expect("it renders");
    let fb = frame.view(View::Left).expect("the left view");
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
            let drawn = fb.depth[k] < 1.0;
            if drawn != inside(p, &outline) {
                wrong.push((col, row, drawn));
            }
            covered += usize::from(drawn);
        }
    }
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(fb.color[(y * w + x) as usize]));
    img.save(dir.join("left.png")).unwrap(); // to look at when this fails
    assert!(
        covered > 1000,
        "{name}: the face covers {covered} pixels: framing is off"
    );
    assert!(
        wrong.is_empty(),
        "{name}: {} pixels away from the outline disagree with it (col, row, drawn): {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(20)]
    );
}
