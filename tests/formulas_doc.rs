//! `docs/formulas.md` names the tests that hold each formula; rustdoc checks its item links
//! (the table is `stereolab-core`'s crate page), this checks its test names.

use std::path::{Path, PathBuf};

use crate::common::root;

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() && !p.ends_with("target") {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The names in backticks of the table's last column that read as test names (snake case,
/// no path, no file name).
fn named_tests(table: &str) -> Vec<String> {
    let mut names = Vec::new();
    for row in table.lines().filter(|l| l.starts_with("| ")).skip(2) {
        let tests = row.trim_end_matches('|').rsplit(" | ").next().unwrap_or("");
        for (i, quoted) in tests.split('`').enumerate() {
            let is_name = quoted.len() > 3
                && quoted
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
            if i % 2 == 1 && is_name {
                names.push(quoted.to_string());
            }
        }
    }
    names
}

#[test]
fn every_test_the_formula_table_names_exists() {
    let table = std::fs::read_to_string(root().join("docs/formulas.md")).unwrap();
    let names = named_tests(&table);
    assert!(
        names.len() > 40,
        "only {} test names read from the table",
        names.len()
    );
    let mut files = Vec::new();
    for dir in ["tests", "crates", "exercises"] {
        rust_files(&root().join(dir), &mut files);
    }
    let code: String = files
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap())
        .collect();
    let missing: Vec<&String> = names
        .iter()
        .filter(|n| !code.contains(&format!("fn {n}(")))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/formulas.md names tests that do not exist: {missing:?}"
    );
}

#[test]
fn the_reader_takes_test_names_from_the_last_column_only() {
    let table = "| a | b | c | d |\n| --- | --- | --- | --- |\n\
                 | `x_y` | src | `math::frustum` | `holds_it`; unit `also_this`, `tests/f.rs` |\n";
    assert_eq!(named_tests(table), ["holds_it", "also_this"]);
}
