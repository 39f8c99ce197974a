//! Running one task of a student's binary, isolated: in the [sandbox](crate::sandbox) (its own
//! namespaces and, as root, its own user), its answers on a pipe of their own (fd 3, never
//! stdout), its stdout and stderr drained while it runs and kept up to a cap, a fresh empty
//! working folder, every process it started killed when the task ends, and limits on memory,
//! CPU time, file size, processes and core dumps. The binary's SHA-256 is checked against its
//! build's right before each run. Every way the child can end is told apart ([`Ending`]), so a
//! crash is not reported as a wrong picture.

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::sandbox::{Jail, Sandbox, User};
use exercise_api::decode_reply;
use exercise_api::protocol::ANSWER_FD_ENV;

/// A built submission binary and the SHA-256 of its bytes when it was built.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Binary {
    /// The executable.
    pub path: PathBuf,
    /// Hex SHA-256 of the file.
    pub sha256: String,
}

impl Binary {
    /// `path` with the hash of its bytes now.
    pub(crate) fn hashed(path: PathBuf) -> std::io::Result<Binary> {
        let sha256 = file_sha256(&path)?;
        Ok(Binary { path, sha256 })
    }

    /// `Err` unless the file still has the bytes it was built with.
    pub(crate) fn verify(&self) -> Result<(), String> {
        match file_sha256(&self.path) {
            Ok(h) if h == self.sha256 => Ok(()),
            Ok(_) => Err(format!(
                "{} changed since it was built: refusing to run it",
                self.path.display()
            )),
            Err(e) => Err(format!("{}: {e}", self.path.display())),
        }
    }
}

/// Hex SHA-256 of a file's bytes.
pub(crate) fn file_sha256(path: &Path) -> std::io::Result<String> {
    use sha2::{Digest, Sha256};
    let bytes = std::fs::read(path)?;
    Ok(Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// Processes the run's own user may have at once (root only: the limit counts per user).
const MAX_PROCESSES: u64 = 256;

/// What a task's process may use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Wall-clock time for the task's inputs (CPU time is limited to the same, rounded up).
    pub time: Duration,
    /// Address space of the process, in bytes.
    pub memory: u64,
}

impl Limits {
    /// 10 s and 1 GiB: every task answers in milliseconds within a few MiB.
    pub const DEFAULT: Limits = Limits {
        time: Duration::from_secs(10),
        memory: 1 << 30,
    };
}

/// The bytes of stdout and of stderr kept for the report (the rest is read and counted).
const KEPT_OUTPUT: usize = 8 << 10;
/// The longest answer line read (a longer one is a broken answer, not a reason to run out of
/// memory in the grader).
const MAX_ANSWER_LINE: u64 = 16 << 20;
/// How long the grader waits for a task's output pipes to end after its processes are killed.
const DRAIN_WAIT: Duration = Duration::from_millis(500);
/// The largest file the task may write (in its scratch folder).
const MAX_FILE_BYTES: u64 = 16 << 20;

/// How a task's process ended, when not by answering every input and exiting with 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Ending {
    /// The hint's id: `timeout`, `cpu-limit`, `out-of-memory`, `stack-overflow`, `abort`,
    /// `crash`, `killed`, `exit`, `no-start`.
    pub kind: &'static str,
    /// What happened, for the details.
    pub message: String,
    /// What to check, for the hint.
    pub hint: &'static str,
}

/// What one run of a task produced.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// One entry per input answered, in order: the flattened answer or the panic message.
    pub replies: Vec<Result<Vec<f64>, String>>,
    /// `None` when every input was answered and the process exited cleanly.
    pub ending: Option<Ending>,
    /// What the task printed to stdout (capped) and how many bytes in all.
    pub stdout: (String, u64),
    /// What the task printed to stderr (capped) and how many bytes in all.
    pub stderr: (String, u64),
}

/// A pipe drained on a thread, keeping the first [`KEPT_OUTPUT`] bytes.
struct Drain {
    kept: Arc<Mutex<(Vec<u8>, u64)>>,
    /// Closed (its sender dropped) when the pipe reached its end.
    ended: mpsc::Receiver<()>,
}

