//! Benchmark rows of the finalize pass: every mode's time on the real model, linear light vs
//! stored values, remap f32 vs f64, and throughput as a fraction of a plain memory copy.

use glam::Mat4;
use rayon::prelude::*;

use super::{Row, median_ms};
use crate::effects::anaglyph::{AnaglyphKind, AnaglyphOptions, anaglyph, anaglyph_with};
use crate::effects::occlusion::occlusion_image;
use crate::effects::parallax::parallax_image_with;
use crate::effects::remap::{
    Precision, Remapper, Visibility, remap_color_with, remap_coordinates, visibility_map,
};
use crate::error::Result;
use crate::framebuffer::Framebuffer;
use crate::plan::{Output, Plan, Shading, View};
use crate::render::{render, render_view};
use crate::scene::Scene;

fn row(knob: &str, setting: impl Into<String>, error: Option<f64>, unit: &str, ms: f64) -> Row {
    Row {
        area: "finalize".into(),
        knob: knob.into(),
        setting: setting.into(),
        error,
        error_unit: unit.into(),
        ms,
        note: String::new(),
    }
}

/// The yardstick: median ms of copying `bytes` bytes between two buffers allocated once
/// (`copy_from_slice`), on one thread and on every thread of the pool (the bytes split into one
/// contiguous part per thread), as `[one thread, all threads]`. The finalize modes run on the
/// pool's threads and allocate their output each call; the copy does neither on one thread.
#[derive(Clone, Copy, Debug)]
struct Memcpy {
    bytes: usize,
    one_thread_ms: f64,
    all_threads_ms: f64,
}

fn memcpy_ms(bytes: usize, iters: usize) -> Memcpy {
    let src = vec![7u8; bytes];
    let mut dst = vec![0u8; bytes];
    let one_thread_ms = median_ms(iters, || {
        dst.copy_from_slice(std::hint::black_box(&src));
        dst[bytes / 2]
    });
    let part = bytes.div_ceil(rayon::current_num_threads()).max(1);
    let all_threads_ms = median_ms(iters, || {
        dst.par_chunks_mut(part)
            .zip(std::hint::black_box(&src).par_chunks(part))
            .for_each(|(d, s)| d.copy_from_slice(s));
        dst[bytes / 2]
    });
    Memcpy {
        bytes,
        one_thread_ms,
        all_threads_ms,
    }
}

/// Fills in the throughput note: the mode reads `copy.bytes` of framebuffers; a plain copy of
/// the same bytes takes `copy.one_thread_ms` on one thread (the ratio the goal states)
/// and `copy.all_threads_ms` on all of the pool's threads.
fn with_throughput(mut r: Row, copy: Memcpy) -> Row {
    let t = format!(
        "{:.3} of memcpy ({:.1} MB read; copy {:.3} ms on 1 thread; {:.3} of the {}-thread copy, {:.3} ms)",
        copy.one_thread_ms / r.ms,
        copy.bytes as f64 / 1e6,
        copy.one_thread_ms,
        copy.all_threads_ms / r.ms,
        rayon::current_num_threads(),
        copy.all_threads_ms,
    );
    r.note = if r.note.is_empty() {
        t
    } else {
        format!("{}; {t}", r.note)
    };
    r
}

