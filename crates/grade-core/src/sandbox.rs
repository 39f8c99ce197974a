//! The sandbox every task and every build of a submission runs in, made of the platform's own
//! mechanisms: [bubblewrap](https://github.com/containers/bubblewrap) (`bwrap`, from Debian's
//! and Ubuntu's `bubblewrap` package) for new PID, mount, network, IPC and UTS namespaces, and,
//! when the grader runs as root, a dedicated unprivileged user per run (`setpriv` from
//! util-linux drops to it inside the sandbox).
//!
//! What a sandboxed process sees and may do:
//! - **Files**: `/usr` (and the `/bin`, `/lib` links into it) read-only, a private `/tmp`, a
//!   fresh `/dev` and `/proc`, and the paths its `Jail` names, at their own paths: for a task
//!   its binary (read-only) and its scratch folder; for a build the crate, the toolchain, the
//!   registry's sources and the shared dependency artifacts (read-only), and its own target
//!   folder. Nothing else: not the grader's sources, its results, the seed, other submissions.
//! - **Processes**: its own PID namespace, so it cannot see, trace or signal the grader, and
//!   when the task's first process ends the kernel kills every process it forked, however it
//!   hid (a new session, a double fork). As root, `kill(-1)` as the run's user after the run
//!   as well.
//! - **Network**: none (a namespace with only a loopback that is down).
//!
//! Where no sandbox can be made (no `bwrap`, or user namespaces switched off), a student's own
//! run still grades, unprotected, and [`check_sandbox`](crate::check_sandbox) says so; the official paths (`grade
//! batch`, the Gradescope bundle, any run as root) refuse to grade without one.

use std::collections::BTreeSet;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use crate::child::{Rlimits, limit_resources};

/// How the grader isolates what it runs.
#[derive(Clone, Debug)]
pub(crate) enum Mechanism {
    /// bubblewrap; `setpriv` set when the grader is root (each run drops to its own user).
    Bubblewrap {
        bwrap: PathBuf,
        setpriv: Option<PathBuf>,
    },
    /// No sandbox could be made here: why.
    Unprotected { why: String },
}

/// Whether a run must be sandboxed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Policy {
    /// The official grade (`grade batch`, the Gradescope bundle, any run as root): no sandbox,
    /// no grade.
    Required,
    /// A student's own run: sandboxed tasks where the machine allows, else unprotected with a
    /// note.
    Auto,
}

impl Policy {
    /// [`Policy::Required`] when this process runs as root, else `otherwise`.
    pub fn for_this_user(otherwise: Policy) -> Policy {
        if is_root() {
            Policy::Required
        } else {
            otherwise
        }
    }
}

/// What one sandboxed process may see, at the same paths as outside.
#[derive(Clone, Debug, Default)]
pub(crate) struct Jail {
    /// Bound read-only.
    pub ro: Vec<PathBuf>,
    /// Bound read-write.
    pub rw: Vec<PathBuf>,
    /// Empty directories (a tmpfs) at these paths, before the binds (a binding's parent).
    pub tmpfs: Vec<PathBuf>,
    /// The whole environment.
    pub env: Vec<(String, OsString)>,
    /// The working folder (one of the bound paths).
    pub cwd: PathBuf,
}

/// The first user id of the runs' users when the grader is root: far above the ids a system
/// gives its accounts and its containers' subordinate ranges, and below 2³¹.
const UID_BASE: u32 = 2_000_000_000;
/// Users per grader process (more than tasks run at once).
const UID_SLOTS: u32 = 1024;
/// Grader processes whose user ranges do not overlap (by process id).
const UID_RANGES: u32 = 100_000;
const _: () = assert!(UID_BASE as u64 + UID_RANGES as u64 * UID_SLOTS as u64 <= i32::MAX as u64);

/// The first of this process's run users.
fn uid_base() -> u32 {
    UID_BASE + (std::process::id() % UID_RANGES) * UID_SLOTS
}

/// This process runs as root.
pub(crate) fn is_root() -> bool {
    #[cfg(unix)]
    // SAFETY: plain syscall.
    unsafe {
        libc::geteuid() == 0
    }
    #[cfg(not(unix))]
    false
}

