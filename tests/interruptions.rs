//! Whatever ends a run, nothing is left half-written: Ctrl-C, SIGTERM, a file-size limit, a
//! killed earlier run's leftovers, an output set that cannot be finished (render, figures,
//! `sirds --decode --pair`, `exercises export`), and an unbounded thread count; a long run
//! says how far it is on a terminal.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

use crate::common::{asset, names, out_dir};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
}

fn temporaries(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.contains(".tmp-"))
        .collect()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `stereolab render` of the Wuson scene at 64×48 into `dir` (`extra` arguments after).
fn render_small(dir: &Path, extra: &[&str]) -> Command {
    let mut cmd = bin();
    cmd.arg("render")
        .arg(asset("scenes/wuson.toml"))
        .args(["--size", "64x48", "--out"])
        .arg(dir)
        .args(extra);
    cmd
}

/// A temporary file name as the writer makes it, of process `pid`.
fn temporary_name(final_name: &str, pid: u32) -> String {
    format!(".{final_name}.tmp-{pid}-1a2b-0")
}

#[cfg(unix)]
#[test]
fn a_signal_during_a_write_removes_the_unfinished_file_and_names_the_signal() {
    for (signal, name, code) in [
        (libc::SIGINT, "SIGINT", 130),
        (libc::SIGTERM, "SIGTERM", 143),
    ] {
        let dir = out_dir(&format!("interrupt-{name}"));
        let gif = dir.join("turn.gif");
        // An animation is encoded into its temporary file frame by frame: a long write.
        let mut child = bin()
            .arg("sirds")
            .arg(asset("scenes/sirds_sphere.toml"))
            .args(["--frames", "120", "-o"])
            .arg(&gif)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn");
        let start = Instant::now();
        while temporaries(&dir).is_empty() {
            assert!(
                start.elapsed() < Duration::from_secs(300),
                "no temporary file appeared"
            );
            assert!(child.try_wait().expect("wait").is_none(), "ended early");
            std::thread::sleep(Duration::from_millis(5));
        }
        let pid = libc::pid_t::try_from(child.id()).expect("pid");
        // SAFETY: signalling the child this test started.
        assert_eq!(unsafe { libc::kill(pid, signal) }, 0);
        let out = child.wait_with_output().expect("wait");
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(code), "{name}: {err}");
        assert!(
            err.contains(&format!("stopped by {name}"))
                && err.contains("1 unfinished output file(s) removed"),
            "{err}"
        );
        assert_eq!(names(&dir), Vec::<String>::new(), "{name} left files");
    }
}

/// Sets a file-size limit of `bytes` in `cmd`'s process.
#[cfg(unix)]
fn with_file_size_limit(cmd: &mut Command, bytes: u64) {
    use std::os::unix::process::CommandExt;
    // SAFETY: between fork and exec only setrlimit, which is async-signal-safe.
    unsafe {
        cmd.pre_exec(move || {
            let r = libc::rlimit {
                rlim_cur: bytes as libc::rlim_t,
                rlim_max: bytes as libc::rlim_t,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &r) < 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

#[cfg(unix)]
#[test]
fn a_file_size_limit_is_an_error_and_no_output_is_replaced() {
    let reference = out_dir("fsize-reference");
    let out = render_small(&reference, &[]).output().expect("render");
    assert!(out.status.success(), "{}", stderr(&out));
    let sizes: Vec<u64> = names(&reference)
        .iter()
        .map(|n| std::fs::metadata(reference.join(n)).expect("size").len())
        .collect();
    let (small, large) = (
        *sizes.iter().min().expect("outputs"),
        *sizes.iter().max().expect("outputs"),
    );
    assert!(small < large, "{sizes:?}");
    // Room for the smaller outputs, not for the largest: the set fails half way.
    let dir = out_dir("fsize");
    for n in names(&reference) {
        std::fs::write(dir.join(&n), b"old").expect("seed");
    }
    let mut cmd = render_small(&dir, &[]);
    with_file_size_limit(&mut cmd, large - 1);
    let out = cmd.output().expect("render");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("File too large"), "{err}");
    for n in names(&reference) {
        assert_eq!(std::fs::read(dir.join(&n)).expect("kept"), b"old", "{n}");
    }
    assert_eq!(temporaries(&dir), Vec::<String>::new());
}

#[cfg(unix)]
#[test]
fn a_killed_runs_leftovers_are_removed_only_when_provably_stale() {
    let dir = out_dir("stale-leftovers");
    let mut child = Command::new("true").spawn().expect("spawn");
    let dead = child.id();
    child.wait().expect("wait");
    let old = SystemTime::now() - Duration::from_secs(3600);
    let plant = |name: String, when: SystemTime| -> PathBuf {
        let p = dir.join(name);
        let f = std::fs::File::create(&p).expect("plant");
        f.set_modified(when).expect("mtime");
        p
    };
    let stale = plant(temporary_name("left.png", dead), old);
    let fresh = plant(temporary_name("right.png", dead), SystemTime::now());
    let live = plant(temporary_name("anaglyph.png", std::process::id()), old);
    let out = render_small(&dir, &[]).output().expect("render");
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stale.exists(), "a stale leftover of a dead process stays");
    assert!(fresh.exists() && live.exists(), "{:?}", names(&dir));
}

#[test]
fn figures_are_written_all_or_none() {
    let dir = out_dir("figures-all-or-none");
    let figures = || {
        bin()
            .arg("figures")
            .arg(asset("scenes/wuson.toml"))
            .arg("--out")
            .arg(&dir)
            .output()
            .expect("figures")
    };
    let first = figures();
    assert!(first.status.success(), "{}", stderr(&first));
    let written = names(&dir);
    assert!(written.len() > 4, "{written:?}");
    for n in &written {
        std::fs::write(dir.join(n), b"old").expect("seed");
    }
    // The last figure's name is taken by a folder: no figure may be replaced.
    let last = written.last().expect("a figure");
    std::fs::remove_file(dir.join(last)).expect("remove");
    std::fs::create_dir(dir.join(last)).expect("folder");
    let out = figures();
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains(last.as_str()) && err.contains("a folder"),
        "{err}"
    );
    for n in written.iter().filter(|n| *n != last) {
        assert_eq!(std::fs::read(dir.join(n)).expect("kept"), b"old", "{n}");
    }
    assert_eq!(temporaries(&dir), Vec::<String>::new());
}

#[test]
fn a_decoded_pair_that_cannot_be_written_writes_no_depth_either() {
    let dir = out_dir("decode-pair-all-or-none");
    let sirds = dir.join("sphere.png");
    let out = bin()
        .arg("sirds")
        .arg(asset("scenes/sirds_sphere.toml"))
        .arg("-o")
        .arg(&sirds)
        .output()
        .expect("sirds");
    assert!(out.status.success(), "{}", stderr(&out));
    let pair = dir.join("pair");
    std::fs::create_dir_all(pair.join("right.png")).expect("a folder in the way");
    let depth = dir.join("depth.png");
    let out = bin()
        .args(["sirds", "--decode"])
        .arg(&sirds)
        .arg("-o")
        .arg(&depth)
        .arg("--pair")
        .arg(&pair)
        .output()
        .expect("decode");
    let err = stderr(&out);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("right.png") && err.contains("a folder"),
        "{err}"
    );
    assert!(
        !depth.exists(),
        "depth.png written although the pair was not"
    );
    assert_eq!(names(&pair), vec!["right.png".to_string()]);
}

