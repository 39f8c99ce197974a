//! ChromaDepth's rows for `stereolab bench`: texgen per vertex vs per pixel, ramp sampling,
//! the one-pass cost against a stereo pair, the glasses simulation and terrain triangulation.

use std::path::Path;

use glam::{DMat4, DVec3};

use super::{Row, median_ms};
use stereolab::plan::Shading;
use stereolab::render::chromadepth::{render_center_with, resolve_texgen, texgen_map};
use stereolab::render::render_view;
use stereolab::scene::{Scene, terrain};
use stereolab_core::{
    ChromaDepthSettings, Error, FAR_HUE_DEGREES, Ramp, RampKind, RampSampling, Result, StereoRig,
    TexgenMode, glasses_pair, hue_degrees, ramp_exact,
};

/// A 4×4 plane slanted 70° away from a camera at the origin looking down −Z, two triangles:
/// the case where interpolation matters most.
const SLANTED_PLANE: &str = r#"
outputs = ["chromadepth"]
[image]
width = 1024
height = 768
background = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.0, 0.0]
target = [0.0, 0.0, -1.0]
fov_y = 60.0
near = 0.5
far = 20.0
[[mesh]]
kind = "plane"
size = 4.0
detail = 3
translate = [0.0, 0.0, -4.0]
rotate = [-70.0, 0.0, 0.0]
"#;

/// Every ChromaDepth row. `scene` is the benchmark's real-model scene (for the pass-vs-pair
/// timing), already sized.
///
/// # Errors
/// A scene that cannot be rendered.
pub fn rows(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let mut rows = texgen_modes(iters)?;
    rows.extend(ramp_sampling(iters, &[16, 256]));
    rows.extend(pass_vs_pair(scene, iters)?);
    rows.extend(glasses_and_terrain(scene, iters)?);
    Ok(rows)
}

fn row(knob: &str, setting: &str, error: Option<f64>, unit: &str, ms: f64, note: String) -> Row {
    Row {
        area: "chromadepth".into(),
        knob: knob.into(),
        setting: setting.into(),
        error,
        error_unit: unit.into(),
        ms,
        note,
    }
}

/// Hue error (degrees, `240° · |Δs|` after clamping) of each texgen mode against `s` from an
/// exact f64 ray–plane intersection at every pixel center, and the pass time.
pub(super) fn texgen_modes(iters: usize) -> Result<Vec<Row>> {
    let base = Scene::from_toml(
        SLANTED_PLANE,
        Path::new("<slanted plane>"),
        Path::new("."),
        &[],
    )?;
    let center = StereoRig::center(&base.camera, base.aspect())?;
    let settings = ChromaDepthSettings::default();
    let texgen = resolve_texgen(&base, &center, &settings)?;
    let reference = exact_plane_s(&base, texgen.d1 as f64, texgen.d2 as f64);
    let mut rows = Vec::new();
    for (name, mode, perspective_correct) in [
        ("per-pixel", TexgenMode::PerPixel, true),
        ("per-vertex", TexgenMode::PerVertex, true),
        ("per-vertex affine", TexgenMode::PerVertex, false),
    ] {
        let mut scene = base.clone();
        scene.raster.perspective_correct = perspective_correct;
        let s = ChromaDepthSettings {
            texgen: mode,
            ..settings.clone()
        };
        let map = texgen_map(&scene, &center, &s)?;
        let max_err = map
            .iter()
            .zip(&reference)
            .filter(|(a, _)| a.is_finite())
            .map(|(a, r)| (a.clamp(0.0, 1.0) as f64 - r.clamp(0.0, 1.0)).abs())
            .fold(0.0, f64::max)
            * FAR_HUE_DEGREES as f64;
        let ms = median_ms(iters, || render_center_with(&scene, &center, &s).is_ok());
        rows.push(row(
            "texgen",
            name,
            Some(max_err),
            "max hue error, deg",
            ms,
            format!(
                "plane slanted 70 deg, 1024x768, D1 {:.3} D2 {:.3}",
                texgen.d1, texgen.d2
            ),
        ));
    }
    Ok(rows)
}

/// `s` of the slanted plane at every pixel center from an f64 ray–plane intersection.
fn exact_plane_s(scene: &Scene, d1: f64, d2: f64) -> Vec<f64> {
    let view = scene.camera.view().as_dmat4();
    let model: DMat4 = scene.objects[0].model.as_dmat4();
    let modelview = view * model;
    let origin = modelview.transform_point3(DVec3::ZERO);
    let normal = modelview.transform_vector3(DVec3::Z);
    let tan = ((scene.camera.fov_y as f64).to_radians() * 0.5).tan();
    let (w, h) = (scene.width as f64, scene.height as f64);
    let mut out = Vec::with_capacity((scene.width * scene.height) as usize);
    for y in 0..scene.height {
        for x in 0..scene.width {
            let nx = (x as f64 + 0.5) / w * 2.0 - 1.0;
            let ny = 1.0 - (y as f64 + 0.5) / h * 2.0;
            let dir = DVec3::new(nx * tan * w / h, ny * tan, -1.0);
            // The ray t·dir meets the plane where (t·dir − origin)·normal = 0; dir.z = −1, so
            // t is the distance in front of the eye.
            let t = origin.dot(normal) / dir.dot(normal);
            out.push((t - d1) / (d2 - d1));
        }
    }
    out
}

