//! Depth maps from other tools: 8- and 16-bit PNG, netpbm PGM/PPM/PAM, float PFM, with white
//! or black meaning near.
//!
//! # Range mapping
//!
//! Every file becomes normalized nearness `z` ∈ [0, 1] (1 = front of the depth range,
//! 0 = the background plane; see [`DepthMap`](super::DepthMap)):
//!
//! - **Integer images** (PNG, PGM, PPM, PAM at any bit depth; color ones by their luma):
//!   the format's full scale, `z = v / max` where `max` is 255, 65535 or the netpbm maxval
//!   (the image crate rescales a netpbm maxval to 8 or 16 bits). The full scale keeps a map's
//!   absolute depths: a map that never reaches white never reaches the front, as in netpbm's
//!   `pamstereogram`. With `--near black`, `z = 1 − v / max`.
//! - **PFM** (floats have no full scale): the file's own finite range, `z = (v − min) /
//!   (max − min)` (white: larger values nearer), `z = (max − v) / (max − min)` with `--near
//!   black` (for maps of distance, where larger is farther). Infinite and NaN samples (a
//!   renderer's "no hit") are the background, `z = 0`. A map of one value is all background.
//!
//! Samples are kept as 16-bit nearness (`round(z · 65535)`): 1/65535 of the range is far
//! below one pixel of separation, and a 4096 × 3072 map takes 25 MB, not 50.
//!
//! # PFM
//!
//! The Portable Float Map as Netpbm's `pfm` documentation and Paul Debevec's HDRShop define it:
//! a text header of three whitespace-separated tokens, `PF` (three channels) or `Pf` (one),
//! `width height`, and a scale whose sign gives the byte order (negative: little-endian,
//! positive: big-endian; its magnitude is not used here), each ended by one whitespace byte;
//! then `width · height · channels` IEEE-754 32-bit floats, rows from the **bottom** of the
//! image to the top, left to right, channels interleaved.

use std::fmt;
use std::io::Read as _;
use std::path::Path;

use crate::error::{Error, Result};
use crate::framebuffer::{MAX_IMAGE_PIXELS, check_size};

/// Which end of a depth map's values is near.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Near {
    /// Larger values (white) are nearer: netpbm, stereolab's own `sirds_depth`, most
    /// autostereogram tools.
    #[default]
    White,
    /// Smaller values (black) are nearer: distance maps, Z-buffers.
    Black,
}

impl Near {
    /// Parses `white` or `black`.
    ///
    /// # Errors
    /// `Invalid` naming `--near` and the two accepted words.
    pub fn parse(text: &str) -> Result<Near> {
        match text {
            "white" => Ok(Near::White),
            "black" => Ok(Near::Black),
            other => Err(Error::invalid(
                "--near",
                other,
                "must be white (larger values near) or black (smaller values near)",
            )),
        }
    }
}

/// The keyword of the PNG text chunk in stereolab's window-depth outputs (`left_depth.png`,
/// `right_depth.png`), whose values grow with distance: [`near_of_file`] finds it, so that
/// `sirds --depth` reads them the right way round without `--near black`.
pub const WINDOW_DEPTH_KEYWORD: &str = "stereolab window depth";

/// The text of that chunk.
pub const WINDOW_DEPTH_TEXT: &str = "0 = near plane (black) .. 65535 = far plane (white)";

/// Which values a depth-map file itself says are near: [`Near::Black`] for a PNG holding
/// stereolab's window-depth text chunk ([`WINDOW_DEPTH_KEYWORD`]), `None` when the file does
/// not say (the reader then takes `--near`, white by default).
pub fn near_of_file(path: &Path) -> Option<Near> {
    let file = std::fs::File::open(path).ok()?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    let info = reader.info();
    let says = info
        .uncompressed_latin1_text
        .iter()
        .any(|t| t.keyword == WINDOW_DEPTH_KEYWORD);
    says.then_some(Near::Black)
}

