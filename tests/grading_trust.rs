//! What an instructor must be able to trust: the grader grades each submission's own code (one
//! shared build folder, files older than earlier builds), a student's printing is never read
//! as an answer, stereolab's library is out of a submission's reach, and a process a task leaves
//! behind cannot change the score.

use std::path::PathBuf;
use std::process::Stdio;
use std::time::{Duration, SystemTime};

use crate::common::out_dir;
use crate::grading::{
    assert_verdict_exit, grade, grade_command, repo_exercises, results, spec_totals, test_named,
    tests_of,
};
use stereolab_grade::Exercise;

/// A submission folder holding `stubs` as `<crate>/src/stubs.rs` for each `(crate, stubs)`,
/// every file dated a year back (older than any build: the case that made cargo reuse a stale
/// binary).
fn submission(name: &str, files: &[(&str, String)]) -> PathBuf {
    let dir = out_dir(&format!("submission_{name}"));
    for (krate, text) in files {
        let path = dir.join(krate).join("src/stubs.rs");
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
        let old = SystemTime::now() - Duration::from_secs(365 * 24 * 3600);
        std::fs::File::options()
            .write(true)
            .open(&path)
            .and_then(|f| f.set_modified(old))
            .unwrap();
    }
    dir
}

fn solution(krate: &str) -> String {
    std::fs::read_to_string(repo_exercises().join(krate).join("src/solution.rs")).unwrap()
}

fn stubs(krate: &str) -> String {
    std::fs::read_to_string(repo_exercises().join(krate).join("src/stubs.rs")).unwrap()
}

fn score(v: &serde_json::Value) -> f64 {
    v["score"].as_f64().expect("score")
}

#[test]
fn one_shared_build_folder_grades_each_submission_by_its_own_code() {
    let swapped = solution("ex1_stereo").replace("planted(\"swapped-eyes\")", "true");
    assert_ne!(swapped, solution("ex1_stereo"));
    let runs = [
        ("solution", solution("ex1_stereo")),
        ("swapped", swapped),
        ("stubs", stubs("ex1_stereo")),
    ];
    let mut scores = Vec::new();
    for (name, text) in runs {
        let dir = submission(&format!("shared_{name}"), &[("ex1_stereo", text)]);
        let (_, v) = grade("ex1", &[], &dir, None, &format!("shared_{name}"));
        scores.push(score(&v));
    }
    // Full marks (and the bonus), partial (the swapped eyes cost their tasks), zero.
    let (reach, bonus) = spec_totals(&[Exercise::Ex1]);
    assert_eq!(scores[0], reach + bonus, "{scores:?}");
    assert!(scores[1] > 2.0 && scores[1] < reach, "{scores:?}");
    assert_eq!(scores[2], 0.0, "{scores:?}");
}

/// Two graders at once on one build folder (the default one, which every grading test shares)
/// and a submission no other test builds: both compile it, and both grade it to full marks. One
/// at a time compiles the shared dependencies and places a binary (the folder's lock file), and
/// the binary one grader placed, and may be running, is not replaced by the other's build.
#[test]
fn two_graders_sharing_a_build_folder_grade_the_same_new_submission() {
    let marked = format!(
        "{}\n// graded by two graders at once\n",
        solution("ex2_chromadepth")
    );
    let dir = submission("twice", &[("ex2_chromadepth", marked)]);
    let graders: Vec<_> = ["twice_a", "twice_b"]
        .into_iter()
        .map(|name| {
            let (mut cmd, json) = grade_command("ex2", &[], &dir, name);
            let child = cmd
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("start stereolab grade");
            (child, json)
        })
        .collect();
    let (reach, bonus) = spec_totals(&[Exercise::Ex2]);
    for (child, json) in graders {
        let out = child.wait_with_output().expect("wait for stereolab grade");
        assert_verdict_exit(&out, "a grader beside another");
        assert_eq!(
            score(&results(&json)),
            reach + bonus,
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
}

/// The solution with `noise();` as the first statement of every public function, and `noise`
/// printing 1 MB to stdout and to stderr once per process (each task is one process).
fn noisy(text: &str) -> String {
    let mut out = String::new();
    let mut pending = false;
    for line in text.lines() {
        out.push_str(line);
        out.push('\n');
        if line.starts_with("pub fn ") {
            pending = true;
        }
        if pending && line.ends_with('{') {
            out.push_str("    noise();\n");
            pending = false;
        }
    }
    out.push_str(
        r#"
fn noise() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let line = "debug output that is not an answer ".repeat(30);
        for _ in 0..1000 {
            println!("{line}");
            eprintln!("{line}");
        }
    });
}
"#,
    );
    out
}

#[test]
fn a_solution_that_prints_a_megabyte_in_every_task_still_scores_full_marks() {
    let files: Vec<(&str, String)> = ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"]
        .into_iter()
        .map(|k| (k, noisy(&solution(k))))
        .collect();
    let dir = submission("noisy", &files);
    let (_, v) = grade("all", &[], &dir, None, "noisy");
    for t in tests_of(&v) {
        assert_eq!(t["status"], "passed", "{}: {}", t["name"], t["output"]);
    }
    let (reach, bonus) = spec_totals(&Exercise::ALL);
    assert_eq!(score(&v), reach + bonus, "{v}");
    let out = test_named(&v, "ex2 texgen")["output"].as_str().unwrap();
    assert!(out.contains("debug output that is not an answer"), "{out}");
}

