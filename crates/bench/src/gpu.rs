//! The `gpu` group: the CPU path beside the wgpu path (lavapipe without a GPU), as ratios in
//! the same run: the stereo pair, pair + anaglyph, each WGSL finalize pass beside its CPU
//! function on identical eye framebuffers, and the SIRDS strips of the paper's Table 1 row 1.

use super::{Row, interleaved_medians, median_ms};
use stereolab::compare::{compare, framebuffer_from_image};
use stereolab::plan::View;
use stereolab::render::Frame;
use stereolab::scene::Scene;
use stereolab_core::{
    AnaglyphKind, AnaglyphOptions, Precision, Result, anaglyph, occlusion_image, parallax_image,
    remap_color,
};

use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan, Shading};
use stereolab::render::render;
use stereolab_core::StripGeometry;
use stereolab_gpu::parity::compare_frames;
use stereolab_gpu::sirds::GpuStrips;
use stereolab_gpu::{GpuFinalize, GpuRenderer, GpuScene};

/// One effect: its name, the CPU function and the GPU function, each returning an image.
type Effect<'a> = (
    &'static str,
    Box<dyn Fn() -> Result<image::RgbaImage> + 'a>,
    Box<dyn Fn() -> Result<image::RgbaImage> + 'a>,
);

/// Dubois anaglyph, remap (left from right), parallax color and occlusion on `frame`'s eyes:
/// per effect a CPU row and a GPU row (error: the largest channel difference against the CPU,
/// 8-bit levels). Remap and occlusion use `Precision::F32Composed` on both sides (the GPU's
/// arithmetic); the CPU parallax image includes its tiny-skia legend, the GPU's does not.
///
/// # Errors
/// An effect fails on either path.
fn finalize_rows(r: &GpuRenderer, frame: &Frame, scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let (Some(left), Some(right)) = (frame.view(View::Left), frame.view(View::Right)) else {
        return Ok(Vec::new());
    };
    let fin = GpuFinalize::new(r)?;
    let mvps = [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp];
    let rig = scene.parallax_rig()?;
    let kind = AnaglyphKind::DuboisRedCyan;
    let opts = AnaglyphOptions::default();
    let crop = |img: image::RgbaImage| {
        image::imageops::crop_imm(&img, 0, 0, left.width(), left.height()).to_image()
    };
    let effects: Vec<Effect> = vec![
        (
            "anaglyph dubois",
            Box::new(|| anaglyph(left, right, kind, opts)),
            Box::new(|| fin.anaglyph(r, left, right, kind, opts)),
        ),
        (
            "remap_left",
            Box::new(|| remap_color(left, right, mvps[0], mvps[1], Precision::F32Composed)),
            Box::new(|| fin.remap_color(r, left, right, mvps[0], mvps[1])),
        ),
        (
            "parallax",
            Box::new(|| parallax_image(left, &rig)),
            Box::new(|| fin.parallax(r, left, &rig).map(|(_, img)| img)),
        ),
        (
            "occlusion",
            Box::new(|| occlusion_image(left, right, mvps, Precision::F32Composed)),
            Box::new(|| fin.occlusion_image(r, left, right, mvps)),
        ),
    ];
    let size = format!("{}x{}", left.width(), left.height());
    let mut rows = Vec::new();
    for (name, cpu, gpu) in effects {
        let (c, g) = (cpu()?, gpu()?);
        let c = if name == "parallax" { crop(c) } else { c };
        let metrics = compare(
            &framebuffer_from_image(&c, scene.background)?,
            &framebuffer_from_image(&g, scene.background)?,
        )?;
        let mut failed = None;
        let cpu_ms = median_ms(iters, || cpu().map_err(|e| failed = Some(e)));
        let gpu_ms = median_ms(iters, || gpu().map_err(|e| failed = Some(e)));
        if let Some(e) = failed {
            return Err(e);
        }
        let row = |setting: String, error, ms, note: String| Row {
            area: "gpu parity".into(),
            knob: "finalize (identical eyes)".into(),
            setting,
            error,
            error_unit: "max level vs cpu".into(),
            ms,
            note,
        };
        rows.push(row(
            format!("cpu {name}"),
            Some(0.0),
            cpu_ms,
            format!("{size}; cpu/gpu time = {:.2}", cpu_ms / gpu_ms),
        ));
        rows.push(row(
            format!("{} {name}", r.short_name()),
            Some(metrics.max_channel_diff as f64),
            gpu_ms,
            format!("{size}; upload + WGSL pass + readback"),
        ));
    }
    Ok(rows)
}

