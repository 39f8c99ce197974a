//! Frame-sequential (time-multiplexed) stereo: the display shows the left eye's buffer, then the
//! right eye's, alternating, while shutter glasses open the matching eye.
//!
//! The SGI course notes (§4.1) draw each eye into its own back buffer (`glDrawBuffer
//! (GL_BACK_LEFT)`, then `GL_BACK_RIGHT`); the StereoGraphics guide (§2–4) describes the
//! quad-buffered display that "will typically maintain four buffers when in stereo display
//! mode" and swaps both back buffers to the front at once. This module is the schedule such a
//! display plays: which buffer is on screen in each field and for how long. The output layer
//! writes it as an animated PNG.
//!
//! Neither document states a refresh rate; [`DEFAULT_EYE_RATE_HZ`] is the common 120 Hz
//! shutter-glasses display (60 images per second per eye).

use serde::Deserialize;

use crate::error::{Error, Result};
use crate::framebuffer::{BACK_LEFT, BACK_RIGHT, DrawBuffer};

/// Images per second per eye unless the scene says otherwise (fields alternate at twice this).
pub const DEFAULT_EYE_RATE_HZ: u32 = 60;
/// The highest rate accepted: 240 fields a second, what the fastest shutter displays run.
pub const MAX_EYE_RATE_HZ: u32 = 120;
/// The most left/right cycles one file holds (the file loops forever anyway).
pub const MAX_CYCLES: u32 = 120;

/// `[frame_sequential]` in a scene file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FrameSequentialSettings {
    /// Images per second per eye, 1 to [`MAX_EYE_RATE_HZ`]; each field lasts `1/(2·rate)` s.
    pub eye_rate_hz: u32,
    /// Left/right pairs written (the animation loops forever), 1 to [`MAX_CYCLES`].
    pub cycles: u32,
}

impl Default for FrameSequentialSettings {
    fn default() -> Self {
        FrameSequentialSettings {
            eye_rate_hz: DEFAULT_EYE_RATE_HZ,
            cycles: 1,
        }
    }
}

/// One field of the sequence: which back buffer is shown, and for how long (a fraction of a
/// second, `numerator / denominator`, as APNG's `fcTL` stores it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// The buffer on screen.
    pub buffer: DrawBuffer,
    /// Duration numerator (seconds).
    pub delay_num: u16,
    /// Duration denominator (seconds).
    pub delay_den: u16,
}

impl FrameSequentialSettings {
    /// # Errors
    /// `Invalid` naming the field out of range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_EYE_RATE_HZ).contains(&self.eye_rate_hz) {
            return Err(Error::invalid(
                "frame_sequential.eye_rate_hz",
                self.eye_rate_hz,
                format!("must be 1 to {MAX_EYE_RATE_HZ} images per second per eye"),
            ));
        }
        if !(1..=MAX_CYCLES).contains(&self.cycles) {
            return Err(Error::invalid(
                "frame_sequential.cycles",
                self.cycles,
                format!("must be 1 to {MAX_CYCLES} left/right pairs"),
            ));
        }
        Ok(())
    }

    /// The fields in display order: `BACK_LEFT`, `BACK_RIGHT`, … (`cycles` pairs), each shown
    /// for `1 / (2 · eye_rate_hz)` seconds.
    ///
    /// # Errors
    /// As [`FrameSequentialSettings::validate`].
    pub fn fields(&self) -> Result<Vec<Field>> {
        self.validate()?;
        let den = u16::try_from(2 * self.eye_rate_hz).expect("bounded by MAX_EYE_RATE_HZ");
        Ok((0..self.cycles)
            .flat_map(|_| [BACK_LEFT, BACK_RIGHT])
            .map(|buffer| Field {
                buffer,
                delay_num: 1,
                delay_den: den,
            })
            .collect())
    }
}

/// The wiggle's time per frame unless the scene says otherwise, in milliseconds.
pub const DEFAULT_WIGGLE_FRAME_MS: u32 = 120;
/// The shortest wiggle frame: GIF viewers show delays under 2/100 s as 1/10 s.
pub const MIN_WIGGLE_FRAME_MS: u32 = 20;
/// The longest wiggle frame (5 s: longer is a slide show, not a wiggle).
pub const MAX_WIGGLE_FRAME_MS: u32 = 5000;

/// Which view a wiggle starts with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum WiggleStart {
    /// Left, right, left, … (default).
    #[default]
    Left,
    /// Right, left, right, …
    Right,
}

/// `[wiggle]` in a scene file: wiggle stereoscopy as StereoPhoto Maker (Masuji Suto) exports
/// it, the left and right views alternating forever, each shown `frame_ms` milliseconds, so
/// the depth is seen with one eye (or none) from the motion parallax.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WiggleSettings {
    /// Milliseconds each view is shown, a multiple of 10 (GIF stores delays in 1/100 s) from
    /// [`MIN_WIGGLE_FRAME_MS`] to [`MAX_WIGGLE_FRAME_MS`].
    pub frame_ms: u32,
    /// The view shown first.
    pub start: WiggleStart,
}

