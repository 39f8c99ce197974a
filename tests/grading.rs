//! The grader end to end: the instructor's solution scores full marks, the untouched stubs score
//! zero without crashing the grader, planted mistakes lose points on the right task with the
//! right hint, and the exported handout builds and grades.
//!
//! Every test here runs `stereolab grade`, which builds the exercise crates with cargo in this
//! workspace's target folder (dependencies are shared, only the small exercise crates compile).
//! The tests run side by side: each writes its own output folder, and the grader's build folder,
//! which they share, takes one build at a time under its own lock, across processes too.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common::{out_dir, root};
use stereolab_grade::Exercise;
use stereolab_grade::points;

/// Per-task time limit: ample for every task (they answer in milliseconds), short enough that
/// the endless-loop mutant costs little.
const TIMEOUT: &str = "4";

/// Runs `stereolab grade WHAT --json …` on `exercises`, with `STEREOLAB_MUTANT` when given.
pub(crate) fn grade(
    what: &str,
    extra: &[&str],
    exercises: &Path,
    mutant: Option<&str>,
    name: &str,
) -> (Output, Value) {
    grade_seeded(what, extra, exercises, mutant, None, name)
}

/// A grading run ended cleanly, with the exit code its verdict gives: 0 for PASSED,
/// [`EXIT_NOT_PASSED`](stereolab_grade::EXIT_NOT_PASSED) for NOT PASSED.
pub(crate) fn assert_verdict_exit(out: &Output, what: &str) {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let not_passed = stdout.contains("NOT PASSED:");
    assert!(
        not_passed || stdout.contains("PASSED:"),
        "{what}: no verdict; stdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let expected = if not_passed {
        i32::from(stereolab_grade::EXIT_NOT_PASSED)
    } else {
        0
    };
    assert_eq!(
        out.status.code(),
        Some(expected),
        "{what}: the exit code must follow the verdict; stdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// [`grade`] with the instructor's seed for hidden cases (`STEREOLAB_GRADER_SEED`) when given.
pub(crate) fn grade_seeded(
    what: &str,
    extra: &[&str],
    exercises: &Path,
    mutant: Option<&str>,
    seed: Option<&str>,
    name: &str,
) -> (Output, Value) {
    let (mut cmd, json) = grade_command(what, extra, exercises, name);
    if let Some(m) = mutant {
        cmd.env("STEREOLAB_MUTANT", m);
    }
    if let Some(s) = seed {
        cmd.env("STEREOLAB_GRADER_SEED", s);
    }
    let out = cmd.output().expect("run stereolab grade");
    assert_verdict_exit(&out, &format!("grade {what} {extra:?} (mutant {mutant:?})"));
    let v = results(&json);
    (out, v)
}

/// `stereolab grade WHAT --json …` on `exercises` (no mutant, no seed), not yet run, with the
/// path its results.json will have: output under `grading_{name}`.
pub(crate) fn grade_command(
    what: &str,
    extra: &[&str],
    exercises: &Path,
    name: &str,
) -> (Command, PathBuf) {
    let dir = out_dir(&format!("grading_{name}"));
    let json = dir.join("results.json");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stereolab"));
    cmd.args(["grade", what, "--timeout", TIMEOUT, "--json"])
        .arg(&json)
        .arg("--out")
        .arg(dir.join("images"))
        .arg("--exercises")
        .arg(exercises)
        .args(extra)
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("STEREOLAB_MUTANT")
        .env_remove("STEREOLAB_GRADER_SEED");
    (cmd, json)
}

/// The results.json a grading run wrote.
pub(crate) fn results(json: &Path) -> Value {
    let text = std::fs::read_to_string(json).expect("results.json written");
    serde_json::from_str(&text).expect("results.json is JSON")
}

/// The target folder this test binary was built in (`<target>/debug/stereolab`): nested builds
/// use it too, so the compiled dependencies are shared whatever `CARGO_TARGET_DIR` CI sets.
pub(crate) fn target_dir() -> PathBuf {
    let exe = Path::new(env!("CARGO_BIN_EXE_stereolab"));
    exe.parent()
        .and_then(Path::parent)
        .expect("the binary lies in <target>/<profile>/")
        .to_path_buf()
}

pub(crate) fn repo_exercises() -> PathBuf {
    root().join("exercises")
}

pub(crate) fn tests_of(v: &Value) -> &Vec<Value> {
    v["tests"].as_array().expect("tests array")
}

pub(crate) fn test_named<'a>(v: &'a Value, name: &str) -> &'a Value {
    tests_of(v)
        .iter()
        .find(|t| {
            t["name"]
                .as_str()
                .is_some_and(|n| n.trim_end_matches(" (bonus)") == name)
        })
        .unwrap_or_else(|| panic!("no test {name} in {v}"))
}

/// The points to reach and the bonus points of `exercises`, from the task specs.
pub(crate) fn spec_totals(exercises: &[Exercise]) -> (f64, f64) {
    points::totals(&points::points_table().expect("the specs"), exercises)
}

