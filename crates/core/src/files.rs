//! Reading input files within bounds, and writing output files so that nothing is lost and
//! nothing half-written is left behind.
//!
//! Every input file (scene, OBJ, terrain CSV, images) is checked by [`check_input`]: a regular
//! file, not a FIFO that would block forever or a device such as `/dev/zero` that never ends;
//! text inputs are read by [`read_input`] with a size limit that holds even if the file grows.
//!
//! Every file stereolab writes goes through [`write_atomic`]: the bytes go to a temporary file
//! in the same folder, every write error (including the last flush, which a `BufWriter`'s drop
//! would swallow) is reported, the data is synced, and only then is the temporary file renamed
//! onto the final name. A failed or killed run therefore leaves the old file (or none) under
//! the final name, never a truncated one; a leftover `.NAME.tmp-…` is all a kill can leave.
//! A final name that is a symbolic link, or exists and is not a regular file, is refused: an
//! output never writes through a link planted in the output folder.

use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Refuses `path` as an output when it is a symbolic link or exists as anything but a regular
/// file (a folder, a device such as `/dev/full`, a FIFO).
///
/// # Errors
/// `Io` naming the path, saying what it is and what to do.
pub fn check_output_path(path: &Path) -> Result<()> {
    let refuse = |what: &str| {
        Error::io(
            path,
            std::io::Error::other(format!(
                "refusing to write the output: it is {what}; remove it or choose another name"
            )),
        )
    };
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() => Err(refuse("a symbolic link")),
        Ok(m) if m.is_dir() => Err(refuse("a folder")),
        Ok(m) if !m.is_file() => Err(refuse("a special file (device, FIFO or socket)")),
        _ => Ok(()),
    }
}

/// Checks that `path` is a regular file (links followed) and returns its size.
///
/// # Errors
/// `Io` naming the path: it does not exist, or it is a folder, a FIFO, a device or a socket.
pub fn check_input(path: &Path) -> Result<u64> {
    let m = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if m.is_file() {
        return Ok(m.len());
    }
    let what = if m.is_dir() {
        "a folder"
    } else {
        "a special file (device, FIFO or socket), which may never end"
    };
    Err(Error::io(
        path,
        std::io::Error::other(format!(
            "refusing to read it: it is {what}; give a regular file"
        )),
    ))
}

/// Reads the regular file `path` whole, refusing it when it is larger than `max_bytes`.
///
/// # Errors
/// As [`check_input`]; `Parse` naming the size and the limit; or the read failed.
pub fn read_input(path: &Path, max_bytes: u64) -> Result<Vec<u8>> {
    let too_large = |size: u64| {
        Error::parse(
            path,
            None,
            format!("file is {size} bytes, more than the {max_bytes} accepted"),
        )
    };
    let size = check_input(path)?;
    if size > max_bytes {
        return Err(too_large(size));
    }
    let mut bytes = Vec::with_capacity(size as usize);
    File::open(path)
        .and_then(|f| f.take(max_bytes + 1).read_to_end(&mut bytes))
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64)); // it grew while being read
    }
    Ok(bytes)
}