/// How a file's values became nearness: what `stereolab sirds --depth` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthMapping {
    /// The file's format in words, e.g. `8-bit gray PNG`.
    pub format: String,
    /// The value mapped to the background (`z = 0`).
    pub far_value: f64,
    /// The value mapped to the front (`z = 1`).
    pub near_value: f64,
    /// Whether `far_value`..`near_value` is the format's full scale (integers) or the file's
    /// own range (floats).
    pub full_scale: bool,
    /// The smallest and largest (finite) values the file holds.
    pub found: (f64, f64),
    /// Samples that were not finite (PFM only), mapped to the background.
    pub non_finite: usize,
}

impl fmt::Display for DepthMapping {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: {} → background (z = 0) .. {} → front (z = 1), linear ({}); the file holds {}..{}",
            self.format,
            self.far_value,
            self.near_value,
            if self.full_scale {
                "the format's full scale"
            } else {
                "the file's own range"
            },
            self.found.0,
            self.found.1
        )?;
        if self.non_finite > 0 {
            write!(f, ", {} non-finite samples as background", self.non_finite)?;
        }
        Ok(())
    }
}

/// A depth map read from a file as 16-bit nearness.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthSamples {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Row-major nearness, `round(z · 65535)`, row 0 at the top.
    pub samples: Vec<u16>,
    /// How the file's values were mapped.
    pub mapping: DepthMapping,
}

/// The largest PFM header accepted, bytes (three short tokens).
const MAX_PFM_HEADER: usize = 256;

impl DepthSamples {
    /// Reads a depth map: PFM by its `PF`/`Pf` magic, anything else through the image crate
    /// (PNG, PGM/PPM/PAM, ...). Sizes are checked from the header before anything is
    /// allocated.
    ///
    /// # Errors
    /// `Io` when the file cannot be read; `Parse` naming the file for a broken or truncated
    /// header or body, an oversized image, or a format the image crate cannot read.
    pub fn load(path: &Path, near: Near) -> Result<DepthSamples> {
        crate::files::check_input(path)?;
        let mut head = Vec::with_capacity(MAX_PFM_HEADER);
        std::fs::File::open(path)
            .and_then(|f| f.take(MAX_PFM_HEADER as u64).read_to_end(&mut head))
            .map_err(|e| Error::io(path, e))?;
        if head.starts_with(b"PF") || head.starts_with(b"Pf") {
            return load_pfm(path, &head, near);
        }
        load_integer(path, near)
    }
}

fn load_integer(path: &Path, near: Near) -> Result<DepthSamples> {
    let img = crate::framebuffer::open_image(path, "depth map")?;
    let (width, height) = (img.width(), img.height());
    check_size(width, height).map_err(|e| e.in_file(path))?;
    let kind = if img.color().has_color() {
        "color (its luma)"
    } else {
        "gray"
    };
    let bits = img.color().bits_per_pixel() / u16::from(img.color().channel_count());
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("image")
        .to_ascii_uppercase();
    let (mut samples, max): (Vec<u16>, u16) = match img {
        image::DynamicImage::ImageLuma8(g) => {
            (g.into_raw().into_iter().map(u16::from).collect(), 255)
        }
        other if bits <= 8 => (
            other
                .to_luma8()
                .into_raw()
                .into_iter()
                .map(u16::from)
                .collect(),
            255,
        ),
        other => (other.to_luma16().into_raw(), 65535),
    };
    let (lo, hi) = samples
        .iter()
        .fold((u16::MAX, 0u16), |(a, b), &v| (a.min(v), b.max(v)));
    // v / max as 16-bit nearness: 8-bit v · 257 is exactly v / 255 of 65535.
    let scale = 65535 / max;
    for v in &mut samples {
        let z = *v * scale;
        *v = if near == Near::Black { 65535 - z } else { z };
    }
    let (far_value, near_value) = match near {
        Near::White => (0.0, f64::from(max)),
        Near::Black => (f64::from(max), 0.0),
    };
    Ok(DepthSamples {
        width,
        height,
        samples,
        mapping: DepthMapping {
            format: format!("{bits}-bit {kind} {ext}"),
            far_value,
            near_value,
            full_scale: true,
            found: (f64::from(lo), f64::from(hi)),
            non_finite: 0,
        },
    })
}

