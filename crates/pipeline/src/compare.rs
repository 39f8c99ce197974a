//! Image metrics and diff images: coverage mismatch, channel differences, PSNR, depth error;
//! the ASCII coverage map and the `expected | diff | actual` PNG strip; thresholds for
//! `stereolab compare`, and comparing two image files. Beside these exact metrics, the
//! perceptual ꟻLIP ([`flip`]), reported and not a limit unless asked for (`flip=`).

pub mod flip;

use std::path::{Path, PathBuf};

use image::{RgbImage, Rgba, RgbaImage};

use stereolab_core::{Error, Framebuffer, Result};

/// How two framebuffers differ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Pixels compared.
    pub pixels: usize,
    /// Pixels whose covered/uncovered state differs (covered = depth < 1).
    pub coverage_mismatch: usize,
    /// Largest |difference| of any RGB channel, 0..255.
    pub max_channel_diff: u8,
    /// Mean |difference| over RGB channels.
    pub mean_channel_diff: f64,
    /// Peak signal-to-noise ratio in dB over RGB (infinite when identical).
    pub psnr: f64,
    /// Largest |depth difference| where both cover.
    pub max_depth_diff: f32,
}

impl Metrics {
    /// Coverage mismatch as a percentage of all pixels.
    pub fn coverage_mismatch_percent(&self) -> f64 {
        100.0 * self.coverage_mismatch as f64 / self.pixels.max(1) as f64
    }
}

/// Compares two framebuffers of the same size.
///
/// # Errors
/// Different sizes.
pub fn compare(expected: &Framebuffer, actual: &Framebuffer) -> Result<Metrics> {
    same_size(expected, actual)?;
    let mut m = Metrics {
        pixels: expected.color().len(),
        coverage_mismatch: 0,
        max_channel_diff: 0,
        mean_channel_diff: 0.0,
        psnr: f64::INFINITY,
        max_depth_diff: 0.0,
    };
    let mut sum = 0u64;
    let mut sq = 0u64;
    for i in 0..expected.color().len() {
        let (a, b) = (expected.color()[i], actual.color()[i]);
        for c in 0..3 {
            let d = a[c].abs_diff(b[c]);
            m.max_channel_diff = m.max_channel_diff.max(d);
            sum += d as u64;
            sq += (d as u64) * (d as u64);
        }
        let (da, db) = (expected.depth()[i], actual.depth()[i]);
        let (ca, cb) = (da < 1.0, db < 1.0);
        if ca != cb {
            m.coverage_mismatch += 1;
        } else if ca {
            m.max_depth_diff = m.max_depth_diff.max((da - db).abs());
        }
    }
    let n = (3 * m.pixels).max(1) as f64;
    m.mean_channel_diff = sum as f64 / n;
    if sq > 0 {
        m.psnr = 10.0 * (255.0f64 * 255.0 / (sq as f64 / n)).log10();
    }
    Ok(m)
}

/// Depth bit for bit: of the pixels both framebuffers cover, how many hold the very same `f32`
/// (same bits) in both, and how many there are: `(identical, both_covered)`. Depth that is
/// equal only to within a tolerance decides coplanar overlaps differently, so parity of
/// decals and coincident faces needs this count, not [`Metrics::max_depth_diff`].
///
/// # Errors
/// Different sizes.
pub fn depth_bits_identical(
    expected: &Framebuffer,
    actual: &Framebuffer,
) -> Result<(usize, usize)> {
    same_size(expected, actual)?;
    let (mut same, mut both) = (0, 0);
    for (e, a) in expected.depth().iter().zip(actual.depth()) {
        if *e < 1.0 && *a < 1.0 {
            both += 1;
            same += usize::from(e.to_bits() == a.to_bits());
        }
    }
    Ok((same, both))
}

/// Coverage of each pixel: depth < 1 (something was drawn).
pub fn coverage(fb: &Framebuffer) -> Vec<bool> {
    fb.depth().iter().map(|d| *d < 1.0).collect()
}

