//! `stereolab render`: the outputs a scene asks for, as PNG files, and the render report.

use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::{Args, ValueEnum};
use stereolab::plan::Plan;
use stereolab::render::Frame;
use stereolab::scene::Scene;
use stereolab::{info, output, render};
use stereolab_core::{Error, Result};
use stereolab_grade as grade;

use super::load_scene;

/// Arguments of `stereolab render`.
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Image size WxH, overriding the scene's.
    #[arg(long)]
    pub size: Option<String>,
    /// Override a scene field: --set stereo.eye_separation=0.2 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Print the plan (which passes run for which outputs) and the memory it needs, and render
    /// nothing.
    #[arg(long)]
    pub explain: bool,
    /// The most memory the render may need (estimated before it starts; `--explain` shows
    /// it): a size such as 512M or 4G. Default: three quarters of this machine's memory.
    #[arg(long, value_name = "SIZE")]
    pub max_memory: Option<String>,
    /// Which path renders.
    #[arg(long, value_enum, default_value = "cpu")]
    pub backend: Backend,
    /// Instead of the scene's outputs: the student's exercise (ex1, ex2, ex3) next to the
    /// reference, as `reference | diff | yours` images.
    #[arg(long, value_name = "EXERCISE")]
    pub exercise: Option<String>,
    /// With --exercise: the instructor's solution instead of the student's code.
    #[arg(long, requires = "exercise")]
    pub solution: bool,
    /// With --exercise: the folder holding the exercise crates (default: ./exercises or .).
    #[arg(long, requires = "exercise")]
    pub exercises: Option<PathBuf>,
}

/// Writes every output of `frame`, with a progress bar on a terminal for the long ones (a
/// frame-sequential animation's fields: count, elapsed time and an estimate of the rest).
fn write_with_progress(frame: &Frame, scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut progress = |name: &str, done: usize, of: usize| {
        let bar = bar.get_or_insert_with(|| {
            let b = indicatif::ProgressBar::new(of as u64).with_message(format!("writing {name}"));
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{msg} {bar:30} {pos}/{len} fields, {elapsed} (about {eta} left)",
            ) {
                b.set_style(style);
            }
            b
        });
        bar.set_position(done as u64);
    };
    let mut write = || {
        output::write_all_reporting(
            frame,
            dir,
            |o| output::produce(o, frame, scene),
            &mut progress,
        )
    };
    // The spinner for the outputs in general; the bar alone when one of them reports fields.
    let paths = if frame
        .plan
        .outputs
        .contains(&stereolab::plan::Output::FrameSequential)
    {
        write()
    } else {
        super::with_spinner("writing", write)
    };
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    paths
}

