//! Single-image random-dot stereograms (SIRDS).
//!
//! Seed 002 (Petz, Goldlücke, Magnor, "Hardware-accelerated autostereogram rendering") is the
//! specification; its reference 5 (Thimbleby, Inglis, Witten 1994, "TIW") is the classic
//! per-pixel algorithm. A SIRDS needs one depth-only pass of the cyclopean view and no color
//! shading (`plan.rs`: `sirds` → `Center`, `DepthOnly`).
//!
//! - [`disparity`]: eq. 1 and eq. 3, physical units → pixels in one place;
//! - [`depthmap`]: nearness per pixel from the depth pass or an image file;
//! - [`per_vertex`]: seed 002's strip algorithm on stereolab's rasterizer;
//! - [`per_pixel`]: TIW with hidden-surface removal and oversampling;
//! - [`pattern`]: random dots, pattern images, guide dots;
//! - [`decode`]: separation (and depth) back from a finished image;
//! - [`animate`]: a rotating model as an animated GIF.

pub mod animate;
pub mod bench;
pub mod cli;
pub mod decode;
pub mod depthmap;
pub mod disparity;
pub mod pattern;
pub mod per_pixel;
pub mod per_vertex;
pub mod settings;

pub use depthmap::{DepthMap, DepthRange};
pub use disparity::{Disparity, DisparityModel, Geometry};
pub use pattern::Pattern;
pub use settings::{Algorithm, Settings, SirdsSpec};

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;
use crate::plan::View;
use crate::render::Frame;
use crate::scene::Scene;

/// A finished autostereogram and what it encodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Sirds {
    /// Row-major RGBA pixels.
    pub pixels: Vec<[u8; 4]>,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// The scene's nearness (before any cross-eyed inversion).
    pub depth: DepthMap,
    /// The set-up in pixels.
    pub disparity: Disparity,
    /// Strip iterations run (per-vertex only).
    pub iterations: Option<u32>,
}

impl Sirds {
    /// The image as RGBA.
    pub fn to_rgba_image(&self) -> image::RgbaImage {
        let bytes = self.pixels.iter().flatten().copied().collect();
        image::RgbaImage::from_raw(self.width, self.height, bytes).expect("buffer size matches")
    }
}

/// The depth range for a depth buffer: the scene's fixed `front`/`back` where given, the
/// buffer's own span ([`DepthMap::auto_range`]) otherwise.
///
/// # Errors
/// An invalid range, or a background plane at or beyond the far clip plane.
pub fn depth_range(
    settings: &Settings,
    fb: &Framebuffer,
    near: f32,
    far: f32,
) -> Result<DepthRange> {
    let auto = DepthMap::auto_range(fb, near, far).unwrap_or(DepthRange {
        front: near,
        back: far * 0.999,
    });
    let range = DepthRange {
        front: settings.front.unwrap_or(auto.front),
        back: settings.back.unwrap_or(auto.back),
    };
    range.validate()?;
    if range.back >= far {
        return Err(Error::invalid(
            "sirds.back",
            range.back,
            format!("the background plane must lie before camera.far ({far})"),
        ));
    }
    Ok(range)
}

/// The cyclopean depth pass of `frame`.
fn depth_pass(frame: &Frame) -> Result<&Framebuffer> {
    frame.view(View::Center).ok_or_else(|| {
        Error::internal(
            "plan",
            "sirds: the Center depth pass was not run (a SIRDS needs it)",
        )
    })
}

/// The depth map a SIRDS of `frame` encodes (output `sirds_depth`).
///
/// # Errors
/// No center pass in the frame, or an invalid depth range.
pub fn scene_depth(frame: &Frame, scene: &Scene) -> Result<(DepthMap, DepthRange)> {
    let fb = depth_pass(frame)?;
    let (near, far) = (scene.camera.near, scene.camera.far);
    let range = depth_range(&scene.sirds, fb, near, far)?;
    Ok((DepthMap::from_framebuffer(fb, near, far, &range), range))
}

/// Makes the scene's SIRDS from its depth pass (output `sirds`) with the algorithm the scene
/// chose; adds guide dots if asked.
///
/// # Errors
/// As [`scene_depth`], [`per_pixel::per_pixel`] and [`per_vertex::per_vertex`].
pub fn from_frame(frame: &Frame, scene: &Scene) -> Result<Sirds> {
    let s = &scene.sirds;
    from_frame_with(frame, scene, |g, d| {
        per_vertex::per_vertex(
            g,
            scene.width,
            scene.height,
            d,
            &s.pattern,
            &s.per_vertex,
            false,
        )
    })
}

/// [`from_frame`] with the per-vertex strips made by `strips` from the strip geometry and the
/// disparity (the CPU's [`per_vertex::per_vertex`], or the GPU's ping-pong); everything else
/// (depth range, TIW, guide dots) is the same for both.
///
/// # Errors
/// As [`from_frame`], and whatever `strips` returns.
pub fn from_frame_with(
    frame: &Frame,
    scene: &Scene,
    strips: impl FnOnce(&per_vertex::StripGeometry, &Disparity) -> Result<per_vertex::StripResult>,
) -> Result<Sirds> {
    let s = &scene.sirds;
    let (depth, range) = scene_depth(frame, scene)?;
    let d = s.geometry.to_pixels()?;
    let (mut pixels, iterations) = match s.algorithm {
        Algorithm::PerPixel => {
            let encoded = if s.cross_eyed {
                depth.inverted()
            } else {
                depth.clone()
            };
            (
                per_pixel::per_pixel(&encoded, &d, &s.pattern, &s.per_pixel)?,
                None,
            )
        }
        Algorithm::PerVertex => {
            let g = per_vertex::StripGeometry::new(scene, &frame.center, &range, &d, s.cross_eyed);
            let r = strips(&g, &d)?;
            (r.pixels, Some(r.iterations))
        }
    };
    if s.guide_dots {
        pattern::draw_guide_dots(&mut pixels, scene.width, scene.height, d.max_separation());
    }
    Ok(Sirds {
        pixels,
        width: scene.width,
        height: scene.height,
        depth,
        disparity: d,
        iterations,
    })
}

/// Makes a SIRDS of a depth map with TIW's algorithm (`stereolab sirds --depth`).
///
/// # Errors
/// As [`per_pixel::per_pixel`].
pub fn from_depth_map(depth: DepthMap, s: &Settings) -> Result<Sirds> {
    let d = s.geometry.to_pixels()?;
    let mut pixels = if s.cross_eyed {
        per_pixel::per_pixel(&depth.inverted(), &d, &s.pattern, &s.per_pixel)?
    } else {
        per_pixel::per_pixel(&depth, &d, &s.pattern, &s.per_pixel)?
    };
    if s.guide_dots {
        pattern::draw_guide_dots(&mut pixels, depth.width, depth.height, d.max_separation());
    }
    Ok(Sirds {
        pixels,
        width: depth.width,
        height: depth.height,
        depth,
        disparity: d,
        iterations: None,
    })
}