/// Scotty3D-style ASCII map of two coverage masks: `#` both, `!` extra (actual only),
/// `?` missed (expected only), `.` neither. Only for small rasters: rows longer than
/// `max_width` are cut.
pub fn ascii_map(expected: &[bool], actual: &[bool], width: usize, max_width: usize) -> String {
    let mut s = String::new();
    for (row_e, row_a) in expected.chunks(width).zip(actual.chunks(width)) {
        for (e, a) in row_e.iter().zip(row_a).take(max_width) {
            s.push(match (e, a) {
                (true, true) => '#',
                (false, true) => '!',
                (true, false) => '?',
                (false, false) => '.',
            });
        }
        s.push('\n');
    }
    s
}

/// An image of where two framebuffers differ: black where equal, the per-pixel maximum channel
/// difference amplified ×8 in red, coverage mismatches in full yellow.
pub fn diff_image(expected: &Framebuffer, actual: &Framebuffer) -> RgbaImage {
    RgbaImage::from_fn(expected.width(), expected.height(), |x, y| {
        let i = expected.index(x, y);
        let (a, b) = (expected.color()[i], actual.color()[i]);
        if (expected.depth()[i] < 1.0) != (actual.depth()[i] < 1.0) {
            return Rgba([255, 255, 0, 255]);
        }
        let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        Rgba([d.saturating_mul(8), 0, 0, 255])
    })
}

/// Height of the caption band above each panel of a diff strip, in pixels.
const CAPTION_HEIGHT: u32 = 22;
/// Pixels between two panels of a diff strip.
const PANEL_GAP: u32 = 4;
/// Small pictures are enlarged (nearest neighbour, whole pixels) to at least this width per
/// panel, so that a 64×48 grading picture can be seen.
const MIN_PANEL_WIDTH: u32 = 240;

/// The enlargement of a `width`-pixel-wide picture in a diff strip (1 to 8).
pub fn strip_scale(width: u32) -> u32 {
    MIN_PANEL_WIDTH.div_ceil(width.max(1)).clamp(1, 8)
}

/// The size of the diff strip of `width`×`height` pictures: three enlarged panels side by side
/// with gaps, under a caption band.
pub fn strip_size(width: u32, height: u32) -> (u32, u32) {
    let k = strip_scale(width);
    (3 * width * k + 2 * PANEL_GAP, height * k + CAPTION_HEIGHT)
}

/// Writes `expected | diff | actual` side by side as `DIR/NAME.png`, each panel captioned and
/// small pictures enlarged ([`strip_size`]); returns the path.
///
/// # Errors
/// Different sizes or an unwritable folder.
pub fn write_diff_strip(
    expected: &Framebuffer,
    actual: &Framebuffer,
    dir: &Path,
    name: &str,
) -> Result<PathBuf> {
    compare(expected, actual)?;
    let (w, h) = (expected.width(), expected.height());
    let k = strip_scale(w);
    let (sw, sh) = strip_size(w, h);
    let diff = diff_image(expected, actual);
    let panels = [
        (expected.to_rgba_image(), "expected"),
        (diff, "difference ×8, yellow: coverage"),
        (actual.to_rgba_image(), "actual"),
    ];
    let mut strip = RgbaImage::from_pixel(sw, sh, Rgba([48, 48, 48, 255]));
    for (i, (img, label)) in panels.iter().enumerate() {
        let x0 = i as u32 * (w * k + PANEL_GAP);
        let band = stereolab_core::caption(w * k, CAPTION_HEIGHT, label, 14.0, [32, 32, 32]);
        image::imageops::replace(&mut strip, &band, i64::from(x0), 0);
        for y in 0..h * k {
            for x in 0..w * k {
                strip.put_pixel(x0 + x, CAPTION_HEIGHT + y, *img.get_pixel(x / k, y / k));
            }
        }
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let path = dir.join(format!("{name}.png"));
    stereolab_core::write_png(&path, &strip)?;
    Ok(path)
}

/// One compared image pair: what it is, how it differs, where its diff strip went.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// What was compared, e.g. `left pass` or `side_by_side`.
    pub name: String,
    /// The metrics.
    pub metrics: Metrics,
    /// False when the images carry no depth (PNG files, layouts): depth is not reported.
    pub has_depth: bool,
    /// The `expected | diff | actual` strip, when one was written.
    pub strip: Option<PathBuf>,
    /// Images with 16 bits per channel are compared at 16 bits: this is the largest channel
    /// difference in 16-bit levels (0..=65535), and the metrics give the mean difference in
    /// 8-bit steps (fractional), the PSNR against 65535, and the largest difference rounded up
    /// to 8-bit steps (so that any difference shows). `None`: compared at 8 bits.
    pub max_levels_16: Option<u16>,
    /// The two pictures compared (RGB, 8 bits per channel), kept for ꟻLIP until [`add_flip`]
    /// measures them; `None` once measured or when not kept.
    pub pictures: Option<Box<[RgbImage; 2]>>,
    /// The ꟻLIP of the pair, once [`add_flip`] has measured it.
    pub flip: Option<FlipResult>,
}

