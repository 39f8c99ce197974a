//! ꟻLIP, the perceptual difference of two pictures as a viewer alternating between them would
//! see it: Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström and Fairchild, "FLIP: A
//! Difference Evaluator for Alternating Images", Proceedings of the ACM on Computer Graphics and
//! Interactive Techniques, 2020. The error map comes from NVIDIA's own C++ implementation of the
//! LDR evaluator (the `nv-flip` crate's bindings); this module adds the viewing condition (pixels
//! per degree from a stated display), the statistics reported beside the exact metrics, and the
//! magma picture of the map, as ꟻLIP's own tool draws it.

use image::RgbImage;

use stereolab_core::{Error, Framebuffer, Result};

/// ꟻLIP's default viewing condition in pixels per degree of visual angle: its paper's and its
/// tool's 67, about a 0.7 m wide display of 3840 pixels across seen from 0.7 m
/// ([`pixels_per_degree`] of [`Display::FLIP_DEFAULT`] is 67.02).
pub const DEFAULT_PPD: f64 = 67.0;

/// Pixels per degree of visual angle of a display `width_m` metres wide showing `resolution_x`
/// pixels across, seen from `distance_m` metres:
/// `ppd = distance · (resolution / width) · π/180`, the pixels on the screen per metre times the
/// metres one degree spans at that distance (small-angle: tan 1° ≈ π/180).
///
/// Source: Andersson et al., "FLIP: A Difference Evaluator for Alternating Images" (2020), its
/// viewing conditions, and the reference implementation's `calculatePPD` (NVlabs/flip).
pub fn pixels_per_degree(distance_m: f64, resolution_x: f64, width_m: f64) -> f64 {
    distance_m * (resolution_x / width_m) * (std::f64::consts::PI / 180.0)
}

/// The display the pictures are assumed seen on: how wide, how far, how many pixels across.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    /// The display's width in metres.
    pub width_m: f64,
    /// The viewer's distance from the display in metres.
    pub distance_m: f64,
    /// The display's horizontal resolution in pixels.
    pub resolution_x: f64,
}

/// Bounds of a sensible display: a phone to a cinema screen, a hand's length to a hall's.
const WIDTH_M: (f64, f64) = (0.01, 100.0);
const DISTANCE_M: (f64, f64) = (0.01, 1000.0);
const RESOLUTION_X: (f64, f64) = (16.0, 100_000.0);
/// Bounds of the pixels per degree ꟻLIP is run at: below 1 a pixel spans more than a degree
/// (no display); print at 600 dpi seen from half a metre is about 200, and above 300 ꟻLIP's
/// filters, as wide as the ppd is large, only make it slow (a 4096×4096 pair: 20 s at 67 ppd,
/// 3 minutes at 1000).
const PPD: (f64, f64) = (1.0, 300.0);

impl Display {
    /// ꟻLIP's default display: 0.7 m wide, 3840 pixels across, seen from 0.7 m.
    pub const FLIP_DEFAULT: Display = Display {
        width_m: 0.7,
        distance_m: 0.7,
        resolution_x: 3840.0,
    };

    /// The display's pixels per degree ([`pixels_per_degree`]).
    pub fn ppd(&self) -> f64 {
        pixels_per_degree(self.distance_m, self.resolution_x, self.width_m)
    }
}

/// A value of a command-line flag, refused unless finite and within `lo..=hi`; the error names
/// the flag.
///
/// # Errors
/// NaN, infinite, or out of range.
fn check_flag(flag: &str, value: f64, (lo, hi): (f64, f64), unit: &str) -> Result<f64> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(Error::invalid(
            flag,
            value,
            format!("expected {lo} to {hi} {unit}"),
        ))
    }
}

/// How ꟻLIP is run: at `ppd` pixels per degree, from the display it was computed for (if any).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewing {
    /// Pixels per degree of visual angle.
    pub ppd: f64,
    /// The display `ppd` was computed from; `None`: ꟻLIP's default or a ppd given directly.
    pub display: Option<Display>,
}

impl Default for Viewing {
    fn default() -> Self {
        Viewing {
            ppd: DEFAULT_PPD,
            display: None,
        }
    }
}