/// A test's points for a complete answer: its `max_score`, or for a bonus task (extra credit,
/// `max_score` 0) the bonus points its spec gives.
pub(crate) fn full_points(t: &Value) -> f64 {
    let max = t["max_score"].as_f64().expect("max_score");
    if t["tags"]
        .as_array()
        .is_some_and(|tags| tags.iter().any(|x| x == "bonus"))
    {
        assert_eq!(max, 0.0, "a bonus test is extra credit: {t}");
        let name = t["name"].as_str().unwrap_or_default();
        points::points_table()
            .expect("the specs")
            .iter()
            .find(|p| name == format!("{} {} (bonus)", p.exercise.id(), p.name))
            .unwrap_or_else(|| panic!("no bonus task {name} in the specs"))
            .points
    } else {
        max
    }
}

#[test]
fn solution_scores_full_marks_on_every_task() {
    let (out, v) = grade("all", &["--solution"], &repo_exercises(), None, "solution");
    for t in tests_of(&v) {
        assert_eq!(t["status"], "passed", "{}: {}", t["name"], t["output"]);
    }
    // Every point to reach and every bonus point.
    let (reach, bonus) = spec_totals(&Exercise::ALL);
    assert_eq!(v["score"].as_f64(), Some(reach + bonus), "{v}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!(
            "\nPASSED: {:.2} of {reach:.2} points",
            reach + bonus
        )),
        "{stdout}"
    );
}

