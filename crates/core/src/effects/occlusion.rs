//! The occlusion map: what each eye sees that the other cannot (the exercise slides, remapping plus the
//! visibility check), drawn as `left eye's map | right eye's map`.

use glam::Mat4;
use image::RgbaImage;
use rayon::prelude::*;

use super::remap::{Precision, Visibility, visibility_map};
use crate::error::Result;
use crate::framebuffer::Framebuffer;

/// Color of a pixel seen only by this eye because something nearer hides it from the other.
pub const OCCLUDED_COLOR: [u8; 4] = [230, 40, 40, 255];
/// Color of a pixel outside the other eye's image.
pub const OUT_OF_VIEW_COLOR: [u8; 4] = [40, 90, 230, 255];
/// Color of a sampling artifact at a silhouette ([`Visibility::Farther`]).
pub const FARTHER_COLOR: [u8; 4] = [230, 200, 40, 255];
/// Color of the background (nothing drawn).
pub const BACKGROUND_COLOR: [u8; 4] = [0, 0, 0, 255];

/// One pixel of the map: the class color, or for a point both eyes see a gray that is lighter
/// the nearer it is (`near_depth`..`far_depth` are this eye's window-depth extremes).
#[inline]
pub fn occlusion_pixel(v: Visibility, depth: f32, near_depth: f32, far_depth: f32) -> [u8; 4] {
    match v {
        Visibility::Background => BACKGROUND_COLOR,
        Visibility::Occluded => OCCLUDED_COLOR,
        Visibility::OutOfView => OUT_OF_VIEW_COLOR,
        Visibility::Farther => FARTHER_COLOR,
        Visibility::Visible => {
            let span = (far_depth - near_depth).max(f32::MIN_POSITIVE);
            let t = ((depth - near_depth) / span).clamp(0.0, 1.0);
            let g = (220.0 - 130.0 * t).round() as u8;
            [g, g, g, 255]
        }
    }
}

/// The nearest and farthest window depth of the drawn (depth < 1) pixels.
fn depth_extremes(fb: &Framebuffer) -> (f32, f32) {
    fb.depth
        .iter()
        .filter(|d| **d < 1.0)
        .fold((1.0f32, 0.0f32), |(lo, hi), d| (lo.min(*d), hi.max(*d)))
}

/// Both eyes' occlusion maps side by side (width 2W): left eye's pixels classified against the
/// right eye, then right against left. Red: occluded in the other eye; blue: outside the other
/// eye's image; yellow: silhouette sampling artifact; gray: seen by both; black: background.
/// Reads the two depth buffers only.
///
/// # Errors
/// Different sizes, or a singular MVP.
pub fn occlusion_image(
    left: &Framebuffer,
    right: &Framebuffer,
    mvps: [&Mat4; 2],
    precision: Precision,
) -> Result<RgbaImage> {
    let maps = [
        visibility_map(left, right, mvps[0], mvps[1], precision)?,
        visibility_map(right, left, mvps[1], mvps[0], precision)?,
    ];
    let (w, h) = (left.width, left.height);
    let extremes = [depth_extremes(left), depth_extremes(right)];
    let eyes = [left, right];
    let mut bytes = vec![0u8; 2 * 4 * w as usize * h as usize];
    let wu = w as usize;
    // Output rows in parallel: the left eye's row, then the right eye's.
    bytes
        .par_chunks_mut(2 * 4 * wu.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (k, half) in row.chunks_exact_mut(4 * wu).enumerate() {
                let (near, far) = extremes[k];
                for (x, out) in half.chunks_exact_mut(4).enumerate() {
                    let i = y * wu + x;
                    out.copy_from_slice(&occlusion_pixel(maps[k][i], eyes[k].depth[i], near, far));
                }
            }
        });
    let out = RgbaImage::from_raw(2 * w, h, bytes).expect("4 bytes per pixel");
    Ok(out)
}