/// The stereo pair of `scene` on the CPU path and on the GPU, whole frame including readback
/// into framebuffers (meshes uploaded once, outside the timing), as a ratio in the same run.
/// Without an adapter the row says so instead of timing anything.
///
/// # Errors
/// Rendering fails on either path.
pub fn rows(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let plan = Plan::new(&[Output::Left, Output::Right]);
    let size = format!("{}x{}", scene.width, scene.height);
    let row = |setting: String, error, ms, note: String| Row {
        area: "gpu parity".into(),
        knob: "backend".into(),
        setting,
        error,
        error_unit: "% coverage vs cpu".into(),
        ms,
        note,
    };
    let r = match GpuRenderer::new() {
        Ok(r) => r,
        Err(e) => {
            return Ok(vec![row(
                "gpu".into(),
                None,
                f64::NAN,
                format!("not measured: {e}"),
            )]);
        }
    };
    let gpu_scene = GpuScene::upload(&r, scene)?;
    let cpu = render(scene, &plan)?;
    let gpu = r.render(&gpu_scene, &plan)?;
    let worst = compare_frames(&cpu, &gpu, scene, None)?
        .iter()
        .map(|c| c.metrics.coverage_mismatch_percent())
        .fold(0.0, f64::max);
    let mut failed = None;
    let cpu_ms = median_ms(iters, || render(scene, &plan).map_err(|e| failed = Some(e)));
    let gpu_ms = median_ms(iters, || {
        r.render(&gpu_scene, &plan).map_err(|e| failed = Some(e))
    });
    if let Some(e) = failed {
        return Err(e);
    }
    let ratio = cpu_ms / gpu_ms;
    let mut rows = vec![
        row(
            "cpu".into(),
            Some(0.0),
            cpu_ms,
            format!("stereo pair {size}, cpu/gpu time = {ratio:.2}"),
        ),
        row(
            r.short_name(),
            Some(worst),
            gpu_ms,
            format!("stereo pair {size} incl. readback; {}", r.adapter_name()),
        ),
    ];
    rows.extend(pair_and_anaglyph(&r, &gpu_scene, scene, iters)?);
    rows.extend(finalize_rows(&r, &cpu, scene, iters)?);
    rows.extend(sirds_rows(&r, iters)?);
    Ok(rows)
}

