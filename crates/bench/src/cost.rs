//! The `cost` group: how the frame's time grows with the work, on the CPU and on lavapipe.
//!
//! Each point is the CPU stereo pair + Dubois anaglyph (`render`, then `produce`) beside the
//! plain wgpu program of `gpu_oneshot.rs` (both eyes, the anaglyph pass, one submission, one
//! readback) on the same scene, the two timed in turns:
//! - **triangles**: a height-field grid of 10 000 … 4 000 000 triangles at 1024×768 (the
//!   pixels stay the same);
//! - **pixels**: the real model at 512² … 4096² (the triangles stay the same).
//!
//! Two rows per point, `cpu` and `wgpu`; the `cpu` row's note carries `cpu / wgpu` (goal
//! ≤ 0.5). Large points take fewer frames (a 4 M-triangle pair is a few hundred
//! milliseconds); each point's memory estimate ([`stereolab::memory::estimate`]) is in its
//! note. Without the `gpu` feature, or without a Vulkan adapter, the `wgpu` rows say so and
//! the CPU rows stand alone.

use super::{Row, interleaved_medians};
use stereolab::fixtures::table_scene;
use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{AnaglyphKind, Error, Result};

/// Area of every row of this group.
pub const AREA: &str = "cost";
/// Knob of the points that vary the triangles.
pub const BY_TRIANGLES: &str = "triangles, grid at 1024x768";
/// Knob of the points that vary the pixels.
pub const BY_PIXELS: &str = "pixels, real model";
/// Triangle counts of the grid.
pub const TRIANGLES: [u32; 4] = [10_000, 100_000, 1_000_000, 4_000_000];
/// Sides of the square images.
pub const SIDES: [u32; 4] = [512, 1024, 2048, 4096];

const OUTPUT: Output = Output::Anaglyph(AnaglyphKind::DuboisRedCyan);

/// The CPU frame: both eyes, then the Dubois anaglyph; its bytes.
fn cpu_frame(scene: &Scene) -> Result<Vec<u8>> {
    match produce(OUTPUT, &render(scene, &Plan::new(&[OUTPUT]))?, scene)? {
        Image::Rgba(img) => Ok(img.into_raw()),
        _ => Err(Error::internal("bench cost", "not an RGBA image")),
    }
}

/// Triangles the pair draws (both eyes).
fn pair_triangles(scene: &Scene) -> usize {
    2 * scene
        .objects
        .iter()
        .map(|o| o.mesh.triangles.len())
        .sum::<usize>()
}

/// Frames per row: `iters`, fewer for the large points.
fn frames(iters: usize, scene: &Scene) -> usize {
    let pixels = u64::from(scene.width) * u64::from(scene.height);
    let tris = pair_triangles(scene) as u64;
    if tris >= 4_000_000 || pixels >= 4096 * 4096 {
        2
    } else if tris >= 1_000_000 || pixels >= 2048 * 2048 {
        3
    } else {
        iters.max(1)
    }
}

/// Every cost row.
///
/// # Errors
/// A scene cannot be built or rendered on the CPU, or a wgpu frame cannot be read back.
pub fn rows(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for tris in TRIANGLES {
        let s = table_scene(1024, 768, tris, 1)?;
        rows.extend(point(
            &s,
            BY_TRIANGLES,
            &format!("grid of {tris} tris"),
            iters,
        )?);
    }
    for side in SIDES {
        let mut s = scene.clone();
        s.set_size(side, side)?;
        rows.extend(point(&s, BY_PIXELS, &format!("{side}x{side}"), iters)?);
    }
    Ok(rows)
}

/// The `cpu` and `wgpu` rows of one point.
fn point(scene: &Scene, knob: &str, setting: &str, iters: usize) -> Result<Vec<Row>> {
    let row = |backend: &str, ms: f64, note: String| Row {
        area: AREA.into(),
        knob: knob.into(),
        setting: format!("{setting}, {backend}"),
        error: None,
        error_unit: String::new(),
        ms,
        note,
    };
    let n = frames(iters, scene);
    let memory = stereolab::memory::estimate(scene, &Plan::new(&[OUTPUT])).total as f64 / 1e9;
    let tris = pair_triangles(scene);
    let (w, h) = (scene.width, scene.height);
    let what = format!("{tris} triangles/pair, {w}x{h}, median of {n}");
    let mut cpu = || cpu_frame(scene).map(drop);
    match wgpu_program(scene)? {
        Ok(oneshot) => {
            let mut gpu = || oneshot.frame().map(drop);
            let ms = interleaved_medians(n, 1, &mut [&mut cpu, &mut gpu])?;
            Ok(vec![
                row(
                    "cpu",
                    ms[0],
                    format!(
                        "{what}; cpu/wgpu time = {:.2} (goal <= 0.5); memory estimate {memory:.2} GB",
                        ms[0] / ms[1]
                    ),
                ),
                row("wgpu", ms[1], format!("{what}; {}", oneshot.adapter())),
            ])
        }
        Err(why) => {
            let ms = interleaved_medians(n, 1, &mut [&mut cpu])?;
            Ok(vec![
                row(
                    "cpu",
                    ms[0],
                    format!("{what}; memory estimate {memory:.2} GB"),
                ),
                row("wgpu", f64::NAN, format!("not measured: {why}")),
            ])
        }
    }
}

#[cfg(feature = "gpu")]
type Program = super::gpu_oneshot::OneShot;

/// The plain wgpu program on `scene`, or why there is none (no adapter, no `gpu` feature).
#[cfg(feature = "gpu")]
fn wgpu_program(scene: &Scene) -> Result<std::result::Result<Program, String>> {
    let eyes = scene.rig.eyes(&scene.camera, scene.aspect())?;
    Ok(Program::new(scene, &eyes).map_err(|e| e.to_string()))
}

/// Without the `gpu` feature there is no wgpu program.
#[cfg(not(feature = "gpu"))]
enum Program {}

#[cfg(not(feature = "gpu"))]
impl Program {
    fn frame(&self) -> Result<Vec<u8>> {
        match *self {}
    }
    fn adapter(&self) -> &str {
        match *self {}
    }
}

#[cfg(not(feature = "gpu"))]
fn wgpu_program(_: &Scene) -> Result<std::result::Result<Program, String>> {
    Ok(Err("built without the gpu feature".into()))
}
