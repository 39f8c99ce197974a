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
//! the final name, never a truncated one. Several files that belong together (a render's
//! outputs, the figures, a handout) go through one [`OutputSet`]: all are written before any is
//! renamed. A signal handler removes the temporary files of an interrupted run
//! ([`remove_temporaries`]); a `.NAME.tmp-…` left by a killed one (SIGKILL) is removed by a
//! later run writing to that folder once it is provably stale ([`remove_stale_temporaries`]).
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

/// What every temporary file's name holds after the final name: `.NAME.tmp-PID-STAMP-N`.
const TEMPORARY_TAG: &str = ".tmp-";

/// How long a temporary file must have been left untouched before a later run may remove it
/// (besides its owner being this user and its process being gone).
pub const STALE_AFTER: std::time::Duration = std::time::Duration::from_secs(600);

/// The temporary files this process is writing, for [`remove_temporaries`].
static LIVE: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Removes every temporary file this process is writing and returns how many there were; any
/// write still under way then fails instead of renaming. A signal handler calls it before the
/// process exits (`stereolab`'s SIGINT, SIGTERM and SIGHUP), so that an interrupted run leaves
/// nothing behind. The list then stays locked until the process ends, so that no new
/// temporary file can start.
pub fn remove_temporaries() -> usize {
    let mut files = live();
    let n = files.len();
    for f in files.drain(..) {
        let _ = remove_temporary(&f);
    }
    std::mem::forget(files);
    n
}

/// A stamp of this process's start, in the temporary names: with the PID it tells this run's
/// files from those of an earlier process that had the same PID.
fn process_stamp() -> u64 {
    static STAMP: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *STAMP.get_or_init(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64)
    })
}

/// Creates a new temporary file beside `path`, `.NAME.tmp-PID-STAMP-N` in the same folder (so
/// the rename is atomic: same file system), and registers it for [`remove_temporaries`]. A
/// name that exists already (a file left by a process that had this PID) is never opened:
/// the next number is tried.
fn create_temporary(path: &Path) -> std::io::Result<(PathBuf, File)> {
    let mut file = None;
    let tmp = create_temporary_with(path, |tmp| {
        file = Some(File::options().write(true).create_new(true).open(tmp)?);
        Ok(())
    })?;
    let file = file.ok_or_else(|| std::io::Error::other("no temporary file"))?;
    Ok((tmp, file))
}

