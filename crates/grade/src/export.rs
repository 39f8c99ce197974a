//! `stereolab exercises export DIR`: the student handout — the exercise crates with their stubs
//! and tests, the slides and docs, and a grader that carries the course's public cases as data:
//! no solution, and no reference implementation (neither stereolab's library nor the task specs'
//! code).

use std::path::Path;

use stereolab_core::{Error, Result, StagingDir};
use stereolab_grade_core::build::{HANDOUT_PROFILE, strip_solution};
use stereolab_grade_core::data::{exercise_data, task_to_data};
use stereolab_grade_core::{
    BuildMode, Exercise, Limits, child, default_work_dir, submission_binary,
};

use crate::fixture::{Fixture, grading_scene};

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::io(path, e)
}

/// Copies `from` into `to` recursively, skipping `target/` and the files `skip` refuses.
fn copy_tree(from: &Path, to: &Path, skip: &dyn Fn(&Path) -> bool) -> Result<()> {
    std::fs::create_dir_all(to).map_err(io(to))?;
    for entry in std::fs::read_dir(from).map_err(io(from))? {
        let entry = entry.map_err(io(from))?;
        let path = entry.path();
        if skip(&path) || entry.file_name() == "target" {
            continue;
        }
        let dest = to.join(entry.file_name());
        if path.is_dir() {
            copy_tree(&path, &dest, skip)?;
        } else {
            std::fs::copy(&path, &dest).map_err(io(&path))?;
        }
    }
    Ok(())
}

/// The versions the crates share (`[workspace.dependencies]` of stereolab's manifest), for the
/// handout's workspace manifest.
fn shared_versions(text: &str, path: &Path) -> Result<toml::Table> {
    let table: toml::Table =
        toml::from_str(text).map_err(|e| Error::parse(path, None, e.message().to_string()))?;
    table
        .get("workspace")
        .and_then(|w| w.get("dependencies").and_then(|d| d.as_table()).cloned())
        .ok_or_else(|| Error::parse(path, None, "no [workspace.dependencies] table"))
}

/// The handout's grader package (`stereolab/Cargo.toml`): `crates/grade-handout`'s manifest
/// named `stereolab` with a `stereolab` binary, so that `cargo run -p stereolab -- grade ex1`
/// reads as in the repository, its grade-core beside it.
fn handout_grader_manifest(root: &Path) -> Result<String> {
    let path = root.join("crates/grade-handout/Cargo.toml");
    let text = std::fs::read_to_string(&path).map_err(io(&path))?;
    let mut table: toml::Table =
        toml::from_str(&text).map_err(|e| Error::parse(&path, None, e.message().to_string()))?;
    let fail = |what: &str| Error::parse(&path, None, format!("no {what}"));
    table
        .get_mut("package")
        .and_then(|p| p.as_table_mut())
        .ok_or_else(|| fail("[package]"))?
        .insert("name".into(), "stereolab".into());
    let bin = toml::Table::from_iter([
        ("name".to_string(), toml::Value::from("stereolab")),
        ("path".to_string(), toml::Value::from("src/main.rs")),
    ]);
    table.insert(
        "bin".into(),
        toml::Value::Array(vec![toml::Value::Table(bin)]),
    );
    table
        .get_mut("dependencies")
        .and_then(|d| d.get_mut("stereolab-grade-core"))
        .and_then(|d| d.as_table_mut())
        .ok_or_else(|| fail("stereolab-grade-core dependency"))?
        .insert("path".into(), "crates/grade-core".into());
    toml::to_string(&table).map_err(|e| Error::parse(&path, None, e.to_string()))
}

