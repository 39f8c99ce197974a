//! The accuracy knobs of the report (`stereolab bench --report DIR`), each measured for error
//! and time in one run and returned as a generic [`Knob`]. The knobs the table of
//! `stereolab bench` already measures are taken from its rows ([`from_rows`]); the others
//! are measured here: subpixel bits against 16 bits and against lavapipe's 8, the rig in f32
//! against an f64 reference, the rig mode, the anaglyph in stored values against linear
//! light, the SIRDS disparity model, strip count, tessellation, start/filter, hidden-surface
//! removal and oversampling, and the thread count.
//!
//! Another benchmark group plugs in by building `Knob`s (a name, the error unit, the time
//! unit, its points as label / error / seconds, notes) and appending them in [`knobs`].

use glam::{DMat4, DVec4, Vec3};

use super::{Row, median_ms};
use stereolab::plan::{Output, Plan, Shading, View};
use stereolab::render::{render, render_view};
use stereolab::scene::{Mesh, Scene};
use stereolab_core::{
    AnaglyphKind, AnaglyphOptions, CameraMode, DisparityModel, Error, Eye, PerPixelOptions,
    PerVertexOptions, Result, Separation, SirdsAlgorithm, SirdsDecodeOptions, StripFilter,
    StripStart, anaglyph, decode_sirds, sirds_round_trip,
};
use stereolab_figures::plot::{Knob, Point};
use stereolab_figures::vertical_parallax_grid;

/// How big and how often: the full report, or the quick one a test runs.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// Image width of the real-model frames.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Repetitions per timing (the median is reported).
    pub iters: usize,
    /// Fewer settings per knob (the quick report).
    pub quick: bool,
}

fn point(label: impl Into<String>, error: f64, ms: f64) -> Point {
    Point {
        label: label.into(),
        error,
        seconds: ms * 1e-3,
    }
}

/// A knob from `stereolab bench` rows: every row with an error becomes a point (its setting
/// through `label`); `unit` says what the rows' error measures, with its unit.
// Each argument is one field of the knob's description; a struct for them would only rename them.
#[allow(clippy::too_many_arguments)]
pub fn from_rows(
    rows: &[Row],
    unit: &str,
    id: &str,
    title: &str,
    time_unit: &str,
    notes: &str,
    negligible: f64,
    label: impl Fn(&str) -> String,
) -> Knob {
    let rows: Vec<&Row> = rows.iter().filter(|r| r.error.is_some()).collect();
    Knob {
        id: id.into(),
        title: title.into(),
        error_unit: unit.into(),
        time_unit: time_unit.into(),
        points: rows
            .iter()
            .map(|r| point(label(&r.setting), r.error.unwrap_or(f64::NAN), r.ms))
            .collect(),
        notes: notes.into(),
        negligible,
    }
}

/// The `[raster] depth` knob (`bench --only depth`, [`super::depth`]) at two near/far ratios:
/// 1e6, where the standard depth buffer starts to lose decals, and 1e9, where it loses most of
/// them; one knob each, its points the four depth modes.
///
/// # Errors
/// As [`super::depth::measure`].
fn depth_modes(scale: Scale) -> Result<Vec<Knob>> {
    let rows = super::depth::measure(192, 128, scale.iters)?;
    let ratios: &[f64] = if scale.quick { &[1e6] } else { &[1e6, 1e9] };
    Ok(ratios
        .iter()
        .map(|&ratio| Knob {
            id: format!("depth_mode_{ratio:.0e}"),
            title: format!("raster: depth mode at near/far 1/{ratio:.0e}"),
            error_unit: "% of covered pixels wrong or lost".into(),
            time_unit: "one 192×128 pass of 24 triangles".into(),
            points: rows
                .iter()
                .filter(|r| r.ratio == ratio)
                .map(|r| point(r.setting.clone(), r.error, r.seconds * 1e3))
                .collect(),
            notes: format!(
                "Six decals, each 1/10 000 of its depth in front of a square (depths 2 to 90, \
                 far plane 100, near plane 100/{ratio:.0e}); error: pixels where a different \
                 square won or nothing was drawn, against the f64 reference (`src/reference`). \
                 Standard is lavapipe's depth; reversed-z stores n·f/(f−n)/w − n/(f−n) in f32."
            ),
            negligible: 0.01,
        })
        .collect())
}