fn find_program(name: &str, var: &str) -> Option<PathBuf> {
    if let Some(p) = std::env::var_os(var) {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH").unwrap_or_else(|| "/usr/bin:/bin".into());
    std::env::split_paths(&path)
        .chain([PathBuf::from("/usr/bin"), PathBuf::from("/bin")])
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// The grader's sandbox, found once per process.
pub(crate) struct Sandbox {
    mechanism: Mechanism,
    /// Users handed out and not yet returned.
    users: Mutex<BTreeSet<u32>>,
}

/// A run's own user (root only): every process of it is killed, and the id freed, on drop.
pub(crate) struct User {
    uid: u32,
}

impl User {
    /// The user and group id.
    pub(crate) fn id(&self) -> u32 {
        self.uid
    }
}

impl Drop for User {
    fn drop(&mut self) {
        kill_all_of(self.uid);
        let sandbox = Sandbox::get();
        sandbox
            .users
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.uid);
    }
}

/// Sends SIGKILL to every process of `uid` (`kill(-1)` from a child that became that user: the
/// kernel signals them all at once, so a process that forks cannot slip through).
fn kill_all_of(uid: u32) {
    #[cfg(unix)]
    // SAFETY: the child only calls async-signal-safe functions (setgid, setuid, kill, _exit).
    unsafe {
        let pid = libc::fork();
        if pid == 0 {
            if libc::setgid(uid) == 0 && libc::setuid(uid) == 0 {
                libc::kill(-1, libc::SIGKILL);
            }
            libc::_exit(0);
        }
        if pid > 0 {
            libc::waitpid(pid, std::ptr::null_mut(), 0);
        }
    }
}

impl Sandbox {
    /// The sandbox of this process (found, and tried on `/usr/bin/true`, on first use).
    pub(crate) fn get() -> &'static Sandbox {
        static SANDBOX: OnceLock<Sandbox> = OnceLock::new();
        SANDBOX.get_or_init(|| Sandbox {
            mechanism: detect(),
            users: Mutex::new(BTreeSet::new()),
        })
    }

    /// Whether processes run sandboxed.
    pub(crate) fn protected(&self) -> bool {
        matches!(self.mechanism, Mechanism::Bubblewrap { .. })
    }

    /// `Ok` when `policy` can be met; the error names what is missing and how to get it.
    pub(crate) fn check(&self, policy: Policy) -> Result<(), String> {
        match (&self.mechanism, policy) {
            (Mechanism::Unprotected { why }, Policy::Required) => Err(format!(
                "the official grade runs every build and task of a submission in a sandbox, and \
                 none can be made here: {why}. Install bubblewrap (`apt-get install bubblewrap`) \
                 on a Linux machine whose kernel allows user namespaces"
            )),
            _ => Ok(()),
        }
    }

    /// One sentence for a student's run without a sandbox (`None` when sandboxed).
    pub fn note(&self) -> Option<String> {
        match &self.mechanism {
            Mechanism::Bubblewrap { .. } => None,
            Mechanism::Unprotected { why } => Some(format!(
                "note: your tasks run without a sandbox ({why}): each in its own process group \
                 with limits on time, memory and file size, but able to read your files and use \
                 the network. That is fine for your own code on your own machine; the official \
                 grade comes from your instructor's sandboxed run."
            )),
        }
    }

    /// A user of its own for one run, when the grader is root (`None` otherwise).
    pub(crate) fn user(&self) -> Option<User> {
        let Mechanism::Bubblewrap {
            setpriv: Some(_), ..
        } = &self.mechanism
        else {
            return None;
        };
        let base = uid_base();
        let mut users = self.users.lock().unwrap_or_else(|e| e.into_inner());
        let uid = (base..base + UID_SLOTS).find(|u| !users.contains(u))?;
        users.insert(uid);
        Some(User { uid })
    }

    /// `program args` inside `jail` (as `user` when given), or plainly with `jail`'s
    /// environment and working folder when unprotected.
    pub(crate) fn command(
        &self,
        jail: &Jail,
        user: Option<&User>,
        program: &Path,
        args: &[OsString],
    ) -> Command {
        self.mechanism
            .command(jail, user.map(User::id), program, args)
    }

    /// [`Sandbox::command`] run to its end under `limits` and within `time` (its whole process
    /// group killed then), stdin empty, stdout and stderr kept.
    pub(crate) fn output(
        &self,
        jail: &Jail,
        user: Option<&User>,
        program: &Path,
        args: &[OsString],
        limits: Rlimits,
        time: Duration,
    ) -> std::io::Result<std::process::Output> {
        let mut cmd = self.command(jail, user, program, args);
        cmd.stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        limit_resources(&mut cmd, limits);
        output_within(&mut cmd, time)
    }
}

