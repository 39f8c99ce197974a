//! Benchmark rows of the WGSL finalize passes beside their CPU functions, on identical eye
//! framebuffers (the CPU path's stereo pair): upload + pass + readback on the GPU, the function
//! on the CPU, as a ratio in the same run.

use crate::bench::{Row, median_ms};
use crate::compare::{compare, framebuffer_from_image};
use crate::effects::anaglyph::{AnaglyphKind, AnaglyphOptions, anaglyph};
use crate::effects::occlusion::occlusion_image;
use crate::effects::parallax::{ParallaxRig, parallax_image};
use crate::effects::remap::{Precision, remap_color};
use crate::error::Result;
use crate::plan::View;
use crate::render::Frame;
use crate::scene::Scene;

use super::device::GpuRenderer;
use super::effects::GpuFinalize;

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
pub fn rows(r: &GpuRenderer, frame: &Frame, scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let (Some(left), Some(right)) = (frame.view(View::Left), frame.view(View::Right)) else {
        return Ok(Vec::new());
    };
    let fin = GpuFinalize::new(r)?;
    let mvps = [&frame.eyes[0].mvp, &frame.eyes[1].mvp];
    let rig = ParallaxRig::of_scene(scene)?;
    let kind = AnaglyphKind::DuboisRedCyan;
    let opts = AnaglyphOptions::default();
    let crop = |img: image::RgbaImage| {
        image::imageops::crop_imm(&img, 0, 0, left.width, left.height).to_image()
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
    let size = format!("{}x{}", left.width, left.height);
    let mut rows = Vec::new();
    for (name, cpu, gpu) in effects {
        let (c, g) = (cpu()?, gpu()?);
        let c = if name == "parallax" { crop(c) } else { c };
        let metrics = compare(
            &framebuffer_from_image(&c, scene.background),
            &framebuffer_from_image(&g, scene.background),
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