/// Every finalize row on `scene` (its size; `stereolab bench` uses 1024×768), each mode on the
/// thread pool it runs on in a render (rows in parallel), against a copy of the same bytes on
/// one thread and on the pool's threads.
///
/// # Errors
/// The scene cannot be rendered, or a mode fails.
pub fn rows(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let frame = render(scene, &Plan::new(&[Output::Left, Output::Right]))?;
    let (Some(left), Some(right)) = (frame.view(View::Left), frame.view(View::Right)) else {
        return Ok(Vec::new());
    };
    let mvp = [frame.eyes[0].mvp, frame.eyes[1].mvp];
    let px = left.color.len();
    let mut rows = anaglyph_rows(left, right, iters)?;
    let copy_color_depth = memcpy_ms(px * 8, iters);
    let mut err = None;
    let mut time = |f: &mut dyn FnMut() -> Result<()>| {
        median_ms(iters, || {
            if let Err(e) = f() {
                err = Some(e);
            }
        })
    };
    // Each mode on the AVX2 rows (where the CPU has AVX2) and on the scalar loops, what a CPU
    // without AVX2 runs; the bytes are the same (unit tests).
    let remap = |simd: bool, right_eye: bool| {
        let (this, other, k) = if right_eye {
            (right, left, 1)
        } else {
            (left, right, 0)
        };
        move || remap_color_with(this, other, &mvp[k], &mvp[1 - k], Precision::F64, simd).map(drop)
    };
    let remap_ms = time(&mut remap(true, false));
    let remap_right_ms = time(&mut remap(true, true));
    let remap_scalar_ms = time(&mut remap(false, false));
    let remap_f32_ms = time(&mut || {
        remap_color_with(left, right, &mvp[0], &mvp[1], Precision::F32Composed, true).map(drop)
    });
    let occlusion_ms =
        time(&mut || occlusion_image(left, right, [&mvp[0], &mvp[1]], Precision::F64).map(drop));
    let rig = scene.parallax_rig()?;
    let parallax_ms = time(&mut || parallax_image_with(left, &rig, true).map(drop));
    let parallax_scalar_ms = time(&mut || parallax_image_with(left, &rig, false).map(drop));
    if let Some(e) = err {
        return Err(e);
    }
    let drawn_share = |fb: &Framebuffer| {
        let drawn = fb.depth.iter().filter(|d| **d < 1.0).count();
        format!("{:.0}% of pixels drawn", 100.0 * drawn as f64 / px as f64)
    };
    for (name, ms, eye) in [
        ("remap_left", remap_ms, left),
        ("remap_right", remap_right_ms, right),
        ("remap_left scalar", remap_scalar_ms, left),
        ("remap_left f32 composed", remap_f32_ms, left),
    ] {
        let mut r = row("mode", name, None, "", ms);
        r.note = drawn_share(eye);
        rows.push(with_throughput(r, copy_color_depth));
    }
    let map = visibility_map(left, right, &mvp[0], &mvp[1], Precision::F64)?;
    let n = |v: Visibility| map.iter().filter(|m| **m == v).count();
    let mut occlusion = row("mode", "occlusion", None, "", occlusion_ms);
    occlusion.note = format!(
        "left eye: {} visible, {} occluded, {} out of view, {} farther (silhouette sampling)",
        n(Visibility::Visible),
        n(Visibility::Occluded),
        n(Visibility::OutOfView),
        n(Visibility::Farther)
    );
    rows.push(with_throughput(occlusion, copy_color_depth));
    let copy_depth = memcpy_ms(px * 4, iters);
    for (name, ms) in [
        ("parallax + legend", parallax_ms),
        ("parallax + legend scalar", parallax_scalar_ms),
    ] {
        let mut r = row("mode", name, None, "", ms);
        r.note = drawn_share(left);
        rows.push(with_throughput(r, copy_depth));
    }
    let (near, deep) = remap_precision(scene, iters)?;
    rows.extend(near);
    rows.extend(deep);
    Ok(rows)
}

/// The remap precision rows on `scene` as it is ("near/far 1/20", wuson's planes) and with
/// near = far / 1e5, where f32 unprojection struggles.
///
/// # Errors
/// The scene cannot be rendered.
pub(super) fn remap_precision(scene: &Scene, iters: usize) -> Result<(Vec<Row>, Vec<Row>)> {
    let mut out = Vec::new();
    for (near, label) in [(None, "near/far 1/20"), (Some(1e-5), "near/far 1e-5")] {
        let mut s = scene.clone();
        if let Some(k) = near {
            s.camera.near = s.camera.far * k;
        }
        let eyes = s.rig.eyes(&s.camera, s.aspect())?;
        let (left, _) = render_view(&s, &eyes[0], Shading::DepthOnly)?;
        out.push(remap_precision_rows(
            &left,
            &[eyes[0].mvp, eyes[1].mvp],
            label,
            iters,
        )?);
    }
    let deep = out.pop().unwrap_or_default();
    Ok((out.pop().unwrap_or_default(), deep))
}