/// ꟻLIP of one compared pair: the statistics of its error map, and where the map's picture went.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipResult {
    /// Mean and percentiles of the per-pixel error.
    pub stats: flip::FlipStats,
    /// The error map in the magma color map (`DIR/<row>.flip.png`), when written.
    pub map: Option<PathBuf>,
}

/// The pictures of two framebuffers, as [`Comparison::pictures`] keeps them.
pub fn pictures(expected: &Framebuffer, actual: &Framebuffer) -> Option<Box<[RgbImage; 2]>> {
    Some(Box::new([flip::rgb(expected), flip::rgb(actual)]))
}

/// A row's name as a file name: letters, digits, `-` and `.` kept, every other run of
/// characters one `_` (`anaglyph (wgsl)` → `anaglyph_wgsl`).
pub fn file_stem_of(name: &str) -> String {
    let mut s = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
            s.push(c);
        } else if !s.ends_with('_') {
            s.push('_');
        }
    }
    let s = s.trim_matches('_');
    if s.is_empty() {
        "image".into()
    } else {
        s.into()
    }
}

/// Bytes ꟻLIP takes for each pixel of a compared pair: its working images (NVIDIA's
/// implementation holds several float copies of both pictures) and the error map, from the peak
/// resident memory of `compare` on a 4096×4096 pair (104 bytes a pixel), rounded up.
pub const FLIP_BYTES_PER_PIXEL: u64 = 128;

/// Measures ꟻLIP on every row that kept its pictures ([`Comparison::pictures`], dropped once
/// measured), at `ppd` pixels per degree, several rows at once. A pair that would take more than
/// `budget` bytes ([`FLIP_BYTES_PER_PIXEL`]) is not measured; the sentences returned say which
/// and why. With `out`, each row's error map is written as `out/<row>.flip.png` in the magma
/// color map ([`file_stem_of`] names it), all of them or none (one
/// [`OutputSet`](stereolab_core::OutputSet)).
///
/// # Errors
/// Pictures of different sizes, a bad `ppd`, or an unwritable folder.
pub fn add_flip(
    rows: &mut [Comparison],
    ppd: f64,
    out: Option<&Path>,
    budget: u64,
) -> Result<Vec<String>> {
    use rayon::prelude::*;
    let mut skipped = Vec::new();
    for r in rows.iter_mut() {
        let Some([e, _]) = r.pictures.as_deref() else {
            continue;
        };
        let need = u64::from(e.width()) * u64::from(e.height()) * FLIP_BYTES_PER_PIXEL;
        if need > budget {
            skipped.push(format!(
                "{}: ꟻLIP not measured: a {}×{} pair needs about {} MiB, more than the {} MiB \
                 it may take",
                r.name,
                e.width(),
                e.height(),
                need >> 20,
                budget >> 20
            ));
            r.pictures = None;
        }
    }
    let maps = rows
        .par_iter_mut()
        .map(|r| {
            let Some(p) = r.pictures.take() else {
                return Ok(None);
            };
            let [e, a] = *p;
            let errors = flip::error_map(&e, &a, ppd)?;
            r.flip = Some(FlipResult {
                stats: flip::FlipStats::of(&errors),
                map: None,
            });
            let picture = out
                .map(|_| flip::magma(&errors, e.width(), e.height()))
                .transpose()?;
            Ok(picture)
        })
        .collect::<Result<Vec<_>>>()?;
    let Some(dir) = out else {
        return Ok(skipped);
    };
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let mut set = stereolab_core::OutputSet::new();
    let mut names = Vec::new();
    for (i, map) in maps.iter().enumerate() {
        if let Some(map) = map {
            let path = dir.join(format!("{}.flip.png", file_stem_of(&rows[i].name)));
            set.stage_png(&path, map)?;
            names.push((i, path));
        }
    }
    set.commit()?;
    for (i, path) in names {
        if let Some(f) = rows[i].flip.as_mut() {
            f.map = Some(path);
        }
    }
    Ok(skipped)
}