#[test]
fn untouched_stubs_score_zero_and_the_grader_exits_cleanly_with_the_table() {
    let (out, v) = grade("all", &[], &repo_exercises(), None, "stubs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    for t in tests_of(&v) {
        assert_eq!(
            t["score"].as_f64(),
            Some(0.0),
            "{}: {}",
            t["name"],
            t["output"]
        );
        let output = t["output"].as_str().unwrap_or_default();
        assert!(output.contains("hint [todo]"), "{}: {output}", t["name"]);
    }
    assert_eq!(v["score"].as_f64(), Some(0.0));
    assert!(
        stdout.contains("ex1  frustum"),
        "the points table:\n{stdout}"
    );
    let (reach, _) = spec_totals(&Exercise::ALL);
    assert!(
        stdout.contains(&format!("NOT PASSED: 0.00 of {reach:.2} points")),
        "{stdout}"
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
}

/// One planted mistake and the tasks it must cost, each with the hint it must get.
struct Planted {
    mutant: &'static str,
    loses: &'static [(&'static str, &'static str)],
}

/// Plants the mistakes together (they touch disjoint tasks), grades once, and checks that each
/// lost points on exactly its tasks with its hint while every other task kept full marks.
fn check_planted(what: &str, planted: &[Planted], name: &str) {
    let mutants: Vec<&str> = planted.iter().map(|p| p.mutant).collect();
    let (_, v) = grade(
        what,
        &["--solution"],
        &repo_exercises(),
        Some(&mutants.join(",")),
        name,
    );
    for p in planted {
        for (task, hint) in p.loses {
            let t = test_named(&v, task);
            let output = t["output"].as_str().unwrap_or_default();
            assert!(
                t["status"] == "failed" && t["score"].as_f64() < Some(full_points(t)),
                "{}: {task} should lose points: {output}",
                p.mutant
            );
            assert!(
                output.contains(&format!("hint [{hint}]")),
                "{}: {task} should get hint [{hint}]:\n{output}",
                p.mutant
            );
            // A recognised mistake is named and keeps the partial credit of the checks that
            // pass (the details say so); crashes, NaN and the dependency hint are no such
            // diagnosis.
            if !["nan", "timeout", "depends-on"].contains(hint) {
                assert!(
                    output.contains(&format!("known mistake [{hint}]"))
                        && output.contains("scores the checks that pass"),
                    "{}: {task} names its mistake and scores its checks: {output}",
                    p.mutant
                );
            }
        }
    }
    let targeted: Vec<&str> = planted
        .iter()
        .flat_map(|p| p.loses.iter().map(|l| l.0))
        .collect();
    for t in tests_of(&v) {
        let name = t["name"]
            .as_str()
            .unwrap_or_default()
            .trim_end_matches(" (bonus)");
        if !targeted.contains(&name) {
            assert_eq!(
                t["status"], "passed",
                "{name} was not targeted: {}",
                t["output"]
            );
        }
    }
}

#[test]
fn swapped_eyes_transposed_anaglyph_opengl_depth_nan_reversed_ramp_full_disparity_lose_points_with_their_hints()
 {
    check_planted(
        "all",
        &[
            Planted {
                mutant: "swapped-eyes",
                loses: &[
                    ("ex1 stereo_frustum", "swapped-eyes"),
                    ("ex1 stereo_matrices", "depends-on"),
                ],
            },
            Planted {
                mutant: "transposed-anaglyph",
                loses: &[("ex1 anaglyph_matrices", "transposed")],
            },
            Planted {
                mutant: "opengl-depth",
                loses: &[
                    ("ex1 remap", "opengl-depth"),
                    ("ex1 remap_right_to_left", "depends-on"),
                    ("ex1 rds_right", "depends-on"),
                ],
            },
            Planted {
                mutant: "nan-parallax",
                loses: &[("ex1 parallax", "nan")],
            },
            Planted {
                mutant: "reversed-ramp",
                loses: &[("ex2 hsv_ramp", "ramp-reversed")],
            },
            Planted {
                mutant: "full-disparity",
                loses: &[("ex3 link_row", "d-instead-of-half-d")],
            },
        ],
        "mutants_a",
    );
}

#[test]
fn toe_in_endless_loop_texgen_sign_and_missing_hidden_surfaces_lose_points_with_their_hints() {
    check_planted(
        "all",
        &[
            Planted {
                mutant: "toe-in",
                loses: &[
                    ("ex1 stereo_frustum", "toe-in"),
                    ("ex1 stereo_matrices", "depends-on"),
                ],
            },
            Planted {
                mutant: "hang-parallax",
                loses: &[("ex1 parallax", "timeout")],
            },
            Planted {
                mutant: "texgen-sign",
                loses: &[("ex2 texgen", "texgen-sign")],
            },
            Planted {
                mutant: "no-hidden-surfaces",
                loses: &[("ex3 link_row", "no-hidden-surfaces")],
            },
        ],
        "mutants_b",
    );
}

#[test]
fn d_instead_of_half_d_in_the_rig_loses_points_with_its_hint() {
    check_planted(
        "ex1",
        &[Planted {
            mutant: "full-separation",
            loses: &[
                ("ex1 stereo_frustum", "d-instead-of-half-d"),
                ("ex1 stereo_matrices", "depends-on"),
            ],
        }],
        "mutants_c",
    );
}

#[test]
fn mv_t_order_one_sided_depth_hue_to_360_and_degrees_lose_points_with_their_hints() {
    check_planted(
        "all",
        &[
            Planted {
                mutant: "mv-t-order",
                loses: &[("ex1 stereo_matrices", "mv-t-order")],
            },
            Planted {
                mutant: "one-sided-depth",
                loses: &[
                    ("ex1 remap", "one-sided-depth"),
                    ("ex1 remap_right_to_left", "depends-on"),
                    ("ex1 rds_right", "depends-on"),
                ],
            },
            Planted {
                mutant: "full-circle-ramp",
                loses: &[("ex2 hsv_ramp", "ramp-full-circle")],
            },
            Planted {
                mutant: "degrees-phi",
                loses: &[("ex3 disparity_constant_direction", "degrees")],
            },
        ],
        "mutants_d",
    );
}

#[test]
fn fov_in_degrees_and_never_none_lose_points_and_the_caller_names_the_callee() {
    check_planted(
        "ex1",
        &[
            Planted {
                mutant: "fov-degrees",
                loses: &[
                    ("ex1 stereo_frustum", "degrees-not-radians"),
                    ("ex1 stereo_matrices", "depends-on"),
                ],
            },
            Planted {
                mutant: "never-none",
                loses: &[
                    ("ex1 remap", "never-none"),
                    ("ex1 remap_right_to_left", "depends-on"),
                ],
            },
        ],
        "mutants_e",
    );
}

#[test]
fn transposed_frustum_fails_stereo_matrices_through_its_dependency_and_no_w_divide_costs_remap() {
    check_planted(
        "ex1",
        &[
            Planted {
                mutant: "transposed-frustum",
                loses: &[
                    ("ex1 frustum", "transposed"),
                    ("ex1 stereo_matrices", "depends-on"),
                ],
            },
            Planted {
                mutant: "no-w-divide",
                loses: &[
                    ("ex1 remap", "no-w-divide"),
                    ("ex1 remap_right_to_left", "depends-on"),
                    // Its toe-in pair has clip.w ≠ 1 (the off-axis pairs have w = 1).
                    ("ex1 rds_right", "depends-on"),
                ],
            },
        ],
        "mutants_f",
    );
    let (_, v) = grade(
        "ex1",
        &["--solution"],
        &repo_exercises(),
        Some("transposed-frustum"),
        "mutants_f_text",
    );
    let output = test_named(&v, "ex1 stereo_matrices")["output"]
        .as_str()
        .unwrap_or_default();
    assert!(
        output.contains("fails because `frustum`, which it calls, fails: fix `frustum` first"),
        "{output}"
    );
}

#[test]
fn the_sheets_frustum_remapping_back_and_the_finalize_pixel_lose_points_with_their_hints() {
    check_planted(
        "ex1",
        &[
            Planted {
                mutant: "sheet-unscaled-shift",
                loses: &[("ex1 sheet_frustum", "missing-near-scale")],
            },
            Planted {
                mutant: "remap-back-same-order",
                loses: &[
                    ("ex1 remap_right_to_left", "matrix-order"),
                    ("ex1 rds_right", "depends-on"),
                ],
            },
            Planted {
                mutant: "finalize-transposed",
                loses: &[("ex1 finalize_pixel", "transposed")],
            },
        ],
        "mutants_g",
    );
    check_planted(
        "ex1",
        &[
            Planted {
                mutant: "sheet-d-not-dw",
                loses: &[("ex1 sheet_frustum", "d-not-d-times-w")],
            },
            Planted {
                mutant: "finalize-no-clamp",
                loses: &[("ex1 finalize_pixel", "no-clamp")],
            },
        ],
        "mutants_h",
    );
    check_planted(
        "ex1",
        &[Planted {
            mutant: "finalize-swapped-eyes",
            loses: &[("ex1 finalize_pixel", "swapped-eyes")],
        }],
        "mutants_i",
    );
}

#[test]
fn the_random_dot_pair_s_mistakes_lose_its_points_with_their_hints() {
    check_planted(
        "ex1",
        &[Planted {
            mutant: "rds-no-visibility",
            loses: &[("ex1 rds_right", "rds-no-visibility")],
        }],
        "mutants_rds_a",
    );
    check_planted(
        "ex1",
        &[Planted {
            mutant: "rds-v-not-flipped",
            loses: &[("ex1 rds_right", "rds-v-not-flipped")],
        }],
        "mutants_rds_b",
    );
    check_planted(
        "ex1",
        &[Planted {
            mutant: "rds-pixel-corner",
            loses: &[("ex1 rds_right", "rds-pixel-corner")],
        }],
        "mutants_rds_c",
    );
    check_planted(
        "ex1",
        &[Planted {
            mutant: "rds-left-fallback",
            loses: &[("ex1 rds_right", "rds-left-fallback")],
        }],
        "mutants_rds_d",
    );
}

/// `P of T hidden cases passed` of a task's hidden-cases test (published only after grades
/// are: `after_published`).
fn hidden_counts(t: &Value) -> Option<(usize, usize)> {
    if !t["name"].as_str()?.ends_with(" (hidden cases)") {
        return None;
    }
    assert_eq!(t["visibility"], "after_published", "{t}");
    let out = t["output"].as_str()?;
    let mut words = out.split_whitespace();
    let p = words.next()?.parse().ok()?;
    let _of = words.next()?;
    let n = words.next()?.parse().ok()?;
    Some((p, n))
}

#[test]
fn hidden_cases_come_from_the_seed_the_solution_passes_them_and_a_mutant_fails_them() {
    let (_, v) = grade_seeded(
        "all",
        &["--solution"],
        &repo_exercises(),
        None,
        Some("20260412"),
        "hidden_solution",
    );
    let mut with_hidden = Vec::new();
    for t in tests_of(&v) {
        assert_eq!(t["status"], "passed", "{}: {}", t["name"], t["output"]);
        if let Some((p, n)) = hidden_counts(t) {
            assert!(n > 0 && p == n, "{}: {}", t["name"], t["output"]);
            with_hidden.push(t["name"].as_str().unwrap_or_default().to_string());
        }
    }
    // Every task has hidden cases except the two whose whole input space is public: the four
    // anaglyph kinds and Dubois' single set of matrices.
    let without: Vec<&str> = tests_of(&v)
        .iter()
        .filter_map(|t| t["name"].as_str())
        .filter(|n| !n.ends_with(" (hidden cases)"))
        .map(|n| n.trim_end_matches(" (bonus)"))
        .filter(|n| !with_hidden.contains(&format!("{n} (hidden cases)")))
        .collect();
    assert_eq!(
        without,
        ["ex1 anaglyph_matrices", "ex1 dubois_matrices"],
        "tasks without hidden cases: {with_hidden:?}"
    );
    let (_, v) = grade_seeded(
        "ex1",
        &["--solution"],
        &repo_exercises(),
        Some("mv-t-order"),
        Some("20260412"),
        "hidden_mutant",
    );
    let t = test_named(&v, "ex1 stereo_matrices (hidden cases)");
    let (p, n) = hidden_counts(t).expect("stereo_matrices has hidden cases");
    assert!(
        p < n,
        "MV·T must fail hidden cases (random cameras): {}",
        t["output"]
    );
    // Without the seed there are none: what students run locally.
    let (_, v) = grade(
        "ex3",
        &["--solution"],
        &repo_exercises(),
        None,
        "hidden_none",
    );
    assert!(
        tests_of(&v).iter().all(|t| hidden_counts(t).is_none()),
        "{v}"
    );
}

/// Every file a shipped copy of stereolab's sources (`lib`: the handout's or the bundle's
/// `stereolab/`: the command's `src/` and the library crates) compiles in with `include_str!`
/// / `include_bytes!` exists in that copy: a copy missing one does not build, and building it
/// here would take minutes.
pub(crate) fn assert_includes_resolve(lib: &Path) {
    let mut checked = 0;
    let sources = files_under(&lib.join("src"))
        .into_iter()
        .chain(files_under(&lib.join("crates")));
    for file in sources {
        if file.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for macro_name in ["include_str!(\"", "include_bytes!(\""] {
            for rest in text.split(macro_name).skip(1) {
                let rel = rest.split('"').next().unwrap();
                let target = file.parent().unwrap().join(rel);
                assert!(
                    target.is_file(),
                    "{} includes {rel}, missing from the shipped copy",
                    file.display()
                );
                checked += 1;
            }
        }
    }
    assert!(
        checked > 5,
        "only {checked} includes found under {}",
        lib.display()
    );
}

pub(crate) fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).expect("read folder").flatten() {
        let p = e.path();
        if p.is_dir() {
            v.extend(files_under(&p));
        } else {
            v.push(p);
        }
    }
    v
}

