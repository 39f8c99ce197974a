//! The README is for a first read: short, its links resolve, and its picture is what its
//! caption's command draws.

use std::path::Path;
use std::process::Command;

use crate::common::{out_dir, root};

/// The relative link targets of a Markdown text: `](target)` without a scheme or an anchor.
fn relative_links(text: &str) -> Vec<String> {
    text.split("](")
        .skip(1)
        .filter_map(|rest| rest.split(')').next())
        .map(|t| t.split('#').next().unwrap_or("").to_string())
        .filter(|t| !t.is_empty() && !t.contains("://"))
        .collect()
}

#[test]
fn the_readme_is_short_and_its_links_resolve() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = text.lines().count();
    assert!(
        lines <= 150,
        "README.md has {lines} lines; the details belong in docs/"
    );
    let links = relative_links(&text);
    assert!(
        links.len() > 10,
        "only {} links read: {links:?}",
        links.len()
    );
    let missing: Vec<&String> = links.iter().filter(|l| !root().join(l).exists()).collect();
    assert!(
        missing.is_empty(),
        "README.md links to missing files: {missing:?}"
    );
}

#[test]
fn the_readme_picture_is_what_its_caption_renders() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let caption = "`stereolab render assets/scenes/wuson.toml --size 480x360`";
    assert!(
        text.contains(caption),
        "the caption changed: update this test with it"
    );
    let out = out_dir("readme_picture");
    let run = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .current_dir(root())
        .args([
            "render",
            "assets/scenes/wuson.toml",
            "--size",
            "480x360",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let pixels = |p: &Path| image::open(p).expect("PNG").to_rgba8();
    let shown = pixels(&root().join("assets/readme/side_by_side.png"));
    let drawn = pixels(&out.join("side_by_side.png"));
    assert_eq!(shown.dimensions(), drawn.dimensions());
    let differ = shown
        .pixels()
        .zip(drawn.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differ,
        0,
        "assets/readme/side_by_side.png differs from its caption's render in {differ} pixels: \
         copy {} over it",
        out.join("side_by_side.png").display()
    );
}

#[test]
fn the_link_reader_skips_urls_and_anchors() {
    let text = "[a](docs/x.md#part) [b](https://example.org) ![c](assets/p.png)";
    assert_eq!(relative_links(text), ["docs/x.md", "assets/p.png"]);
}

/// `examples/` holds short complete programs (CI builds and runs them): each fits a screen.
#[test]
fn the_examples_are_short_programs() {
    let mut count = 0;
    for entry in std::fs::read_dir(root().join("examples"))
        .unwrap()
        .flatten()
    {
        let text = std::fs::read_to_string(entry.path()).unwrap();
        let lines = text.lines().count();
        assert!(
            lines <= 60,
            "{}: {lines} lines, more than 60",
            entry.path().display()
        );
        assert!(
            text.contains("fn main()"),
            "{}: no main",
            entry.path().display()
        );
        count += 1;
    }
    assert!(count >= 4, "only {count} examples");
}
