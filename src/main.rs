//! The `stereolab` command line.

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};

use stereolab::compare::{self, Comparison, Thresholds};
use stereolab::plan::Plan;
use stereolab::render::Frame;
use stereolab::scene::Scene;
use stereolab::{Error, Result, bench, effects, grade, info, output, render};

/// mimalloc instead of the system allocator. Every frame allocates and frees framebuffers of a
/// few MB; glibc serves those with mmap and hands them back to the OS on free, so each frame
/// page-faulted its 12.6 MB of targets back in: a 1024×768 stereo pair took 23 ms with glibc
/// against 9.0–9.7 ms with mimalloc, which keeps the pages (same run, `examples`-style loop).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Which path renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Backend {
    /// The CPU rasterizer (the reference).
    Cpu,
    /// wgpu on Vulkan (lavapipe without a GPU); needs the `gpu` cargo feature.
    Gpu,
}

#[derive(Parser)]
#[command(
    name = "stereolab",
    version,
    about = "A deterministic CPU rasterizer for stereoscopic rendering"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render the outputs a scene asks for, as PNG files.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Image size WxH, overriding the scene's.
        #[arg(long)]
        size: Option<String>,
        /// Override a scene field: --set stereo.eye_separation=0.2 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Print the plan (which passes run for which outputs) and render nothing.
        #[arg(long)]
        explain: bool,
        /// Which path renders.
        #[arg(long, value_enum, default_value = "cpu")]
        backend: Backend,
        /// Instead of the scene's outputs: the student's exercise (ex1, ex2, ex3) next to the
        /// reference, as `reference | diff | yours` images.
        #[arg(long, value_name = "EXERCISE")]
        exercise: Option<String>,
        /// With --exercise: the instructor's solution instead of the student's code.
        #[arg(long, requires = "exercise")]
        solution: bool,
        /// With --exercise: the folder holding the exercise crates (default: ./exercises or .).
        #[arg(long, requires = "exercise")]
        exercises: Option<PathBuf>,
    },
    /// Compare the CPU and GPU renders of a scene (`compare SCENE`), or any two images
    /// (`compare EXPECTED.png ACTUAL.png`); exits non-zero past a threshold.
    Compare {
        /// A scene file (TOML), or the expected image when ACTUAL is given.
        first: PathBuf,
        /// The actual image (compares two image files).
        second: Option<PathBuf>,
        /// Folder for the `expected | diff | actual` PNG strips.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Change a limit: coverage=% (0.1), max=0..255 (255), mean=channel (1.0),
        /// psnr=dB (30), depth=window depth (1e-5). Repeatable.
        #[arg(long = "threshold", value_name = "KEY=VALUE")]
        thresholds: Vec<String>,
        /// Image size WxH, overriding the scene's.
        #[arg(long)]
        size: Option<String>,
        /// Override a scene field (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Background color R,G,B (0..255) for two images; default: each image's top-left pixel.
        #[arg(long)]
        background: Option<String>,
        /// Instead of the scene's outputs: the student's ex1 stereo matrices rendered on the
        /// CPU (actual) against the reference rig on the GPU (expected), one row per eye.
        #[arg(long, value_name = "EXERCISE", conflicts_with_all = ["second", "background"])]
        exercise: Option<String>,
        /// With --exercise: the instructor's solution instead of the student's code.
        #[arg(long, requires = "exercise")]
        solution: bool,
        /// With --exercise: the folder holding the exercise crates (default: ./exercises or .).
        #[arg(long, requires = "exercise")]
        exercises: Option<PathBuf>,
    },
    /// Build and run the student's exercise crates; points table, verdict and hints.
    Grade {
        /// ex1, ex2, ex3 or all.
        exercise: String,
        /// Also write Gradescope's results.json here.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Grade the instructor's solution (the crates' `solution` feature).
        #[arg(long)]
        solution: bool,
        /// The folder holding the exercise crates (default: ./exercises, else .).
        #[arg(long)]
        exercises: Option<PathBuf>,
        /// Time limit per task in seconds (an endless loop costs that task only).
        #[arg(long, default_value_t = 10.0)]
        timeout: f64,
        /// Where failing image checks write `expected | diff | actual`.
        #[arg(long, default_value = "grade-out")]
        out: PathBuf,
    },
    /// Exercise material.
    Exercises {
        #[command(subcommand)]
        command: ExercisesCommand,
    },
    /// Print the derived cameras and the scene's parallax range.
    Info {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Override a scene field (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
    },
    /// Draw the slides' figures (rig top views, parallax plot) for a scene.
    Figures {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "slides/figures")]
        out: PathBuf,
    },
    /// Measure accuracy knobs and speed: error and time side by side.
    Bench {
        /// Also write the rows as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Scene with the real model (default: assets/scenes/wuson.toml).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Repetitions per timing (median reported).
        #[arg(long, default_value_t = 15)]
        iterations: usize,
        /// Run only these groups, comma-separated: stereo, raster, chromadepth, finalize, sirds,
        /// gpu (default: all).
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
    },
    /// Autostereograms (SIRDS): from a scene, from a depth map (--depth), animated (--frames),
    /// or decoded back to depth (--decode).
    Sirds(stereolab::effects::sirds::cli::SirdsArgs),
}

