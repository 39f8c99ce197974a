//! The wiggle outputs: wiggle stereoscopy as StereoPhoto Maker (Masuji Suto) exports it, the
//! left and right views alternating forever, `wiggle.frame_ms` each
//! ([`WiggleSettings`](stereolab_core::WiggleSettings)). `wiggle_apng` is the
//! [`FrameSequence`] written as the frame-sequential output's animated PNG (lossless);
//! `wiggle_gif` is the same sequence as an animated GIF, written here.
//!
//! A GIF frame holds at most 256 colours. Both frames share one global palette, so a pixel
//! that is the same in both eyes (the background, everything at zero parallax) is the same
//! palette entry in both frames and does not shimmer as the wiggle alternates:
//!
//! - when both eyes together hold at most 256 distinct colours, the palette is those colours
//!   (sorted), and the GIF is lossless;
//! - otherwise the palette is NeuQuant's (Anthony Dekker's neural-net quantiser, the
//!   `color_quant` crate that the `gif` and `image` crates use), trained on both eyes' pixels
//!   (left then right, sampling factor 10, `image`'s default), and each pixel takes its nearest
//!   entry. NeuQuant is integer arithmetic with no random numbers: the same eyes give the
//!   same bytes on every run. No dithering: dithered noise would differ between the eyes and
//!   itself wiggle.
//!
//! Delays are in 1/100 s: `frame_ms / 10`, a whole number because `wiggle.frame_ms` must be a
//! multiple of 10. The file loops forever (the NETSCAPE2.0 extension, loop count 0).

use std::borrow::Cow;
use std::collections::BTreeMap;

use image::RgbaImage;

use super::frame_sequential::FrameSequence;
use stereolab_core::{Error, Result};

/// Distinct colours a GIF palette holds.
pub const GIF_COLORS: usize = 256;
/// NeuQuant's sampling factor (1 best, 30 fastest): `image`'s GIF encoder's default.
pub const NEUQUANT_SAMPLING: i32 = 10;

/// One palette for both eyes, and the palette index of every pixel of each eye.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SharedPalette {
    /// RGB triples, at most [`GIF_COLORS`].
    pub rgb: Vec<[u8; 3]>,
    /// Per image, one index into `rgb` per pixel, row-major.
    pub indices: Vec<Vec<u8>>,
    /// Whether `rgb` holds every colour of the images exactly (no quantisation).
    pub exact: bool,
}

/// The shared palette of `images` (alpha ignored: a GIF frame here is opaque): their own
/// colours when they have at most 256, NeuQuant's otherwise.
pub fn shared_palette(images: &[&RgbaImage]) -> SharedPalette {
    let rgb_of = |p: &[u8]| [p[0], p[1], p[2]];
    let mut distinct: BTreeMap<[u8; 3], u8> = BTreeMap::new();
    'count: for img in images {
        for p in img.as_raw().chunks_exact(4) {
            distinct.insert(rgb_of(p), 0);
            if distinct.len() > GIF_COLORS {
                break 'count;
            }
        }
    }
    if distinct.len() <= GIF_COLORS {
        for (i, v) in distinct.values_mut().enumerate() {
            *v = i as u8;
        }
        let indices = images
            .iter()
            .map(|img| {
                img.as_raw()
                    .chunks_exact(4)
                    .map(|p| distinct[&rgb_of(p)])
                    .collect()
            })
            .collect();
        return SharedPalette {
            rgb: distinct.keys().copied().collect(),
            indices,
            exact: true,
        };
    }
    let mut samples = Vec::with_capacity(images.iter().map(|i| i.as_raw().len()).sum());
    for img in images {
        for p in img.as_raw().chunks_exact(4) {
            samples.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
    }
    let nq = color_quant::NeuQuant::new(NEUQUANT_SAMPLING, GIF_COLORS, &samples);
    let rgb = nq
        .color_map_rgb()
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    let indices = images
        .iter()
        .map(|img| {
            img.as_raw()
                .chunks_exact(4)
                .map(|p| nq.index_of(&[p[0], p[1], p[2], 255]) as u8)
                .collect()
        })
        .collect();
    SharedPalette {
        rgb,
        indices,
        exact: false,
    }
}

/// Writes `seq` as an animated GIF into `out`: one global palette ([`shared_palette`]), one
/// full frame per field with its delay in 1/100 s (rounded to the nearest; the wiggle's are
/// whole), looping forever; `progress(fields written, fields)` after each field.
///
/// # Errors
/// An image side above 65535 (GIF's limit), or writing failed.
pub fn encode_gif(
    seq: &FrameSequence,
    out: &mut dyn std::io::Write,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<()> {
    let (w, h) = seq.left.dimensions();
    let side = |v: u32| {
        u16::try_from(v).map_err(|_| {
            Error::invalid(
                "image.width / image.height",
                v,
                format!("{}: a GIF side is at most 65535 pixels", seq.name),
            )
        })
    };
    let (gw, gh) = (side(w)?, side(h)?);
    let gif_err =
        |e: gif::EncodingError| Error::internal(format!("{} GIF", seq.name), e.to_string());
    let palette = shared_palette(&[&seq.left, &seq.right]);
    let flat: Vec<u8> = palette.rgb.iter().flatten().copied().collect();
    let mut enc = gif::Encoder::new(out, gw, gh, &flat).map_err(gif_err)?;
    enc.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
    for (k, field) in seq.fields.iter().enumerate() {
        let which = usize::from(seq.image(field) != &seq.left);
        let centiseconds = (u32::from(field.delay_num) * 100 + u32::from(field.delay_den) / 2)
            / u32::from(field.delay_den);
        let frame = gif::Frame {
            width: gw,
            height: gh,
            delay: u16::try_from(centiseconds).unwrap_or(u16::MAX),
            buffer: Cow::Borrowed(&palette.indices[which]),
            ..gif::Frame::default()
        };
        enc.write_frame(&frame).map_err(gif_err)?;
        progress(k + 1, seq.fields.len());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image_of(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> RgbaImage {
        RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)))
    }

    #[test]
    fn few_colours_are_kept_exactly_and_many_are_quantised() {
        // 16 × 16 = 256 colours over both images: the palette is exact.
        let a = image_of(16, 8, |x, y| [x as u8 * 16, y as u8 * 16, 7, 255]);
        let b = image_of(16, 8, |x, y| [x as u8 * 16, (y as u8 + 8) * 16, 7, 255]);
        let p = shared_palette(&[&a, &b]);
        assert!(p.exact);
        assert_eq!(p.rgb.len(), 256);
        for (img, idx) in [&a, &b].into_iter().zip(&p.indices) {
            for (px, &i) in img.pixels().zip(idx) {
                assert_eq!(p.rgb[usize::from(i)], [px.0[0], px.0[1], px.0[2]]);
            }
        }
        // One more colour: NeuQuant, the same bytes on every call.
        let c = image_of(16, 8, |x, y| [x as u8 * 16, y as u8 * 16, 200, 255]);
        let q = shared_palette(&[&a, &b, &c]);
        assert!(!q.exact);
        assert!(q.rgb.len() <= GIF_COLORS);
        assert_eq!(q, shared_palette(&[&a, &b, &c]));
    }
}
