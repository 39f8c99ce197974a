//! The bytes of every shipped scene's outputs, held by their hashes: a refactor that changes
//! no behaviour leaves `tests/data/scene_hashes.txt` as it is.
//!
//! Each scene in `assets/scenes/` renders its own outputs at its own size, and then every
//! output stereolab has at 160×120 (so each effect's path is covered by every scene). The hash
//! is FNV-1a 64 over the image's size and raw pixel bytes (not the PNG encoding, which belongs
//! to the image crate). Regenerate only on purpose: `UPDATE_HASHES=1 cargo test scene_hashes`.

use std::fmt::Write as _;

use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;

use crate::common::{asset, root};

/// FNV-1a, 64 bits: small, fixed, and the same on every machine.
fn fnv1a(bytes: impl IntoIterator<Item = u8>, mut h: u64) -> u64 {
    for b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

fn image_hash(img: &Image) -> (u32, u32, u64) {
    let seed = 0xcbf2_9ce4_8422_2325;
    match img {
        Image::Rgba(i) => (
            i.width(),
            i.height(),
            fnv1a(i.as_raw().iter().copied(), seed),
        ),
        Image::Gray16(i) | Image::WindowDepth(i) => (
            i.width(),
            i.height(),
            fnv1a(i.as_raw().iter().flat_map(|v| v.to_le_bytes()), seed),
        ),
        // The pixels of both views (not the JPEG encoding, which belongs to the image crate).
        Image::Stereo(p) => (
            p.left.width(),
            p.left.height(),
            fnv1a(
                p.left.as_raw().iter().chain(p.right.as_raw()).copied(),
                seed,
            ),
        ),
        // The pixels of every field in order, then each field's delay.
        Image::Sequence(s) => (
            s.left.width(),
            s.left.height(),
            fnv1a(
                s.fields.iter().flat_map(|f| {
                    let delay = [f.delay_num.to_le_bytes(), f.delay_den.to_le_bytes()];
                    s.image(f)
                        .as_raw()
                        .iter()
                        .copied()
                        .chain(delay.into_iter().flatten())
                }),
                seed,
            ),
        ),
    }
}

fn hash_lines(scene_name: &str, scene: &Scene, outputs: &[Output], lines: &mut String) {
    let frame = render(scene, &Plan::new(outputs)).unwrap();
    for &o in outputs {
        let (w, h, hash) = image_hash(&produce(o, &frame, scene).unwrap());
        writeln!(lines, "{scene_name} {} {w}x{h} {hash:016x}", o.name()).unwrap();
    }
}

fn all_hashes() -> String {
    let mut names: Vec<_> = std::fs::read_dir(asset("scenes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    let mut lines = String::new();
    for path in names {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let scene = Scene::load(&path, &[]).unwrap();
        hash_lines(&name, &scene, &scene.outputs.clone(), &mut lines);
        let mut small = scene.clone();
        small.set_size(160, 120).unwrap();
        hash_lines(&format!("{name}@160x120"), &small, Output::ALL, &mut lines);
    }
    lines
}

#[test]
fn every_shipped_scene_renders_the_recorded_bytes() {
    let file = root().join("tests/data/scene_hashes.txt");
    let now = all_hashes();
    if std::env::var_os("UPDATE_HASHES").is_some() {
        std::fs::write(&file, &now).unwrap();
        return;
    }
    let recorded = std::fs::read_to_string(&file).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run with UPDATE_HASHES=1 to create)",
            file.display()
        )
    });
    let differ: Vec<String> = recorded
        .lines()
        .zip(now.lines())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| format!("recorded {a}\n     now {b}"))
        .collect();
    assert!(
        differ.is_empty() && recorded.lines().count() == now.lines().count(),
        "{} of {} outputs changed bytes:\n{}",
        differ.len(),
        recorded.lines().count(),
        differ.join("\n")
    );
}