impl Mechanism {
    /// See [`Sandbox::command`]; `uid`: the run's own user (root only).
    fn command(&self, jail: &Jail, uid: Option<u32>, program: &Path, args: &[OsString]) -> Command {
        let Mechanism::Bubblewrap { bwrap, setpriv } = self else {
            let mut cmd = Command::new(program);
            cmd.args(args).current_dir(&jail.cwd).env_clear();
            for (k, v) in &jail.env {
                cmd.env(k, v);
            }
            return cmd;
        };
        let mut cmd = Command::new(bwrap);
        cmd.args(bwrap_args(jail, setpriv.is_some()));
        if let (Some(setpriv), Some(uid)) = (setpriv, uid) {
            let id = uid.to_string();
            cmd.arg(setpriv)
                .args(["--reuid", &id, "--regid", &id, "--clear-groups"])
                .args(["--bounding-set", "-all", "--inh-caps", "-all"])
                .args(["--no-new-privs", "--"]);
        }
        cmd.arg(program).args(args).env_clear();
        cmd
    }
}

/// bubblewrap's options for `jail`, up to the command (`--`).
fn bwrap_args(jail: &Jail, root: bool) -> Vec<OsString> {
    let mut a: Vec<OsString> = [
        "--unshare-pid",
        "--unshare-net",
        "--unshare-ipc",
        "--unshare-uts",
        "--unshare-cgroup-try",
        "--die-with-parent",
        "--new-session",
        "--cap-drop",
        "ALL",
    ]
    .map(OsString::from)
    .to_vec();
    if root {
        // Kept only for `setpriv` to drop to the run's user; it clears them all with the uid.
        a.extend(["--cap-add", "CAP_SETUID", "--cap-add", "CAP_SETGID"].map(OsString::from));
    } else {
        a.push("--unshare-user".into());
    }
    a.push("--clearenv".into());
    for (k, v) in &jail.env {
        a.extend([OsString::from("--setenv"), k.into(), v.clone()]);
    }
    a.extend(["--proc", "/proc", "--dev", "/dev", "--tmpfs", "/tmp"].map(OsString::from));
    let mut mounts = Mounts::default();
    mounts.bind("--ro-bind", Path::new("/usr"), &mut a);
    // `/bin`, `/lib`… are links into /usr on a merged-/usr system, folders on an older one.
    for top in ["/bin", "/sbin", "/lib", "/lib32", "/lib64"] {
        match std::fs::read_link(top) {
            Ok(target) => a.extend([
                OsString::from("--symlink"),
                target.into_os_string(),
                top.into(),
            ]),
            Err(_) => mounts.bind("--ro-bind-try", Path::new(top), &mut a),
        }
    }
    // `cc` (the linker rustc calls) is a link through /etc/alternatives on Debian and Ubuntu.
    for etc in ["/etc/alternatives", "/etc/ld.so.cache"] {
        mounts.bind("--ro-bind-try", Path::new(etc), &mut a);
    }
    for p in &jail.tmpfs {
        mounts.parents(p, &mut a);
        a.extend([OsString::from("--tmpfs"), p.into()]);
        mounts.made.insert(p.clone());
    }
    for p in &jail.ro {
        mounts.bind("--ro-bind", p, &mut a);
    }
    for p in &jail.rw {
        mounts.bind("--bind", p, &mut a);
    }
    a.extend([OsString::from("--chdir"), jail.cwd.clone().into()]);
    a.push("--".into());
    a
}

/// The folders that exist inside the sandbox as its options are laid down.
struct Mounts {
    made: BTreeSet<PathBuf>,
}

impl Default for Mounts {
    fn default() -> Mounts {
        Mounts {
            made: ["/", "/proc", "/dev", "/tmp"].map(PathBuf::from).into(),
        }
    }
}

impl Mounts {
    /// bubblewrap makes a missing parent folder private (0700), which the run's user could not
    /// pass: each one is made first, open to all (`--perms 0755 --dir`).
    fn parents(&mut self, p: &Path, a: &mut Vec<OsString>) {
        let mut chain: Vec<&Path> = p.ancestors().skip(1).collect();
        chain.reverse();
        for dir in chain {
            let inside_bind = ["/usr", "/proc", "/dev"].iter().any(|m| dir.starts_with(m));
            if !inside_bind && self.made.insert(dir.to_path_buf()) {
                a.extend(["--perms", "0755", "--dir"].map(OsString::from));
                a.push(dir.into());
            }
        }
    }

