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
//! - **One cargo at a time.** Cargo locks its target folder anyway; the lock here also covers
//!   copying the executable out, so parallel graders never pick up each other's binaries.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;

use serde_json::Value;
use sha2::{Digest, Sha256};

use super::Exercise;
use super::child::{spawn_tracked, untrack};
use super::export::strip_solution;

/// The largest stubs file the grader reads from a submission.
pub(crate) const MAX_STUBS_BYTES: u64 = 1 << 20;

/// The grader's own copy of an exercise crate (everything but the stubs).
struct Template {
    manifest: &'static str,
    lib: &'static str,
    main: &'static str,
}

fn template(ex: Exercise) -> Template {
    match ex {
        Exercise::Ex1 => Template {
            manifest: include_str!("../../../exercises/ex1_stereo/Cargo.toml"),
            lib: include_str!("../../../exercises/ex1_stereo/src/lib.rs"),
            main: include_str!("../../../exercises/ex1_stereo/src/main.rs"),
        },
        Exercise::Ex2 => Template {
            manifest: include_str!("../../../exercises/ex2_chromadepth/Cargo.toml"),
            lib: include_str!("../../../exercises/ex2_chromadepth/src/lib.rs"),
            main: include_str!("../../../exercises/ex2_chromadepth/src/main.rs"),
        },
        Exercise::Ex3 => Template {
            manifest: include_str!("../../../exercises/ex3_sirds/Cargo.toml"),
            lib: include_str!("../../../exercises/ex3_sirds/src/lib.rs"),
            main: include_str!("../../../exercises/ex3_sirds/src/main.rs"),
        },
    }
}

/// The lock file every build resolves from: the same versions as stereolab, no network.
const LOCK: &str = include_str!("../../../Cargo.lock");
/// stereolab's manifest: its build profiles apply to the student's build too.
const STEREOLAB_MANIFEST: &str = include_str!("../../../Cargo.toml");

/// stereolab's build profiles from its manifest: `Some` in the repository, `None` in a
/// student's handout, whose copy of the manifest has none (`export::library_manifest`).
fn repository_profile() -> Result<Option<toml::Value>, String> {
    let stereolab: toml::Table =
        toml::from_str(STEREOLAB_MANIFEST).map_err(|e| format!("stereolab's manifest: {e}"))?;
    Ok(stereolab.get("profile").cloned())
}

/// Where `exercise-api` lives (the build's only dependency besides glam and serde).
pub(crate) fn exercise_api_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../exercises/exercise-api")
}

/// The build's manifest: the exercise's own, without the instructor's `solution` feature, with
/// `exercise-api` by absolute path, as a workspace of its own with stereolab's profiles (the
/// handout's, [`super::export::HANDOUT_PROFILE`], in a handout).
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
    // The repository's profiles; in a student's handout, the handout's (no optimization, no
    // debug info: the exercise crates compile fastest).
    let profile = match repository_profile()? {
        Some(p) => Some(p),
        None => toml::from_str::<toml::Table>(super::export::HANDOUT_PROFILE)
            .map_err(|e| format!("the handout's profile: {e}"))?
            .remove("profile"),
    };
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

/// Serializes cargo and the copy of its output (see the module documentation).
static CARGO: Mutex<()> = Mutex::new(());

/// Builds `sources` for `ex` under `work` (`work/target`: the shared target folder;
/// `work/src/<crate>-<hash>`: the sources; `work/bin/<crate>-<hash>`: the checked executable).
/// A binary already built from the same hash is reused. `Ok(path)` is the executable; `Err` the
/// compiler's messages or why the build could not run.
pub(crate) fn build(ex: Exercise, sources: &Sources, work: &Path) -> Result<PathBuf, String> {
    // Absolute: the binary runs in a scratch folder of its own, where a relative path is wrong.
    let work = &std::path::absolute(work).map_err(|e| format!("{}: {e}", work.display()))?;
    let name = ex.crate_name();
    let short = &sources.hash[..16];
    let bin = work.join("bin").join(format!("{name}-{short}"));
    if bin.is_file() && reported_hash(&bin).as_deref() == Some(&sources.hash) {
        return Ok(bin);
    }
    let dir = work.join("src").join(format!("{name}-{short}"));
    let _turn = CARGO.lock().unwrap_or_else(|e| e.into_inner());
    let io = |what: &Path, e: std::io::Error| format!("{}: {e}", what.display());
    if dir.exists() {
        std::fs::remove_dir_all(&dir).map_err(|e| io(&dir, e))?;
    }
    for (file, text) in &sources.files {
        let path = dir.join(file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| io(parent, e))?;
        }
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
    }
    let target = handout_target().unwrap_or_else(|| work.join("target"));
    let built = cargo_build(&dir, name, &target, &sources.hash)?;
    let bin_dir = work.join("bin");
    std::fs::create_dir_all(&bin_dir).map_err(|e| io(&bin_dir, e))?;
    let partial = bin_dir.join(format!(".{name}-{short}.partial"));
    std::fs::copy(&built, &partial).map_err(|e| io(&built, e))?;
    std::fs::rename(&partial, &bin).map_err(|e| io(&bin, e))?;
    match reported_hash(&bin) {
        Some(h) if h == sources.hash => Ok(bin),
        other => Err(format!(
            "the built binary reports source hash {other:?}, not {}: refusing to grade code \
             that is not this submission's",
            sources.hash
        )),
    }
}

/// In a student's handout (whose copy of stereolab's manifest has no profiles), the handout
/// workspace's own target folder: the exercise builds then use the same profile
/// ([`super::export::HANDOUT_PROFILE`]) and reuse the dependencies the grader's build compiled
/// there (glam; 7 of the first grade's 18 CPU-s). `cargo run` holds no lock on it while the
/// grader runs. `None` in the repository: `work/target`.
fn handout_target() -> Option<PathBuf> {
    if !matches!(repository_profile(), Ok(None)) {
        return None;
    }
    Some(
        std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../target")),
    )
}

/// The hash `bin --source-hash` prints, if it runs and prints one.
fn reported_hash(bin: &Path) -> Option<String> {
    let out = tracked_output(
        Command::new(bin)
            .arg("--source-hash")
            .env_clear()
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null()),
    )
    .ok()?;
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

fn cargo_build(dir: &Path, name: &str, target: &Path, hash: &str) -> Result<PathBuf, String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = tracked_output(
        Command::new(cargo)
            .arg("build")
            .arg("--manifest-path")
            .arg(dir.join("Cargo.toml"))
            .args(["--bin", name, "--message-format=json-render-diagnostics"])
            .env("CARGO_TARGET_DIR", target)
            .env("STEREOLAB_SOURCE_HASH", hash)
            .env_remove("RUSTFLAGS")
            .env_remove("CARGO_BUILD_RUSTFLAGS")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped()),
    )
    .map_err(|e| format!("cannot run cargo: {e}"))?;
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