/// The task data of every exercise into `data` (`ex1.json`…, `pictures/<exercise>/`): the
/// specs the instructor's grader computes, without hidden cases, with the reference's answers
/// to the image checks' inputs (the instructor's solution built and run) and the reference
/// pictures.
fn write_task_data(root: &Path, data: &Path) -> Result<()> {
    let fx = Fixture::new(grading_scene()?)?;
    // The instructor's own solutions: trusted code, built plainly.
    let mode = BuildMode::PLAIN;
    for ex in Exercise::ALL {
        let binary =
            submission_binary(&root.join("exercises"), ex, true, &default_work_dir(), mode)
                .map_err(|why| {
                    Error::invalid(ex.crate_name(), "the instructor's solution", why.message)
                })?;
        let pictures = data.join("pictures").join(ex.id());
        let mut tasks = Vec::new();
        for spec in crate::tasks(ex, &fx) {
            let Some(img) = &spec.image else {
                tasks.push(task_to_data(&spec, None, &[]));
                continue;
            };
            let run = child::run(&binary, spec.name, &img.inputs, Limits::DEFAULT);
            let expected: Vec<Option<Vec<f64>>> = (0..img.inputs.len())
                .map(|k| run.replies.get(k).and_then(|r| r.as_ref().ok().cloned()))
                .collect();
            if run.ending.is_some() || expected.iter().any(Option::is_none) {
                let mut why = match &run.ending {
                    Some(e) => format!("{} ({})", e.message, e.kind),
                    None => format!(
                        "{} of {} inputs answered",
                        expected.iter().flatten().count(),
                        expected.len()
                    ),
                };
                let stderr = run.stderr.0.trim();
                if !stderr.is_empty() {
                    why = format!("{why}; it printed: {stderr}");
                }
                return Err(Error::invalid(
                    ex.crate_name(),
                    spec.name,
                    format!(
                        "the instructor's solution does not answer every input of its image \
                         check: {why}"
                    ),
                ));
            }
            let written = img
                .reference
                .as_ref()
                .map_or_else(Vec::new, |r| r(&expected, &pictures));
            if let Some(e) = written.iter().find(|n| n.starts_with("error:")) {
                return Err(Error::invalid(ex.crate_name(), spec.name, e.clone()));
            }
            let names: Vec<String> = written
                .iter()
                .map(|n| format!("pictures/{}/{n}", ex.id()))
                .collect();
            tasks.push(task_to_data(&spec, Some(&expected), &names));
        }
        let text = serde_json::to_string(&exercise_data(ex, tasks))
            .map_err(|e| Error::internal("task data", e.to_string()))?;
        let path = data.join(format!("{}.json", ex.id()));
        stereolab_core::write_bytes(&path, text.as_bytes())?;
    }
    Ok(())
}

/// Writes the handout for the repository at `root` into `dir`:
/// `dir/Cargo.toml` (a workspace of the three exercises and the grader, with the handout's build
/// profile), `dir/stereolab/` (the grader: `stereolab-grade-core` and the task data, no
/// reference code and no renderer; the docs), `dir/ex*/` (stubs, student tests, the grader's
/// entry binary; no `solution.rs`, no `solution` feature), `dir/slides/`, `dir/README.md`.
///
/// The handout is made in a new folder beside `dir` and put in its place only when complete
/// ([`StagingDir`]): a failure (a full disk, the solution not building, Ctrl-C) leaves `dir` as
/// it was. `dir` may be absent, an empty folder, or a handout this command wrote, which is
/// replaced; any other folder is refused.
///
/// # Errors
/// Unreadable sources, the instructor's solution not building, `dir` holding something else,
/// or an unwritable `dir`.
pub fn export(root: &Path, dir: &Path, documents: Option<&Path>) -> Result<()> {
    if let Some(docs) = documents
        && !docs.is_dir()
    {
        return Err(Error::invalid(
            "--documents",
            docs.display(),
            "not a folder: name the folder holding the course's copies of the documents \
             listed in docs/sources.md",
        ));
    }
    if !replaceable(dir) {
        return Err(Error::invalid(
            "DIR",
            dir.display(),
            "is a folder with other files in it, not a handout this command wrote: name a new \
             or empty folder",
        ));
    }
    let staging = StagingDir::new(dir)?;
    write_handout(root, staging.path(), documents)?;
    staging.commit()
}

