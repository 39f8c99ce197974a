//! One scene rendered by both paths, the CPU rasterizer and wgpu (lavapipe on a machine without
//! a GPU), and compared pass by pass: coverage, colour and depth.
//!
//! `cargo run --release --features gpu --example gpu_compare -- assets/scenes/wuson.toml`

use std::path::PathBuf;

use stereolab::{Plan, Scene};
use stereolab_gpu::GpuRenderer;
use stereolab_gpu::parity::compare_scene;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or("assets/scenes/wuson.toml".into()),
    );
    // A small frame keeps the software Vulkan driver quick.
    let sets = [
        "image.width=256".to_string(),
        "image.height=192".to_string(),
    ];
    let scene = Scene::load(&path, &sets)?;
    let plan = Plan::new(&scene.outputs);
    let gpu = GpuRenderer::new()?;
    println!("{} on {}", path.display(), gpu.adapter_name());
    let rows = compare_scene(&gpu, &scene, &plan, None)?;
    println!(
        "{:<22} {:>10} {:>9} {:>8}",
        "pass", "coverage %", "max diff", "PSNR"
    );
    for row in &rows {
        let m = &row.metrics;
        println!(
            "{:<22} {:>10.4} {:>9} {:>8.1}",
            row.name,
            m.coverage_mismatch_percent(),
            m.max_channel_diff,
            m.psnr
        );
    }
    let worst = rows
        .iter()
        .map(|r| r.metrics.coverage_mismatch_percent())
        .fold(0.0, f64::max);
    // The paths follow the same rasterization rules: a few edge pixels may differ, no more.
    if worst > 0.5 {
        return Err(format!("coverage differs on {worst:.3}% of the pixels").into());
    }
    Ok(())
}
