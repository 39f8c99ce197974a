//! `stereolab grade batch`: every submission in a folder, graded on a bounded number of threads,
//! one `results.json` and `report.txt` each, a `scores.csv` of all and a `similarity.csv` (see
//! [`super::similarity`]).
//!
//! A submission is one subfolder of the batch folder, holding the handout's layout
//! (`<crate>/src/stubs.rs`), directly or one folder further down (`alice/ex1_stereo/src/stubs.rs`
//! or `alice/handout/ex1_stereo/src/stubs.rs`, as an unpacked archive often is), or under
//! `exercises/`. Only the stubs files are read. A submission that lacks a file or does not
//! compile gets its zero in its own results; the batch goes on.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use super::report::Report;
use super::{Exercise, GradeOptions, Limits, grade, stubs_path};
use stereolab_core::{Error, Result};

/// How to grade a batch.
#[derive(Clone, Debug)]
pub struct BatchOptions {
    /// The folder whose subfolders are the submissions.
    pub submissions: PathBuf,
    /// Where the results go (`<submission>/results.json`, `<submission>/report.txt`,
    /// `scores.csv`).
    pub out: PathBuf,
    /// Which exercises.
    pub exercises: Vec<Exercise>,
    /// Submissions graded at once (see [`max_jobs`]).
    pub jobs: usize,
    /// Limits of one task's subprocess.
    pub limits: Limits,
    /// The grader's build folder, shared by all submissions.
    pub work: PathBuf,
    /// Wall-clock limit of one submission's build (every build and task of a batch runs in
    /// the sandbox).
    pub build_timeout: std::time::Duration,
    /// Pairs of functions at least this similar are flagged in `similarity.csv`.
    pub similarity_threshold: f64,
}

/// The most submissions graded at once: twice the machine's cores (a grading thread waits on
/// cargo and on its tasks' processes much of the time), at most 64.
pub fn max_jobs() -> usize {
    std::thread::available_parallelism()
        .map_or(2, |n| n.get() * 2)
        .min(64)
}

/// One submission's outcome.
#[derive(Clone, Debug)]
pub struct BatchEntry {
    /// The subfolder's name.
    pub name: String,
    /// Its report, or why it could not be graded at all.
    pub report: std::result::Result<Report, String>,
}

/// The folder of `submission` that holds the exercise crates: itself, or its one subfolder
/// that does (`None` when none or several do: the report then says what is missing).
pub fn submission_root(submission: &Path, exercises: &[Exercise]) -> Option<PathBuf> {
    let holds = |d: &Path| {
        exercises
            .iter()
            .any(|ex| stubs_path(d, *ex, false).is_file())
    };
    if holds(submission) {
        return Some(submission.to_path_buf());
    }
    let mut found: Vec<PathBuf> = std::fs::read_dir(submission)
        .ok()?
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
        .map(|e| e.path())
        .filter(|p| holds(p))
        .collect();
    (found.len() == 1).then(|| found.remove(0))
}

/// The submissions: the subfolders of `dir` (hidden ones skipped), sorted by name.
///
/// # Errors
/// `dir` unreadable, or a subfolder name that is not UTF-8 (it names a results folder and a CSV
/// row).
pub fn submissions(dir: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut subs = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let name = entry.file_name();
        let Some(name) = name.to_str() else {
            return Err(Error::invalid(
                "submission folder",
                entry.path().display(),
                "its name is not UTF-8; rename it",
            ));
        };
        if !name.starts_with('.') {
            subs.push((name.to_string(), entry.path()));
        }
    }
    subs.sort();
    Ok(subs)
}

