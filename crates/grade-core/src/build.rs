//! Building a submission: a clean copy of the exercise crate in which only `src/stubs.rs` comes
//! from the student, compiled with the hash of its sources baked in.
//!
//! Why this shape:
//! - **Nothing but the stubs is taken from a submission.** The manifest, `lib.rs` and `main.rs`
//!   are the grader's own (compiled into stereolab from `exercises/<crate>/`), so a submission
//!   cannot add a dependency (stereolab's reference code, for one) or change how answers travel.
//! - **Never a stale binary.** Each build lives in a folder named by the SHA-256 of everything
//!   it is built from, and the binary reports the hash it was compiled with
//!   (`BINARY --source-hash`); the grader refuses a binary whose hash differs. Compiled
//!   dependencies (glam, serde, `exercise-api`) are shared between submissions in one target
//!   folder, so a warm build compiles only the student's crate.
//! - **Sandboxed on the official paths.** There a submission compiles in the
//!   sandbox ([`crate::sandbox`]) as a user of its own, with a wall-clock limit: it sees its crate,
//!   the toolchain, the registry's sources and the dependencies' artifacts (read-only, built
//!   once from the untouched stubs into `work/deps`), and writes only its own target folder,
//!   whose dependency artifacts are hard links to those (a build cannot change them: they are
//!   not its user's). So `include_str!` of an outside file finds nothing, and a build that does
//!   not end stops at its limit without holding up anyone else's.
//! - **One cargo at a time** where builds share a target folder (a student's own run, and the
//!   shared dependencies): cargo locks it anyway; the work folder's lock file also covers
//!   copying the executable out and mirroring the dependencies, so graders that share a work
//!   folder, the threads of one batch or separate processes, never pick up each other's binaries
//!   nor half-written artifacts. A placed binary that reports its hash is never replaced (a
//!   grader may be running it, and checks its bytes before each run); only a missing or wrong one
//!   is.

use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::Exercise;
use super::child::{Binary, Rlimits, Scratch, spawn_tracked, task_jail, untrack};
use super::sandbox::{self, Jail, Sandbox, User};

/// The largest stubs file the grader reads from a submission.
pub(crate) const MAX_STUBS_BYTES: u64 = 1 << 20;

/// Lines between these markers (inclusive) are the instructor's and are dropped from the handout.
pub const SOLUTION_BEGIN: &str = "solution-begin";
/// See [`SOLUTION_BEGIN`].
pub const SOLUTION_END: &str = "solution-end";

