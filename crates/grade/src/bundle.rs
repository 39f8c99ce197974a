//! `stereolab grade bundle`: the Gradescope autograder (a zip with `setup.sh`, `run_autograder`
//! and the grader's sources) and a GitHub Classroom workflow.
//!
//! Gradescope unpacks the zip into `/autograder/source`, runs `setup.sh` once when it builds the
//! image (here: Rust if absent, the grader's build, and a warm-up grading of the stubs so the
//! exercise crates' dependencies are compiled), then `run_autograder` for every submission with
//! the student's files in `/autograder/submission`; the results go to
//! `/autograder/results/results.json`. `AUTOGRADER_ROOT` moves `/autograder` (the tests run the
//! scripts in a temporary folder). The solutions are not in the bundle.

use std::path::Path;

use super::Exercise;
use stereolab_core::{Error, Result};

/// The largest file the bundle takes from the sources (the models and scenes are far smaller).
const MAX_FILE_BYTES: u64 = 16 << 20;

/// The files of the bundle: `(path in the zip, bytes, executable)`, sorted by path.
type Files = Vec<(String, Vec<u8>, bool)>;

fn io(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::io(path, e)
}

fn add_tree(root: &Path, rel: &str, files: &mut Files) -> Result<()> {
    let dir = root.join(rel);
    for entry in std::fs::read_dir(&dir).map_err(io(&dir))? {
        let entry = entry.map_err(io(&dir))?;
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let rel = format!("{rel}/{name}");
        let kind = entry.file_type().map_err(io(&dir))?;
        if kind.is_dir() {
            if name != "target" {
                add_tree(root, &rel, files)?;
            }
        } else if kind.is_file() && name != "solution.rs" {
            add_file(root, &rel, files)?;
        }
    }
    Ok(())
}

fn add_file(root: &Path, rel: &str, files: &mut Files) -> Result<()> {
    let path = root.join(rel);
    let bytes = stereolab_core::read_input(&path, MAX_FILE_BYTES)?;
    files.push((format!("stereolab/{rel}"), bytes, false));
    Ok(())
}

/// stereolab's manifest for the bundle: a workspace of its own (no exercise crates as members,
/// no repository tests or examples), the same dependencies and profiles.
fn bundle_manifest(text: &str, path: &Path) -> Result<String> {
    let mut table: toml::Table =
        toml::from_str(text).map_err(|e| Error::parse(path, None, e.message().to_string()))?;
    table.remove("test");
    table.remove("example");
    // A workspace of its own: the versions the crates share, the crates as path dependencies.
    let shared = table
        .get("workspace")
        .and_then(|w| w.get("dependencies"))
        .cloned()
        .ok_or_else(|| Error::parse(path, None, "no [workspace.dependencies] table"))?;
    table.insert(
        "workspace".into(),
        toml::Value::Table(toml::Table::from_iter([(
            "dependencies".to_string(),
            shared,
        )])),
    );
    toml::to_string(&table).map_err(|e| Error::parse(path, None, e.to_string()))
}

/// The crates a submission provides, in the order `run_autograder` looks for them.
fn crate_names() -> String {
    Exercise::ALL
        .iter()
        .map(|e| e.crate_name())
        .collect::<Vec<_>>()
        .join(" ")
}

/// `setup.sh`: Rust when cargo is missing, the grader (or `STEREOLAB_BIN`, a prebuilt one), and a
/// grading of the stubs that compiles the exercise crates' dependencies into the build folder.
fn setup_sh() -> String {
    r#"#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image (Ubuntu).
set -euo pipefail
ROOT="${AUTOGRADER_ROOT:-/autograder}"
SRC="$ROOT/source"
if ! command -v cargo >/dev/null 2>&1 && [ -f "$HOME/.cargo/env" ]; then . "$HOME/.cargo/env"; fi
if ! command -v cargo >/dev/null 2>&1; then
    if command -v apt-get >/dev/null 2>&1; then
        apt-get update && apt-get install -y --no-install-recommends curl ca-certificates build-essential
    fi
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
    . "$HOME/.cargo/env"
fi
# Every build and task of a submission runs in a bubblewrap sandbox (the grader refuses to
# grade without one): new namespaces, and a user of its own per run.
if ! command -v bwrap >/dev/null 2>&1 && command -v apt-get >/dev/null 2>&1; then
    apt-get update && apt-get install -y --no-install-recommends bubblewrap util-linux
fi
mkdir -p "$SRC/bin"
if [ -n "${STEREOLAB_BIN:-}" ]; then
    # A grader built elsewhere (the repository's tests use their own build).
    cp "$STEREOLAB_BIN" "$SRC/bin/stereolab"
else
    export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$SRC/target}"
    # The command alone: no viewer, allocator or zip code (what a student's handout builds too).
    cargo build --release \
        --manifest-path "$SRC/stereolab/Cargo.toml" --bin stereolab
    cp "$CARGO_TARGET_DIR/release/stereolab" "$SRC/bin/stereolab"
