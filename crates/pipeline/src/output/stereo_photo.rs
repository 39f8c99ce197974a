//! The stereo photo formats that stereo viewers, 3D cameras and photo sites open: MPO, JPS
//! and PNS (outputs `mpo`, `jps`, `pns`), and reading them back (`stereolab compare`).
//!
//! # MPO (CIPA DC-007, "Multi-Picture Format")
//!
//! Two baseline JPEGs, one after the other. The first carries an APP2 segment `MPF\0`
//! holding a TIFF-style structure (byte order mark, 42, offset of the first IFD; every offset
//! counts from the byte order mark, the "MP Endian" field):
//!
//! - the **MP Index IFD**: `MPFVersion` (0xB000, UNDEFINED 4, `"0100"`), `NumberOfImages`
//!   (0xB001, LONG, 2) and `MPEntry` (0xB002, UNDEFINED, 16 bytes per image: the individual
//!   image attribute — flags in bits 31–27 with 0x20000000 = representative image, the data
//!   format in bits 26–24 with 0 = JPEG, the type in bits 23–0 with 0x020002 = "Multi-frame
//!   Disparity" —, the image's size in bytes, its offset from the MP Endian field (0 for the
//!   first image), and two dependent-image entry numbers, 0 here);
//! - its next-IFD offset points at the first image's **MP Attribute IFD**: `MPFVersion`,
//!   `MPIndividualNum` (0xB101, LONG: 1 for the left, the leftmost viewpoint, 2 for the right),
//!   `BaseViewpointNum` (0xB204, LONG, 1), `ConvergenceAngle` (0xB205, SRATIONAL, degrees) and
//!   `BaselineLength` (0xB206, RATIONAL, metres).
//!
//! The second JPEG carries an APP2 `MPF\0` with its own MP Attribute IFD only. The rig gives
//! the convergence angle exactly (toe-in: the two axes meet at the zero-parallax distance,
//! `2 atan((d/2)/z0)`; off-axis and parallel: parallel axes, 0°) and the baseline `d` in scene
//! units, which stereolab writes as metres (its scenes carry no unit; glTF's convention).
//!
//! # JPS and PNS
//!
//! One JPEG (JPS) or PNG (PNS) holding both views side by side in **cross-eyed order: the
//! right eye's view on the left half**, as stereo viewers expect of these files. The JPS
//! carries the APP3 `_JPSJPS_` descriptor as ExifTool reads it: a 16-bit block length (4), then
//! four bytes — separation (0 px), flags (bit 2 "left field first", clear: right first), layout
//! (2, side by side), type (1, stereo) — then a 16-bit comment length and the comment.

use std::io::Cursor;
use std::path::Path;

use image::RgbaImage;

use stereolab_core::{Error, Result};

/// Which stereo photo format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotoFormat {
    /// CIPA DC-007 multi-picture JPEG: left, then right.
    Mpo,
    /// Side-by-side JPEG, right | left.
    Jps,
    /// Side-by-side PNG, right | left.
    Pns,
}

impl PhotoFormat {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            PhotoFormat::Mpo => "mpo",
            PhotoFormat::Jps => "jps",
            PhotoFormat::Pns => "pns",
        }
    }

    /// The format a file name asks for, by its extension (ASCII case ignored).
    pub fn from_path(path: &Path) -> Option<PhotoFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        [PhotoFormat::Mpo, PhotoFormat::Jps, PhotoFormat::Pns]
            .into_iter()
            .find(|f| f.extension() == ext)
    }
}

/// What the rig tells an MPO's MP Attribute IFDs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigMetadata {
    /// Distance between the two cameras, scene units (written as metres).
    pub baseline: f32,
    /// Angle between the two optical axes, degrees (0 for parallel axes).
    pub convergence_deg: f32,
}

/// A stereo pair to be written in one of the formats.
#[derive(Clone, Debug, PartialEq)]
pub struct StereoPhoto {
    /// The format.
    pub format: PhotoFormat,
    /// The left eye's view.
    pub left: RgbaImage,
    /// The right eye's view (same size).
    pub right: RgbaImage,
    /// Baseline and convergence (MPO only).
    pub rig: Option<RigMetadata>,
}

