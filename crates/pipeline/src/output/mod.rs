//! Turns a rendered [`Frame`] into the images the scene asked for, and writes them.

pub mod animate;
pub mod chromadepth;
pub mod frame_sequential;
pub mod report;
pub mod shear_rotate;
pub mod sirds;
pub mod stereo_photo;
pub mod wiggle;

use std::path::{Path, PathBuf};

use crate::plan::{Output, View};
use crate::render::Frame;
use crate::scene::Scene;
use stereo_photo::{PhotoFormat, RigMetadata, StereoPhoto};
use stereolab_core::{
    AnaglyphKind, Error, Framebuffer, OutputSet, Precision, Result, above_below,
    above_below_squashed, anaglyph, calibration_screen, cancelled, check_output_path,
    frame_packing, ghosted, half_above_below, half_side_by_side, interleave, lenticular_interleave,
    occlusion_image, parallax_image, rds_framebuffer, rds_left, rds_right, remap_color,
    side_by_side, view_tiles,
};

/// One finished output image.
pub enum Image {
    /// 8-bit RGBA.
    Rgba(image::RgbaImage),
    /// 16-bit grayscale (a SIRDS depth map: white near).
    Gray16(image::ImageBuffer<image::Luma<u16>, Vec<u16>>),
    /// 16-bit window depth (`left_depth`, `right_depth`: 0 at the near plane, 65535 at the
    /// far plane), saved with the text chunk that says so ([`stage_window_depth`]).
    WindowDepth(image::ImageBuffer<image::Luma<u16>, Vec<u16>>),
    /// Both eyes in a stereo photo format (MPO, JPS, PNS), encoded when saved.
    Stereo(stereo_photo::StereoPhoto),
    /// Both eyes alternating in time (`frame_sequential`, `wiggle_apng`: an animated PNG when
    /// saved; `wiggle_gif`: an animated GIF).
    Sequence(frame_sequential::FrameSequence),
}

impl Image {
    /// Writes the image as PNG (a stereo photo in its own format), all or nothing
    /// ([`write_atomic`](stereolab_core::write_atomic)).
    ///
    /// # Errors
    /// The file cannot be written, or its name is a link or a special file.
    pub fn save_png(&self, path: &Path) -> Result<()> {
        let mut set = OutputSet::new();
        self.stage(&mut set, path)?;
        set.commit().map(drop)
    }

    /// Writes the image as [`save_png`](Image::save_png) does into `set`, to be renamed onto
    /// `path` with the set's other files.
    ///
    /// # Errors
    /// As [`OutputSet::stage`].
    pub fn stage(&self, set: &mut OutputSet, path: &Path) -> Result<()> {
        self.stage_reporting(set, path, &mut |_, _| {})
    }

