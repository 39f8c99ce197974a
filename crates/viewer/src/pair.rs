//! A stereo pair read back by `stereolab inspect` ([`inspect::read`]) and the ways the viewer
//! shows it without a scene: an anaglyph (every kind `stereolab_core` mixes), side by side,
//! cross-eyed, one eye alone, or the disparity map `inspect` measures.
//!
//! A photo pair has no camera to move, so its one depth control is the horizontal image shift:
//! the two views slide against each other by whole pixels, which adds the shift to every
//! parallax and so moves the zero-parallax plane through the scene. Both views are then cut to
//! the columns they still share, as a stereo photo editor crops an aligned pair.
//!
//! Everything here is a pure function of the two views and [`PairParams`], made by the
//! library's own functions ([`stereolab_core::anaglyph`], [`stereolab_core::side_by_side`],
//! [`inspect::disparity_image`]); the window (`pair_window`, private) calls [`compose`].

use std::path::PathBuf;

use image::RgbaImage;
use stereolab::inspect::{self, Layout, Measured, Views};
use stereolab_core::{AnaglyphKind, AnaglyphOptions, Error, Framebuffer, Result};

/// How the pair is shown. The names are `stereolab render`'s output names where one exists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PairMode {
    /// One anaglyph of the two views.
    Anaglyph(AnaglyphKind),
    /// Left | right (parallel viewing).
    SideBySide,
    /// Right | left (cross-eyed viewing).
    CrossEyed,
    /// The left view alone.
    Left,
    /// The right view alone.
    Right,
    /// The disparity map `inspect` measures, with its legend.
    Disparity,
}

impl PairMode {
    /// Every mode: the layouts and single views, the disparity map, then every anaglyph kind
    /// (stereolab's nine, then three.js's table).
    pub fn all() -> Vec<PairMode> {
        let mut all = vec![
            PairMode::SideBySide,
            PairMode::CrossEyed,
            PairMode::Left,
            PairMode::Right,
            PairMode::Disparity,
        ];
        all.extend(AnaglyphKind::ALL.map(PairMode::Anaglyph));
        all.extend(AnaglyphKind::THREE_JS.map(PairMode::Anaglyph));
        all
    }

    /// The mode's name: `anaglyph_dubois`, `side_by_side`, `disparity`, …
    pub fn name(self) -> &'static str {
        match self {
            PairMode::Anaglyph(kind) => kind.output_name(),
            PairMode::SideBySide => "side_by_side",
            PairMode::CrossEyed => "cross_eyed",
            PairMode::Left => "left",
            PairMode::Right => "right",
            PairMode::Disparity => "disparity",
        }
    }

    /// The mode named `name` (`-` and `_` alike).
    ///
    /// # Errors
    /// `Invalid` listing the modes a pair has.
    pub fn parse(name: &str) -> Result<PairMode> {
        let wanted = name.replace('-', "_");
        PairMode::all()
            .into_iter()
            .find(|m| m.name() == wanted)
            .ok_or_else(|| {
                Error::invalid(
                    "--output",
                    name,
                    "a pair of images is shown as side_by_side, cross_eyed, left, right, \
                     disparity or an anaglyph (anaglyph_dubois, anaglyph_color, … as `stereolab \
                     render` names them); the other outputs need a scene",
                )
            })
    }
}

/// What the window shows of the pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PairParams {
    /// The mode.
    pub mode: PairMode,
    /// The horizontal image shift in whole pixels, added to every parallax (`x_right −
    /// x_left`): positive moves the scene back behind the screen, negative brings it forward.
    /// Within ±[`max_shift`] of the width.
    pub shift: i32,
    /// Swap the views before anything else (a pair read in the wrong order).
    pub swap_eyes: bool,
    /// Anaglyphs: mix in linear light ([`AnaglyphOptions::linear_light`]).
    pub linear_light: bool,
    /// Anaglyphs: Rendepth's anti-rivalry stage ([`AnaglyphOptions::anti_rivalry`]).
    pub anti_rivalry: bool,
}

impl Default for PairParams {
    /// The Dubois red-cyan anaglyph, no shift.
    fn default() -> PairParams {
        PairParams {
            mode: PairMode::Anaglyph(AnaglyphKind::DuboisRedCyan),
            shift: 0,
            swap_eyes: false,
            linear_light: false,
            anti_rivalry: false,
        }
    }
}

/// The largest image shift for views `width` pixels wide: ⅛ of the width, the parallax
/// `inspect` searches, so the shift can bring any parallax it measured to zero.
pub fn max_shift(width: u32) -> i32 {
    (width / 8) as i32
}

/// The pair: its two views, the files they came from, and the measurement if there is one.
#[derive(Clone, Debug)]
pub struct Pair {
    /// The views, the layout taken and why.
    pub views: Views,
    /// The files given (one, or a left and a right).
    pub images: Vec<PathBuf>,
    /// The disparity measured already (`stereolab inspect --view` hands over its own);
    /// `None`: the window measures it on a worker thread.
    pub measured: Option<Measured>,
}

