//! `stereolab inspect`: another program's stereo image read back as two views. The layout is
//! given (`--layout`) or detected, and the report says which was taken and on what evidence.
//!
//! Each layout's inverse is [`split`], the undoing of the matching writer in
//! `stereolab_core`'s layouts (a squeezed view is stretched back by repeating its columns or
//! rows, an interleaved one fills each missing pixel from its neighbour of the same eye, an
//! anaglyph gives each eye the channels its filter passes, as gray). [`detect`] tries the
//! layouts that leave a mark no single view has: the black active space of frame packing, the
//! black blank interval of the squashed above-below format, an anaglyph's edges that sit in
//! different places in different channels, the comb of interleaved rows or columns; then two
//! halves that show the same scene. A picture with none of these is refused, never guessed.

pub mod anaglyph;
pub mod disparity;
pub mod eyes;
pub mod findings;
pub mod picture;

pub use findings::{Finding, Severity};

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec4};
use image::{Rgba, RgbaImage};
use stereolab_core::{Error, Result, frame_packing_active_space};

use crate::output::stereo_photo::{PhotoFormat, read_stereo};

/// How two views share one picture (or two files).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Two files, left then right.
    Pair,
    /// Left | right, each view full size (parallel viewing).
    SideBySide,
    /// Right | left, each view full size (cross-eyed viewing; JPS and PNS order).
    CrossEyed,
    /// Left | right squeezed into one view's width (3D TVs' side-by-side (half)).
    HalfSideBySide,
    /// Left over right, each view full size.
    AboveBelow,
    /// Left over right squeezed into one view's height (top-and-bottom).
    HalfAboveBelow,
    /// Left over right, each squashed to `(H − blank)/2` rows around a black blank interval.
    AboveBelowSquashed,
    /// HDMI 1.4a frame packing: left, `H/24` black rows, right.
    FramePacking,
    /// Even rows left, odd rows right.
    InterlacedRows,
    /// Even columns left, odd columns right.
    InterlacedColumns,
    /// Left where `x + y` is even.
    Checkerboard,
    /// Red for the left eye, green and blue for the right.
    AnaglyphRedCyan,
    /// Green for the left eye, red and blue for the right.
    AnaglyphGreenMagenta,
    /// Red and green (amber) for the left eye, blue for the right.
    AnaglyphAmberBlue,
    /// A CIPA DC-007 multi-picture JPEG (`.mpo`): its first two images.
    Mpo,
    /// A JPEG stereo file (`.jps`): right | left unless its descriptor says otherwise.
    Jps,
    /// A PNG stereo file (`.pns`): right | left.
    Pns,
    /// An animated GIF or PNG (a wiggle, a frame-sequential animation): its first two frames,
    /// left then right.
    Animation,
}

impl Layout {
    /// The layouts `--layout` takes (the containers come from the file name).
    pub const GIVEN: [Layout; 14] = [
        Layout::Pair,
        Layout::SideBySide,
        Layout::CrossEyed,
        Layout::HalfSideBySide,
        Layout::AboveBelow,
        Layout::HalfAboveBelow,
        Layout::AboveBelowSquashed,
        Layout::FramePacking,
        Layout::InterlacedRows,
        Layout::InterlacedColumns,
        Layout::Checkerboard,
        Layout::AnaglyphRedCyan,
        Layout::AnaglyphGreenMagenta,
        Layout::AnaglyphAmberBlue,
    ];

    /// The name `--layout` and the report use: the output name of the layout that writes it.
    pub fn name(self) -> &'static str {
        match self {
            Layout::Pair => "pair",
            Layout::SideBySide => "side_by_side",
            Layout::CrossEyed => "cross_eyed",
            Layout::HalfSideBySide => "half_side_by_side",
            Layout::AboveBelow => "above_below",
            Layout::HalfAboveBelow => "half_above_below",
            Layout::AboveBelowSquashed => "above_below_squashed",
            Layout::FramePacking => "frame_packing",
            Layout::InterlacedRows => "interlaced_rows",
            Layout::InterlacedColumns => "interlaced_columns",
            Layout::Checkerboard => "checkerboard",
            Layout::AnaglyphRedCyan => "anaglyph_red_cyan",
            Layout::AnaglyphGreenMagenta => "anaglyph_green_magenta",
            Layout::AnaglyphAmberBlue => "anaglyph_amber_blue",
            Layout::Mpo => "mpo",
            Layout::Jps => "jps",
            Layout::Pns => "pns",
            Layout::Animation => "animation",
        }
    }

    /// Parses a `--layout` value.
    ///
    /// # Errors
    /// `Invalid` listing the known names.
    pub fn parse(name: &str) -> Result<Layout> {
        let wanted = name.replace('-', "_");
        Layout::GIVEN
            .into_iter()
            .find(|l| l.name() == wanted)
            .ok_or_else(|| {
                let known: Vec<&str> = Layout::GIVEN.iter().map(|l| l.name()).collect();
                Error::invalid(
                    "--layout",
                    stereolab_core::excerpt(name),
                    format!("known layouts: {}", known.join(", ")),
                )
            })
    }

    /// Whether each view comes back gray (an anaglyph keeps one filter's channels per eye).
    pub fn gray_views(self) -> bool {
        matches!(
            self,
            Layout::AnaglyphRedCyan | Layout::AnaglyphGreenMagenta | Layout::AnaglyphAmberBlue
        )
    }
}

/// Two views read back, the layout they came in, and why that layout.
#[derive(Clone, Debug)]
pub struct Views {
    /// The left eye's view.
    pub left: RgbaImage,
    /// The right eye's view.
    pub right: RgbaImage,
    /// The layout taken.
    pub layout: Layout,
    /// `given` (by `--layout` or the file name), or the detection's evidence.
    pub evidence: String,
}

/// Reads `paths` (two images: a pair; one: a layout) as two views.
///
/// # Errors
/// A file that cannot be read, two files of different sizes, a `--layout` that does not fit
/// the picture, or a picture with no detectable stereo layout.
pub fn read(paths: &[PathBuf], layout: Option<Layout>) -> Result<Views> {
    match paths {
        [left, right] => {
            if layout.is_some_and(|l| l != Layout::Pair) {
                return Err(Error::invalid(
                    "--layout",
                    layout.map_or("", Layout::name),
                    "two files are a left/right pair; give one file for a layout",
                ));
            }
            let (l, r) = (open(left)?, open(right)?);
            if l.dimensions() != r.dimensions() {
                return Err(Error::invalid(
                    "inspect",
                    format!(
                        "{} is {}×{}, {} is {}×{}",
                        left.display(),
                        l.width(),
                        l.height(),
                        right.display(),
                        r.width(),
                        r.height()
                    ),
                    "the two views of a pair have the same size",
                ));
            }
            Ok(Views {
                left: l,
                right: r,
                layout: Layout::Pair,
                evidence: "two files".into(),
            })
        }
        [one] => read_one(one, layout),
        _ => Err(Error::invalid(
            "inspect",
            format!("{} files", paths.len()),
            "give one picture with both views, or a left and a right picture",
        )),
    }
}

fn read_one(path: &Path, layout: Option<Layout>) -> Result<Views> {
    if let Some(format) = PhotoFormat::from_path(path) {
        if layout.is_some() {
            return Err(Error::invalid(
                "--layout",
                layout.map_or("", Layout::name),
                format!(
                    "a .{} file says its own layout; leave --layout out",
                    format.extension()
                ),
            ));
        }
        let (left, right) = read_stereo(path)?;
        let layout = match format {
            PhotoFormat::Mpo => Layout::Mpo,
            PhotoFormat::Jps => Layout::Jps,
            PhotoFormat::Pns => Layout::Pns,
        };
        return Ok(Views {
            left,
            right,
            layout,
            evidence: format!("the .{} container", format.extension()),
        });
    }
    if layout.is_none()
        && let Some((left, right)) = first_two_frames(path)?
    {
        return Ok(Views {
            left,
            right,
            layout: Layout::Animation,
            evidence: "an animation: its first two frames, left first (a wiggle started on the \
                       right reads as swapped eyes)"
                .into(),
        });
    }
    let img = open(path)?;
    let (layout, evidence) = match layout {
        Some(Layout::Pair) => {
            return Err(Error::invalid(
                "--layout",
                "pair",
                "a pair is two files: give the right eye's picture too",
            ));
        }
        Some(l) => (l, "given".to_string()),
        None => detect(&img).map_err(|e| match e {
            Error::Invalid { reason, .. } => Error::invalid(
                "inspect",
                path.display(),
                format!("{reason}; if it is a stereo picture, say its --layout"),
            ),
            other => other,
        })?,
    };
    let (left, right) = split(&img, layout)?;
    Ok(Views {
        left,
        right,
        layout,
        evidence,
    })
}

