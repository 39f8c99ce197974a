//! Dependencies point one way inside each library crate too. Cargo keeps the crates apart
//! (`stereolab-core` ← `stereolab` ← the tool crates ← the command); what it cannot see is the
//! order of the modules inside one crate. This test reads each crate's source: the import graph
//! of its top-level modules has no cycle, and every edge goes down the crate's layers.
//!
//! `cargo test --test main architecture -- --nocapture` prints the graphs.
//!
//! `stereolab-core`, lowest first:
//! - `error`: the one error type.
//! - `files`, `eye`, `simd`: bounded reads and all-or-nothing writes; which eye (left or
//!   right); the one question to the CPU about its vector instructions.
//! - `math`, `framebuffer`, `shade`, `text`: matrices and the rig, the render target (and the
//!   image sizes it accepts), the shader stages, text in pictures.
//! - `raster`, `reference`: fixed-point setup and traversal (knows nothing of scenes or
//!   stereo); the f64 reference the hard cases are measured against.
//! - `effects`: pure functions of framebuffers, matrices and their own settings types.
//!
//! `stereolab` (the pipeline), lowest first:
//! - `plan`: the outputs a scene can ask for, and the passes each needs.
//! - `scene`: the scene file, meshes, camera and rig, with every effect's settings.
//! - `fixtures`: scenes and depth maps shared by tests, benchmarks and the GPU path.
//! - `render`: the passes (eye passes, the ChromaDepth pass, the SIRDS strips) over a scene.
//! - `output`: a rendered frame into the images the scene asked for, and files.
//! - `info`, `inspect`, `compare`: reports, other programs' stereo pictures, image metrics.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::common::root;

/// Each layered crate's source folder and its layers, lowest first.
const CRATES: &[(&str, &[&[&str]])] = &[
    (
        "crates/core/src",
        &[
            &["error"],
            &["files", "eye", "simd"],
            &["math", "framebuffer", "shade", "text"],
            &["raster", "reference"],
            &["effects"],
        ],
    ),
    (
        "crates/pipeline/src",
        &[
            &["plan"],
            &["scene"],
            &["fixtures"],
            &["render"],
            &["output"],
            &["info", "inspect", "compare", "memory"],
        ],
    ),
];

fn layer_of(layers: &[&[&str]], module: &str) -> Option<usize> {
    layers.iter().position(|l| l.contains(&module))
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The module path of a file under `src/`: `effects/sirds/mod.rs` → `[effects, sirds]`.
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|c| c.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs");
    if stem != "mod" {
        parts.push(stem.to_string());
    }
    parts
}

/// The source without comments (line comments, doc comments and block comments), so a doc
/// link or a remark about another module is not an import.
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let (mut i, mut in_str) = (0, false);
    while i < b.len() {
        if in_str {
            if b[i] == b'\\' {
                i += 2;
                continue;
            }
            if b[i] == b'"' {
                in_str = false;
            }
            out.push(b[i] as char);
            i += 1;
        } else if b[i] == b'"' {
            in_str = true;
            out.push('"');
            i += 1;
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2);
            i = end;
        } else {
            out.push(b[i] as char);
            i += 1;
        }
    }
    out
}

/// The top-level modules a file names: `crate::x`, `crate::{x, y::z}`, and `super::…` chains
/// that climb to the crate root.
fn referenced(code: &str, path: &[String]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    for (i, _) in code.match_indices("crate::") {
        if i > 0 && code.as_bytes()[i - 1].is_ascii_alphanumeric() {
            continue; // e.g. `stereolab_crate::`
        }
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            // Top-level names of a `use crate::{a, b::c, d::{e, f}}` group.
            let (mut depth, mut start) = (0, true);
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        out.insert(ident(&group[j..]));
                        start = false;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident(rest));
        }
    }
    for (i, _) in code.match_indices("super::") {
        if i >= 2 && &code[i - 2..i] == "::" {
            continue; // counted with the chain's first `super::`
        }
        let mut rest = &code[i..];
        let mut up = 0;
        while let Some(r) = rest.strip_prefix("super::") {
            up += 1;
            rest = r;
        }
        if up == path.len() {
            out.insert(ident(rest));
        }
    }
    out
}

/// The import graph of the crate whose source is `src`: top-level module → the other
/// top-level modules it names.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in rust_files(src) {
        let rel = file.strip_prefix(src).unwrap();
        if rel == Path::new("lib.rs") {
            continue; // it declares the modules
        }
        let path = module_path(rel);
        let top = path[0].clone();
        let code = strip_comments(&std::fs::read_to_string(&file).unwrap());
        let refs = referenced(&code, &path);
        let entry = g.entry(top.clone()).or_default();
        entry.extend(refs.into_iter().filter(|r| *r != top));
    }
    let modules: BTreeSet<String> = g.keys().cloned().collect();
    for deps in g.values_mut() {
        deps.retain(|d| modules.contains(d));
    }
    g
}

/// A cycle of the graph, if it has one (depth-first search).
fn find_cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        g: &BTreeMap<String, BTreeSet<String>>,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = stack.iter().position(|s| s == n) {
            let mut cycle = stack[at..].to_vec();
            cycle.push(n.to_string());
            return Some(cycle);
        }
        if done.contains(n) {
            return None;
        }
        stack.push(n.to_string());
        for d in &g[n] {
            if let Some(c) = visit(d, g, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|n| visit(n, g, &mut Vec::new(), &mut done))
}

#[test]
fn top_level_modules_import_each_other_one_way_only() {
    for (dir, layers) in CRATES {
        let g = graph(&root().join(dir));
        println!("import graph of {dir} (module -> what it imports):");
        for (m, deps) in &g {
            let deps: Vec<&str> = deps.iter().map(String::as_str).collect();
            println!("  {m:<12} -> {}", deps.join(", "));
        }
        let declared: usize = layers.iter().map(|l| l.len()).sum();
        assert_eq!(
            g.len(),
            declared,
            "{dir}: the graph reader found {:?}, the layers name {declared} modules",
            g.keys()
        );
        if let Some(cycle) = find_cycle(&g) {
            panic!("{dir}: import cycle: {}", cycle.join(" -> "));
        }
        let mut upward = Vec::new();
        for (m, deps) in &g {
            let Some(lm) = layer_of(layers, m) else {
                panic!(
                    "{dir}: module `{m}` has no layer: add it to CRATES in tests/architecture.rs"
                );
            };
            for d in deps {
                let ld = layer_of(layers, d).unwrap_or(usize::MAX);
                if ld >= lm {
                    upward.push(format!("{m} (layer {lm}) imports {d} (layer {ld})"));
                }
            }
        }
        assert!(
            upward.is_empty(),
            "{dir}: imports against the layers:\n{}",
            upward.join("\n")
        );
    }
}

#[test]
fn the_reader_sees_grouped_nested_and_super_imports() {
    let code = strip_comments(
        "use crate::{a, b::c, d::{e, f}};\n// crate::commented\nlet x = crate::g::h();\n\
         use super::super::i::J; \"crate::in_string\"",
    );
    let got = referenced(&code, &["top".into(), "inner".into()]);
    let want: BTreeSet<String> = ["a", "b", "d", "g", "i", "in_string"]
        .into_iter()
        .map(String::from)
        .collect();
    assert_eq!(got, want);
    let mut g = BTreeMap::new();
    g.insert("a".to_string(), BTreeSet::from(["b".to_string()]));
    g.insert("b".to_string(), BTreeSet::from(["a".to_string()]));
    assert!(find_cycle(&g).is_some(), "a two-module cycle must be found");
}