    /// `flag p p` (the same path inside), its parents made first.
    fn bind(&mut self, flag: &str, p: &Path, a: &mut Vec<OsString>) {
        self.parents(p, a);
        a.extend([OsString::from(flag), p.into(), p.into()]);
        self.made.insert(p.to_path_buf());
    }
}

/// Finds bubblewrap (and `setpriv` as root) and tries them on `/usr/bin/true`.
fn detect() -> Mechanism {
    if cfg!(not(target_os = "linux")) {
        return Mechanism::Unprotected {
            why: "the sandbox uses Linux namespaces".into(),
        };
    }
    let Some(bwrap) = find_program("bwrap", "STEREOLAB_BWRAP") else {
        return Mechanism::Unprotected {
            why: "bubblewrap (`bwrap`) is not installed".into(),
        };
    };
    let setpriv = if is_root() {
        match find_program("setpriv", "STEREOLAB_SETPRIV") {
            Some(p) => Some(p),
            None => {
                return Mechanism::Unprotected {
                    why: "`setpriv` (util-linux) is missing: as root each run needs it to drop \
                          to a user of its own"
                        .into(),
                };
            }
        }
    } else {
        None
    };
    let mechanism = Mechanism::Bubblewrap { bwrap, setpriv };
    // As root the probe runs as the first user of this process's range, as a run would.
    let uid = is_root().then(uid_base);
    let jail = Jail {
        cwd: "/".into(),
        ..Jail::default()
    };
    let mut cmd = mechanism.command(&jail, uid, Path::new("/usr/bin/true"), &[]);
    cmd.stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let outcome = output_within(&mut cmd, Duration::from_secs(20));
    if let Some(uid) = uid {
        kill_all_of(uid);
    }
    match outcome {
        Ok(out) if out.status.success() => mechanism,
        Ok(out) => Mechanism::Unprotected {
            why: format!(
                "bubblewrap cannot make a sandbox here ({})",
                String::from_utf8_lossy(&out.stderr).trim()
            ),
        },
        Err(e) => Mechanism::Unprotected {
            why: format!("bubblewrap cannot run: {e}"),
        },
    }
}

/// `cmd.output()`, killing the process (its whole group) at `limit`.
pub(crate) fn output_within(
    cmd: &mut Command,
    limit: Duration,
) -> std::io::Result<std::process::Output> {
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(cmd, 0);
    // Known to the grader as its own while it runs (see `child::reap_orphans`).
    let child = crate::child::spawn_tracked(cmd)?;
    let pid = child.id();
    let deadline = Instant::now() + limit;
    let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
    let watchdog = std::thread::spawn(move || {
        if done_rx
            .recv_timeout(deadline.saturating_duration_since(Instant::now()))
            .is_err()
        {
            #[cfg(unix)]
            if let Ok(pid) = i32::try_from(pid) {
                // SAFETY: plain syscall; ESRCH (already gone) is fine.
                unsafe {
                    libc::kill(-pid, libc::SIGKILL);
                }
            }
        }
    });
    let out = child.wait_with_output();
    crate::child::untrack(pid);
    let _ = done_tx.send(());
    let _ = watchdog.join();
    if Instant::now() >= deadline {
        return Err(std::io::Error::new(
            std::io::ErrorKind::TimedOut,
            format!("stopped after the limit of {} s", limit.as_secs()),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parents_of_bound_paths_are_made_passable_once_and_system_folders_are_not() {
        let jail = Jail {
            ro: vec!["/opt/a/b".into(), "/opt/a/c".into(), "/usr/lib/x".into()],
            rw: vec!["/tmp/t1".into()],
            tmpfs: vec![],
            env: vec![],
            cwd: "/tmp/t1".into(),
        };
        let args: Vec<String> = bwrap_args(&jail, false)
            .into_iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        let dirs: Vec<&str> = args
            .windows(2)
            .filter(|w| w[0] == "--dir")
            .map(|w| w[1].as_str())
            .collect();
        assert_eq!(dirs, ["/etc", "/opt", "/opt/a"], "{args:?}");
        assert!(args.ends_with(&["--chdir".into(), "/tmp/t1".into(), "--".into()]));
        assert!(args.contains(&"--unshare-user".to_string()));
        assert!(args.contains(&"--unshare-net".to_string()));
    }
}