/// The comparisons as an aligned table, one row each.
pub fn table(rows: &[Comparison]) -> String {
    use std::fmt::Write as _;
    let mut s = format!(
        "{:<24} {:>12} {:>9} {:>9} {:>9} {:>11}\n",
        "image", "coverage %", "max diff", "mean diff", "PSNR dB", "max depth"
    );
    for r in rows {
        let m = &r.metrics;
        let depth = if r.has_depth {
            format!("{:.3e}", m.max_depth_diff)
        } else {
            "-".into()
        };
        let _ = writeln!(
            s,
            "{:<24} {:>12.5} {:>9} {:>9.4} {:>9.2} {:>11}",
            r.name,
            m.coverage_mismatch_percent(),
            m.max_channel_diff,
            m.mean_channel_diff,
            m.psnr,
            depth
        );
        if let Some(f) = &r.flip {
            let f = &f.stats;
            let [p50, p95, p99, max] = [f.p50, f.p95, f.p99, f.max].map(f64::from);
            let _ = writeln!(
                s,
                "{:<24} ꟻLIP mean {}  median {}  95% {}  99% {}  max {}",
                "",
                flip_figure(f.mean),
                flip_figure(p50),
                flip_figure(p95),
                flip_figure(p99),
                flip_figure(max)
            );
        }
        if let Some(levels) = r.max_levels_16 {
            let _ = writeln!(
                s,
                "{:<24} compared at 16 bits: max diff {levels} of 65535 levels (above in 8-bit steps, rounded up)",
                ""
            );
        }
    }
    s
}

/// A ꟻLIP error (0..1) for the table: four decimals, or three significant digits below 0.001 so
/// that a difference of a few pixels does not print as zero.
fn flip_figure(v: f64) -> String {
    if v == 0.0 || v >= 1e-3 {
        format!("{v:.4}")
    } else {
        format!("{v:.2e}")
    }
}

/// Limits past which `stereolab compare` exits non-zero. The defaults are the GPU parity
/// targets (docs/gpu-parity.md has the measured figures they leave room for).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thresholds {
    /// Largest coverage mismatch, % of pixels (`coverage=`). Target: 0.1 (≥ 99.9% identical).
    pub coverage_percent: f64,
    /// Largest channel difference, 0..255 (`max=`).
    pub max_channel: u8,
    /// Largest mean channel difference (`mean=`).
    pub mean_channel: f64,
    /// Smallest PSNR in dB (`psnr=`).
    pub min_psnr: f64,
    /// Largest depth difference where both cover (`depth=`). Target: 1e-5.
    pub max_depth: f32,
    /// Largest mean ꟻLIP error, 0..1 (`flip=`); `None`, the default: ꟻLIP is reported only.
    pub max_flip_mean: Option<f64>,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            coverage_percent: 0.1,
            max_channel: 255,
            mean_channel: 1.0,
            min_psnr: 30.0,
            max_depth: 1e-5,
            max_flip_mean: None,
        }
    }
}

