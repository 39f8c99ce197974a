//! Screen parallax per pixel, `p(z) = d·(1 − z0/z)` (the exercise slides), drawn as color (blue negative,
//! red positive, as the exercise slides' last slide), and the StereoGraphics guide's parallax budget.
//!
//! Per pixel, as a shader: the window depth back to the eye distance z ([`ParallaxRig::
//! eye_distance`]), then `p(z)` in world units at the zero-parallax plane, then in pixels
//! (`× W / Xrange`, Xrange the view width at z0). Positive parallax lies behind the screen (the
//! right eye's image of a point is right of the left eye's), as the StereoGraphics guide (Akka) defines it.

use std::mem::MaybeUninit;

use image::RgbaImage;
use rayon::prelude::*;

use super::legend::{LEGEND_HEIGHT, draw_legend_into, draw_legend_reference};
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;
use crate::math::{Camera, CameraMode, StereoRig};
use crate::simd::{Kernels, kernels};

#[cfg(target_arch = "x86_64")]
mod avx2;

/// The StereoGraphics guide (Akka): keep negative and positive parallax each within about 3% of the image width.
pub const PARALLAX_BUDGET_PERCENT: f32 = 3.0;

/// The rig's numbers the parallax formula needs, resolved for one image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParallaxRig {
    /// Eye separation d (world units, `user_offset` applied).
    pub eye_separation: f64,
    /// Zero-parallax distance z0.
    pub zero_parallax_distance: f64,
    /// The StereoGraphics guide's `UserBalanceAdjustment` b (off-axis), 1 for toe-in, 0 for
    /// parallel axes; for image-shift the balance its whole-pixel shift applies
    /// ([`crate::math::ImageShift::balance`]).
    pub balance: f64,
    /// Near plane distance n.
    pub near: f64,
    /// Far plane distance f.
    pub far: f64,
    /// Pixels per world unit at the zero-parallax plane: `W / Xrange`.
    pub pixels_per_unit: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl ParallaxRig {
    /// Resolves `rig` against `camera` for a `width`×`height` image.
    ///
    /// # Errors
    /// As [`StereoRig::resolve`] and [`Camera::validate`].
    pub fn new(rig: &StereoRig, camera: &Camera, width: u32, height: u32) -> Result<Self> {
        camera.validate()?;
        let r = rig.resolve(camera, width as f32 / height as f32)?;
        Ok(ParallaxRig {
            eye_separation: r.eye_separation as f64,
            zero_parallax_distance: r.zero_parallax_distance as f64,
            balance: match rig.mode {
                CameraMode::OffAxis => rig.user_balance as f64,
                CameraMode::ToeIn => 1.0,
                CameraMode::Parallel => 0.0,
                CameraMode::ImageShift => rig.image_shift(camera, width, height)?.balance,
            },
            near: camera.near as f64,
            far: camera.far as f64,
            pixels_per_unit: width as f64 / r.xrange as f64,
            width,
            height,
        })
    }

    /// Eye distance z of a window depth `d_w` (inverting `d_w = f/(f−n)·(1 − n/z)`, the
    /// depth `P_frustum` and `glDepthRange(0, 1)` produce): `z = n f / (f − d_w (f − n))`.
    #[inline]
    pub fn eye_distance(&self, window_depth: f32) -> f64 {
        let (n, f) = (self.near, self.far);
        n * f / (f - window_depth as f64 * (f - n))
    }

    /// Screen parallax of a point at eye distance z, world units at the zero-parallax plane:
    /// `p(z) = d·(b − z0/z)`. With the StereoGraphics guide's balance b = 1 this is the exercise slides'
    /// `p(z) = d·(1 − z0/z)`; b scales the frustum shift (`n·d/(2 z0)·b`), b = 0 is parallel
    /// axes. Exact for off-axis and parallel rigs; for toe-in a first-order approximation on the
    /// center line (0.3% off at wuson's nearest depths; tests/figures.rs measures it).
    #[inline]
    pub fn parallax(&self, z: f64) -> f64 {
        self.eye_separation * (self.balance - self.zero_parallax_distance / z)
    }

    /// Parallax in pixels of the point a pixel with window depth `d_w` shows; `None` for the
    /// background (depth 1).
    #[inline]
    pub fn parallax_pixels(&self, window_depth: f32) -> Option<f64> {
        (window_depth < 1.0)
            .then(|| self.parallax(self.eye_distance(window_depth)) * self.pixels_per_unit)
    }

    /// [`color_scale`] of the budget of a depth buffer (`width × height` values, any row
    /// length): the largest |parallax| in pixels over the drawn pixels (depth < 1), at least
    /// half a pixel, or ½ when nothing is drawn. Computed without the parallax map.
    ///
    /// Found from the two depth extremes alone. Every step of [`Self::parallax_pixels`] is
    /// monotone in the window depth, rounding included (IEEE rounding is monotone): `d·(f−n)`
    /// grows with d, `f − d(f−n)` shrinks and stays ≥ 0 (for d < 1 the product is at most
    /// `fl(f−n) ≤ f`), `n f / (…)` grows (to +∞ at 0), `z0/z` moves one way, `b − z0/z` the
    /// other, and the products with d and W/Xrange keep the order or reverse it throughout. So
    /// p is monotone in d, and the extremes of p are at the nearest and the farthest drawn
    /// depth (up to the sign of a zero, which |p| drops). That needs `0 < n < f` and finite
    /// factors, which a resolved rig has; other values get the full scan, as [`budget`] does
    /// it. `parallax_image_matches_reference` holds the result to the full map.
    fn color_scale_of(&self, depth: &[f32]) -> f64 {
        let monotone = self.near > 0.0
            && self.far > self.near
            && [
                self.far,
                self.zero_parallax_distance,
                self.eye_separation,
                self.balance,
                self.pixels_per_unit,
            ]
            .iter()
            .all(|v| v.is_finite());
        let extremes = if monotone {
            // The drawn depths' extremes, per block in parallel (min and max are exact, so the
            // result does not depend on the split).
            let (lo, hi) = depth
                .par_chunks(1 << 14)
                .map(drawn_extremes)
                .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
            let p = |b: u32| self.parallax_pixels(f32::from_bits(b));
            (lo != u32::MAX)
                .then(|| p(lo).zip(p(hi)).map(|(a, b)| (a.min(b), a.max(b))))
                .flatten()
        } else {
            depth
                .iter()
                .filter_map(|d| self.parallax_pixels(*d))
                .fold(None, |e, p| {
                    let (lo, hi) = e.unwrap_or((f64::INFINITY, f64::NEG_INFINITY));
                    Some((lo.min(p), hi.max(p)))
                })
        };
        extremes.map_or(0.5, |(lo, hi)| lo.abs().max(hi.abs()).max(0.5))
    }

    /// `fb` has the size the rig was resolved for.
    fn check_size(&self, fb: &Framebuffer) -> Result<()> {
        if (fb.width, fb.height) != (self.width, self.height) {
            return Err(Error::invalid(
                "parallax framebuffer",
                format!("{}x{}", fb.width, fb.height),
                format!("the rig was resolved for {}x{}", self.width, self.height),
            ));
        }
        Ok(())
    }
}

