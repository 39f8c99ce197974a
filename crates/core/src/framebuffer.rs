//! Color + depth render targets, and the pair of eye framebuffers.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::eye::Eye;

/// Largest image side we accept.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// Largest pixel count we accept (8192², 512 MiB of color + depth per framebuffer): checked
/// before anything is allocated, so an absurd size never asks for gigabytes.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

/// Largest side of an image file a command writes: two eye images beside each other
/// (`side_by_side` of the widest framebuffer). What `compare` reads.
pub const MAX_OUTPUT_SIDE: u32 = 2 * MAX_IMAGE_SIDE;

/// Largest pixel count of an image file a command writes, with room to spare: two eye images
/// and the rows between them (`above_below` of the largest framebuffer is twice its pixels).
pub const MAX_OUTPUT_PIXELS: u64 = 3 * MAX_IMAGE_PIXELS;

/// An RGBA8 color buffer and an f32 depth buffer in [0, 1] (1 = far plane), row 0 at the top.
///
/// Valid by construction: its size is one [`check_size`] accepts (or, for buffers read from
/// a file an output was written to, [`check_output_size`]), both buffers hold
/// `width × height` values, and every depth is a window depth in [0, 1]. [`Framebuffer::new`]
/// clears one, the rasterizer draws into it, [`Framebuffer::from_buffers`] checks buffers from
/// elsewhere (files, the GPU's readback); nothing downstream checks them again.
#[derive(Clone, Debug, PartialEq)]
pub struct Framebuffer {
    /// Width in pixels.
    pub(crate) width: u32,
    /// Height in pixels.
    pub(crate) height: u32,
    /// Row-major RGBA8 pixels, row 0 at the top.
    pub(crate) color: Vec<[u8; 4]>,
    /// Row-major window depth, `glDepthRange(0, 1)`.
    pub(crate) depth: Vec<f32>,
}

/// The stereo draw buffers of a quad-buffered OpenGL context, by the names the SGI course notes
/// (`glDrawBuffer(GL_BACK_LEFT)` … `glDrawBuffer(GL_BACK_RIGHT)`, §4.1.2) and the StereoGraphics
/// guide (§3–4: "you can specify your drawing buffer as GL_BACK_LEFT or GL_BACK_RIGHT, which will
/// result in subsequent OpenGL drawings and renderings appearing only in one eye's drawing
/// buffer") use. stereolab's eye framebuffers are these two buffers: `Frame::draw_buffer` in
/// `render` returns them by these names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DrawBuffer {
    /// `GL_BACK_LEFT`: the left eye's back buffer ([`Eye::Left`]).
    BackLeft,
    /// `GL_BACK_RIGHT`: the right eye's back buffer ([`Eye::Right`]).
    BackRight,
}

/// `GL_BACK_LEFT`, the left eye's back buffer.
pub const BACK_LEFT: DrawBuffer = DrawBuffer::BackLeft;
/// `GL_BACK_RIGHT`, the right eye's back buffer.
pub const BACK_RIGHT: DrawBuffer = DrawBuffer::BackRight;

impl DrawBuffer {
    /// The eye whose buffer this is.
    pub fn eye(self) -> Eye {
        match self {
            DrawBuffer::BackLeft => Eye::Left,
            DrawBuffer::BackRight => Eye::Right,
        }
    }

    /// The OpenGL name, as the documents write it.
    pub fn gl_name(self) -> &'static str {
        match self {
            DrawBuffer::BackLeft => "GL_BACK_LEFT",
            DrawBuffer::BackRight => "GL_BACK_RIGHT",
        }
    }
}

/// The two eye framebuffers, indexed by [`Eye::index`]: 0 left, 1 right as in the exercise
/// slides.
pub type EyePair = [Framebuffer; 2];

impl Framebuffer {
    /// A framebuffer cleared to `clear_color` and depth 1.0.
    ///
    /// # Errors
    /// A zero side, or a side above [`MAX_IMAGE_SIDE`].
    pub fn new(width: u32, height: u32, clear_color: [u8; 4]) -> Result<Self> {
        check_size(width, height)?;
        let n = width as usize * height as usize;
        // Filled in parallel, each thread a run of whole rows in both buffers, the halves a
        // rasterizer's bands are then likely to split the same way (the thread that draws a
        // band finds it in its own cache).
        let (mut color, mut depth) = (Vec::with_capacity(n), Vec::with_capacity(n));
        rayon::iter::repeat_n((clear_color, 1.0f32), n).unzip_into_vecs(&mut color, &mut depth);
        Ok(Framebuffer {
            width,
            height,
            color,
            depth,
        })
    }

    /// A framebuffer of buffers made elsewhere (an image file, the GPU's readback), checked.
    /// Its size may be any an output file has ([`check_output_size`]: a `side_by_side.png`
    /// read back is twice an eye's width).
    ///
    /// # Errors
    /// `Invalid` for a size [`check_output_size`] refuses, a buffer whose length is not
    /// `width × height`, or a depth that is not a number in [0, 1] (naming its pixel).
    pub fn from_buffers(
        width: u32,
        height: u32,
        color: Vec<[u8; 4]>,
        depth: Vec<f32>,
    ) -> Result<Self> {
        check_output_size(width, height)?;
        let n = width as usize * height as usize;
        for (name, len) in [("color", color.len()), ("depth", depth.len())] {
            if len != n {
                return Err(Error::invalid(
                    format!("framebuffer {name}"),
                    format!("{len} values"),
                    format!("a {width}x{height} framebuffer holds {n}"),
                ));
            }
        }
        if let Some(i) = depth.iter().position(|d| !(0.0..=1.0).contains(d)) {
            return Err(Error::invalid(
                format!(
                    "depth at pixel ({}, {})",
                    i % width as usize,
                    i / width as usize
                ),
                depth[i],
                "window depth must be a number in [0, 1] (NaN or out of range found)",
            ));
        }
        Ok(Framebuffer {
            width,
            height,
            color,
            depth,
        })
    }

