//! Same scene, same bytes: every run, every thread count.

use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::Scene;

use crate::common::asset;

fn render_bytes(threads: usize) -> Vec<Vec<u8>> {
    let mut scene = Scene::load(&asset("scenes/wuson.toml"), &[]).unwrap();
    scene.set_size(256, 192).unwrap();
    let plan = Plan::new(&[Output::Left, Output::Right, Output::LeftDepth]);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let frame = pool.install(|| render(&scene, &plan)).unwrap();
    frame
        .passes
        .iter()
        .flat_map(|p| {
            let color: Vec<u8> = p.framebuffer.color().iter().flatten().copied().collect();
            let depth: Vec<u8> = p
                .framebuffer
                .depth()
                .iter()
                .flat_map(|d| d.to_le_bytes())
                .collect();
            [color, depth]
        })
        .collect()
}

#[test]
fn two_runs_and_one_vs_many_threads_give_identical_bytes() {
    let one = render_bytes(1);
    assert!(
        one[0].chunks(4).any(|p| p != [128, 128, 128, 255]),
        "the model must be visible"
    );
    assert_eq!(one, render_bytes(1), "second run differs");
    assert_eq!(one, render_bytes(2), "2 threads differ from 1");
    assert_eq!(one, render_bytes(4), "4 threads differ from 1");
}

/// SIRDS of a shipped scene (strip algorithm and TIW) under a pool of `threads` threads.
fn sirds_bytes(threads: usize) -> Vec<Vec<[u8; 4]>> {
    use stereolab::output::sirds::from_frame;
    use stereolab_core::SirdsAlgorithm;
    let mut scene = Scene::load(&asset("scenes/sirds_sphere.toml"), &[]).unwrap();
    scene.set_size(300, 150).unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let frame = render(&scene, &Plan::new(&[Output::Sirds])).unwrap();
        [SirdsAlgorithm::PerVertex, SirdsAlgorithm::PerPixel]
            .into_iter()
            .map(|a| {
                let mut s = scene.clone();
                s.sirds.algorithm = a;
                from_frame(&frame, &s).unwrap().pixels
            })
            .collect()
    })
}

#[test]
fn sirds_bytes_do_not_depend_on_the_thread_count() {
    let one = sirds_bytes(1);
    assert_ne!(
        one[0], one[1],
        "the two algorithms should not agree byte for byte"
    );
    assert_eq!(one, sirds_bytes(2), "2 threads differ from 1");
    assert_eq!(one, sirds_bytes(3), "3 threads differ from 1");
    assert_eq!(one, sirds_bytes(4), "4 threads differ from 1");
}

/// The AVX2 loops change the speed only: the whole `render` of both SIRDS scenes (strips,
/// depth pass, depth map) writes the same PNG bytes with them as with `STEREOLAB_SCALAR=1`.
/// Each scene is also rendered with the other filter, so nearest and bilinear both run.
#[test]
fn scalar_and_avx2_loops_write_the_same_files() {
    if !stereolab_core::avx2_available() {
        eprintln!("scalar_and_avx2_loops_write_the_same_files: NOT RUN: no AVX2 here");
        return;
    }
    let run = |scene: &str, filter: &str, scalar: bool| {
        let dir = crate::common::out_dir(&format!("simd-{scene}-{filter}-{scalar}"));
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .args([
                "render",
                &asset(&format!("scenes/{scene}.toml")).to_string_lossy(),
            ])
            .args([
                "--out",
                &dir.to_string_lossy(),
                "--set",
                &format!("sirds.filter=\"{filter}\""),
            ])
            .env("STEREOLAB_SCALAR", if scalar { "1" } else { "0" })
            .output()
            .expect("run stereolab");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .expect("output folder")
            .map(|e| e.expect("entry").path())
            .collect();
        files.sort();
        assert!(
            files.len() >= 2,
            "{scene}: expected sirds and sirds_depth, got {files:?}"
        );
        files
            .iter()
            .map(|f| {
                (
                    f.file_name().map(|n| n.to_owned()),
                    std::fs::read(f).expect("read"),
                )
            })
            .collect::<Vec<_>>()
    };
    for scene in ["sirds_sphere", "sirds_ramp"] {
        for filter in ["nearest", "bilinear"] {
            assert!(
                run(scene, filter, false) == run(scene, filter, true),
                "{scene} {filter}: the scalar and AVX2 loops wrote different files"
            );
        }
    }
}

/// The finalize passes fill their rows in parallel tasks: each image's bytes on 1, 2 and 3
/// threads (an anaglyph of every matrix shape's loop, the remap and the parallax map).
#[test]
fn finalize_images_do_not_depend_on_the_thread_count() {
    use stereolab::output::{Image, produce};
    use stereolab_core::AnaglyphKind;
    let mut scene = Scene::load(&asset("scenes/wuson.toml"), &[]).unwrap();
    scene.set_size(203, 150).unwrap();
    let outputs = [
        Output::Anaglyph(AnaglyphKind::DuboisRedCyan),
        Output::Anaglyph(AnaglyphKind::Optimized),
        Output::Anaglyph(AnaglyphKind::Gray),
        Output::RemapLeft,
        Output::Parallax,
    ];
    let images = |threads: usize| -> Vec<Vec<u8>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let frame = render(&scene, &Plan::new(&outputs)).unwrap();
            outputs
                .iter()
                .map(|&o| match produce(o, &frame, &scene).unwrap() {
                    Image::Rgba(img) => img.into_raw(),
                    _ => panic!("{o:?}: not an RGBA image"),
                })
                .collect()
        })
    };
    let one = images(1);
    assert!(
        one[0]
            .chunks(4)
            .collect::<std::collections::HashSet<_>>()
            .len()
            > 100,
        "the anaglyph should show the model"
    );
    assert_eq!(one, images(2), "2 threads differ from 1");
    assert_eq!(one, images(3), "3 threads differ from 1");
}