/// Every knob of the report, in the order it prints them.
///
/// # Errors
/// The scene cannot be loaded or rendered, or a measurement fails.
pub fn knobs(scene: &Scene, scale: Scale) -> Result<Vec<Knob>> {
    let it = scale.iters;
    let size = format!("{}×{}", scene.width, scene.height);
    let mut out = subpixel_bits(scene, scale)?;
    out.push(from_rows(
        &super::perspective_correction(it)?,
        "max uv error (texture coordinates, 0..1)",
        "varyings",
        "raster: perspective-correct vs affine varyings",
        "one 1024×768 pass of a 2-triangle plane",
        "A 4×4 plane slanted 70° away, its texture coordinates written per pixel; error: the \
         largest difference of u or v against perspective-correct interpolation.",
        1e-3,
        str::to_string,
    ));
    out.push(from_rows(
        &super::chromadepth::texgen_modes(it)?,
        "max hue error (degrees)",
        "chromadepth_texgen",
        "ChromaDepth: texgen per pixel vs per vertex",
        "one 1024×768 ChromaDepth pass",
        "The slanted plane again; error: the hue each pixel gets against the hue of its exact \
         depth from an f64 ray–plane intersection (240° spans D1..D2).",
        1.0,
        str::to_string,
    ));
    let texels: &[usize] = if scale.quick {
        &[16, 256]
    } else {
        &[4, 16, 64, 256, 1024]
    };
    out.push(from_rows(
        &super::chromadepth::ramp_sampling(it, texels),
        "max hue error (degrees)",
        "chromadepth_ramp",
        "ChromaDepth: ramp texels and sampling",
        "10⁶ ramp samples",
        "The HSV ramp stored as N texels and sampled nearest or linear, against the exact \
         ramp at 100 001 evenly spaced s; error: the largest hue difference.",
        1.0,
        str::to_string,
    ));
    out.push(anaglyph_light(scene, it)?);
    let (remap_near, remap_deep) = super::finalize::remap_precision(scene, it)?;
    let remap_label = |s: &str| {
        s.split(", near/far")
            .next()
            .unwrap_or(s)
            .replace("the exercise slides", "(slides)")
    };
    out.push(from_rows(
        &remap_near,
        "max texture-coordinate error (1 = image width)",
        "remap_precision",
        "remap: f32 vs f64 unprojection, near/far = 1/20",
        &format!("remapping one {size} eye"),
        "The left eye remapped into the right through MVP_r·MVP_l⁻¹ (the exercise slides' \
         shader in f32, the composed matrix in f32, and f64); error: the largest texture \
         coordinate difference to f64 over drawn pixels (1/width is one pixel).",
        1e-4,
        remap_label,
    ));
    out.push(from_rows(
        &remap_deep,
        "max texture-coordinate error (1 = image width)",
        "remap_precision_deep",
        "remap: f32 vs f64 unprojection, near/far = 1e-5",
        &format!("remapping one {size} eye"),
        "As above with camera.near = camera.far · 1e-5, where window depth crowds against 1 \
         and f32 unprojection loses digits.",
        1e-4,
        remap_label,
    ));
    out.extend(depth_modes(scale)?);
    out.push(rig_precision(scene, 0.0, it)?);
    out.push(rig_precision(scene, 1e5, it)?);
    out.push(rig_mode(scene, it)?);
    out.extend(sirds_knobs(scale)?);
    out.push(threads(scene, it)?);
    Ok(out)
}

