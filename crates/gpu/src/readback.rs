//! Offscreen targets and their readback into [`Framebuffer`]s: RGBA8 color and f32 depth,
//! copied through buffers whose rows are padded to wgpu's 256-byte alignment.

use std::sync::mpsc;

use image::RgbaImage;
use rayon::prelude::*;

use stereolab_core::{Framebuffer, Result};

use super::device::GpuRenderer;
use super::gpu_error;
use super::resources::texture_2d;

/// The color format of every target: 8-bit RGBA, no sRGB conversion (docs/ARCHITECTURE.md).
pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Spare targets kept between frames: a stereo pair plus a center pass and an effect pass.
const MAX_SPARE_TARGETS: usize = 4;

/// Where a target's depth lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum DepthKind {
    /// A real depth buffer, for scene passes.
    DepthBuffer,
    /// A second color attachment holding depth as `R32Float`, for full-screen passes.
    ColorR32,
}

impl DepthKind {
    pub(crate) fn format(self) -> wgpu::TextureFormat {
        match self {
            DepthKind::DepthBuffer => wgpu::TextureFormat::Depth32Float,
            DepthKind::ColorR32 => wgpu::TextureFormat::R32Float,
        }
    }
    fn aspect(self) -> wgpu::TextureAspect {
        match self {
            DepthKind::DepthBuffer => wgpu::TextureAspect::DepthOnly,
            DepthKind::ColorR32 => wgpu::TextureAspect::All,
        }
    }
}

/// A color texture, a depth texture, and the two buffers they are copied into.
pub(crate) struct Target {
    pub width: u32,
    pub height: u32,
    pub color_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
    color: wgpu::Texture,
    depth: wgpu::Texture,
    depth_kind: DepthKind,
    color_buffer: wgpu::Buffer,
    depth_buffer: wgpu::Buffer,
    /// Bytes per padded row (both textures have 4-byte texels).
    padded_row: u32,
}

/// `4·width` rounded up to `COPY_BYTES_PER_ROW_ALIGNMENT` (256).
pub(crate) fn padded_row_bytes(width: u32) -> u32 {
    (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

impl Target {
    /// A `width × height` target: a spare one of an earlier frame, else a new one.
    ///
    /// # Errors
    /// A side the device does not support.
    pub fn take(r: &GpuRenderer, width: u32, height: u32, depth_kind: DepthKind) -> Result<Self> {
        if let Ok(mut spare) = r.spare_targets.lock() {
            let fits =
                |t: &Target| (t.width, t.height, t.depth_kind) == (width, height, depth_kind);
            if let Some(i) = spare.iter().position(fits) {
                return Ok(spare.swap_remove(i));
            }
        }
        Target::new(r, width, height, depth_kind)
    }

    /// Hands targets back for later frames, keeping at most [`MAX_SPARE_TARGETS`].
    pub(crate) fn give_back(r: &GpuRenderer, targets: impl IntoIterator<Item = Target>) {
        if let Ok(mut spare) = r.spare_targets.lock() {
            for t in targets {
                if spare.len() == MAX_SPARE_TARGETS {
                    spare.remove(0);
                }
                spare.push(t);
            }
        }
    }

    /// Allocates a `width × height` target.
    ///
    /// # Errors
    /// A side the device does not support.
    fn new(r: &GpuRenderer, width: u32, height: u32, depth_kind: DepthKind) -> Result<Self> {
        r.check_target_size(width, height)?;
        // TEXTURE_BINDING: a finalize pass may read the target where it lies
        // (`FullscreenPass::encode`), without a readback and a re-upload.
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING;
        let texture = |label, format| texture_2d(r, label, width, height, format, usage);
        let color = texture("color target", COLOR_FORMAT);
        let depth = texture("depth target", depth_kind.format());
        let padded_row = padded_row_bytes(width);
        let buffer = |label| {
            r.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: padded_row as u64 * height as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            })
        };
        Ok(Target {
            width,
            height,
            color_view: color.create_view(&wgpu::TextureViewDescriptor::default()),
            depth_view: depth.create_view(&wgpu::TextureViewDescriptor::default()),
            color_buffer: buffer("color readback"),
            depth_buffer: buffer("depth readback"),
            color,
            depth,
            depth_kind,
            padded_row,
        })
    }

    /// Records the copies of both textures into the readback buffers.
    pub(crate) fn encode_copies(&self, encoder: &mut wgpu::CommandEncoder) {
        self.encode(encoder, true);
    }

    /// Records the copy of the color texture alone (for [`submit_and_read_colors`]): what an
    /// output image needs, a quarter or half of [`Target::encode_copies`]'s bytes.
    pub(crate) fn encode_color_copy(&self, encoder: &mut wgpu::CommandEncoder) {
        self.encode(encoder, false);
    }

    fn encode(&self, encoder: &mut wgpu::CommandEncoder, with_depth: bool) {
        let size = wgpu::Extent3d {
            width: self.width,
            height: self.height,
            depth_or_array_layers: 1,
        };
        let copies = [
            (&self.color, wgpu::TextureAspect::All, &self.color_buffer),
            (&self.depth, self.depth_kind.aspect(), &self.depth_buffer),
        ];
        for (texture, aspect, buffer) in &copies[..1 + usize::from(with_depth)] {
            let (texture, aspect, buffer) = (*texture, *aspect, *buffer);
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(self.padded_row),
                        rows_per_image: Some(self.height),
                    },
                },
                size,
            );
        }
    }
}