/// The stereo pair + Dubois anaglyph frame with the eyes kept on the GPU, timed round-robin in one run:
/// - the CPU path (passes + `anaglyph`);
/// - the GPU path through the host, as `render --backend gpu` makes it: passes, readback of
///   both eyes (color and depth), then the WGSL anaglyph pass with its upload and readback;
/// - the GPU path with the eyes on the GPU ([`GpuRenderer::render_resident`]): the anaglyph
///   folded into the eye passes, one submission, one readback of the anaglyph's color; and the
///   same frame with the anaglyph as a full-screen pass over the eye textures (the route of a
///   frame with several outputs, and of this one before the fold);
/// - the yardsticks: the GPU stereo pair alone (with its readback into framebuffers, the
///   `backend` row), the same passes with no readback at all (the floor), and the plain wgpu
///   program of [`super::gpu_oneshot`].
///
/// The goal rows' notes carry the ratios; the resident row's error is against the CPU and its
/// note says whether its bytes equal the host route's.
fn pair_and_anaglyph(
    r: &GpuRenderer,
    gpu_scene: &GpuScene,
    scene: &Scene,
    iters: usize,
) -> Result<Vec<Row>> {
    let output = Output::Anaglyph(AnaglyphKind::DuboisRedCyan);
    let plan = Plan::new(&[output]);
    let pair = Plan::new(&[Output::Left, Output::Right]);
    let fin = GpuFinalize::new(r)?;
    let cpu_frame = || -> Result<Image> { produce(output, &render(scene, &plan)?, scene) };
    let host_frame = || -> Result<image::RgbaImage> {
        let frame = r.render(gpu_scene, &plan)?;
        stereolab_gpu::effects::produce_wgsl(r, &fin, output, &frame, scene)?
            .ok_or_else(|| stereolab_core::Error::internal("anaglyph", "no WGSL pass"))
    };
    let resident_frame = || -> Result<image::RgbaImage> {
        r.render_resident(gpu_scene, &fin, &[output])?
            .pop()
            .ok_or_else(|| stereolab_core::Error::internal("anaglyph", "no image came back"))
    };
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    let oneshot = super::gpu_oneshot::OneShot::new(scene, &eyes)?;
    let cpu = match cpu_frame()? {
        Image::Rgba(img) => framebuffer_from_image(&img, scene.background)?,
        _ => {
            return Err(stereolab_core::Error::internal(
                "anaglyph",
                "not an RGBA image",
            ));
        }
    };
    let host = host_frame()?;
    let resident = resident_frame()?;
    let identical = host == resident;
    let fb = |img: &image::RgbaImage| framebuffer_from_image(img, scene.background);
    let host_diff = compare(&cpu, &fb(&host)?)?.max_channel_diff;
    let resident_diff = compare(&cpu, &fb(&resident)?)?.max_channel_diff;
    let ms = interleaved_medians(
        iters,
        1,
        &mut [
            &mut || cpu_frame().map(drop),
            &mut || host_frame().map(drop),
            &mut || resident_frame().map(drop),
            &mut || r.render(gpu_scene, &pair).map(drop),
            &mut || r.render_without_readback(gpu_scene, &pair),
            &mut || oneshot.frame().map(drop),
            &mut || r.resident(gpu_scene, &fin, &[output], false).map(drop),
        ],
    )?;
    let [
        cpu_ms,
        host_ms,
        resident_ms,
        pair_ms,
        floor_ms,
        oneshot_ms,
        fullscreen_ms,
    ] = ms[..]
    else {
        return Err(stereolab_core::Error::internal(
            "bench",
            "seven timings expected",
        ));
    };
    let size = format!("{}x{}", scene.width, scene.height);
    let gpu = r.short_name();
    let row = |setting: String, error: Option<u8>, ms: f64, note: String| Row {
        area: "gpu parity".into(),
        knob: "pair + anaglyph".into(),
        setting,
        error: error.map(f64::from),
        error_unit: "max level vs cpu".into(),
        ms,
        note,
    };
    Ok(vec![
        row(
            "cpu".into(),
            Some(0),
            cpu_ms,
            format!(
                "stereo pair + Dubois anaglyph {size}; cpu/{gpu} resident time = {:.2}",
                cpu_ms / resident_ms
            ),
        ),
        row(
            format!("{gpu}, eyes via host"),
            Some(host_diff),
            host_ms,
            format!(
                "{size}: passes + readback of both eyes + WGSL anaglyph (upload, pass, \
                 readback); / pair alone = {:.2}",
                host_ms / pair_ms
            ),
        ),
        row(
            format!("{gpu}, eyes on gpu"),
            Some(resident_diff),
            resident_ms,
            format!(
                "{size}: the anaglyph folded into the eye passes (WGSL), 1 submission, 1 \
                 readback of the anaglyph; / pair alone = {:.2} (goal <= 1.2), / wgpu one \
                 submission = {:.2} (goal <= 1.1); bytes {} the host route's",
                resident_ms / pair_ms,
                resident_ms / oneshot_ms,
                if identical {
                    "identical to"
                } else {
                    "DIFFER from"
                }
            ),
        ),
        row(
            format!("{gpu} pair alone"),
            None,
            pair_ms,
            format!("{size}: both eye passes + readback of color and depth (the backend row)"),
        ),
        row(
            format!("{gpu} pair, no readback"),
            None,
            floor_ms,
            format!(
                "{size}: both eye passes into textures, submitted and waited for: the floor; \
                 eyes-on-gpu minus this = {:.2} ms (the folded anaglyph's work + its \
                 readback), the full-screen route minus this = {:.2} ms",
                resident_ms - floor_ms,
                fullscreen_ms - floor_ms
            ),
        ),
        row(
            format!("{gpu}, eyes on gpu, full-screen pass"),
            None,
            fullscreen_ms,
            format!(
                "{size}: the same frame with the anaglyph as a full-screen WGSL pass over the \
                 eye textures (the route of a frame with several outputs); / pair alone = {:.2}",
                fullscreen_ms / pair_ms
            ),
        ),
        row(
            "wgpu one submission".into(),
            None,
            oneshot_ms,
            format!(
                "{size}: the plain wgpu program (gpu_oneshot), timed in this round-robin; {}",
                oneshot.adapter()
            ),
        ),
    ])
}