/// Removes every `solution-begin` … `solution-end` block (marker lines included).
pub fn strip_solution(text: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for line in text.lines() {
        if line.contains(SOLUTION_BEGIN) {
            skipping = true;
        } else if line.contains(SOLUTION_END) {
            skipping = false;
        } else if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The handout workspace's build profile, and every exercise build's (in the repository too):
/// no optimization and no debug info for the grader and every dependency, proc macros
/// included. The grader's work (64×48 fixtures, a few thousand numbers per task) takes well
/// under a second unoptimized; what a student waits for is the first build of the grader and
/// its dependencies (docs/performance.md, "A student's first grade").
pub const HANDOUT_PROFILE: &str = "\
[profile.dev]
opt-level = 0
debug = false
incremental = false

[profile.dev.package.\"*\"]
opt-level = 0
debug = false
";

/// The grader's own copy of an exercise crate (everything but the stubs).
struct Template {
    manifest: &'static str,
    lib: &'static str,
    main: &'static str,
    /// The handout's stubs: what the dependencies' artifacts are built with.
    stubs: &'static str,
}

fn template(ex: Exercise) -> Template {
    match ex {
        Exercise::Ex1 => Template {
            manifest: include_str!("../../../exercises/ex1_stereo/Cargo.toml"),
            lib: include_str!("../../../exercises/ex1_stereo/src/lib.rs"),
            main: include_str!("../../../exercises/ex1_stereo/src/main.rs"),
            stubs: include_str!("../../../exercises/ex1_stereo/src/stubs.rs"),
        },
        Exercise::Ex2 => Template {
            manifest: include_str!("../../../exercises/ex2_chromadepth/Cargo.toml"),
            lib: include_str!("../../../exercises/ex2_chromadepth/src/lib.rs"),
            main: include_str!("../../../exercises/ex2_chromadepth/src/main.rs"),
            stubs: include_str!("../../../exercises/ex2_chromadepth/src/stubs.rs"),
        },
        Exercise::Ex3 => Template {
            manifest: include_str!("../../../exercises/ex3_sirds/Cargo.toml"),
            lib: include_str!("../../../exercises/ex3_sirds/src/lib.rs"),
            main: include_str!("../../../exercises/ex3_sirds/src/main.rs"),
            stubs: include_str!("../../../exercises/ex3_sirds/src/stubs.rs"),
        },
    }
}

/// The lock file every build resolves from: the same versions as stereolab, no network.
const LOCK: &str = include_str!("../../../Cargo.lock");
/// stereolab's manifest: whether it has build profiles tells the repository from a handout.
const STEREOLAB_MANIFEST: &str = include_str!("../../../Cargo.toml");

/// Whether this grader runs in a student's handout: its copy of stereolab's manifest has no
/// build profiles (`export::library_manifest`), the repository's has.
fn in_handout() -> bool {
    toml::from_str::<toml::Table>(STEREOLAB_MANIFEST).is_ok_and(|m| !m.contains_key("profile"))
}

/// Where `exercise-api` lives (the build's only dependency besides glam and serde).
pub(crate) fn exercise_api_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../exercises/exercise-api");
    // Canonical: the sandbox binds it at this path, and the shared artifacts name it so.
    std::fs::canonicalize(&dir).unwrap_or(dir)
}

/// The build's manifest: the exercise's own, without the instructor's `solution` feature, with
/// `exercise-api` by absolute path, as a workspace of its own with the handout's profile
/// ([`HANDOUT_PROFILE`]), in the repository as in a handout.
fn manifest(ex: Exercise) -> Result<String, String> {
    let text = strip_solution(template(ex).manifest);
    let mut table: toml::Table =
        toml::from_str(&text).map_err(|e| format!("the grader's manifest: {e}"))?;
    let api = exercise_api_dir();
    let dep = table
        .get_mut("dependencies")
        .and_then(|d| d.get_mut("exercise-api"))
        .and_then(|d| d.as_table_mut())
        .ok_or("the grader's manifest has no exercise-api dependency")?;
    dep.insert(
        "path".into(),
        toml::Value::String(api.to_string_lossy().into_owned()),
    );
    table.insert("workspace".into(), toml::Value::Table(toml::Table::new()));
    // No optimization and no debug info: the exercise crate and its dependencies compile
    // fastest, and every task still answers in milliseconds.
    let profile = toml::from_str::<toml::Table>(HANDOUT_PROFILE)
        .map_err(|e| format!("the handout's profile: {e}"))?
        .remove("profile");
    if let Some(p) = profile {
        table.insert("profile".into(), p);
    }
    toml::to_string(&table).map_err(|e| format!("the build's manifest: {e}"))
}

/// The files of one build, by path inside its folder.
pub(crate) struct Sources {
    files: Vec<(&'static str, String)>,
    /// SHA-256 (hex) of the grader's version and every file's name and bytes.
    pub(crate) hash: String,
}

impl Sources {
    /// The template of `ex` with `stubs` as `src/stubs.rs`.
    pub(crate) fn new(ex: Exercise, stubs: String) -> Result<Sources, String> {
        let t = template(ex);
        let files = vec![
            ("Cargo.toml", manifest(ex)?),
            ("Cargo.lock", LOCK.to_string()),
            ("src/lib.rs", strip_solution(t.lib)),
            ("src/main.rs", t.main.to_string()),
            ("src/stubs.rs", stubs),
        ];
        let mut h = Sha256::new();
        h.update(concat!(
            "stereolab grader ",
            env!("CARGO_PKG_VERSION"),
            "\n"
        ));
        for (name, text) in &files {
            h.update(name.as_bytes());
            h.update((text.len() as u64).to_le_bytes());
            h.update(text.as_bytes());
        }
        let hash = h.finalize().iter().fold(String::new(), |mut s, b| {
            let _ = write!(s, "{b:02x}");
            s
        });
        Ok(Sources { files, hash })
    }
}

/// The work folder's build lock, held while cargo runs in it and its output is copied out or
/// mirrored (see the module documentation). A lock on a file (`flock`), so that it holds
/// between the threads of one grader and between graders that share the folder; it is
/// released when the guard is dropped, or by the system when the process ends.
struct BuildLock {
    _file: std::fs::File,
}

impl BuildLock {
    /// Waits for, then takes, the build lock of `work`.
    fn take(work: &Path) -> Result<BuildLock, String> {
        let path = work.join(".build-lock");
        let io = |e: std::io::Error| format!("{}: {e}", path.display());
        std::fs::create_dir_all(work).map_err(|e| format!("{}: {e}", work.display()))?;
        let file = std::fs::File::options()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)
            .map_err(io)?;
        file.lock().map_err(io)?;
        Ok(BuildLock { _file: file })
    }
}

/// How a submission is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildMode {
    /// In the sandbox, as a user of its own, with its own target folder (the official paths).
    pub sandboxed: bool,
    /// Wall-clock limit of one sandboxed build.
    pub timeout: Duration,
}

impl BuildMode {
    /// The default limit of a sandboxed build (`--build-timeout`): a cold build of an exercise
    /// crate against the shared dependencies takes seconds.
    pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(120);

    /// A plain build (trusted code: the instructor's solution, a student's own run).
    pub const PLAIN: BuildMode = BuildMode {
        sandboxed: false,
        timeout: BuildMode::DEFAULT_TIMEOUT,
    };

    /// Sandboxed when `policy` requires it, stopped at `timeout`.
    pub fn new(policy: super::Policy, timeout: Duration) -> BuildMode {
        BuildMode {
            sandboxed: policy == super::Policy::Required,
            timeout,
        }
    }
}

/// Builds `sources` for `ex` under `work` (`work/bin/<crate>-<hash>`: the checked executable;
/// see [`BuildMode`] for where it compiles). A binary already built from the same hash is
/// reused. `Ok` is the executable with the SHA-256 of its bytes; `Err` the compiler's messages
/// or why the build could not run.
pub(crate) fn build(
    ex: Exercise,
    sources: &Sources,
    work: &Path,
    mode: BuildMode,
) -> Result<Binary, String> {
    // Absolute: the binary runs in a scratch folder of its own, where a relative path is wrong.
    let work = &std::path::absolute(work).map_err(|e| format!("{}: {e}", work.display()))?;
    let name = ex.crate_name();
    let short = &sources.hash[..16];
    let io = |what: &Path, e: std::io::Error| format!("{}: {e}", what.display());
    let bin_dir = work.join("bin");
    let bin = bin_dir.join(format!("{name}-{short}"));
    let ready = || bin.is_file() && reported_hash(&bin).as_deref() == Some(&sources.hash);
    if ready() {
        return Binary::hashed(bin.clone()).map_err(|e| io(&bin, e));
    }
    std::fs::create_dir_all(&bin_dir).map_err(|e| io(&bin_dir, e))?;
    if sandbox::is_root() {
        // Only the grader lists or reads the binaries; each task's sandbox binds its own.
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&bin_dir, std::fs::Permissions::from_mode(0o700))
            .map_err(|e| io(&bin_dir, e))?;
    }
    if mode.sandboxed {
        let dir = build_dir(work, name, short);
        let built = sandboxed_build(ex, sources, work, &dir, mode.timeout);
        let placed = built.and_then(|exe| {
            // A binary another grader placed meanwhile stays: it may be running it.
            let _turn = BuildLock::take(work)?;
            if ready() {
                Ok(())
            } else {
                place(&exe, &bin_dir, &bin)
            }
        });
        let _ = std::fs::remove_dir_all(&dir);
        placed?;
    } else {
        let dir = work.join("src").join(format!("{name}-{short}"));
        let _turn = BuildLock::take(work)?;
        // Another grader may have built it while this one waited for the lock.
        if !ready() {
            write_sources(&dir, sources)?;
            let target = handout_target().unwrap_or_else(|| work.join("target"));
            let exe = cargo_build(&dir, name, &target, &sources.hash)?;
            place(&exe, &bin_dir, &bin)?;
        }
    }
    match reported_hash(&bin) {
        Some(h) if h == sources.hash => Binary::hashed(bin.clone()).map_err(|e| io(&bin, e)),
        other => Err(format!(
            "the built binary reports source hash {other:?}, not {}: refusing to grade code \
             that is not this submission's",
            sources.hash
        )),
    }
}