/// The first two frames of an animated GIF or PNG (no more are decoded), or `None` for a
/// still picture. The size is checked against the largest output stereolab writes before a
/// frame is decoded.
fn first_two_frames(path: &Path) -> Result<Option<(RgbaImage, RgbaImage)>> {
    use image::AnimationDecoder;
    use image::codecs::gif::GifDecoder;
    use image::codecs::png::PngDecoder;
    use std::io::BufReader;
    let reader = || {
        std::fs::File::open(path)
            .map(BufReader::new)
            .map_err(|e| Error::io(path, e))
    };
    let format = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| Error::io(path, e))?
        .format();
    let bad =
        |e: image::ImageError| Error::parse(path, None, format!("cannot read the animation: {e}"));
    let frames: Vec<image::Frame> = match format {
        Some(image::ImageFormat::Gif) => {
            let d = GifDecoder::new(reader()?).map_err(bad)?;
            check_frame_size(path, image::ImageDecoder::dimensions(&d))?;
            d.into_frames()
                .take(2)
                .collect::<std::result::Result<_, _>>()
                .map_err(bad)?
        }
        Some(image::ImageFormat::Png) => {
            let d = PngDecoder::new(reader()?).map_err(bad)?;
            if !d.is_apng().map_err(bad)? {
                return Ok(None);
            }
            check_frame_size(path, image::ImageDecoder::dimensions(&d))?;
            d.apng()
                .map_err(bad)?
                .into_frames()
                .take(2)
                .collect::<std::result::Result<_, _>>()
                .map_err(bad)?
        }
        _ => return Ok(None),
    };
    let mut it = frames.into_iter().map(image::Frame::into_buffer);
    Ok(match (it.next(), it.next()) {
        (Some(a), Some(b)) => Some((a, b)),
        _ => None,
    })
}

fn check_frame_size(path: &Path, (w, h): (u32, u32)) -> Result<()> {
    use stereolab_core::{MAX_OUTPUT_PIXELS, MAX_OUTPUT_SIDE};
    if w > MAX_OUTPUT_SIDE || h > MAX_OUTPUT_SIDE || u64::from(w) * u64::from(h) > MAX_OUTPUT_PIXELS
    {
        return Err(Error::parse(
            path,
            None,
            format!("{w}×{h}: more than the largest picture stereolab reads"),
        ));
    }
    Ok(())
}

/// A picture read as RGBA 8-bit.
///
/// # Errors
/// An unreadable or undecodable file, named.
pub fn open(path: &Path) -> Result<RgbaImage> {
    Ok(stereolab_core::open_output_image(path, "stereo picture")?.to_rgba8())
}

/// The two views of `img` in `layout`, each at the size of one view (squeezed and interleaved
/// views restored to the frame's size).
///
/// # Errors
/// A picture that cannot hold the layout (an odd width for side by side, a frame packing
/// height that fits no view height, no blank interval for the squashed format).
pub fn split(img: &RgbaImage, layout: Layout) -> Result<(RgbaImage, RgbaImage)> {
    let (w, h) = img.dimensions();
    let crop = |x, y, cw, ch| image::imageops::crop_imm(img, x, y, cw, ch).to_image();
    let need = |ok: bool, what: &str| {
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "--layout",
                layout.name(),
                format!("a {w}×{h} picture {what}"),
            ))
        }
    };
    Ok(match layout {
        Layout::SideBySide | Layout::CrossEyed | Layout::Jps | Layout::Pns => {
            need(w % 2 == 0 && w >= 2, "needs an even width")?;
            let (a, b) = (crop(0, 0, w / 2, h), crop(w / 2, 0, w / 2, h));
            if layout == Layout::SideBySide {
                (a, b)
            } else {
                (b, a)
            }
        }
        Layout::HalfSideBySide => {
            need(w >= 2, "needs two columns")?;
            let half = w / 2;
            let stretch =
                |x0: u32| RgbaImage::from_fn(w, h, |x, y| *img.get_pixel(x0 + (x * half / w), y));
            (stretch(0), stretch(half))
        }
        Layout::AboveBelow => {
            need(h % 2 == 0 && h >= 2, "needs an even height")?;
            (crop(0, 0, w, h / 2), crop(0, h / 2, w, h / 2))
        }
        Layout::HalfAboveBelow => {
            need(h >= 2, "needs two rows")?;
            let half = h / 2;
            let stretch =
                |y0: u32| RgbaImage::from_fn(w, h, |x, y| *img.get_pixel(x, y0 + (y * half / h)));
            (stretch(0), stretch(half))
        }
        Layout::AboveBelowSquashed => {
            let (top, blank) = blank_band(img).ok_or_else(|| {
                Error::invalid(
                    "--layout",
                    layout.name(),
                    "no black blank interval between two equal halves",
                )
            })?;
            let stretch =
                |y0: u32| RgbaImage::from_fn(w, h, |x, y| *img.get_pixel(x, y0 + (y * top / h)));
            (stretch(0), stretch(top + blank))
        }
        Layout::FramePacking => {
            let view = packed_view_height(h);
            need(view.is_some(), "is no 2H + H/24 rows for any view height H")?;
            let view = view.unwrap_or(0);
            let gap = frame_packing_active_space(view);
            (crop(0, 0, w, view), crop(0, view + gap, w, view))
        }
        Layout::InterlacedRows => {
            need(h >= 2, "needs two rows")?;
            let field = |parity: u32| {
                RgbaImage::from_fn(w, h, |x, y| *img.get_pixel(x, same_parity(y, parity, h)))
            };
            (field(0), field(1))
        }
        Layout::InterlacedColumns => {
            need(w >= 2, "needs two columns")?;
            let field = |parity: u32| {
                RgbaImage::from_fn(w, h, |x, y| *img.get_pixel(same_parity(x, parity, w), y))
            };
            (field(0), field(1))
        }
        Layout::Checkerboard => {
            need(w >= 2, "needs two columns")?;
            let field = |parity: u32| {
                RgbaImage::from_fn(w, h, |x, y| {
                    // The pixel itself where it is this eye's, else its row neighbour.
                    let p = (parity + y) % 2;
                    *img.get_pixel(same_parity(x, p, w), y)
                })
            };
            (field(0), field(1))
        }
        Layout::AnaglyphRedCyan => (channels(img, [1, 0, 0]), channels(img, [0, 1, 1])),
        Layout::AnaglyphGreenMagenta => (channels(img, [0, 1, 0]), channels(img, [1, 0, 1])),
        Layout::AnaglyphAmberBlue => (channels(img, [1, 1, 0]), channels(img, [0, 0, 1])),
        Layout::Pair | Layout::Mpo | Layout::Animation => {
            return Err(Error::invalid(
                "--layout",
                layout.name(),
                "is not a layout of one picture",
            ));
        }
    })
}

/// `i` if it has `parity`, else its neighbour that has (the one before, at the far edge).
fn same_parity(i: u32, parity: u32, n: u32) -> u32 {
    if i % 2 == parity {
        i
    } else if i + 1 < n {
        i + 1
    } else {
        i - 1
    }
}

/// The channels of `pass` that are not black all over (a true anaglyph leaves green black).
fn lit(img: &RgbaImage, pass: [u32; 3]) -> [u32; 3] {
    let used: [u32; 3] =
        std::array::from_fn(|c| u32::from(pass[c] == 1 && img.pixels().any(|p| p.0[c] > 0)));
    if used.contains(&1) { used } else { pass }
}

