//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file under `assets/`.
pub fn asset(rel: &str) -> PathBuf {
    root().join("assets").join(rel)
}

/// A fresh folder under `target/test-out/<name>` for files a test writes.
pub fn out_dir(name: &str) -> PathBuf {
    let d = root().join("target").join("test-out").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create test output folder");
    d
}

/// Where failing image tests write `expected | diff | actual` (ignored by git).
pub fn failure_dir() -> PathBuf {
    let d = root().join("tests").join("failures");
    std::fs::create_dir_all(&d).expect("create tests/failures");
    d
}

/// The names in `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

/// Runs netpbm's `pamstereogram` with `args` and writes what it prints to `out`; fails clearly
/// when netpbm is missing.
pub fn pamstereogram<S: AsRef<std::ffi::OsStr>>(args: &[S], out: &Path) {
    let result = std::process::Command::new("pamstereogram")
        .args(args)
        .output();
    let output = result.unwrap_or_else(|e| {
        panic!("pamstereogram could not run ({e}): install Debian's netpbm (.ci/run does)")
    });
    assert!(
        output.status.success(),
        "pamstereogram {:?}: {}",
        args.iter()
            .map(|a| a.as_ref().to_string_lossy())
            .collect::<Vec<_>>(),
        String::from_utf8_lossy(&output.stderr)
    );
    std::fs::write(out, &output.stdout).expect("write stereogram");
}

/// `python3` when it imports `modules` (`.ci/run` puts a virtual environment with PyPI's
/// opencv-python-headless, flip-evaluator, numpy and Pillow first on the path); `None`, with the
/// reason and `install` printed, when it does not, which under CI is a broken setup and fails.
pub fn python_with(modules: &str, install: &str) -> Option<String> {
    let python = "python3".to_string();
    let ok = std::process::Command::new(&python)
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if ok {
        return Some(python);
    }
    let why = format!("{python} cannot import {modules} ({install})");
    assert!(std::env::var_os("CI").is_none(), "{why}");
    eprintln!("skipped: {why}");
    None
}
