//! The attacks in `tests/data/attacks/` against the official paths: one `grade batch` of all of
//! them beside an honest submission, as CI runs it (as root: each build and task in a bubblewrap
//! sandbox as a user of its own). None gains a point or reads a secret; the honest one keeps
//! full marks.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use serde_json::Value;

use crate::common::{out_dir, root};
use crate::grading::{repo_exercises, target_dir, tests_of};

/// The instructor's seed for the hidden cases (never to appear in anything a task can reach).
const SEED: &str = "9173548201";
/// The text of a file of the grader's machine that no submission may read.
pub(crate) const SECRET: &str = "TOPSECRET-7f3a91c4";
pub(crate) const KRATE: &str = "ex2_chromadepth";
const DEPTH_RANGE: &str = "pub fn depth_range(center: Vec3, radius: f32) -> [f32; 2] {\n";
const DEPTH_RANGE_BODY: &str = "    [-center.z - radius, -center.z + radius]\n}";

/// Paths the attacks aim at, substituted for their `@…@` placeholders.
pub(crate) struct Targets {
    /// The results folder (`@OUT@`).
    pub results: PathBuf,
    /// The results.json the hopper forges (`@RESULTS@`).
    pub results_json: PathBuf,
    /// The CSV of all scores (`@SCORES@`).
    pub scores: PathBuf,
    /// The grader's build folder (`@WORK@`).
    pub work: PathBuf,
    /// A file of the grader's machine (`@SECRET@`).
    pub secret: PathBuf,
}

/// The instructor's ex2 solution with `attack`'s file spliced in (see the folder's README).
pub(crate) fn spliced(attack: &str, t: &Targets) -> String {
    let solution =
        std::fs::read_to_string(repo_exercises().join(KRATE).join("src/solution.rs")).unwrap();
    assert!(solution.contains(DEPTH_RANGE) && solution.contains(DEPTH_RANGE_BODY));
    let code = std::fs::read_to_string(root().join(format!("tests/data/attacks/{attack}.rs")))
        .unwrap()
        .replace("@RESULTS@", &t.results_json.display().to_string())
        .replace("@SCORES@", &t.scores.display().to_string())
        .replace("@OUT@", &t.results.display().to_string())
        .replace("@WORK@", &t.work.display().to_string())
        .replace("@SECRET@", &t.secret.display().to_string());
    let text = if attack == "classmate" {
        solution.replace(
            DEPTH_RANGE_BODY,
            "    classmate_depth_range(center, radius)\n}",
        )
    } else {
        solution.replace(
            DEPTH_RANGE,
            &format!("{DEPTH_RANGE}    attack(center, radius);\n"),
        )
    };
    format!("{text}\n{code}")
}

const ATTACKS: [&str; 8] = [
    "hopper",
    "proc_reader",
    "input_printer",
    "classmate",
    "system_caller",
    "signaller",
    "include_outside",
    "const_loop",
];

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Every text file under `dir`, by path.
fn texts_under(dir: &Path) -> BTreeMap<PathBuf, String> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let p = entry.path();
        if p.is_dir() {
            out.extend(texts_under(&p));
        } else if let Ok(text) = std::fs::read_to_string(&p) {
            out.insert(p, text);
        }
    }
    out
}

/// All a results.json says: its top-level output and every test's (a passing task's details,
/// what its program printed among them, are only there).
pub(crate) fn said(v: &Value) -> String {
    let mut text = v["output"].as_str().unwrap_or("").to_string();
    for t in tests_of(v) {
        text.push('\n');
        text.push_str(t["output"].as_str().unwrap_or(""));
    }
    text
}

/// All a submission's results say: report.txt and [`said`] of its results.json.
fn report(results: &Path, name: &str) -> String {
    let text = std::fs::read_to_string(results.join(name).join("report.txt"))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    format!("{text}\n{}", said(&results_json(results, name)))
}

fn results_json(results: &Path, name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(results.join(name).join("results.json")).unwrap())
        .unwrap()
}