impl Default for WiggleSettings {
    fn default() -> Self {
        WiggleSettings {
            frame_ms: DEFAULT_WIGGLE_FRAME_MS,
            start: WiggleStart::Left,
        }
    }
}

impl WiggleSettings {
    /// # Errors
    /// `Invalid` naming `wiggle.frame_ms` when it is out of range or not a multiple of 10 (the
    /// remedy names the nearest multiples): a GIF delay is a whole number of 1/100 s, and both
    /// wiggle files show the same timing, so the time is refused rather than rounded.
    pub fn validate(&self) -> Result<()> {
        let ms = self.frame_ms;
        if !(MIN_WIGGLE_FRAME_MS..=MAX_WIGGLE_FRAME_MS).contains(&ms) {
            return Err(Error::invalid(
                "wiggle.frame_ms",
                ms,
                format!(
                    "must be {MIN_WIGGLE_FRAME_MS} to {MAX_WIGGLE_FRAME_MS} milliseconds per \
                     view (StereoPhoto Maker's wiggles run about 100 to 200)"
                ),
            ));
        }
        if !ms.is_multiple_of(10) {
            let below = ms / 10 * 10;
            return Err(Error::invalid(
                "wiggle.frame_ms",
                ms,
                format!(
                    "must be a multiple of 10 ms (a GIF delay is a whole number of 1/100 s); \
                     use {below} or {}",
                    below + 10
                ),
            ));
        }
        Ok(())
    }

    /// The GIF delay of each frame in 1/100 s: `frame_ms / 10`.
    ///
    /// # Errors
    /// As [`WiggleSettings::validate`].
    pub fn gif_delay_centiseconds(&self) -> Result<u16> {
        self.validate()?;
        Ok(u16::try_from(self.frame_ms / 10).expect("bounded by MAX_WIGGLE_FRAME_MS"))
    }

    /// The two frames in display order (the file loops forever), each shown
    /// `frame_ms / 1000` s.
    ///
    /// # Errors
    /// As [`WiggleSettings::validate`].
    pub fn fields(&self) -> Result<Vec<Field>> {
        self.validate()?;
        let num = u16::try_from(self.frame_ms).expect("bounded by MAX_WIGGLE_FRAME_MS");
        let order = match self.start {
            WiggleStart::Left => [BACK_LEFT, BACK_RIGHT],
            WiggleStart::Right => [BACK_RIGHT, BACK_LEFT],
        };
        Ok(order
            .into_iter()
            .map(|buffer| Field {
                buffer,
                delay_num: num,
                delay_den: 1000,
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_alternate_left_right_at_twice_the_eye_rate() {
        let f = FrameSequentialSettings {
            eye_rate_hz: 60,
            cycles: 3,
        }
        .fields()
        .unwrap();
        assert_eq!(f.len(), 6);
        for (i, field) in f.iter().enumerate() {
            assert_eq!(
                field.buffer,
                if i % 2 == 0 { BACK_LEFT } else { BACK_RIGHT }
            );
            assert_eq!((field.delay_num, field.delay_den), (1, 120));
        }
    }

    #[test]
    fn rates_and_cycles_are_bounded() {
        for (rate, cycles, field) in [
            (0, 1, "eye_rate_hz"),
            (MAX_EYE_RATE_HZ + 1, 1, "eye_rate_hz"),
            (60, 0, "cycles"),
            (60, MAX_CYCLES + 1, "cycles"),
        ] {
            let e = FrameSequentialSettings {
                eye_rate_hz: rate,
                cycles,
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains(field), "{e}");
        }
    }

    #[test]
    fn wiggle_frame_times_are_bounded_and_whole_centiseconds() {
        for (ms, remedy) in [
            (0, "20 to 5000"),
            (10, "20 to 5000"),
            (5010, "20 to 5000"),
            (125, "use 120 or 130"),
            (21, "use 20 or 30"),
        ] {
            let e = WiggleSettings {
                frame_ms: ms,
                ..WiggleSettings::default()
            }
            .validate()
            .unwrap_err()
            .to_string();
            assert!(e.contains("wiggle.frame_ms") && e.contains(remedy), "{e}");
        }
        let s = WiggleSettings {
            frame_ms: 130,
            start: WiggleStart::Right,
        };
        assert_eq!(s.gif_delay_centiseconds().unwrap(), 13);
        let f = s.fields().unwrap();
        assert_eq!(
            f.iter().map(|f| f.buffer).collect::<Vec<_>>(),
            [BACK_RIGHT, BACK_LEFT]
        );
        assert!(f.iter().all(|f| (f.delay_num, f.delay_den) == (130, 1000)));
    }
}