/// JPEG quality of the MPO and JPS images (the image crate's encoder, 1–100).
pub const JPEG_QUALITY: u8 = 95;

impl StereoPhoto {
    /// The file's bytes.
    ///
    /// # Errors
    /// `Invalid` for views of different sizes, or an encoder error.
    pub fn encode(&self) -> Result<Vec<u8>> {
        if self.left.dimensions() != self.right.dimensions() {
            return Err(Error::invalid(
                "stereo photo",
                format!(
                    "{:?} and {:?}",
                    self.left.dimensions(),
                    self.right.dimensions()
                ),
                "both views must have the same size",
            ));
        }
        match self.format {
            PhotoFormat::Mpo => encode_mpo(&self.left, &self.right, self.rig),
            PhotoFormat::Jps => {
                let jpeg = jpeg(&cross_eyed(&self.left, &self.right)?)?;
                let mut app3 = b"_JPSJPS_".to_vec();
                app3.extend(4u16.to_be_bytes());
                // Separation 0, flags 0 (right field first), layout 2 (side by side), stereo.
                app3.extend([0, 0, 2, 1]);
                let comment = b"stereolab: right | left (cross-eyed)";
                app3.extend((comment.len() as u16).to_be_bytes());
                app3.extend(comment);
                insert_segment(&jpeg, 0xE3, &app3)
            }
            PhotoFormat::Pns => {
                let mut bytes = Vec::new();
                cross_eyed(&self.left, &self.right)?
                    .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
                    .map_err(|e| Error::internal("pns", e.to_string()))?;
                Ok(bytes)
            }
        }
    }
}

/// Right | left, side by side.
fn cross_eyed(left: &RgbaImage, right: &RgbaImage) -> Result<RgbaImage> {
    let (w, h) = left.dimensions();
    let mut out = RgbaImage::new(w * 2, h);
    image::imageops::replace(&mut out, right, 0, 0);
    image::imageops::replace(&mut out, left, i64::from(w), 0);
    Ok(out)
}

/// A baseline JPEG of `img` (alpha dropped) at [`JPEG_QUALITY`].
fn jpeg(img: &RgbaImage) -> Result<Vec<u8>> {
    let rgb = image::DynamicImage::ImageRgba8(img.clone()).into_rgb8();
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, JPEG_QUALITY)
        .encode_image(&rgb)
        .map_err(|e| Error::internal("jpeg", e.to_string()))?;
    Ok(bytes)
}

/// `jpeg` with an APPn segment (`marker` 0xE0..=0xEF) inserted after SOI and any APP0 (JFIF
/// must come first).
fn insert_segment(jpeg: &[u8], marker: u8, payload: &[u8]) -> Result<Vec<u8>> {
    if !jpeg.starts_with(&[0xFF, 0xD8]) || payload.len() + 2 > usize::from(u16::MAX) {
        return Err(Error::internal("jpeg", "not a JPEG, or segment too long"));
    }
    let mut at = 2;
    if jpeg.get(2..4) == Some(&[0xFF, 0xE0][..]) {
        let len = u16::from_be_bytes([jpeg[4], jpeg[5]]) as usize;
        at = 4 + len;
    }
    let mut out = Vec::with_capacity(jpeg.len() + payload.len() + 4);
    out.extend(&jpeg[..at]);
    out.extend([0xFF, marker]);
    out.extend(((payload.len() + 2) as u16).to_be_bytes());
    out.extend(payload);
    out.extend(&jpeg[at..]);
    Ok(out)
}

// TIFF field types.
const LONG: u16 = 4;
const UNDEFINED: u16 = 7;
const RATIONAL: u16 = 5;
const SRATIONAL: u16 = 10;

/// An IFD being built (little-endian): 12-byte entries, values over 4 bytes placed after it.
struct Ifd {
    entries: Vec<(u16, u16, u32, Vec<u8>)>,
}

impl Ifd {
    fn new() -> Ifd {
        Ifd {
            entries: Vec::new(),
        }
    }