/// Coverage of the real model's left eye at 2…16 subpixel bits, against 16 bits (closest to
/// the exact geometry) and against 8 bits (lavapipe's: the CPU path at 8 bits matches it
/// pixel for pixel, see docs/gpu-parity.md): two knobs from the same renders.
fn subpixel_bits(scene: &Scene, scale: Scale) -> Result<Vec<Knob>> {
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    let bits: &[u32] = if scale.quick {
        &[4, 8, 16]
    } else {
        &[2, 4, 6, 8, 10, 12, 16]
    };
    let mut runs = Vec::new();
    for &b in bits {
        let mut s = scene.clone();
        s.raster.subpixel_bits = b;
        let (fb, _) = render_view(&s, &eyes[0], Shading::DepthOnly)?;
        let cov: Vec<bool> = fb.depth().iter().map(|d| *d < 1.0).collect();
        let ms = median_ms(scale.iters, || {
            render_view(&s, &eyes[0], Shading::DepthOnly).is_ok()
        });
        runs.push((b, cov, ms));
    }
    let knob = |reference: u32, id: &str, title: &str, notes: &str| -> Result<Knob> {
        let Some((_, want, _)) = runs.iter().find(|r| r.0 == reference) else {
            return Err(Error::internal("subpixel bits", "reference not measured"));
        };
        let points = runs
            .iter()
            .map(|(b, cov, ms)| {
                let diff = cov.iter().zip(want).filter(|(a, b)| a != b).count();
                point(
                    format!("{b} bits"),
                    diff as f64 / want.len() as f64 * 100.0,
                    *ms,
                )
            })
            .collect();
        Ok(Knob {
            id: id.into(),
            title: title.into(),
            error_unit: format!("pixels differing from {reference} bits (%)"),
            time_unit: format!("one {}×{} depth pass", scene.width, scene.height),
            points,
            notes: notes.into(),
            negligible: 0.0,
        })
    };
    Ok(vec![
        knob(
            16,
            "subpixel_bits",
            "raster: subpixel bits against the geometry (16 bits)",
            "The real model's left eye, depth only; error: the share of pixels whose coverage \
             differs from 16 subpixel bits, the closest to the exact triangle edges.",
        )?,
        knob(
            8,
            "subpixel_bits_lavapipe",
            "raster: subpixel bits against lavapipe's coverage (8 bits)",
            "The same renders; error: the share of pixels whose coverage differs from 8 bits, \
             which is what lavapipe (llvmpipe's fixed point) covers: at 8 bits the CPU path \
             matches it pixel for pixel (docs/gpu-parity.md).",
        )?,
    ])
}

/// The off-axis eye's MVP in f64 from the same scene fields the f32 rig reads (the
/// StereoGraphics guide's `FrustumAsymmetry = −offset · balance · n / z0`, the exercise
/// slides' frustum), for one `eye`.
///
/// # Errors
/// A rig that is not off-axis (the reference covers the mode the renderer defaults to).
pub fn off_axis_mvp_f64(scene: &Scene, eye: Eye) -> Result<DMat4> {
    if scene.rig.mode != CameraMode::OffAxis {
        return Err(Error::invalid(
            "stereo.mode",
            format!("{:?}", scene.rig.mode),
            "the f64 reference rig is off-axis only",
        ));
    }
    let c = &scene.camera;
    let aspect = f64::from(scene.width) / f64::from(scene.height);
    let tan = (f64::from(c.fov_y).to_radians() * 0.5).tan();
    let z0 = stereolab_core::zero_parallax_f64(&scene.rig, c);
    let base = match scene.rig.separation {
        Separation::Absolute(d) => f64::from(d),
        Separation::Auto => 2.0 * (2.0 * z0 * tan * aspect) * 0.035,
    };
    // The rig in f64 (`stereolab_core::eye_matrices_f64`), with the separation resolved in f64 as above.
    Ok(stereolab_core::eye_matrices_f64(
        &scene.rig,
        c,
        aspect,
        base * f64::from(scene.rig.user_offset),
        z0,
        eye,
    ))
}

/// Window x, y (pixels) of every vertex of every object in both eyes, for the three ways
/// of computing them; `None` behind an eye.
fn window_positions(scene: &Scene, way: u8) -> Result<Vec<Option<(f64, f64)>>> {
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    let (w, h) = (f64::from(scene.width), f64::from(scene.height));
    let win =
        |c: DVec4| (c.w > 0.0).then(|| ((c.x / c.w + 1.0) * 0.5 * w, (1.0 - c.y / c.w) * 0.5 * h));
    let mut out = Vec::new();
    for (e, eye) in eyes.iter().zip(Eye::BOTH) {
        let mvp64 = off_axis_mvp_f64(scene, eye)?;
        for o in &scene.objects {
            let m32 = e.mvp * o.model;
            let m64 = mvp64 * o.model.as_dmat4();
            let m32_in_64 = m32.as_dmat4();
            for p in &o.mesh.positions {
                let c = match way {
                    // f32 matrices, f32 arithmetic: what the renderer does.
                    0 => (m32 * p.extend(1.0)).as_dvec4(),
                    // f32 matrices, f64 arithmetic.
                    1 => m32_in_64 * p.as_dvec3().extend(1.0),
                    // The f64 rig and f64 arithmetic: the reference.
                    _ => m64 * p.as_dvec3().extend(1.0),
                };
                out.push(win(c));
            }
        }
    }
    Ok(out)
}

