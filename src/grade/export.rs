//! `stereolab exercises export DIR`: the student handout — the exercise crates with their stubs,
//! tests and the stereolab library (with the grader and its assets), without the solutions.

use std::path::Path;

use crate::error::{Error, Result};

/// Lines between these markers (inclusive) are the instructor's and are dropped from the handout.
pub(crate) const SOLUTION_BEGIN: &str = "solution-begin";
/// See [`SOLUTION_BEGIN`].
pub(crate) const SOLUTION_END: &str = "solution-end";

/// Removes every `solution-begin` … `solution-end` block (marker lines included).
pub(crate) fn strip_solution(text: &str) -> String {
    let mut out = String::new();
    let mut skipping = false;
    for line in text.lines() {
        if line.contains(SOLUTION_BEGIN) {
            skipping = true;
        } else if line.contains(SOLUTION_END) {
            skipping = false;
        } else if !skipping {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

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

/// The handout's copy of stereolab's manifest: the same package, dependencies and profiles (so
/// a shared target folder reuses compiled dependencies), without the workspace and the
/// repository's own tests.
fn library_manifest(text: &str, path: &Path) -> Result<String> {
    let mut table: toml::Table =
        toml::from_str(text).map_err(|e| Error::parse(path, None, e.message().to_string()))?;
    table.remove("workspace");
    table.remove("test");
    table.remove("profile");
    toml::to_string(&table).map_err(|e| Error::parse(path, None, e.to_string()))
}

/// Writes the handout for the repository at `root` into `dir`:
/// `dir/Cargo.toml` (a workspace of the three exercises, with stereolab's profiles),
/// `dir/stereolab/` (library, CLI with the grader, docs, assets), `dir/ex*/` (stubs, student tests,
/// the grader's entry binary; no `solution.rs`, no `solution` feature), `dir/README.md`.
///
/// # Errors
/// Unreadable sources or an unwritable `dir`.
pub fn export(root: &Path, dir: &Path) -> Result<()> {
    let manifest_path = root.join("Cargo.toml");
    let manifest = std::fs::read_to_string(&manifest_path).map_err(io(&manifest_path))?;
    let lib = dir.join("stereolab");
    std::fs::create_dir_all(&lib).map_err(io(&lib))?;
    std::fs::write(
        lib.join("Cargo.toml"),
        library_manifest(&manifest, &manifest_path)?,
    )
    .map_err(io(&lib))?;
    copy_tree(&root.join("src"), &lib.join("src"), &|_| false)?;
    // The crate documentation includes docs/formulas.md, and the code cites the rest.
    copy_tree(&root.join("docs"), &lib.join("docs"), &|_| false)?;
    for asset in ["scenes", "models"] {
        copy_tree(
            &root.join("assets").join(asset),
            &lib.join("assets").join(asset),
            &|_| false,
        )?;
    }
    // The lock file twice: the handout's workspace resolves from it, and the grader compiles it
    // in (every build of a submission resolves from the same versions).
    for (from, to) in [
        (root.join("LICENSE"), lib.join("LICENSE")),
        (root.join("Cargo.lock"), dir.join("Cargo.lock")),
        (root.join("Cargo.lock"), lib.join("Cargo.lock")),
    ] {
        std::fs::copy(&from, &to).map_err(io(&from))?;
    }
    // The grader's templates (manifest, lib.rs, main.rs of each exercise) and exercise-api, the
    // one crate a student's crate depends on besides glam.
    copy_tree(
        &root.join("exercises/exercise-api"),
        &lib.join("exercises/exercise-api"),
        &|_| false,
    )?;
    let mut members = Vec::new();
    for ex in super::Exercise::ALL {
        let name = ex.crate_name();
        let from = root.join("exercises").join(name);
        for file in ["Cargo.toml", "src/lib.rs", "src/main.rs"] {
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
        members.push(format!("\"{name}\""));
    }
    let profiles = toml::from_str::<toml::Table>(&manifest)
        .ok()
        .and_then(|t| t.get("profile").cloned())
        .map(|p| {
            let mut t = toml::Table::new();
            t.insert("profile".into(), p);
            toml::to_string(&t).unwrap_or_default()
        })
        .unwrap_or_default();
    let workspace = format!(
        "[workspace]\nmembers = [{}, \"stereolab\"]\nresolver = \"3\"\n\n{profiles}",
        members.join(", ")
    );
    std::fs::write(dir.join("Cargo.toml"), workspace).map_err(io(dir))?;
    std::fs::write(dir.join("README.md"), HANDOUT_README).map_err(io(dir))?;
    Ok(())
}

const HANDOUT_README: &str = "# Stereo rendering exercises

Three exercises, one crate each: `ex1_stereo` (the exercise slides: stereo frusta, anaglyphs, remapping,
parallax), `ex2_chromadepth` (the ChromaDepth article), `ex3_sirds` (the SIRDS paper (Petz et al.)). Complete the `todo!`s in each
crate's `src/stubs.rs`; every stub's doc comment states the task, the formula's source and the
conventions (right-handed, NDC z in [-1, 1], eye index 0 = left).

```sh
cargo test -p ex1_stereo                                  # the worked examples
cargo run -p stereolab -- grade ex1                       # points, hints (or: all)
cargo run -p stereolab -- grade all --json results.json   # Gradescope's format
cargo run -p stereolab -- render --exercise ex1 stereolab/assets/scenes/wuson.toml --out out
```

Passing: at least 50% of all points and at least 2 points in each exercise.
";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strip_solution_drops_marked_blocks_with_their_markers() {
        let text = "a\n# solution-begin\n[features]\nsolution = []\n# solution-end\nb\n";
        assert_eq!(strip_solution(text), "a\nb\n");
    }
}