impl Thresholds {
    /// Applies one `KEY=VALUE` setting (`coverage`, `max`, `mean`, `psnr`, `depth`, `flip`).
    ///
    /// # Errors
    /// An unknown key or a value that is not a number in range.
    pub fn set(&mut self, spec: &str) -> Result<()> {
        let bad = |why: &str| Error::invalid("--threshold", spec, why.to_string());
        let (key, value) = spec
            .split_once('=')
            .ok_or_else(|| bad("expected KEY=VALUE, e.g. coverage=0.1"))?;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| bad("the value must be a number"))?;
        if !v.is_finite() || v < 0.0 {
            return Err(bad("the value must be a finite number ≥ 0"));
        }
        match key.trim() {
            "coverage" => self.coverage_percent = v,
            "max" if v <= 255.0 => self.max_channel = v as u8,
            "max" => return Err(bad("max is a channel difference in 0..=255")),
            "mean" => self.mean_channel = v,
            "psnr" => self.min_psnr = v,
            "depth" => self.max_depth = v as f32,
            "flip" if v <= 1.0 => self.max_flip_mean = Some(v),
            "flip" => return Err(bad("flip is a mean ꟻLIP error in 0..=1")),
            _ => return Err(bad("known keys: coverage, max, mean, psnr, depth, flip")),
        }
        Ok(())
    }

    /// Every limit a comparison exceeds, one sentence each: the row's name, what differs and
    /// by how much, how far past its limit, and the `--threshold` key that moves the limit
    /// (e.g. `left pass: PSNR 20.00 dB, 10.00 dB under the least allowed 30 dB (psnr=)`).
    pub fn violations(&self, rows: &[Comparison]) -> Vec<String> {
        let mut v = Vec::new();
        for r in rows {
            let m = &r.metrics;
            let mut fail = |sentence: String| v.push(format!("{}: {sentence}", r.name));
            let coverage = m.coverage_mismatch_percent();
            if coverage > self.coverage_percent {
                fail(format!(
                    "coverage differs on {coverage:.5}% of the pixels (drawn in one image, \
                     background in the other), {:.5} points over the limit of {}% (coverage=)",
                    coverage - self.coverage_percent,
                    self.coverage_percent
                ));
            }
            if m.max_channel_diff > self.max_channel {
                fail(format!(
                    "a color channel differs by {} levels, {} over the limit of {} (max=)",
                    m.max_channel_diff,
                    m.max_channel_diff - self.max_channel,
                    self.max_channel
                ));
            }
            if m.mean_channel_diff > self.mean_channel {
                fail(format!(
                    "the color channels differ by {:.4} levels on average, {:.4} over the \
                     limit of {} (mean=)",
                    m.mean_channel_diff,
                    m.mean_channel_diff - self.mean_channel,
                    self.mean_channel
                ));
            }
            if m.psnr < self.min_psnr {
                fail(format!(
                    "PSNR {:.2} dB, {:.2} dB under the least allowed {} dB (psnr=)",
                    m.psnr,
                    self.min_psnr - m.psnr,
                    self.min_psnr
                ));
            }
            if r.has_depth && m.max_depth_diff > self.max_depth {
                fail(format!(
                    "the depth differs by up to {:.3e} where both images cover, {:.3e} over \
                     the limit of {:e} (depth=)",
                    m.max_depth_diff,
                    m.max_depth_diff - self.max_depth,
                    self.max_depth
                ));
            }
            if let (Some(limit), Some(f)) = (self.max_flip_mean, &r.flip)
                && f.stats.mean > limit
            {
                fail(format!(
                    "mean ꟻLIP error {:.4}, {:.4} over the limit of {limit} (flip=)",
                    f.stats.mean,
                    f.stats.mean - limit
                ));
            }
        }
        v
    }
}

/// A framebuffer from an image without depth: a pixel counts as covered (depth 0) when it
/// differs from `background` in RGB, uncovered (depth 1) otherwise, so that coverage mismatch
/// means "drawn in one image, background in the other".
///
/// # Errors
/// An image larger than a framebuffer may be.
pub fn framebuffer_from_image(img: &RgbaImage, background: [u8; 4]) -> Result<Framebuffer> {
    let color: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    let depth = color
        .iter()
        .map(|c| if c[..3] == background[..3] { 1.0 } else { 0.0 })
        .collect();
    Framebuffer::from_buffers(img.width(), img.height(), color, depth)
}