/// The rig and vertex transform in f32 against the f64 reference, on the scene as it is and
/// moved `offset` world units from the origin (camera and model together).
fn rig_precision(scene: &Scene, offset: f32, iters: usize) -> Result<Knob> {
    let mut s = scene.clone();
    if offset != 0.0 {
        for a in [&mut s.camera.eye, &mut s.camera.target] {
            a[0] += offset;
        }
        for o in &mut s.objects {
            o.model = glam::Mat4::from_translation(Vec3::new(offset, 0.0, 0.0)) * o.model;
        }
    }
    let reference = window_positions(&s, 2)?;
    let mut points = Vec::new();
    for (way, label) in [
        (0, "f32 rig, f32 transform (the renderer)"),
        (1, "f32 rig, f64 transform"),
        (2, "f64 rig, f64 transform (reference)"),
    ] {
        let got = window_positions(&s, way)?;
        let err = got
            .iter()
            .zip(&reference)
            .map(|(a, b)| match (a, b) {
                (Some(a), Some(b)) => (a.0 - b.0).abs().max((a.1 - b.1).abs()),
                (None, None) => 0.0,
                _ => f64::INFINITY,
            })
            .fold(0.0, f64::max);
        let ms = median_ms(iters, || window_positions(&s, way).map(|v| v.len()));
        points.push(point(label, err, ms));
    }
    let (id, title, where_) = if offset == 0.0 {
        (
            "rig_precision",
            "rig: f32 vs f64 eye matrices and transform".to_string(),
            "the real model as the scene places it".to_string(),
        )
    } else {
        (
            "rig_precision_far",
            format!("rig: f32 vs f64, scene {offset:.0e} units from the origin"),
            format!("the real model and camera moved {offset:.0e} world units along x"),
        )
    };
    Ok(Knob {
        id: id.into(),
        title,
        error_unit: "max vertex position error (px)".into(),
        time_unit: "both eyes' matrices + every vertex".into(),
        points,
        notes: format!(
            "Every vertex of {where_} projected into both eyes at {}×{}; error: the largest \
             window-position difference to the off-axis rig computed in f64 from the same \
             scene fields. The time includes building the f64 rig for comparison's sake, so \
             read the ratio between settings, not the absolute time.",
            s.width, s.height
        ),
        negligible: 0.01,
    })
}