/// Opens and decodes the image file `path` (`what` names it in errors, e.g. `depth map`),
/// reading its size from the header first: an image over `max_side` pixels a side or
/// `max_pixels` in all is refused before a pixel is decoded (a 388 KB PNG can claim
/// 20000×20000), and the decoder's allocations are capped to match.
///
/// # Errors
/// As [`check_input`]; `Parse` naming the size and the limit, or what the decoder said.
pub fn open_image(
    path: &Path,
    what: &str,
    max_side: u32,
    max_pixels: u64,
) -> Result<image::DynamicImage> {
    check_input(path)?;
    let unreadable =
        |e: &dyn std::fmt::Display| Error::parse(path, None, format!("cannot read {what}: {e}"));
    let reader = || -> Result<image::ImageReader<std::io::BufReader<File>>> {
        image::ImageReader::open(path)
            .and_then(|r| r.with_guessed_format())
            .map_err(|e| Error::io(path, e))
    };
    let (w, h) = reader()?.into_dimensions().map_err(|e| unreadable(&e))?;
    if w > max_side || h > max_side || u64::from(w) * u64::from(h) > max_pixels {
        return Err(Error::parse(
            path,
            None,
            format!(
                "{what} is {w}x{h}: more than the {max_side} pixels a side or {max_pixels} \
                 pixels in all accepted"
            ),
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(max_side);
    limits.max_image_height = Some(max_side);
    // 16-bit RGBA, the widest layout a decoder produces, plus the same again for conversion.
    limits.max_alloc = Some(max_pixels.saturating_mul(16));
    let mut r = reader()?;
    r.limits(limits);
    r.decode().map_err(|e| unreadable(&e))
}

/// A temporary name beside `path`: `.NAME.tmp-PID-N` in the same folder (so the rename is
/// atomic: same file system), unique within the process.
fn temporary_beside(path: &Path) -> PathBuf {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy());
    path.with_file_name(format!(".{name}.tmp-{}-{n}", std::process::id()))
}

/// Writes the file `path` with `write`, all or nothing: through a temporary file beside it,
/// renamed onto `path` only after `write` succeeded and the data reached the disk. `write` may
/// fail with any error (a render that fails half way through an animation, say); that error is
/// returned as it is.
///
/// # Errors
/// `path` is refused ([`check_output_path`]), `write` failed, or creating, flushing, syncing
/// or renaming failed (the temporary file is removed; `path` is as it was).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut (dyn Write + Send)) -> Result<()>,
) -> Result<()> {
    check_output_path(path)?;
    let tmp = temporary_beside(path);
    let io = |e: std::io::Error| Error::io(path, e);
    let result = (|| -> Result<()> {
        let file = File::options()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(io)?;
        let mut w = BufWriter::with_capacity(1 << 20, file);
        write(&mut w)?;
        // `into_inner` flushes and reports what the flush met; a drop would discard it.
        let file = w.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// [`write_atomic`] of `bytes`.
///
/// # Errors
/// As [`write_atomic`].
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
}

/// An image encoder's error while writing `path`, as the `Io` error it is.
pub fn image_error(path: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::IoError(e) => Error::io(path, e),
        other => Error::io(path, std::io::Error::other(other.to_string())),
    }
}

/// Writes an image as PNG, all or nothing ([`write_atomic`]).
///
/// # Errors
/// As [`write_atomic`], or the encoder refused the image.
pub fn write_png<P, C>(path: &Path, image: &image::ImageBuffer<P, C>) -> Result<()>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    write_atomic(path, |w| {
        image
            .write_with_encoder(image::codecs::png::PngEncoder::new(w))
            .map_err(|e| image_error(path, e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("stereolab-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    #[test]
    fn utf16_is_told_from_utf8_by_its_nul_bytes() {
        let text = "outputs = [\"left\"]\n";
        let le: Vec<u8> = text.encode_utf16().flat_map(u16::to_le_bytes).collect();
        let be: Vec<u8> = text.encode_utf16().flat_map(u16::to_be_bytes).collect();
        assert!(looks_like_utf16(&le) && looks_like_utf16(&be));
        assert!(!looks_like_utf16(text.as_bytes()));
        // All NULs, or too short to tell, is not text of either kind.
        assert!(!looks_like_utf16(&[0; 64]));
        assert!(!looks_like_utf16(b"a\0"));
    }

    fn leftovers(d: &Path) -> Vec<String> {
        std::fs::read_dir(d)
            .expect("read dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp-"))
            .collect()
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let d = dir("failed");
        let path = d.join("precious.ppm");
        std::fs::write(&path, b"precious").expect("seed file");
        let err = write_atomic(&path, |w| {
            w.write_all(b"P6\n1 1\n255\n")
                .map_err(|e| Error::io(&path, e))?;
            Err(Error::invalid("test", "encoder", "gave up half way"))
        })
        .expect_err("must fail");
        assert!(err.to_string().contains("half way"), "{err}");
        assert_eq!(std::fs::read(&path).expect("still there"), b"precious");
        assert!(leftovers(&d).is_empty(), "{:?}", leftovers(&d));
    }

    #[test]
    fn a_successful_write_replaces_the_file_whole() {
        let d = dir("ok");
        let path = d.join("out.bin");
        std::fs::write(&path, b"old and longer").expect("seed file");
        write_bytes(&path, b"new").expect("write");
        assert_eq!(std::fs::read(&path).expect("read"), b"new");
        assert!(leftovers(&d).is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn symbolic_links_and_special_files_are_refused() {
        let d = dir("links");
        let target = d.join("victim.txt");
        std::fs::write(&target, b"keep me").expect("victim");
        let link = d.join("left.png");
        std::os::unix::fs::symlink(&target, &link).expect("symlink");
        let err = write_bytes(&link, b"png").expect_err("a link must be refused");
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read(&target).expect("victim"), b"keep me");
        let err = write_bytes(Path::new("/dev/full"), b"x").expect_err("a device");
        assert!(err.to_string().contains("special file"), "{err}");
        let err = write_bytes(&d, b"x").expect_err("a folder");
        assert!(err.to_string().contains("a folder"), "{err}");
    }
}

/// Where a scene may read the files it names (models, terrain, pattern images): relative paths
/// start at `base` (the scene's folder), and unless outside paths are allowed, the file a path
/// names, with every symbolic link followed, must lie inside `base`'s folder tree. A scene handed
/// in by someone else (a student's, to a grader) thereby reads nothing else on the machine.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputRoot {
    base: PathBuf,
    allow_outside: bool,
}

impl InputRoot {
    /// Paths confined to `base`'s folder tree.
    pub fn confined(base: &Path) -> InputRoot {
        InputRoot {
            base: base.to_path_buf(),
            allow_outside: false,
        }
    }

    /// Paths relative to `base`, anywhere on the machine (`--allow-outside-paths`).
    pub fn anywhere(base: &Path) -> InputRoot {
        InputRoot {
            base: base.to_path_buf(),
            allow_outside: true,
        }
    }

    /// The file `path` (from the scene's field `field`) names.
    ///
    /// # Errors
    /// `Invalid` naming the field when the file lies outside the scene's folder tree (its
    /// contents are never read, so no message can quote them); `Io` when it cannot be found.
    pub fn resolve(&self, field: &str, path: &str) -> Result<PathBuf> {
        let base = if self.base.as_os_str().is_empty() {
            Path::new(".")
        } else {
            &self.base
        };
        let joined = base.join(path);
        if self.allow_outside {
            return Ok(joined);
        }
        let root = base.canonicalize().map_err(|e| Error::io(base, e))?;
        let full = joined.canonicalize().map_err(|e| Error::io(&joined, e))?;
        if full.starts_with(&root) {
            Ok(full)
        } else {
            Err(Error::invalid(
                field,
                format!("\"{}\"", path.escape_debug()),
                format!(
                    "names a file outside the scene's folder {}: a scene may read only files \
                     in its own folder tree (pass --allow-outside-paths to allow it)",
                    root.display()
                ),
            ))
        }
    }
}

/// Longest excerpt of an input line an error message quotes.
pub const EXCERPT_CHARS: usize = 40;

/// A short, printable excerpt of `text` for an error message: at most [`EXCERPT_CHARS`]
/// characters, control characters and quotes escaped, `…` when cut. Messages never quote more
/// of a file than this (the file may not be the user's to show).
pub fn excerpt(text: &str) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == EXCERPT_CHARS {
            out.push('…');
            break;
        }
        out.extend(c.escape_debug());
    }
    out
}

/// [`read_input`] of a UTF-8 text file, without its byte-order mark ([`without_bom`]).
///
/// # Errors
/// As [`read_input`], and `Parse` naming the first byte that is not UTF-8 (or
/// [`UTF16_WITHOUT_BOM`] when the bytes look like UTF-16).
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String> {
    let bytes = read_input(path, max_bytes)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        let message = if looks_like_utf16(e.as_bytes()) {
            UTF16_WITHOUT_BOM.to_string()
        } else {
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to())
        };
        Error::parse(path, None, message)
    })?;
    Ok(without_bom(text))
}