#[test]
fn exported_handout_has_no_solutions_builds_and_grades() {
    let handout = out_dir("handout");
    let documents = out_dir("handout_documents");
    std::fs::write(documents.join("course-copy.txt"), "the course's copy\n").unwrap();
    export_handout(&handout, Some(&documents));
    let files = files_under(&handout);
    assert!(
        !files.iter().any(|f| f.ends_with("solution.rs")),
        "{files:?}"
    );
    for ex in ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"] {
        for f in ["src/stubs.rs", "src/main.rs", "tests/worked_examples.rs"] {
            assert!(handout.join(ex).join(f).is_file(), "{ex}/{f} missing");
        }
        for f in ["Cargo.toml", "src/lib.rs"] {
            let text = std::fs::read_to_string(handout.join(ex).join(f)).unwrap();
            assert!(
                !text.contains("solution"),
                "{ex}/{f} mentions the solution:\n{text}"
            );
        }
    }
    // The grader's data: every exercise's public cases and the reference pictures.
    for ex in ["ex1", "ex2", "ex3"] {
        assert!(handout.join(format!("stereolab/data/{ex}.json")).is_file());
    }
    assert!(
        handout
            .join("stereolab/data/pictures/ex2/chromadepth_texgen.png")
            .is_file()
    );
    assert_includes_resolve(&handout.join("stereolab"));
    // The handout compiles the grader unoptimized, dependencies and proc macros included (the
    // repository's profile optimizes every dependency: 632 CPU-s against 109 for the grader).
    let workspace = std::fs::read_to_string(handout.join("Cargo.toml")).unwrap();
    assert!(
        workspace.contains("[profile.dev.package.\"*\"]\nopt-level = 0\ndebug = false"),
        "{workspace}"
    );
    // What a student's crate can reach: exercise-api, glam and serde, never stereolab.
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    for ex in ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"] {
        let tree = Command::new(&cargo)
            .current_dir(&handout)
            .args(["tree", "--offline", "-e", "normal", "-p", ex])
            .output()
            .expect("run cargo tree");
        let text = String::from_utf8_lossy(&tree.stdout);
        assert!(
            tree.status.success(),
            "{}",
            String::from_utf8_lossy(&tree.stderr)
        );
        assert!(text.contains("exercise-api"), "{text}");
        assert!(
            !text.contains(" stereolab"),
            "{ex} reaches a stereolab crate:\n{text}"
        );
    }
    // The grader a student compiles is the command line only: no window, GPU path, C allocator
    // or zip code in its dependency tree (they made a first `grade` take minutes).
    let tree = Command::new(&cargo)
        .current_dir(&handout)
        .args(["tree", "--offline", "-e", "normal,build", "-p", "stereolab"])
        .output()
        .expect("run cargo tree");
    let text = String::from_utf8_lossy(&tree.stdout);
    assert!(
        tree.status.success() && text.contains("clap v"),
        "{text}{}",
        String::from_utf8_lossy(&tree.stderr)
    );
    for heavy in [
        "eframe v",
        "wgpu v",
        "mimalloc v",
        "zip v",
        "cc v",
        "stereolab-core v",
        "stereolab-pipeline v",
        "stereolab-grade v",
        "image v",
        "tiny-skia v",
    ] {
        assert!(
            !text.contains(heavy),
            "the handout's grader builds {heavy}:\n{text}"
        );
    }
    // Everything the stubs and the handout's README cite is in the handout.
    for f in [
        "slides/01-perception.md",
        "slides/06-sirds.md",
        "slides/figures/parallax_vs_depth.png",
        "slides/README.md",
        "stereolab/docs/sources.md",
        "stereolab/docs/anaglyph-matrices.md",
        "stereolab/exercises/exercise-api/src/lib.rs",
        "documents/course-copy.txt",
    ] {
        assert!(handout.join(f).is_file(), "{f} missing from the handout");
    }
    // The decks travel as sources: no local npm install or build.
    for f in ["slides/node_modules", "slides/build"] {
        assert!(!handout.join(f).exists(), "{f} copied into the handout");
    }
    // The documents are named by title, never by the team's file numbers.
    for f in files_under(&handout) {
        let in_student_part = !f.starts_with(handout.join("stereolab"));
        if in_student_part && f.extension().is_some_and(|e| e == "rs" || e == "md") {
            let text = std::fs::read_to_string(&f).unwrap().to_lowercase();
            assert!(
                !text.contains("seed 00") && !text.contains("seed00"),
                "{} names a source document by its file number",
                f.display()
            );
        }
    }
    let readme = std::fs::read_to_string(handout.join("README.md")).unwrap();
    for says in [
        "Only `src/stubs.rs` is\n  graded",
        "compiles the grader",
        "How points are given",
        "println!",
    ] {
        assert!(
            readme.contains(says),
            "the handout README does not say {says:?}"
        );
    }
    for ex in ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"] {
        let stubs = std::fs::read_to_string(handout.join(ex).join("src/stubs.rs")).unwrap();
        for cited in stubs
            .split('`')
            .filter(|w| w.ends_with(".md") && w.contains('/'))
        {
            assert!(
                handout.join(cited).is_file(),
                "{ex} cites {cited}, not in the handout"
            );
        }
        let manifest = std::fs::read_to_string(handout.join(ex).join("Cargo.toml")).unwrap();
        assert!(
            !manifest.contains("stereolab ="),
            "{ex} depends on stereolab:\n{manifest}"
        );
    }

    // The handout's crates build (the grader builds them) and the untouched stubs grade to zero.
    let (_, v) = grade("all", &[], &handout, None, "handout");
    assert_eq!(v["score"].as_f64(), Some(0.0), "{v}");
    // The students' own tests compile too.
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let tests = Command::new(cargo)
        .current_dir(&handout)
        .args([
            "test",
            "--offline",
            "--no-run",
            "-p",
            "ex1_stereo",
            "-p",
            "ex2_chromadepth",
            "-p",
            "ex3_sirds",
        ])
        .env("CARGO_TARGET_DIR", target_dir())
        .output()
        .expect("run cargo");
    assert!(
        tests.status.success(),
        "{}",
        String::from_utf8_lossy(&tests.stderr)
    );

    // The handout's own grader, from its data alone: the solution scores full marks and a
    // planted mistake is named, as the instructor's grader does.
    let handout_grade = |stubs: &str, name: &str| -> Value {
        let sub = handout.join(format!("sub-{name}"));
        let file = sub.join("ex2_chromadepth/src/stubs.rs");
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(&file, stubs).unwrap();
        let json = handout.join(format!("{name}.json"));
        let out = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
            .current_dir(&handout)
            .args([
                "run",
                "--offline",
                "--quiet",
                "-p",
                "stereolab",
                "--",
                "grade",
                "ex2",
            ])
            .arg("--exercises")
            .arg(&sub)
            .arg("--json")
            .arg(&json)
            .env("CARGO_TARGET_DIR", target_dir().join("handout-grader"))
            .output()
            .expect("run the handout's grader");
        assert_verdict_exit(&out, "the handout's grader");
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
    };
    let solution =
        std::fs::read_to_string(repo_exercises().join("ex2_chromadepth/src/solution.rs")).unwrap();
    assert_eq!(
        handout_grade(&solution, "solution")["score"].as_f64(),
        Some(5.0)
    );
    let sign = solution.replace("let c = -1.0 / (d2 - d1);", "let c = 1.0 / (d2 - d1);");
    assert_ne!(sign, solution);
    let v = handout_grade(&sign, "sign");
    let texgen = test_named(&v, "ex2 texgen")["output"].as_str().unwrap();
    assert!(
        texgen.contains("hint [texgen-sign]") && texgen.contains("chromadepth_texgen.png"),
        "{texgen}"
    );
    assert_eq!(v["score"].as_f64(), Some(3.0), "{v}");

    // A compile error costs its exercise only: the grader reports it and still exits cleanly.
    std::fs::write(
        handout.join("ex3_sirds/src/stubs.rs"),
        "pub fn broken( {}\n",
    )
    .unwrap();
    let (out, v) = grade("all", &[], &handout, None, "handout_broken");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("ex3_sirds: does not compile"), "{stdout}");
    assert!(
        test_named(&v, "ex3 link_row")["output"]
            .as_str()
            .unwrap()
            .contains("hint [build]")
    );
    assert!(
        test_named(&v, "ex2 texgen")["output"]
            .as_str()
            .unwrap()
            .contains("hint [todo]")
    );
}