/// A folder of its own for one sandboxed build.
fn build_dir(work: &Path, name: &str, short: &str) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    work.join("builds").join(format!(
        "{name}-{short}-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Writes `sources` into `dir` (emptied first).
fn write_sources(dir: &Path, sources: &Sources) -> Result<(), String> {
    let io = |what: &Path, e: std::io::Error| format!("{}: {e}", what.display());
    if dir.exists() {
        std::fs::remove_dir_all(dir).map_err(|e| io(dir, e))?;
    }
    for (file, text) in &sources.files {
        let path = dir.join(file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
        }
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
    }
    Ok(())
}

/// Copies the executable `exe` to `bin` (through a partial file: whole or not at all).
fn place(exe: &Path, bin_dir: &Path, bin: &Path) -> Result<(), String> {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let io = |what: &Path, e: std::io::Error| format!("{}: {e}", what.display());
    let partial = bin_dir.join(format!(
        ".partial-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::copy(exe, &partial).map_err(|e| io(exe, e))?;
    std::fs::rename(&partial, bin).map_err(|e| io(bin, e))
}

/// The toolchain the grader builds with, as the sandbox binds it.
struct Toolchain {
    /// `rustc --print sysroot`: rustc, cargo and the standard library.
    sysroot: PathBuf,
    /// Cargo's home: the registry's index and sources (read-only in the sandbox).
    home: PathBuf,
}

fn toolchain() -> Result<&'static Toolchain, String> {
    static TOOLCHAIN: OnceLock<Result<Toolchain, String>> = OnceLock::new();
    TOOLCHAIN
        .get_or_init(|| {
            let rustc = std::env::var_os("RUSTC")
                .map(PathBuf::from)
                .or_else(|| {
                    let cargo = PathBuf::from(std::env::var_os("CARGO")?);
                    let sibling = cargo.with_file_name("rustc");
                    sibling.is_file().then_some(sibling)
                })
                .unwrap_or_else(|| PathBuf::from("rustc"));
            let out = sandbox::output_within(
                Command::new(&rustc)
                    .args(["--print", "sysroot"])
                    .stdin(Stdio::null())
                    .stdout(Stdio::piped())
                    .stderr(Stdio::null()),
                Duration::from_secs(60),
            )
            .map_err(|e| format!("cannot run {}: {e}", rustc.display()))?;
            let sysroot = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
            let sysroot = std::fs::canonicalize(&sysroot)
                .map_err(|e| format!("rustc's sysroot {}: {e}", sysroot.display()))?;
            let home = std::env::var_os("CARGO_HOME")
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
                .ok_or("neither CARGO_HOME nor HOME is set: where is cargo's registry?")?;
            let home = std::fs::canonicalize(&home).unwrap_or(home);
            Ok(Toolchain { sysroot, home })
        })
        .as_ref()
        .map_err(Clone::clone)
}

/// The dependencies' artifacts every sandboxed build of `ex` starts from: the handout's own
/// stubs built (trusted code, outside the sandbox) into `work/deps/target`.
///
/// The caller holds the work folder's [`BuildLock`].
fn deps_target(ex: Exercise, work: &Path) -> Result<PathBuf, String> {
    let sources = Sources::new(ex, template(ex).stubs.to_string())?;
    let dir = work.join("deps").join("src").join(ex.crate_name());
    let unchanged = sources
        .files
        .iter()
        .all(|(f, text)| std::fs::read_to_string(dir.join(f)).is_ok_and(|t| &t == text));
    if !unchanged {
        write_sources(&dir, &sources)?;
    }
    let target = work.join("deps").join("target");
    let tc = toolchain()?;
    let mut cargo = Command::new(tc.sysroot.join("bin/cargo"));
    cargo
        .current_dir(&dir)
        .env_clear()
        .envs(build_env(tc, &dir, &target, &sources.hash));
    unsandboxed_build(cargo, &dir, ex.crate_name())
        .map_err(|e| format!("the handout's own {} does not build: {e}", ex.crate_name()))?;
    Ok(target)
}

/// The environment of both builds of an exercise crate in the grader: the dependencies' (the
/// handout's own stubs, [`deps_target`]) and each submission's in the sandbox, which starts
/// from their artifacts. Nothing else from the grader's environment: a variable cargo or a
/// build script takes into its fingerprints (`RUSTFLAGS`, `RUSTC_BOOTSTRAP`,
/// `CARGO_INCREMENTAL`, a profile override, `CC`) set for one build and not the other would
/// make cargo rebuild the dependencies in the sandbox, where they are read-only, and every
/// submission would fail to build. `home` is the build's own folder. Both run offline: the
/// sandboxed build has no network, so the registry's cache must hold every dependency anyway.
fn build_env(tc: &Toolchain, home: &Path, target: &Path, hash: &str) -> Vec<(String, OsString)> {
    vec![
        (
            "PATH".into(),
            format!("{}/bin:/usr/bin:/bin", tc.sysroot.display()).into(),
        ),
        ("HOME".into(), home.into()),
        ("CARGO_HOME".into(), tc.home.clone().into()),
        ("RUSTC".into(), tc.sysroot.join("bin/rustc").into()),
        ("CARGO_TARGET_DIR".into(), target.into()),
        ("CARGO_NET_OFFLINE".into(), "true".into()),
        ("CARGO_TERM_COLOR".into(), "never".into()),
        ("STEREOLAB_SOURCE_HASH".into(), hash.into()),
    ]
}

/// Mirrors the artifacts under `from` into `to` as hard links, leaving out the crate `own`'s
/// (which the build makes anew) and cargo's lock and caches.
fn mirror(from: &Path, to: &Path, own: &str) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for entry in std::fs::read_dir(from)? {
        let entry = entry?;
        let name = entry.file_name();
        let text = name.to_string_lossy();
        if text.contains(own) || text == ".cargo-lock" || text == ".rustc_info.json" {
            continue;
        }
        let (src, dst) = (entry.path(), to.join(&name));
        let kind = entry.file_type()?;
        if kind.is_dir() {
            mirror(&src, &dst, own)?;
        } else if kind.is_file() && std::fs::hard_link(&src, &dst).is_err() {
            std::fs::copy(&src, &dst)?;
        }
    }
    Ok(())
}

/// Gives `user` the folders under `dir` and the files under `dir/src` (not the hard links to
/// the shared artifacts, which stay the grader's and so read-only to the build).
fn give(dir: &Path, uid: u32, files_too: bool) -> std::io::Result<()> {
    std::os::unix::fs::chown(dir, Some(uid), Some(uid))?;
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let kind = entry.file_type()?;
        let path = entry.path();
        if kind.is_dir() {
            give(&path, uid, files_too || path.ends_with("src"))?;
        } else if files_too && kind.is_file() {
            std::os::unix::fs::chown(&path, Some(uid), Some(uid))?;
        }
    }
    Ok(())
}

/// Compiles `sources` in the sandbox, in `dir`, within `timeout`; the executable's path.
fn sandboxed_build(
    ex: Exercise,
    sources: &Sources,
    work: &Path,
    dir: &Path,
    timeout: Duration,
) -> Result<PathBuf, String> {
    let name = ex.crate_name();
    let io = |what: &Path, e: std::io::Error| format!("{}: {e}", what.display());
    let src = dir.join("src");
    write_sources(&src, sources)?;
    let target = dir.join("target");
    {
        // Built and mirrored under one lock: no other build rewrites the artifacts in between.
        let _turn = BuildLock::take(work)?;
        let deps = deps_target(ex, work)?;
        mirror(&deps, &target, name).map_err(|e| io(&deps, e))?;
    }
    let sandbox = Sandbox::get();
    let user: Option<User> = sandbox.user();
    if let Some(u) = &user {
        give(dir, u.id(), false).map_err(|e| io(dir, e))?;
    }
    let tc = toolchain()?;
    let mut jail = Jail {
        ro: vec![exercise_api_dir()],
        rw: vec![dir.to_path_buf()],
        tmpfs: vec![tc.home.clone()],
        env: build_env(tc, dir, &target, &sources.hash),
        cwd: dir.to_path_buf(),
    };
    if !tc.sysroot.starts_with("/usr") {
        jail.ro.push(tc.sysroot.clone());
    }
    for extra in ["registry", "config.toml", "config"] {
        let p = tc.home.join(extra);
        if p.exists() {
            jail.ro.push(p);
        }
    }
    let mut args = build_args(&src, name);
    args.insert(1, "--offline".into());
    let limits = Rlimits {
        memory: None,
        cpu_seconds: Some(timeout.as_secs() * 4 + 1),
        file_bytes: 1 << 30,
        processes: user.as_ref().map(|_| 512),
    };
    let cargo = tc.sysroot.join("bin/cargo");
    let out = sandbox
        .output(&jail, user.as_ref(), &cargo, &args, limits, timeout)
        .map_err(|e| {
            if e.kind() == std::io::ErrorKind::TimedOut {
                format!(
                    "the build was stopped at its time limit of {} s: does a constant, a macro or \
                 a type take forever to compile?",
                    timeout.as_secs()
                )
            } else {
                format!("cannot run cargo in the sandbox: {e}")
            }
        })?;
    drop(user); // every process of the build's user ends here
    artifact(&out, &src, name)
}

/// The executable cargo reported building, or the compiler's errors.
fn artifact(out: &std::process::Output, dir: &Path, name: &str) -> Result<PathBuf, String> {
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(compiler_errors(&stderr, dir));
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|v| v["reason"] == "compiler-artifact" && v["target"]["name"] == name)
        .find_map(|v| v["executable"].as_str().map(PathBuf::from))
        .ok_or_else(|| format!("cargo built no executable named {name}:\n{stderr}"))
}

