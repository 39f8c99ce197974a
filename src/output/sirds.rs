//! The scene's SIRDS from a rendered frame: the cyclopean depth pass, the scene's depth range,
//! and the algorithm the scene chose (the strips pass or TIW), guide dots last; and the SIRDS
//! files (PNG or PPM, streamed for large depth maps).

use std::path::Path;

use crate::effects::sirds::depthfile::{DepthMapping, DepthSamples, Near};
use crate::effects::sirds::{
    Algorithm, DepthMap, DepthRange, Disparity, DisparityModel, Filter, Settings, Sirds,
    depth_range, pattern, per_pixel,
};
use crate::error::{Error, Result};
use crate::files;
use crate::framebuffer::Framebuffer;
use crate::plan::View;
use crate::render::Frame;
use crate::render::sirds_strips::{self, StripGeometry, StripResult};
use crate::scene::Scene;

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
/// As [`scene_depth`], [`per_pixel::per_pixel`] and [`sirds_strips::per_vertex`].
pub fn from_frame(frame: &Frame, scene: &Scene) -> Result<Sirds> {
    let s = &scene.sirds;
    from_frame_with(frame, scene, |g, d| {
        sirds_strips::per_vertex(
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
pub const FIG5_BANDS: [(DisparityModel, Filter); 3] = [
    (DisparityModel::EyeDistance, Filter::Bilinear),
    (DisparityModel::ViewAngle, Filter::Bilinear),
    (DisparityModel::EyeDistance, Filter::Nearest),
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
        s.sirds.algorithm = Algorithm::PerVertex;
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
/// disparity (the CPU's [`sirds_strips::per_vertex`], or the GPU's ping-pong); everything else
/// (depth range, TIW, guide dots) is the same for both.
///
/// # Errors
/// As [`from_frame`], and whatever `strips` returns.
pub(crate) fn from_frame_with(
    frame: &Frame,
    scene: &Scene,
    strips: impl FnOnce(&StripGeometry, &Disparity) -> Result<StripResult>,
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
            let g = StripGeometry::new(scene, &frame.center, &range, &d, s.cross_eyed);
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

/// Writes RGBA pixels as PNG, or as binary PPM (P6, no compression) for `.ppm`/`.pnm`, all or
/// nothing ([`files::write_atomic`]).
///
/// # Errors
/// The file cannot be written, or its name is a link or a special file.
pub fn save(pixels: &[[u8; 4]], width: u32, height: u32, path: &Path) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext == "ppm" || ext == "pnm" {
        files::write_atomic(path, |w| {
            let mut ppm = || -> std::io::Result<()> {
                write!(w, "P6\n{width} {height}\n255\n")?;
                let mut row = Vec::with_capacity(width as usize * 3);
                for line in pixels.chunks_exact(width.max(1) as usize) {
                    row.clear();
                    row.extend(line.iter().flat_map(|p| [p[0], p[1], p[2]]));
                    w.write_all(&row)?;
                }
                Ok(())
            };
            ppm().map_err(|e| Error::io(path, e))
        })
    } else {
        let bytes = pixels.iter().flatten().copied().collect();
        let img = image::RgbaImage::from_raw(width, height, bytes).ok_or_else(|| {
            Error::internal(
                "sirds",
                format!("{} pixels for {width}x{height}", pixels.len()),
            )
        })?;
        files::write_png(path, &img)
    }
}

/// TIW from a depth-map file straight into a PPM, a chunk of rows at a time: the depth map is
/// never held as floats, nor the image as RGBA (a 4096×3072 map would need 100 MB for both).
///
/// # Errors
/// The depth map cannot be read or is too large, or the file cannot be written.
pub fn stream_depth_map(
    depth: &Path,
    near: Near,
    settings: &Settings,
    out: &Path,
) -> Result<(u32, u32, DepthMapping)> {
    let DepthSamples {
        width,
        height,
        samples,
        mapping,
    } = DepthSamples::load(depth, near)?;
    let invert = settings.cross_eyed;
    let w = width as usize;
    let depth_row = |y: u32, row: &mut Vec<f32>| {
        let line = &samples[y as usize * w..(y as usize + 1) * w];
        row.extend(line.iter().map(|&v| {
            let z = v as f32 / 65535.0;
            if invert { 1.0 - z } else { z }
        }));
    };
    let d = settings.geometry.to_pixels()?;
    // The rows stream into a temporary file: a failure in TIW or in the writing leaves `out`
    // as it was.
    files::write_atomic(out, |writer| {
        write!(writer, "P6\n{width} {height}\n255\n").map_err(|e| Error::io(out, e))?;
        let mut bytes = Vec::new();
        crate::effects::sirds::per_pixel::per_pixel_streamed(
            width,
            height,
            depth_row,
            &d,
            &settings.pattern,
            &settings.per_pixel,
            |rows| {
                bytes.resize(rows.len() * 3, 0);
                for (b, p) in bytes.chunks_exact_mut(3).zip(rows) {
                    b.copy_from_slice(&p[..3]);
                }
                writer.write_all(&bytes).map_err(|e| Error::io(out, e))
            },
        )
    })?;
    Ok((width, height, mapping))
}