/// Tries `create` on temporary names beside `path` until one does not exist yet; registers
/// the one made.
fn create_temporary_with(
    path: &Path,
    mut create: impl FnMut(&Path) -> std::io::Result<()>,
) -> std::io::Result<PathBuf> {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map_or_else(|| "output".into(), |n| n.to_string_lossy());
    loop {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let tmp = path.with_file_name(format!(
            ".{name}{TEMPORARY_TAG}{}-{:x}-{n}",
            std::process::id(),
            process_stamp()
        ));
        let mut files = live();
        match create(&tmp) {
            Ok(()) => {
                files.push(tmp.clone());
                return Ok(tmp);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 1 << 20 => {}
            Err(e) => return Err(e),
        }
    }
}

/// Removes a temporary file or folder.
fn remove_temporary(tmp: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(tmp) {
        Ok(m) if m.is_dir() => std::fs::remove_dir_all(tmp),
        _ => std::fs::remove_file(tmp),
    }
}

/// Forgets the temporary `tmp` (renamed or removed).
fn unregister(tmp: &Path) {
    live().retain(|f| f != tmp);
}

/// Whether the process `pid` is alive (or exists but is not ours to signal).
#[cfg(unix)]
fn process_alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    // SAFETY: signal 0 only checks whether the process exists and may be signalled.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Removes the temporary files (and [`StagingDir`] folders) in `dir` that are provably stale: named as [`write_atomic`]
/// names them, owned by this user, untouched for [`STALE_AFTER`], and written by a process
/// that no longer exists. Returns how many it removed. Anything else (another user's file, a
/// live writer's, a recent one) is left alone.
pub fn remove_stale_temporaries(dir: &Path) -> usize {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temporary_pid) else {
            continue;
        };
        let Ok(meta) = entry.path().symlink_metadata() else {
            continue;
        };
        let old = meta
            .modified()
            .ok()
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age >= STALE_AFTER);
        #[cfg(unix)]
        let stale = {
            use std::os::unix::fs::MetadataExt;
            // SAFETY: geteuid has no preconditions.
            let me = unsafe { libc::geteuid() };
            (meta.is_file() || meta.is_dir()) && meta.uid() == me && old && !process_alive(pid)
        };
        #[cfg(not(unix))]
        let stale = (meta.is_file() || meta.is_dir()) && old && pid != std::process::id();
        if stale && remove_temporary(&entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// The PID in a temporary file's name (`.NAME.tmp-PID-STAMP-N`), or `None` for other names.
fn temporary_pid(name: &str) -> Option<u32> {
    let rest = &name[name.rfind(TEMPORARY_TAG)? + TEMPORARY_TAG.len()..];
    let mut parts = rest.split('-');
    let pid = parts.next()?.parse().ok()?;
    let stamp = parts.next()?;
    let n = parts.next()?;
    let ok = name.starts_with('.')
        && parts.next().is_none()
        && u64::from_str_radix(stamp, 16).is_ok()
        && n.parse::<u64>().is_ok();
    ok.then_some(pid)
}

/// Files written together or not at all: each [`stage`](OutputSet::stage) writes one to a
/// temporary file beside its final name (synced to disk), and [`commit`](OutputSet::commit)
/// renames them all onto their names once every one is written. A set dropped before its
/// commit (an error, a panic) removes its temporary files and leaves every final name as it
/// was. The renames are the only step that can fail half way, and a rename within a folder
/// needs no space.
#[derive(Debug, Default)]
pub struct OutputSet {
    staged: Vec<(PathBuf, PathBuf)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Writes the file that will become `path` with `write`, through a temporary file beside
    /// it. `write` may fail with any error; it is returned as it is.
    ///
    /// # Errors
    /// `path` is refused ([`check_output_path`]), `write` failed, or creating, flushing or
    /// syncing the temporary file failed (it is removed).
    pub fn stage(
        &mut self,
        path: &Path,
        write: impl FnOnce(&mut (dyn Write + Send)) -> Result<()>,
    ) -> Result<()> {
        check_output_path(path)?;
        if let Some(dir) = path.parent() {
            remove_stale_temporaries(if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            });
        }
        let io = |e: std::io::Error| Error::io(path, e);
        let (tmp, file) = create_temporary(path).map_err(io)?;
        let result = (|| -> Result<()> {
            let mut w = BufWriter::with_capacity(1 << 20, file);
            write(&mut w)?;
            // `into_inner` flushes and reports what the flush met; a drop would discard it.
            let file = w.into_inner().map_err(|e| io(e.into_error()))?;
            file.sync_all().map_err(io)
        })();
        match result {
            Ok(()) => {
                self.staged.push((tmp, path.to_path_buf()));
                Ok(())
            }
            Err(e) => {
                let _ = std::fs::remove_file(&tmp);
                unregister(&tmp);
                Err(e)
            }
        }
    }

    /// [`stage`](OutputSet::stage) of `bytes`.
    ///
    /// # Errors
    /// As [`stage`](OutputSet::stage).
    pub fn stage_bytes(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.stage(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
    }

    /// [`stage`](OutputSet::stage) of an image as PNG.
    ///
    /// # Errors
    /// As [`stage`](OutputSet::stage), or the encoder refused the image.
    pub fn stage_png<P, C>(&mut self, path: &Path, image: &image::ImageBuffer<P, C>) -> Result<()>
    where
        P: image::PixelWithColorType,
        [P::Subpixel]: image::EncodableLayout,
        C: std::ops::Deref<Target = [P::Subpixel]>,
    {
        self.stage(path, |w| {
            image
                .write_with_encoder(image::codecs::png::PngEncoder::new(w))
                .map_err(|e| image_error(path, e))
        })
    }

    /// Renames every staged file onto its name, in the order staged; returns the names.
    ///
    /// # Errors
    /// A final name became a link or a special file meanwhile, or a rename failed: the files
    /// not yet renamed are removed.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let staged = std::mem::take(&mut self.staged);
        let mut done = Vec::with_capacity(staged.len());
        let mut rest = staged.into_iter();
        for (tmp, path) in rest.by_ref() {
            let renamed = check_output_path(&path)
                .and_then(|()| std::fs::rename(&tmp, &path).map_err(|e| Error::io(&path, e)));
            unregister(&tmp);
            if let Err(e) = renamed {
                let _ = std::fs::remove_file(&tmp);
                for (tmp, _) in rest {
                    let _ = std::fs::remove_file(&tmp);
                    unregister(&tmp);
                }
                return Err(e);
            }
            done.push(path);
        }
        Ok(done)
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        for (tmp, _) in self.staged.drain(..) {
            let _ = std::fs::remove_file(&tmp);
            unregister(&tmp);
        }
    }
}

