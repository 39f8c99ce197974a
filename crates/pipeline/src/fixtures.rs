//! Scenes and depth maps shared by the benchmarks, the tests and the GPU path: one definition
//! each, so a test and a benchmark row measure the same thing.

use std::path::Path;

use crate::scene::Scene;
use stereolab_core::{DepthMap, Result};

/// The SIRDS paper's Table 1: (width, height, triangles, k, frame rate in Hz on a GeForce4 Ti 4600).
pub const TABLE_1: [(u32, u32, u32, u32, f64); 6] = [
    (512, 512, 2_500, 10, 60.1),
    (512, 512, 5_000, 10, 40.2),
    (512, 512, 10_000, 10, 25.6),
    (1024, 512, 1_000, 20, 26.2),
    (1024, 512, 2_500, 20, 17.3),
    (1024, 512, 5_000, 20, 12.4),
];

/// A sphere over a ramp as a depth map: the ramp falls from `z = 0.5` at the left edge to 0 at
/// the right, the sphere (radius 0.35 of the shorter side, centered) rises to `z = 1`.
pub fn sphere_over_ramp(width: u32, height: u32) -> DepthMap {
    let (w, h) = (width as f32, height as f32);
    let radius = 0.35 * w.min(h);
    let z = (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ramp = 0.5 * (1.0 - (x as f32 + 0.5) / w);
            let (dx, dy) = (x as f32 + 0.5 - w * 0.5, y as f32 + 0.5 - h * 0.5);
            let r2 = (dx * dx + dy * dy) / (radius * radius);
            if r2 < 1.0 {
                ramp.max(0.5 + 0.5 * (1.0 - r2).sqrt())
            } else {
                ramp
            }
        })
        .collect();
    DepthMap { width, height, z }
}

/// A scene from TOML text (paths relative to the working folder).
///
/// # Errors
/// As [`Scene::from_toml`].
pub fn scene_from_text(text: &str) -> Result<Scene> {
    Scene::from_toml(text, Path::new("bench"), Path::new("."), &[])
}

/// The Table 1 scene: a height-field grid of exactly `triangles` triangles facing the camera.
pub fn table_scene(width: u32, height: u32, triangles: u32, k: u32) -> Result<Scene> {
    scene_from_text(&format!(
        r#"outputs = ["sirds"]
[image]
width = {width}
height = {height}
[camera]
eye = [0.0, 0.0, 2.8]
target = [0.0, 0.0, 0.0]
fov_y = 45.0
near = 1.0
far = 10.0
[sirds]
start = "left"
filter = "bilinear"
iterations = {k}
[[mesh]]
kind = "triangles"
count = {triangles}
"#
    ))
}