#[test]
fn a_submission_that_calls_stereolab_does_not_compile() {
    let cheat = format!(
        "{}\npub fn cheat() -> glam::Mat4 {{ stereolab_core::frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 10.0) }}\n",
        solution("ex2_chromadepth")
    );
    let dir = submission("cheat", &[("ex2_chromadepth", cheat)]);
    let (out, v) = grade("ex2", &[], &dir, None, "cheat");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("ex2_chromadepth: does not compile"),
        "{stdout}"
    );
    assert!(stdout.contains("stereolab"), "{stdout}");
    assert_eq!(score(&v), 0.0, "{v}");
}

#[test]
fn a_process_left_behind_by_a_task_cannot_change_the_results() {
    let dir = out_dir("grading_forged");
    let results = dir.join("results.json");
    // Two ways to outlive the task: a plain child in its process group, and one in a new
    // session of its own (`setsid`), both rewriting results.json a second later.
    // Each says it started on the task's stderr and leaves a marker in the task's folder
    // first, to prove it ran (a forger that never started proves nothing), and the task waits
    // (at most 5 s) for that marker before it returns, so that on a busy machine the grader's
    // end of task cannot come before the forger has started.
    let forge = |how: &str| {
        let label = if how.is_empty() { "plain" } else { how };
        format!(
            "std::process::Command::new(\"sh\").args([\"-c\", \"{how} sh -c 'echo started-{label} >&2; touch started-{label}; sleep 1; echo forged > {}'\"]).spawn().ok(); \
             for _ in 0..500 {{ if std::path::Path::new(\"started-{label}\").exists() {{ break; }} std::thread::sleep(std::time::Duration::from_millis(10)); }}",
            results.display()
        )
    };
    let text = solution("ex2_chromadepth").replace(
        "pub fn texgen(d1: f32, d2: f32) -> [f32; 4] {",
        &format!(
            "pub fn texgen(d1: f32, d2: f32) -> [f32; 4] {{\n    {}\n    {}",
            forge(""),
            forge("setsid")
        ),
    );
    let sub = submission("forged", &[("ex2_chromadepth", text)]);
    let (_, v) = grade("ex2", &[], &sub, None, "forged");
    assert_eq!(score(&v), 5.0, "{v}");
    let written = std::fs::read_to_string(&results).unwrap();
    std::thread::sleep(Duration::from_millis(2500));
    let texgen = test_named(&v, "ex2 texgen")["output"]
        .as_str()
        .unwrap()
        .to_string();
    for how in ["plain", "setsid"] {
        assert!(
            texgen.contains(&format!("started-{how}")),
            "the {how} forger never ran: the test would prove nothing\n{texgen}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(&results).unwrap(),
        written,
        "results.json changed after the grader finished"
    );
}

#[test]
fn crashes_aborts_exits_and_memory_hogs_get_their_own_hint() {
    let base = solution("ex3_sirds");
    let cases: [(&str, &str, &str); 5] = [
        ("abort", "std::process::abort();", "[abort]"),
        ("exit", "std::process::exit(0);", "[exit]"),
        (
            "oom",
            "let mut v: Vec<Vec<u8>> = Vec::new(); loop { v.push(vec![1u8; 1 << 24]); }",
            "[out-of-memory]",
        ),
        (
            "stack",
            "fn deep(n: u64) -> u64 { let a = [n; 64]; if a[63] == u64::MAX { 0 } else { deep(n + 1) + a[1] } } std::hint::black_box(deep(0));",
            "[stack-overflow]",
        ),
        (
            "segv",
            "unsafe { std::ptr::null_mut::<u32>().write_volatile(1) };",
            "[crash]",
        ),
    ];
    for (name, code, hint) in cases {
        let text = base.replacen(
            "pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {",
            &format!("pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {{\n    {code}"),
            1,
        );
        assert_ne!(text, base);
        let sub = submission(&format!("ending_{name}"), &[("ex3_sirds", text)]);
        let (_, v) = grade(
            "ex3",
            &["--memory-mb", "256"],
            &sub,
            None,
            &format!("ending_{name}"),
        );
        let t = test_named(&v, "ex3 disparity_constant_direction");
        let out = t["output"].as_str().unwrap();
        assert_eq!(t["score"].as_f64(), Some(0.0), "{name}: {out}");
        assert!(out.contains(hint), "{name}: {out}");
        // The other tasks of the exercise are not affected.
        assert_eq!(
            test_named(&v, "ex3 link_row")["score"].as_f64(),
            Some(3.0),
            "{name}"
        );
    }
}

/// The build folder students get by default is relative (`target/stereolab-grade`), while each
/// task runs in a scratch folder of its own: the grader must still find the binaries.
#[test]
fn a_relative_build_folder_grades_like_an_absolute_one() {
    let json = out_dir("grading_relative").join("results.json");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .current_dir(crate::grading::target_dir())
        .env("CARGO_TARGET_DIR", ".")
        .env_remove("STEREOLAB_MUTANT")
        .args(["grade", "ex2", "--solution", "--exercises"])
        .arg(repo_exercises())
        .arg("--json")
        .arg(&json)
        .output()
        .expect("run stereolab grade");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(score(&v), 5.0, "{}", String::from_utf8_lossy(&out.stdout));
}