impl Viewing {
    /// The viewing condition of the `--display-width`, `--display-distance`,
    /// `--display-resolution` and `--ppd` flags: none given, ꟻLIP's default 67 ppd; a ppd, that
    /// ppd; any display flag, the display's ppd with the others at ꟻLIP's default display.
    ///
    /// # Errors
    /// A value that is not finite or out of its range (the error names its flag), a display
    /// whose pixels per degree are out of range, or both `--ppd` and a display flag.
    pub fn from_flags(
        width_m: Option<f64>,
        distance_m: Option<f64>,
        resolution_x: Option<f64>,
        ppd: Option<f64>,
    ) -> Result<Viewing> {
        let any_display = width_m.is_some() || distance_m.is_some() || resolution_x.is_some();
        if let Some(p) = ppd {
            if any_display {
                return Err(Error::invalid(
                    "--ppd",
                    p,
                    "give either --ppd or the display (--display-width, --display-distance, \
                     --display-resolution), not both",
                ));
            }
            return Ok(Viewing {
                ppd: check_flag("--ppd", p, PPD, "pixels per degree")?,
                display: None,
            });
        }
        if !any_display {
            return Ok(Viewing::default());
        }
        let d = Display::FLIP_DEFAULT;
        let display = Display {
            width_m: check_flag(
                "--display-width",
                width_m.unwrap_or(d.width_m),
                WIDTH_M,
                "m",
            )?,
            distance_m: check_flag(
                "--display-distance",
                distance_m.unwrap_or(d.distance_m),
                DISTANCE_M,
                "m",
            )?,
            resolution_x: check_flag(
                "--display-resolution",
                resolution_x.unwrap_or(d.resolution_x),
                RESOLUTION_X,
                "pixels",
            )?,
        };
        let ppd = display.ppd();
        if !(PPD.0..=PPD.1).contains(&ppd) {
            return Err(Error::invalid(
                "--display-width, --display-distance, --display-resolution",
                format!(
                    "{} m, {} m, {} px",
                    display.width_m, display.distance_m, display.resolution_x
                ),
                format!(
                    "make {ppd:.3} pixels per degree; ꟻLIP is run at {} to {}",
                    PPD.0, PPD.1
                ),
            ));
        }
        Ok(Viewing {
            ppd,
            display: Some(display),
        })
    }

    /// One line naming the condition, e.g. `ꟻLIP at 67.0 pixels per degree (ꟻLIP's default)`.
    pub fn describe(&self) -> String {
        let whence = match self.display {
            Some(d) => format!(
                "a {} m wide display of {} pixels across, seen from {} m",
                d.width_m, d.resolution_x, d.distance_m
            ),
            None if self.ppd == DEFAULT_PPD => {
                "ꟻLIP's default: about a 0.7 m wide display of 3840 pixels across, seen from 0.7 m"
                    .to_string()
            }
            None => "given with --ppd".to_string(),
        };
        format!("ꟻLIP at {:.2} pixels per degree ({whence})", self.ppd)
    }
}

/// The per-pixel ꟻLIP error of `actual` against `expected` (both sRGB, 8 bits per channel), row
/// by row from the top left: 0 where the two cannot be told apart, up to 1.
///
/// # Errors
/// Pictures of different sizes or empty, or `ppd` not a finite positive number.
pub fn error_map(expected: &RgbImage, actual: &RgbImage, ppd: f64) -> Result<Vec<f32>> {
    if expected.dimensions() != actual.dimensions() {
        let (a, b) = (expected.dimensions(), actual.dimensions());
        return Err(Error::invalid(
            "ꟻLIP",
            format!("{}x{} vs {}x{}", a.0, a.1, b.0, b.1),
            "images must have the same size",
        ));
    }
    let (w, h) = expected.dimensions();
    if w == 0 || h == 0 {
        return Err(Error::invalid(
            "ꟻLIP",
            "0 pixels",
            "images must not be empty",
        ));
    }
    if !(ppd.is_finite() && ppd > 0.0) {
        return Err(Error::invalid(
            "ꟻLIP",
            ppd,
            "pixels per degree must be a finite positive number",
        ));
    }
    let e = nv_flip::FlipImageRgb8::with_data(w, h, expected.as_raw());
    let a = nv_flip::FlipImageRgb8::with_data(w, h, actual.as_raw());
    Ok(nv_flip::flip(e, a, ppd as f32).to_vec())
}

/// The RGB colors of a framebuffer (ꟻLIP takes no alpha).
pub fn rgb(fb: &Framebuffer) -> RgbImage {
    let raw = fb.color().iter().flat_map(|c| [c[0], c[1], c[2]]).collect();
    RgbImage::from_raw(fb.width(), fb.height(), raw).unwrap_or_default()
}