#[test]
fn no_attack_in_a_batch_gains_a_point_or_reads_a_secret() {
    let base = out_dir("grading_sandbox");
    let subs = base.join("submissions");
    let t = Targets {
        results: base.join("results"),
        results_json: base.join("results/hopper/results.json"),
        scores: base.join("results/scores.csv"),
        work: base.join("work"),
        secret: base.join("secret.txt"),
    };
    write(&t.secret, &format!("{SECRET}\n"));
    let _ = std::fs::remove_file("/tmp/stereolab-pwned");
    let solution =
        std::fs::read_to_string(repo_exercises().join(KRATE).join("src/solution.rs")).unwrap();
    write(
        &subs.join("honest").join(KRATE).join("src/stubs.rs"),
        &solution,
    );
    for attack in ATTACKS {
        write(
            &subs.join(attack).join(KRATE).join("src/stubs.rs"),
            &spliced(attack, &t),
        );
    }
    // A stubs.rs that is a link to the secret: followed, its text came back in compile errors.
    let link = subs.join("symlink").join(KRATE).join("src/stubs.rs");
    std::fs::create_dir_all(link.parent().unwrap()).unwrap();
    std::os::unix::fs::symlink(&t.secret, &link).unwrap();

    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["grade", "batch"])
        .arg(&subs)
        .arg("--out")
        .arg(&t.results)
        .arg("--build-dir")
        .arg(&t.work)
        .args(["--jobs", "2", "--exercises-list", "ex2", "--timeout", "8"])
        .args(["--build-timeout", "30"])
        .env("CARGO_TARGET_DIR", target_dir())
        .env("STEREOLAB_GRADER_SEED", SEED)
        .output()
        .expect("run stereolab");
    let log = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{log}");
    let csv = std::fs::read_to_string(t.results.join("scores.csv")).unwrap();
    let hopper_json = std::fs::read_to_string(t.results.join("hopper/results.json")).unwrap();
    // The hopper would go on for 15 s: give any survivor time to forge.
    std::thread::sleep(Duration::from_secs(3));

    let scores: BTreeMap<&str, &str> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let mut f = l.split(',');
            (f.next().unwrap(), f.next().unwrap())
        })
        .collect();
    let expected = [
        // Correct formulas beside the attack: full marks, nothing more.
        ("honest", "5.00"),
        ("hopper", "5.00"),
        ("proc_reader", "5.00"),
        ("input_printer", "5.00"),
        ("system_caller", "5.00"),
        ("signaller", "5.00"),
        // No formula of its own for depth_range (1 point), and no classmate to call.
        ("classmate", "4.00"),
        // Does not build: the outside file is not there; the constant is stopped.
        ("include_outside", "0.00"),
        ("const_loop", "0.00"),
        ("symlink", "0.00"),
    ];
    assert_eq!(
        scores,
        expected.into_iter().collect::<BTreeMap<_, _>>(),
        "{csv}"
    );
    assert!(!csv.contains("999"), "{csv}");

    // Nothing any result file holds carries the seed or the secret.
    for (path, text) in texts_under(&t.results) {
        for secret in [SEED, SECRET, "STEREOLAB_GRADER_SEED="] {
            assert!(
                !text.contains(secret),
                "{} holds {secret}:\n{text}",
                path.display()
            );
        }
    }

    // The hopper ran, and its forgery never landed.
    assert!(
        report(&t.results, "hopper").contains("hopper started"),
        "{}",
        report(&t.results, "hopper")
    );
    assert_eq!(
        std::fs::read_to_string(t.results.join("hopper/results.json")).unwrap(),
        hopper_json
    );
    assert_eq!(results_json(&t.results, "hopper")["score"], 5.0);
    assert_eq!(
        std::fs::read_to_string(t.results.join("scores.csv")).unwrap(),
        csv
    );

    // The /proc reader saw only its own sandbox: no seed, the parent's memory closed.
    let proc = report(&t.results, "proc_reader");
    assert!(proc.contains("proc reader ran"), "{proc}");
    assert!(
        proc.contains("memory open: false") && proc.contains("found []"),
        "{proc}"
    );

    // The input printer's visible output lists the public inputs only.
    let printer = results_json(&t.results, "input_printer");
    let visible: Vec<&Value> = tests_of(&printer)
        .iter()
        .filter(|t| t["visibility"] == "visible")
        .collect();
    let depth = visible
        .iter()
        .find(|t| t["name"] == "ex2 depth_range")
        .expect("the visible depth_range test");
    let public = std::fs::read_to_string(t.results.join("input_printer/report.txt"))
        .unwrap()
        .lines()
        .find(|l| l.contains(" depth_range "))
        .and_then(|l| l.split_whitespace().nth(5))
        .and_then(|c| c.split('/').nth(1))
        .and_then(|n| n.parse::<usize>().ok())
        .expect("the number of public depth_range cases");
    let printed = depth["output"]
        .as_str()
        .unwrap()
        .matches("input printer:")
        .count();
    assert_eq!(printed, public, "{depth}");
    assert!(
        tests_of(&printer)
            .iter()
            .any(|t| t["name"] == "ex2 depth_range (hidden cases)"
                && t["visibility"] == "after_published"),
        "the seed made hidden cases: {printer}"
    );
    let top = printer["output"].as_str().unwrap();
    assert!(
        top.contains("published with the grades") && !top.contains("hidden cases:"),
        "{top}"
    );

    // The classmate caller found no one to call.
    let classmate = report(&t.results, "classmate");
    assert!(
        classmate.contains("classmate binaries run: 0"),
        "{classmate}"
    );

    // system() ran a shell, which reached no file outside and no network.
    let system = report(&t.results, "system_caller");
    assert!(system.contains("system() ran"), "{system}");
    assert!(!system.contains("network-open"), "{system}");
    assert!(!t.results.join("pwned").exists());
    assert!(!Path::new("/tmp/stereolab-pwned").exists());

    // The signaller reached no one (the batch went on; every other score is as expected).
    assert!(
        report(&t.results, "signaller").contains("signaller: kill(parent"),
        "{}",
        report(&t.results, "signaller")
    );

    // The outside file is not in the build's sandbox; the endless constant met the limit.
    let include = report(&t.results, "include_outside");
    assert!(
        include.contains("does not compile") && include.contains("couldn't read"),
        "{include}"
    );
    let spin = report(&t.results, "const_loop");
    assert!(spin.contains("time limit of 30 s"), "{spin}");
    let link = report(&t.results, "symlink");
    assert!(link.contains("symbolic link"), "{link}");
}