#[test]
fn the_handout_is_not_written_into_a_folder_of_other_files() {
    let dir = out_dir("export-foreign");
    std::fs::write(dir.join("thesis.tex"), b"mine").expect("seed");
    let out = bin()
        .args(["exercises", "export"])
        .arg(&dir)
        .output()
        .expect("export");
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(err.contains("not a handout this command wrote"), "{err}");
    assert_eq!(names(&dir), vec!["thesis.tex".to_string()]);
    assert!(
        temporaries(dir.parent().expect("parent")).is_empty(),
        "a staging folder stayed"
    );
}

#[test]
fn a_thread_count_beyond_the_cap_is_lowered_and_said() {
    let dir = out_dir("threads-cap");
    let out = render_small(&dir, &[])
        .env("RAYON_NUM_THREADS", "5000")
        .output()
        .expect("render");
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("RAYON_NUM_THREADS = 5000 is more than the 256 threads"),
        "{err}"
    );
    // The same bytes as with one thread.
    let one = out_dir("threads-one");
    let out = render_small(&one, &[])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("render");
    assert!(out.status.success(), "{}", stderr(&out));
    for n in names(&one) {
        assert_eq!(
            std::fs::read(one.join(&n)).expect("one"),
            std::fs::read(dir.join(&n)).expect("capped"),
            "{n}"
        );
    }
}

/// A long run on a terminal (`script` from util-linux gives the command a pseudo-terminal)
/// shows a bar with the fields written and an estimate; into a pipe it prints none.
#[cfg(unix)]
#[test]
fn a_long_animation_shows_its_progress_on_a_terminal_only() {
    let dir = out_dir("progress-bar");
    let log = dir.join("terminal.log");
    let command = format!(
        "{} render {} --size 1024x768 --set frame_sequential.cycles=10 --out {}",
        env!("CARGO_BIN_EXE_stereolab"),
        asset("scenes/frame_sequential.toml").display(),
        dir.join("out").display()
    );
    let out = Command::new("script")
        .args(["-qec", &command])
        .arg(&log)
        .stdin(Stdio::null())
        .output()
        .expect("script (util-linux) runs");
    assert!(out.status.success(), "{}", stderr(&out));
    let seen = String::from_utf8_lossy(&std::fs::read(&log).expect("log")).into_owned();
    assert!(
        seen.contains("writing frame_sequential.png") && seen.contains("/20 fields"),
        "{seen}"
    );
    assert!(seen.contains("left)"), "no estimate: {seen}");
    let piped = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .arg("render")
        .arg(asset("scenes/frame_sequential.toml"))
        .args([
            "--size",
            "1024x768",
            "--set",
            "frame_sequential.cycles=10",
            "--out",
        ])
        .arg(dir.join("piped"))
        .output()
        .expect("render");
    assert!(piped.status.success());
    assert!(!stderr(&piped).contains("fields"), "{}", stderr(&piped));
}