    fn add(&mut self, tag: u16, kind: u16, count: u32, value: Vec<u8>) {
        self.entries.push((tag, kind, count, value));
    }

    fn long(&mut self, tag: u16, v: u32) {
        self.add(tag, LONG, 1, v.to_le_bytes().to_vec());
    }

    /// Bytes of the IFD placed at `offset` (from the MP Endian field), ending with
    /// `next` as the next-IFD offset, its long values right after it.
    fn bytes(&self, offset: u32, next: u32) -> Vec<u8> {
        let n = self.entries.len() as u32;
        let mut data_at = offset + 2 + 12 * n + 4;
        let (mut head, mut data): (Vec<u8>, Vec<u8>) = (Vec::new(), Vec::new());
        head.extend((n as u16).to_le_bytes());
        for (tag, kind, count, value) in &self.entries {
            head.extend(tag.to_le_bytes());
            head.extend(kind.to_le_bytes());
            head.extend(count.to_le_bytes());
            if value.len() <= 4 {
                let mut v = value.clone();
                v.resize(4, 0);
                head.extend(v);
            } else {
                head.extend(data_at.to_le_bytes());
                data.extend(value);
                data_at += value.len() as u32;
            }
        }
        head.extend(next.to_le_bytes());
        head.extend(data);
        head
    }

    /// Length in bytes once written.
    fn len(&self) -> u32 {
        self.bytes(0, 0).len() as u32
    }
}

/// The MP Attribute IFD of image `number` (1 = left).
fn attribute_ifd(number: u32, rig: Option<RigMetadata>) -> Ifd {
    let mut ifd = Ifd::new();
    ifd.add(0xB000, UNDEFINED, 4, b"0100".to_vec());
    ifd.long(0xB101, number);
    ifd.long(0xB204, 1);
    if let Some(rig) = rig {
        // Rationals as value / 10000 (0.1 mm, 0.0001°).
        let convergence = (f64::from(rig.convergence_deg) * 10_000.0).round() as i32;
        let mut v = convergence.to_le_bytes().to_vec();
        v.extend(10_000i32.to_le_bytes());
        ifd.add(0xB205, SRATIONAL, 1, v);
        let baseline = (f64::from(rig.baseline) * 10_000.0).round().max(0.0) as u32;
        let mut v = baseline.to_le_bytes().to_vec();
        v.extend(10_000u32.to_le_bytes());
        ifd.add(0xB206, RATIONAL, 1, v);
    }
    ifd
}

/// An APP2 `MPF\0` payload: the MP Endian field (`II*\0`, first IFD at 8) and the IFDs.
fn mpf_payload(ifds: &[u8]) -> Vec<u8> {
    let mut p = b"MPF\0II\x2a\0".to_vec();
    p.extend(8u32.to_le_bytes());
    p.extend(ifds);
    p
}

/// The MPO of `left` and `right` (see the module documentation).
///
/// # Errors
/// An encoder error.
pub fn encode_mpo(
    left: &RgbaImage,
    right: &RgbaImage,
    rig: Option<RigMetadata>,
) -> Result<Vec<u8>> {
    let (first, second) = (jpeg(left)?, jpeg(right)?);
    let second = insert_segment(
        &second,
        0xE2,
        &mpf_payload(&attribute_ifd(2, rig).bytes(8, 0)),
    )?;
    // The index IFD's size does not depend on the values, so the first image's size is known
    // before its entries are filled in.
    let index = |sizes: [u32; 2], offset2: u32| {
        let mut ifd = Ifd::new();
        ifd.add(0xB000, UNDEFINED, 4, b"0100".to_vec());
        ifd.long(0xB001, 2);
        let mut entries = Vec::new();
        for (i, (size, offset)) in sizes.into_iter().zip([0, offset2]).enumerate() {
            let attribute: u32 = if i == 0 { 0x2000_0000 } else { 0 } | 0x0002_0002;
            entries.extend(attribute.to_le_bytes());
            entries.extend(size.to_le_bytes());
            entries.extend(offset.to_le_bytes());
            entries.extend([0u8; 4]);
        }
        ifd.add(0xB002, UNDEFINED, 32, entries);
        ifd
    };
    let attr1 = attribute_ifd(1, rig);
    let index_len = index([0, 0], 0).len();
    let build = |sizes: [u32; 2], offset2: u32| -> Result<Vec<u8>> {
        let mut ifds = index(sizes, offset2).bytes(8, 8 + index_len);
        ifds.extend(attr1.bytes(8 + index_len, 0));
        insert_segment(&first, 0xE2, &mpf_payload(&ifds))
    };
    let size1 = build([0, 0], 0)?.len();
    // Offsets count from the MP Endian field: 4 bytes into the APP2 payload.
    let endian_at = mp_endian_offset(&build([0, 0], 0)?)?;
    let offset2 = (size1 - endian_at) as u32;
    let mut out = build([size1 as u32, second.len() as u32], offset2)?;
    debug_assert_eq!(out.len(), size1);
    out.extend(second);
    Ok(out)
}