/// In a student's handout (whose copy of stereolab's manifest has no profiles), the handout
/// workspace's own target folder: the exercise builds then use the same profile
/// ([`HANDOUT_PROFILE`]) and reuse the dependencies the grader's build compiled
/// there (glam; 7 of the first grade's 18 CPU-s). `cargo run` holds no lock on it while the
/// grader runs. `None` in the repository: `work/target`.
fn handout_target() -> Option<PathBuf> {
    if !in_handout() {
        return None;
    }
    Some(
        std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../target")),
    )
}

/// The hash `bin --source-hash` prints, if it runs (in the sandbox: a submission's code may
/// run before `main`) and prints one within 10 s.
fn reported_hash(bin: &Path) -> Option<String> {
    let sandbox = Sandbox::get();
    let user = sandbox.user();
    let scratch = Scratch::new(user.as_ref()).ok()?;
    let mut jail = task_jail(bin, &scratch.0);
    // Without the answer pipe the hash goes to stdout.
    jail.env
        .retain(|(k, _)| k != exercise_api::protocol::ANSWER_FD_ENV);
    let limits = Rlimits {
        memory: Some(1 << 30),
        cpu_seconds: Some(10),
        file_bytes: 1 << 20,
        processes: user.as_ref().map(|_| 16),
    };
    let args = ["--source-hash".into()];
    let out = sandbox
        .output(
            &jail,
            user.as_ref(),
            bin,
            &args,
            limits,
            Duration::from_secs(10),
        )
        .ok()?;
    drop(user);
    let text = String::from_utf8(out.stdout).ok()?;
    out.status.success().then(|| text.trim().to_string())
}