/// A folder written whole or not at all: made as a new temporary folder beside its final name,
/// filled, then put in place by [`commit`](StagingDir::commit). Dropped before its commit (an
/// error), it is removed with everything in it; a signal removes it too
/// ([`remove_temporaries`]). Everything in it was created by this run, so nothing is written
/// through a link planted in an existing folder.
#[derive(Debug)]
pub struct StagingDir {
    path: PathBuf,
    target: PathBuf,
}

impl StagingDir {
    /// A new, empty staging folder for `target` (whose parent folders are created).
    ///
    /// # Errors
    /// `target` is a link or not a folder, or the folder cannot be created.
    pub fn new(target: &Path) -> Result<StagingDir> {
        match std::fs::symlink_metadata(target) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(Error::io(
                    target,
                    std::io::Error::other(
                        "refusing to write the output folder: it is a symbolic link; name the \
                         folder itself",
                    ),
                ));
            }
            Ok(m) if !m.is_dir() => {
                return Err(Error::io(
                    target,
                    std::io::Error::other(
                        "refusing to write the output folder: a file of that name exists",
                    ),
                ));
            }
            _ => {}
        }
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        remove_stale_temporaries(parent);
        let path = create_temporary_with(target, |p| std::fs::create_dir(p))
            .map_err(|e| Error::io(target, e))?;
        Ok(StagingDir {
            path,
            target: target.to_path_buf(),
        })
    }

    /// The folder to fill.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Puts the filled folder in place of its target: renamed onto it when it does not exist;
    /// when it does (an empty folder, or one the caller has agreed to replace), the two are
    /// exchanged in one step where the system can (Linux's `renameat2` with `RENAME_EXCHANGE`)
    /// and the old one is removed.
    ///
    /// # Errors
    /// A rename failed; the target is then as it was, and the staging folder is removed.
    pub fn commit(self) -> Result<()> {
        let io = |e: std::io::Error| Error::io(&self.target, e);
        if std::fs::symlink_metadata(&self.target).is_err() {
            return std::fs::rename(&self.path, &self.target).map_err(io);
        }
        if exchange(&self.path, &self.target).is_err() {
            // Two renames: the target is missing for the moment between them.
            let old = create_temporary_with(&self.target, |p| {
                if p.exists() {
                    Err(std::io::ErrorKind::AlreadyExists.into())
                } else {
                    Ok(())
                }
            })
            .map_err(io)?;
            std::fs::rename(&self.target, &old).map_err(io)?;
            if let Err(e) = std::fs::rename(&self.path, &self.target) {
                let _ = std::fs::rename(&old, &self.target);
                unregister(&old);
                return Err(io(e));
            }
            let _ = remove_temporary(&old);
            unregister(&old);
            return Ok(());
        }
        // The old folder is now at the staging name; the drop removes it.
        Ok(())
    }
}

impl Drop for StagingDir {
    fn drop(&mut self) {
        let _ = remove_temporary(&self.path);
        unregister(&self.path);
    }
}

/// Exchanges the folders `a` and `b` in one step.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        std::ffi::CString::new(p.as_os_str().as_bytes())
            .map_err(|_| std::io::Error::from(std::io::ErrorKind::InvalidInput))
    };
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: two NUL-terminated paths that live across the call.
    let r = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// Exchanges the folders `a` and `b` in one step (not available here).