    /// [`stage`](Image::stage), calling `progress(done, of)` as a long output (a
    /// frame-sequential animation, field by field) is written.
    ///
    /// # Errors
    /// As [`OutputSet::stage`].
    pub fn stage_reporting(
        &self,
        set: &mut OutputSet,
        path: &Path,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<()> {
        match self {
            Image::Rgba(i) => set.stage_png(path, i),
            Image::Gray16(i) => set.stage_png(path, i),
            Image::WindowDepth(i) => stage_window_depth(set, path, i),
            Image::Stereo(photo) => set.stage_bytes(path, &photo.encode()?),
            Image::Sequence(seq) => set.stage(path, |w| seq.encode_to(w, progress)),
        }
    }

    /// The image as 8-bit RGBA for a screen or a page: 16-bit depth by its high byte, a stereo
    /// photo as its file shows it (cross-eyed: the right eye on the left).
    pub fn to_display_rgba(&self) -> image::RgbaImage {
        match self {
            Image::Rgba(i) => i.clone(),
            Image::Gray16(g) | Image::WindowDepth(g) => {
                image::RgbaImage::from_fn(g.width(), g.height(), |x, y| {
                    let v = (g.get_pixel(x, y).0[0] >> 8) as u8;
                    image::Rgba([v, v, v, 255])
                })
            }
            Image::Stereo(p) => {
                let w = p.left.width();
                let mut out = image::RgbaImage::new(2 * w, p.left.height());
                image::imageops::replace(&mut out, &p.right, 0, 0);
                image::imageops::replace(&mut out, &p.left, i64::from(w), 0);
                out
            }
            // The fields side by side in display order (L | R | …), as a film strip.
            Image::Sequence(s) => {
                let w = s.left.width();
                let mut out = image::RgbaImage::new(w * s.fields.len() as u32, s.left.height());
                for (i, f) in s.fields.iter().enumerate() {
                    image::imageops::replace(&mut out, s.image(f), i64::from(w) * i as i64, 0);
                }
                out
            }
        }
    }

    /// Width and height of [`Image::to_display_rgba`].
    pub fn display_size(&self) -> (u32, u32) {
        match self {
            Image::Rgba(i) => i.dimensions(),
            Image::Gray16(i) | Image::WindowDepth(i) => i.dimensions(),
            Image::Stereo(p) => (2 * p.left.width(), p.left.height()),
            Image::Sequence(s) => (s.left.width() * s.fields.len() as u32, s.left.height()),
        }
    }
}

fn need(frame: &Frame, view: View, output: Output) -> Result<&Framebuffer> {
    frame.view(view).ok_or_else(|| {
        Error::internal(
            "plan",
            format!("{}: the {view:?} pass was not run", output.name()),
        )
    })
}

/// Produces `output` from `frame`.
///
/// # Errors
/// A pass the output needs is missing from the frame (a plan bug), or a layout error.
pub fn produce(output: Output, frame: &Frame, scene: &Scene) -> Result<Image> {
    let eye = |v| need(frame, v, output);
    Ok(match output {
        Output::Left => Image::Rgba(eye(View::Left)?.to_rgba_image()),
        Output::Right => Image::Rgba(eye(View::Right)?.to_rgba_image()),
        Output::LeftDepth => Image::WindowDepth(eye(View::Left)?.depth_image()),
        Output::RightDepth => Image::WindowDepth(eye(View::Right)?.depth_image()),
        Output::SideBySide => Image::Rgba(side_by_side(eye(View::Left)?, eye(View::Right)?)?),
        Output::CrossEyed => Image::Rgba(side_by_side(eye(View::Right)?, eye(View::Left)?)?),
        Output::AboveBelow => Image::Rgba(above_below(eye(View::Left)?, eye(View::Right)?)?),
        Output::AboveBelowSquashed => Image::Rgba(above_below_squashed(
            eye(View::Left)?,
            eye(View::Right)?,
            scene.blank_interval,
        )?),
        Output::HalfSideBySide => {
            Image::Rgba(half_side_by_side(eye(View::Left)?, eye(View::Right)?)?)
        }
        Output::HalfAboveBelow => {
            Image::Rgba(half_above_below(eye(View::Left)?, eye(View::Right)?)?)
        }
        Output::FramePacking => Image::Rgba(frame_packing(eye(View::Left)?, eye(View::Right)?)?),
        Output::InterlacedRows => {
            Image::Rgba(interleave(eye(View::Left)?, eye(View::Right)?, |_, y| {
                y % 2 == 0
            })?)
        }
        Output::InterlacedColumns => {
            Image::Rgba(interleave(eye(View::Left)?, eye(View::Right)?, |x, _| {
                x % 2 == 0
            })?)
        }
        Output::Checkerboard => {
            Image::Rgba(interleave(eye(View::Left)?, eye(View::Right)?, |x, y| {
                (x + y) % 2 == 0
            })?)
        }
        Output::ChromaDepth
        | Output::ChromaDepthLeft
        | Output::ChromaDepthRight
        | Output::ChromaDepthAnaglyph => {
            Image::Rgba(chromadepth::produce(output, frame, &scene.chromadepth)?.to_rgba_image())
        }
        Output::Anaglyph(kind) => Image::Rgba(anaglyph(
            eye(View::Left)?,
            eye(View::Right)?,
            kind,
            scene.finalize,
        )?),
        Output::RemapLeft => Image::Rgba(remap_color(
            eye(View::Left)?,
            eye(View::Right)?,
            &frame.views.eyes[0].mvp,
            &frame.views.eyes[1].mvp,
            Precision::default(),
        )?),
        Output::RemapRight => Image::Rgba(remap_color(
            eye(View::Right)?,
            eye(View::Left)?,
            &frame.views.eyes[1].mvp,
            &frame.views.eyes[0].mvp,
            Precision::default(),
        )?),
        Output::Occlusion => Image::Rgba(occlusion_image(
            eye(View::Left)?,
            eye(View::Right)?,
            [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp],
            Precision::default(),
        )?),
        Output::Parallax => Image::Rgba(parallax_image(eye(View::Left)?, &scene.parallax_rig()?)?),
        Output::RdsLeft => Image::Rgba(rds_left(scene.width, scene.height, &scene.rds)),
        Output::RdsRight => Image::Rgba(rds_right_of(frame, scene, output)?),
        Output::RdsAnaglyph => {
            let left = rds_framebuffer(&rds_left(scene.width, scene.height, &scene.rds));
            let right = rds_framebuffer(&rds_right_of(frame, scene, output)?);
            Image::Rgba(anaglyph(&left, &right, AnaglyphKind::Gray, scene.finalize)?)
        }
        Output::FrameSequential => Image::Sequence(frame_sequential::FrameSequence::from_frame(
            frame,
            &scene.frame_sequential,
        )?),
        Output::GhostingLeft => Image::Rgba(ghosted(
            eye(View::Left)?,
            eye(View::Right)?,
            &scene.ghosting,
        )?),
        Output::GhostingRight => Image::Rgba(ghosted(
            eye(View::Right)?,
            eye(View::Left)?,
            &scene.ghosting,
        )?),
        Output::CancelledLeft => Image::Rgba(cancelled(
            eye(View::Left)?,
            eye(View::Right)?,
            &scene.ghosting,
        )?),
        Output::CancelledRight => Image::Rgba(cancelled(
            eye(View::Right)?,
            eye(View::Left)?,
            &scene.ghosting,
        )?),
        Output::AboveBelowCalibration => Image::Rgba(calibration_screen(
            scene.width,
            scene.height,
            scene.blank_interval,
        )?),
        Output::WiggleGif | Output::WiggleApng => {
            let file = match output {
                Output::WiggleGif => frame_sequential::SequenceFile::Gif,
                _ => frame_sequential::SequenceFile::Apng,
            };
            Image::Sequence(frame_sequential::FrameSequence::wiggle(
                frame,
                &scene.wiggle,
                output.name(),
                file,
            )?)
        }
        Output::ViewTiles(n) => Image::Rgba(view_tiles(&multiview(frame, output, n)?)?),
        Output::ViewInterleaved(n) => {
            Image::Rgba(lenticular_interleave(&multiview(frame, output, n)?)?)
        }
        Output::Sirds => Image::Rgba(sirds::from_frame(frame, scene)?.to_rgba_image()),
        Output::SirdsDepth => Image::Gray16(sirds::scene_depth(frame, scene)?.0.to_image()),
        Output::ShearVsRotate => Image::Rgba(shear_rotate::shear_vs_rotate(frame)?.0),
        Output::SirdsFig5 => Image::Rgba(sirds::fig5_bands(frame, scene)?.to_rgba_image()),
        Output::Mpo | Output::Jps | Output::Pns => {
            let format = match output {
                Output::Mpo => PhotoFormat::Mpo,
                Output::Jps => PhotoFormat::Jps,
                _ => PhotoFormat::Pns,
            };
            Image::Stereo(StereoPhoto {
                format,
                left: eye(View::Left)?.to_rgba_image(),
                right: eye(View::Right)?.to_rgba_image(),
                rig: Some(rig_metadata(scene)?),
            })
        }
    })
}

/// The `n` multiview cameras' framebuffers, index 0 the leftmost.
fn multiview(frame: &Frame, output: Output, n: u8) -> Result<Vec<&Framebuffer>> {
    if frame.views.multi.len() != usize::from(n) {
        return Err(Error::internal(
            "plan",
            format!(
                "{}: {n} views asked for, {} cameras placed (every multiview output carries                  the scene's multiview.views)",
                output.name(),
                frame.views.multi.len()
            ),
        ));
    }
    (0..n)
        .map(|i| need(frame, View::Multi(i), output))
        .collect()
}

/// The right image of the random-dot pair from the frame's two depth passes.
fn rds_right_of(frame: &Frame, scene: &Scene, output: Output) -> Result<image::RgbaImage> {
    rds_right(
        need(frame, View::Left, output)?,
        need(frame, View::Right, output)?,
        &frame.views.eyes[0].mvp,
        &frame.views.eyes[1].mvp,
        &scene.rds,
    )
}

/// The MPO's baseline and convergence from the scene's rig: the resolved eye separation, and
/// the angle between the optical axes — `2 atan((d/2)/z0)` for toe-in (the SGI course notes'
/// rotation of each eye towards the fusion point), 0 for off-axis, parallel and image-shift
/// (parallel axes).
///
/// # Errors
/// As [`StereoRig::resolve`](stereolab_core::StereoRig::resolve).
pub fn rig_metadata(scene: &Scene) -> Result<RigMetadata> {
    use stereolab_core::CameraMode;
    let r = scene.rig.resolve(&scene.camera, scene.aspect())?;
    let convergence_deg = match scene.rig.mode {
        CameraMode::ToeIn => {
            2.0 * (r.eye_separation / 2.0 / r.zero_parallax_distance)
                .atan()
                .to_degrees()
        }
        CameraMode::OffAxis | CameraMode::Parallel | CameraMode::ImageShift => 0.0,
    };
    Ok(RigMetadata {
        baseline: r.eye_separation,
        convergence_deg,
    })
}

/// Writes a window-depth image (`left_depth`, `right_depth`: 0 at the near plane, 65535 at
/// the far plane) as a 16-bit gray PNG carrying the text chunk
/// [`WINDOW_DEPTH_KEYWORD`](stereolab_core::WINDOW_DEPTH_KEYWORD), so that a reader (`sirds
/// --depth`) knows that black is near.
///
/// # Errors
/// As [`OutputSet::stage`], or the encoder failed.
pub fn stage_window_depth(
    set: &mut OutputSet,
    path: &Path,
    depth: &image::ImageBuffer<image::Luma<u16>, Vec<u16>>,
) -> Result<()> {
    let png_error = |e: png::EncodingError| Error::io(path, std::io::Error::other(e.to_string()));
    set.stage(path, |w| {
        let mut enc = png::Encoder::new(w, depth.width(), depth.height());
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        enc.add_text_chunk(
            stereolab_core::WINDOW_DEPTH_KEYWORD.to_string(),
            stereolab_core::WINDOW_DEPTH_TEXT.to_string(),
        )
        .map_err(png_error)?;
        let mut writer = enc.write_header().map_err(png_error)?;
        let bytes: Vec<u8> = depth
            .as_raw()
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        writer.write_image_data(&bytes).map_err(png_error)?;
        writer.finish().map_err(png_error)
    })
}

/// Produces and writes every requested output as `DIR/<name>.png` (`.mpo`, `.jps`, `.pns` for
/// the stereo photo formats); returns the paths.
///
/// # Errors
/// The folder cannot be created, or an output fails.
pub fn write_all(frame: &Frame, scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    write_all_with(frame, dir, |o| produce(o, frame, scene))
}

/// Writes every output of `frame`'s plan, made by `make`, as `DIR/<name>.png`, in plan order;
/// returns the paths. [`write_all`] makes them with [`produce`]; the GPU backend with its
/// WGSL passes.
///
/// # Errors
/// The folder cannot be created, or an output fails.
pub fn write_all_with(
    frame: &Frame,
    dir: &Path,
    make: impl FnMut(Output) -> Result<Image>,
) -> Result<Vec<PathBuf>> {
    write_all_reporting(frame, dir, make, &mut |_, _, _| {})
}

/// [`write_all_with`], calling `progress(file name, done, of)` as a long output is written.
///
/// # Errors
/// As [`write_all_with`].
pub fn write_all_reporting(
    frame: &Frame,
    dir: &Path,
    mut make: impl FnMut(Output) -> Result<Image>,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<Vec<PathBuf>> {
    // Every output is made (and every final name checked) before any is written, and all are
    // written before any is renamed onto its name: an output that fails, a full disk or a
    // signal leaves the folder as it was.
    let outputs = frame
        .plan
        .outputs
        .iter()
        .map(|&o| {
            let path = dir.join(o.file_name());
            check_output_path(&path)?;
            Ok((path, make(o)?))
        })
        .collect::<Result<Vec<_>>>()?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut set = OutputSet::new();
    for (path, image) in &outputs {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        image.stage_reporting(&mut set, path, &mut |done, of| progress(&name, done, of))?;
    }
    set.commit()
}