/// The PFM header: channels, width, height, little-endian, and its length in bytes.
fn pfm_header(path: &Path, head: &[u8]) -> Result<(usize, u32, u32, bool, usize)> {
    let bad = |what: String| Error::parse(path, None, format!("PFM header: {what}"));
    // Three tokens, each ended by one whitespace byte.
    let mut tokens: Vec<&str> = Vec::new();
    let mut pos = 0;
    while tokens.len() < 4 {
        while pos < head.len() && head[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < head.len() && !head[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if pos >= head.len() {
            return Err(bad(format!(
                "expected `PF|Pf width height scale` in the first {MAX_PFM_HEADER} bytes"
            )));
        }
        tokens.push(std::str::from_utf8(&head[start..pos]).map_err(|_| bad("not text".into()))?);
    }
    let body = pos + 1; // the single whitespace byte after the scale
    let channels = match tokens[0] {
        "PF" => 3,
        "Pf" => 1,
        other => {
            return Err(bad(format!(
                "magic {other:?}, want PF (color) or Pf (gray)"
            )));
        }
    };
    let side = |t: &str, name: &str| {
        t.parse::<u32>()
            .map_err(|_| bad(format!("{name} {t:?} is not a whole number")))
    };
    let (w, h) = (side(tokens[1], "width")?, side(tokens[2], "height")?);
    let scale: f32 = tokens[3]
        .parse()
        .map_err(|_| bad(format!("scale {:?} is not a number", tokens[3])))?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(bad(format!(
            "scale {scale} must be a non-zero number (its sign is the byte order)"
        )));
    }
    Ok((channels, w, h, scale < 0.0, body))
}

fn load_pfm(path: &Path, head: &[u8], near: Near) -> Result<DepthSamples> {
    let (channels, width, height, little, body) = pfm_header(path, head)?;
    check_size(width, height).map_err(|e| e.in_file(path))?;
    let n = width as usize * height as usize;
    debug_assert!(n as u64 <= MAX_IMAGE_PIXELS);
    let want = body + n * channels * 4;
    let size = crate::files::check_input(path)?;
    let bytes = if size == want as u64 {
        crate::files::read_input(path, want as u64)?
    } else {
        Vec::new()
    };
    if bytes.len() != want {
        return Err(Error::parse(
            path,
            None,
            format!(
                "PFM body: {} bytes, a {width}x{height} {}-channel map needs {}",
                size.saturating_sub(body as u64),
                channels,
                want - body
            ),
        ));
    }
    let value = |i: usize| {
        let b: [u8; 4] = bytes[body + 4 * i..body + 4 * i + 4]
            .try_into()
            .expect("4 bytes");
        if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    };
    // Rec. 709 luma, as the image crate weighs color. In f64: the luma of three samples near
    // f32's largest value, and the span between −3e38 and 3e38, overflow f32.
    let sample = |i: usize| -> f64 {
        if channels == 1 {
            f64::from(value(i))
        } else {
            0.2126 * f64::from(value(3 * i))
                + 0.7152 * f64::from(value(3 * i + 1))
                + 0.0722 * f64::from(value(3 * i + 2))
        }
    };
    let (mut lo, mut hi, mut non_finite) = (f64::INFINITY, f64::NEG_INFINITY, 0usize);
    for i in 0..n {
        let v = sample(i);
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        } else {
            non_finite += 1;
        }
    }
    let span = hi - lo;
    // No finite sample, or a map of one value: all background.
    let flat = span.is_nan() || span <= 0.0;
    let (w, h) = (width as usize, height as usize);
    let mut samples = vec![0u16; n];
    for (y, row) in samples.chunks_exact_mut(w).enumerate() {
        // PFM rows run from the bottom up.
        let src = (h - 1 - y) * w;
        for (x, out) in row.iter_mut().enumerate() {
            let v = sample(src + x);
            let z = if !v.is_finite() || flat {
                0.0
            } else if near == Near::White {
                (v - lo) / span
            } else {
                (hi - v) / span
            };
            *out = (z.clamp(0.0, 1.0) * 65535.0).round() as u16;
        }
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
    let (far_value, near_value) = match near {
        Near::White => (lo, hi),
        Near::Black => (hi, lo),
    };
    Ok(DepthSamples {
        width,
        height,
        samples,
        mapping: DepthMapping {
            format: format!(
                "32-bit float {} PFM ({}-endian)",
                if channels == 1 {
                    "gray"
                } else {
                    "color (its luma)"
                },
                if little { "little" } else { "big" }
            ),
            far_value,
            near_value,
            full_scale: false,
            found: (lo, hi),
            non_finite,
        },
    })
}

/// A binary PGM (P5) or one-channel PAM (P7, DEPTH 1) with maxval 255 or 65535 read a run of
/// rows at a time, as 16-bit nearness
/// with [`DepthSamples::load`]'s mapping and the same numbers: `stereolab sirds --depth` into a
/// netpbm file streams it, so a 4096×3072 map is never held whole (its 25 MB buffer and the
/// image crate's copy cost more page faults than the reading).
#[derive(Debug)]
pub struct PgmRows {
    reader: std::io::BufReader<std::fs::File>,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    wide: bool,
    near: Near,
    found: (u16, u16),
    ext: String,
    bytes: Vec<u8>,
    path: std::path::PathBuf,
}

/// The header of a binary PGM (P5) or a one-channel PAM (P7 with DEPTH 1, what the image
/// crate writes for `.pgm`): width, height, maxval and its length in bytes; `None` for
/// anything else (another magic or depth, a malformed or over-long header).
fn pgm_header(head: &[u8]) -> Option<(u32, u32, u32, usize)> {
    if head.starts_with(b"P7") {
        return pam_header(head);
    }
    if !head.starts_with(b"P5") {
        return None;
    }
    let mut pos = 2;
    let mut numbers = [0u32; 3];
    for n in &mut numbers {
        // Whitespace and `#` comments (to the end of the line) before each number.
        loop {
            match head.get(pos)? {
                c if c.is_ascii_whitespace() => pos += 1,
                b'#' => {
                    while *head.get(pos)? != b'\n' {
                        pos += 1;
                    }
                }
                _ => break,
            }
        }
        let start = pos;
        while head.get(pos)?.is_ascii_digit() {
            pos += 1;
        }
        *n = std::str::from_utf8(&head[start..pos]).ok()?.parse().ok()?;
    }
    // Exactly one whitespace byte ends the header.
    head.get(pos)?.is_ascii_whitespace().then_some(())?;
    Some((numbers[0], numbers[1], numbers[2], pos + 1))
}

/// A PAM header (`P7`, then `KEYWORD value` lines and `#` comments up to `ENDHDR`): width,
/// height, maxval and its length, for DEPTH 1 and TUPLTYPE GRAYSCALE only (anything else
/// goes to the image crate, which decides what it means).
fn pam_header(head: &[u8]) -> Option<(u32, u32, u32, usize)> {
    let (mut width, mut height, mut depth, mut maxval) = (None, None, None, None);
    let mut gray = false;
    let mut pos = head.iter().position(|&b| b == b'\n')? + 1;
    loop {
        let end = pos + head[pos..].iter().position(|&b| b == b'\n')?;
        let line = std::str::from_utf8(&head[pos..end]).ok()?.trim();
        pos = end + 1;
        let mut words = line.split_ascii_whitespace();
        let number = |w: Option<&str>| w.and_then(|v| v.parse::<u32>().ok());
        match words.next() {
            Some("ENDHDR") => break,
            Some("WIDTH") => width = number(words.next()),
            Some("HEIGHT") => height = number(words.next()),
            Some("DEPTH") => depth = number(words.next()),
            Some("MAXVAL") => maxval = number(words.next()),
            Some("TUPLTYPE") => gray = words.next() == Some("GRAYSCALE"),
            Some(w) if w.starts_with('#') => {}
            None => {}
            Some(_) => return None,
        }
    }
    (depth? == 1 && gray).then_some(())?;
    Some((width?, height?, maxval?, pos))
}

impl PgmRows {
    /// Opens `path` when it is a binary PGM or one-channel PAM of maxval 255 or 65535 whose
    /// size is exactly its header and samples; `Ok(None)` for any other file (read it with
    /// [`DepthSamples::load`], which also gives the errors).
    ///
    /// # Errors
    /// `Io` when the file cannot be opened or read, or is not a regular file.
    pub fn open(path: &Path, near: Near) -> Result<Option<PgmRows>> {
        let size = crate::files::check_input(path)?;
        let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        let mut head = Vec::with_capacity(MAX_PFM_HEADER);
        (&mut file)
            .take(MAX_PFM_HEADER as u64)
            .read_to_end(&mut head)
            .map_err(|e| Error::io(path, e))?;
        let Some((width, height, maxval, body)) = pgm_header(&head) else {
            return Ok(None);
        };
        let wide = match maxval {
            255 => false,
            65535 => true,
            _ => return Ok(None),
        };
        let samples = u64::from(width) * u64::from(height);
        if check_size(width, height).is_err()
            || size != body as u64 + samples * if wide { 2 } else { 1 }
        {
            return Ok(None);
        }
        use std::io::Seek as _;
        file.seek(std::io::SeekFrom::Start(body as u64))
            .map_err(|e| Error::io(path, e))?;
        Ok(Some(PgmRows {
            reader: std::io::BufReader::with_capacity(1 << 20, file),
            width,
            height,
            wide,
            near,
            found: (u16::MAX, 0),
            ext: path
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("image")
                .to_ascii_uppercase(),
            bytes: Vec::new(),
            path: path.to_path_buf(),
        }))
    }

    /// The next `out.len()` samples (whole rows, in file order) as 16-bit nearness: `v · 257`
    /// (8-bit) or `v` (16-bit), `65535 −` that with `--near black`, as [`DepthSamples::load`]
    /// maps them.
    ///
    /// # Errors
    /// `Io` when the read fails (the file shrank since it was opened).
    pub fn read(&mut self, out: &mut [u16]) -> Result<()> {
        let per = if self.wide { 2 } else { 1 };
        self.bytes.resize(out.len() * per, 0);
        self.reader
            .read_exact(&mut self.bytes)
            .map_err(|e| Error::io(&self.path, e))?;
        let (mut lo, mut hi) = self.found;
        let black = self.near == Near::Black;
        let mut put = |o: &mut u16, v: u16, scale: u16| {
            lo = lo.min(v);
            hi = hi.max(v);
            let z = v * scale;
            *o = if black { 65535 - z } else { z };
        };
        if self.wide {
            for (o, b) in out.iter_mut().zip(self.bytes.chunks_exact(2)) {
                put(o, u16::from_be_bytes([b[0], b[1]]), 1);
            }
        } else {
            for (o, &b) in out.iter_mut().zip(&self.bytes) {
                put(o, u16::from(b), 257);
            }
        }
        self.found = (lo, hi);
        Ok(())
    }

    /// How the values became nearness, `found` over the samples read so far (all of them
    /// once the image has been read): what [`DepthSamples::load`] reports for the same file.
    pub fn mapping(&self) -> DepthMapping {
        let max = if self.wide { 65535.0 } else { 255.0 };
        let (far_value, near_value) = match self.near {
            Near::White => (0.0, max),
            Near::Black => (max, 0.0),
        };
        DepthMapping {
            format: format!("{}-bit gray {}", if self.wide { 16 } else { 8 }, self.ext),
            far_value,
            near_value,
            full_scale: true,
            found: (f64::from(self.found.0), f64::from(self.found.1)),
            non_finite: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stream opens the PGMs it knows (the image crate's one-channel PAM at 8 and 16 bits,
    /// a hand-written P5 with a comment) and reads, in runs of rows, the samples and mapping
    /// that [`DepthSamples::load`] gives for the same file, near white and black; anything
    /// else (a PNG, an RGB PAM, a truncated P5, maxval 1000) is left to `load`.
    #[test]
    fn pgm_rows_read_what_load_reads() {
        let dir = std::env::temp_dir().join(format!("stereolab-pgm-rows-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let (w, h) = (37u32, 11u32);
        let values: Vec<u16> = (0..w * h)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 16) as u16)
            .collect();
        let img16 = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, values.clone())
            .expect("size");
        let (pam16, pam8, p5) = (dir.join("a.pgm"), dir.join("b.pgm"), dir.join("c.pgm"));
        img16.save(&pam16).expect("pam16");
        image::DynamicImage::ImageLuma16(img16.clone())
            .to_luma8()
            .save(&pam8)
            .expect("pam8");
        let mut bytes = format!("P5\n# a comment\n{w} {h}\n65535\n").into_bytes();
        bytes.extend(values.iter().flat_map(|v| v.to_be_bytes()));
        std::fs::write(&p5, &bytes).expect("p5");
        for path in [&pam16, &pam8, &p5] {
            for near in [Near::White, Near::Black] {
                let mut rows = PgmRows::open(path, near)
                    .expect("opens")
                    .unwrap_or_else(|| panic!("{} not streamed", path.display()));
                let whole = DepthSamples::load(path, near).expect("loads");
                assert_eq!((rows.width, rows.height), (whole.width, whole.height));
                let mut got = vec![0u16; whole.samples.len()];
                for run in got.chunks_mut(3 * w as usize) {
                    rows.read(run).expect("reads");
                }
                assert!(got == whole.samples, "{} {near:?}: samples", path.display());
                assert_eq!(rows.mapping(), whole.mapping, "{} {near:?}", path.display());
            }
        }
        // Left to `load`: a PNG, an RGB PAM, a truncated P5, a maxval the stream does not map.
        let png = dir.join("d.png");
        img16.save(&png).expect("png");
        let rgb = dir.join("e.pam");
        image::DynamicImage::ImageLuma16(img16.clone())
            .to_rgb8()
            .save(&rgb)
            .expect("rgb pam");
        let short = dir.join("f.pgm");
        std::fs::write(&short, &bytes[..bytes.len() - 1]).expect("short");
        let odd = dir.join("g.pgm");
        let mut odd_bytes = format!("P5 {w} {h} 1000\n").into_bytes();
        odd_bytes.extend(values.iter().flat_map(|v| (v % 1000).to_be_bytes()));
        std::fs::write(&odd, odd_bytes).expect("odd");
        for path in [&png, &rgb, &short, &odd] {
            assert!(
                PgmRows::open(path, Near::White).expect("opens").is_none(),
                "{} streamed",
                path.display()
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A float PFM holding an 8-bit map's values scaled and shifted to f32's extremes
    /// (`v · 2.6e36 − 3.3e38`, gray and as RGB) reads as the same nearness as the 8-bit PGM of
    /// `v`: min..max in the one is 0..255 full scale in the other; the span (6.6e38, past f32's
    /// largest value) is taken in f64.

    #[test]
    fn a_pfm_at_the_extremes_reads_as_the_8_bit_map_it_scales() {
        let dir = std::env::temp_dir().join(format!("stereolab-pfm-ext-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let (w, h) = (16u32, 16u32);
        let v: Vec<u8> = (0..w * h).map(|i| (i % 256) as u8).collect();
        let pgm = dir.join("v.pgm");
        let mut bytes = format!("P5\n{w} {h}\n255\n").into_bytes();
        bytes.extend(&v);
        std::fs::write(&pgm, bytes).expect("pgm");
        let scaled = |b: u8| (f64::from(b) * 2.6e36 - 3.3e38) as f32;
        // PFM rows run from the bottom up.
        let rows_up = |channels: usize| -> Vec<u8> {
            (0..h as usize)
                .rev()
                .flat_map(|y| v[y * w as usize..(y + 1) * w as usize].to_vec())
                .flat_map(|b| std::iter::repeat_n(scaled(b).to_le_bytes(), channels))
                .flatten()
                .collect()
        };
        for (name, magic, channels) in [("g.pfm", "Pf", 1), ("c.pfm", "PF", 3)] {
            let path = dir.join(name);
            let mut bytes = format!("{magic}\n{w} {h}\n-1.0\n").into_bytes();
            bytes.extend(rows_up(channels));
            std::fs::write(&path, bytes).expect("pfm");
            for near in [Near::White, Near::Black] {
                let pfm = DepthSamples::load(&path, near).expect("pfm loads");
                let reference = DepthSamples::load(&pgm, near).expect("pgm loads");
                assert_eq!(pfm.mapping.non_finite, 0, "{name}");
                assert!(pfm.samples == reference.samples, "{name} {near:?}");
            }
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