/// Loads any image the `image` crate reads (PNG, PPM, GIF) as RGBA8.
///
/// # Errors
/// The file cannot be read or decoded.
pub fn load_image(path: &Path) -> Result<RgbaImage> {
    let img = stereolab_core::open_image(path, "image")?;
    Ok(img.to_rgba8())
}

/// Compares two image files (a student's screenshot against the reference render, say). Each
/// image's background is `background` when given, else its own top-left pixel. Writes the
/// `expected | diff | actual` strip into `out` when given.
///
/// # Errors
/// Unreadable files, or images of different sizes.
pub fn compare_images(
    expected: &Path,
    actual: &Path,
    background: Option<[u8; 4]>,
    out: Option<&Path>,
) -> Result<Comparison> {
    let (de, da) = (
        stereolab_core::open_output_image(expected, "image")?,
        stereolab_core::open_output_image(actual, "image")?,
    );
    let to_fb = |img: &image::DynamicImage| -> Result<Framebuffer> {
        let img = img.to_rgba8();
        let bg = background.unwrap_or_else(|| img.get_pixel(0, 0).0);
        framebuffer_from_image(&img, bg)
    };
    let (e, a) = (to_fb(&de)?, to_fb(&da)?);
    let deep = is_16_bit(&de) || is_16_bit(&da);
    let metrics = compare(&e, &a).map_err(|err| match err {
        Error::Invalid { value, .. } => Error::invalid(
            format!("{} vs {}", expected.display(), actual.display()),
            value,
            "images must have the same size",
        ),
        other => other,
    })?;
    let name = actual
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    let strip = out
        .map(|dir| write_diff_strip(&e, &a, dir, &format!("{name}-diff")))
        .transpose()?;
    let (metrics, max_levels_16) = if deep {
        let bg16 = background.map(|b| b.map(|c| u16::from(c) * 257));
        let (m, max) = compare_16(&de.to_rgba16(), &da.to_rgba16(), bg16);
        (m, Some(max))
    } else {
        (metrics, None)
    };
    Ok(Comparison {
        name,
        metrics,
        has_depth: false,
        strip,
        max_levels_16,
        pictures: Some(Box::new([de.to_rgb8(), da.to_rgb8()])),
        flip: None,
    })
}

/// Compares two stereo photos (MPO, JPS or PNS, in any combination) eye by eye: each file is
/// split into its left and right views
/// ([`read_stereo`](crate::output::stereo_photo::read_stereo)), and the views are compared as
/// [`compare_views`] does; rows `<actual>-left` and `<actual>-right`.
///
/// # Errors
/// Unreadable files, or views of different sizes.
pub fn compare_stereo_photos(
    expected: &Path,
    actual: &Path,
    background: Option<[u8; 4]>,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    use crate::output::stereo_photo::read_stereo;
    let (e, a) = (read_stereo(expected)?, read_stereo(actual)?);
    compare_views(expected, actual, [e, a], background, out)
}

