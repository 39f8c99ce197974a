//! `stereolab view`: the interactive viewer (cargo feature `viewer`, on by default), so a
//! student sees what every parameter does while moving it.
//!
//! The viewer is a thin layer over the library. A worker thread renders the latest
//! [`Params`] with the same calls `stereolab render` makes ([`stereolab::Plan::new`] for the one
//! output shown, [`stereolab::render()`], [`stereolab::output::produce`]), so only the passes that
//! output needs run; the window (eframe/egui on OpenGL, which Mesa's software GL provides on a
//! machine without a GPU) shows the last finished frame and never waits for one.
//!
//! - [`session`]: the parameters, how they reach the scene, and the scene file a screenshot
//!   writes (which `stereolab render` turns into the same bytes);
//! - [`frame`]: one frame and its readouts (passes and times, parallax against the ±3% budget);
//! - `gpu` (cargo feature `gpu`): the wgpu path's frame beside the CPU's, with `compare`'s
//!   numbers;
//! - `app` (private): the window, keys and mouse.
//!
//! Without a scene the viewer shows a stereo pair read back by `stereolab inspect`
//! ([`run_pair`]):
//! - [`pair`]: the pair, the ways to show it (anaglyphs, side by side, one eye, the disparity
//!   map) and the horizontal image shift;
//! - `pair_window` (private): its window, keys and readouts.
//!
//! [`benchmark`] renders an orbit without a window (`--benchmark-frames N`).

mod app;
pub mod frame;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod pair;
mod pair_window;
pub mod session;

use std::path::PathBuf;
use std::time::Duration;

pub use frame::{Shown, display_image, render_shown};
pub use pair::{Pair, PairMode, PairParams};
pub use session::{Params, Session};

use stereolab::scene::Scene;
use stereolab_core::{Error, Result};

/// What `stereolab view` was asked besides the scene.
#[derive(Clone, Debug, Default)]
pub struct ViewOptions {
    /// Where the screenshot key writes (`None`: beside the scene file, so the TOML's relative
    /// model paths still hold; for a pair, beside its first image).
    pub shots: Option<PathBuf>,
    /// A JSON file rewritten with the readouts after every frame shown (for scripts and tests).
    pub state_file: Option<PathBuf>,
}

/// Opens the window on `scene` (loaded from `session.path`) and runs until it is closed.
///
/// # Errors
/// No display (`DISPLAY` unset), a window or OpenGL context that cannot be made, or a
/// screenshot folder that cannot be created.
pub fn run(scene: Scene, session: Session, opts: ViewOptions) -> Result<()> {
    check_display(std::env::var_os("DISPLAY"))?;
    app::run(scene, session, opts)
}

/// Opens the window on a stereo `pair`, first shown as `params` says, and runs until it is
/// closed.
///
/// # Errors
/// As [`run`].
pub fn run_pair(pair: Pair, params: PairParams, opts: ViewOptions) -> Result<()> {
    check_display(std::env::var_os("DISPLAY"))?;
    pair_window::run(pair, params, opts)
}

/// The viewer opens an X11 window (on Wayland through XWayland, which sets `DISPLAY`).
///
/// # Errors
/// `display` is unset or empty: an error naming `DISPLAY` and what to do instead.
pub fn check_display(display: Option<std::ffi::OsString>) -> Result<()> {
    match display {
        Some(d) if !d.is_empty() => Ok(()),
        _ => Err(Error::invalid(
            "DISPLAY",
            "(not set)",
            "stereolab view needs a display: it opens an X11 window (XWayland sets DISPLAY on \
             Wayland). Over ssh use `ssh -X`; on a machine without a screen run it under \
             `xvfb-run`, or measure without a window with --benchmark-frames N",
        )),
    }
}

/// The figures of a benchmark run.
#[derive(Clone, Debug)]
pub struct BenchmarkReport {
    /// Frames rendered.
    pub frames: usize,
    /// Median time of a whole viewer frame on the worker thread: the library's render, the
    /// readouts, and the texture pixels for the window.
    pub median_frame: Duration,
    /// Median of each pass, by name, in plan order.
    pub median_passes: Vec<(String, Duration)>,
    /// Median time of making the output from the passes.
    pub median_effect: Duration,
    /// Median of the library's render alone (passes and output: what `stereolab render`
    /// spends on the frame).
    pub median_library: Duration,
    /// Median of the readouts (parallax range, budget, ChromaDepth range).
    pub median_readouts: Duration,
    /// Median of turning the output into the window's texture pixels ([`display_image`]).
    pub median_display: Duration,
}

impl BenchmarkReport {
    /// Frames per second at the median frame time.
    pub fn fps(&self) -> f64 {
        1.0 / self.median_frame.as_secs_f64().max(1e-9)
    }
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v.get(v.len() / 2).copied().unwrap_or_default()
}

/// Renders `frames` frames of a full orbit of the camera about its target (360°/`frames`
/// per frame) with the worker's own frame function ([`render_shown`]: passes, output,
/// readouts, then [`display_image`]: the texture pixels), and returns the medians. Nothing else
/// changes between frames. The window's own share (moving the pixels into its OpenGL texture
/// and painting) is not in it: the viewer shows that as "window" in its readouts.
///
/// # Errors
/// `frames` is 0 or above 100 000, or a frame fails.
pub fn benchmark(
    mut scene: Scene,
    session: &Session,
    mut params: Params,
    frames: usize,
) -> Result<BenchmarkReport> {
    if !(1..=100_000).contains(&frames) {
        return Err(Error::invalid(
            "--benchmark-frames",
            frames,
            "must lie in 1..=100000",
        ));
    }
    let step = 360.0 / frames as f32;
    let (mut totals, mut effects, mut library, mut readouts, mut display) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut passes: Vec<(String, Vec<Duration>)> = Vec::new();
    for _ in 0..frames {
        params.orbit(step, 0.0);
        session.apply(&params, &mut scene);
        let start = std::time::Instant::now();
        let shown = render_shown(&scene, &params, None)?;
        let shown_at = std::time::Instant::now();
        let pixels = display_image(&shown.image);
        let done = std::time::Instant::now();
        std::hint::black_box(&pixels);
        totals.push(done - start);
        display.push(done - shown_at);
        library.push(shown.total);
        readouts.push(shown.readouts);
        effects.push(shown.effect);
        for (name, t) in shown.passes {
            match passes.iter_mut().find(|(n, _)| *n == name) {
                Some((_, v)) => v.push(t),
                None => passes.push((name, vec![t])),
            }
        }
    }
    Ok(BenchmarkReport {
        frames,
        median_frame: median(totals),
        median_passes: passes.into_iter().map(|(n, v)| (n, median(v))).collect(),
        median_effect: median(effects),
        median_library: median(library),
        median_readouts: median(readouts),
        median_display: median(display),
    })
}