#[test]
fn students_worked_examples_pass_with_the_solution() {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(root())
        .args(["test", "--offline", "--all-features"])
        .args([
            "-p",
            "ex1_stereo",
            "-p",
            "ex2_chromadepth",
            "-p",
            "ex3_sirds",
        ])
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("STEREOLAB_MUTANT")
        .output()
        .expect("run cargo test");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(stdout.matches("test result: ok").count(), 3, "{stdout}");
}

#[test]
fn bad_grade_arguments_get_clear_errors() {
    for (args, says) in [
        (vec!["grade", "ex9"], "expected ex1, ex2, ex3 or all"),
        (vec!["grade", "ex1", "--timeout", "0"], "--timeout"),
        (
            vec!["grade", "ex1", "--exercises", "/nonexistent"],
            "no exercise there",
        ),
        (
            vec!["render", "assets/scenes/wuson.toml", "--exercise", "all"],
            "name one exercise",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .current_dir(root())
            .args(&args)
            .output()
            .expect("run stereolab");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.starts_with("error: ") && err.contains(says),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn render_exercise_writes_the_solution_next_to_the_reference_on_any_scene() {
    let dir = out_dir("render_exercise");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .current_dir(root())
        .args(["render", "assets/scenes/wuson.toml", "--size", "96x72"])
        .args(["--exercise", "ex1", "--solution", "--out"])
        .arg(&dir)
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("STEREOLAB_MUTANT")
        .output()
        .expect("run stereolab render --exercise");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Four eye renders, four anaglyphs, two finalize pictures, remap both ways, visibility,
    // the random-dot pair's right dots and anaglyph, parallax colors.
    assert_eq!(stdout.lines().count(), 16, "{stdout}");
    for line in stdout.lines() {
        assert!(
            line.contains("mismatch   0.00%, mean channel difference   0.00"),
            "{line}"
        );
    }
    let strip = image::open(dir.join("anaglyph_true.png")).expect("strip written");
    assert_eq!(
        (strip.width(), strip.height()),
        stereolab::compare::strip_size(96, 72)
    );
}

/// Runs `stereolab compare --exercise ex1` on a small wuson with the solution, planting
/// `mutant` when given; returns the exit code and stdout.
#[cfg(feature = "gpu")]
fn compare_exercise(mutant: Option<&str>, name: &str) -> (Option<i32>, String) {
    let dir = out_dir(name);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stereolab"));
    cmd.current_dir(root())
        .args(["compare", "assets/scenes/wuson.toml", "--size", "96x72"])
        .args(["--exercise", "ex1", "--solution", "--out"])
        .arg(&dir)
        .env("CARGO_TARGET_DIR", target_dir())
        .env_remove("STEREOLAB_MUTANT");
    if let Some(m) = mutant {
        cmd.env("STEREOLAB_MUTANT", m);
    }
    let out = cmd.output().expect("run stereolab compare --exercise");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    for side in ["left", "right"] {
        let strip = image::open(dir.join(format!("ex1_stereo_matrices_{side}.png")))
            .unwrap_or_else(|e| panic!("{side} strip: {e}\n{text}"));
        assert_eq!(
            (strip.width(), strip.height()),
            stereolab::compare::strip_size(96, 72)
        );
    }
    (out.status.code(), text)
}

/// Measured (lavapipe, Mesa 22.3.6): the solution's pair matches the GPU reference with 0
/// coverage mismatch, identical colors and depth within 2.4e-7 on both eyes; swapped eyes
/// mismatch 0.35% coverage with depth differences of 2.1e-2 and exit 1.
#[cfg(feature = "gpu")]
#[test]
fn compare_exercise_solution_matches_the_gpu_and_swapped_eyes_exceed_the_parity_thresholds() {
    if crate::gpu_parity::gpu().is_none() {
        return;
    }
    let (code, text) = compare_exercise(None, "compare_exercise_solution");
    assert_eq!(code, Some(0), "{text}");
    for side in ["left", "right"] {
        let row = text
            .lines()
            .find(|l| l.starts_with(&format!("{side} (gpu | yours)")))
            .unwrap_or_else(|| panic!("no {side} row:\n{text}"));
        let cols: Vec<&str> = row.split_whitespace().collect();
        // name (4 words), coverage %, max diff, mean diff, PSNR, max depth.
        assert_eq!(cols[4], "0.00000", "coverage mismatch: {row}");
        let depth: f64 = cols[8].parse().expect("depth column");
        assert!(depth <= 1e-6, "{row}");
    }
    let (code, text) = compare_exercise(Some("swapped-eyes"), "compare_exercise_swapped");
    assert_eq!(code, Some(1), "{text}");
    for side in ["left", "right"] {
        assert!(
            text.contains(&format!("{side} (gpu | yours): coverage differs on")),
            "{text}"
        );
    }
}

#[cfg(not(feature = "gpu"))]
#[test]
fn compare_exercise_without_the_gpu_feature_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .current_dir(root())
        .args(["compare", "assets/scenes/wuson.toml", "--exercise", "ex1"])
        .output()
        .expect("run stereolab compare --exercise");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("built without the GPU path"),
        "{err}"
    );
}

/// `(2 points`, `1 bonus point`, `points to 23`: a figure quoted next to the word.
fn quoted_points(text: &str) -> Vec<String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let number = |w: &str| {
        w.trim_matches(|c: char| !c.is_ascii_digit() && c != '.')
            .parse::<f64>()
            .is_ok()
    };
    words
        .windows(3)
        .filter(|w| {
            let point = |x: &str| {
                x.trim_matches(|c: char| !c.is_alphabetic())
                    .starts_with("point")
            };
            (number(w[0]) && (point(w[1]) || (w[1] == "bonus" && point(w[2]))))
                || (point(w[0]) && w[1] == "to" && number(w[2]))
        })
        .map(|w| w.join(" "))
        .collect()
}

