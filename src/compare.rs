//! `stereolab compare`: CPU against GPU for a scene, or any two images: metrics and diff strips.

use std::path::PathBuf;
#[cfg(feature = "gpu")]
use std::time::Duration;

use clap::Args;
use stereolab::compare::flip::Viewing;
use stereolab::compare::{self, Comparison, Thresholds};
use stereolab::inspect::{Layout, split};
use stereolab::output::stereo_photo::PhotoFormat;
#[cfg(feature = "gpu")]
use stereolab::plan::Plan;
use stereolab::scene::Scene;
use stereolab_core::{Error, Result};
use stereolab_grade as grade;

use super::load_scene;

/// Arguments of `stereolab compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// A scene file (TOML), or the expected image when ACTUAL is given.
    pub first: PathBuf,
    /// The actual image (compares two image files).
    pub second: Option<PathBuf>,
    /// Folder for the `expected | diff | actual` PNG strips.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Change a limit: coverage=% (0.1), max=0..255 (255), mean=channel (1.0),
    /// psnr=dB (30), depth=window depth (1e-5), flip=mean ꟻLIP 0..1 (none: reported only).
    /// Repeatable.
    #[arg(long = "threshold", value_name = "KEY=VALUE")]
    pub thresholds: Vec<String>,
    /// Image size WxH, overriding the scene's.
    #[arg(long)]
    pub size: Option<String>,
    /// Override a scene field (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// With two images: both are stereo pictures in this layout (side_by_side, cross_eyed,
    /// above_below, half_side_by_side, … as `inspect --layout` takes), compared eye by eye.
    #[arg(long, value_name = "NAME", requires = "second")]
    pub layout: Option<String>,
    /// Background color R,G,B (0..255) for two images; default: each image's top-left pixel.
    #[arg(long)]
    pub background: Option<String>,
    /// Instead of the scene's outputs: the student's ex1 stereo matrices rendered on the
    /// CPU (actual) against the reference rig on the GPU (expected), one row per eye.
    #[arg(long, value_name = "EXERCISE", conflicts_with_all = ["second", "background"])]
    pub exercise: Option<String>,
    /// With --exercise: the instructor's solution instead of the student's code.
    #[arg(long, requires = "exercise")]
    pub solution: bool,
    /// With --exercise: the folder holding the exercise crates (default: ./exercises or .).
    #[arg(long, requires = "exercise")]
    pub exercises: Option<PathBuf>,
    /// ꟻLIP's viewing condition: the display's width in metres (default 0.7).
    #[arg(long, value_name = "METRES")]
    pub display_width: Option<f64>,
    /// ꟻLIP's viewing condition: the viewer's distance from the display in metres (default 0.7).
    #[arg(long, value_name = "METRES")]
    pub display_distance: Option<f64>,
    /// ꟻLIP's viewing condition: the display's horizontal resolution in pixels (default 3840).
    #[arg(long, value_name = "PIXELS")]
    pub display_resolution: Option<f64>,
    /// ꟻLIP's pixels per degree, given directly instead of a display (default 67).
    #[arg(long, value_name = "PPD")]
    pub ppd: Option<f64>,
}

