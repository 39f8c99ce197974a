//! At scale: results.json as Gradescope documents it, `stereolab grade batch` over a folder of
//! submissions, and the Gradescope bundle's scripts run in a folder laid out like Gradescope's
//! `/autograder`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common::out_dir;
use crate::grading::{full_points, grade, repo_exercises, spec_totals, target_dir, tests_of};
use stereolab_grade::Exercise;

/// Gradescope's values for `visibility` (results.json and each test).
const VISIBILITY: [&str; 4] = ["hidden", "after_due_date", "after_published", "visible"];
/// Gradescope's output formats.
const FORMATS: [&str; 5] = ["text", "html", "simple_format", "md", "ansi"];
/// The longest per-test output: the grader's cap (4 000 characters), the line saying so, the hint.
const TEST_OUTPUT_LIMIT: usize = 4500;

fn fail(what: &str, v: &Value) -> ! {
    panic!("results.json: {what}: {v}")
}

fn check_string_in(v: &Value, key: &str, allowed: &[&str]) {
    if let Some(x) = v.get(key) {
        let ok = x.as_str().is_some_and(|s| allowed.contains(&s));
        if !ok {
            fail(&format!("{key} must be one of {allowed:?}"), v);
        }
    }
}

/// Gradescope's documented results.json fields (the autograder specification): only known
/// keys, their types, the allowed `visibility`, `status` and format values. Returns the sum of
/// the tests' `max_score`.
fn check_gradescope_schema(v: &Value) -> f64 {
    const TOP: [&str; 11] = [
        "score",
        "execution_time",
        "output",
        "output_format",
        "test_output_format",
        "test_name_format",
        "visibility",
        "stdout_visibility",
        "extra_data",
        "tests",
        "leaderboard",
    ];
    const TEST: [&str; 11] = [
        "score",
        "max_score",
        "status",
        "name",
        "name_format",
        "number",
        "output",
        "output_format",
        "tags",
        "visibility",
        "extra_data",
    ];
    let Some(top) = v.as_object() else {
        fail("not an object", v)
    };
    for k in top.keys() {
        if !TOP.contains(&k.as_str()) {
            fail(&format!("unknown top-level key {k}"), v);
        }
    }
    if !v["score"].is_number() {
        fail("score must be a number", v);
    }
    if v.get("execution_time").is_some_and(|t| !t.is_u64()) {
        fail("execution_time must be whole seconds", v);
    }
    if v.get("output").is_some_and(|o| !o.is_string()) {
        fail("output must be a string", v);
    }
    if v.get("extra_data").is_some_and(|e| !e.is_object()) {
        fail("extra_data must be an object", v);
    }
    check_string_in(v, "visibility", &VISIBILITY);
    check_string_in(v, "stdout_visibility", &VISIBILITY);
    check_string_in(v, "output_format", &FORMATS);
    let Some(tests) = v["tests"].as_array() else {
        fail("tests must be an array", v)
    };
    let mut max = 0.0;
    for t in tests {
        let Some(obj) = t.as_object() else {
            fail("a test is not an object", t)
        };
        for k in obj.keys() {
            if !TEST.contains(&k.as_str()) {
                fail(&format!("unknown test key {k}"), t);
            }
        }
        if !t["name"].is_string() || !t["score"].is_number() || !t["max_score"].is_number() {
            fail(
                "a test needs name (string), score and max_score (numbers)",
                t,
            );
        }
        max += t["max_score"].as_f64().unwrap_or_default();
        for k in ["number", "output"] {
            if t.get(k).is_some_and(|x| !x.is_string()) {
                fail(&format!("{k} must be a string"), t);
            }
        }
        if t.get("tags")
            .is_some_and(|x| !x.as_array().is_some_and(|a| a.iter().all(Value::is_string)))
        {
            fail("tags must be strings", t);
        }
        check_string_in(t, "status", &["passed", "failed"]);
        check_string_in(t, "visibility", &VISIBILITY);
        check_string_in(t, "output_format", &FORMATS);
        let output = t["output"].as_str().unwrap_or_default();
        if output.chars().count() > TEST_OUTPUT_LIMIT {
            fail("a test's output is longer than the cap", t);
        }
        if output.contains(".png") && output.contains("/target/") {
            fail("a test's output names a folder of the grader's machine", t);
        }
    }
    max
}

