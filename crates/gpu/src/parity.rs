//! Both paths on one scene: `stereolab compare SCENE` (raster and, on identical inputs, finalize
//! parity) and the benchmark's CPU-vs-lavapipe row.

use std::path::Path;

use stereolab::compare::{
    Comparison, compare, depth_bits_identical, framebuffer_from_image, pictures, write_diff_strip,
};
use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan, View};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::{Precision, Result, anaglyph, occlusion_image, parallax_image, remap_color};

use super::device::GpuRenderer;
use super::effects::GpuFinalize;
use super::raster::GpuScene;

/// Outputs that are one pass's framebuffer as it is: compared once, as the pass.
const PASS_OUTPUTS: [Output; 4] = [
    Output::Left,
    Output::Right,
    Output::LeftDepth,
    Output::RightDepth,
];

/// Renders `plan` on the CPU (expected) and on the GPU (actual) and compares every pass
/// (color, coverage and depth) and every other RGBA output (color and coverage against the
/// scene's background). With `out`, writes an `expected | diff | actual` strip per row.
///
/// # Errors
/// Rendering fails on either path, or a strip cannot be written.
pub fn compare_scene(
    r: &GpuRenderer,
    scene: &Scene,
    plan: &Plan,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    let cpu = render(scene, plan)?;
    let gpu = r.render(&GpuScene::upload(r, scene)?, plan)?;
    let mut rows = compare_frames(&cpu, &gpu, scene, out)?;
    rows.extend(compare_finalize(r, &cpu, scene, out)?);
    rows.extend(super::sirds_frame::compare_strips(r, &cpu, scene, out)?);
    Ok(rows)
}

/// Depth bit for bit over every pass of two frames of the same plan:
/// `(identical, both_covered)` summed as [`depth_bits_identical`] counts them per pass.
///
/// # Errors
/// Passes of different sizes.
pub fn depth_identity(expected: &Frame, actual: &Frame) -> Result<(usize, usize)> {
    let (mut same, mut both) = (0, 0);
    for (e, a) in expected.passes.iter().zip(&actual.passes) {
        let (s, b) = depth_bits_identical(&e.framebuffer, &a.framebuffer)?;
        same += s;
        both += b;
    }
    Ok((same, both))
}

/// Finalize parity apart from raster parity: every finalize output of the plan (anaglyphs,
/// remap, occlusion, parallax color) computed from the CPU frame's own eye framebuffers by the
/// CPU function and by its WGSL mirror ([`GpuFinalize`]). Rows are named `<output> (wgsl)`;
/// remap and occlusion use `Precision::F32Composed` on both sides, parallax compares the image
/// area (the legend is tiny-skia's, on the CPU).
///
/// # Errors
/// A finalize function fails on either path, or a strip cannot be written.
pub fn compare_finalize(
    r: &GpuRenderer,
    frame: &Frame,
    scene: &Scene,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    let (Some(left), Some(right)) = (frame.view(View::Left), frame.view(View::Right)) else {
        return Ok(Vec::new());
    };
    let fin = GpuFinalize::new(r)?;
    let mvps = [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp];
    let mut rows = Vec::new();
    for &o in &frame.plan.outputs {
        let (cpu, gpu) = match o {
            // Rendepth's gamma stage has no WGSL mirror: the GPU path leaves it to the CPU.
            Output::Anaglyph(_) if !crate::effects::has_wgsl_anaglyph(scene.finalize) => continue,
            Output::Anaglyph(kind) => (
                anaglyph(left, right, kind, scene.finalize)?,
                fin.anaglyph(r, left, right, kind, scene.finalize)?,
            ),
            Output::RemapLeft | Output::RemapRight => {
                let k = usize::from(o == Output::RemapRight);
                let (this, other) = if k == 0 { (left, right) } else { (right, left) };
                (
                    remap_color(this, other, mvps[k], mvps[1 - k], Precision::F32Composed)?,
                    fin.remap_color(r, this, other, mvps[k], mvps[1 - k])?,
                )
            }
            Output::Occlusion => (
                occlusion_image(left, right, mvps, Precision::F32Composed)?,
                fin.occlusion_image(r, left, right, mvps)?,
            ),
            Output::Parallax => {
                let rig = scene.parallax_rig()?;
                let full = parallax_image(left, &rig)?;
                let cpu = image::imageops::crop_imm(&full, 0, 0, left.width(), left.height());
                (cpu.to_image(), fin.parallax(r, left, &rig)?.1)
            }
            _ => continue,
        };
        let name = format!("{} (wgsl)", o.name());
        let (e, a) = (
            framebuffer_from_image(&cpu, scene.background)?,
            framebuffer_from_image(&gpu, scene.background)?,
        );
        let metrics = compare(&e, &a)?;
        let strip = out
            .map(|d| write_diff_strip(&e, &a, d, &format!("{}_wgsl", o.name())))
            .transpose()?;
        rows.push(Comparison {
            name,
            metrics,
            has_depth: false,
            strip,
            max_levels_16: None,
            pictures: pictures(&e, &a),
            flip: None,
        });
    }
    Ok(rows)
}

/// Compares two frames of the same plan, as [`compare_scene`] describes.
///
/// # Errors
/// Different sizes, a missing pass, or a strip that cannot be written.
pub fn compare_frames(
    expected: &Frame,
    actual: &Frame,
    scene: &Scene,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    let mut rows = Vec::new();
    for (e, a) in expected.passes.iter().zip(&actual.passes) {
        let name = format!("{} pass", format!("{:?}", e.pass.view).to_lowercase());
        let metrics = compare(&e.framebuffer, &a.framebuffer)?;
        let strip = out
            .map(|d| write_diff_strip(&e.framebuffer, &a.framebuffer, d, &name.replace(' ', "_")))
            .transpose()?;
        rows.push(Comparison {
            name,
            metrics,
            has_depth: true,
            strip,
            max_levels_16: None,
            pictures: pictures(&e.framebuffer, &a.framebuffer),
            flip: None,
        });
    }
    for &o in &expected.plan.outputs {
        if PASS_OUTPUTS.contains(&o) {
            continue;
        }
        let (Image::Rgba(e), Image::Rgba(a)) =
            (produce(o, expected, scene)?, produce(o, actual, scene)?)
        else {
            continue; // depth images: the pass rows already compare depth exactly
        };
        let (e, a) = (
            framebuffer_from_image(&e, scene.background)?,
            framebuffer_from_image(&a, scene.background)?,
        );
        let metrics = compare(&e, &a)?;
        let strip = out
            .map(|d| write_diff_strip(&e, &a, d, o.name()))
            .transpose()?;
        rows.push(Comparison {
            name: o.name().to_string(),
            metrics,
            has_depth: false,
            strip,
            max_levels_16: None,
            pictures: pictures(&e, &a),
            flip: None,
        });
    }
    Ok(rows)
}