/// Whether the handout may be written at `dir`: it does not exist, or is an empty folder, or
/// holds a handout (its grader's task data, manifest and README).
fn replaceable(dir: &Path) -> bool {
    match std::fs::read_dir(dir) {
        Err(_) => true, // absent (or not a folder: StagingDir::new says what it is)
        Ok(mut entries) => {
            entries.next().is_none()
                || ["Cargo.toml", "README.md", "stereolab/data/ex1.json"]
                    .iter()
                    .all(|f| dir.join(f).is_file())
        }
    }
}

/// Writes the handout's files into the new folder `dir`.
fn write_handout(root: &Path, dir: &Path, documents: Option<&Path>) -> Result<()> {
    let manifest_path = root.join("Cargo.toml");
    let manifest = std::fs::read_to_string(&manifest_path).map_err(io(&manifest_path))?;
    let lib = dir.join("stereolab");
    std::fs::create_dir_all(&lib).map_err(io(&lib))?;
    let shared = shared_versions(&manifest, &manifest_path)?;
    std::fs::write(lib.join("Cargo.toml"), handout_grader_manifest(root)?).map_err(io(&lib))?;
    // The grader: its command, the shared machinery and the one error type; nothing else of
    // stereolab (every other crate holds reference code).
    copy_tree(
        &root.join("crates/grade-handout/src"),
        &lib.join("src"),
        &|_| false,
    )?;
    for krate in ["grade-core", "error"] {
        copy_tree(
            &root.join("crates").join(krate),
            &lib.join("crates").join(krate),
            &|_| false,
        )?;
    }
    write_task_data(root, &lib.join("data"))?;
    // The stubs and the README cite the docs (sources, formulas, the anaglyph matrices).
    copy_tree(&root.join("docs"), &lib.join("docs"), &|_| false)?;
    // The course decks, at the handout's top level: Markdown, figures, the npm manifest and
    // lock file to build them; not a local `npm ci` or build.
    copy_tree(&root.join("slides"), &dir.join("slides"), &|p| {
        p.parent() == Some(&root.join("slides"))
            && (p.ends_with("node_modules") || p.ends_with("build"))
    })?;
    // The lock file twice: the handout's workspace resolves from it, and the grader compiles it
    // in (every build of a submission resolves from the same versions).
    for (from, to) in [
        (root.join("LICENSE"), lib.join("LICENSE")),
        (root.join("Cargo.lock"), dir.join("Cargo.lock")),
        (root.join("Cargo.lock"), lib.join("Cargo.lock")),
    ] {
        std::fs::copy(&from, &to).map_err(io(&from))?;
    }
    // The grader's templates (manifest, lib.rs, main.rs and the untouched stubs of each
    // exercise) and exercise-api, the one crate a student's crate depends on besides glam.
    copy_tree(
        &root.join("exercises/exercise-api"),
        &lib.join("exercises/exercise-api"),
        &|_| false,
    )?;
    let mut members = Vec::new();
    for ex in Exercise::ALL {
        let name = ex.crate_name();
        let from = root.join("exercises").join(name);
        for file in ["Cargo.toml", "src/lib.rs", "src/main.rs", "src/stubs.rs"] {
            let (src, dst) = (from.join(file), lib.join("exercises").join(name).join(file));
            if let Some(parent) = dst.parent() {
                std::fs::create_dir_all(parent).map_err(io(parent))?;
            }
            std::fs::copy(&src, &dst).map_err(io(&src))?;
        }
        let to = dir.join(name);
        copy_tree(&from, &to, &|p| {
            p.file_name().is_some_and(|n| n == "solution.rs")
        })?;
        for file in ["Cargo.toml", "src/lib.rs"] {
            let p = to.join(file);
            let text = std::fs::read_to_string(&p).map_err(io(&p))?;
            let text = text.replace(
                "path = \"../exercise-api\"",
                "path = \"../stereolab/exercises/exercise-api\"",
            );
            std::fs::write(&p, strip_solution(&text)).map_err(io(&p))?;
        }
        members.push(name.to_string());
    }
    // The handout's own profile, not the repository's (which optimizes every dependency for
    // the test suite's renders): a student compiles the grader once and grades small pictures,
    // so compile time is what they wait for (docs/performance.md, "A student's first grade").
    let profiles = HANDOUT_PROFILE;
    members.push("stereolab".to_string());
    let workspace: toml::Table = [
        ("members", toml::Value::from(members)),
        ("resolver", toml::Value::from("3")),
        ("dependencies", toml::Value::Table(shared)),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let workspace = toml::to_string(&toml::Table::from_iter([(
        "workspace".to_string(),
        toml::Value::Table(workspace),
    )]))
    .map_err(|e| Error::parse(&manifest_path, None, e.to_string()))?;
    let workspace = format!("{workspace}\n{profiles}");
    std::fs::write(dir.join("Cargo.toml"), workspace).map_err(io(dir))?;
    let readme = handout_readme(&super::points::points_table()?);
    std::fs::write(dir.join("README.md"), readme).map_err(io(dir))?;
    // The course's own copies of the source documents (not redistributable, so not in the
    // repository): copied in when the instructor names the folder that holds them.
    if let Some(docs) = documents {
        copy_tree(docs, &dir.join("documents"), &|_| false)?;
    }
    Ok(())
}

/// The handout's README: [`HANDOUT_README`] with each exercise's points from `table`.
fn handout_readme(table: &[super::points::TaskPoints]) -> String {
    super::Exercise::ALL
        .into_iter()
        .fold(HANDOUT_README.to_string(), |text, ex| {
            text.replace(
                &format!("{{points:{}}}", ex.crate_name()),
                &super::points::exercise_points(table, ex),
            )
        })
}

/// The handout's README; `{points:<crate>}` stands for the crate's points (see
/// [`handout_readme`]).
const HANDOUT_README: &str = r#"# Stereo rendering exercises

Three exercises, one crate each:

| crate | topic | source (see `stereolab/docs/sources.md`) | points |
| --- | --- | --- | --- |
| `ex1_stereo` | stereo frusta, anaglyphs, remapping, visibility, parallax, a random-dot pair | the exercise slides, *Exercise 1: Stereoscopy* | {points:ex1_stereo} |
| `ex2_chromadepth` | the ChromaDepth ramp and texgen | Bailey, Clark: *Using ChromaDepth to obtain Inexpensive Single-image Stereovision for Scientific Visualization* | {points:ex2_chromadepth} |
| `ex3_sirds` | single-image random-dot stereograms | Petz, Goldlücke, Magnor: *Hardware-accelerated Autostereogram Rendering for Interactive 3D Visualization* | {points:ex3_sirds} |

Complete the `todo!`s in each crate's `src/stubs.rs`. Every stub's doc comment states the task,
the formula's source and the conventions (right-handed, NDC z in [-1, 1], the eyes
`exercise_api::Eye::Left` and `Eye::Right`); `cargo run -p stereolab -- grade points` prints
every task's points (the table above sums them).

