//! The `stereolab` command line: one module per subcommand. The library (`stereolab::…`)
//! does the work; this binary parses arguments, prints, and sets process-wide things (the
//! allocator, the thread pool). `STEREOLAB_SCALAR=1` (the scalar loops for every pass) is read
//! once, where the core chooses its loops (`stereolab_core::uses_avx2` tells which).

/// `print!` to standard output, but a closed pipe or a full disk comes back as an error (which
/// `main` reports, or ends on quietly for a closed pipe) instead of a panic.
macro_rules! out {
    ($($arg:tt)*) => {
        crate::write_stdout(format_args!($($arg)*))?
    };
}

/// `println!` as [`out!`] does it.
macro_rules! outln {
    ($($arg:tt)*) => {
        crate::write_stdout(format_args!("{}\n", format_args!($($arg)*)))?
    };
}

mod bench;
mod compare;
mod exercises;
mod figures;
mod grade;
mod info;
mod inspect;
mod render;
mod sirds;
#[cfg(feature = "viewer")]
mod view;

use std::io::Write as _;
use std::path::Path;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use stereolab::scene::Scene;
use stereolab_core::{Error, Result};

/// mimalloc instead of the system allocator. Every frame allocates and frees framebuffers of a
/// few MB; glibc serves those with mmap and hands them back to the OS on free, so each frame
/// page-faulted its 12.6 MB of targets back in: a 1024×768 stereo pair took 23 ms with glibc
/// against 9.0–9.7 ms with mimalloc, which keeps the pages (same run, `examples`-style loop).
/// A C library, so a feature of its own (`mimalloc`, off by default) that the student handout
/// leaves off: it would only lengthen a student's first build.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// mimalloc's `mi_option_purge_delay` (`mimalloc.h`): how long freed memory stays committed
/// before it is purged, in milliseconds (default 10).
#[cfg(feature = "mimalloc")]
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// mimalloc's `mi_option_purge_decommits` (`mimalloc.h`): whether a purge decommits the memory
/// (default 1) or resets it, leaving the kernel free to take the pages when it needs them.
#[cfg(feature = "mimalloc")]
const MI_OPTION_PURGE_DECOMMITS: libmimalloc_sys::mi_option_t = 5;

/// Freed pages stay with the process for a second, and a purge resets them instead of
/// decommitting them. A frame frees its buffers at its end and the next frame asks for as much
/// again at its start; with mimalloc's defaults the pages were decommitted in between and every
/// one of them faulted back in, zeroed by the kernel: at a million triangles a quarter of the
/// frame's time was spent in the kernel, and 2 ms of a 200 ms frame with these settings. Memory
/// still goes back to the OS when the kernel needs it. Each option's index is checked by its
/// default value before it is set.
#[cfg(feature = "mimalloc")]
fn keep_freed_pages() {
    use libmimalloc_sys::{mi_option_get, mi_option_set};
    // SAFETY: mimalloc's option calls take plain integers and may be called at any time.
    unsafe {
        if mi_option_get(MI_OPTION_PURGE_DELAY) == 10 {
            mi_option_set(MI_OPTION_PURGE_DELAY, 1000);
        }
        if mi_option_get(MI_OPTION_PURGE_DECOMMITS) == 1 {
            mi_option_set(MI_OPTION_PURGE_DECOMMITS, 0);
        }
    }
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
    /// Let a scene read files outside its own folder tree (models, terrain, pattern images).
    /// Off by default, so a scene someone hands you reads nothing else on your machine.
    #[arg(long, global = true)]
    allow_outside_paths: bool,
    /// The most triangles a scene's meshes may have together.
    #[arg(long, global = true, default_value_t = stereolab::scene::DEFAULT_MAX_TRIANGLES,
          value_parser = clap::value_parser!(u64).range(1..=1_000_000_000))]
    max_triangles: u64,
}

/// The scene-loading options of this run (`--allow-outside-paths`, `--max-triangles`).
static LOAD_OPTIONS: std::sync::OnceLock<stereolab::scene::LoadOptions> =
    std::sync::OnceLock::new();