#[test]
fn the_stubs_and_the_instructors_guide_quote_no_points_and_name_where_they_are_printed() {
    assert_eq!(
        quoted_points("Task `a` (2 points, image check)"),
        ["(2 points, image"]
    );
    assert_eq!(quoted_points("(1 bonus point)").len(), 1);
    assert_eq!(
        quoted_points("set the points to 23: the"),
        ["points to 23:"]
    );
    let guide = std::fs::read_to_string(root().join("exercises/INSTRUCTORS.md")).unwrap();
    assert_eq!(
        quoted_points(&guide),
        Vec::<String>::new(),
        "INSTRUCTORS.md"
    );
    assert!(guide.contains("stereolab grade points"), "INSTRUCTORS.md");
    for krate in ["ex1_stereo", "ex2_chromadepth", "ex3_sirds"] {
        let stubs =
            std::fs::read_to_string(repo_exercises().join(krate).join("src/stubs.rs")).unwrap();
        assert_eq!(quoted_points(&stubs), Vec::<String>::new(), "{krate}");
        assert!(stubs.contains("`stereolab grade points`"), "{krate}");
    }
}

/// `stereolab exercises export DIR` of this repository, with the course's `documents` if given.
fn export_handout(dir: &Path, documents: Option<&Path>) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stereolab"));
    cmd.args(["exercises", "export"])
        .arg(dir)
        .arg("--root")
        .arg(root());
    if let Some(d) = documents {
        cmd.arg("--documents").arg(d);
    }
    let out = cmd.output().expect("run export");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Functions of every `.rs` file under `dir`, as `(file, function)` with their fingerprints