/// One eye of an anaglyph: the mean of the channels its filter passes (those not black all
/// over), as gray.
fn channels(img: &RgbaImage, pass: [u32; 3]) -> RgbaImage {
    let pass = lit(img, pass);
    let n: u32 = pass.iter().sum();
    RgbaImage::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get_pixel(x, y).0;
        let sum: u32 = (0..3).map(|c| pass[c] * u32::from(p[c])).sum();
        let v = ((sum + n / 2) / n) as u8;
        Rgba([v, v, v, 255])
    })
}

/// The view height H of a frame-packed picture `rows` tall: `2H + H/24 = rows`.
fn packed_view_height(rows: u32) -> Option<u32> {
    let guess = u64::from(rows) * 24 / 49;
    (guess.saturating_sub(2)..=guess + 2)
        .filter_map(|v| u32::try_from(v).ok())
        .find(|&v| {
            v > 0 && 2 * u64::from(v) + u64::from(frame_packing_active_space(v)) == u64::from(rows)
        })
}

/// Whether row `y` of `img` is black (every channel of every pixel at most 2).
fn black_row(img: &RgbaImage, y: u32) -> bool {
    (0..img.width()).all(|x| img.get_pixel(x, y).0[..3].iter().all(|&c| c <= 2))
}

/// The squashed format's geometry: `(rows, blank)` when rows `rows..rows + blank` are black,
/// with `rows` view rows on either side (`2·rows + blank` = the height, ± the one row an odd
/// remainder leaves at the bottom), and the rows just around the band are not all black.
fn blank_band(img: &RgbaImage) -> Option<(u32, u32)> {
    let h = img.height();
    let mid = h / 2;
    if h < 4 || !black_row(img, mid) {
        return None;
    }
    let mut top = mid;
    while top > 0 && black_row(img, top - 1) {
        top -= 1;
    }
    let mut end = mid + 1;
    while end < h && black_row(img, end) {
        end += 1;
    }
    let blank = end - top;
    let below = h - end;
    let fits = top > 0 && (below == top || below == top + 1);
    fits.then_some((top, blank))
}

/// Rec. 601 luma of every pixel, in [0, 255].
fn luma(img: &RgbaImage) -> Vec<f32> {
    img.pixels()
        .map(|p| 0.299 * f32::from(p.0[0]) + 0.587 * f32::from(p.0[1]) + 0.114 * f32::from(p.0[2]))
        .collect()
}

/// How alike the edges of an anaglyph's two eyes are at 64 px: the correlation of their
/// gradient magnitudes. A filter's channels may show a surface brighter or darker than its
/// background (a brown model is bright in red, dark in blue), but its outline is in both.
fn edges_alike(img: &RgbaImage, layout: Layout) -> Option<f64> {
    let (a, b) = split(img, layout).ok()?;
    let edges = |v: &RgbaImage| {
        let (l, w, h) = small_luma(v, 64);
        let at = |x: u32, y: u32| l[(y * w + x) as usize];
        let mut g = Vec::new();
        for y in 1..h {
            for x in 1..w {
                g.push((at(x, y) - at(x - 1, y)).abs() + (at(x, y) - at(x, y - 1)).abs());
            }
        }
        g
    };
    ncc(&edges(&a), &edges(&b))
}

/// Normalized cross-correlation of two equally long signals; `None` when either is flat.
fn ncc(a: &[f32], b: &[f32]) -> Option<f64> {
    let n = a.len().min(b.len()) as f64;
    if n == 0.0 {
        return None;
    }
    let mean = |s: &[f32]| s.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        let (x, y) = (f64::from(x) - ma, f64::from(y) - mb);
        ab += x * y;
        aa += x * x;
        bb += y * y;
    }
    (aa > 1e-9 * n && bb > 1e-9 * n).then(|| ab / (aa * bb).sqrt())
}

/// The luma of `img` box-filtered by `f` (each output pixel the mean of an `f`×`f` block;
/// the last partial blocks left out).
fn box_luma(img: &RgbaImage, f: u32) -> (Vec<f32>, u32, u32) {
    let (w, h) = img.dimensions();
    let (sw, sh) = (w / f, h / f);
    let full = luma(img);
    let mut out = vec![0f32; (sw * sh) as usize];
    for y in 0..sh * f {
        for x in 0..sw * f {
            out[((y / f) * sw + x / f) as usize] += full[(y * w + x) as usize];
        }
    }
    let k = (f * f) as f32;
    out.iter_mut().for_each(|v| *v /= k);
    (out, sw, sh)
}

/// `img`'s luma box-filtered to at most `side` pixels on its longer side.
fn small_luma(img: &RgbaImage, side: u32) -> (Vec<f32>, u32, u32) {
    let (w, h) = img.dimensions();
    box_luma(img, w.max(h).div_ceil(side).max(1))
}

/// How alike the two views of `layout` are, seen at 64 px: the correlation of their lumas.
/// Stereo views of one scene differ by a few pixels of parallax, which vanish at that scale.
fn views_alike(img: &RgbaImage, layout: Layout) -> Option<f64> {
    let (a, b) = split(img, layout).ok()?;
    let (a, ..) = small_luma(&a, 64);
    let (b, ..) = small_luma(&b, 64);
    ncc(&a, &b)
}

/// The comb of interleaving along one axis: the mean |second difference| over neighbours one
/// pixel away, divided by that over neighbours two pixels away. A single view changes slowly,
/// so its neighbours one pixel away are the closer (below 1); interleaved views put the other
/// eye one pixel away, so every parallax edge adds to the numerator only.
fn comb(l: &[f32], w: u32, h: u32, vertical: bool) -> f64 {
    let at = |x: u32, y: u32| f64::from(l[(y * w + x) as usize]);
    let (mut near, mut far) = (0.0, 0.0);
    let (len, other) = if vertical { (h, w) } else { (w, h) };
    if len < 5 {
        return 0.0;
    }
    for o in 0..other {
        for i in 2..len - 2 {
            let p = |i: u32| if vertical { at(o, i) } else { at(i, o) };
            near += (p(i) - 0.5 * (p(i - 1) + p(i + 1))).abs();
            far += (p(i) - 0.5 * (p(i - 2) + p(i + 2))).abs();
        }
    }
    if far <= 0.0 { 0.0 } else { near / far }
}

/// Horizontal gradient of one channel (`[1, 0, 0]` red, …, means for several).
fn channel_gradient(img: &RgbaImage, pass: [u32; 3]) -> Vec<f32> {
    let (w, h) = img.dimensions();
    let n: u32 = pass.iter().sum();
    let v = |x: u32, y: u32| {
        let p = img.get_pixel(x, y).0;
        (0..3)
            .map(|c| (pass[c] * u32::from(p[c])) as f32)
            .sum::<f32>()
            / n as f32
    };
    let mut g = Vec::with_capacity((w.saturating_sub(1) * h) as usize);
    for y in 0..h {
        for x in 1..w {
            g.push((v(x, y) - v(x - 1, y)).abs());
        }
    }
    g
}

/// The score of an anaglyph for glasses whose left filter passes `left` and right `right`:
/// how much better the right filter's channels agree with each other than with the left's, on
/// horizontal edges. One camera's picture has its edges in the same place in every channel
/// (score near 0); an anaglyph moves them by the parallax between the eyes' channels.
fn anaglyph_score(img: &RgbaImage, left: [u32; 3], right: [u32; 3]) -> Option<f64> {
    let (left, right) = (lit(img, left), lit(img, right));
    let gl = channel_gradient(img, left);
    let gr = channel_gradient(img, right);
    let across = ncc(&gl, &gr)?;
    // Within the filter that passes two lit channels; a filter of one lit channel (a true
    // anaglyph's) agrees with itself.
    let two = [right, left]
        .into_iter()
        .find(|f| f.iter().sum::<u32>() == 2);
    let within = match two {
        Some(f) => {
            let c: Vec<usize> = (0..3).filter(|&c| f[c] == 1).collect();
            ncc(
                &channel_gradient(img, one_hot(c[0])),
                &channel_gradient(img, one_hot(c[1])),
            )?
        }
        None => 1.0,
    };
    Some(within - across)
}