/// Runs `stereolab render`.
///
/// # Errors
/// Whatever the work fails with; the message names the input.
pub fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        scene,
        out,
        size,
        sets,
        explain,
        max_memory,
        backend,
        exercise,
        solution,
        exercises,
    } = args;
    let budget = max_memory
        .as_deref()
        .map(stereolab::memory::parse_bytes)
        .transpose()?;
    if out.is_file() {
        return Err(Error::invalid(
            "--out",
            out.display(),
            "names a file: --out is the folder the outputs are written into",
        ));
    }
    let s = load_scene(&scene, &sets, size.as_deref())?;
    if let Some(name) = exercise {
        let [ex] = grade::Exercise::parse_list(&name)?[..] else {
            return Err(Error::invalid(
                "--exercise",
                name,
                "name one exercise: ex1, ex2 or ex3",
            ));
        };
        let dir = grade::exercises_dir(exercises)?;
        let limits = grade::Limits {
            time: Duration::from_secs(30),
            ..grade::Limits::DEFAULT
        };
        for line in grade::render_exercise(ex, s, &dir, solution, limits, &out)? {
            outln!("{line}");
        }
        return Ok(());
    }
    let plan = Plan::new(&s.outputs);
    let needs = stereolab::memory::estimate(&s, &plan);
    let limit = budget.unwrap_or_else(stereolab::memory::default_budget);
    if explain {
        out!("{}", plan.explain());
        if plan.outputs.iter().any(|o| o.name().starts_with("sirds")) {
            outln!("  sirds: {}", s.sirds.describe());
        }
        outln!(
            "  memory: {needs}; budget {}{}",
            stereolab::memory::human_bytes(limit),
            if budget.is_none() {
                " (three quarters of this machine's memory; --max-memory sets it)"
            } else {
                ""
            }
        );
        return Ok(());
    }
    stereolab::memory::check_budget(&needs, limit, budget.is_none())?;
    let (frame, paths) = match backend {
        Backend::Cpu => {
            // Errors this late still name the scene they come from.
            let frame = super::with_spinner("rendering", || render::render(&s, &plan))
                .map_err(|e| e.in_file(&scene))?;
            let paths = write_with_progress(&frame, &s, &out)?;
            (frame, paths)
        }
        Backend::Gpu => render_gpu(&s, &plan, &out)?,
    };
    outln!("rendered {} ({}x{})", scene.display(), s.width, s.height);
    if let Some(peak) = stereolab::memory::peak_resident() {
        outln!(
            "  memory: peak {} resident, estimated {} before the render",
            stereolab::memory::human_bytes(peak),
            stereolab::memory::human_bytes(needs.total)
        );
    }
    for note in &s.notes {
        if note.starts_with("warning:") {
            outln!("  {note}");
        } else {
            outln!("  note: {note}");
        }
    }
    if backend == Backend::Gpu {
        let ms = frame
            .passes
            .first()
            .map_or(0.0, |p| p.time.as_secs_f64() * 1e3);
        outln!(
            "  {} passes on the GPU in one submission: {ms:.2} ms including readback \
             and, on this first frame, shader compilation",
            frame.passes.len()
        );
    }
    for p in frame.passes.iter().filter(|_| backend == Backend::Cpu) {
        outln!(
            "  pass {:?} {:?}: {:.2} ms, {} triangles, {} fragments, {} clipped, {} culled",
            p.pass.view,
            p.pass.shading,
            p.time.as_secs_f64() * 1e3,
            p.stats.triangles,
            p.stats.fragments,
            p.stats.clipped,
            p.stats.culled
        );
    }
    // Nothing drawn at all is never what a scene means: say so instead of exiting quietly with
    // background-only images (the precision cases are refused at load; this catches the rest).
    let cpu_passes = frame.passes.iter().filter(|_| backend == Backend::Cpu);
    if cpu_passes.clone().count() > 0 && cpu_passes.clone().all(|p| p.stats.fragments == 0) {
        outln!(
            "  warning: no pass drew a fragment: the images show only the background; check \
             that the meshes lie inside the view (camera.eye, camera.target, camera.near, \
             camera.far, each mesh's translate and scale)"
        );
    }
    // Clipped triangles with coordinates past what the clipper places within a subpixel step
    // (`ClipRange`, docs/reliability.md "Large coordinates").
    let mut range = stereolab_core::ClipRange::default();
    for p in frame.passes.iter().filter(|_| backend == Backend::Cpu) {
        range.merge(p.stats.clip_range);
    }
    if range.triangles > 0 {
        outln!(
            "  warning: {} clipped triangles have clip coordinates beyond the clipper's range \
             (largest {:e}, limit {:e} for that triangle: 2^43 times its nearest w over the \
             image's larger side); their edges and depth may be off by more than 1/256 pixel \
             or lost: bring the meshes' coordinates nearer the camera's scale (each mesh's \
             scale and translate, camera.near)",
            range.triangles,
            range.coordinate,
            range.limit
        );
    }
    if let Some(report) = info::frame_budget_report(&frame, &s)? {
        out!("{report}");
    }
    if let Some(report) = stereolab::output::shear_rotate::report(&frame)? {
        out!("{report}");
    }
    for line in output::report::effect_lines(&frame, &s)? {
        outln!("  {line}");
    }
    for p in paths {
        outln!("  wrote {}", p.display());
    }
    Ok(())
}

/// Which path renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Backend {
    /// The CPU rasterizer (the reference).
    Cpu,
    /// wgpu on Vulkan (lavapipe without a GPU); needs the `gpu` cargo feature.
    Gpu,
}

/// Renders on the GPU and writes the outputs (a per-vertex `sirds` with the WGSL strips).
#[cfg(feature = "gpu")]
fn render_gpu(scene: &Scene, plan: &Plan, out: &Path) -> Result<(Frame, Vec<PathBuf>)> {
    use stereolab_gpu::{GpuRenderer, GpuScene};
    let r = GpuRenderer::new()?;
    outln!("gpu: {}", r.adapter_name());
    let frame = r.render(&GpuScene::upload(&r, scene)?, plan)?;
    let paths = stereolab_gpu::output::write_all(&r, &frame, scene, out)?;
    Ok((frame, paths))
}

#[cfg(not(feature = "gpu"))]
fn render_gpu(_: &Scene, _: &Plan, _: &Path) -> Result<(Frame, Vec<PathBuf>)> {
    Err(super::no_gpu("--backend"))
}