/// (the similarity report's winnowing, the handout's stubs as base code).
fn functions_under(
    dir: &Path,
    base: &std::collections::BTreeSet<u64>,
) -> Vec<(PathBuf, stereolab_grade::similarity::Function)> {
    files_under(dir)
        .into_iter()
        .filter(|f| f.extension().is_some_and(|e| e == "rs"))
        .flat_map(|f| {
            let text = std::fs::read_to_string(&f).unwrap();
            stereolab_grade::similarity::fingerprint_file(&text, base)
                .into_iter()
                .map(move |func| (f.clone(), func))
        })
        .collect()
}

#[test]
fn the_exported_handout_holds_no_reference_function() {
    use stereolab_grade::similarity::{DEFAULT_THRESHOLD, base_hashes, score};
    let handout = out_dir("handout_no_reference");
    // An earlier handout in the folder, its README a link planted to a file outside: the new
    // handout replaces the folder whole and writes through no link.
    let victim = out_dir("handout_no_reference_victim").join("victim.txt");
    std::fs::write(&victim, "keep me").unwrap();
    std::fs::create_dir_all(handout.join("stereolab/data")).unwrap();
    std::fs::write(handout.join("stereolab/data/ex1.json"), "{}").unwrap();
    std::fs::write(handout.join("Cargo.toml"), "").unwrap();
    std::os::unix::fs::symlink(&victim, handout.join("README.md")).unwrap();
    export_handout(&handout, None);
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me");
    let readme = handout.join("README.md");
    assert!(std::fs::symlink_metadata(&readme).unwrap().is_file());
    let base: std::collections::BTreeSet<u64> = Exercise::ALL
        .iter()
        .flat_map(|ex| {
            let stubs = repo_exercises().join(ex.crate_name()).join("src/stubs.rs");
            base_hashes(&std::fs::read_to_string(stubs).unwrap())
        })
        .collect();
    // The reference: the instructor's solutions, stereolab's library and the grader's task
    // specs (every function of them).
    let mut reference = Vec::new();
    for ex in Exercise::ALL {
        let dir = repo_exercises().join(ex.crate_name()).join("src");
        reference.extend(
            functions_under(&dir, &base)
                .into_iter()
                .filter(|(f, _)| f.ends_with("solution.rs")),
        );
    }
    for krate in ["core", "pipeline", "grade"] {
        reference.extend(functions_under(
            &root().join("crates").join(krate).join("src"),
            &base,
        ));
    }
    // The functions the handout must not hold, by name: the test would prove nothing without
    // them among the references.
    for name in [
        "frustum",
        "hsv_to_rgb",
        "variant_links",
        "sheet_reference",
        "visible_reference",
        "finalize_reference",
        "remap_reference",
        "link_row",
        "stereo_matrices",
    ] {
        assert!(
            reference
                .iter()
                .any(|(_, f)| f.name == name && f.fingerprints.len() >= 16),
            "no reference function {name} to look for"
        );
    }
    let shipped = functions_under(&handout, &base);
    assert!(
        shipped.len() > 100,
        "{} functions in the handout",
        shipped.len()
    );
    for (file, f) in &shipped {
        for (rfile, r) in &reference {
            if let Some((shared, sim)) = score(&f.fingerprints, &r.fingerprints) {
                assert!(
                    sim < DEFAULT_THRESHOLD,
                    "{}: `{}` (line {}) is {sim:.2} similar ({shared} fingerprints) to `{}` of {}",
                    file.display(),
                    f.name,
                    f.line,
                    r.name,
                    rfile.display()
                );
            }
        }
    }
}