/// The smallest and largest bit patterns of the drawn (< 1) depths of `c`, `(u32::MAX, 0)`
/// when none is drawn. For depths in [0, 1] (a framebuffer's) with the sign bit cleared (so −0
/// reads as 0) the order of the bits is the order of the values. Eight at a time on AVX2
/// (`avx2::drawn_extremes`), else [`drawn_extremes_scalar`].
fn drawn_extremes(c: &[f32]) -> (u32, u32) {
    #[cfg(target_arch = "x86_64")]
    if kernels().avx2() {
        // SAFETY: the CPU has AVX2 (checked above), the function's only requirement. The same
        // result as the scalar fold (`avx2_drawn_extremes_match_scalar`).
        return unsafe { avx2::drawn_extremes(c) };
    }
    drawn_extremes_scalar(c)
}

/// [`drawn_extremes`] one depth at a time, the reference.
fn drawn_extremes_scalar(c: &[f32]) -> (u32, u32) {
    const ONE: u32 = 0x3f80_0000;
    c.iter().fold((u32::MAX, 0), |(lo, hi), d| {
        let b = d.to_bits() & 0x7fff_ffff;
        if b < ONE {
            (lo.min(b), hi.max(b))
        } else {
            (lo, hi)
        }
    })
}

/// Parallax in pixels of every pixel of `fb` (row-major), `None` on the background.
///
/// # Errors
/// A size other than the rig's.
pub fn parallax_map(fb: &Framebuffer, rig: &ParallaxRig) -> Result<Vec<Option<f64>>> {
    rig.check_size(fb)?;
    Ok(fb.depth.iter().map(|d| rig.parallax_pixels(*d)).collect())
}