/// Where the first APP2 `MPF\0` segment's MP Endian field starts in `jpeg`.
fn mp_endian_offset(jpeg: &[u8]) -> Result<usize> {
    let mut at = 2;
    while at + 4 <= jpeg.len() && jpeg[at] == 0xFF {
        let marker = jpeg[at + 1];
        let len = u16::from_be_bytes([jpeg[at + 2], jpeg[at + 3]]) as usize;
        if marker == 0xDA || len < 2 {
            break;
        }
        if marker == 0xE2 && jpeg.get(at + 4..at + 8) == Some(&b"MPF\0"[..]) {
            return Ok(at + 8);
        }
        at += 2 + len;
    }
    Err(Error::parse(
        Path::new("MPO"),
        None,
        "no APP2 MPF segment before the image data: not a multi-picture file (CIPA DC-007)",
    ))
}

/// The JPEG streams an MPO's MP Index IFD lists, in order (`bytes` is the whole file).
///
/// # Errors
/// `Parse` naming `path` for a missing or malformed MP index, or entries outside the file.
pub fn mpo_images<'a>(path: &Path, bytes: &'a [u8]) -> Result<Vec<&'a [u8]>> {
    let bad = |what: &str| Error::parse(path, None, format!("MPO: {what}"));
    let base = mp_endian_offset(bytes).map_err(|_| {
        bad("no APP2 MPF segment before the image data: not a multi-picture file (CIPA DC-007)")
    })?;
    let get = |at: usize, n: usize| {
        bytes
            .get(base + at..base + at + n)
            .ok_or_else(|| bad("MP index runs past the file"))
    };
    let little = match get(0, 2)? {
        b"II" => true,
        b"MM" => false,
        _ => return Err(bad("MP Endian field is neither II nor MM")),
    };
    let u16_at = |at: usize| -> Result<u16> {
        let b: [u8; 2] = get(at, 2)?.try_into().expect("2 bytes");
        Ok(if little {
            u16::from_le_bytes(b)
        } else {
            u16::from_be_bytes(b)
        })
    };
    let u32_at = |at: usize| -> Result<u32> {
        let b: [u8; 4] = get(at, 4)?.try_into().expect("4 bytes");
        Ok(if little {
            u32::from_le_bytes(b)
        } else {
            u32::from_be_bytes(b)
        })
    };
    let ifd = u32_at(4)? as usize;
    let count = u16_at(ifd)? as usize;
    let mut entries = None;
    for i in 0..count {
        let e = ifd + 2 + 12 * i;
        if u16_at(e)? == 0xB002 {
            entries = Some((u32_at(e + 4)? as usize, u32_at(e + 8)? as usize));
        }
    }
    let (len, at) = entries.ok_or_else(|| bad("the MP Index IFD has no MPEntry (0xB002)"))?;
    if len % 16 != 0 || len == 0 || len > 16 * 64 {
        return Err(bad(
            "MPEntry length is not a multiple of 16 bytes (at most 64 images)",
        ));
    }
    (0..len / 16)
        .map(|i| {
            let (size, offset) = (
                u32_at(at + 16 * i + 4)? as usize,
                u32_at(at + 16 * i + 8)? as usize,
            );
            let start = if i == 0 { 0 } else { base + offset };
            bytes
                .get(start..start.saturating_add(size))
                .filter(|b| b.starts_with(&[0xFF, 0xD8]))
                .ok_or_else(|| {
                    bad(&format!(
                        "image {} ({size} bytes at {start}) is not a JPEG inside the file",
                        i + 1
                    ))
                })
        })
        .collect()
}