impl Pair {
    /// Reads `images` as `stereolab inspect` does ([`inspect::read`]).
    ///
    /// # Errors
    /// The inspect errors: an unreadable file, a layout that does not fit, no stereo layout
    /// found.
    pub fn read(images: &[PathBuf], layout: Option<Layout>) -> Result<Pair> {
        Ok(Pair {
            views: inspect::read(images, layout)?,
            images: images.to_vec(),
            measured: None,
        })
    }

    /// The width of one view.
    pub fn width(&self) -> u32 {
        self.views.left.width()
    }

    /// The files' names for the title and the readouts: `a.png` or `l.png + r.png`.
    pub fn names(&self) -> String {
        let names: Vec<String> = self
            .images
            .iter()
            .map(|p| {
                p.file_name()
                    .map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into())
            })
            .collect();
        names.join(" + ")
    }
}

/// The two views slid against each other by `shift` pixels and cut to their common columns:
/// the left view loses its first `shift` columns (a positive shift), or the right view its
/// first `−shift`; both lose the same number at their right edge. A point at `x_l` in the left
/// view and `x_r` in the right then lies at `x_l − a` and `x_r − b` with `a − b = shift`, so its
/// parallax grows by `shift`.
///
/// # Errors
/// `|shift|` above [`max_shift`], or views of different sizes.
pub fn shifted(
    left: &RgbaImage,
    right: &RgbaImage,
    shift: i32,
) -> Result<(Framebuffer, Framebuffer)> {
    let (w, h) = left.dimensions();
    if right.dimensions() != (w, h) {
        return Err(Error::invalid(
            "pair",
            format!("{w}×{h} and {:?}", right.dimensions()),
            "the two views must have the same size",
        ));
    }
    let max = max_shift(w);
    if shift.abs() > max {
        return Err(Error::invalid(
            "image shift",
            shift,
            format!("must lie in −{max}..={max} px (⅛ of the width)"),
        ));
    }
    let keep = w - shift.unsigned_abs();
    let (a, b) = if shift >= 0 {
        (shift as u32, 0)
    } else {
        (0, shift.unsigned_abs())
    };
    let cut = |img: &RgbaImage, from: u32| {
        let part = image::imageops::crop_imm(img, from, 0, keep, h).to_image();
        stereolab_core::rds_framebuffer(&part)
    };
    Ok((cut(left, a), cut(right, b)))
}

/// The picture of `views` under `params`: an anaglyph, a layout or one view, of the views
/// swapped if asked and shifted ([`shifted`]). The disparity mode shows `disparity` (from
/// [`inspect::disparity_image`], of the pair as read: neither swapped nor shifted), `None`
/// while it is still being measured.
///
/// # Errors
/// A shift beyond [`max_shift`], or views of different sizes.
pub fn compose(
    views: &Views,
    params: &PairParams,
    disparity: Option<&RgbaImage>,
) -> Result<Option<RgbaImage>> {
    let (left, right) = if params.swap_eyes {
        (&views.right, &views.left)
    } else {
        (&views.left, &views.right)
    };
    let (l, r) = shifted(left, right, params.shift)?;
    let image = match params.mode {
        PairMode::Anaglyph(kind) => {
            let options = AnaglyphOptions {
                linear_light: params.linear_light,
                swap_eyes: false,
                anti_rivalry: params.anti_rivalry,
            };
            stereolab_core::anaglyph(&l, &r, kind, options)?
        }
        PairMode::SideBySide => stereolab_core::side_by_side(&l, &r)?,
        PairMode::CrossEyed => stereolab_core::side_by_side(&r, &l)?,
        PairMode::Left => l.to_rgba_image(),
        PairMode::Right => r.to_rgba_image(),
        PairMode::Disparity => return Ok(disparity.cloned()),
    };
    Ok(Some(image))
}

/// The measurement and its picture (the map with its legend), as `stereolab inspect` makes
/// them: `measured` if given, else [`inspect::measure`].
///
/// # Errors
/// The views are too small to match.
pub fn measure(views: &Views, measured: Option<Measured>) -> Result<(Measured, RgbaImage)> {
    let m = match measured {
        Some(m) => m,
        None => inspect::measure(views)?,
    };
    let picture = inspect::disparity_image(&m)?;
    Ok((m, picture))
}

/// The readout of a measurement under an image shift: the measured 5th percentile, median
/// and 95th percentile of the parallax, each moved by the shift.
pub fn shifted_percentiles(m: &Measured, shift: i32) -> Option<[f64; 3]> {
    m.percentiles.map(|p| p.map(|v| v + f64::from(shift)))
}

