//! The `frame_sequential` output: the two eye back buffers (`BACK_LEFT`, `BACK_RIGHT`) as an
//! animated PNG (APNG) that alternates them at the scene's rate, what a shutter-glasses display
//! shows ([`FrameSequentialSettings::fields`](stereolab_core::FrameSequentialSettings::fields) is the schedule).
//!
//! APNG stores each frame's duration as a fraction `delay_num / delay_den` seconds (`fcTL`), so
//! 1/120 s is exact (GIF's centiseconds could not say it). The file loops forever
//! (`num_plays = 0`); a viewer that cannot keep up with the rate shows it slower, but the file
//! states it. Viewers without APNG support show the first frame, the left eye.

use image::RgbaImage;

use crate::render::Frame;
use stereolab_core::{
    DrawBuffer, Error, FrameField, FrameSequentialSettings, Result, WiggleSettings,
};

/// The file a [`FrameSequence`] is written as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SequenceFile {
    /// An animated PNG, lossless, each field's delay as the exact fraction it is.
    Apng,
    /// An animated GIF ([`super::wiggle`]): one palette of 256 colours for both eyes, delays in
    /// 1/100 s.
    Gif,
}

/// Both eyes and the order and durations they are shown in.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameSequence {
    /// `BACK_LEFT`: the left eye's image.
    pub left: RgbaImage,
    /// `BACK_RIGHT`: the right eye's image (same size).
    pub right: RgbaImage,
    /// The fields in display order.
    pub fields: Vec<FrameField>,
    /// The output's name, for messages.
    pub name: &'static str,
    /// The file written: APNG or GIF, looping forever either way.
    pub file: SequenceFile,
}

/// `frame`'s two eye buffers with `fields`, written as `file`.
fn eye_buffers(
    frame: &Frame,
    name: &'static str,
    fields: Vec<FrameField>,
    file: SequenceFile,
) -> Result<FrameSequence> {
    let buffer = |b: DrawBuffer| {
        frame
            .draw_buffer(b)
            .map(|fb| fb.to_rgba_image())
            .ok_or_else(|| {
                Error::internal("plan", format!("{name}: {} was not rendered", b.gl_name()))
            })
    };
    Ok(FrameSequence {
        left: buffer(DrawBuffer::BackLeft)?,
        right: buffer(DrawBuffer::BackRight)?,
        fields,
        name,
        file,
    })
}

impl FrameSequence {
    /// The sequence of `frame`'s two eye buffers under `settings`.
    ///
    /// # Errors
    /// An eye was not rendered (a plan bug), or settings out of range.
    pub fn from_frame(frame: &Frame, settings: &FrameSequentialSettings) -> Result<FrameSequence> {
        eye_buffers(
            frame,
            "frame_sequential",
            settings.fields()?,
            SequenceFile::Apng,
        )
    }

    /// The wiggle of `frame`'s two eyes under `settings` (StereoPhoto Maker's wiggle export:
    /// two frames alternating forever), written as `file`; `name` is the output's.
    ///
    /// # Errors
    /// An eye was not rendered (a plan bug), or `wiggle.frame_ms` out of range.
    pub fn wiggle(
        frame: &Frame,
        settings: &WiggleSettings,
        name: &'static str,
        file: SequenceFile,
    ) -> Result<FrameSequence> {
        eye_buffers(frame, name, settings.fields()?, file)
    }

    /// The image shown in `field`.
    pub fn image(&self, field: &FrameField) -> &RgbaImage {
        match field.buffer {
            DrawBuffer::BackLeft => &self.left,
            DrawBuffer::BackRight => &self.right,
        }
    }

    /// The file's bytes ([`SequenceFile`]): one full-size frame per field, each with its delay,
    /// looping forever.
    ///
    /// # Errors
    /// Different eye sizes, no fields, or an encoder error.
    pub fn encode(&self) -> Result<Vec<u8>> {
        let mut bytes = Vec::new();
        self.encode_to(&mut bytes, &mut |_, _| {})?;
        Ok(bytes)
    }

    /// [`encode`](FrameSequence::encode) into `out` as it goes (a long sequence is never held
    /// whole in memory), calling `progress(fields written, fields)` after each field.
    ///
    /// # Errors
    /// As [`encode`](FrameSequence::encode), or writing to `out` failed.
    pub fn encode_to(
        &self,
        out: &mut dyn std::io::Write,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Result<()> {
        if self.left.dimensions() != self.right.dimensions() {
            return Err(Error::invalid(
                self.name,
                format!(
                    "{:?} and {:?}",
                    self.left.dimensions(),
                    self.right.dimensions()
                ),
                "both eyes must have the same size",
            ));
        }
        let n = u32::try_from(self.fields.len())
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| Error::internal(self.name, "no fields to write"))?;
        if self.file == SequenceFile::Gif {
            return super::wiggle::encode_gif(self, out, progress);
        }
        let png_err =
            |e: png::EncodingError| Error::internal(format!("{} APNG", self.name), e.to_string());
        {
            let (w, h) = self.left.dimensions();
            let mut enc = png::Encoder::new(out, w, h);
            enc.set_color(png::ColorType::Rgba);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_animated(n, 0).map_err(png_err)?;
            let mut writer = enc.write_header().map_err(png_err)?;
            for (k, field) in self.fields.iter().enumerate() {
                writer
                    .set_frame_delay(field.delay_num, field.delay_den)
                    .map_err(png_err)?;
                writer
                    .write_image_data(self.image(field).as_raw())
                    .map_err(png_err)?;
                progress(k + 1, self.fields.len());
            }
            writer.finish().map_err(png_err)?;
        }
        Ok(())
    }
}
