//! A rotating model as an animated SIRDS GIF (the SIRDS paper's §5: animated SIRDS stay fusable, and a
//! pattern that changes every frame keeps the eyes on the object rather than the dots).

use std::path::Path;

use glam::{Mat4, Vec3};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame};

use super::sirds::from_frame;
use crate::plan::{Output, Plan};
use crate::render::render;
use crate::scene::Scene;
use stereolab_core::{Error, Result, SirdsPattern, image_error, write_atomic};

/// The most frames an animation may have: every frame is a full render and a GIF frame, and the
/// count is a number on the command line (a typo of 100000 would run for hours and fill a disk).
pub const MAX_FRAMES: u32 = 720;

/// Animation settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnimationOptions {
    /// Number of frames (one full turn).
    pub frames: u32,
    /// Keep the scene's seed in every frame; otherwise frame `i` uses seed + i.
    pub fixed_seed: bool,
    /// Milliseconds per frame.
    pub delay_ms: u32,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        AnimationOptions {
            frames: 36,
            fixed_seed: false,
            delay_ms: 80,
        }
    }
}

/// Renders `opts.frames` SIRDS of `scene` turning once about the vertical axis through its
/// bounding-box center and writes them to `path` as a looping GIF. The depth range comes from
/// the bounding sphere (unless the scene fixes it), so it stays the same in every frame.
/// `on_frame(done, total)` is called after each frame (the CLI draws its progress bar there).
///
/// # Errors
/// No frames, an empty scene, a render error, or the file cannot be written.
pub fn animate(
    scene: &Scene,
    opts: &AnimationOptions,
    path: &Path,
    mut on_frame: impl FnMut(u32, u32),
) -> Result<()> {
    if opts.frames == 0 || opts.frames > MAX_FRAMES {
        return Err(Error::invalid(
            "--frames",
            opts.frames,
            format!("must be 1 to {MAX_FRAMES} (two frames per degree of the turn)"),
        ));
    }
    let points: Vec<Vec3> = scene.world_points().collect();
    if points.is_empty() {
        return Err(Error::invalid("mesh", "none", "an animation needs a model"));
    }
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(a, b), p| (a.min(*p), b.max(*p)),
    );
    let pivot = (lo + hi) * 0.5;
    let radius = points.iter().map(|p| p.distance(pivot)).fold(0.0, f32::max);
    let distance = -scene.camera.view().transform_point3(pivot).z;
    let (near, far) = (scene.camera.near, scene.camera.far);
    let mut s = scene.clone();
    s.sirds.front = Some(
        s.sirds
            .front
            .unwrap_or((distance - radius).max(near * 1.01)),
    );
    s.sirds.back = Some(
        s.sirds
            .back
            .unwrap_or((distance + 1.1 * radius).min(far * 0.99)),
    );
    let models: Vec<Mat4> = scene.objects.iter().map(|o| o.model).collect();
    let plan = Plan::new(&[Output::Sirds]);
    let seed_pattern = scene.sirds.pattern.clone();
    // The frames stream into a temporary file renamed onto `path` only once the last one is in:
    // a failed or killed run never leaves a truncated GIF.
    write_atomic(path, |w| {
        let gif_error = |e| image_error(path, e);
        let mut gif = GifEncoder::new_with_speed(w, 10);
        gif.set_repeat(Repeat::Infinite).map_err(gif_error)?;
        let mut frame_of = |i: u32| -> Result<Frame> {
            let angle = std::f32::consts::TAU * i as f32 / opts.frames as f32;
            let turn = Mat4::from_translation(pivot)
                * Mat4::from_rotation_y(angle)
                * Mat4::from_translation(-pivot);
            for (o, m) in s.objects.iter_mut().zip(&models) {
                o.model = turn * *m;
            }
            if !opts.fixed_seed {
                let seed = match &seed_pattern {
                    SirdsPattern::BlackWhite { seed }
                    | SirdsPattern::Gray { seed }
                    | SirdsPattern::Color { seed } => seed.wrapping_add(i as u64),
                    SirdsPattern::Image(_) | SirdsPattern::Textured(_) => 0,
                };
                s.sirds.pattern = seed_pattern.reseeded(seed);
            }
            let sirds = from_frame(&render(&s, &plan)?, &s)?;
            let delay = Delay::from_numer_denom_ms(opts.delay_ms, 1);
            Ok(Frame::from_parts(sirds.to_rgba_image(), 0, 0, delay))
        };
        for i in 0..opts.frames {
            gif.encode_frame(frame_of(i)?).map_err(gif_error)?;
            on_frame(i + 1, opts.frames);
        }
        Ok(())
    })
}