#[test]
fn results_json_follows_gradescopes_fields_with_the_bonus_as_extra_credit() {
    let (_, v) = grade(
        "all",
        &["--solution"],
        &repo_exercises(),
        None,
        "gs_solution",
    );
    let max = check_gradescope_schema(&v);
    // The points to reach; the bonus points beyond them.
    let (reach, bonus_points) = spec_totals(&Exercise::ALL);
    assert_eq!(max, reach, "{v}");
    assert_eq!(v["score"].as_f64(), Some(reach + bonus_points), "{v}");
    assert!(v["execution_time"].is_u64(), "{v}");
    let bonus: Vec<&Value> = tests_of(&v)
        .iter()
        .filter(|t| t["name"].as_str().unwrap_or_default().ends_with("(bonus)"))
        .collect();
    assert_eq!(bonus.len(), 1, "{v}");
    assert_eq!(bonus[0]["max_score"].as_f64(), Some(0.0), "{v}");
    assert_eq!(
        bonus[0]["score"].as_f64(),
        Some(full_points(bonus[0])),
        "{v}"
    );
    for t in tests_of(&v) {
        assert_eq!(t["visibility"], "visible", "{t}");
        assert_eq!(t["status"], "passed", "{t}");
    }
    assert!(
        v["output"].as_str().unwrap().contains(&format!(
            "PASSED: {:.2} of {reach:.2}",
            reach + bonus_points
        )),
        "the full report is the top-level output: {v}"
    );

    // The stubs: every test failed, with short outputs and no picture folders; the report
    // (with every failing task) is the top-level output.
    let (_, v) = grade("all", &[], &repo_exercises(), None, "gs_stubs");
    check_gradescope_schema(&v);
    assert_eq!(v["score"].as_f64(), Some(0.0), "{v}");
    for t in tests_of(&v) {
        assert_eq!(t["status"], "failed", "{t}");
    }
    let output = v["output"].as_str().unwrap();
    assert!(output.contains("NOT PASSED"), "{output}");
    assert!(output.contains("Tasks that lost points"), "{output}");
    assert_eq!(v["extra_data"]["passed"], false, "{v}");
}

#[test]
fn a_failing_image_check_names_its_picture_without_the_graders_folders() {
    let (_, v) = grade(
        "ex1",
        &["--solution"],
        &repo_exercises(),
        Some("swapped-eyes"),
        "gs_swapped",
    );
    check_gradescope_schema(&v);
    let outputs: Vec<&str> = tests_of(&v)
        .iter()
        .filter_map(|t| t["output"].as_str())
        .collect();
    let strips: Vec<&&str> = outputs
        .iter()
        .filter(|o| o.contains("expected | diff | actual: "))
        .collect();
    assert!(
        !strips.is_empty(),
        "a swapped rig fails an image check: {v}"
    );
    for o in strips {
        assert!(
            o.contains("expected | diff | actual: ex1_") && !o.contains("/images/"),
            "{o}"
        );
    }
    assert!(!v["output"].as_str().unwrap().contains("/images/"), "{v}");
}

fn stereolab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .env("CARGO_TARGET_DIR", target_dir())
        .output()
        .expect("run stereolab")
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn repo_file(krate: &str, file: &str) -> String {
    std::fs::read_to_string(repo_exercises().join(krate).join("src").join(file)).unwrap()
}

fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("JSON")
}