    /// Width in pixels.
    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major RGBA8 pixels, row 0 at the top.
    #[inline]
    pub fn color(&self) -> &[[u8; 4]] {
        &self.color
    }

    /// The color buffer to draw into (its length is fixed; depth is not touched).
    #[inline]
    pub fn color_mut(&mut self) -> &mut [[u8; 4]] {
        &mut self.color
    }

    /// Row-major window depth in [0, 1], `glDepthRange(0, 1)`.
    #[inline]
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }

    /// Depth 0 everywhere: every pixel counts as drawn (a picture compared by coverage, not a
    /// pass).
    pub fn cover_all(&mut self) {
        self.depth.fill(0.0);
    }

    /// The buffers, for a caller that takes them over (an image, a texture upload).
    pub fn into_buffers(self) -> (Vec<[u8; 4]>, Vec<f32>) {
        (self.color, self.depth)
    }

    /// Index of pixel (x, y) in the row-major buffers.
    #[inline]
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// Color of pixel (x, y).
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        self.color[self.index(x, y)]
    }

    /// Clears every column outside `keep` to `clear_color` and depth 1.0, as a scissor
    /// rectangle `keep × all rows` would have left them: the columns an image-shift eye's
    /// shifted viewport does not cover.
    pub fn clear_outside_columns(&mut self, keep: std::ops::Range<u32>, clear_color: [u8; 4]) {
        let w = self.width as usize;
        let (x0, x1) = (
            keep.start.min(self.width) as usize,
            keep.end.min(self.width) as usize,
        );
        for (color, depth) in self.color.chunks_mut(w).zip(self.depth.chunks_mut(w)) {
            for x in (0..x0).chain(x1.max(x0)..w) {
                color[x] = clear_color;
                depth[x] = 1.0;
            }
        }
    }

    /// The color buffer as an `image` RGBA image.
    pub fn to_rgba_image(&self) -> image::RgbaImage {
        let bytes: Vec<u8> = self.color.iter().flatten().copied().collect();
        image::RgbaImage::from_raw(self.width, self.height, bytes).expect("buffer size matches")
    }

    /// The depth buffer as a 16-bit grayscale image (0 = near, 65535 = far plane/background).
    pub fn depth_image(&self) -> image::ImageBuffer<image::Luma<u16>, Vec<u16>> {
        let data = self
            .depth
            .iter()
            .map(|d| (d.clamp(0.0, 1.0) * 65535.0).round() as u16)
            .collect();
        image::ImageBuffer::from_raw(self.width, self.height, data).expect("buffer size matches")
    }
}

/// Opens the image file `path` (`what` names it in errors), refusing from its header alone
/// one larger than a framebuffer may be ([`MAX_IMAGE_SIDE`], [`MAX_IMAGE_PIXELS`]).
///
/// # Errors
/// As [`crate::files::open_image`].
pub fn open_image(path: &std::path::Path, what: &str) -> Result<image::DynamicImage> {
    crate::files::open_image(path, what, MAX_IMAGE_SIDE, MAX_IMAGE_PIXELS)
}

/// Opens an image file as large as any a command writes ([`MAX_OUTPUT_SIDE`],
/// [`MAX_OUTPUT_PIXELS`]): what `compare` reads, so every output `render` writes can be
/// compared.
///
/// # Errors
/// As [`crate::files::open_image`].
pub fn open_output_image(path: &std::path::Path, what: &str) -> Result<image::DynamicImage> {
    crate::files::open_image(path, what, MAX_OUTPUT_SIDE, MAX_OUTPUT_PIXELS)
}

/// Checks an image size before anything is allocated.
///
/// # Errors
/// `Invalid` for a zero side or a side above [`MAX_IMAGE_SIDE`].
pub fn check_size(width: u32, height: u32) -> Result<()> {
    check_size_within(width, height, MAX_IMAGE_SIDE, MAX_IMAGE_PIXELS)
}

/// Checks the size of an image an output file may have ([`MAX_OUTPUT_SIDE`],
/// [`MAX_OUTPUT_PIXELS`]).
///
/// # Errors
/// `Invalid` for a zero side, or a side or pixel count above those limits.
pub fn check_output_size(width: u32, height: u32) -> Result<()> {
    check_size_within(width, height, MAX_OUTPUT_SIDE, MAX_OUTPUT_PIXELS)
}

fn check_size_within(width: u32, height: u32, max_side: u32, max_pixels: u64) -> Result<()> {
    for (name, v) in [("width", width), ("height", height)] {
        if v == 0 {
            return Err(Error::invalid(
                format!("image.{name}"),
                v,
                "must be at least 1 pixel",
            ));
        }
        if v > max_side {
            return Err(Error::invalid(
                format!("image.{name}"),
                v,
                format!("must be at most {max_side} pixels"),
            ));
        }
    }
    let pixels = width as u64 * height as u64;
    if pixels > max_pixels {
        return Err(Error::invalid(
            "image size",
            format!("{width}x{height}"),
            format!("{pixels} pixels, more than the {max_pixels} accepted"),
        ));
    }
    Ok(())
}