#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// Writes the file `path` with `write`, all or nothing: through a temporary file beside it,
/// renamed onto `path` only after `write` succeeded and the data reached the disk (an
/// [`OutputSet`] of one). `write` may fail with any error (a render that fails half way
/// through an animation, say); that error is returned as it is.
///
/// # Errors
/// `path` is refused ([`check_output_path`]), `write` failed, or creating, flushing, syncing
/// or renaming failed (the temporary file is removed; `path` is as it was).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut (dyn Write + Send)) -> Result<()>,
) -> Result<()> {
    let mut set = OutputSet::new();
    set.stage(path, write)?;
    set.commit().map(drop)
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
    let mut set = OutputSet::new();
    set.stage_png(path, image)?;
    set.commit().map(drop)
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

    /// A temporary name as [`create_temporary`] makes it, for process `pid`.
    fn temporary_name(final_name: &str, pid: u32) -> String {
        format!(".{final_name}{TEMPORARY_TAG}{pid}-{:x}-0", 12345)
    }

    #[test]
    fn a_set_that_fails_half_way_renames_nothing() {
        let d = dir("set");
        let (a, b) = (d.join("left.png"), d.join("right.png"));
        std::fs::write(&a, b"old left").expect("seed");
        let mut set = OutputSet::new();
        set.stage_bytes(&a, b"new left").expect("first");
        let err = set
            .stage(&b, |_| Err(Error::invalid("test", "right", "disk full")))
            .expect_err("second fails");
        assert!(err.to_string().contains("disk full"), "{err}");
        drop(set);
        assert_eq!(std::fs::read(&a).expect("left"), b"old left");
        assert!(!b.exists());
        assert!(leftovers(&d).is_empty(), "{:?}", leftovers(&d));
        let mut set = OutputSet::new();
        set.stage_bytes(&a, b"new left").expect("first");
        set.stage_bytes(&b, b"new right").expect("second");
        assert_eq!(
            std::fs::read(&a).expect("left"),
            b"old left",
            "not before commit"
        );
        assert_eq!(set.commit().expect("commit"), vec![a.clone(), b.clone()]);
        assert_eq!(std::fs::read(&a).expect("left"), b"new left");
        assert_eq!(std::fs::read(&b).expect("right"), b"new right");
        assert!(leftovers(&d).is_empty());
    }

    #[test]
    fn a_leftover_with_this_processes_pid_does_not_stop_a_write() {
        let d = dir("reuse");
        let path = d.join("out.png");
        // What an earlier process with this PID left: the same PID, another stamp and the
        // numbers this run will use.
        for n in 0..4 {
            let name = format!(".out.png{TEMPORARY_TAG}{}-1-{n}", std::process::id());
            std::fs::write(d.join(name), b"stale").expect("plant");
        }
        write_bytes(&path, b"fresh").expect("write beside a leftover");
        assert_eq!(std::fs::read(&path).expect("out"), b"fresh");
    }

    #[cfg(unix)]
    #[test]
    fn only_provably_stale_temporaries_are_removed() {
        let d = dir("stale");
        // A process that has ended: its PID is free.
        let mut child = std::process::Command::new("true").spawn().expect("spawn");
        let dead = child.id();
        child.wait().expect("wait");
        let old = std::time::SystemTime::now() - STALE_AFTER * 2;
        let plant = |name: String, when: std::time::SystemTime| {
            let p = d.join(name);
            let f = File::create(&p).expect("plant");
            f.set_modified(when).expect("mtime");
            p
        };
        let stale = plant(temporary_name("a.png", dead), old);
        let recent = plant(temporary_name("b.png", dead), std::time::SystemTime::now());
        let live = plant(temporary_name("c.png", std::process::id()), old);
        let other = plant(".a.png.tmp-notapid".to_string(), old);
        let user_file = plant("notes.tmp-1-2-3".to_string(), old);
        assert_eq!(remove_stale_temporaries(&d), 1);
        assert!(!stale.exists());
        for kept in [recent, live, other, user_file] {
            assert!(kept.exists(), "{} must stay", kept.display());
        }
        // A write into the folder cleans it as well.
        let stale = plant(temporary_name("d.png", dead), old);
        write_bytes(&d.join("d.png"), b"x").expect("write");
        assert!(!stale.exists());
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
        // A file outside the tree gets the same answer whether or not it exists, so a scene
        // cannot probe the machine's files by the wording of its errors.
        let refused = || {
            Error::invalid(
                field,
                format!("\"{}\"", excerpt(path)),
                format!(
                    "names no file inside the scene's folder {}: a scene may read only files \
                     in its own folder tree (pass --allow-outside-paths to allow others)",
                    root.display()
                ),
            )
        };
        let inside = |p: &Path| p.starts_with(&root);
        match joined.canonicalize() {
            Ok(full) if inside(&full) => Ok(full),
            Ok(_) => Err(refused()),
            // Missing: said as missing only when the deepest folder of the path that exists,
            // links followed, is inside the tree (and the name is no dangling link).
            Err(e) => {
                let dangling = joined.symlink_metadata().is_ok();
                let lexical = lexical(&root, path);
                let existing = lexical
                    .ancestors()
                    .find(|a| a.symlink_metadata().is_ok())
                    .and_then(|a| a.canonicalize().ok());
                if !dangling && existing.is_some_and(|a| inside(&a)) && inside(&lexical) {
                    Err(Error::io(&joined, e))
                } else {
                    Err(refused())
                }
            }
        }
    }
}

/// `path` joined onto `root` as written, `.` and `..` resolved without the file system (links
/// are not followed: a link's target is judged once it exists).
fn lexical(root: &Path, path: &str) -> PathBuf {
    use std::path::Component;
    let mut out = root.to_path_buf();
    for c in Path::new(path).components() {
        match c {
            Component::RootDir | Component::Prefix(_) => out = PathBuf::from(c.as_os_str()),
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            Component::Normal(n) => out.push(n),
        }
    }
    out
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