#[test]
fn batch_grades_every_submission_folder_and_writes_a_sorted_csv() {
    let base = out_dir("grading_batch");
    let subs = base.join("submissions");
    let k = "ex2_chromadepth";
    // Handout layout; nested one folder down; a compile error; nothing at all.
    write(
        &subs.join("zoe/ex2_chromadepth/src/stubs.rs"),
        &repo_file(k, "solution.rs"),
    );
    write(
        &subs.join("bob, jr/handout/ex2_chromadepth/src/stubs.rs"),
        &repo_file(k, "solution.rs"),
    );
    write(
        &subs.join("carl/ex2_chromadepth/src/stubs.rs"),
        "pub fn broken( {\n",
    );
    std::fs::create_dir_all(subs.join("dana")).unwrap();
    std::fs::create_dir_all(subs.join(".hidden")).unwrap();
    // A single file named by the crate (as Gradescope takes it), under a name a spreadsheet
    // would read as a formula.
    write(
        &subs.join("=1+1/ex2_chromadepth.rs"),
        &repo_file(k, "solution.rs"),
    );
    let results = base.join("results");
    let out = stereolab(&[
        "grade",
        "batch",
        subs.to_str().unwrap(),
        "--out",
        results.to_str().unwrap(),
        "--jobs",
        "2",
        "--exercises-list",
        "ex2",
        "--timeout",
        "4",
    ]);
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(results.join("scores.csv")).unwrap();
    let (reach, _) = spec_totals(&[Exercise::Ex2]);
    assert_eq!(
        csv,
        format!(
            "submission,ex2,total,max,passed\n\
             '=1+1,{reach:.2},{reach:.2},{reach:.2},true\n\
             \"bob, jr\",{reach:.2},{reach:.2},{reach:.2},true\n\
             carl,0.00,0.00,{reach:.2},false\n\
             dana,0.00,0.00,{reach:.2},false\n\
             zoe,{reach:.2},{reach:.2},{reach:.2},true\n"
        )
    );
    let here = base.display().to_string();
    for name in ["=1+1", "bob, jr", "carl", "dana", "zoe"] {
        let v = read_json(&results.join(name).join("results.json"));
        check_gradescope_schema(&v);
        assert!(v["execution_time"].is_u64(), "{name}: {v}");
        let report = std::fs::read_to_string(results.join(name).join("report.txt")).unwrap();
        assert!(!report.contains(&here), "{name}: {report}");
        assert!(!v.to_string().contains(&here), "{name}: {v}");
    }
    let carl = std::fs::read_to_string(results.join("carl/report.txt")).unwrap();
    assert!(carl.contains("does not compile"), "{carl}");
    let dana = std::fs::read_to_string(results.join("dana/report.txt")).unwrap();
    assert!(
        dana.contains("ex2_chromadepth: missing file: no `ex2_chromadepth/src/stubs.rs`")
            && dana.contains("`ex2_chromadepth.rs`")
            && dana.contains("hint [missing-file]")
            && !dana.contains("does not compile"),
        "names the missing file and where it was looked for: {dana}"
    );
    assert!(!results.join(".hidden").exists());
}