/// What a text reader says of a file that [`looks_like_utf16`]: the encoding and the remedy.
pub const UTF16_WITHOUT_BOM: &str =
    "UTF-16 without a byte-order mark (NUL bytes every other byte); save the file as UTF-8";

/// Whether `bytes` look like UTF-16 text without a byte-order mark: in their first 512 bytes
/// (at least 4), every byte at one parity (odd for little-endian, even for big-endian) is NUL
/// and at most a quarter of the bytes at the other are, the pattern ASCII text has in UTF-16.
pub fn looks_like_utf16(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    if head.len() < 4 {
        return false;
    }
    let nuls_at = |parity: usize| {
        let (mut nul, mut all) = (0usize, 0usize);
        for b in head.iter().skip(parity).step_by(2) {
            all += 1;
            nul += usize::from(*b == 0);
        }
        (nul, all)
    };
    let (even, evens) = nuls_at(0);
    let (odd, odds) = nuls_at(1);
    (odd == odds && even * 4 <= evens) || (even == evens && odd * 4 <= odds)
}

/// `text` without a leading byte-order mark (U+FEFF), which Windows editors write at the start
/// of UTF-8 files and which would otherwise become part of the first word.
pub fn without_bom(text: String) -> String {
    match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_string(),
        None => text,
    }
}