/// Runs `stereolab compare`.
///
/// # Errors
/// Whatever the work fails with; the message names the input.
pub fn run(args: CompareArgs) -> Result<()> {
    let CompareArgs {
        first,
        second,
        out,
        thresholds,
        size,
        sets,
        background,
        layout,
        exercise,
        solution,
        exercises,
        display_width,
        display_distance,
        display_resolution,
        ppd,
    } = args;
    let mut limits = Thresholds::default();
    for t in &thresholds {
        limits.set(t)?;
    }
    let viewing = Viewing::from_flags(display_width, display_distance, display_resolution, ppd)?;
    let mut problems = Vec::new();
    // A failure is named by the input judged: the actual image, or the scene.
    let judged = second.clone().unwrap_or_else(|| first.clone());
    let mut rows = match second {
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
        Some(second) if layout.is_some() => {
            // One picture holding both views: split each into left and right, one row per eye.
            let layout = Layout::parse(layout.as_deref().unwrap_or_default())?;
            let views = |path: &PathBuf| split(&compare::load_image(path)?, layout);
            let bg = background.as_deref().map(parse_rgb).transpose()?;
            let pair = [views(&first)?, views(&second)?];
            compare::compare_views(&first, &second, pair, bg, out.as_deref())?
        }
        Some(second)
            if PhotoFormat::from_path(&first).is_some()
                || PhotoFormat::from_path(&second).is_some() =>
        {
            // Stereo photos (MPO, JPS, PNS): split into left and right, one row per eye.
            let bg = background.as_deref().map(parse_rgb).transpose()?;
            compare::compare_stereo_photos(&first, &second, bg, out.as_deref())?
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
        None if is_image_name(&first) => {
            return Err(Error::invalid(
                "compare",
                first.display(),
                "is an image: compare EXPECTED ACTUAL takes two images (or one scene file, to \
                 compare its CPU and GPU renders)",
            ));
        }
        None => {
            let s = load_scene(&first, &sets, size.as_deref())?;
            compare_scene(&s, out.as_deref())?
        }
    };
    // Each of the rows measured at once may take its share of the memory budget.
    let budget = stereolab::memory::default_budget() / rayon::current_num_threads().max(1) as u64;
    let flip_notes = compare::add_flip(&mut rows, viewing.ppd, out.as_deref(), budget)?;
    outln!("{}", viewing.describe());
    out!("{}", compare::table(&rows));
    for p in rows.iter().filter_map(|r| r.strip.as_ref()) {
        outln!("  wrote {}", p.display());
    }
    for p in rows.iter().filter_map(|r| r.flip.as_ref()?.map.as_ref()) {
        outln!("  wrote {} (ꟻLIP error map, magma)", p.display());
    }
    for note in &flip_notes {
        outln!("  {note}");
    }
    for p in &problems {
        outln!("  {p}");
    }
    let violations = limits.violations(&rows);
    if violations.is_empty() && problems.is_empty() {
        return Ok(());
    }
    let heading = match violations.len() {
        0 => "the comparison found problems".to_string(),
        1 => "1 limit exceeded (a limit is set with --threshold KEY=VALUE)".to_string(),
        n => format!("{n} limits exceeded (a limit is set with --threshold KEY=VALUE)"),
    };
    let mut lines: Vec<String> = violations.into_iter().chain(problems).collect();
    if out.is_none() {
        lines.push(
            "no difference image was written: add --out DIR for `expected | diff | actual` \
             strips that show where"
                .to_string(),
        );
    }
    Err(Error::parse(
        &judged,
        None,
        format!("{heading}:\n  {}", lines.join("\n  ")),
    ))
}

/// A file name with an image extension stereolab reads.
fn is_image_name(path: &std::path::Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        [
            "png", "ppm", "pgm", "pbm", "pam", "pnm", "gif", "mpo", "jps", "pns",
        ]
        .contains(&e.to_ascii_lowercase().as_str())
    })
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

#[cfg(feature = "gpu")]
fn compare_scene(scene: &Scene, out: Option<&std::path::Path>) -> Result<Vec<Comparison>> {
    let r = stereolab_gpu::GpuRenderer::new()?;
    outln!("cpu (expected) vs gpu (actual): {}", r.adapter_name());
    stereolab_gpu::parity::compare_scene(&r, scene, &Plan::new(&scene.outputs), out)
}

#[cfg(not(feature = "gpu"))]
fn compare_scene(_: &Scene, _: Option<&std::path::Path>) -> Result<Vec<Comparison>> {
    Err(super::no_gpu("compare SCENE (CPU against GPU)"))
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
    let r = stereolab_gpu::GpuRenderer::new()?;
    outln!(
        "gpu reference (expected) vs your matrices on the cpu (actual): {}",
        r.adapter_name()
    );
    let c = grade::gpu_compare::compare_exercise(
        &r,
        ex,
        scene,
        &dir,
        solution,
        grade::Limits {
            time: Duration::from_secs(30),
            ..grade::Limits::DEFAULT
        },
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
    Err(super::no_gpu(
        "compare --exercise (your matrices against the GPU)",
    ))
}