fn one_hot(c: usize) -> [u32; 3] {
    let mut p = [0; 3];
    p[c] = 1;
    p
}

/// The least correlation of two views at 64 px (their lumas, or an anaglyph's outlines) for
/// them to count as one scene's two views.
pub const ALIKE: f64 = 0.8;
/// The least comb (second differences one pixel away over those two pixels away) that counts
/// as interleaving.
pub const COMB: f64 = 0.8;
/// The least anaglyph score (edge agreement within a filter's channels minus across the
/// filters) that counts as an anaglyph.
pub const ANAGLYPH: f64 = 0.25;

/// The layout of one picture, with the evidence, or why none was found.
///
/// # Errors
/// `Invalid` when no layout leaves its mark (a flat picture, a single view).
pub fn detect(img: &RgbaImage) -> Result<(Layout, String)> {
    let (w, h) = img.dimensions();
    let alike = |l: Layout| views_alike(img, l).unwrap_or(0.0);
    // Frame packing: the exact height and a black active space between two alike views.
    if let Some(view) = packed_view_height(h) {
        let gap = frame_packing_active_space(view);
        let black = gap > 0 && (view..view + gap).all(|y| black_row(img, y));
        let a = alike(Layout::FramePacking);
        if black && a >= ALIKE {
            return Ok((
                Layout::FramePacking,
                format!(
                    "{h} rows = 2 × {view} + {gap} black rows of active space; views alike {a:.2}"
                ),
            ));
        }
    }
    // The squashed format: a black band around the middle between two alike halves.
    if let Some((rows, blank)) = blank_band(img) {
        let a = alike(Layout::AboveBelowSquashed);
        if a >= ALIKE {
            return Ok((
                Layout::AboveBelowSquashed,
                format!("{blank} black rows between two views of {rows} rows; views alike {a:.2}"),
            ));
        }
    }
    // Anaglyphs: edges displaced between the channels of the two filters.
    let anaglyphs = [
        (Layout::AnaglyphRedCyan, [1, 0, 0], [0, 1, 1]),
        (Layout::AnaglyphGreenMagenta, [0, 1, 0], [1, 0, 1]),
        (Layout::AnaglyphAmberBlue, [1, 1, 0], [0, 0, 1]),
    ];
    let best = anaglyphs
        .iter()
        .filter_map(|&(l, a, b)| anaglyph_score(img, a, b).map(|s| (l, s)))
        // The first of equal scores: a red-blue (true) anaglyph reads as red-cyan.
        .fold(None, |best: Option<(Layout, f64)>, c| match best {
            Some(b) if b.1 >= c.1 => Some(b),
            _ => Some(c),
        });
    // A colourful picture of different-coloured things moves edges between channels too: the
    // two eyes' channels must also show one scene.
    let edges = |l: Layout| edges_alike(img, l).unwrap_or(0.0);
    if let Some((layout, score)) = best.filter(|&(l, s)| s >= ANAGLYPH && edges(l) >= ALIKE) {
        return Ok((
            layout,
            format!(
                "edges agree within each filter's channels {score:.2} better than across them \
                 (one camera's picture: about 0); the eyes' outlines alike {:.2}",
                edges(layout)
            ),
        ));
    }
    // Interleaving: a comb along rows, columns or both.
    let l = luma(img);
    let (cv, ch) = (comb(&l, w, h, true), comb(&l, w, h, false));
    let combed = match (cv >= COMB, ch >= COMB) {
        (true, true) => Some(Layout::Checkerboard),
        (true, false) => Some(Layout::InterlacedRows),
        (false, true) => Some(Layout::InterlacedColumns),
        (false, false) => None,
    };
    // Noise has a comb near 1 too: the two fields must also show one scene.
    if let Some(layout) = combed.filter(|&l| alike(l) >= ALIKE) {
        return Ok((
            layout,
            format!(
                "comb {cv:.2} down the columns, {ch:.2} along the rows (a single view: below \
                 {COMB}); the fields alike {:.2}",
                alike(layout)
            ),
        ));
    }
    // Two alike halves: side by side or above-below, full or squeezed by the aspect.
    let (sbs, ab) = (alike(Layout::SideBySide), alike(Layout::AboveBelow));
    let aspect = f64::from(w) / f64::from(h);
    if sbs >= ALIKE && sbs >= ab {
        let (layout, why) = if aspect >= 2.0 {
            (
                Layout::SideBySide,
                "at least twice as wide as tall: full-size views",
            )
        } else {
            (
                Layout::HalfSideBySide,
                "less than twice as wide as tall: views squeezed to half width",
            )
        };
        return Ok((
            layout,
            format!(
                "left and right halves alike {sbs:.2} (top and bottom {ab:.2}); {w}×{h} is {why} \
                 (parallel order assumed: a cross-eyed pair reads as swapped eyes)"
            ),
        ));
    }
    if ab >= ALIKE {
        let (layout, why) = if aspect <= 1.0 {
            (
                Layout::AboveBelow,
                "at least as tall as wide: full-size views",
            )
        } else {
            (
                Layout::HalfAboveBelow,
                "wider than tall: views squeezed to half height",
            )
        };
        return Ok((
            layout,
            format!(
                "top and bottom halves alike {ab:.2} (left and right {sbs:.2}); {w}×{h} is {why}"
            ),
        ));
    }
    Err(Error::invalid(
        "inspect",
        format!("{w}×{h}"),
        format!(
            "no stereo layout found: no frame-packing or blank-interval band, no anaglyph \
             (score below {ANAGLYPH}), no interleaving comb (rows {cv:.2}, columns {ch:.2}, below \
             {COMB}), halves not alike (side by side {sbs:.2}, above-below {ab:.2}, below {ALIKE})"
        ),
    ))
}

/// What the matcher measured on two views.
#[derive(Clone, Debug)]
pub struct Measured {
    /// The disparity map of the left view at the matching scale, in full-size pixels.
    pub map: disparity::DisparityMap,
    /// The whole right view's vertical shift (rows, `y_right − y_left`) found before matching
    /// and undone for it ([`row_shift`]).
    pub row_shift: i32,
    /// The views were matched at `1/scale` of their size (a cost volume within
    /// [`disparity::MAX_CELLS`]).
    pub scale: u32,
    /// The disparities searched, `−range..=range` full-size pixels.
    pub range: i32,
    /// The share of the left view's pixels with a left-right consistent match.
    pub matched: f64,
    /// 5th percentile, median and 95th percentile of the parallax (px), if any matched.
    pub percentiles: Option<[f64; 3]>,
    /// The views' width (px).
    pub width: u32,
}

/// The whole-row vertical shift of `right` against `left` (`y_right − y_left`) within ±⅒ of
/// the height: the shift that best correlates the two views' row means. A row's mean does not
/// change when its content moves sideways, so horizontal parallax leaves the profiles alike
/// and only a vertical shift moves them.
pub fn row_shift(left: &RgbaImage, right: &RgbaImage) -> i32 {
    let (w, h) = left.dimensions();
    let profile = |img: &RgbaImage| -> Vec<f32> {
        let l = luma(img);
        (0..h as usize)
            .map(|y| l[y * w as usize..(y + 1) * w as usize].iter().sum::<f32>() / w as f32)
            .collect()
    };
    let (a, b) = (profile(left), profile(right));
    let reach = (h / 10) as i32;
    let score = |s: i32| {
        // Rows y of the left against y + s of the right, where both exist.
        let (from, to) = ((-s).max(0), (h as i32 - s).min(h as i32));
        if to - from < h as i32 / 2 {
            return f64::MIN;
        }
        let x: Vec<f32> = (from..to).map(|y| a[y as usize]).collect();
        let y: Vec<f32> = (from..to).map(|y| b[(y + s) as usize]).collect();
        ncc(&x, &y).unwrap_or(f64::MIN)
    };
    (-reach..=reach)
        .map(|s| (s, score(s)))
        // The smallest |shift| among equal scores.
        .fold((0i32, f64::MIN), |best, c| {
            if c.1 > best.1 || (c.1 == best.1 && c.0.abs() < best.0.abs()) {
                c
            } else {
                best
            }
        })
        .0
}

