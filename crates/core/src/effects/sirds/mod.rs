//! Single-image random-dot stereograms (SIRDS).
//!
//! The SIRDS paper (Petz, Goldlücke, Magnor, "Hardware-accelerated autostereogram rendering") is the
//! specification; its reference 5 (Thimbleby, Inglis, Witten 1994, "TIW") is the classic
//! per-pixel algorithm. A SIRDS needs one depth-only pass of the cyclopean view and no color
//! shading (`plan.rs`: `sirds` → `Center`, `DepthOnly`).
//!
//! - [`disparity`]: eq. 1 and eq. 3, physical units → pixels in one place;
//! - [`depthmap`]: nearness per pixel from the depth pass or an image file;
//! - [`strips`]: the SIRDS paper's strip algorithm on stereolab's rasterizer;
//! - [`per_pixel`]: TIW with hidden-surface removal and oversampling;
//! - [`pattern`]: random dots, pattern images, guide dots;
//! - [`decode`]: separation (and depth) back from a finished image;
//! - a rotating model as an animated GIF: `output::animate` (the `stereolab` crate).

pub mod decode;
pub mod depthfile;
pub mod depthmap;
pub mod disparity;
pub mod pair;
pub mod pattern;
pub mod per_pixel;
pub mod search;
pub mod settings;
pub mod strips;

pub use depthmap::{DepthMap, DepthRange};
pub use disparity::{Disparity, DisparityModel, Geometry};
pub use pattern::Pattern;
pub use settings::{Algorithm, Filter, PerVertexOptions, Settings, SirdsSpec, Start};

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

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

/// Makes a SIRDS of a depth map with TIW's algorithm (`stereolab sirds --depth`).
///
/// # Errors
/// As [`per_pixel::per_pixel`] and [`pattern::draw_guide_boxes`].
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
    if let Some(boxes) = s.guide_boxes {
        let (w, h) = (depth.width, depth.height);
        pattern::draw_guide_boxes(&mut pixels, w, h, d.max_separation(), boxes)?;
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