#[derive(Subcommand)]
enum Command {
    /// Render the outputs a scene asks for, as PNG files.
    Render(render::RenderArgs),
    /// Compare the CPU and GPU renders of a scene (`compare SCENE`), or any two images
    /// (`compare EXPECTED.png ACTUAL.png`); exits non-zero past a threshold.
    Compare(compare::CompareArgs),
    /// Build and run the student's exercise crates; points table, verdict and hints.
    Grade(grade::GradeArgs),
    /// Exercise material.
    Exercises {
        #[command(subcommand)]
        command: exercises::ExercisesCommand,
    },
    /// Print the derived cameras and the scene's parallax range.
    Info(info::InfoArgs),
    /// Check another program's stereo picture: read back as two views (layout given or
    /// detected), matched, its mistakes named; exits 3 when a finding is an error.
    Inspect(inspect::InspectArgs),
    /// Draw the slides' figures (rig top views, parallax plot) for a scene.
    Figures(figures::FiguresArgs),
    /// Measure accuracy knobs and speed: error and time side by side.
    Bench(bench::BenchArgs),
    /// Autostereograms (SIRDS): from a scene, from a depth map (--depth), animated (--frames),
    /// or decoded back to depth (--decode).
    Sirds(sirds::SirdsArgs),
    /// The interactive viewer: any output live, camera, rig, readouts, screenshots; or a
    /// stereo pair (--images) as anaglyphs, side by side, its disparity, with an image shift.
    #[cfg(feature = "viewer")]
    View(view::ViewArgs),
}

#[cfg(not(feature = "gpu"))]
fn no_gpu(what: &str) -> Error {
    Error::invalid(
        what,
        "gpu",
        "this stereolab was built without the GPU path: cargo build --release --features gpu",
    )
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || Error::invalid("--size", s, "expected WxH, e.g. 1024x768");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 {
        return Err(Error::invalid(
            "--size",
            s,
            "width and height must be at least 1 pixel",
        ));
    }
    Ok((w, h))
}

/// Runs `work`, showing a spinner with `what` on a terminal's stderr once it has taken more
/// than a second (never for quick work, never into a pipe or a file).
fn with_spinner<T>(what: &str, work: impl FnOnce() -> T) -> T {
    use std::sync::{Arc, Condvar, Mutex};
    let done = Arc::new((Mutex::new(false), Condvar::new()));
    let watcher = {
        let (done, what) = (Arc::clone(&done), what.to_string());
        std::thread::spawn(move || {
            let (lock, cv) = &*done;
            let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
            let (guard, _) = cv
                .wait_timeout_while(guard, std::time::Duration::from_secs(1), |d| !*d)
                .unwrap_or_else(|e| e.into_inner());
            if *guard {
                return;
            }
            drop(guard);
            let bar = indicatif::ProgressBar::new_spinner().with_message(what);
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
            let _unused = cv.wait_while(guard, |d| !*d);
            bar.finish_and_clear();
        })
    };
    let result = work();
    {
        let (lock, cv) = &*done;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cv.notify_all();
    }
    let _ = watcher.join();
    result
}

/// Loads a scene with `--set` overrides and `--size` applied.
fn load_scene(path: &std::path::Path, sets: &[String], size: Option<&str>) -> Result<Scene> {
    let opts = LOAD_OPTIONS.get().copied().unwrap_or_default();
    let mut s = with_spinner(&format!("loading {}", path.display()), || {
        Scene::load_with(path, sets, &opts)
    })?;
    if let Some(size) = size {
        let (w, h) = parse_size(size)?;
        s.set_size(w, h).map_err(|e| match e {
            Error::Invalid { value, reason, .. } => Error::invalid("--size", value, reason),
            other => other,
        })?;
    }
    Ok(s)
}

/// Whether standard output was closed when the process started (`stereolab info >&-`). Before
/// `main`, the Rust runtime opens `/dev/null` on a closed standard descriptor, after which
/// every write succeeds and goes nowhere; [`CHECK_STDOUT`] records the state before it does.
#[cfg(target_os = "linux")]
static STDOUT_CLOSED_AT_START: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Run by the loader with the program's constructors, before the runtime's descriptor
/// sanitizing: notes whether descriptor 1 is open.
#[cfg(target_os = "linux")]
#[used]
#[unsafe(link_section = ".init_array")]
static CHECK_STDOUT: extern "C" fn() = {
    extern "C" fn check_stdout() {
        // SAFETY: F_GETFD only reads the descriptor's flags; it fails (EBADF) when fd 1 is
        // not open.
        let closed = unsafe { libc::fcntl(1, libc::F_GETFD) } == -1;
        STDOUT_CLOSED_AT_START.store(closed, std::sync::atomic::Ordering::Relaxed);
    }
    check_stdout
};