/// Each anaglyph kind on stored values and in linear light: time, and the largest and mean
/// channel difference (8-bit levels) of linear light against stored values.
fn anaglyph_rows(left: &Framebuffer, right: &Framebuffer, iters: usize) -> Result<Vec<Row>> {
    let px = left.color.len();
    let copy = memcpy_ms(px * 8, iters);
    let mut rows = Vec::new();
    for kind in AnaglyphKind::ALL {
        let run = |linear_light| {
            anaglyph(
                left,
                right,
                kind,
                AnaglyphOptions {
                    linear_light,
                    swap_eyes: false,
                },
            )
        };
        let stored = run(false)?;
        let linear = run(true)?;
        let diffs: Vec<u8> = stored
            .as_raw()
            .iter()
            .zip(linear.as_raw())
            .map(|(a, b)| a.abs_diff(*b))
            .collect();
        let max = diffs.iter().copied().max().unwrap_or(0) as f64;
        let mean = diffs.iter().map(|d| *d as f64).sum::<f64>() / (px * 3) as f64;
        let stored_ms = median_ms(iters, || run(false).is_ok());
        let linear_ms = median_ms(iters, || run(true).is_ok());
        rows.push(with_throughput(
            row(
                "anaglyph",
                format!("{} stored", kind.output_name()),
                Some(0.0),
                "max levels vs stored",
                stored_ms,
            ),
            copy,
        ));
        let mut r = row(
            "anaglyph",
            format!("{} linear", kind.output_name()),
            Some(max),
            "max levels vs stored",
            linear_ms,
        );
        r.note = format!("mean {mean:.2} levels");
        rows.push(with_throughput(r, copy));
    }
    // The frame's background is one color in both eyes, which the AVX2 rows compute once per
    // run of equal pixels: the same kind on two eyes of pseudo-random colors (no two
    // neighbours equal) shows the rate of the arithmetic itself.
    let kind = AnaglyphKind::DuboisRedCyan;
    let noise = |seed: u64| -> Result<Framebuffer> {
        let mut fb = Framebuffer::new(left.width, left.height, [0, 0, 0, 255])?;
        let mut state = seed;
        for c in &mut fb.color {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let b = state.to_le_bytes();
            *c = [b[0], b[1], b[2], 255];
        }
        Ok(fb)
    };
    let (noise_l, noise_r) = (noise(0x2545_f491_4f6c_dd1d)?, noise(0x9e37_79b9_7f4a_7c15)?);
    for (simd, label) in [(true, ""), (false, " scalar")] {
        let ms = median_ms(iters, || {
            anaglyph_with(&noise_l, &noise_r, kind, AnaglyphOptions::default(), simd).is_ok()
        });
        let mut r = row(
            "anaglyph",
            format!("{} stored, noise{label}", kind.output_name()),
            Some(0.0),
            "max levels vs stored",
            ms,
        );
        r.note = "random colors, no equal neighbours".into();
        rows.push(with_throughput(r, copy));
    }
    // The scalar loop, what a CPU without AVX2 runs (the same bytes), on the kind goal 1 uses.
    let scalar_ms = median_ms(iters, || {
        anaglyph_with(left, right, kind, AnaglyphOptions::default(), false).is_ok()
    });
    rows.push(with_throughput(
        row(
            "anaglyph",
            format!("{} stored scalar", kind.output_name()),
            Some(0.0),
            "max levels vs stored",
            scalar_ms,
        ),
        copy,
    ));
    Ok(rows)
}

/// Remap coordinates in f32 (the exercise slides' shader), f32 with the composed matrix, and f64: time,
/// and the largest texture-coordinate difference to f64 over drawn pixels (and over all pixels,
/// including the far plane).
fn remap_precision_rows(
    left: &Framebuffer,
    mvp: &[Mat4; 2],
    label: &str,
    iters: usize,
) -> Result<Vec<Row>> {
    let exact = remap_coordinates(left, &mvp[0], &mvp[1], Precision::F64)?;
    let mut rows = Vec::new();
    for (p, name) in [
        (Precision::F64, "f64"),
        (Precision::F32Composed, "f32 composed"),
        (Precision::F32, "f32 the exercise slides"),
    ] {
        let coords = remap_coordinates(left, &mvp[0], &mvp[1], p)?;
        let (mut drawn, mut all) = (0.0f64, 0.0f64);
        for ((a, b), d) in exact.iter().zip(&coords).zip(&left.depth) {
            let e = match (a, b) {
                (Some(a), Some(b)) => (a.tex[0] - b.tex[0]).abs().max((a.tex[1] - b.tex[1]).abs()),
                (None, None) => 0.0,
                _ => f64::INFINITY,
            };
            all = all.max(e);
            if *d < 1.0 {
                drawn = drawn.max(e);
            }
        }
        // Time the per-pixel program alone (no coordinate buffer to allocate).
        let remapper = Remapper::new(&mvp[0], &mvp[1], left.width, left.height, p)?;
        let ms = median_ms(iters, || {
            let mut sum = 0.0;
            for y in 0..left.height {
                for x in 0..left.width {
                    if let Some(m) = remapper.remap(x, y, left.depth[left.index(x, y)]) {
                        sum += m.tex[0] + m.tex[1] + m.depth;
                    }
                }
            }
            sum
        });
        let mut r = row(
            "remap unproject",
            format!("{name}, {label}"),
            Some(drawn),
            "max |tex| error",
            ms,
        );
        r.note = format!(
            "= {:.4} px at width {}; all pixels incl. far plane {:.2e}",
            drawn * left.width as f64,
            left.width,
            all
        );
        rows.push(r);
    }
    Ok(rows)
}