#[test]
fn batch_refuses_bad_jobs_and_an_empty_folder_with_a_message() {
    let base = out_dir("grading_batch_bad");
    let subs = base.join("submissions");
    std::fs::create_dir_all(subs.join("a")).unwrap();
    let results = base.join("results");
    for jobs in ["0", "100000"] {
        let out = stereolab(&[
            "grade",
            "batch",
            subs.to_str().unwrap(),
            "--out",
            results.to_str().unwrap(),
            "--jobs",
            jobs,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains("--jobs"),
            "{jobs}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
    let empty = base.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = stereolab(&[
        "grade",
        "batch",
        empty.to_str().unwrap(),
        "--out",
        results.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("no submission"),
        "{err}"
    );
    // `grade EXERCISE` still parses next to the subcommands.
    let out = stereolab(&["grade", "ex9"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("ex9"), "{err}");
}

/// Unpacks `zip` into `dir`; returns the names in the archive.
fn unzip(zip: &Path, dir: &Path) -> Vec<String> {
    let file = std::fs::File::open(zip).unwrap();
    let mut archive = zip::ZipArchive::new(file).unwrap();
    let names: Vec<String> = archive
        .file_names()
        .map(|n| n.expect("a UTF-8 name").into_owned())
        .collect();
    archive.extract(dir).unwrap();
    names
}

/// Runs `script` of the bundle with `/autograder` at `root`.
fn run_script(root: &Path, script: &str) -> Output {
    run_script_with(root, script, &[])
}

/// [`run_script`] with `env` added.
fn run_script_with(root: &Path, script: &str, env: &[(&str, &str)]) -> Output {
    let out = Command::new(root.join("source").join(script))
        .envs(env.iter().copied())
        .current_dir(root)
        .env("AUTOGRADER_ROOT", root)
        .env("STEREOLAB_BIN", env!("CARGO_BIN_EXE_stereolab"))
        // The tests' shared build folder: the exercise crates' dependencies are compiled there.
        .env("STEREOLAB_BUILD_DIR", target_dir().join("stereolab-grade"))
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("STEREOLAB_MUTANT")
        .output()
        .expect("run the script");
    assert!(
        out.status.success(),
        "{script}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Makes `root/submission` hold exactly `files`.
fn submit(root: &Path, files: &[(String, String)]) {
    let sub = root.join("submission");
    let _ = std::fs::remove_dir_all(&sub);
    std::fs::create_dir_all(&sub).unwrap();
    for (path, text) in files {
        write(&sub.join(path), text);
    }
}

#[test]
fn the_gradescope_bundle_runs_in_an_autograder_layout() {
    let base = out_dir("grading_bundle");
    let zip = base.join("autograder.zip");
    let classroom = base.join("classroom");
    let out = stereolab(&[
        "grade",
        "bundle",
        "--out",
        zip.to_str().unwrap(),
        "--seed",
        "7",
        "--classroom",
        classroom.to_str().unwrap(),
        "--root",
        crate::common::root().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let yml = std::fs::read_to_string(classroom.join(".github/workflows/classroom.yml")).unwrap();
    assert!(yml.contains("grade all --json results.json"), "{yml}");

    let root: PathBuf = base.join("autograder");
    let names = unzip(&zip, &root.join("source"));
    for needed in [
        "setup.sh",
        "run_autograder",
        "stereolab/Cargo.toml",
        "stereolab/crates/core/src/lib.rs",
    ] {
        assert!(names.iter().any(|n| n == needed), "{needed} in {names:?}");
    }
    assert!(
        !names.iter().any(|n| n.contains("solution")),
        "no solutions in the bundle: {names:?}"
    );
    let run = std::fs::read_to_string(root.join("source/run_autograder")).unwrap();
    assert!(run.contains("export STEREOLAB_GRADER_SEED=7"), "{run}");
    // Everything the bundled sources compile in is bundled.
    crate::grading::assert_includes_resolve(&root.join("source/stereolab"));
    // The bundled sources are a workspace of their own that cargo can read.
    let meta = Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
        .args([
            "metadata",
            "--no-deps",
            "--offline",
            "--format-version",
            "1",
        ])
        .arg("--manifest-path")
        .arg(root.join("source/stereolab/Cargo.toml"))
        .output()
        .unwrap();
    assert!(
        meta.status.success(),
        "{}",
        String::from_utf8_lossy(&meta.stderr)
    );

    std::fs::create_dir_all(root.join("results")).unwrap();
    run_script(&root, "setup.sh");

    // The solutions, uploaded as single files named by crate.
    let files: Vec<(String, String)> = ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"]
        .iter()
        .map(|k| (format!("{k}.rs"), repo_file(k, "solution.rs")))
        .collect();
    submit(&root, &files);
    run_script(&root, "run_autograder");
    let v = read_json(&root.join("results/results.json"));
    let (reach, bonus) = spec_totals(&Exercise::ALL);
    assert_eq!(check_gradescope_schema(&v), reach, "{v}");
    assert_eq!(v["score"].as_f64(), Some(reach + bonus), "{v}");
    let tasks = tests_of(&v).len();

    // The untouched stubs in the handout's layout, one folder down.
    let files: Vec<(String, String)> = ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"]
        .iter()
        .map(|k| {
            (
                format!("handout/{k}/src/stubs.rs"),
                repo_file(k, "stubs.rs"),
            )
        })
        .collect();
    submit(&root, &files);
    run_script(&root, "run_autograder");
    let v = read_json(&root.join("results/results.json"));
    check_gradescope_schema(&v);
    assert_eq!(v["score"].as_f64(), Some(0.0), "{v}");
    assert_eq!(tests_of(&v).len(), tasks, "every task a test: {v}");

    // Nothing usable: a zero that says what to submit.
    submit(&root, &[("notes.txt".into(), "hello".into())]);
    run_script(&root, "run_autograder");
    let v = read_json(&root.join("results/results.json"));
    check_gradescope_schema(&v);
    assert_eq!(v["score"].as_f64(), Some(0.0), "{v}");
    assert!(
        v["output"].as_str().unwrap().contains("ex1_stereo.rs"),
        "{v}"
    );
    // Attacks on the official path, as Gradescope runs it (as root here: sandboxed).
    let secret = base.join("secret.txt");
    write(&secret, &format!("{}\n", crate::grading_sandbox::SECRET));
    let t = crate::grading_sandbox::Targets {
        results: root.join("results"),
        results_json: root.join("results/results.json"),
        scores: root.join("results/scores.csv"),
        work: root.join("work/build"),
        secret: secret.clone(),
    };
    let krate = crate::grading_sandbox::KRATE;
    let said = crate::grading_sandbox::said;
    // A hopper that outlives its task to rewrite results.json.
    let hopper = crate::grading_sandbox::spliced("hopper", &t);
    submit(&root, &[(format!("{krate}.rs"), hopper)]);
    run_script(&root, "run_autograder");
    let written = std::fs::read_to_string(root.join("results/results.json")).unwrap();
    std::thread::sleep(std::time::Duration::from_secs(3));
    assert_eq!(
        std::fs::read_to_string(root.join("results/results.json")).unwrap(),
        written,
        "results.json changed after the grader finished"
    );
    let v = read_json(&root.join("results/results.json"));
    assert!(said(&v).contains("hopper started"), "{v}");
    assert_eq!(v["score"].as_f64(), Some(5.0), "{v}");
    // A /proc reader looking for the seed.
    submit(
        &root,
        &[(
            format!("{krate}.rs"),
            crate::grading_sandbox::spliced("proc_reader", &t),
        )],
    );
    run_script(&root, "run_autograder");
    let v = read_json(&root.join("results/results.json"));
    let text = said(&v);
    assert!(
        text.contains("proc reader ran") && text.contains("found []"),
        "{text}"
    );
    assert!(!text.contains("STEREOLAB_GRADER_SEED="), "{text}");
    // The other attacks: correct formulas beside them keep their points, nothing more.
    for (attack, points) in [
        ("input_printer", 5.0),
        ("classmate", 4.0),
        ("system_caller", 5.0),
        ("signaller", 5.0),
        ("include_outside", 0.0),
        ("const_loop", 0.0),
    ] {
        submit(
            &root,
            &[(
                format!("{krate}.rs"),
                crate::grading_sandbox::spliced(attack, &t),
            )],
        );
        run_script_with(
            &root,
            "run_autograder",
            &[("STEREOLAB_BUILD_TIMEOUT", "15")],
        );
        let v = read_json(&root.join("results/results.json"));
        let text = said(&v);
        assert_eq!(v["score"].as_f64(), Some(points), "{attack}: {text}");
        assert!(
            !text.contains(crate::grading_sandbox::SECRET)
                && !text.contains("STEREOLAB_GRADER_SEED=")
                && !text.contains("network-open"),
            "{attack}: {text}"
        );
    }
    assert!(!root.join("results/pwned").exists());

    // A stubs file that is a link to a secret of the machine.
    let sub = root.join("submission");
    let _ = std::fs::remove_dir_all(&sub);
    std::fs::create_dir_all(sub.join(format!("{krate}/src"))).unwrap();
    std::os::unix::fs::symlink(&secret, sub.join(format!("{krate}/src/stubs.rs"))).unwrap();
    run_script(&root, "run_autograder");
    let v = read_json(&root.join("results/results.json"));
    let text = said(&v);
    assert!(text.contains("symbolic link"), "{text}");
    assert!(!text.contains(crate::grading_sandbox::SECRET), "{text}");
}