/// The StereoGraphics guide's parallax budget over one eye's pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParallaxBudget {
    /// Image width (parallax percentages are of this).
    pub width: u32,
    /// Pixels showing geometry (depth < 1).
    pub drawn: usize,
    /// Most negative parallax, pixels (in front of the screen).
    pub min_pixels: f64,
    /// Most positive parallax, pixels (behind the screen).
    pub max_pixels: f64,
    /// Drawn pixels whose |parallax| exceeds [`PARALLAX_BUDGET_PERCENT`] of the width.
    pub beyond_budget: usize,
    /// Border pixels with negative parallax (the StereoGraphics guide's window violation), per side:
    /// left, right, top, bottom.
    pub window_violations: [usize; 4],
}

impl ParallaxBudget {
    /// `pixels` as percent of the image width.
    pub fn percent(&self, pixels: f64) -> f64 {
        pixels / self.width as f64 * 100.0
    }

    /// Share (0..1) of drawn pixels beyond the budget.
    pub fn share_beyond(&self) -> f64 {
        self.beyond_budget as f64 / self.drawn.max(1) as f64
    }

    /// The lines `stereolab info` and the render report print.
    pub fn report(&self) -> String {
        if self.drawn == 0 {
            return "parallax budget: no geometry drawn\n".into();
        }
        let sides = ["left", "right", "top", "bottom"];
        let violations: Vec<String> = sides
            .iter()
            .zip(self.window_violations)
            .filter(|(_, n)| *n > 0)
            .map(|(s, n)| format!("{s} {n} px"))
            .collect();
        format!(
            "parallax budget (per pixel, {} drawn): min {:+.2} px ({:+.3}%), max {:+.2} px ({:+.3}%)\n  \
             beyond ±{}% of width: {:.2}% of drawn pixels ({})\n  window violations (negative parallax at the border): {}\n",
            self.drawn,
            self.min_pixels,
            self.percent(self.min_pixels),
            self.max_pixels,
            self.percent(self.max_pixels),
            PARALLAX_BUDGET_PERCENT,
            self.share_beyond() * 100.0,
            self.beyond_budget,
            if violations.is_empty() {
                "none".to_string()
            } else {
                violations.join(", ")
            }
        )
    }
}

/// The budget of a parallax map of a `width`×`height` image.
pub fn budget(map: &[Option<f64>], width: u32, height: u32) -> ParallaxBudget {
    let limit = PARALLAX_BUDGET_PERCENT as f64 / 100.0 * width as f64;
    let mut b = ParallaxBudget {
        width,
        drawn: 0,
        min_pixels: f64::INFINITY,
        max_pixels: f64::NEG_INFINITY,
        beyond_budget: 0,
        window_violations: [0; 4],
    };
    for (i, p) in map.iter().enumerate() {
        let Some(p) = *p else { continue };
        let (x, y) = ((i % width as usize) as u32, (i / width as usize) as u32);
        b.drawn += 1;
        b.min_pixels = b.min_pixels.min(p);
        b.max_pixels = b.max_pixels.max(p);
        b.beyond_budget += (p.abs() > limit) as usize;
        if p < 0.0 {
            let on = [x == 0, x + 1 == width, y == 0, y + 1 == height];
            for (v, on) in b.window_violations.iter_mut().zip(on) {
                *v += on as usize;
            }
        }
    }
    b
}

/// The budget of one eye's depth buffer.
///
/// # Errors
/// As [`parallax_map`].
pub fn budget_of(fb: &Framebuffer, rig: &ParallaxRig) -> Result<ParallaxBudget> {
    Ok(budget(&parallax_map(fb, rig)?, fb.width, fb.height))
}