impl Drain {
    fn start(source: Option<impl Read + Send + 'static>) -> Drain {
        let kept = Arc::new(Mutex::new((Vec::new(), 0u64)));
        let (end, ended) = mpsc::channel::<()>();
        if let Some(mut source) = source {
            let k = Arc::clone(&kept);
            std::thread::spawn(move || {
                let _end = end; // dropped when the pipe ends
                let mut buf = [0u8; 8192];
                while let Ok(n) = source.read(&mut buf) {
                    if n == 0 {
                        break;
                    }
                    let mut g = k.lock().unwrap_or_else(|e| e.into_inner());
                    let room = KEPT_OUTPUT.saturating_sub(g.0.len()).min(n);
                    g.0.extend_from_slice(&buf[..room]);
                    g.1 += n as u64;
                }
            });
        }
        Drain { kept, ended }
    }

    /// What the pipe carried, once it ended, or after `wait` if something still holds it open
    /// (a process that escaped the task's group).
    fn take(&self, wait: Duration) -> (String, u64) {
        let _ = self.ended.recv_timeout(wait);
        let g = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        (String::from_utf8_lossy(&g.0).into_owned(), g.1)
    }
}

/// A fresh, empty working folder for one task, removed when dropped.
pub(crate) struct Scratch(pub(crate) PathBuf);

