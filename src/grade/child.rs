//! Building an exercise crate and running its binary in a subprocess with a time limit.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::exercise::protocol::decode_reply;

/// What one run of a task produced.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// One entry per input answered, in order: the flattened answer or the panic message.
    pub replies: Vec<Result<Vec<f64>, String>>,
    /// The binary ran past the time limit and was killed.
    pub timed_out: bool,
    /// The binary died or misbehaved (exit status and stderr), after the replies it gave.
    pub failure: Option<String>,
}

/// Builds `crate_dir`'s binary (named like the crate) with cargo, in the dev profile so it shares
/// the workspace's compiled dependencies. `Ok(path)` is the executable; `Err` the compiler's
/// messages (a compile error in the student's code is a result to report, not a crash).
/// stereolab is built with the features this grader has (`gpu`), so the build the grader came
/// from is reused instead of compiled again with other features.
pub fn build(crate_dir: &Path, name: &str, solution: bool) -> Result<PathBuf, String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.arg("build")
        .arg("--manifest-path")
        .arg(crate_dir.join("Cargo.toml"))
        .args(["--bin", name, "--message-format=json-render-diagnostics"]);
    if solution {
        cmd.args(["--features", "solution"]);
    }
    if cfg!(feature = "gpu") {
        cmd.args(["--features", "stereolab/gpu"]);
    }
    let out = cmd
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        return Err(compiler_errors(&stderr));
    }
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|v| v["reason"] == "compiler-artifact" && v["target"]["name"] == name)
        .find_map(|v| v["executable"].as_str().map(PathBuf::from))
        .ok_or_else(|| format!("cargo built no executable named {name}:\n{stderr}"))
}

/// The error lines of a failed build (warnings and progress left out), at most 40 lines.
fn compiler_errors(stderr: &str) -> String {
    let mut lines: Vec<&str> = Vec::new();
    let mut in_error = false;
    for l in stderr.lines() {
        if l.starts_with("error") {
            in_error = true;
        } else if l.starts_with("warning") || l.trim_start().starts_with("Compiling") {
            in_error = false;
        }
        if in_error {
            lines.push(l);
        }
    }
    if lines.is_empty() {
        lines = stderr.lines().collect();
    }
    lines.truncate(40);
    lines.join("\n")
}

/// Runs `binary TASK` with `inputs` on stdin; kills it after `limit`. Never panics: every way the
/// child can fail is described in the returned [`Run`].
pub fn run(binary: &Path, task: &str, inputs: &[Value], limit: Duration) -> Run {
    let mut run = Run {
        replies: Vec::new(),
        timed_out: false,
        failure: None,
    };
    let child = Command::new(binary)
        .arg(task)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) => {
            run.failure = Some(format!("cannot start {}: {e}", binary.display()));
            return run;
        }
    };
    let text = Value::Array(inputs.to_vec()).to_string();
    // A writer thread: a child that never reads must not block the grader.
    if let Some(mut stdin) = child.stdin.take() {
        std::thread::spawn(move || {
            let _ = stdin.write_all(text.as_bytes());
        });
    }
    let (tx, rx) = mpsc::channel();
    if let Some(stdout) = child.stdout.take() {
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if tx.send(decode_reply(&line)).is_err() {
                    break;
                }
            }
        });
    }
    let stderr = child.stderr.take();
    let deadline = Instant::now() + limit;
    while run.replies.len() < inputs.len() {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(reply) => run.replies.push(reply),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                run.timed_out = true;
                break;
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    if run.timed_out {
        let _ = child.kill();
        let _ = child.wait();
        return run;
    }
    match child.wait() {
        Ok(status) if status.success() && run.replies.len() == inputs.len() => {}
        Ok(status) => {
            let mut err = String::new();
            if let Some(mut s) = stderr {
                let _ = std::io::Read::read_to_string(&mut s, &mut err);
            }
            let err: String = err.lines().take(5).collect::<Vec<_>>().join("\n");
            run.failure = Some(format!(
                "the exercise binary exited with {status} after {} of {} answers{}{err}",
                run.replies.len(),
                inputs.len(),
                if err.is_empty() { "" } else { ": " }
            ));
        }
        Err(e) => run.failure = Some(format!("waiting for the exercise binary: {e}")),
    }
    run
}