/// Color of background pixels in the parallax image.
pub const PARALLAX_BACKGROUND: [u8; 4] = [24, 24, 24, 255];

/// The exercise slides' parallax color: white at zero, towards blue (0, 64, 255) for negative and red
/// (255, 32, 0) for positive parallax, saturating at ±`scale` pixels.
#[inline]
pub fn parallax_color(pixels: f64, scale: f64) -> [u8; 4] {
    let t = (pixels / scale).clamp(-1.0, 1.0);
    let (end, s) = if t < 0.0 {
        ([0.0, 64.0, 255.0], -t)
    } else {
        ([255.0, 32.0, 0.0], t)
    };
    let c = |k: usize| (255.0 + (end[k] - 255.0) * s).round() as u8;
    [c(0), c(1), c(2), 255]
}

/// The symmetric color scale of a budget: the largest |parallax|, at least half a pixel.
pub fn color_scale(b: &ParallaxBudget) -> f64 {
    if b.drawn == 0 {
        return 0.5;
    }
    b.min_pixels.abs().max(b.max_pixels.abs()).max(0.5)
}

/// The color that marks a window violation on the parallax image: yellow, on no point of the
/// blue–white–red scale.
pub const VIOLATION_COLOR: [u8; 4] = [255, 220, 0, 255];

/// How far into the image a window violation's mark reaches: `max(2, W/64)` pixels.
pub fn violation_band(width: u32) -> u32 {
    (width / 64).max(2)
}

/// The pixels (row-major indices) that mark the StereoGraphics guide's window violations on the
/// parallax image: where a border pixel shows negative parallax (an object in front of the
/// screen cut by the window's edge, the count [`ParallaxBudget::window_violations`] reports),
/// a band [`violation_band`] pixels deep runs from that border pixel into the image, across
/// the border (along its row at the left and right edges, its column at the top and bottom).
/// Sorted and without repeats; empty when nothing violates the window.
pub fn window_violation_marks(map: &[Option<f64>], width: u32, height: u32) -> Vec<usize> {
    let w = width as usize;
    violation_marks_where(width, height, |x, y| {
        map[y * w + x].is_some_and(|p| p < 0.0)
    })
}

/// [`window_violation_marks`] with `negative(x, y)` saying whether pixel (x, y) shows negative
/// parallax; it is asked about border pixels only.
fn violation_marks_where(
    width: u32,
    height: u32,
    negative: impl Fn(usize, usize) -> bool,
) -> Vec<usize> {
    let (w, h) = (width as usize, height as usize);
    if w == 0 || h == 0 {
        return Vec::new();
    }
    let band = (violation_band(width) as usize).min(w).min(h);
    let mut marks = Vec::new();
    for y in 0..h {
        for (x, step) in [(0usize, 1isize), (w - 1, -1)] {
            if negative(x, y) {
                marks.extend((0..band).map(|k| y * w + (x as isize + step * k as isize) as usize));
            }
        }
    }
    for x in 0..w {
        for (y, step) in [(0usize, 1isize), (h - 1, -1)] {
            if negative(x, y) {
                marks.extend((0..band).map(|k| (y as isize + step * k as isize) as usize * w + x));
            }
        }
    }
    marks.sort_unstable();
    marks.dedup();
    marks
}

/// One pixel of the parallax image before the window marks: the background color, or
/// [`parallax_color`] of the pixel's parallax.
#[inline]
pub fn parallax_pixel_color(rig: &ParallaxRig, window_depth: f32, scale: f64) -> [u8; 4] {
    rig.parallax_pixels(window_depth)
        .map_or(PARALLAX_BACKGROUND, |p| parallax_color(p, scale))
}