/// The gray (Rec. 601 luma, 8 bits) of `img` box-filtered by `scale`.
fn gray_at(img: &RgbaImage, scale: u32) -> (Vec<u8>, u32, u32) {
    let (l, sw, sh) = box_luma(img, scale);
    (l.iter().map(|v| v.round() as u8).collect(), sw, sh)
}

/// Matches the two views: parallax searched over ±⅛ of the width (at least 8 px), at the
/// largest scale `1/s` whose cost volume fits [`disparity::MAX_CELLS`].
///
/// # Errors
/// Views of different sizes, or views too small to match (under 16 px a side).
pub fn measure(views: &Views) -> Result<Measured> {
    let (w, h) = views.left.dimensions();
    if views.right.dimensions() != (w, h) {
        return Err(Error::invalid(
            "inspect",
            format!("{w}×{h} and {:?}", views.right.dimensions()),
            "the two views must have the same size",
        ));
    }
    if w < 16 || h < 16 {
        return Err(Error::invalid(
            "inspect",
            format!("{w}×{h}"),
            "views under 16 pixels a side are too small to match",
        ));
    }
    let range = (w / 8).max(8) as i32;
    let fits = |s: u32| {
        let cells =
            u64::from(w / s) * u64::from(h / s) * (2 * (range as u64).div_ceil(u64::from(s)) + 1);
        cells <= disparity::MAX_CELLS
    };
    let scale = (1..=64).find(|&s| fits(s)).unwrap_or(64);
    let shift = row_shift(&views.left, &views.right);
    let (l, sw, sh) = gray_at(&views.left, scale);
    // The right view moved back by the whole rows it is shifted (edge rows repeated), so the
    // matcher compares the same rows.
    let (r, ..) = if shift == 0 {
        gray_at(&views.right, scale)
    } else {
        let unshifted = RgbaImage::from_fn(w, h, |x, y| {
            *views
                .right
                .get_pixel(x, (y as i32 + shift).clamp(0, h as i32 - 1) as u32)
        });
        gray_at(&unshifted, scale)
    };
    let r_scaled = (range as u32).div_ceil(scale) as i32;
    let mut map = disparity::sgm(&l, &r, sw, sh, disparity::SgmSettings::symmetric(r_scaled))?;
    // Full-size pixels; a match no better than its rivals (flat, untextured areas) is none.
    for (d, c) in map.disparity.iter_mut().zip(&map.confidence) {
        *d = if *c >= MIN_CONFIDENCE {
            *d * scale as f32
        } else {
            f32::NAN
        };
    }
    let mut valid: Vec<f64> = map.valid().map(f64::from).collect();
    valid.sort_by(f64::total_cmp);
    let matched = valid.len() as f64 / map.disparity.len() as f64;
    let at = |q: f64| valid[((valid.len() - 1) as f64 * q).round() as usize];
    let percentiles = (!valid.is_empty()).then(|| [at(0.05), at(0.5), at(0.95)]);
    Ok(Measured {
        map,
        row_shift: shift,
        scale,
        range,
        matched,
        percentiles,
        width: w,
    })
}

/// The largest parallax to expect (px): the larger of the 5th and 95th percentiles'
/// magnitudes plus 2, or the whole search range when nothing matched.
pub fn reach(m: &Measured) -> u32 {
    m.percentiles.map_or(m.range.unsigned_abs(), |[lo, _, hi]| {
        (lo.abs().max(hi.abs()) + 2.0).ceil() as u32
    })
}

/// The share of matched pixels in front of the zero-parallax plane (parallax below zero):
/// where the screen lies in the scene's depth (0 when nothing matched).
pub fn in_front_share(m: &Measured) -> f64 {
    let (front, all) = m.map.valid().fold((0usize, 0usize), |(f, a), d| {
        (f + usize::from(d < 0.0), a + 1)
    });
    if all == 0 {
        0.0
    } else {
        front as f64 / all as f64
    }
}

/// The least [`disparity::DisparityMap::confidence`] a match needs to count: below it the
/// best disparity is hardly better than another (a flat surface, a repeated pattern).
pub const MIN_CONFIDENCE: f32 = 0.1;

/// The rows where something in front of the screen meets the left or the right edge (the
/// StereoGraphics guide's window violation), as `(left rows, right rows)`: per row, the
/// first (last) matched pixel within [`window_margin`] columns of the edge has a parallax
/// under −½ px. At the left edge a pixel with parallax −p has no match in the right view (it
/// leaves it), so the margin there also reaches past the map's 1st percentile of negative
/// parallax, where the nearest matched pixel stands for the edge. At the right edge negative
/// parallax stays inside the other view, but positive parallax leaves it: the last columns
/// (as many as the 99th percentile of positive parallax) hold only mismatches and are skipped.
pub fn window_violations(m: &Measured) -> (Vec<u32>, Vec<u32>) {
    let (w, h) = (m.map.width, m.map.height);
    let mut negative: Vec<f32> = m.map.valid().filter(|d| *d < 0.0).collect();
    negative.sort_by(f32::total_cmp);
    let reach = negative
        .get(negative.len() / 100)
        .map_or(0, |d| (-d / m.scale as f32).ceil() as u32);
    let mut positive: Vec<f32> = m.map.valid().filter(|d| *d > 0.0).collect();
    positive.sort_by(f32::total_cmp);
    let skip = positive
        .get(positive.len() * 99 / 100)
        .map_or(0, |d| (d / m.scale as f32).ceil() as u32);
    let left_margin = (window_margin(w) + reach).min(w);
    let right_end = w.saturating_sub(skip).max(1);
    let right_start = right_end.saturating_sub(window_margin(w));
    let d = |x: u32, y: u32| m.map.disparity[(y * w + x) as usize];
    let mut out = (Vec::new(), Vec::new());
    for y in 0..h {
        let first = (0..left_margin).map(|x| d(x, y)).find(|v| !v.is_nan());
        let last = (right_start..right_end)
            .rev()
            .map(|x| d(x, y))
            .find(|v| !v.is_nan());
        if first.is_some_and(|v| v < -0.5) {
            out.0.push(y);
        }
        if last.is_some_and(|v| v < -0.5) {
            out.1.push(y);
        }
    }
    out
}

/// How far from the edge [`window_violations`] looks: 1/40 of the width, at least 4 columns.
pub fn window_margin(width: u32) -> u32 {
    (width / 40).max(4)
}

/// The StereoGraphics guide's comfortable parallax: ±3% of the width.
pub const BUDGET_SHARE: f64 = 0.03;

/// The report's lines about a measurement: coverage, the parallax range against the guide's
/// budget, and whether there is depth to see at all ([`findings()`]).
pub fn describe(m: &Measured) -> String {
    let mut s = format!(
        "  disparity: semi-global matching (census 5×5, 8 paths), {:.1}% of pixels matched \
         (left-right consistent, confidence at least {MIN_CONFIDENCE}), searched ±{} px{}\n",
        100.0 * m.matched,
        m.range,
        if m.scale > 1 {
            format!(" at 1/{} size", m.scale)
        } else {
            String::new()
        }
    );
    let Some([lo, mid, hi]) = m.percentiles else {
        s += "  no pixel matched: the views show no common texture\n";
        return s;
    };
    let pct = |p: f64| 100.0 * p / f64::from(m.width);
    s += &format!(
        "  parallax: {lo:.1} to {hi:.1} px (5th to 95th percentile; {:.1}% to {:.1}% of the \
         width), median {mid:.1} px; negative is in front of the screen\n",
        pct(lo),
        pct(hi)
    );
    s += &format!(
        "  zero-parallax plane: {:.0}% of the matched pixels in front of it, {:.0}% behind\n",
        100.0 * in_front_share(m),
        100.0 * (1.0 - in_front_share(m))
    );
    s += &findings::lines(&findings(m));
    s
}

