//! The instructor's solution (feature `solution`). Never part of the student handout.
//!
//! `STEREOLAB_MUTANT=name[,name]` plants a known mistake for the grader's mutation tests:
//! `reversed-ramp`, `full-circle-ramp` (hue to 360°), `texgen-sign`.

use glam::Vec3;

fn planted(mistake: &str) -> bool {
    std::env::var("STEREOLAB_MUTANT").is_ok_and(|v| v.split(',').any(|m| m == mistake))
}

/// HSV ramp, hue 240° · t.
pub fn hsv_ramp(t: f32) -> [f32; 3] {
    let t = t.clamp(0.0, 1.0);
    let t = if planted("reversed-ramp") { 1.0 - t } else { t };
    let end = if planted("full-circle-ramp") {
        360.0
    } else {
        240.0
    };
    let h = end * t / 60.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    match h as u32 {
        0 => [1.0, x, 0.0],
        1 => [x, 1.0, 0.0],
        2 => [0.0, 1.0, x],
        3 => [0.0, x, 1.0],
        4 => [x, 0.0, 1.0],
        _ => [1.0, 0.0, x],
    }
}

/// The ChromaDepth article's texgen coefficients.
pub fn texgen(d1: f32, d2: f32) -> [f32; 4] {
    let c = -1.0 / (d2 - d1);
    let c = if planted("texgen-sign") { -c } else { c };
    [0.0, 0.0, c, -d1 / (d2 - d1)]
}

/// D1, D2 from a bounding sphere.
pub fn depth_range(center: Vec3, radius: f32) -> [f32; 2] {
    [-center.z - radius, -center.z + radius]
}