/// [`parallax_image`] as the readable program it is held to (`parallax_image_matches_reference`):
/// the parallax map, its budget, the color scale, the colors, the marks, the legend (drawn by
/// tiny-skia, [`draw_legend_reference`]).
///
/// # Errors
/// As [`parallax_map`].
pub fn parallax_image_reference(fb: &Framebuffer, rig: &ParallaxRig) -> Result<RgbaImage> {
    let map = parallax_map(fb, rig)?;
    let b = budget(&map, fb.width, fb.height);
    let scale = color_scale(&b);
    let legend = draw_legend_reference(fb.width, scale, &|p| parallax_color(p, scale))?;
    let mut bytes: Vec<u8> = map
        .iter()
        .flat_map(|p| p.map_or(PARALLAX_BACKGROUND, |p| parallax_color(p, scale)))
        .collect();
    for i in window_violation_marks(&map, fb.width, fb.height) {
        bytes[4 * i..4 * i + 4].copy_from_slice(&VIOLATION_COLOR);
    }
    bytes.extend_from_slice(legend.data());
    let h = fb.height + legend.height();
    Ok(RgbaImage::from_raw(fb.width, h, bytes).expect("4 bytes per pixel"))
}

/// The parallax of one eye's depth buffer as color, with a legend bar (drawn with tiny-skia)
/// appended below the image: the color scale from −S to +S pixels, ticks at 0 and at seed
/// 003's ±3% budget, labels in pixels and percent of the width. Window violations are marked
/// in [`VIOLATION_COLOR`] ([`window_violation_marks`]).
///
/// The same bytes as [`parallax_image_reference`] (the readable program: the parallax map, its
/// budget, the colors), computed without the map: S from the depth extremes
/// (`ParallaxRig::color_scale_of`), each row's colors in parallel, four pixels at a time on
/// AVX2 where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)) (`parallax/avx2.rs`, the scalar [`parallax_color`]
/// elsewhere), the window violations from the border pixels alone.
///
/// # Errors
/// As [`parallax_map`].
pub fn parallax_image(fb: &Framebuffer, rig: &ParallaxRig) -> Result<RgbaImage> {
    parallax_image_on(fb, rig, kernels())
}