What is here:
- `ex1_stereo/`, `ex2_chromadepth/`, `ex3_sirds/`: your crates. **Only `src/stubs.rs` is
  graded**: the grader builds a clean copy of each crate with your `src/stubs.rs` in it, so
  changes to other files (and added dependencies) do not reach the grade. Your crate may use
  `glam` and `exercise_api` (the types the stubs take and return), nothing else.
- `slides/`: the course decks (Marp Markdown), one per topic; each exercise is introduced on the
  slide that teaches its formula. `ex1_stereo`: `01-perception.md` (parallax),
  `02-rig.md` (frusta, stereo matrices), `03-finalize.md` (anaglyphs), `04-remap.md`
  (remapping, visibility, the random-dot pair); `ex2_chromadepth`: `05-chromadepth.md`; `ex3_sirds`:
  `06-sirds.md`. Read the Markdown as it is, or build HTML/PDF as `slides/README.md` says.
- `stereolab/`: the grader. It holds the course's public test inputs with their expected
  answers and the reference pictures (`stereolab/data/`), not the renderer or any reference
  code. `stereolab/docs/sources.md` names the course's
  source documents (title, authors, where to get them); `stereolab/docs/formulas.md` collects the
  formulas; `stereolab/docs/anaglyph-matrices.md` holds the published anaglyph matrices the
  bonus task needs. `documents/`, when your instructor added it, holds the documents
  themselves.