/// Reads a stereo photo back as its (left, right) views: an MPO's first two images, or a
/// JPS/PNS split down the middle (right | left unless a JPS descriptor says left first).
///
/// # Errors
/// `Io`/`Parse` naming the file: unreadable, not the format its name says, an odd width, or
/// a JPS layout other than side by side.
pub fn read_stereo(path: &Path) -> Result<(RgbaImage, RgbaImage)> {
    use stereolab_core::{MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE};
    let format = PhotoFormat::from_path(path).ok_or_else(|| {
        Error::invalid("stereo photo", path.display(), "name it .mpo, .jps or .pns")
    })?;
    // A JPEG of the largest accepted image stays well under 4 bytes a pixel.
    let bytes = stereolab_core::read_input(path, MAX_IMAGE_PIXELS * 4)?;
    let decode = |data: &[u8], fmt: image::ImageFormat| -> Result<RgbaImage> {
        let mut r = image::ImageReader::with_format(Cursor::new(data), fmt);
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_IMAGE_SIDE);
        limits.max_image_height = Some(MAX_IMAGE_SIDE);
        limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16);
        r.limits(limits);
        Ok(r.decode()
            .map_err(|e| Error::parse(path, None, format!("cannot read the image: {e}")))?
            .to_rgba8())
    };
    if format == PhotoFormat::Mpo {
        let images = mpo_images(path, &bytes)?;
        if images.len() < 2 {
            return Err(Error::parse(
                path,
                None,
                "MPO holds one image: no stereo pair",
            ));
        }
        return Ok((
            decode(images[0], image::ImageFormat::Jpeg)?,
            decode(images[1], image::ImageFormat::Jpeg)?,
        ));
    }
    let (fmt, left_first) = if format == PhotoFormat::Jps {
        (image::ImageFormat::Jpeg, jps_left_first(path, &bytes)?)
    } else {
        (image::ImageFormat::Png, false)
    };
    let both = decode(&bytes, fmt)?;
    let (w, h) = both.dimensions();
    if w % 2 != 0 {
        return Err(Error::parse(
            path,
            None,
            format!("{w} px wide: a side-by-side pair has an even width"),
        ));
    }
    let first = image::imageops::crop_imm(&both, 0, 0, w / 2, h).to_image();
    let second = image::imageops::crop_imm(&both, w / 2, 0, w / 2, h).to_image();
    Ok(if left_first {
        (first, second)
    } else {
        (second, first)
    })
}

/// Whether a JPS's `_JPSJPS_` descriptor says "left field first" (no descriptor: right first).
fn jps_left_first(path: &Path, jpeg: &[u8]) -> Result<bool> {
    let mut at = 2;
    while at + 4 <= jpeg.len() && jpeg[at] == 0xFF {
        let marker = jpeg[at + 1];
        let len = u16::from_be_bytes([jpeg[at + 2], jpeg[at + 3]]) as usize;
        if marker == 0xDA || len < 2 {
            break;
        }
        let payload = jpeg.get(at + 4..at + 2 + len).unwrap_or(&[]);
        if marker == 0xE3 && payload.starts_with(b"_JPSJPS_") && payload.len() >= 14 {
            let (flags, layout, kind) = (payload[11], payload[12], payload[13]);
            if kind == 1 && layout != 2 {
                return Err(Error::parse(
                    path,
                    None,
                    format!("JPS layout {layout}: only side by side (2) is read"),
                ));
            }
            return Ok(flags & 0x04 != 0);
        }
        at += 2 + len;
    }
    Ok(false)
}