fi
# Warm-up: grading the untouched stubs compiles glam, serde and exercise-api into the build
# folder, so a submission compiles only its own crate. The stubs score zero, NOT PASSED (exit
# code 3); that is expected, any other failure is not.
status=0
"$SRC/bin/stereolab" grade all --exercises "$SRC/stereolab/exercises" \
    --build-dir "${STEREOLAB_BUILD_DIR:-$ROOT/work/build}" --out "$ROOT/work/images" >/dev/null \
    || status=$?
if [ "$status" -ne 0 ] && [ "$status" -ne 3 ]; then exit "$status"; fi
echo "stereolab autograder ready"
"#
    .to_string()
}

/// `run_autograder`: the submission's stubs into a clean folder, then `stereolab grade all`.
fn run_autograder(seed: Option<u64>) -> String {
    let seed_line = seed.map_or_else(
        || "# No hidden cases: the bundle was built without --seed.\n".to_string(),
        |s| format!("export STEREOLAB_GRADER_SEED={s}\n"),
    );
    format!(
        r#"#!/usr/bin/env bash
# Gradescope runs this for every submission (working folder /autograder).
# Accepted submissions, per exercise crate C (ex1_stereo, ex2_chromadepth, ex3_sirds):
#   C/src/stubs.rs (the handout's layout, e.g. a GitHub repository of the handout),
#   the same one folder further down (handout/C/src/stubs.rs) or under exercises/,
#   or a single uploaded file named C.rs (ex1_stereo.rs).
# Only these files are read; a missing one costs that exercise's points.
set -uo pipefail
ROOT="${{AUTOGRADER_ROOT:-/autograder}}"
SRC="$ROOT/source"
SUB="$ROOT/submission"
RES="$ROOT/results"
STAGE="$ROOT/work/submission"
if [ -f "$HOME/.cargo/env" ]; then . "$HOME/.cargo/env"; fi
{seed_line}mkdir -p "$RES"
rm -rf "$STAGE"
mkdir -p "$STAGE"
found=0
for crate in {crates}; do
    for cand in "$SUB/$crate/src/stubs.rs" "$SUB/exercises/$crate/src/stubs.rs" \
        "$SUB"/*/"$crate/src/stubs.rs" "$SUB/$crate.rs"; do
        if [ -L "$cand" ] || {{ [ -e "$cand" ] && case "$(realpath -- "$cand")" in
                "$(realpath -- "$SUB")"/*) false ;; *) true ;; esac; }}; then
            # A link (or a path through one) out of the submission: staged as a link, which
            # the grader refuses with that reason instead of reading what it points to.
            mkdir -p "$STAGE/$crate/src"
            ln -s "$cand" "$STAGE/$crate/src/stubs.rs"
            found=1
            break
        elif [ -f "$cand" ]; then
            mkdir -p "$STAGE/$crate/src"
            cp "$cand" "$STAGE/$crate/src/stubs.rs"
            found=1
            break
        fi
    done
done
rm -f "$RES/results.json"
if [ "$found" = 1 ]; then
    "$SRC/bin/stereolab" grade all --exercises "$STAGE" --json "$RES/results.json" \
        --build-dir "${{STEREOLAB_BUILD_DIR:-$ROOT/work/build}}" --out "$ROOT/work/images" \
        --build-timeout "${{STEREOLAB_BUILD_TIMEOUT:-120}}"
fi
if [ ! -s "$RES/results.json" ]; then
    cat > "$RES/results.json" <<'JSON'
{{"score": 0.0, "output": "The grader found no exercise in your submission (or could not run). Submit ex1_stereo/src/stubs.rs, ex2_chromadepth/src/stubs.rs and ex3_sirds/src/stubs.rs as in the handout, or the files ex1_stereo.rs, ex2_chromadepth.rs and ex3_sirds.rs.", "output_format": "text", "visibility": "visible", "tests": []}}
JSON
fi
"#,
        crates = crate_names()
    )
}

/// `.github/workflows/classroom.yml` for a GitHub Classroom repository made from the handout:
/// feedback on every push, not a grade (it runs the student's own, editable copy of the grader,
/// and Classroom reads no points from an artifact).
pub const CLASSROOM_YML: &str = r#"# GitHub Classroom: FEEDBACK ONLY, NOT A GRADE.
# On every push this runs the grader of this repository (the student's own copy, which the
# student can edit) and shows its report in the job's log; results.json is kept as an artifact.
# GitHub Classroom reads no points from it, and a result from an editable grader is no grade:
# official grades come from the instructor's Gradescope autograder or `stereolab grade batch`.
name: Feedback (not the grade)
on: [push, workflow_dispatch]
permissions:
  contents: read
jobs:
  feedback:
    name: Grader feedback (not the grade)
    runs-on: ubuntu-latest
    timeout-minutes: 30
    steps:
      - uses: actions/checkout@v4
      - uses: dtolnay/rust-toolchain@stable
      - uses: Swatinem/rust-cache@v2
      # The step fails (exit code 3) when the verdict is NOT PASSED: a red run is the feedback.
      - name: Feedback from this repository's grader (not the grade)
        run: cargo run --release -p stereolab -- grade all --json results.json
      - name: Keep the feedback's results.json (not read as points)
        if: always()
        uses: actions/upload-artifact@v4
        with:
          name: feedback-results
          path: results.json
"#;

/// The bundle's files for the repository at `root`.
fn files(root: &Path, seed: Option<u64>) -> Result<Files> {
    let mut files: Files = vec![
        ("setup.sh".into(), setup_sh().into_bytes(), true),
        (
            "run_autograder".into(),
            run_autograder(seed).into_bytes(),
            true,
        ),
        (
            "github-classroom/classroom.yml".into(),
            CLASSROOM_YML.as_bytes().to_vec(),
            false,
        ),
    ];
    let manifest_path = root.join("Cargo.toml");
    let manifest = std::fs::read_to_string(&manifest_path).map_err(io(&manifest_path))?;
    files.push((
        "stereolab/Cargo.toml".into(),
        bundle_manifest(&manifest, &manifest_path)?.into_bytes(),
        false,
    ));
    for file in ["Cargo.lock", "LICENSE"] {
        add_file(root, file, &mut files)?;
    }
    for dir in [
        "src",
        "crates",
        "docs",
        "assets/scenes",
        "assets/fonts",
        "exercises/exercise-api",
    ] {
        add_tree(root, dir, &mut files)?;
    }
    // The templates the grader compiles in, and the stubs for setup's warm-up (no solutions).
    for ex in Exercise::ALL {
        for file in ["Cargo.toml", "src/lib.rs", "src/main.rs", "src/stubs.rs"] {
            add_file(
                root,
                &format!("exercises/{}/{file}", ex.crate_name()),
                &mut files,
            )?;
        }
    }
    files.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(files)
}

/// Writes the Gradescope autograder zip for the repository at `root` to `out` (whole or not at
/// all; the same bytes for the same sources and seed).
///
/// # Errors
/// Unreadable sources or an unwritable `out`.
/// An instructor's command: without the `bundle` feature (the student handout's build) it says
/// how to get one instead of pulling the zip crate into every build.
pub fn bundle(root: &Path, out: &Path, seed: Option<u64>) -> Result<()> {
    let files = files(root, seed)?;
    write_zip(&files, out)
}

#[cfg(not(feature = "bundle"))]
fn write_zip(_files: &Files, out: &Path) -> Result<()> {
    Err(Error::invalid(
        "grade bundle --out",
        out.display(),
        "this stereolab was built without the `bundle` feature (the student handout's build): \
         build the grader with `cargo build --release --features bundle`",
    ))
}

#[cfg(feature = "bundle")]
fn write_zip(files: &Files, out: &Path) -> Result<()> {
    use std::io::Write as _;
    use zip::write::SimpleFileOptions;
    use zip::{CompressionMethod, DateTime, ZipWriter};

    let mut zip = ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let zerr = |e: zip::result::ZipError| Error::io(out, std::io::Error::other(e));
    for (name, bytes, exec) in files {
        let options = SimpleFileOptions::default()
            .compression_method(CompressionMethod::Deflated)
            .last_modified_time(DateTime::default())
            .unix_permissions(if *exec { 0o755 } else { 0o644 });
        zip.start_file(name.as_str(), options).map_err(zerr)?;
        zip.write_all(bytes).map_err(io(out))?;
    }
    let bytes = zip.finish().map_err(zerr)?.into_inner();
    stereolab_core::write_bytes(out, &bytes)
}

/// Writes `.github/workflows/classroom.yml` under `dir`.
///
/// # Errors
/// An unwritable `dir`.
pub fn write_classroom(dir: &Path) -> Result<std::path::PathBuf> {
    let path = dir.join(".github/workflows/classroom.yml");
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io(parent))?;
    }
    stereolab_core::write_bytes(&path, CLASSROOM_YML.as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_classroom_workflow_says_it_is_feedback_only_in_its_comments_and_step_names() {
        let header: Vec<&str> = CLASSROOM_YML
            .lines()
            .take_while(|l| l.starts_with('#'))
            .collect();
        let header = header.join("\n");
        assert!(header.contains("FEEDBACK ONLY, NOT A GRADE"), "{header}");
        assert!(header.contains("official grades come from"), "{header}");
        let names: Vec<&str> = CLASSROOM_YML
            .lines()
            .filter_map(|l| {
                let l = l.trim_start().trim_start_matches("- ");
                l.strip_prefix("name: ")
            })
            .collect();
        assert!(names.len() >= 4, "{names:?}");
        for n in names.iter().filter(|n| !n.starts_with("feedback-")) {
            assert!(
                n.contains("not"),
                "step or job named without saying it is no grade: {n}"
            );
        }
        assert!(!CLASSROOM_YML.to_lowercase().contains("autograding"));
    }
}
