//! The GPU strips in use: a scene's SIRDS from a frame's depth pass, the strip-parity row of
//! `compare SCENE`, and seed 002 Table 1's first row on both paths for `stereolab bench`.

use std::path::Path;

use crate::compare::{Comparison, compare, framebuffer_from_image, write_diff_strip};
use crate::effects::sirds::per_vertex::StripGeometry;
use crate::effects::sirds::{self, Algorithm, Sirds};
use crate::error::Result;
use crate::plan::Output;
use crate::render::Frame;
use crate::scene::Scene;

use super::device::GpuRenderer;
use super::sirds::GpuStrips;

/// The scene's SIRDS (output `sirds`) from `frame`'s depth pass, as
/// [`sirds::from_frame`](crate::effects::sirds::from_frame) but with the strips on the GPU.
/// The per-pixel algorithm (TIW: a serial chain of links along each row) has no WGSL mirror and
/// runs on the CPU.
///
/// # Errors
/// As `sirds::from_frame` and [`GpuStrips::run`].
pub fn from_frame(
    r: &GpuRenderer,
    strips: &GpuStrips,
    frame: &Frame,
    scene: &Scene,
) -> Result<Sirds> {
    let s = &scene.sirds;
    sirds::from_frame_with(frame, scene, |g, d| {
        strips.run(
            r,
            g,
            scene.width,
            scene.height,
            d,
            &s.pattern,
            &s.per_vertex,
        )
    })
}

/// Strip parity apart from raster parity: the SIRDS of the CPU frame's own depth pass made by
/// the CPU strips and by the WGSL strips (same [`StripGeometry`], same strips), as a row
/// `sirds (wgsl strips)`. Empty unless the plan makes a per-vertex `sirds`.
///
/// # Errors
/// Either path fails, or a strip cannot be written.
pub fn compare_strips(
    r: &GpuRenderer,
    frame: &Frame,
    scene: &Scene,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    if !frame.plan.outputs.contains(&Output::Sirds) || scene.sirds.algorithm != Algorithm::PerVertex
    {
        return Ok(Vec::new());
    }
    let cpu = sirds::from_frame(frame, scene)?.to_rgba_image();
    let gpu = from_frame(r, &GpuStrips::new(r)?, frame, scene)?.to_rgba_image();
    let (e, a) = (
        framebuffer_from_image(&cpu, scene.background),
        framebuffer_from_image(&gpu, scene.background),
    );
    let metrics = compare(&e, &a)?;
    let strip = out
        .map(|dir| write_diff_strip(&e, &a, dir, "sirds_wgsl_strips"))
        .transpose()?;
    Ok(vec![Comparison {
        name: "sirds (wgsl strips)".into(),
        metrics,
        has_depth: false,
        strip,
    }])
}

/// Seed 002 Table 1's first row (512×512, 2,500 triangles, k = 10, left start, bilinear) as a
/// whole frame on each path: the depth pass (GPU: including its readback, which the depth range
/// needs), the strip geometry on the host, the strips (GPU: including the image's readback).
/// The GPU row's error is the share of pixels that differ from the CPU's, in percent.
///
/// # Errors
/// Either path fails.
pub fn bench_rows(r: &GpuRenderer, iters: usize) -> Result<Vec<crate::bench::Row>> {
    use crate::bench::{Row, median_ms};
    use crate::effects::sirds::bench::{TABLE_1, table_scene};
    use crate::effects::sirds::depth_range;
    use crate::effects::sirds::per_vertex::per_vertex;
    use crate::math::StereoRig;
    use crate::plan::Shading;
    use crate::render::render_view;

    let (w, h, tris, k, paper_hz) = TABLE_1[0];
    let s = table_scene(w, h, tris, k)?;
    let center = StereoRig::center(&s.camera, s.aspect())?;
    let d = s.sirds.geometry.to_pixels()?;
    let opts = &s.sirds.per_vertex;
    let cpu_frame = || -> Result<Vec<[u8; 4]>> {
        let (fb, _) = render_view(&s, &center, Shading::DepthOnly)?;
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far)?;
        let g = StripGeometry::new(&s, &center, &range, &d, false);
        Ok(per_vertex(&g, w, h, &d, &s.sirds.pattern, opts, false)?.pixels)
    };
    let gpu_scene = super::GpuScene::upload(r, &s)?;
    let strips = GpuStrips::new(r)?;
    let gpu_frame = || -> Result<Vec<[u8; 4]>> {
        let fb = r.render_view(&gpu_scene, &center, Shading::DepthOnly)?;
        let range = depth_range(&s.sirds, &fb, s.camera.near, s.camera.far)?;
        let g = StripGeometry::new(&s, &center, &range, &d, false);
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
        knob: "sirds strips, seed 002 Table 1".into(),
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