/// Compares two stereo pictures eye by eye, given as their views `[(expected left, expected
/// right), (actual left, actual right)]` (from the files `expected` and `actual`, which name
/// the rows and errors): each view as [`compare_images`] compares two files; rows
/// `<actual>-left` and `<actual>-right`, strips `<actual>-left-diff.png` and
/// `<actual>-right-diff.png`.
///
/// # Errors
/// Views of different sizes, or an unwritable folder.
pub fn compare_views(
    expected: &Path,
    actual: &Path,
    views: [(RgbaImage, RgbaImage); 2],
    background: Option<[u8; 4]>,
    out: Option<&Path>,
) -> Result<Vec<Comparison>> {
    let [e, a] = views;
    let stem = actual
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    [("left", &e.0, &a.0), ("right", &e.1, &a.1)]
        .into_iter()
        .map(|(eye, ei, ai)| {
            let to_fb = |img: &RgbaImage| {
                let bg = background.unwrap_or_else(|| img.get_pixel(0, 0).0);
                framebuffer_from_image(img, bg)
            };
            let (ef, af) = (to_fb(ei)?, to_fb(ai)?);
            let metrics = compare(&ef, &af).map_err(|err| match err {
                Error::Invalid { value, .. } => Error::invalid(
                    format!("{} vs {} ({eye} eye)", expected.display(), actual.display()),
                    value,
                    "views must have the same size",
                ),
                other => other,
            })?;
            let name = format!("{stem}-{eye}");
            let strip = out
                .map(|dir| write_diff_strip(&ef, &af, dir, &format!("{name}-diff")))
                .transpose()?;
            Ok(Comparison {
                name,
                metrics,
                has_depth: false,
                strip,
                max_levels_16: None,
                pictures: pictures(&ef, &af),
                flip: None,
            })
        })
        .collect()
}

/// Whether an image holds 16 bits per channel (16-bit PNG or PGM, as depth maps often are).
fn is_16_bit(img: &image::DynamicImage) -> bool {
    use image::ColorType::{L16, La16, Rgb16, Rgba16};
    matches!(img.color(), L16 | La16 | Rgb16 | Rgba16)
}

/// The metrics of two same-sized images at 16 bits per channel (see
/// [`Comparison::max_levels_16`]); a pixel is covered when it differs from the background
/// (`background`, else each image's top-left pixel). Returns the metrics and the largest
/// difference in 16-bit levels.
fn compare_16(
    expected: &image::ImageBuffer<image::Rgba<u16>, Vec<u16>>,
    actual: &image::ImageBuffer<image::Rgba<u16>, Vec<u16>>,
    background: Option<[u16; 4]>,
) -> (Metrics, u16) {
    let bg_e = background.unwrap_or_else(|| expected.get_pixel(0, 0).0);
    let bg_a = background.unwrap_or_else(|| actual.get_pixel(0, 0).0);
    let (mut max, mut sum, mut sq, mut mismatch) = (0u16, 0u64, 0u128, 0usize);
    for (pe, pa) in expected.pixels().zip(actual.pixels()) {
        for c in 0..3 {
            let d = pe[c].abs_diff(pa[c]);
            max = max.max(d);
            sum += u64::from(d);
            sq += u128::from(d) * u128::from(d);
        }
        if (pe.0[..3] != bg_e[..3]) != (pa.0[..3] != bg_a[..3]) {
            mismatch += 1;
        }
    }
    let pixels = (expected.width() as usize) * (expected.height() as usize);
    let n = (3 * pixels).max(1) as f64;
    let psnr = if sq == 0 {
        f64::INFINITY
    } else {
        10.0 * (65535.0f64 * 65535.0 / (sq as f64 / n)).log10()
    };
    let metrics = Metrics {
        pixels,
        coverage_mismatch: mismatch,
        max_channel_diff: u8::try_from(max.div_ceil(257)).unwrap_or(u8::MAX),
        mean_channel_diff: sum as f64 / n / 257.0,
        psnr,
        max_depth_diff: 0.0,
    };
    (metrics, max)
}