/// [`parallax_image`] on the rows `kernels` names: the AVX2 rows, or the scalar loop over
/// [`parallax_pixel_color`] (the same bytes).
fn parallax_image_on(fb: &Framebuffer, rig: &ParallaxRig, kernels: Kernels) -> Result<RgbaImage> {
    rig.check_size(fb)?;
    let scale = rig.color_scale_of(&fb.depth);
    let (w, n) = (fb.width as usize, fb.depth.len());
    let simd = kernels.avx2();
    // The AVX2 rows' affine form of the color scale, once per image.
    #[cfg(target_arch = "x86_64")]
    // SAFETY: only where `simd` says the CPU has AVX2, `Affine::of`'s only requirement.
    let affine = simd
        .then(|| unsafe { avx2::Affine::of(rig, scale) })
        .flatten();
    // Rows in parallel: every pixel is independent, so the bytes do not depend on the threads.
    let fill = |y: usize, out: &mut [MaybeUninit<[u8; 4]>]| {
        let depth = &fb.depth[y * w..y * w + out.len()];
        #[cfg(target_arch = "x86_64")]
        if simd {
            // SAFETY: `simd` holds only where `Kernels::avx2` found AVX2, the row's only
            // safety condition. The same bytes as the loop below
            // (`avx2_rows_match_parallax_color`).
            unsafe { avx2::row(rig, scale, affine.as_ref(), depth, out) };
            return;
        }
        let _ = simd;
        for (out, d) in out.iter_mut().zip(depth) {
            out.write(parallax_pixel_color(rig, *d, scale));
        }
    };
    // The legend is drawn into the rows below the image while the image's rows are colored
    // (it needs only the width and the scale): one thread would otherwise draw it while the
    // other waited.
    let legend_px = w * LEGEND_HEIGHT as usize;
    let mut out: Vec<[u8; 4]> = Vec::with_capacity(n + legend_px);
    let (rows, legend) = out.spare_capacity_mut()[..n + legend_px].split_at_mut(n);
    let (drawn, ()) = rayon::join(
        || draw_legend_into(legend, fb.width, scale, &|p| parallax_color(p, scale)),
        || {
            rows.par_chunks_mut(w.max(1))
                .enumerate()
                .with_max_len(super::rows_per_task(w))
                .for_each(|(y, row)| fill(y, row))
        },
    );
    drawn?;
    // SAFETY: the rows (a framebuffer holds width × height depths, one pixel each) and
    // the legend wrote every one of the first n + legend_px elements, within the capacity.
    unsafe { out.set_len(n + legend_px) };
    let mut bytes = out.into_flattened();
    let negative = |x: usize, y: usize| {
        rig.parallax_pixels(fb.depth[y * w + x])
            .is_some_and(|p| p < 0.0)
    };
    for i in violation_marks_where(fb.width, fb.height, negative) {
        bytes[4 * i..4 * i + 4].copy_from_slice(&VIOLATION_COLOR);
    }
    let h = fb.height + LEGEND_HEIGHT;
    Ok(RgbaImage::from_raw(fb.width, h, bytes).expect("4 bytes per pixel"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rig with the eye separation 0.065 and the given planes and size (also the AVX2 rows'
    /// tests').
    pub(super) fn rig(
        near: f64,
        far: f64,
        z0: f64,
        balance: f64,
        width: u32,
        height: u32,
    ) -> ParallaxRig {
        ParallaxRig {
            eye_separation: 0.065,
            zero_parallax_distance: z0,
            balance,
            near,
            far,
            pixels_per_unit: width as f64 / 1.7,
            width,
            height,
        }
    }

    /// `parallax_image` (AVX2 rows where the CPU has them, and the scalar rows) gives
    /// `parallax_image_reference`'s bytes: sizes from 1×1 (no legend bar) to odd widths, depth
    /// buffers with nothing drawn, everything drawn, negative parallax at every border (window
    /// marks), one drawn pixel, and rigs whose extremes cannot be read off the depth extremes
    /// (far < near, a non-finite factor: the full scan).
    #[test]
    fn parallax_image_matches_reference() {
        let mut state = 0x853c_49e6_748f_ea9b_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut cases = 0;
        for (width, height) in [(1, 1), (2, 3), (13, 7), (37, 19), (130, 41)] {
            let rigs = [
                rig(0.1, 50.0, 4.0, 1.0, width, height),
                rig(1.0, 20.0, 19.0, 0.0, width, height),
                rig(1e-5, 1.0, 0.5, 0.5, width, height),
                rig(3.0, 2.0, 2.5, 1.0, width, height),
                rig(0.1, 50.0, f64::INFINITY, 1.0, width, height),
            ];
            for (k, r) in rigs.iter().enumerate() {
                for pattern in 0..5 {
                    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255]).unwrap();
                    for (i, d) in fb.depth.iter_mut().enumerate() {
                        *d = match pattern {
                            0 => 1.0,
                            1 => (next() % 1_000_000) as f32 / 1e6,
                            2 => {
                                // Near (negative parallax) along the borders, far inside.
                                let (x, y) = (i as u32 % width, i as u32 / width);
                                if x == 0 || y == 0 || x + 1 == width || y + 1 == height {
                                    (next() % 1000) as f32 * 1e-5
                                } else {
                                    0.9 + (next() % 1000) as f32 * 1e-4
                                }
                            }
                            3 if i == 0 => 0.25,
                            3 => 1.0,
                            _ if next() % 3 == 0 => 1.0,
                            _ => (next() % 1_000_000) as f32 / 1e6,
                        };
                    }
                    let want = parallax_image_reference(&fb, r).unwrap();
                    for kernels in [Kernels::Avx2, Kernels::Scalar] {
                        let got = parallax_image_on(&fb, r, kernels).unwrap();
                        assert_eq!(got.dimensions(), want.dimensions());
                        if let Some(i) = got
                            .as_raw()
                            .iter()
                            .zip(want.as_raw())
                            .position(|(a, b)| a != b)
                        {
                            panic!(
                                "{width}x{height}, rig {k}, pattern {pattern}, {kernels:?}: byte {i} \
                                 (pixel {}) differs",
                                i / 4
                            );
                        }
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 5 * 5 * 5 * 2);
    }

    /// Bad input is an error, not a panic: a framebuffer of another size than the rig's.
    #[test]
    fn parallax_image_rejects_a_size_mismatch() {
        let fb = Framebuffer::new(4, 4, [0, 0, 0, 255]).unwrap();
        let err = parallax_image(&fb, &rig(0.1, 50.0, 4.0, 1.0, 5, 4)).unwrap_err();
        assert!(err.to_string().contains("5x4"), "{err}");
    }
}