/// `cmd.output()`, with the process known to the grader as its own while it runs.
fn tracked_output(cmd: &mut Command) -> std::io::Result<std::process::Output> {
    let child = spawn_tracked(cmd)?;
    let pid = child.id();
    let out = child.wait_with_output();
    untrack(pid);
    out
}

/// `cargo build` of the crate in `dir` into `target`, outside the sandbox and in the caller's
/// environment (but for `RUSTFLAGS`): a build not sandboxed, as a student's run on their own
/// machine.
fn cargo_build(dir: &Path, name: &str, target: &Path, hash: &str) -> Result<PathBuf, String> {
    let mut cargo = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()));
    cargo
        .env("CARGO_TARGET_DIR", target)
        .env("STEREOLAB_SOURCE_HASH", hash)
        .env_remove("RUSTFLAGS")
        .env_remove("CARGO_BUILD_RUSTFLAGS");
    unsandboxed_build(cargo, dir, name)
}

/// `cargo`, its environment set, run with [`build_args`] outside the sandbox: the executable
/// it built, or the compiler's errors.
fn unsandboxed_build(mut cargo: Command, dir: &Path, name: &str) -> Result<PathBuf, String> {
    let out = tracked_output(
        cargo
            .args(build_args(dir, name))
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
    )
    .map_err(|e| format!("cannot run cargo: {e}"))?;
    artifact(&out, dir, name)
}