/// The SIRDS paper's Table 1's first row (512×512, 2,500 triangles, k = 10, left start, bilinear) as a
/// whole frame on each path: the depth pass (GPU: including its readback, which the depth range
/// needs), the strip geometry on the host, the strips (GPU: including the image's readback).
/// The GPU row's error is the share of pixels that differ from the CPU's, in percent.
///
/// # Errors
/// Either path fails.
fn sirds_rows(r: &GpuRenderer, iters: usize) -> Result<Vec<Row>> {
    use stereolab::fixtures::{TABLE_1, table_scene};
    use stereolab::render::render_view;
    use stereolab_core::per_vertex;
    use stereolab_core::{StereoRig, depth_range};

    let (w, h, tris, k, paper_hz) = TABLE_1[0];
    let s = table_scene(w, h, tris, k)?;
    let center = StereoRig::center(&s.camera, s.aspect())?;
    let d = s.sirds.geometry.to_pixels()?;
    let opts = &s.sirds.per_vertex;
    let cpu_frame = || -> Result<Vec<[u8; 4]>> {
        let (fb, _) = render_view(&s, &center, Shading::DepthOnly)?;
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far)?;
        let g = StripGeometry::new(&s.strip_objects(), &center, &range, &d, false);
        Ok(per_vertex(&g, w, h, &d, &s.sirds.pattern, opts, false)?.pixels)
    };
    let gpu_scene = GpuScene::upload(r, &s)?;
    let strips = GpuStrips::new(r)?;
    let gpu_frame = || -> Result<Vec<[u8; 4]>> {
        let fb = r.render_view(&gpu_scene, &center, Shading::DepthOnly)?;
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far)?;
        let g = StripGeometry::new(&s.strip_objects(), &center, &range, &d, false);
        Ok(strips.run(r, &g, w, h, &d, &s.sirds.pattern, opts)?.pixels)
    };
    let (cpu, gpu) = (cpu_frame()?, gpu_frame()?);
    let differ = cpu.iter().zip(&gpu).filter(|(a, b)| a != b).count();
    let differ_percent = 100.0 * differ as f64 / cpu.len() as f64;
    let mut failed = None;
    let cpu_ms = median_ms(iters, || cpu_frame().map_err(|e| failed = Some(e)));
    let gpu_ms = median_ms(iters, || gpu_frame().map_err(|e| failed = Some(e)));
    if let Some(e) = failed {
        return Err(e);
    }
    let row = |setting: String, error, ms: f64, note: String| Row {
        area: "gpu parity".into(),
        knob: "sirds strips, the SIRDS paper's Table 1".into(),
        setting,
        error,
        error_unit: "% pixels differing from cpu".into(),
        ms,
        note,
    };
    let what = format!("{w}x{h} {tris} tris k={k}");
    Ok(vec![
        row(
            format!("cpu {what}"),
            Some(0.0),
            cpu_ms,
            format!(
                "depth pass + strips; cpu/gpu time = {:.2}; paper {paper_hz} Hz",
                cpu_ms / gpu_ms
            ),
        ),
        row(
            format!("{} {what}", r.short_name()),
            Some(differ_percent),
            gpu_ms,
            format!(
                "depth pass + readback + WGSL strips + readback: {:.0} Hz",
                1e3 / gpu_ms
            ),
        ),
    ])
}