/// The findings of a measurement: no visible depth (a parallax range under 1 px, an error: the
/// pair shows no stereo effect), window violations and parallax beyond the StereoGraphics
/// guide's ±3% (warnings: comfort guidelines).
pub fn findings(m: &Measured) -> Vec<Finding> {
    let mut out = Vec::new();
    let Some([lo, _, hi]) = m.percentiles else {
        return out;
    };
    if hi - lo < 1.0 {
        out.push(Finding::error(
            "no visible depth",
            "the parallax range is under 1 px; increase the separation (or these are two \
             copies of one view)",
        ));
    }
    let (left, right) = window_violations(m);
    for (rows, edge) in [(&left, "left"), (&right, "right")] {
        // One row in fifty: a few stray matches at the edge are no violation.
        if rows.len() as u32 * 50 >= m.map.height.max(1) {
            out.push(Finding::warning(
                "window violation",
                format!(
                    "something in front of the screen meets the {edge} edge on {} rows \
                     (marked in disparity.png); move the zero-parallax plane nearer or keep \
                     near objects off the edges",
                    rows.len()
                ),
            ));
        }
    }
    let budget = BUDGET_SHARE * f64::from(m.width);
    if lo < -budget || hi > budget {
        out.push(Finding::warning(
            "parallax beyond the StereoGraphics guide's ±3%",
            format!(
                "{lo:.1} to {hi:.1} px against ±{budget:.1} px; move the zero-parallax plane \
                 toward the scene's middle or reduce the separation"
            ),
        ));
    }
    out
}

/// The disparity map as a picture: stereolab's parallax colours (blue in front of the
/// screen, red behind), dark gray where nothing matched, a legend below.
///
/// # Errors
/// The legend cannot be drawn (a map under one pixel wide).
pub fn disparity_image(m: &Measured) -> Result<RgbaImage> {
    let (w, h) = (m.map.width, m.map.height);
    // The colour scale: the 99th percentile of |parallax|, so a few wild matches do not
    // wash the map out.
    let mut mags: Vec<f64> = m.map.valid().map(|d| f64::from(d).abs()).collect();
    mags.sort_by(f64::total_cmp);
    let scale = mags
        .get((mags.len().saturating_sub(1) as f64 * 0.99) as usize)
        .copied()
        .unwrap_or(0.5)
        .max(0.5);
    let legend =
        stereolab_core::draw_legend(w, scale, &|p| stereolab_core::parallax_color(p, scale))?;
    let mut bytes: Vec<u8> = m
        .map
        .disparity
        .iter()
        .flat_map(|d| {
            if d.is_nan() {
                [40, 40, 40, 255]
            } else {
                stereolab_core::parallax_color(f64::from(*d), scale)
            }
        })
        .collect();
    // The window violations: a band along each violating row from its edge, in the parallax
    // output's violation colour.
    let (left, right) = window_violations(m);
    let band = window_margin(w).min(w);
    // (A band of the fixed margin: the violation's own depth is in the map beside it.)
    for (rows, from_left) in [(&left, true), (&right, false)] {
        for &y in rows.iter() {
            for k in 0..band {
                let x = if from_left { k } else { w - 1 - k };
                let i = 4 * (y * w + x) as usize;
                bytes[i..i + 4].copy_from_slice(&stereolab_core::PARALLAX_VIOLATION_COLOR);
            }
        }
    }
    bytes.extend_from_slice(legend.data());
    RgbaImage::from_raw(w, h + legend.height(), bytes)
        .ok_or_else(|| Error::internal("inspect", "map and legend size mismatch"))
}

/// One block's vertical disparity: the left view's block centred at `(x, y)` (full-size
/// pixels) is found `v` pixels lower in the right view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerticalSample {
    /// Column of the block's centre.
    pub x: f64,
    /// Row of the block's centre.
    pub y: f64,
    /// `y_right − y_left`, sub-pixel.
    pub v: f64,
}

/// The vertical disparity of a pair as `v = a + b·X + c·Y + e·X·Y` over the view, with
/// `X = (x − W/2)/(W/2)` and `Y = (y − H/2)/(H/2)` in −1..1: `a` is the shift at the centre,
/// `b` the rotation's shift at the left and right edges, `c` a size difference's shift at the
/// top and bottom, `e` toe-in's keystone at the corners (all in pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerticalFit {
    /// Shift at the centre (px): vertical misalignment.
    pub offset: f64,
    /// At the left and right edges (px, opposite signs): a rotation between the views.
    pub rotation: f64,
    /// At the top and bottom edges (px, opposite signs): one view larger than the other.
    pub scale: f64,
    /// At the corners (px, opposite signs at opposite corners): toe-in's keystone.
    pub keystone: f64,
    /// The samples fitted.
    pub samples: usize,
    /// The samples left out as outliers of a first fit ([`fit_vertical`]).
    pub rejected: usize,
    /// Root-mean-square residual of the fit (px).
    pub rms: f64,
    /// Each term's standard error (offset, rotation, scale, keystone; px).
    pub standard_error: [f64; 4],
    /// How far the samples reach in each term's variable (1, |X|, |Y|, |X·Y|; 1 at the
    /// view's edges and corners).
    pub extent: [f64; 4],
}

impl VerticalFit {
    /// Whether term `i` (0 offset, 1 rotation, 2 scale, 3 keystone) is a finding: at least
    /// [`VERTICAL_FINDING`] px where the samples reach, and four standard errors from zero.
    pub fn significant(&self, i: usize) -> bool {
        let c = [self.offset, self.rotation, self.scale, self.keystone][i];
        c.abs() * self.extent[i] >= VERTICAL_FINDING && c.abs() >= 4.0 * self.standard_error[i]
    }
}

/// Vertical disparity block by block: 11×11 blocks of the left view on a grid, each searched in
/// the right view at its horizontal disparity (±1 px) over `±max(3, H/40)` rows by the sum of
/// absolute differences, refined by a parabola; blocks without texture or without a clear best
/// row are left out.
pub fn vertical_samples(views: &Views, m: &Measured) -> Vec<VerticalSample> {
    const R: i32 = 5;
    let (w, h) = views.left.dimensions();
    let (l, r) = (luma(&views.left), luma(&views.right));
    let (wi, hi) = (w as i32, h as i32);
    let reach = (hi / 40).max(3);
    let step = (w.max(h) / 64).max(12) as i32;
    let at = |img: &[f32], x: i32, y: i32| img[(y * wi + x) as usize];
    let mut out = Vec::new();
    let mut y = R + reach;
    while y < hi - R - reach {
        let mut x = R;
        while x < wi - R {
            // The block's horizontal disparity from the map (at its scale).
            let (mx, my) = ((x as u32) / m.scale, (y as u32) / m.scale);
            let d = (mx < m.map.width && my < m.map.height)
                .then(|| m.map.disparity[(my * m.map.width + mx) as usize])
                .filter(|d| !d.is_nan());
            if let Some(d) = d {
                let (mut lo, mut hi_v) = (f32::MAX, f32::MIN);
                for dy in -R..=R {
                    for dx in -R..=R {
                        let v = at(&l, x + dx, y + dy);
                        lo = lo.min(v);
                        hi_v = hi_v.max(v);
                    }
                }
                let xr = x + d.round() as i32;
                let yr = y + m.row_shift;
                if hi_v - lo > 8.0
                    && two_dimensional(&l, wi, x, y, R)
                    && xr - R > 0
                    && xr + R + 1 < wi
                    && yr - R - reach >= 0
                    && yr + R + reach < hi
                {
                    let sad = |sx: i32, sy: i32| -> f64 {
                        let mut s = 0.0;
                        for dy in -R..=R {
                            for dx in -R..=R {
                                s += f64::from(
                                    (at(&l, x + dx, y + dy) - at(&r, sx + dx, sy + dy)).abs(),
                                );
                            }
                        }
                        s
                    };
                    // Per row offset, the best of three columns around the disparity.
                    let costs: Vec<f64> = (-reach..=reach)
                        .map(|dv| {
                            (-1..=1)
                                .map(|dx| sad(xr + dx, yr + dv))
                                .fold(f64::MAX, f64::min)
                        })
                        .collect();
                    let k = (0..costs.len())
                        .min_by(|&a, &b| costs[a].total_cmp(&costs[b]))
                        .unwrap_or(0);
                    let second = (0..costs.len())
                        .filter(|&j| j.abs_diff(k) > 1)
                        .map(|j| costs[j])
                        .fold(f64::MAX, f64::min);
                    let clear = costs[k] < 0.8 * second;
                    if clear && k > 0 && k + 1 < costs.len() {
                        let (a, b, c) = (costs[k - 1], costs[k], costs[k + 1]);
                        let curv = a - 2.0 * b + c;
                        let frac = if curv > 0.0 {
                            ((a - c) / (2.0 * curv)).clamp(-0.5, 0.5)
                        } else {
                            0.0
                        };
                        out.push(VerticalSample {
                            x: f64::from(x),
                            y: f64::from(y),
                            v: f64::from(m.row_shift + k as i32 - reach) + frac,
                        });
                    }
                }
            }
            x += step;
        }
        y += step;
    }
    out
}