/// Max hue error of the HSV ramp of each texel count sampled nearest and linear, against the
/// exact ramp, over 100 001 evenly spaced `s`; time for a million samples.
pub(super) fn ramp_sampling(iters: usize, texel_counts: &[usize]) -> Vec<Row> {
    const SAMPLES: usize = 100_000;
    let mut rows = Vec::new();
    for &texels in texel_counts {
        let Ok(r) = Ramp::new(RampKind::Hsv, texels) else {
            continue;
        };
        for (name, sampling) in [
            ("nearest", RampSampling::Nearest),
            ("linear", RampSampling::Linear),
        ] {
            let (mut hue_err, mut rgb_err) = (0.0f64, 0.0f32);
            for k in 0..=SAMPLES {
                let s = k as f32 / SAMPLES as f32;
                let got = r.sample(s, sampling);
                let want = ramp_exact(RampKind::Hsv, s);
                rgb_err = rgb_err.max((got - want).abs().max_element());
                if let Some(h) = hue_degrees(got) {
                    hue_err = hue_err.max((h as f64 - (FAR_HUE_DEGREES * s) as f64).abs());
                }
            }
            let ms = median_ms(iters, || {
                (0..1_000_000u32)
                    .map(|k| r.sample(k as f32 * 1e-6, sampling).x)
                    .sum::<f32>()
            });
            rows.push(row(
                "ramp sampling",
                &format!("{name}, {texels} texels"),
                Some(hue_err),
                "max hue error, deg",
                ms,
                format!(
                    "1M samples; max RGB error {:.4} ({:.2}/255)",
                    rgb_err,
                    rgb_err * 255.0
                ),
            ));
        }
    }
    rows
}

/// The ChromaDepth pass against the left + right color passes of the same scene, each pass run
/// on one thread: the CPU work a frame costs.
fn pass_vs_pair(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let center = StereoRig::center(&scene.camera, scene.aspect())?;
    let mut err: Option<Error> = None;
    let mut run = |f: &mut dyn FnMut() -> Result<()>| {
        median_ms(iters, || {
            if let Err(e) = f() {
                err = Some(e);
            }
        })
    };
    let pair_ms = run(&mut || {
        render_view(scene, &eyes[0], Shading::Color)?;
        render_view(scene, &eyes[1], Shading::Color)?;
        Ok(())
    });
    let one_ms = run(&mut || render_view(scene, &center, Shading::ChromaDepth).map(|_| ()));
    let mut lit = scene.clone();
    lit.chromadepth.lit = true;
    let lit_ms = run(&mut || render_view(&lit, &center, Shading::ChromaDepth).map(|_| ()));
    let phong_ms = run(&mut || render_view(scene, &center, Shading::Color).map(|_| ()));
    if let Some(e) = err {
        return Err(e);
    }
    let size = format!("{}x{}", scene.width, scene.height);
    Ok(vec![
        row(
            "one pass",
            "stereo pair (2 color passes)",
            None,
            "",
            pair_ms,
            format!("{size}, real model, sequential"),
        ),
        row(
            "one pass",
            "chromadepth (1 center pass)",
            None,
            "",
            one_ms,
            format!(
                "{size}; time ratio chromadepth/pair = {:.3}",
                one_ms / pair_ms
            ),
        ),
        row(
            "one pass",
            "lit chromadepth (1 pass)",
            None,
            "",
            lit_ms,
            format!("{size}; time ratio lit/pair = {:.3}", lit_ms / pair_ms),
        ),
        row(
            "one pass",
            "blinn-phong (1 center pass)",
            None,
            "",
            phong_ms,
            format!(
                "{size}; pass count alone: ratio {:.3}; the rest is the cheaper shader",
                phong_ms / pair_ms
            ),
        ),
    ])
}

/// The glasses simulation of a rendered ChromaDepth image, and triangulating the island.
fn glasses_and_terrain(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let center = StereoRig::center(&scene.camera, scene.aspect())?;
    let (fb, _) = render_view(scene, &center, Shading::ChromaDepth)?;
    let shift = scene.chromadepth.max_shift_px(fb.width());
    let glasses_ms = median_ms(iters, || glasses_pair(&fb, shift));
    let csv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/terrain/island.csv");
    let text = std::fs::read_to_string(&csv).map_err(|e| Error::io(&csv, e))?;
    let points = terrain::parse_csv(&csv, &text)?;
    let mut triangles = 0;
    let tri_ms = median_ms(iters, || {
        if let Ok(t) = terrain::triangulate(&csv, &points) {
            triangles = t.mesh.triangles.len();
        }
    });
    Ok(vec![
        row(
            "glasses",
            "left + right views",
            None,
            "",
            glasses_ms,
            format!("{}x{}, max shift {shift:.1} px", fb.width(), fb.height()),
        ),
        row(
            "terrain",
            "delaunay (spade)",
            None,
            "",
            tri_ms,
            format!(
                "island.csv: {} points -> {triangles} triangles",
                points.len()
            ),
        ),
    ])
}