/// Under `base`, a folder of one submission, `a`, whose stubs are the instructor's ex2
/// solution; its path.
fn solution_only(base: &Path) -> PathBuf {
    let subs = base.join("submissions");
    let solution =
        std::fs::read_to_string(repo_exercises().join(KRATE).join("src/solution.rs")).unwrap();
    write(&subs.join("a").join(KRATE).join("src/stubs.rs"), &solution);
    subs
}

/// `grade batch` of the submissions in `subs`, ex2 only, one job, results into `results`,
/// built in `work` (the command, not yet run).
fn batch_of_ex2(subs: &Path, results: &Path, work: &Path) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stereolab"));
    cmd.args(["grade", "batch"])
        .arg(subs)
        .arg("--out")
        .arg(results)
        .arg("--build-dir")
        .arg(work)
        .args(["--jobs", "1", "--exercises-list", "ex2"])
        .env("CARGO_TARGET_DIR", target_dir());
    cmd
}

#[test]
fn a_binary_changed_after_its_build_is_not_run() {
    let base = out_dir("grading_sandbox_swap");
    let subs = solution_only(&base);
    let work = base.join("work");
    let batch = |results: &Path| {
        batch_of_ex2(&subs, results, &work)
            .output()
            .expect("run stereolab")
    };
    let first = batch(&base.join("r1"));
    assert!(first.status.success(), "{first:?}");
    // Another file put in the binary's place (as a task of another submission could, were the
    // folder shared): the grader builds anew rather than run it.
    let bins: Vec<PathBuf> = std::fs::read_dir(work.join("bin"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with(KRATE))
        .collect();
    assert_eq!(bins.len(), 1, "{bins:?}");
    std::fs::write(&bins[0], "#!/bin/sh\necho '{\"ok\": [0]}' >&3\n").unwrap();
    let second = batch(&base.join("r2"));
    assert!(second.status.success(), "{second:?}");
    let csv = std::fs::read_to_string(base.join("r2/scores.csv")).unwrap();
    assert!(csv.contains("\na,5.00,"), "{csv}");
}

/// Build settings in the instructor's environment reach neither the build of the handout's own
/// stubs, whose artifacts every sandboxed build starts from, nor the sandboxed build itself:
/// set for one and not the other, cargo would rebuild those (read-only) artifacts in the
/// sandbox and every submission would score 0.
#[test]
fn build_settings_in_the_graders_environment_change_no_score() {
    let base = out_dir("grading_sandbox_env");
    let subs = solution_only(&base);
    let out = batch_of_ex2(&subs, &base.join("results"), &base.join("work"))
        .env("RUSTC_BOOTSTRAP", "1")
        .env("RUSTFLAGS", "-C debug-assertions=off")
        .env("CARGO_INCREMENTAL", "1")
        .output()
        .expect("run stereolab");
    assert!(out.status.success(), "{out:?}");
    let csv = std::fs::read_to_string(base.join("results/scores.csv")).unwrap();
    let report = std::fs::read_to_string(base.join("results/a/report.txt")).unwrap();
    assert!(csv.contains("\na,5.00,"), "{csv}\n{report}");
}