impl Scratch {
    /// A new folder, given to `user` when the run has one (it is the task's to write).
    pub(crate) fn new(user: Option<&User>) -> std::io::Result<Scratch> {
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let dir = std::env::temp_dir().join(format!(
            "stereolab-task-{}-{}",
            std::process::id(),
            NEXT.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir_all(&dir)?;
        let scratch = Scratch(dir);
        #[cfg(unix)]
        if let Some(u) = user {
            std::os::unix::fs::chown(&scratch.0, Some(u.id()), Some(u.id()))?;
        }
        Ok(scratch)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `binary TASK` with `inputs` on stdin under `limits`. Never panics: every way the child
/// can fail is described in the returned [`Run`].
pub fn run(binary: &Binary, task: &str, inputs: &[Value], limits: Limits) -> Run {
    let mut run = Run {
        replies: Vec::new(),
        ending: None,
        stdout: (String::new(), 0),
        stderr: (String::new(), 0),
    };
    let no_start = |e: String| Ending {
        kind: "no-start",
        message: format!("cannot start {}: {e}", binary.path.display()),
        hint: "the grader could not start your program (see above)",
    };
    if let Err(e) = binary.verify() {
        run.ending = Some(no_start(e));
        return run;
    }
    let sandbox = Sandbox::get();
    let user = sandbox.user();
    let scratch = match Scratch::new(user.as_ref()) {
        Ok(s) => s,
        Err(e) => {
            run.ending = Some(no_start(e.to_string()));
            return run;
        }
    };
    let (answers, mut child) = match spawn(&binary.path, task, &scratch.0, limits, user.as_ref()) {
        Ok(x) => x,
        Err(e) => {
            run.ending = Some(no_start(e.to_string()));
            return run;
        }
    };
    let pid = child.id();
    let text = Value::Array(inputs.to_vec()).to_string();
    // A writer thread: a child that never reads must not block the grader.
    if let Some(mut stdin) = child.stdin.take() {
        std::thread::spawn(move || {
            let _ = stdin.write_all(text.as_bytes());
        });
    }
    let out = Drain::start(child.stdout.take());
    let err = Drain::start(child.stderr.take());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut reader = BufReader::new(answers);
        loop {
            let mut line = Vec::new();
            match (&mut reader)
                .take(MAX_ANSWER_LINE)
                .read_until(b'\n', &mut line)
            {
                Ok(0) | Err(_) => break,
                Ok(_) => {
                    let reply = if line.ends_with(b"\n") {
                        decode_reply(&String::from_utf8_lossy(&line))
                    } else if line.len() as u64 >= MAX_ANSWER_LINE {
                        Err(format!("an answer longer than {MAX_ANSWER_LINE} bytes"))
                    } else {
                        decode_reply(&String::from_utf8_lossy(&line))
                    };
                    if tx.send(reply).is_err() {
                        break;
                    }
                }
            }
        }
    });
    let deadline = Instant::now() + limits.time;
    let mut timed_out = false;
    while run.replies.len() < inputs.len() {
        let left = deadline.saturating_duration_since(Instant::now());
        match rx.recv_timeout(left) {
            Ok(reply) => run.replies.push(reply),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                timed_out = true;
                break;
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
    }
    // Every input answered (or the channel closed): give the process a moment to exit.
    let status = if timed_out {
        None
    } else {
        wait_until(&mut child, Instant::now() + Duration::from_secs(2))
    };
    kill_group(pid);
    let status = status.or_else(|| child.wait().ok());
    untrack(pid);
    drop(user); // kills whatever else ran as the task's user
    if !sandbox.protected() {
        // Unprotected, a process in a new session of its own outlives the group kill.
        reap_orphans();
    }
    // Everything the task printed: the pipes end now that its processes are gone.
    run.stdout = out.take(DRAIN_WAIT);
    run.stderr = err.take(DRAIN_WAIT);
    run.ending = if timed_out {
        Some(Ending {
            kind: "timeout",
            message: format!(
                "killed after the time limit of {:?} ({} of {} inputs answered)",
                limits.time,
                run.replies.len(),
                inputs.len()
            ),
            hint: "your code ran past the time limit: an endless loop?",
        })
    } else {
        status.and_then(|s| {
            classify(
                s,
                sandbox.protected(),
                &run.stderr.0,
                run.replies.len(),
                inputs.len(),
                limits,
            )
        })
    };
    run
}

/// Waits for `child` until `deadline`; `None` if it is still running.
fn wait_until(child: &mut Child, deadline: Instant) -> Option<ExitStatus> {
    loop {
        match child.try_wait() {
            Ok(Some(s)) => return Some(s),
            Ok(None) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(2)),
            _ => return None,
        }
    }
}

/// The signal that ended a process: its own, or, through the sandbox (whose first process
/// exits with 128 + the signal of the task it ran, as a shell does), that code's.
fn signal_of(status: ExitStatus, sandboxed: bool) -> Option<i32> {
    #[cfg(unix)]
    if let Some(sig) = std::os::unix::process::ExitStatusExt::signal(&status) {
        return Some(sig);
    }
    match status.code() {
        Some(c) if sandboxed && (129..=128 + 64).contains(&c) => Some(c - 128),
        _ => None,
    }
}

/// Tells apart the ways a process ends early. `None`: it answered everything and exited with 0.
fn classify(
    status: ExitStatus,
    sandboxed: bool,
    stderr: &str,
    answered: usize,
    expected: usize,
    limits: Limits,
) -> Option<Ending> {
    let progress = format!("after {answered} of {expected} answers");
    #[cfg(unix)]
    if let Some(sig) = signal_of(status, sandboxed) {
        let (kind, message, hint) = match sig {
            libc::SIGXCPU => (
                "cpu-limit",
                format!(
                    "stopped at the CPU-time limit of {:?} {progress}",
                    limits.time
                ),
                "your code used more CPU time than allowed: an endless loop?",
            ),
            libc::SIGABRT if stderr.contains("memory allocation of") => (
                "out-of-memory",
                format!(
                    "ran out of memory (limit {} MiB) {progress}",
                    limits.memory >> 20
                ),
                "your code allocates without bound: a loop that pushes forever, or a size \
                 computed from a wrong value?",
            ),
            libc::SIGABRT | libc::SIGSEGV if stderr.contains("overflowed its stack") => (
                "stack-overflow",
                format!("overflowed its stack {progress}"),
                "endless recursion: does a function call itself without a base case?",
            ),
            libc::SIGABRT => (
                "abort",
                format!("aborted (SIGABRT) {progress}"),
                "your code called abort(), or panicked while panicking",
            ),
            libc::SIGSEGV | libc::SIGBUS | libc::SIGILL | libc::SIGFPE => (
                "crash",
                format!("crashed with signal {sig} {progress}"),
                "your program crashed: unsafe code, or a pointer gone wrong?",
            ),
            _ => (
                "killed",
                format!("killed by signal {sig} {progress}"),
                "your program was killed from outside (out of memory on the machine?)",
            ),
        };
        return Some(Ending {
            kind,
            message,
            hint,
        });
    }
    if status.success() && answered == expected {
        return None;
    }
    let code = status.code().unwrap_or(-1);
    Some(Ending {
        kind: "exit",
        message: if code == 3 {
            format!("could not write its answers {progress}")
        } else {
            format!("exited with code {code} {progress}")
        },
        hint: "your code ended the program (std::process::exit?) before answering every input",
    })
}

/// The jail of one task: its binary (read-only) and its scratch folder, nothing else.
pub(crate) fn task_jail(binary: &Path, dir: &Path) -> Jail {
    let mut env: Vec<(String, std::ffi::OsString)> = vec![
        ("PATH".into(), "/usr/bin:/bin".into()),
        ("HOME".into(), dir.into()),
        ("RUST_BACKTRACE".into(), "0".into()),
        (ANSWER_FD_ENV.into(), "3".into()),
    ];
    // The mutation tests plant mistakes in the instructor's solution through this variable.
    if let Some(m) = std::env::var_os("STEREOLAB_MUTANT") {
        env.push(("STEREOLAB_MUTANT".into(), m));
    }
    Jail {
        ro: vec![binary.to_path_buf()],
        rw: vec![dir.to_path_buf()],
        tmpfs: Vec::new(),
        env,
        cwd: dir.to_path_buf(),
    }
}

/// Starts `binary task` in `dir`, in the sandbox (as `user` when given): fd 3 the write end of
/// the answer pipe, its own process group, only its jail's environment, and the limits.
#[cfg(unix)]
fn spawn(
    binary: &Path,
    task: &str,
    dir: &Path,
    limits: Limits,
    user: Option<&User>,
) -> std::io::Result<(std::io::PipeReader, Child)> {
    use std::os::fd::AsRawFd;
    use std::os::unix::process::CommandExt;

    let (reader, writer) = std::io::pipe()?;
    let wfd = writer.as_raw_fd();
    let mut cmd = Sandbox::get().command(&task_jail(binary, dir), user, binary, &[task.into()]);
    cmd.stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0);
    // SAFETY: between fork and exec only async-signal-safe calls (dup2, fcntl).
    unsafe {
        cmd.pre_exec(move || {
            if wfd == 3 {
                if libc::fcntl(3, libc::F_SETFD, 0) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
            } else if libc::dup2(wfd, 3) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    limit_resources(
        &mut cmd,
        Rlimits {
            memory: Some(limits.memory),
            cpu_seconds: Some(limits.time.as_secs() + 1),
            file_bytes: MAX_FILE_BYTES,
            processes: user.map(|_| MAX_PROCESSES),
        },
    );
    let child = spawn_tracked(&mut cmd)?;
    drop(writer); // the child holds the only write end: EOF when it (and its group) is gone
    Ok((reader, child))
}

#[cfg(not(unix))]
fn spawn(
    _binary: &Path,
    _task: &str,
    _dir: &Path,
    _limits: Limits,
    _user: Option<&User>,
) -> std::io::Result<(std::io::PipeReader, Child)> {
    Err(std::io::Error::other(
        "the grader isolates tasks with Unix process groups and limits: grade on Linux or macOS",
    ))
}

/// Resource limits of a sandboxed process (and of all it starts).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rlimits {
    /// Address space, bytes.
    pub memory: Option<u64>,
    /// CPU time, seconds (SIGXCPU at the soft limit, SIGKILL a second later).
    pub cpu_seconds: Option<u64>,
    /// Largest file written, bytes.
    pub file_bytes: u64,
    /// Processes of the run's own user (only when it has one: the count is per user).
    pub processes: Option<u64>,
}

/// Sets `l` (and no core dumps) in `cmd`'s process before it starts.
pub(crate) fn limit_resources(cmd: &mut Command, l: Rlimits) {
    #[cfg(unix)]
    // SAFETY: between fork and exec only async-signal-safe calls (setrlimit, sigaction).
    unsafe {
        use std::os::unix::process::CommandExt;
        cmd.pre_exec(move || {
            let limit = |what, soft: u64, hard: u64| {
                let r = libc::rlimit {
                    rlim_cur: soft as libc::rlim_t,
                    rlim_max: hard as libc::rlim_t,
                };
                if libc::setrlimit(what, &r) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            };
            if let Some(m) = l.memory {
                limit(libc::RLIMIT_AS, m, m)?;
            }
            if let Some(c) = l.cpu_seconds {
                limit(libc::RLIMIT_CPU, c, c + 1)?;
            }
            limit(libc::RLIMIT_FSIZE, l.file_bytes, l.file_bytes)?;
            // The file-size limit kills the task (SIGXFSZ), whatever its parent does with the
            // signal (the stereolab command ignores it, to report the error instead).
            let mut dfl: libc::sigaction = std::mem::zeroed();
            dfl.sa_sigaction = libc::SIG_DFL;
            if libc::sigaction(libc::SIGXFSZ, &dfl, std::ptr::null_mut()) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            limit(libc::RLIMIT_CORE, 0, 0)?;
            if let Some(n) = l.processes {
                limit(libc::RLIMIT_NPROC, n, n)?;
            }
            Ok(())
        });
    }
    #[cfg(not(unix))]
    let _ = (cmd, l);
}

/// Kills the task's whole process group (the task and whatever it started).
fn kill_group(pid: u32) {
    #[cfg(unix)]
    if let Ok(pid) = i32::try_from(pid) {
        // SAFETY: plain syscall; ESRCH (already gone) is fine.
        unsafe {
            libc::kill(-pid, libc::SIGKILL);
        }
    }
}

/// Makes this process the reaper of its orphaned descendants (Linux), so a process a task
/// starts in a new session of its own, to outlive the task, comes back to the grader and is
/// killed (`reap_orphans`).
pub fn become_subreaper() {
    #[cfg(target_os = "linux")]
    // SAFETY: plain syscall with constant arguments.
    unsafe {
        libc::prctl(libc::PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0);
    }
}

/// The grader's own children (tasks, cargo) while they run: everything else whose parent is
/// the grader is an orphan a task left behind.
static CHILDREN: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Spawns `cmd` and records it as one of the grader's own children until [`untrack`].
pub(crate) fn spawn_tracked(cmd: &mut Command) -> std::io::Result<Child> {
    let mut children = CHILDREN.lock().unwrap_or_else(|e| e.into_inner());
    let child = cmd.spawn()?;
    children.push(child.id());
    Ok(child)
}

/// Forgets a child [`spawn_tracked`] started, once it has been waited for.
pub(crate) fn untrack(pid: u32) {
    CHILDREN
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|p| *p != pid);
}

/// Kills and reaps every child of this process the grader did not start itself: orphans a task
/// left behind, re-parented here (see [`become_subreaper`]).
pub(crate) fn reap_orphans() {
    #[cfg(target_os = "linux")]
    {
        let children = CHILDREN.lock().unwrap_or_else(|e| e.into_inner());
        let me = std::process::id().to_string();
        let Ok(entries) = std::fs::read_dir("/proc") else {
            return;
        };
        for e in entries.flatten() {
            let name = e.file_name();
            let Some(pid) = name.to_str().and_then(|s| s.parse::<u32>().ok()) else {
                continue;
            };
            if children.contains(&pid) {
                continue;
            }
            let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
                continue;
            };
            // `pid (comm) state ppid …`: comm may hold spaces and parentheses.
            let Some(rest) = stat.rfind(')').map(|i| &stat[i + 1..]) else {
                continue;
            };
            if rest.split_whitespace().nth(1) != Some(me.as_str()) {
                continue;
            }
            let Ok(pid) = i32::try_from(pid) else {
                continue;
            };
            // SAFETY: plain syscalls on a process that is our child and not one we wait for.
            unsafe {
                libc::kill(pid, libc::SIGKILL);
                libc::waitpid(pid, std::ptr::null_mut(), 0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_binary_whose_bytes_changed_since_its_build_is_not_run() {
        let dir = std::env::temp_dir().join(format!("stereolab-binary-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("task");
        std::fs::write(&path, "#!/bin/sh\nexit 0\n").unwrap();
        let binary = Binary::hashed(path.clone()).unwrap();
        assert_eq!(binary.sha256.len(), 64);
        assert_eq!(binary.verify(), Ok(()));
        std::fs::write(&path, "#!/bin/sh\necho forged\n").unwrap();
        let err = binary.verify().unwrap_err();
        assert!(err.contains("changed since it was built"), "{err}");
        let run = run(&binary, "task", &[], Limits::DEFAULT);
        let ending = run.ending.expect("not run");
        assert_eq!(ending.kind, "no-start", "{ending:?}");
        assert!(run.replies.is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