/// Off-axis, parallel and toe-in: how far each eye's image of the zero-parallax plane lies
/// from where the off-axis rig (the source documents' correct one) puts it, and the stereo
/// pair's time.
fn rig_mode(scene: &Scene, iters: usize) -> Result<Knob> {
    use stereolab_core::{StereoRig, project_ndc};
    let plan = Plan::new(&[Output::Left, Output::Right]);
    let rig_of = |mode| StereoRig { mode, ..scene.rig };
    let reference = rig_of(CameraMode::OffAxis).eyes(&scene.camera, scene.aspect())?;
    let r = scene.rig.resolve(&scene.camera, scene.aspect())?;
    let inv = scene.camera.view().inverse();
    let (hw, hh) = scene.camera.near_half_extents(scene.aspect());
    let k = r.zero_parallax_distance / scene.camera.near;
    let (w, h) = (f64::from(scene.width), f64::from(scene.height));
    let mut points = Vec::new();
    for (mode, label) in [
        (CameraMode::OffAxis, "off-axis"),
        (CameraMode::Parallel, "parallel"),
        (CameraMode::ToeIn, "toe-in"),
    ] {
        let eyes = rig_of(mode).eyes(&scene.camera, scene.aspect())?;
        let mut worst = 0.0f64;
        for row in 0..12 {
            for col in 0..16 {
                let nx = 2.0 * (col as f32 + 0.5) / 16.0 - 1.0;
                let ny = 1.0 - 2.0 * (row as f32 + 0.5) / 12.0;
                let p = inv.transform_point3(Vec3::new(
                    nx * hw * k,
                    ny * hh * k,
                    -r.zero_parallax_distance,
                ));
                for i in 0..2 {
                    let got = project_ndc(&eyes[i].mvp, p);
                    let want = project_ndc(&reference[i].mvp, p);
                    let d = match (got, want) {
                        (Some(a), Some(b)) => (f64::from(a.x - b.x) * 0.5 * w)
                            .abs()
                            .max((f64::from(a.y - b.y) * 0.5 * h).abs()),
                        _ => f64::INFINITY,
                    };
                    worst = worst.max(d);
                }
            }
        }
        let mut s = scene.clone();
        s.rig.mode = mode;
        render(&s, &plan)?;
        let ms = median_ms(iters, || render(&s, &plan).is_ok());
        points.push(point(label, worst, ms));
    }
    let toe_in = vertical_parallax_grid(scene, CameraMode::ToeIn, 16, 12)?
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs()));
    Ok(Knob {
        id: "rig_mode".into(),
        title: "stereo camera: off-axis vs parallel vs toe-in".into(),
        error_unit: "max image displacement from off-axis (px)".into(),
        time_unit: format!("one {}×{} stereo pair", scene.width, scene.height),
        points,
        notes: format!(
            "16×12 points of the zero-parallax plane projected by each rig's eyes, against \
             where the off-axis rig (parallel axes, asymmetric frusta: the StereoGraphics \
             guide, the exercise slides) puts them. Parallel cameras without an image shift \
             put zero parallax at infinity (every point in front of the screen); toe-in adds \
             vertical parallax (up to {toe_in:.2} px here, eye strain)."
        ),
        negligible: 0.01,
    })
}

/// Each anaglyph in stored (gamma-encoded) values against the same matrices in linear light.
fn anaglyph_light(scene: &Scene, iters: usize) -> Result<Knob> {
    let frame = render(scene, &Plan::new(&[Output::Left, Output::Right]))?;
    let (Some(left), Some(right)) = (frame.view(View::Left), frame.view(View::Right)) else {
        return Err(Error::internal("anaglyph bench", "eye views missing"));
    };
    let mut points = Vec::new();
    for kind in [AnaglyphKind::DuboisRedCyan] {
        let run = |linear_light| {
            anaglyph(
                left,
                right,
                kind,
                AnaglyphOptions {
                    linear_light,
                    swap_eyes: false,
                    anti_rivalry: false,
                },
            )
        };
        let linear = run(true)?;
        for linear_light in [false, true] {
            let img = run(linear_light)?;
            let sum: u64 = img
                .as_raw()
                .iter()
                .zip(linear.as_raw())
                .map(|(a, b)| u64::from(a.abs_diff(*b)))
                .sum();
            let mean = sum as f64 / (left.color().len() * 3) as f64;
            let ms = median_ms(iters, || run(linear_light).is_ok());
            let how = if linear_light { "linear" } else { "stored" };
            points.push(point(format!("{} {how}", kind.output_name()), mean, ms));
        }
    }
    Ok(Knob {
        id: "anaglyph_light".into(),
        title: "anaglyph (Dubois): stored values vs linear light".into(),
        error_unit: "mean channel difference (8-bit levels)".into(),
        time_unit: format!("one {}×{} anaglyph", scene.width, scene.height),
        points,
        notes: "The real model's stereo pair mixed by Dubois' red–cyan matrices on the \
                stored (sRGB-encoded) values and in linear light (decoded, mixed, encoded \
                again); error: the mean difference to the linear-light mix, over all channels \
                of all pixels."
            .into(),
        negligible: 0.5,
    })
}

/// Decode error (RMS decoded separation against `intended`, px) and time of the SIRDS of
/// scene `s`.
fn sirds_point(s: &Scene, intended_from: Option<&Scene>, iters: usize) -> Result<(f64, f64)> {
    use stereolab::output::sirds::{from_frame, scene_depth};
    let frame = render(s, &Plan::new(&[Output::Sirds]))?;
    let (depth, _) = scene_depth(&frame, s)?;
    let sirds = from_frame(&frame, s)?;
    let d = sirds.disparity;
    let opts = SirdsDecodeOptions::for_disparity(&d);
    let decoded = decode_sirds(&sirds.pixels, sirds.width, sirds.height, &opts)?;
    let want = match intended_from {
        Some(r) => r.sirds.geometry.to_pixels()?,
        None => d,
    };
    let intended: Vec<f32> = depth.z.iter().map(|&z| want.separation(z)).collect();
    let rt = sirds_round_trip(&decoded, &intended, &opts);
    let ms = median_ms(iters, || from_frame(&frame, s).is_ok());
    Ok((rt.rms, ms))
}