## Commands

```sh
cargo test -p ex1_stereo                                  # the worked examples of the sources
cargo run -p stereolab -- grade ex1                       # points, hints (or ex2, ex3, all)
cargo run -p stereolab -- grade points                    # every task's points
```

**The first `cargo run -p stereolab` compiles the grader** and its few dependencies,
unoptimized (this workspace's profile: compiling fast matters more than running fast). Later
runs start at once. Each `grade` then builds your crates in `target/stereolab-grade/` in
seconds.

To see your functions draw in the real renderer, beside the reference, clone the public
stereolab repository and run `cargo run -- render --exercise ex1 assets/scenes/wuson.toml
--exercises PATH/TO/THIS/HANDOUT --out out` there.

## How points are given

- Each task is checked on many inputs (the numbers, with a tolerance printed beside every
  failure) and, where it draws something, by an image check: in the official grade your
  function is plugged into the real renderer and its picture compared with the reference's;
  this handout's grader, which has no renderer, compares the answers the picture is drawn from
  with the reference's (answers within the tolerance draw the reference's picture). The image
  check carries 30% of the task's points, the numeric checks 70%, in proportion to the inputs
  you get right.
- A mistake the grader recognizes (swapped eyes, a transposed matrix, degrees for radians, …)
  is named in a hint. The task still scores the checks your answer passes, like any other
  answer: a recognized mistake never scores below an unrecognized answer that passes fewer
  checks.
- The instructor may grade extra hidden inputs beside the ones you see.
- A task whose function panics, loops (killed after 10 s), crashes or runs out of memory
  (1 GiB) loses that task only.
- Bonus tasks add points beyond the total.
- Passing: at least 50% of all points and at least 2 points in each exercise.

## Printing while you debug

`println!` and `eprintln!` are fine: the grader shows the first lines of what each task printed
and never reads it as an answer. Printing a lot slows a task down; remove it when you are done.

## Pictures

The reference pictures of every image check are in `stereolab/data/pictures/`; a failing
image check names the ones to look at.
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_handout_profile_compiles_everything_unoptimized_without_debug_info() {
        let t: toml::Table = toml::from_str(HANDOUT_PROFILE).unwrap();
        let dev = &t["profile"]["dev"];
        let deps = &dev["package"]["*"];
        for p in [dev, deps] {
            assert_eq!(p["opt-level"].as_integer(), Some(0), "{t}");
            assert_eq!(p["debug"].as_bool(), Some(false), "{t}");
        }
    }

    #[test]
    fn the_handout_readme_takes_each_exercises_points_from_the_specs_and_states_the_partial_credit_rule()
     {
        let table = super::super::points::points_table().expect("the grading scene loads");
        let text = handout_readme(&table);
        assert!(!text.contains("{points:"), "{text}");
        for ex in super::super::Exercise::ALL {
            let cell = super::super::points::exercise_points(&table, ex);
            assert!(
                text.contains(&format!("| {cell} |\n")),
                "{}: {cell}\n{text}",
                ex.crate_name()
            );
        }
        assert!(text.contains("grade points"), "{text}");
        assert!(
            text.contains("still scores the checks your answer passes"),
            "{text}"
        );
        assert!(!text.contains("scores 0"), "{text}");
    }

    #[test]
    fn strip_solution_drops_marked_blocks_with_their_markers() {
        let text = "a\n# solution-begin\n[features]\nsolution = []\n# solution-end\nb\n";
        assert_eq!(strip_solution(text), "a\nb\n");
    }
}