/// `cargo build`'s arguments for the binary `name` of the crate in `dir`, its messages as the
/// JSON [`artifact`] reads.
fn build_args(dir: &Path, name: &str) -> Vec<OsString> {
    vec![
        "build".into(),
        "--manifest-path".into(),
        dir.join("Cargo.toml").into(),
        "--bin".into(),
        name.into(),
        "--message-format=json-render-diagnostics".into(),
    ]
}

/// The error lines of a failed build (warnings and progress left out), at most 40 lines, with
/// the build folder's path shortened to the crate's own paths (`src/stubs.rs:12:5`).
fn compiler_errors(stderr: &str, dir: &Path) -> String {
    let prefix = format!("{}/", dir.display());
    let mut lines: Vec<String> = Vec::new();
    let mut in_error = false;
    for l in stderr.lines() {
        if l.starts_with("error") {
            in_error = true;
        } else if l.starts_with("warning") || l.trim_start().starts_with("Compiling") {
            in_error = false;
        }
        if in_error {
            lines.push(l.replace(&prefix, ""));
        }
    }
    if lines.is_empty() {
        lines = stderr.lines().map(|l| l.replace(&prefix, "")).collect();
    }
    lines.truncate(40);
    lines.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_handout_shares_its_target_folder_with_the_exercise_builds() {
        // The repository's manifest has profiles: its exercise builds stay in `work/target`.
        assert_eq!(handout_target(), None);
        assert!(manifest(Exercise::Ex1).unwrap().contains("[profile.dev"));
    }

    #[test]
    fn the_hash_changes_with_the_stubs_and_the_manifest_is_the_graders() {
        let a = Sources::new(Exercise::Ex2, "pub fn f() {}\n".into()).unwrap();
        let b = Sources::new(Exercise::Ex2, "pub fn f() { }\n".into()).unwrap();
        assert_ne!(a.hash, b.hash);
        assert_eq!(a.hash.len(), 64);
        let manifest = &a.files[0].1;
        assert!(!manifest.contains("solution"), "{manifest}");
        assert!(!manifest.contains("stereolab ="), "{manifest}");
        assert!(manifest.contains("[workspace]"), "{manifest}");
        assert!(manifest.contains("exercises/exercise-api"), "{manifest}");
    }
}