/// The SIRDS knobs on the Fig. 5 ramp (a plane turned 35°, 512×256).
fn sirds_knobs(scale: Scale) -> Result<Vec<Knob>> {
    let it = scale.iters.min(5);
    let base = super::sirds::ramp_scene()?;
    let unit = "rms decoded separation error (px)";
    let time = "one 512×256 SIRDS from its depth pass";
    let knob = |id: &str, title: &str, points, notes: &str, negligible| Knob {
        id: id.into(),
        title: title.into(),
        error_unit: unit.into(),
        time_unit: time.into(),
        points,
        notes: format!(
            "{notes} Error: the SIRDS decoded back to separations (a bounded search per \
             pixel), RMS against the separation the depth map asks for."
        ),
        negligible,
    };
    let mut out = Vec::new();
    // Start strip and filter.
    let mut pts = Vec::new();
    for (start, filter) in [
        (StripStart::Left, StripFilter::Nearest),
        (StripStart::Left, StripFilter::Bilinear),
        (StripStart::Center, StripFilter::Nearest),
        (StripStart::Center, StripFilter::Bilinear),
    ] {
        let mut s = base.clone();
        s.sirds.per_vertex = PerVertexOptions {
            start,
            filter,
            ..PerVertexOptions::default()
        };
        let (e, ms) = sirds_point(&s, None, it)?;
        pts.push(point(
            format!(
                "{} start, {}",
                format!("{start:?}").to_lowercase(),
                format!("{filter:?}").to_lowercase()
            ),
            e,
            ms,
        ));
    }
    out.push(knob(
        "sirds_start_filter",
        "SIRDS strips: start strip and filtering",
        pts,
        "The SIRDS paper's strip algorithm, the pattern strip at the left edge or in the \
         center (§4), sampling the previous strip nearest or bilinear (Fig. 5).",
        0.5,
    ));
    // Strip count k.
    let ks: &[Option<u32>] = if scale.quick {
        &[None, Some(16)]
    } else {
        &[None, Some(10), Some(12), Some(16), Some(24), Some(32)]
    };
    let mut pts = Vec::new();
    let mut refused = Vec::new();
    for &k in ks {
        let mut s = base.clone();
        s.sirds.per_vertex.iterations = k;
        let label = k.map_or("k = fewest (auto)".to_string(), |k| format!("k = {k}"));
        match sirds_point(&s, None, it) {
            Ok((e, ms)) => pts.push(point(label, e, ms)),
            Err(e) => refused.push(format!("{label}: {e}")),
        }
    }
    out.push(knob(
        "sirds_strip_count",
        "SIRDS strips: strip count k",
        pts,
        &format!(
            "The strip algorithm with k iterations (strip width ⌈W/k⌉; the fewest is what the \
             front separation allows).{}",
            if refused.is_empty() {
                String::new()
            } else {
                format!(" Refused: {}.", refused.join("; "))
            }
        ),
        0.5,
    ));
    // Tessellation of the plane: the per-vertex algorithm shifts vertices, so separation is
    // linear across each triangle while eq. 3 is not.
    let details: &[u32] = if scale.quick {
        &[1, 8]
    } else {
        &[1, 2, 4, 8, 16, 32, 64]
    };
    let mut pts = Vec::new();
    for &n in details {
        let mut s = base.clone();
        s.objects[0].mesh = Mesh::plane(20.0, n);
        let (e, ms) = sirds_point(&s, None, it)?;
        pts.push(point(
            format!("{n}×{n} quads ({} triangles)", 2 * n * n),
            e,
            ms,
        ));
    }
    out.push(knob(
        "sirds_tessellation",
        "SIRDS strips: tessellation of large triangles",
        pts,
        "The ramp plane cut into n×n quads. The strip algorithm interpolates separation \
         linearly across each triangle, eq. 3 is not linear in depth: the piecewise-linear \
         depth error large triangles carry.",
        0.5,
    ));
    // Disparity model: eq. 1 against eq. 3 (the viewer's eyes).
    let mut pts = Vec::new();
    for (model, label) in [
        (DisparityModel::EyeDistance, "eq. 3, constant eye distance"),
        (DisparityModel::ViewAngle, "eq. 1, constant view angle"),
    ] {
        let mut s = base.clone();
        s.sirds.geometry.model = model;
        let (e, ms) = sirds_point(&s, Some(&base), it)?;
        pts.push(point(label, e, ms));
    }
    out.push(knob(
        "sirds_model",
        "SIRDS: disparity model eq. 1 vs eq. 3",
        pts,
        "The same depth encoded with the SIRDS paper's eq. 1 (d = 2t / tan φ, linear in depth) \
         and eq. 3 (d = a t / (t + f), the geometry of two eyes at distance a). Error against \
         eq. 3's separations: what a viewer's eyes would need.",
        0.5,
    ));
    // TIW: hidden-surface removal, and oversampling.
    let tiw = |hidden_surface, oversample| -> Result<(f64, f64)> {
        let mut s = base.clone();
        s.sirds.algorithm = SirdsAlgorithm::PerPixel;
        s.sirds.per_pixel = PerPixelOptions {
            hidden_surface,
            oversample,
            ..PerPixelOptions::default()
        };
        sirds_point(&s, None, it)
    };
    let mut pts = Vec::new();
    for hsr in [false, true] {
        let (e, ms) = tiw(hsr, 1)?;
        pts.push(point(if hsr { "with hsr" } else { "without hsr" }, e, ms));
    }
    out.push(knob(
        "sirds_hidden_surface",
        "SIRDS per pixel (TIW): hidden-surface removal",
        pts,
        "Thimbleby–Inglis–Witten on the depth map, with and without its hidden-surface \
         removal (a point one eye cannot see is not linked).",
        0.5,
    ));
    let mut pts = Vec::new();
    for x in if scale.quick {
        &[1, 2][..]
    } else {
        &[1, 2, 4][..]
    } {
        let (e, ms) = tiw(true, *x)?;
        pts.push(point(format!("oversample ×{x}"), e, ms));
    }
    out.push(knob(
        "sirds_oversample",
        "SIRDS per pixel (TIW): horizontal oversampling",
        pts,
        "TIW linking on a row oversampled ×n (finer separations, the dots averaged back).",
        0.5,
    ));
    Ok(out)
}