#[derive(Subcommand)]
enum ExercisesCommand {
    /// Write the student handout (stubs, tests, assets, the library with the grader; no
    /// solutions) to DIR.
    Export {
        /// Output folder.
        dir: PathBuf,
        /// The stereolab repository (default: . when it has exercises/, else the build's source).
        #[arg(long)]
        root: Option<PathBuf>,
    },
}

fn parse_timeout(seconds: f64) -> Result<Duration> {
    if seconds.is_finite() && seconds > 0.0 && seconds <= 3600.0 {
        Ok(Duration::from_secs_f64(seconds))
    } else {
        Err(Error::invalid(
            "--timeout",
            seconds,
            "must be between 0 and 3600 seconds",
        ))
    }
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::invalid("--size", s, "expected WxH, e.g. 1024x768");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

fn parse_rgb(s: &str) -> Result<[u8; 4]> {
    let bad = || Error::invalid("--background", s, "expected R,G,B with each in 0..=255");
    let v = s
        .split(',')
        .map(|c| c.trim().parse::<u8>().map_err(|_| bad()))
        .collect::<Result<Vec<_>>>()?;
    match v[..] {
        [r, g, b] => Ok([r, g, b, 255]),
        _ => Err(bad()),
    }
}

fn load_scene(path: &std::path::Path, sets: &[String], size: Option<&str>) -> Result<Scene> {
    let mut s = Scene::load(path, sets)?;
    if let Some(size) = size {
        let (w, h) = parse_size(size)?;
        s.set_size(w, h)?;
    }
    Ok(s)
}

/// Renders on the GPU and writes the outputs (a per-vertex `sirds` with the WGSL strips).
#[cfg(feature = "gpu")]
fn render_gpu(scene: &Scene, plan: &Plan, out: &Path) -> Result<(Frame, Vec<PathBuf>)> {
    use stereolab::gpu::{GpuRenderer, GpuScene};
    let r = GpuRenderer::new()?;
    println!("gpu: {}", r.adapter_name());
    let frame = r.render(&GpuScene::upload(&r, scene)?, plan)?;
    let paths = stereolab::gpu::output::write_all(&r, &frame, scene, out)?;
    Ok((frame, paths))
}

#[cfg(feature = "gpu")]
fn compare_scene(scene: &Scene, out: Option<&std::path::Path>) -> Result<Vec<Comparison>> {
    let r = stereolab::gpu::GpuRenderer::new()?;
    println!("cpu (expected) vs gpu (actual): {}", r.adapter_name());
    stereolab::gpu::parity::compare_scene(&r, scene, &Plan::new(&scene.outputs), out)
}

/// `compare --exercise`: rows and the student's per-eye problems.
#[cfg(feature = "gpu")]
fn compare_exercise(
    ex: grade::Exercise,
    scene: &Scene,
    exercises: Option<PathBuf>,
    solution: bool,
    out: Option<&std::path::Path>,
) -> Result<(Vec<Comparison>, Vec<String>)> {
    let dir = grade::exercises_dir(exercises)?;
    let r = stereolab::gpu::GpuRenderer::new()?;
    println!(
        "gpu reference (expected) vs your matrices on the cpu (actual): {}",
        r.adapter_name()
    );
    let c = grade::gpu_compare::compare_exercise(
        &r,
        ex,
        scene,
        &dir,
        solution,
        Duration::from_secs(30),
        out,
    )?;
    Ok((c.rows, c.problems))
}

#[cfg(not(feature = "gpu"))]
fn compare_exercise(
    _: grade::Exercise,
    _: &Scene,
    _: Option<PathBuf>,
    _: bool,
    _: Option<&std::path::Path>,
) -> Result<(Vec<Comparison>, Vec<String>)> {
    Err(no_gpu("compare --exercise (your matrices against the GPU)"))
}

#[cfg(not(feature = "gpu"))]
fn no_gpu(what: &str) -> Error {
    Error::invalid(
        what,
        "gpu",
        "this stereolab was built without the GPU path: cargo build --release --features gpu",
    )
}

#[cfg(not(feature = "gpu"))]
fn render_gpu(_: &Scene, _: &Plan, _: &Path) -> Result<(Frame, Vec<PathBuf>)> {
    Err(no_gpu("--backend"))
}

#[cfg(not(feature = "gpu"))]
fn compare_scene(_: &Scene, _: Option<&std::path::Path>) -> Result<Vec<Comparison>> {
    Err(no_gpu("compare SCENE (CPU against GPU)"))
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render {
            scene,
            out,
            size,
            sets,
            explain,
            backend,
            exercise,
            solution,
            exercises,
        } => {
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
                let timeout = Duration::from_secs(30);
                for line in grade::render_exercise(ex, s, &dir, solution, timeout, &out)? {
                    println!("{line}");
                }
                return Ok(());
            }
            let plan = Plan::new(&s.outputs);
            if explain {
                print!("{}", plan.explain());
                return Ok(());
            }
            let (frame, paths) = match backend {
                Backend::Cpu => {
                    let frame = render::render(&s, &plan)?;
                    let paths = output::write_all(&frame, &s, &out)?;
                    (frame, paths)
                }
                Backend::Gpu => render_gpu(&s, &plan, &out)?,
            };
            println!("rendered {} ({}x{})", scene.display(), s.width, s.height);
            if backend == Backend::Gpu {
                let ms = frame
                    .passes
                    .first()
                    .map_or(0.0, |p| p.time.as_secs_f64() * 1e3);
                println!(
                    "  {} passes on the GPU in one submission: {ms:.2} ms including readback \
                     and, on this first frame, shader compilation",
                    frame.passes.len()
                );
            }
            for p in frame.passes.iter().filter(|_| backend == Backend::Cpu) {
                println!(
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
            if let Some(report) = effects::parallax::frame_budget_report(&frame, &s)? {
                print!("{report}");
            }
            for p in paths {
                println!("  wrote {}", p.display());
            }
            Ok(())
        }
        Command::Compare {
            first,
            second,
            out,
            thresholds,
            size,
            sets,
            background,
            exercise,
            solution,
            exercises,
        } => {
            let mut limits = Thresholds::default();
            for t in &thresholds {
                limits.set(t)?;
            }
            let mut problems = Vec::new();
            let rows = match second {
                None if exercise.is_some() => {
                    let name = exercise.unwrap_or_default();
                    let [ex] = grade::Exercise::parse_list(&name)?[..] else {
                        return Err(Error::invalid("--exercise", name, "name one exercise: ex1"));
                    };
                    let s = load_scene(&first, &sets, size.as_deref())?;
                    let (rows, p) = compare_exercise(ex, &s, exercises, solution, out.as_deref())?;
                    problems = p;
                    rows
                }
                Some(second) => {
                    let bg = background.as_deref().map(parse_rgb).transpose()?;
                    vec![compare::compare_images(
                        &first,
                        &second,
                        bg,
                        out.as_deref(),
                    )?]
                }
                None => {
                    let s = load_scene(&first, &sets, size.as_deref())?;
                    compare_scene(&s, out.as_deref())?
                }
            };
            print!("{}", compare::table(&rows));
            for p in rows.iter().filter_map(|r| r.strip.as_ref()) {
                println!("  wrote {}", p.display());
            }
            for p in &problems {
                println!("  {p}");
            }
            let mut failed = limits.violations(&rows);
            failed.extend(problems);
            if failed.is_empty() {
                Ok(())
            } else {
                Err(Error::invalid(
                    "--threshold",
                    format!("{} exceeded", failed.len()),
                    failed.join("; "),
                ))
            }
        }
        Command::Grade {
            exercise,
            json,
            solution,
            exercises,
            timeout,
            out,
        } => {
            let opts = grade::GradeOptions {
                exercises: grade::Exercise::parse_list(&exercise)?,
                dir: grade::exercises_dir(exercises)?,
                solution,
                timeout: parse_timeout(timeout)?,
                out,
            };
            let report = grade::grade(&opts, grade::fixture::grading_scene()?)?;
            print!("{}", report.text());
            if let Some(path) = json {
                let text = serde_json::to_string_pretty(&report.gradescope())
                    .map_err(|e| Error::io(&path, std::io::Error::other(e)))?;
                std::fs::write(&path, text).map_err(|e| Error::io(&path, e))?;
            }
            Ok(())
        }
        Command::Exercises {
            command: ExercisesCommand::Export { dir, root },
        } => {
            let root = root.unwrap_or_else(|| {
                if Path::new("exercises/ex1_stereo").is_dir() {
                    PathBuf::from(".")
                } else {
                    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                }
            });
            grade::export::export(&root, &dir)?;
            println!("wrote the student handout to {}", dir.display());
            Ok(())
        }
        Command::Info { scene, sets } => {
            let s = Scene::load(&scene, &sets)?;
            print!("{}", info::describe(&s)?);
            Ok(())
        }
        Command::Figures { scene, out } => {
            let s = Scene::load(&scene, &[])?;
            for p in stereolab::figures::write_all(&s, &out)? {
                println!("wrote {}", p.display());
            }
            Ok(())
        }
        Command::Bench {
            csv,
            scene,
            iterations,
            only,
        } => {
            let mut opts = bench::BenchOptions {
                iterations,
                only,
                ..Default::default()
            };
            if let Some(s) = scene {
                opts.scene = s;
            }
            let rows = bench::run(&opts)?;
            print!("{}", bench::table(&rows));
            if let Some(path) = csv {
                bench::write_csv(&rows, &path)?;
            }
            Ok(())
        }
        Command::Sirds(args) => {
            print!("{}", stereolab::effects::sirds::cli::run(&args)?);
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The whole command runs on a worker of the thread pool, so every parallel pass inside it
    // starts from the pool instead of waking it from outside: a 512×512 SIRDS frame (seed 002
    // Table 1 row 1) made of seven parallel passes took 6–8% less time. The main thread's 8 MB
    // of stack carries over.
    let pool = rayon::ThreadPoolBuilder::new().stack_size(8 << 20).build();
    let result = match pool {
        Ok(pool) => pool.install(|| run(cli)),
        Err(_) => run(cli),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