/// An error when standard output was closed at the start: what would be printed is lost.
fn check_stdout_open() -> Result<()> {
    #[cfg(target_os = "linux")]
    if STDOUT_CLOSED_AT_START.load(std::sync::atomic::Ordering::Relaxed) {
        return Err(Error::io(
            Path::new("standard output"),
            std::io::Error::other(
                "it is closed (>&-), so nothing can be printed; redirect it to a file or to \
                 /dev/null instead",
            ),
        ));
    }
    Ok(())
}

/// Writes to standard output and flushes, reporting what the write met (a standard output
/// closed at the start included).
fn write_stdout(args: std::fmt::Arguments) -> Result<()> {
    check_stdout_open()?;
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_fmt(args)
        .and_then(|()| stdout.flush())
        .map_err(|e| Error::io(Path::new("standard output"), e))
}

/// Refuses a file name given to `flag` unless its extension (ASCII case ignored) is one of
/// `accepted`: a file is written in the format its name says, or not at all.
///
/// # Errors
/// `Invalid` naming the flag, the extension and the accepted ones.
fn require_extension(flag: &str, path: &Path, accepted: &[&str]) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str());
    if ext.is_some_and(|e| accepted.iter().any(|a| e.eq_ignore_ascii_case(a))) {
        return Ok(());
    }
    Err(stereolab::output::sirds::unsupported_extension_of(
        flag, path, accepted,
    ))
}

/// Whether the command opens the viewer's window (`view`, `inspect --view`), whose event loop
/// must run on the main thread.
#[cfg(feature = "viewer")]
fn opens_window(command: &Command) -> bool {
    match command {
        Command::View(_) => true,
        Command::Inspect(args) => args.view,
        _ => false,
    }
}

/// Whether `e` is a write to standard output whose reader went away (`stereolab info … | head`):
/// the normal end of a pipeline, not a failure.
fn is_closed_pipe(e: &Error) -> bool {
    matches!(e, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
}

/// Runs the command; `Ok(false)` is a run that worked and says no (a grading verdict of NOT
/// PASSED, an inspected pair with an error among its findings).
fn run(cli: Cli) -> Result<bool> {
    let done = match cli.command {
        Command::Grade(args) => return grade::run(args),
        Command::Render(args) => render::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Exercises { command } => exercises::run(command),
        Command::Info(args) => info::run(args),
        Command::Inspect(args) => return inspect::run(args),
        Command::Figures(args) => figures::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Sirds(args) => sirds::run(&args),
        #[cfg(feature = "viewer")]
        Command::View(args) => view::run(args),
    };
    done.map(|()| true)
}

/// Mesa's Vulkan driver complains twice on stderr ("XDG_RUNTIME_DIR is invalid or not set")
/// when the variable is missing, although the GPU path needs no runtime folder: a run that
/// succeeds must not print errors. Without a usable one, a private folder of this user's is
/// named (created 0700 under the temporary folder).
#[cfg(all(feature = "gpu", unix))]
fn ensure_runtime_dir() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let usable = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir());
    if usable {
        return;
    }
    // SAFETY: getuid has no preconditions.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir().join(format!("stereolab-runtime-{uid}"));
    let ours = std::fs::create_dir_all(&dir).is_ok()
        && std::fs::metadata(&dir).is_ok_and(|m| m.is_dir() && m.uid() == uid)
        && std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).is_ok();
    if ours {
        // SAFETY: called first thing in main, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

/// Ctrl-C (SIGINT), SIGTERM and SIGHUP end the command cleanly: a thread waits for them,
/// removes the temporary files of the outputs being written
/// ([`remove_temporaries`](stereolab_core::remove_temporaries); every output keeps its old
/// content or stays absent) and exits with 128 + the signal's number, as a shell reports a
/// process that a signal ended. A file-size limit (`ulimit -f`, SIGXFSZ) makes the write fail
/// with an error naming the file instead of killing the process without a word.
#[cfg(unix)]
fn end_cleanly_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    // SAFETY: setting a signal's disposition to "ignore" has no preconditions.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return; // the default dispositions stay: the run ends, its temporaries stay behind
    };
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            let removed = stereolab_core::remove_temporaries();
            let name = match sig {
                SIGINT => "SIGINT (Ctrl-C)",
                SIGTERM => "SIGTERM",
                _ => "SIGHUP",
            };
            let _ = writeln!(
                std::io::stderr(),
                "\nstopped by {name}: {removed} unfinished output file(s) removed; no output \
                 is left half-written"
            );
            std::process::exit(128 + sig);
        }
    });
}