/// Grades every submission of `opts.submissions` on `opts.jobs` threads, writing each one's
/// `results.json` and `report.txt` as it finishes, `scores.csv` and `similarity.csv` at the end;
/// `done` is called once per submission (the progress bar). Returns the entries sorted by name.
///
/// # Errors
/// Bad options (no submissions, `jobs` out of range) or an unwritable results folder; a
/// submission's own problems are its result.
pub fn grade_batch(
    opts: &BatchOptions,
    done: &(dyn Fn(&BatchEntry) + Sync),
) -> Result<Vec<BatchEntry>> {
    if !(1..=max_jobs()).contains(&opts.jobs) {
        return Err(Error::invalid(
            "--jobs",
            opts.jobs,
            format!("must be between 1 and {} on this machine", max_jobs()),
        ));
    }
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    if absolute(&opts.out).starts_with(absolute(&opts.submissions)) {
        return Err(Error::invalid(
            "--out",
            opts.out.display(),
            "must lie outside the submissions folder (it would be graded as a submission)",
        ));
    }
    super::check_sandbox(super::Policy::Required)?;
    let subs = submissions(&opts.submissions)?;
    if subs.is_empty() {
        return Err(Error::invalid(
            "SUBMISSIONS_DIR",
            opts.submissions.display(),
            "holds no submission folders",
        ));
    }
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::io(&opts.out, e))?;
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<BatchEntry>> = Mutex::new(Vec::with_capacity(subs.len()));
    let failure: Mutex<Option<Error>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..opts.jobs.min(subs.len()) {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some((name, dir)) = subs.get(k) else {
                        break;
                    };
                    let started = std::time::Instant::now();
                    let entry = grade_one(opts, name, dir);
                    if let Err(e) = write_entry(&opts.out, &entry, started.elapsed()) {
                        failure
                            .lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .get_or_insert(e);
                    }
                    done(&entry);
                    results
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push(entry);
                }
            });
        }
    });
    if let Some(e) = failure.into_inner().unwrap_or_else(|e| e.into_inner()) {
        return Err(e);
    }
    let mut entries = results.into_inner().unwrap_or_else(|e| e.into_inner());
    entries.sort_by(|a, b| a.name.cmp(&b.name));
    let csv_path = opts.out.join("scores.csv");
    stereolab_core::write_bytes(&csv_path, scores_csv(&opts.exercises, &entries).as_bytes())?;
    super::similarity::write_batch_report(
        &subs,
        &opts.exercises,
        opts.similarity_threshold,
        &opts.out,
    )?;
    Ok(entries)
}

fn grade_one(opts: &BatchOptions, name: &str, dir: &Path) -> BatchEntry {
    let root = submission_root(dir, &opts.exercises).unwrap_or_else(|| dir.to_path_buf());
    let report = super::fixture::grading_scene()
        .and_then(|scene| {
            grade(
                &GradeOptions {
                    exercises: opts.exercises.clone(),
                    dir: root,
                    solution: false,
                    limits: opts.limits,
                    out: opts.out.join(name).join("images"),
                    work: opts.work.clone(),
                    sandbox: super::Policy::Required,
                    build_timeout: opts.build_timeout,
                },
                scene,
            )
        })
        .map_err(|e| e.to_string());
    BatchEntry {
        name: name.to_string(),
        report,
    }
}

/// results.json (with Gradescope's `execution_time`, whole seconds) and report.txt of one
/// submission (each written whole or not at all; folders of this machine left out of both).
fn write_entry(out: &Path, entry: &BatchEntry, took: std::time::Duration) -> Result<()> {
    let dir = out.join(&entry.name);
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let (mut json, text) = match &entry.report {
        Ok(r) => (r.gradescope(), super::report::without_dirs(&r.text())),
        Err(e) => (
            serde_json::json!({
                "score": 0.0,
                "output": format!("not graded: {e}"),
                "output_format": "text",
                "visibility": "visible",
                "tests": [],
            }),
            format!("not graded: {e}\n"),
        ),
    };
    json["execution_time"] = took.as_secs().into();
    let json = serde_json::to_string_pretty(&json)
        .map_err(|e| Error::io(&dir, std::io::Error::other(e)))?;
    // The two files of one submission: both written, or neither.
    let mut set = stereolab_core::OutputSet::new();
    set.stage_bytes(&dir.join("results.json"), json.as_bytes())?;
    set.stage_bytes(&dir.join("report.txt"), text.as_bytes())?;
    set.commit().map(drop)
}

/// A CSV field: quoted when it holds a comma, quote or line break; a field a spreadsheet would
/// read as a formula (starting with `=`, `+`, `-`, `@`, a tab or a carriage return) gets a
/// leading `'`, which spreadsheets show as text.
pub(crate) fn csv_field(s: &str) -> String {
    let s = if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{s}")
    } else {
        s.to_string()
    };
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s
    }
}

