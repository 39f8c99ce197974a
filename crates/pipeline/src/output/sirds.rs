//! The scene's SIRDS from a rendered frame: the cyclopean depth pass, the scene's depth range,
//! and the algorithm the scene chose (the strips pass or TIW), guide dots last; and the SIRDS
//! files (PNG or PPM, streamed for large depth maps).

use std::path::Path;

use crate::plan::View;
use crate::render::Frame;
use crate::scene::Scene;
use stereolab_core::{
    DepthMap, DepthMapping, DepthRange, DepthSamples, Disparity, DisparityModel, Error,
    Framebuffer, Near, PgmRows, Result, Sirds, SirdsAlgorithm, SirdsPattern, SirdsSettings,
    StripFilter, StripGeometry, StripResult, depth_range, draw_guide_boxes, draw_guide_dots,
    image_error, per_pixel, per_vertex, write_atomic, write_png,
};

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
/// As [`scene_depth`], [`per_pixel`] and [`per_vertex`].
pub fn from_frame(frame: &Frame, scene: &Scene) -> Result<Sirds> {
    let s = &scene.sirds;
    from_frame_with(frame, scene, |g, d| {
        per_vertex(
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

/// The three variants of the SIRDS paper's Fig. 5, top to bottom: eq. 3 (constant eye
/// distance) with bilinear filtering, eq. 1 (constant viewing direction) bilinear, eq. 3 with
/// nearest filtering ("without texture interpolation, discrete depth layers are visible").
pub const FIG5_BANDS: [(DisparityModel, StripFilter); 3] = [
    (DisparityModel::EyeDistance, StripFilter::Bilinear),
    (DisparityModel::ViewAngle, StripFilter::Bilinear),
    (DisparityModel::EyeDistance, StripFilter::Nearest),
];

/// Output `sirds_fig5`: the scene's per-vertex SIRDS made three times from the one depth pass,
/// once per [`FIG5_BANDS`] variant (the scene's other `[sirds]` settings kept), each
/// contributing a third of the rows (band `k`: rows `k·H/3 .. (k+1)·H/3`). On the ramp scene
/// (`sirds_fig5.toml`) it is the paper's figure. `disparity` is the top band's.
///
/// # Errors
/// As [`from_frame`].
pub fn fig5_bands(frame: &Frame, scene: &Scene) -> Result<Sirds> {
    let (w, h) = (scene.width as usize, scene.height as usize);
    let mut bands = Vec::with_capacity(3);
    for (model, filter) in FIG5_BANDS {
        let mut s = scene.clone();
        s.sirds.algorithm = SirdsAlgorithm::PerVertex;
        // The figure is the strip algorithm's: TIW's options (texture, tileable, planes) off.
        if let SirdsPattern::Textured(t) = &s.sirds.pattern {
            s.sirds.pattern = t.base.clone();
        }
        s.sirds.per_pixel.tileable = false;
        s.sirds.per_pixel.planes = None;
        s.sirds.geometry.model = model;
        s.sirds.per_vertex.filter = filter;
        bands.push(from_frame(frame, &s)?);
    }
    let mut out = bands[0].clone();
    for (k, band) in bands.iter().enumerate() {
        let rows = k * h / 3..(k + 1) * h / 3;
        out.pixels[rows.start * w..rows.end * w]
            .copy_from_slice(&band.pixels[rows.start * w..rows.end * w]);
    }
    out.iterations = None;
    Ok(out)
}

/// [`from_frame`] with the per-vertex strips made by `strips` from the strip geometry and the
/// disparity (the CPU's [`per_vertex`], or the GPU's ping-pong); everything else
/// (depth range, TIW, guide dots) is the same for both.
///
/// # Errors
/// As [`from_frame`], and whatever `strips` returns.
pub fn from_frame_with(
    frame: &Frame,
    scene: &Scene,
    strips: impl FnOnce(&StripGeometry, &Disparity) -> Result<StripResult>,
) -> Result<Sirds> {
    let s = &scene.sirds;
    let (depth, range) = scene_depth(frame, scene)?;
    let d = s.geometry.to_pixels()?;
    let (mut pixels, iterations) = match s.algorithm {
        SirdsAlgorithm::PerPixel => {
            let encoded = if s.cross_eyed {
                depth.inverted()
            } else {
                depth.clone()
            };
            (per_pixel(&encoded, &d, &s.pattern, &s.per_pixel)?, None)
        }
        SirdsAlgorithm::PerVertex => {
            if let Some(field) = s.per_pixel_only() {
                return Err(Error::invalid(
                    field,
                    "with algorithm per-vertex",
                    "is made by TIW's per-pixel linking: set sirds.algorithm = \"per-pixel\"",
                ));
            }
            let g = StripGeometry::new(
                &scene.strip_objects(),
                &frame.views.center,
                &range,
                &d,
                s.cross_eyed,
            );
            let r = strips(&g, &d)?;
            (r.pixels, Some(r.iterations))
        }
    };
    if s.guide_dots {
        draw_guide_dots(&mut pixels, scene.width, scene.height, d.max_separation());
    }
    if let Some(boxes) = s.guide_boxes {
        let (w, h, sep) = (scene.width, scene.height, d.max_separation());
        draw_guide_boxes(&mut pixels, w, h, sep, boxes)?;
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

/// The uncompressed netpbm kinds a SIRDS is written as: binary PPM (P6, three bytes a pixel)
/// for `.ppm`/`.pnm`, binary PGM (P5, one byte a pixel: gray patterns only) for `.pgm`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Netpbm {
    /// P6, RGB.
    Ppm,
    /// P5, gray (`pgm_bytes` refuses a pixel whose channels differ).
    Pgm,
}

impl Netpbm {
    /// The kind `path`'s extension names (ASCII case ignored), `None` for anything else.
    pub fn of(path: &Path) -> Option<Netpbm> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ppm" | "pnm" => Some(Netpbm::Ppm),
            "pgm" => Some(Netpbm::Pgm),
            _ => None,
        }
    }

    /// The header of a `width`×`height` image of this kind, maxval 255.
    fn header(self, width: u32, height: u32) -> String {
        let magic = match self {
            Netpbm::Ppm => "P6",
            Netpbm::Pgm => "P5",
        };
        format!("{magic}\n{width} {height}\n255\n")
    }

    /// `pixels` as this kind's bytes, appended to `out` (cleared first).
    ///
    /// # Errors
    /// `Invalid` naming `--out` for PGM when a pixel is not gray (its R, G and B differ): a
    /// color SIRDS needs `.ppm` or `.png`.
    fn bytes(self, pixels: &[[u8; 4]], out: &mut Vec<u8>, path: &Path) -> Result<()> {
        out.clear();
        match self {
            Netpbm::Ppm => out.extend(pixels.iter().flat_map(|p| [p[0], p[1], p[2]])),
            Netpbm::Pgm => {
                // One pass that vectorizes: the gray level, and whether any channel differed.
                out.resize(pixels.len(), 0);
                let mut differ = 0;
                for (o, p) in out.iter_mut().zip(pixels) {
                    *o = p[0];
                    differ |= (p[0] ^ p[1]) | (p[1] ^ p[2]);
                }
                if differ == 0 {
                    return Ok(());
                }
                if let Some(p) = pixels.iter().find(|p| p[0] != p[1] || p[1] != p[2]) {
                    return Err(Error::invalid(
                        "--out",
                        path.display(),
                        format!(
                            "a PGM holds gray levels, and this SIRDS has colors (e.g. {:?}): name the file .ppm or .png",
                            &p[..3]
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The extensions a still SIRDS may be named with ([`StillFormat::of`]), in the order an
/// error lists them.
pub const STILL_EXTENSIONS: [&str; 7] = ["png", "ppm", "pnm", "pgm", "jpg", "jpeg", "gif"];

/// The container a still SIRDS is written as, by its name's extension (ASCII case ignored).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StillFormat {
    /// `.png`: lossless RGBA.
    Png,
    /// `.ppm`, `.pnm`, `.pgm`: uncompressed netpbm ([`Netpbm`]).
    Netpbm(Netpbm),
    /// `.jpg`, `.jpeg`: baseline JPEG at quality [`JPEG_QUALITY`] (lossy: the dots blur a
    /// little).
    Jpeg,
    /// `.gif`: one frame, quantized to 256 colors as the frames of an animation are (lossless
    /// for black-and-white and gray patterns).
    Gif,
}

/// The JPEG quality a still SIRDS is written at: at the encoder's default of 75 the random
/// dots smear into their neighbours, which the eyes then fuse less well.
pub const JPEG_QUALITY: u8 = 95;

impl StillFormat {
    /// The format `path`'s extension names.
    ///
    /// # Errors
    /// `Invalid` naming `--out`, the extension and the accepted ones ([`STILL_EXTENSIONS`]).
    pub fn of(path: &Path) -> Result<StillFormat> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        Ok(match ext.as_deref() {
            Some("png") => StillFormat::Png,
            Some("jpg" | "jpeg") => StillFormat::Jpeg,
            Some("gif") => StillFormat::Gif,
            _ => match Netpbm::of(path) {
                Some(kind) => StillFormat::Netpbm(kind),
                None => return Err(unsupported_extension(path, &STILL_EXTENSIONS)),
            },
        })
    }
}

/// The error for an output name whose extension is not one of `accepted`: names `--out`, the
/// extension (or its absence) and the accepted extensions.
pub fn unsupported_extension(path: &Path, accepted: &[&str]) -> Error {
    unsupported_extension_of("--out", path, accepted)
}

/// [`unsupported_extension`] of the file named by `flag`.
pub fn unsupported_extension_of(flag: &str, path: &Path, accepted: &[&str]) -> Error {
    let what = match path.extension() {
        Some(e) => format!("unsupported extension .{}", e.to_string_lossy()),
        None => "no extension".to_string(),
    };
    let list: Vec<String> = accepted.iter().map(|e| format!(".{e}")).collect();
    Error::invalid(
        flag,
        path.display(),
        format!(
            "{what}; use {} (the file is written in the format its name says)",
            list.join(", ")
        ),
    )
}

/// Writes RGBA pixels in the format `path`'s extension names ([`StillFormat`]): PNG, JPEG, a
/// one-frame GIF, or uncompressed binary PPM (`.ppm`/`.pnm`) or PGM (`.pgm`, gray SIRDS only,
/// see [`Netpbm`]); all or nothing ([`write_atomic`]).
///
/// # Errors
/// An extension [`StillFormat::of`] refuses (nothing is written); the file cannot be written,
/// or its name is a link or a special file; a `.pgm` of a color SIRDS.
pub fn save(pixels: &[[u8; 4]], width: u32, height: u32, path: &Path) -> Result<()> {
    let format = StillFormat::of(path)?;
    if let StillFormat::Netpbm(kind) = format {
        return write_atomic(path, |w| {
            w.write_all(kind.header(width, height).as_bytes())
                .map_err(|e| Error::io(path, e))?;
            let mut row = Vec::with_capacity(width as usize * 3);
            for line in pixels.chunks_exact(width.max(1) as usize) {
                kind.bytes(line, &mut row, path)?;
                w.write_all(&row).map_err(|e| Error::io(path, e))?;
            }
            Ok(())
        });
    }
    let bytes = pixels.iter().flatten().copied().collect();
    let img = image::RgbaImage::from_raw(width, height, bytes).ok_or_else(|| {
        Error::internal(
            "sirds",
            format!("{} pixels for {width}x{height}", pixels.len()),
        )
    })?;
    match format {
        StillFormat::Jpeg => write_atomic(path, |w| {
            let rgb = image::DynamicImage::ImageRgba8(img).into_rgb8();
            rgb.write_with_encoder(image::codecs::jpeg::JpegEncoder::new_with_quality(
                w,
                JPEG_QUALITY,
            ))
            .map_err(|e| image_error(path, e))
        }),
        StillFormat::Gif => write_atomic(path, |w| {
            let mut gif = image::codecs::gif::GifEncoder::new_with_speed(w, 10);
            gif.encode_frame(image::Frame::new(img))
                .map_err(|e| image_error(path, e))
        }),
        StillFormat::Png | StillFormat::Netpbm(_) => write_png(path, &img),
    }
}

/// TIW from a depth-map file straight into a PPM or PGM (`out`'s extension, see [`Netpbm`]), a chunk of rows at a time: the depth map is never held as
/// floats, nor the image as RGBA (a 4096×3072 map would need 100 MB for both).
///
/// # Errors
/// `out` is not named `.ppm`, `.pnm` or `.pgm` (refused before the map is read); the depth map
/// cannot be read or is too large, or the file cannot be written; a `.pgm` of a color SIRDS.
pub fn stream_depth_map(
    depth: &Path,
    near: Near,
    settings: &SirdsSettings,
    out: &Path,
) -> Result<(u32, u32, DepthMapping)> {
    let kind = Netpbm::of(out).ok_or_else(|| unsupported_extension(out, &["ppm", "pnm", "pgm"]))?;
    // A binary PGM is read as it is used; anything else whole first.
    let mut source = match PgmRows::open(depth, near)? {
        Some(rows) => Ok(rows),
        None => Err(DepthSamples::load(depth, near)?),
    };
    let (width, height) = match &source {
        Ok(rows) => (rows.width, rows.height),
        Err(whole) => (whole.width, whole.height),
    };
    let mut taken = 0;
    let read = |buf: &mut [u16]| match &mut source {
        Ok(rows) => rows.read(buf),
        Err(whole) => {
            buf.copy_from_slice(&whole.samples[taken..taken + buf.len()]);
            taken += buf.len();
            Ok(())
        }
    };
    let invert = settings.cross_eyed;
    let z_of = |v: u16| {
        let z = v as f32 / 65535.0;
        if invert { 1.0 - z } else { z }
    };
    let d = settings.geometry.to_pixels()?;
    // The rows stream into a temporary file: a failure in TIW or in the writing leaves `out`
    // as it was.
    write_atomic(out, |writer| {
        writer
            .write_all(kind.header(width, height).as_bytes())
            .map_err(|e| Error::io(out, e))?;
        let mut bytes = Vec::new();
        stereolab_core::per_pixel_samples(
            width,
            height,
            read,
            z_of,
            &d,
            &settings.pattern,
            &settings.per_pixel,
            |rows| {
                kind.bytes(rows, &mut bytes, out)?;
                writer.write_all(&bytes).map_err(|e| Error::io(out, e))
            },
        )
    })?;
    let mapping = match &source {
        Ok(rows) => rows.mapping(),
        Err(whole) => whole.mapping.clone(),
    };
    Ok((width, height, mapping))
}