/// The most threads a run starts: `RAYON_NUM_THREADS` above it is lowered to it (with a note),
/// since thousands of threads for a few hundred rows only wait on each other.
pub const MAX_THREADS: usize = 256;

/// The thread count of the run: `RAYON_NUM_THREADS` when set to a number from 1 to
/// [`MAX_THREADS`] (above it, the cap, said on stderr), else one a core (rayon's default).
fn thread_count() -> Option<usize> {
    let asked = std::env::var("RAYON_NUM_THREADS").ok()?;
    match asked.trim().parse::<usize>() {
        Ok(n) if n > MAX_THREADS => {
            let _ = writeln!(
                std::io::stderr(),
                "note: RAYON_NUM_THREADS = {n} is more than the {MAX_THREADS} threads a run \
                 uses; using {MAX_THREADS}"
            );
            Some(MAX_THREADS)
        }
        Ok(n) if n > 0 => Some(n),
        _ => None, // 0 or not a number: rayon's own default, one thread a core
    }
}

fn main() -> ExitCode {
    #[cfg(feature = "mimalloc")]
    keep_freed_pages();
    #[cfg(all(feature = "gpu", unix))]
    ensure_runtime_dir();
    #[cfg(unix)]
    end_cleanly_on_signals();
    let cli = Cli::parse();
    let _ = LOAD_OPTIONS.set(stereolab::scene::LoadOptions {
        allow_outside_paths: cli.allow_outside_paths,
        max_triangles: cli.max_triangles,
    });
    // The whole command runs on a worker of the thread pool, so every parallel pass inside it
    // starts from the pool instead of waking it from outside: a 512×512 SIRDS frame (the SIRDS
    // paper's Table 1 row 1) made of seven parallel passes took 6–8% less time. The main
    // thread's 8 MB of stack carries over.
    let threads = thread_count();
    if let Some(n) = threads {
        // The viewer's frames render in the global pool: the same cap.
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .stack_size(8 << 20)
        .build();
    let result = match pool {
        // A window's event loop belongs on the main thread (winit's rule); the viewer's frames
        // render on its own worker thread, in rayon's global pool.
        #[cfg(feature = "viewer")]
        _ if opens_window(&cli.command) => run(cli),
        Ok(pool) => pool.install(|| run(cli)),
        Err(_) => run(cli),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(stereolab_grade::EXIT_NOT_PASSED),
        Err(e) if is_closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            // Standard error may be gone too; nothing more can be said then.
            let _ = writeln!(std::io::stderr(), "error: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    //! The command line's parser, fuzzed: any argument list gives a parsed command
    //! or clap's error, never a panic (`PROPTEST_CASES` sets the count, docs/reliability.md).

    use clap::{CommandFactory, Parser};
    use proptest::prelude::*;

    use super::Cli;

    #[test]
    fn the_command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    fn word() -> impl Strategy<Value = String> {
        prop_oneof![
            prop::sample::select(vec![
                "render",
                "compare",
                "grade",
                "exercises",
                "export",
                "info",
                "figures",
                "bench",
                "sirds",
                "view",
                "--benchmark-frames",
                "--state-file",
                "--shots",
                "--output",
                "batch",
                "bundle",
                "all",
                "ex1",
                "--out",
                "-o",
                "--size",
                "--set",
                "--frames",
                "--depth",
                "--decode",
                "--json",
                "--timeout",
                "--memory-mb",
                "--jobs",
                "--seed",
                "--max-triangles",
                "--allow-outside-paths",
                "--exercise",
                "--solution",
                "--threshold",
                "--backend",
                "gpu",
                "cpu",
                "--help",
                "-h",
                "--version",
                "0",
                "-1",
                "1e30",
                "nan",
                "64x48",
                "0x0",
                "x",
                "=",
                "--",
            ])
            .prop_map(str::to_string),
            "\\PC{0,12}",
        ]
    }

    proptest! {
        #[test]
        fn any_arguments_parse_or_fail_cleanly(args in prop::collection::vec(word(), 0..8)) {
            let argv = std::iter::once("stereolab".to_string()).chain(args);
            let _ = Cli::try_parse_from(argv);
        }
    }
}