/// Submits `encoder` (which must have recorded [`Target::encode_copies`] for every target),
/// waits, and reads every target back, in order.
///
/// # Errors
/// The device was lost, or a buffer could not be mapped.
pub(crate) fn submit_and_read(
    r: &GpuRenderer,
    encoder: wgpu::CommandEncoder,
    targets: &[&Target],
) -> Result<Vec<Readback>> {
    let buffers: Vec<&wgpu::Buffer> = targets
        .iter()
        .flat_map(|t| [&t.color_buffer, &t.depth_buffer])
        .collect();
    submit_and_map(r, encoder, &buffers)?;
    // One target per thread: unpadding a 1024×768 pair takes 2–6 ms on one thread.
    targets.par_iter().map(|t| read_target(t)).collect()
}

/// Submits `encoder` (which must have recorded [`Target::encode_color_copy`] for every
/// target), waits, and reads every target's color back as an image, in order. The images'
/// bytes are those [`submit_and_read`] would give as `Framebuffer::to_rgba_image`.
///
/// # Errors
/// The device was lost, or a buffer could not be mapped.
pub(crate) fn submit_and_read_colors(
    r: &GpuRenderer,
    encoder: wgpu::CommandEncoder,
    targets: &[&Target],
) -> Result<Vec<RgbaImage>> {
    let buffers: Vec<&wgpu::Buffer> = targets.iter().map(|t| &t.color_buffer).collect();
    submit_and_map(r, encoder, &buffers)?;
    targets.iter().map(|t| read_color(t)).collect()
}

/// Submits `encoder` and nothing else, and waits until the GPU has done it (no readback).
///
/// # Errors
/// The device was lost.
pub(crate) fn submit_and_wait(r: &GpuRenderer, encoder: wgpu::CommandEncoder) -> Result<()> {
    submit_and_map(r, encoder, &[])
}

/// Submits `encoder`, maps `buffers` for reading and waits for both.
fn submit_and_map(
    r: &GpuRenderer,
    encoder: wgpu::CommandEncoder,
    buffers: &[&wgpu::Buffer],
) -> Result<()> {
    r.queue.submit([encoder.finish()]);
    let (tx, rx) = mpsc::channel();
    for b in buffers {
        let tx = tx.clone();
        b.map_async(wgpu::MapMode::Read, .., move |res| {
            let _ = tx.send(res);
        });
    }
    drop(tx);
    r.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| gpu_error("readback", format!("waiting for the GPU failed: {e}")))?;
    for res in rx.iter() {
        res.map_err(|e| gpu_error("readback", format!("cannot map a buffer: {e}")))?;
    }
    Ok(())
}

/// Unpads the mapped color buffer of `t` into an image, then unmaps it.
fn read_color(t: &Target) -> Result<RgbaImage> {
    let (w, row) = (4 * t.width as usize, t.padded_row as usize);
    let mut bytes = Vec::with_capacity(w * t.height as usize);
    {
        let c = t
            .color_buffer
            .get_mapped_range(..)
            .map_err(|e| gpu_error("readback", format!("buffer not mapped: {e}")))?;
        for c in c.chunks_exact(row) {
            bytes.extend_from_slice(&c[..w]);
        }
    }
    t.color_buffer.unmap();
    RgbaImage::from_raw(t.width, t.height, bytes)
        .ok_or_else(|| stereolab_core::Error::internal("readback", "color buffer size mismatch"))
}

/// A target's pixels as read back: its colors and the f32 values of its depth (or R32) texture,
/// which a full-screen pass may fill with other numbers than depths (the parallax pass writes
/// p(z) there).
pub(crate) struct Readback {
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) color: Vec<[u8; 4]>,
    pub(crate) values: Vec<f32>,
}

impl Readback {
    /// The readback of a depth target as a framebuffer (its values checked as window depths).
    pub(crate) fn into_framebuffer(self) -> Result<Framebuffer> {
        Framebuffer::from_buffers(self.width, self.height, self.color, self.values)
    }

    /// The colors as an image.
    pub(crate) fn to_rgba_image(&self) -> RgbaImage {
        let bytes: Vec<u8> = self.color.iter().flatten().copied().collect();
        RgbaImage::from_raw(self.width, self.height, bytes).expect("4 bytes per pixel")
    }
}

/// Unpads the mapped buffers of `t`, then unmaps them.
fn read_target(t: &Target) -> Result<Readback> {
    let (w, row) = (t.width as usize, t.padded_row as usize);
    let n = w * t.height as usize;
    let (mut color, mut depth) = (Vec::with_capacity(n), Vec::with_capacity(n));
    {
        let mapped = |b: &wgpu::Buffer| {
            b.get_mapped_range(..)
                .map_err(|e| gpu_error("readback", format!("buffer not mapped: {e}")))
        };
        let (c, d) = (mapped(&t.color_buffer)?, mapped(&t.depth_buffer)?);
        // Row by row, dropping the padding; 4-byte texels as [u8; 4] and native-endian f32.
        for (c, d) in c.chunks_exact(row).zip(d.chunks_exact(row)) {
            color.extend(c[..4 * w].chunks_exact(4).map(|p| [p[0], p[1], p[2], p[3]]));
            depth.extend(
                d[..4 * w]
                    .chunks_exact(4)
                    .map(|p| f32::from_ne_bytes([p[0], p[1], p[2], p[3]])),
            );
        }
    }
    t.color_buffer.unmap();
    t.depth_buffer.unmap();
    Ok(Readback {
        width: t.width,
        height: t.height,
        color,
        values: depth,
    })
}