/// Whether the block of radius `r` around `(x, y)` has texture in two directions, so that a
/// vertical shift cannot pass for a horizontal one: the smaller eigenvalue of the gradient's
/// structure tensor `Σ [gx², gx·gy; gx·gy, gy²]` (central differences) is at least a quarter
/// of the larger (Shi and Tomasi, "Good Features to Track", CVPR 1994). A block on one
/// straight edge (the aperture problem) fails.
fn two_dimensional(img: &[f32], w: i32, x: i32, y: i32, r: i32) -> bool {
    let at = |x: i32, y: i32| f64::from(img[(y * w + x) as usize]);
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for yy in y - r + 1..y + r {
        for xx in x - r + 1..x + r {
            let gx = (at(xx + 1, yy) - at(xx - 1, yy)) / 2.0;
            let gy = (at(xx, yy + 1) - at(xx, yy - 1)) / 2.0;
            a += gx * gx;
            b += gx * gy;
            c += gy * gy;
        }
    }
    let (mean, root) = ((a + c) / 2.0, (((a - c) / 2.0).powi(2) + b * b).sqrt());
    let (small, large) = (mean - root, mean + root);
    large > 0.0 && small >= 0.25 * large
}

/// [`VerticalFit`]'s model fitted to `samples` twice: once to all, then to the samples within
/// [`VERTICAL_OUTLIER`] px of the first fit (blocks matched on smooth shading or a repeated
/// pattern land anywhere); `None` under 12 samples or for a singular system (samples on a
/// line). [`VerticalFit::reliable`] says whether the second fit explains the blocks.
pub fn fit_vertical(samples: &[VerticalSample], width: u32, height: u32) -> Option<VerticalFit> {
    let first = fit_once(samples, width, height)?;
    let kept: Vec<VerticalSample> = samples
        .iter()
        .copied()
        .filter(|s| (s.v - first.at(s, width, height)).abs() <= VERTICAL_OUTLIER)
        .collect();
    let mut fit = fit_once(&kept, width, height).unwrap_or(first);
    fit.rejected = samples.len() - fit.samples;
    Some(fit)
}

/// The fewest blocks a reliable fit keeps: a textured 480×360 pair gives 700–1 000, smooth
/// shading a few dozen at the silhouettes.
pub const VERTICAL_MIN_BLOCKS: usize = 100;

/// How far (px) a block may lie from the first fit and still count in the second.
pub const VERTICAL_OUTLIER: f64 = 1.5;

/// The most fit residual (px, root mean square) a reliable fit has: the correct and planted
/// pairs of textured scenes fit within 0.3 px; smooth shading without texture leaves 0.6–4 px.
pub const VERTICAL_MAX_RMS: f64 = 0.5;

impl VerticalFit {
    /// The fitted vertical disparity at a sample's place.
    pub fn at(&self, s: &VerticalSample, width: u32, height: u32) -> f64 {
        let (cx, cy) = (f64::from(width) / 2.0, f64::from(height) / 2.0);
        let (x, y) = ((s.x - cx) / cx, (s.y - cy) / cy);
        self.offset + self.rotation * x + self.scale * y + self.keystone * x * y
    }

    /// Whether the fit explains the blocks well enough for findings: at least
    /// [`VERTICAL_MIN_BLOCKS`] blocks kept, at most one in five left out, and a residual within
    /// [`VERTICAL_MAX_RMS`].
    pub fn reliable(&self) -> bool {
        self.samples >= VERTICAL_MIN_BLOCKS
            && 4 * self.rejected <= self.samples
            && self.rms <= VERTICAL_MAX_RMS
    }
}

/// The least-squares fit of [`VerticalFit`]'s model to `samples`: the normal equations
/// `NᵀN c = Nᵀv` solved by inverting `NᵀN` (glam's `DMat4`), whose diagonal with the residual
/// variance gives each term's standard error; `None` under 12 samples or for a singular system
/// (samples on a line).
fn fit_once(samples: &[VerticalSample], width: u32, height: u32) -> Option<VerticalFit> {
    if samples.len() < 12 {
        return None;
    }
    let (cx, cy) = (f64::from(width) / 2.0, f64::from(height) / 2.0);
    let basis = |s: &VerticalSample| {
        let (x, y) = ((s.x - cx) / cx, (s.y - cy) / cy);
        DVec4::new(1.0, x, y, x * y)
    };
    // NᵀN (symmetric: each sample's outer product) and Nᵀv.
    let (mut normal, mut rhs, mut extent) = (DMat4::ZERO, DVec4::ZERO, DVec4::ZERO);
    for s in samples {
        let f = basis(s);
        normal += DMat4::from_cols(f * f.x, f * f.y, f * f.z, f * f.w);
        rhs += f * s.v;
        extent = extent.max(f.abs());
    }
    // Samples on a line (or a point) leave NᵀN singular.
    if normal.determinant().abs() < 1e-9 * normal.x_axis.x.powi(4) {
        return None;
    }
    let inverse = normal.inverse();
    let coef = inverse * rhs;
    let rss: f64 = samples
        .iter()
        .map(|s| (s.v - coef.dot(basis(s))).powi(2))
        .sum();
    let variance = rss / (samples.len() - 4) as f64;
    let se: [f64; 4] = std::array::from_fn(|i| (variance * inverse.col(i)[i]).max(0.0).sqrt());
    let (coef, extent) = (coef.to_array(), extent.to_array());
    Some(VerticalFit {
        offset: coef[0],
        rotation: coef[1],
        scale: coef[2],
        keystone: coef[3],
        samples: samples.len(),
        rejected: 0,
        rms: (rss / samples.len() as f64).sqrt(),
        standard_error: se,
        extent,
    })
}

/// The least vertical disparity (px) a term of the fit must reach to be a finding: half a
/// pixel, about what the eyes stop fusing comfortably at small sizes.
pub const VERTICAL_FINDING: f64 = 0.5;

/// The report's lines about the vertical disparity and its findings ([`vertical_findings`]).
pub fn describe_vertical(fit: Option<&VerticalFit>, width: u32) -> String {
    let Some(f) = fit else {
        return "  vertical disparity: too few textured blocks to measure\n".into();
    };
    let mut s = format!(
        "  vertical disparity ({} blocks, {} left out, fit residual {:.2} px): {:+.2} px at the \
         centre, {:+.2} px at the right edge (rotation), {:+.2} px at the bottom edge (size), \
         {:+.2} px at the bottom-right corner (keystone)\n",
        f.samples, f.rejected, f.rms, f.offset, f.rotation, f.scale, f.keystone
    );
    if !f.reliable() {
        s += "  vertical disparity unreliable (under 100 blocks kept, over one in five left out, \
              or a residual over 0.5 px: too little texture to match): no finding from it\n";
    }
    s += &findings::lines(&vertical_findings(fit, width));
    s
}

