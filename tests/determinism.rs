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
            let color: Vec<u8> = p.framebuffer.color.iter().flatten().copied().collect();
            let depth: Vec<u8> = p
                .framebuffer
                .depth
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
