//! `stereolab view`: the interactive viewer (`stereolab-viewer`) on a scene or on a stereo
//! pair (`--images`, read as `stereolab inspect` reads it), or its benchmark.

use std::path::PathBuf;

use clap::Args;
use stereolab::inspect::{Layout, Measured, Views};
use stereolab::plan::Output;
use stereolab_core::{Error, Result};
use stereolab_viewer::{self as viewer, Pair, PairMode, PairParams, Session, ViewOptions};

use super::load_scene;

/// Arguments of `stereolab view`.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("shown").required(true).args(["scene", "images"])))]
pub struct ViewArgs {
    /// Scene file (TOML).
    pub scene: Option<PathBuf>,
    /// A stereo pair instead of a scene: one picture holding both views (any layout
    /// `stereolab inspect` reads), or a left and a right picture.
    #[arg(long, num_args = 1..=2, value_name = "IMAGE")]
    pub images: Vec<PathBuf>,
    /// With --images: the layout instead of detecting it (the names `stereolab inspect
    /// --layout` takes).
    #[arg(long, conflicts_with = "scene")]
    pub layout: Option<String>,
    /// Image size WxH, overriding the scene's.
    #[arg(long, conflicts_with = "images")]
    pub size: Option<String>,
    /// Override a scene field: --set stereo.eye_separation=0.2 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", conflicts_with = "images")]
    pub sets: Vec<String>,
    /// The output shown first (default: the scene's first output; for a pair,
    /// anaglyph_dubois), e.g. anaglyph_dubois.
    #[arg(long)]
    pub output: Option<String>,
    /// Where the screenshot key writes its PNG and TOML (default: the scene's folder, or the
    /// first image's).
    #[arg(long)]
    pub shots: Option<PathBuf>,
    /// A JSON file rewritten with the readouts after every frame (for scripts and tests).
    #[arg(long, value_name = "FILE")]
    pub state_file: Option<PathBuf>,
    /// No window: render N frames of an orbit about the target and print the median frame
    /// time and frames per second.
    #[arg(long, value_name = "N", conflicts_with = "images")]
    pub benchmark_frames: Option<usize>,
}

/// Runs `stereolab view`.
///
/// # Errors
/// The scene does not load, there is no display, or a frame fails.
pub fn run(args: ViewArgs) -> Result<()> {
    if let Some(path) = &args.state_file {
        crate::require_extension("--state-file", path, &["json"])?;
    }
    let Some(path) = &args.scene else {
        return view_images(&args);
    };
    let mut scene = load_scene(path, &args.sets, args.size.as_deref())?;
    if let Some(name) = &args.output {
        let o = Output::parse(name).map_err(|e| match e {
            Error::Invalid { value, reason, .. } => Error::invalid("--output", value, reason),
            other => other,
        })?;
        scene.outputs = vec![o];
    }
    let session = Session::new(&scene, path, &args.sets)?;
    let Some(frames) = args.benchmark_frames else {
        let opts = ViewOptions {
            shots: args.shots,
            state_file: args.state_file,
        };
        return viewer::run(scene, session, opts);
    };
    let params = session.initial.clone();
    let (w, h) = (scene.width, scene.height);
    let r = viewer::benchmark(scene, &session, params.clone(), frames)?;
    outln!(
        "view benchmark: {} at {w}x{h}, {} frames of an orbit",
        params.output.name(),
        r.frames
    );
    for (name, t) in &r.median_passes {
        outln!("  pass {name}: median {:.2} ms", t.as_secs_f64() * 1e3);
    }
    outln!(
        "  {}: median {:.2} ms",
        params.output.name(),
        r.median_effect.as_secs_f64() * 1e3
    );
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    outln!(
        "  library render (passes + output): median {:.2} ms",
        ms(r.median_library)
    );
    outln!("  readouts: median {:.2} ms", ms(r.median_readouts));
    outln!(
        "  texture pixels for the window: median {:.2} ms",
        ms(r.median_display)
    );
    outln!(
        "  viewer frame (library + readouts + texture pixels): median {:.2} ms, {:.1} frames/s \
         ({:.2}x the library render)",
        ms(r.median_frame),
        r.fps(),
        r.median_frame.as_secs_f64() / r.median_library.as_secs_f64().max(1e-9)
    );
    Ok(())
}

/// `stereolab view --images`: the pair read as `stereolab inspect` reads it (its errors, before
/// any window opens), then the window.
fn view_images(args: &ViewArgs) -> Result<()> {
    let layout = args.layout.as_deref().map(Layout::parse).transpose()?;
    let mut params = PairParams::default();
    if let Some(name) = &args.output {
        params.mode = PairMode::parse(name)?;
    }
    let pair = Pair::read(&args.images, layout)?;
    let opts = ViewOptions {
        shots: args.shots.clone(),
        state_file: args.state_file.clone(),
    };
    viewer::run_pair(pair, params, opts)
}

/// `stereolab inspect --view`: the window on the pair just inspected, with its measurement.
///
/// # Errors
/// No display, or a window that cannot be opened.
pub fn view_inspected(views: Views, images: &[PathBuf], measured: Measured) -> Result<()> {
    let pair = Pair {
        views,
        images: images.to_vec(),
        measured: Some(measured),
    };
    viewer::run_pair(pair, PairParams::default(), ViewOptions::default())
}
