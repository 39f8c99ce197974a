//! `stereolab view`: the interactive viewer (`stereolab-viewer`), or its benchmark.

use std::path::PathBuf;

use clap::Args;
use stereolab::plan::Output;
use stereolab_core::{Error, Result};
use stereolab_viewer::{self as viewer, Session, ViewOptions};

use super::load_scene;

/// Arguments of `stereolab view`.
#[derive(Args)]
pub struct ViewArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Image size WxH, overriding the scene's.
    #[arg(long)]
    pub size: Option<String>,
    /// Override a scene field: --set stereo.eye_separation=0.2 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// The output shown first (default: the scene's first output), e.g. anaglyph_dubois.
    #[arg(long)]
    pub output: Option<String>,
    /// Where the screenshot key writes its PNG and TOML (default: the scene's folder).
    #[arg(long)]
    pub shots: Option<PathBuf>,
    /// A JSON file rewritten with the readouts after every frame (for scripts and tests).
    #[arg(long, value_name = "FILE")]
    pub state_file: Option<PathBuf>,
    /// No window: render N frames of an orbit about the target and print the median frame
    /// time and frames per second.
    #[arg(long, value_name = "N")]
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
    let mut scene = load_scene(&args.scene, &args.sets, args.size.as_deref())?;
    if let Some(name) = &args.output {
        let o = Output::parse(name).map_err(|e| match e {
            Error::Invalid { value, reason, .. } => Error::invalid("--output", value, reason),
            other => other,
        })?;
        scene.outputs = vec![o];
    }
    let session = Session::new(&scene, &args.scene, &args.sets)?;
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