/// `submission,<ex>…,total,max,passed`, one row per entry in the order given; scores with two
/// decimals; a submission that could not be graded has empty scores and `error` as `passed`.
pub fn scores_csv(exercises: &[Exercise], entries: &[BatchEntry]) -> String {
    let mut s = String::from("submission");
    for ex in exercises {
        let _ = write!(s, ",{}", ex.id());
    }
    s.push_str(",total,max,passed\n");
    for e in entries {
        s.push_str(&csv_field(&e.name));
        match &e.report {
            Ok(r) => {
                for ex in exercises {
                    let score = r
                        .exercises
                        .iter()
                        .find(|x| x.exercise == *ex)
                        .map_or(0.0, super::report::ExerciseResult::score);
                    let _ = write!(s, ",{score:.2}");
                }
                let _ = writeln!(s, ",{:.2},{:.2},{}", r.score(), r.max(), r.passed());
            }
            Err(_) => {
                for _ in exercises {
                    s.push(',');
                }
                s.push_str(",,,error\n");
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_with_commas_and_quotes_are_quoted() {
        assert_eq!(csv_field("alice"), "alice");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn csv_fields_a_spreadsheet_reads_as_formulas_start_with_a_quote() {
        for (name, field) in [
            ("=1+1", "'=1+1"),
            ("+cmd", "'+cmd"),
            ("-2", "'-2"),
            ("@SUM(A1)", "'@SUM(A1)"),
            ("=HYPERLINK(\"x\",1)", "\"'=HYPERLINK(\"\"x\"\",1)\""),
            ("bob-2", "bob-2"),
        ] {
            assert_eq!(csv_field(name), field, "{name}");
        }
        let entries = [BatchEntry {
            name: "=cmd|' /C calc'!A0".into(),
            report: Err("x".into()),
        }];
        let csv = scores_csv(&[Exercise::Ex2], &entries);
        assert_eq!(
            csv.lines().nth(1),
            Some("'=cmd|' /C calc'!A0,,,,error"),
            "{csv}"
        );
    }

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("stereolab-batch-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_single_file_per_crate_is_a_submission_directly_or_one_folder_down() {
        let base = scratch("single");
        let alice = base.join("alice");
        std::fs::create_dir_all(&alice).unwrap();
        std::fs::write(alice.join("ex1_stereo.rs"), "pub fn f() {}\n").unwrap();
        assert_eq!(
            submission_root(&alice, &[Exercise::Ex1]),
            Some(alice.clone())
        );
        assert_eq!(
            stubs_path(&alice, Exercise::Ex1, false),
            alice.join("ex1_stereo.rs")
        );
        // The handout's layout is taken first when both are there.
        let layout = alice.join("ex1_stereo/src/stubs.rs");
        std::fs::create_dir_all(layout.parent().unwrap()).unwrap();
        std::fs::write(&layout, "pub fn g() {}\n").unwrap();
        assert_eq!(stubs_path(&alice, Exercise::Ex1, false), layout);
        let bob = base.join("bob");
        std::fs::create_dir_all(bob.join("upload")).unwrap();
        std::fs::write(bob.join("upload/ex3_sirds.rs"), "pub fn f() {}\n").unwrap();
        assert_eq!(
            submission_root(&bob, &Exercise::ALL),
            Some(bob.join("upload"))
        );
        let _ = std::fs::remove_dir_all(&base);
    }

    #[test]
    fn a_missing_file_is_named_with_where_it_was_looked_for_and_its_own_hint() {
        let base = scratch("missing");
        let Err(why) =
            crate::submission_binary(&base, Exercise::Ex2, false, &base, crate::BuildMode::PLAIN)
        else {
            panic!("an empty submission builds nothing");
        };
        assert_eq!(why.id, "missing-file");
        for looked in [
            "`ex2_chromadepth/src/stubs.rs`",
            "`exercises/ex2_chromadepth/src/stubs.rs`",
            "`ex2_chromadepth.rs`",
        ] {
            assert!(why.message.contains(looked), "{looked}: {}", why.message);
        }
        assert!(!why.message.contains("compile"), "{}", why.message);
        assert!(
            !why.message.contains(&base.display().to_string()),
            "{}",
            why.message
        );
        assert!(why.hint.contains("ex2_chromadepth.rs"), "{}", why.hint);
        let _ = std::fs::remove_dir_all(&base);
    }

    #[test]
    fn results_json_has_execution_time_and_report_txt_names_no_folder_of_this_machine() {
        use super::super::report::ExerciseResult;
        use super::super::score::TaskResult;
        let base = scratch("entry");
        let strip = base.join("alice/images/ex2_hsv_ramp.png");
        let task = TaskResult {
            exercise: "ex2",
            name: "hsv_ramp",
            points: 2.0,
            bonus: false,
            score: 1.4,
            passed: 1,
            total: 1,
            image_passed: Some(false),
            details: vec![format!(
                "image ramp: expected | diff | actual: {}",
                strip.display()
            )],
            hint: None,
            hidden: None,
        };
        let entry = BatchEntry {
            name: "alice".into(),
            report: Ok(Report {
                exercises: vec![ExerciseResult {
                    exercise: Exercise::Ex2,
                    build_error: None,
                    tasks: vec![task],
                }],
            }),
        };
        write_entry(&base, &entry, std::time::Duration::from_millis(2600)).unwrap();
        let json: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(base.join("alice/results.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(json["execution_time"], serde_json::json!(2), "{json}");
        let text = std::fs::read_to_string(base.join("alice/report.txt")).unwrap();
        assert!(text.contains("actual: ex2_hsv_ramp.png"), "{text}");
        assert!(!text.contains(&base.display().to_string()), "{text}");
        let _ = std::fs::remove_dir_all(&base);
    }
}