/// The shift that puts the measured median at zero parallax (the screen), within the bounds.
pub fn shift_to_median(m: &Measured) -> Option<i32> {
    let max = max_shift(m.width);
    m.percentiles
        .map(|[_, median, _]| (-median.round() as i32).clamp(-max, max))
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    /// A left view of random dots, and the right view the same dots `parallax` pixels
    /// further right.
    fn pair(w: u32, h: u32, parallax: u32) -> Views {
        let band = |x: u32, y: u32| {
            let v = ((x.wrapping_mul(73_856_093) ^ y.wrapping_mul(19_349_663))
                .wrapping_mul(2_654_435_761)
                >> 24) as u8;
            Rgba([v, 255 - v, v / 2, 255])
        };
        let left = RgbaImage::from_fn(w, h, band);
        let right = RgbaImage::from_fn(w, h, |x, y| {
            if x >= parallax {
                band(x - parallax, y)
            } else {
                Rgba([0, 0, 0, 255])
            }
        });
        Views {
            left,
            right,
            layout: Layout::Pair,
            evidence: "given".into(),
        }
    }

    #[test]
    fn every_mode_has_a_name_that_parses_back() {
        let all = PairMode::all();
        assert_eq!(all.len(), 5 + 9 + 21);
        for m in all {
            assert_eq!(PairMode::parse(m.name()).unwrap(), m);
        }
        assert_eq!(
            PairMode::parse("anaglyph-dubois").unwrap(),
            PairMode::Anaglyph(AnaglyphKind::DuboisRedCyan)
        );
        let e = PairMode::parse("chromadepth").unwrap_err().to_string();
        assert!(e.contains("need a scene"), "{e}");
    }

    /// The shift that undoes the pair's parallax leaves two equal views: each anaglyph kind
    /// then mixes a pixel with itself, as the library's own function says.
    #[test]
    fn a_shift_of_minus_the_parallax_makes_the_views_equal() {
        let views = pair(64, 20, 5);
        let (l, r) = shifted(&views.left, &views.right, -5).unwrap();
        assert_eq!((l.width(), l.height()), (59, 20));
        assert_eq!(l.color(), r.color());
        for kind in [AnaglyphKind::DuboisRedCyan, AnaglyphKind::Color] {
            let params = PairParams {
                mode: PairMode::Anaglyph(kind),
                shift: -5,
                ..PairParams::default()
            };
            let img = compose(&views, &params, None).unwrap().unwrap();
            let m = kind.matrices();
            for (x, y, p) in img.enumerate_pixels() {
                let v = views.left.get_pixel(x, y).0;
                let want = stereolab_core::anaglyph_pixel(&m, v, v, false);
                assert_eq!(p.0, want, "{kind:?} at ({x}, {y})");
            }
        }
        // At no shift the views differ.
        let (l, r) = shifted(&views.left, &views.right, 0).unwrap();
        assert_ne!(l.color(), r.color());
    }

    #[test]
    fn a_positive_shift_cuts_the_left_view_and_layouts_keep_the_order() {
        let views = pair(64, 20, 5);
        let (l, r) = shifted(&views.left, &views.right, 3).unwrap();
        assert_eq!(l.pixel(0, 4), views.left.get_pixel(3, 4).0);
        assert_eq!(r.pixel(0, 4), views.right.get_pixel(0, 4).0);
        let sbs = PairParams {
            mode: PairMode::SideBySide,
            shift: 3,
            ..PairParams::default()
        };
        let img = compose(&views, &sbs, None).unwrap().unwrap();
        assert_eq!(img.dimensions(), (2 * 61, 20));
        assert_eq!(img.get_pixel(0, 4).0, l.pixel(0, 4));
        assert_eq!(img.get_pixel(61, 4).0, r.pixel(0, 4));
        let cross = PairParams {
            mode: PairMode::CrossEyed,
            swap_eyes: true,
            ..sbs
        };
        // Cross-eyed of the swapped pair is side by side of the pair read, but the shift then
        // cuts the other view.
        let img = compose(&views, &cross, None).unwrap().unwrap();
        assert_eq!(img.get_pixel(0, 4).0, views.left.get_pixel(0, 4).0);
        assert_eq!(img.get_pixel(61, 4).0, views.right.get_pixel(3, 4).0);
    }

    #[test]
    fn the_shift_is_bounded_and_the_disparity_mode_waits_for_its_map() {
        let views = pair(64, 20, 5);
        assert_eq!(max_shift(64), 8);
        let e = shifted(&views.left, &views.right, 9)
            .unwrap_err()
            .to_string();
        assert!(e.contains("−8..=8"), "{e}");
        let params = PairParams {
            mode: PairMode::Disparity,
            ..PairParams::default()
        };
        assert!(compose(&views, &params, None).unwrap().is_none());
        let map = RgbaImage::new(3, 3);
        assert_eq!(compose(&views, &params, Some(&map)).unwrap(), Some(map));
    }

    /// The measured parallax of the pair is the band's 5 px; the median shift brings it to 0.
    #[test]
    fn the_median_shift_puts_the_measured_parallax_on_the_screen() {
        let views = pair(96, 48, 5);
        let (m, picture) = measure(&views, None).unwrap();
        assert!(picture.width() > 0);
        let [_, median, _] = m.percentiles.unwrap();
        assert!((median - 5.0).abs() < 0.5, "median {median}");
        assert_eq!(shift_to_median(&m), Some(-5));
        let [_, at, _] = shifted_percentiles(&m, -5).unwrap();
        assert!(at.abs() < 0.5, "{at}");
    }
}