/// Refuses two framebuffers of different sizes, naming both.
fn same_size(expected: &Framebuffer, actual: &Framebuffer) -> Result<()> {
    if (expected.width(), expected.height()) != (actual.width(), actual.height()) {
        return Err(Error::invalid(
            "compare",
            format!(
                "{}x{} vs {}x{}",
                expected.width(),
                expected.height(),
                actual.width(),
                actual.height()
            ),
            "images must have the same size",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(coverage_mismatch: usize, max: u8, mean: f64, psnr: f64, depth: f32) -> Metrics {
        Metrics {
            pixels: 1000,
            coverage_mismatch,
            max_channel_diff: max,
            mean_channel_diff: mean,
            psnr,
            max_depth_diff: depth,
        }
    }

    fn row(m: Metrics, has_depth: bool) -> Comparison {
        Comparison {
            name: "left pass".into(),
            metrics: m,
            has_depth,
            strip: None,
            max_levels_16: None,
            pictures: None,
            flip: None,
        }
    }

    #[test]
    fn thresholds_pass_identical_images_and_name_every_exceeded_limit() {
        let t = Thresholds::default();
        assert!(
            t.violations(&[row(metrics(0, 0, 0.0, f64::INFINITY, 0.0), true)])
                .is_empty()
        );
        let bad = t.violations(&[row(metrics(2, 9, 2.0, 20.0, 1e-3), true)]);
        assert_eq!(bad.len(), 4, "coverage 0.2%, mean, PSNR, depth: {bad:?}");
        assert_eq!(
            bad[0],
            "left pass: coverage differs on 0.20000% of the pixels (drawn in one image, \
             background in the other), 0.10000 points over the limit of 0.1% (coverage=)"
        );
        assert_eq!(
            bad[2],
            "left pass: PSNR 20.00 dB, 10.00 dB under the least allowed 30 dB (psnr=)"
        );
        assert!(
            bad[3].contains("depth differs by up to 1.000e-3"),
            "{}",
            bad[3]
        );
        // Without depth (PNG files), depth is not judged.
        let no_depth = t.violations(&[row(metrics(0, 0, 0.0, 90.0, 1.0), false)]);
        assert!(no_depth.is_empty(), "{no_depth:?}");
    }

    #[test]
    fn threshold_settings_parse_and_bad_ones_are_named() {
        let mut t = Thresholds::default();
        t.set("coverage=0.5").expect("valid");
        t.set("max=3").expect("valid");
        t.set("depth=1e-4").expect("valid");
        assert_eq!(
            (t.coverage_percent, t.max_channel, t.max_depth),
            (0.5, 3, 1e-4)
        );
        for bad in [
            "coverage",
            "colour=1",
            "max=256",
            "psnr=-1",
            "mean=abc",
            "depth=inf",
        ] {
            let e = t.set(bad).expect_err(bad).to_string();
            assert!(e.contains(bad), "the message names the setting: {e}");
        }
    }

    #[test]
    fn image_coverage_is_whatever_differs_from_the_background() {
        let bg = [10, 20, 30, 255];
        let img = RgbaImage::from_fn(3, 1, |x, _| match x {
            0 => Rgba(bg),
            1 => Rgba([10, 20, 31, 255]),
            _ => Rgba([10, 20, 30, 0]), // alpha is ignored
        });
        let fb = framebuffer_from_image(&img, bg).expect("a 3x1 image");
        assert_eq!(coverage(&fb), vec![false, true, false]);
    }

    #[test]
    fn comparing_two_image_files_reports_differences_and_writes_the_strip() {
        let dir = std::env::temp_dir().join(format!("stereolab-compare-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let bg = Rgba([0, 0, 0, 255]);
        let a = RgbaImage::from_fn(8, 8, |x, y| {
            if (2..5).contains(&x) && (2..5).contains(&y) {
                Rgba([200, 100, 50, 255])
            } else {
                bg
            }
        });
        let mut b = a.clone();
        b.put_pixel(6, 6, Rgba([200, 100, 50, 255])); // one extra covered pixel
        b.put_pixel(3, 3, Rgba([204, 100, 50, 255])); // one color off by 4
        let (pa, pb) = (dir.join("expected.png"), dir.join("actual.png"));
        a.save(&pa).expect("write");
        b.save(&pb).expect("write");
        let c = compare_images(&pa, &pb, None, Some(&dir)).expect("compare");
        assert_eq!(c.metrics.coverage_mismatch, 1);
        assert_eq!(c.metrics.max_channel_diff, 200);
        assert!(c.strip.as_ref().is_some_and(|p| p.exists()));
        let small = RgbaImage::new(4, 4);
        let pc = dir.join("small.png");
        small.save(&pc).expect("write");
        let e = compare_images(&pa, &pc, None, None)
            .expect_err("sizes differ")
            .to_string();
        assert!(e.contains("8x8 vs 4x4"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