/// The findings of the vertical disparity's fit, all errors: toe-in (the keystone), a
/// vertical misalignment (the offset), a rotation, one view larger (the size term); none
/// without a fit.
pub fn vertical_findings(fit: Option<&VerticalFit>, width: u32) -> Vec<Finding> {
    let mut out = Vec::new();
    let Some(f) = fit.filter(|f| f.reliable()) else {
        return out;
    };
    if f.significant(3) {
        out.push(Finding::error(
            "toe-in",
            format!(
                "vertical disparity grows toward the corners in the keystone pattern, up to \
                 {:.1} px; render with parallel axes and sheared frusta (off-axis)",
                f.keystone.abs()
            ),
        ));
    }
    if f.significant(0) {
        out.push(Finding::error(
            "vertical misalignment",
            format!(
                "the right view is {:.1} px {} than the left; shift it back",
                f.offset.abs(),
                if f.offset > 0.0 { "lower" } else { "higher" }
            ),
        ));
    }
    if f.significant(1) {
        let degrees = (f.rotation / (f64::from(width) / 2.0)).atan().to_degrees();
        out.push(Finding::error(
            "rotation between the views",
            format!(
                "{degrees:+.2}° (±{:.1} px at the edges); level the cameras or rotate one view \
                 back",
                f.rotation.abs()
            ),
        ));
    }
    if f.significant(2) {
        out.push(Finding::error(
            "one view is larger",
            format!(
                "±{:.1} px at the top and bottom; match the cameras' fields of view",
                f.scale.abs()
            ),
        ));
    }
    out
}

/// The measured parallax against a scene's exact parallax, pixel by pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceFit {
    /// Pixels with both a match and an exact parallax.
    pub pixels: usize,
    /// Median |measured − reference| (px).
    pub median: f64,
    /// `measured ≈ slope · reference + offset`, by least squares with the pixels off by more
    /// than 1.5 px from a first fit left out.
    pub slope: f64,
    /// See [`ReferenceFit::slope`] (px).
    pub offset: f64,
    /// The reference's parallax at infinity, `b·d·W/Xrange` (px).
    pub at_infinity: f64,
}

impl ReferenceFit {
    /// The separation and zero-parallax factors `(s, t)` that explain the fit. In pixels the
    /// scene's parallax is `p = C·(b/z0 − 1/z)` (`W/Xrange` shrinks as `z0` grows), so a rig
    /// with separation `s·d` and zero-parallax distance `t·z0` gives `s·p + s·A·(1/t − 1)`, `A`
    /// the parallax at infinity: the slope is `s`, and `t = 1/(1 + offset/(s·A))`. A wrong
    /// zero-parallax distance is a constant shift between the views.
    pub fn factors(&self) -> (f64, f64) {
        let s = self.slope;
        let denominator = 1.0 + self.offset / (s * self.at_infinity);
        (
            s,
            if denominator == 0.0 {
                f64::INFINITY
            } else {
                1.0 / denominator
            },
        )
    }
}

/// Least squares of `y ≈ a·x + b` over `pairs`; `None` when the x are all equal.
fn line_fit(pairs: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = pairs.len() as f64;
    let (sx, sy) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for (x, y) in pairs {
        sxx += (x - mx) * (x - mx);
        sxy += (x - mx) * (y - my);
    }
    (sxx > 1e-12 * n).then(|| {
        let a = sxy / sxx;
        (a, my - a * mx)
    })
}

/// Compares the measured parallax with `reference` (the scene's exact parallax of each left
/// pixel, `None` on the background; full size), whose parallax at infinity is `at_infinity` px.
/// `None` under 100 pixels with both, or when the reference is flat (one depth).
pub fn compare_reference(
    m: &Measured,
    reference: &[Option<f64>],
    at_infinity: f64,
) -> Option<ReferenceFit> {
    let (w, h) = (m.width, m.map.height * m.scale);
    let mut pairs = Vec::new();
    for y in 0..m.map.height {
        for x in 0..m.map.width {
            let d = m.map.disparity[(y * m.map.width + x) as usize];
            let (fx, fy) = (x * m.scale + m.scale / 2, y * m.scale + m.scale / 2);
            if d.is_nan() || fx >= w || fy >= h {
                continue;
            }
            if let Some(p) = reference.get((fy * w + fx) as usize).copied().flatten() {
                pairs.push((p, f64::from(d)));
            }
        }
    }
    if pairs.len() < 100 {
        return None;
    }
    let (a, b) = line_fit(&pairs)?;
    let kept: Vec<(f64, f64)> = pairs
        .iter()
        .copied()
        .filter(|(x, y)| (y - (a * x + b)).abs() <= 1.5)
        .collect();
    let (slope, offset) = if kept.len() >= 100 {
        line_fit(&kept)?
    } else {
        (a, b)
    };
    let mut errors: Vec<f64> = pairs.iter().map(|(x, y)| (y - x).abs()).collect();
    errors.sort_by(f64::total_cmp);
    Some(ReferenceFit {
        pixels: pairs.len(),
        median: errors[errors.len() / 2],
        slope,
        offset,
        at_infinity,
    })
}

/// The report's lines about the pair against the scene: the agreement, and the mistake that
/// explains a disagreement ([`reference_findings`]).
pub fn describe_reference(fit: &ReferenceFit) -> String {
    let mut s = format!(
        "  against the scene: median |measured − reference| {:.2} px over {} px; measured ≈ \
         {:.3} × reference {:+.2} px\n",
        fit.median, fit.pixels, fit.slope, fit.offset
    );
    let found = reference_findings(fit);
    s += &findings::lines(&found);
    if found.is_empty() && fit.median <= 0.5 {
        s += "  the pair agrees with the scene's rig\n";
    }
    s
}

/// The mistake that explains the pair's disagreement with the scene, by name (all errors):
/// eyes swapped (the slope negative), a wrong separation (the slope more than 5% off 1), half
/// a pixel's shift (0.35–0.65 px at a slope within 5% of 1: a pixel-centre convention), a wrong
/// zero-parallax distance (a shift that makes it more than 5% off). Toe-in is named by the
/// vertical disparity.
pub fn reference_findings(fit: &ReferenceFit) -> Vec<Finding> {
    if fit.slope < 0.0 {
        return vec![Finding::error(
            "eyes swapped",
            "the parallax is the scene's turned around; swap the views (or the cameras)",
        )];
    }
    let mut out = Vec::new();
    let (sep, zp) = fit.factors();
    if (sep - 1.0).abs() > 0.05 {
        out.push(Finding::error(
            "wrong eye separation",
            format!("the pair's is {sep:.2} × the scene's"),
        ));
    }
    if (sep - 1.0).abs() <= 0.05 && (fit.offset.abs() - 0.5).abs() <= 0.15 {
        out.push(Finding::error(
            "half a pixel's shift",
            format!(
                "the views are shifted half a pixel ({:+.2} px) against each other: a \
                 pixel-centre convention (corner against centre)",
                fit.offset
            ),
        ));
    } else if (zp - 1.0).abs() > 0.05 {
        out.push(Finding::error(
            "wrong zero-parallax distance",
            format!(
                "the pair's is {zp:.2} × the scene's (the views shifted {:+.2} px against each \
                 other)",
                fit.offset
            ),
        ));
    }
    out
}

/// The exact parallax of `scene`'s left eye at `width`×`height` (each pixel's, `None` on the
/// background) and its parallax at infinity (px): the reference [`compare_reference`] takes.
///
/// # Errors
/// The scene's rig or size is invalid, or its render fails.
pub fn reference_parallax(
    scene: &crate::scene::Scene,
    width: u32,
    height: u32,
) -> Result<(Vec<Option<f64>>, f64)> {
    use crate::plan::{Output, Plan, View};
    let mut scene = scene.clone();
    scene.set_size(width, height)?;
    let frame = crate::render::render(&scene, &Plan::new(&[Output::LeftDepth]))?;
    let left = frame
        .view(View::Left)
        .ok_or_else(|| Error::internal("inspect", "the left depth pass was not run"))?;
    let rig = scene.parallax_rig()?;
    let map = stereolab_core::parallax_map(left, &rig)?;
    Ok((map, rig.eye_separation * rig.balance * rig.pixels_per_unit))
}