/// The stereo pair on 1, 2 and 4 threads: same bytes (the error, to be 0), and the time.
fn threads(scene: &Scene, iters: usize) -> Result<Knob> {
    let plan = Plan::new(&[Output::Left, Output::Right]);
    let mut reference: Option<Vec<u8>> = None;
    let mut points = Vec::new();
    for n in [1usize, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::internal("thread pool", e.to_string()))?;
        let bytes = pool.install(|| -> Result<Vec<u8>> {
            let f = render(scene, &plan)?;
            let mut b = Vec::new();
            for v in [View::Left, View::Right] {
                if let Some(fb) = f.view(v) {
                    b.extend(fb.color().iter().flatten());
                    b.extend(fb.depth().iter().flat_map(|d| d.to_le_bytes()));
                }
            }
            Ok(b)
        })?;
        let want = reference.get_or_insert_with(|| bytes.clone());
        let diff = bytes
            .iter()
            .zip(want.iter())
            .filter(|(a, b)| a != b)
            .count()
            + bytes.len().abs_diff(want.len());
        let ms = pool.install(|| median_ms(iters, || render(scene, &plan).is_ok()));
        points.push(point(
            format!("{n} thread{}", if n == 1 { "" } else { "s" }),
            diff as f64,
            ms,
        ));
    }
    Ok(Knob {
        id: "threads".into(),
        title: "thread count (rayon pool size)".into(),
        error_unit: "bytes differing from 1 thread".into(),
        time_unit: format!("one {}×{} stereo pair", scene.width, scene.height),
        points,
        notes: format!(
            "The real model's stereo pair (color and depth of both eyes) rendered in a pool of \
             n threads; error: bytes that differ from the one-thread render (determinism says \
             0). This machine has {} hardware threads.",
            std::thread::available_parallelism().map_or(0, |n| n.get())
        ),
        negligible: 0.0,
    })
}