/// An error map in the magma color map, as ꟻLIP's tool writes it (black-purple for 0 through
/// orange to pale yellow for 1; ꟻLIP's own 256-entry table).
///
/// # Errors
/// `errors` does not hold `width × height` values.
pub fn magma(errors: &[f32], width: u32, height: u32) -> Result<RgbImage> {
    if errors.len() != width as usize * height as usize {
        return Err(Error::invalid(
            "ꟻLIP error map",
            format!("{} values", errors.len()),
            format!("expected {width}×{height}"),
        ));
    }
    let map = nv_flip::FlipImageFloat::with_data(width, height, errors);
    let colored = map.apply_color_lut(&nv_flip::magma_lut());
    RgbImage::from_raw(width, height, colored.to_vec())
        .ok_or_else(|| Error::invalid("ꟻLIP error map", width, "the colored map is short"))
}

/// The magma color map itself: ꟻLIP's 256 colors, for error 0, 1/255, …, 1.
pub fn magma_table() -> Vec<[u8; 3]> {
    let ramp: Vec<f32> = (0..256).map(|i| i as f32 / 255.0).collect();
    magma(&ramp, 256, 1)
        .map(|img| img.pixels().map(|p| p.0).collect())
        .unwrap_or_default()
}

/// The summary of an error map: its mean (ꟻLIP's one-number summary, the one its authors
/// recommend) and its percentiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlipStats {
    /// The mean error.
    pub mean: f64,
    /// The median error.
    pub p50: f32,
    /// The 95th percentile.
    pub p95: f32,
    /// The 99th percentile.
    pub p99: f32,
    /// The largest error.
    pub max: f32,
}

impl FlipStats {
    /// The statistics of `errors` (zero for none).
    pub fn of(errors: &[f32]) -> FlipStats {
        let mut sorted = errors.to_vec();
        sorted.sort_by(f32::total_cmp);
        let mean = if sorted.is_empty() {
            0.0
        } else {
            sorted.iter().map(|&e| f64::from(e)).sum::<f64>() / sorted.len() as f64
        };
        FlipStats {
            mean,
            p50: percentile(&sorted, 0.50),
            p95: percentile(&sorted, 0.95),
            p99: percentile(&sorted, 0.99),
            max: sorted.last().copied().unwrap_or(0.0),
        }
    }
}

/// The `q`-quantile (0..=1) of ascending `sorted` values by the nearest-rank method: the
/// smallest value with at least `q · n` values at or below it, `sorted[⌈q·n⌉ − 1]` (the first
/// value for `q = 0`); 0 for no values.
///
/// Source: the inverse of the empirical distribution function, definition 1 of Hyndman and Fan,
/// "Sample Quantiles in Statistical Packages", The American Statistician, 1996.
pub fn percentile(sorted: &[f32], q: f64) -> f32 {
    let n = sorted.len();
    if n == 0 {
        return 0.0;
    }
    let rank = (q.clamp(0.0, 1.0) * n as f64).ceil() as usize;
    sorted[rank.clamp(1, n) - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let v: Vec<f32> = (1..=100).map(|i| i as f32).collect();
        assert_eq!(percentile(&v, 0.5), 50.0);
        assert_eq!(percentile(&v, 0.95), 95.0);
        assert_eq!(percentile(&v, 0.99), 99.0);
        assert_eq!(percentile(&v, 1.0), 100.0);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
        let s = FlipStats::of(&[0.0, 0.5, 1.0, 0.5]);
        assert_eq!((s.mean, s.p50, s.max), (0.5, 0.5, 1.0));
    }

    #[test]
    fn bad_viewing_conditions_are_refused_by_flag() {
        for (w, d, r, flag) in [
            (Some(0.0), None, None, "--display-width"),
            (Some(-0.7), None, None, "--display-width"),
            (None, Some(f64::NAN), None, "--display-distance"),
            (None, None, Some(f64::INFINITY), "--display-resolution"),
            (None, None, Some(1e9), "--display-resolution"),
        ] {
            let e = Viewing::from_flags(w, d, r, None)
                .expect_err(flag)
                .to_string();
            assert!(e.contains(flag), "{e}");
        }
        let e = Viewing::from_flags(Some(0.7), None, None, Some(60.0))
            .expect_err("both")
            .to_string();
        assert!(e.contains("--ppd"), "{e}");
        let v = Viewing::from_flags(None, None, None, None).expect("defaults");
        assert_eq!(v.ppd, DEFAULT_PPD);
    }
}
