//! Which anaglyph method made a picture, estimated from its channels.
//!
//! Where the scene has a uniform area wider than the parallax, both eyes see the same colour
//! `c` there, and the anaglyph shows `clamp((ML + MR)·c)`: each method can only produce the
//! colours of its sum matrix applied to the colour cube (in stored values, or in linear light
//! when it mixes there). A gray method's colours all have green equal to blue; the colour
//! method produces any colour; a half-colour method cannot produce a saturated red, since its
//! red is a luma. For every known method and each of the picture's uniform colours the nearest
//! colour it can produce is found (a least-squares fit over the cube, clamped channels counting
//! only past their limit); a method explains the picture when it comes within four levels of
//! nearly all of them. The colour method produces every colour, so it always explains: of the
//! methods that explain, the most likely is the narrowest: the one whose colours span the fewest
//! dimensions (the rank of `ML + MR`: a line for the gray method, a plane for the optimized
//! one), then fill the least of the cube, since a picture made another way would hardly keep to
//! its colours. Scenes without saturated colours fit nearly every method,
//! and the report says so instead of guessing.

use std::collections::HashMap;

use image::RgbaImage;
use stereolab_core::{
    AnaglyphGlasses, AnaglyphKind, AnaglyphMatrices, AnaglyphMethod, AnaglyphOptions,
    anaglyph_pixel_with, linear_to_srgb, srgb_to_linear,
};

use super::Layout;

/// One method's fit: the share of the uniform pixels it explains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MethodFit {
    /// The anaglyph kind (its output name says the method and the glasses).
    pub kind: AnaglyphKind,
    /// Whether it mixes in linear light.
    pub linear_light: bool,
    /// The share (0..1) of the uniform colours it produces within [`TOLERANCE`] levels.
    pub explained: f64,
    /// The rank of `ML + MR`: its colours fill the cube (3), a plane (2) or a line (1).
    pub rank: u8,
    /// The share of the colour cube it produces (0 below rank 3): of a 16³ grid of colours,
    /// those `(ML + MR)⁻¹` maps into the cube.
    pub volume: f64,
}

impl MethodFit {
    /// The method's name as the report gives it: the output name, and `in linear light`.
    pub fn name(&self) -> String {
        format!(
            "{}{}",
            self.kind.output_name(),
            if self.linear_light {
                " in linear light"
            } else {
                ""
            }
        )
    }
}

/// The estimate: how many uniform pixels and colours were read, and every candidate's fit:
/// those that explain the picture first, narrowest first, then the rest by their share.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodEstimate {
    /// Pixels in uniform areas wider than the parallax.
    pub pixels: usize,
    /// Distinct colours among them covering at least [`MIN_PIXELS`] pixels each (at most
    /// [`MAX_COLOURS`] are fitted, the most frequent).
    pub colours: usize,
    /// Each candidate's fit, best first.
    pub fits: Vec<MethodFit>,
}

/// The most channel difference (8-bit levels) between a colour and the nearest a method
/// produces for it to count as explained.
pub const TOLERANCE: u8 = 4;

/// The share of the uniform colours a method must explain.
pub const EXPLAINS: f64 = 0.98;

/// The fewest pixels a uniform colour needs to count.
pub const MIN_PIXELS: usize = 8;

/// The most distinct colours fitted.
pub const MAX_COLOURS: usize = 256;

/// The known anaglyph kinds for the glasses a layout names, each set of matrices once:
/// stereolab's kinds first, then three.js's cells (red-cyan also stands for magenta-cyan,
/// whose blue both filters pass).
pub fn candidates(layout: Layout) -> Vec<AnaglyphKind> {
    let mut kinds: Vec<AnaglyphKind> = match layout {
        Layout::AnaglyphRedCyan => {
            // stereolab's own red-cyan kinds: all but the two other glasses' Dubois.
            let mut v: Vec<AnaglyphKind> = AnaglyphKind::ALL
                .into_iter()
                .filter(|k| {
                    !matches!(
                        k,
                        AnaglyphKind::DuboisGreenMagenta | AnaglyphKind::DuboisAmberBlue
                    )
                })
                .collect();
            for glasses in [AnaglyphGlasses::RedCyan, AnaglyphGlasses::MagentaCyan] {
                v.extend(
                    AnaglyphMethod::ALL
                        .iter()
                        .map(|&m| AnaglyphKind::ThreeJs(m, glasses)),
                );
            }
            v
        }
        Layout::AnaglyphGreenMagenta => std::iter::once(AnaglyphKind::DuboisGreenMagenta)
            .chain(
                AnaglyphMethod::ALL
                    .iter()
                    .map(|&m| AnaglyphKind::ThreeJs(m, AnaglyphGlasses::MagentaGreen)),
            )
            .collect(),
        Layout::AnaglyphAmberBlue => vec![AnaglyphKind::DuboisAmberBlue],
        _ => Vec::new(),
    };
    let mut seen: Vec<AnaglyphMatrices> = Vec::new();
    kinds.retain(|k| {
        let m = k.matrices();
        let new = !seen.contains(&m);
        seen.push(m);
        new
    });
    kinds
}

/// The most a channel may vary (8-bit levels) over the `2·reach + 1` pixels around a pixel
/// for the pixel to count as uniform.
pub const UNIFORM_SPREAD: u8 = 2;

/// The colours of the pixels of `img` around which no channel varies by more than
/// [`UNIFORM_SPREAD`] levels over `reach` pixels to each side (smooth shading counts, edges and
/// texture do not): where both eyes see about the same colour when no parallax exceeds `reach`.
/// Each row's sliding minimum and maximum per channel come from monotone queues.
pub fn uniform_colours(img: &RgbaImage, reach: u32) -> HashMap<[u8; 3], usize> {
    use std::collections::VecDeque;
    let (w, h) = img.dimensions();
    let r = reach as usize;
    let mut counts = HashMap::new();
    if (w as usize) < 2 * r + 1 {
        return counts;
    }
    for y in 0..h {
        let row: Vec<[u8; 4]> = (0..w).map(|x| img.get_pixel(x, y).0).collect();
        // For each channel, whether the window ending at each x spans at most the spread.
        let mut calm = vec![true; row.len()];
        for c in 0..3 {
            let (mut lo, mut hi): (VecDeque<usize>, VecDeque<usize>) =
                (VecDeque::new(), VecDeque::new());
            for x in 0..row.len() {
                let v = row[x][c];
                while lo.back().is_some_and(|&i| row[i][c] >= v) {
                    lo.pop_back();
                }
                while hi.back().is_some_and(|&i| row[i][c] <= v) {
                    hi.pop_back();
                }
                lo.push_back(x);
                hi.push_back(x);
                let start = (x + 1).saturating_sub(2 * r + 1);
                while lo.front().is_some_and(|&i| i < start) {
                    lo.pop_front();
                }
                while hi.front().is_some_and(|&i| i < start) {
                    hi.pop_front();
                }
                if let (Some(&a), Some(&b)) = (lo.front(), hi.front()) {
                    calm[x] &= row[b][c] - row[a][c] <= UNIFORM_SPREAD;
                }
            }
        }
        // The window ending at x + r is centred on x.
        for x in r..row.len() - r {
            if calm[x + r] {
                let p = row[x];
                *counts.entry([p[0], p[1], p[2]]).or_insert(0) += 1;
            }
        }
    }
    counts
}

/// Estimates the method of an anaglyph `img` of `layout`'s glasses whose parallax stays
/// within `reach` pixels.
pub fn estimate(img: &RgbaImage, layout: Layout, reach: u32) -> MethodEstimate {
    let counts = uniform_colours(img, reach);
    let pixels = counts.values().sum();
    let mut colours: Vec<([u8; 3], usize)> =
        counts.into_iter().filter(|c| c.1 >= MIN_PIXELS).collect();
    // The most frequent first; equal counts in colour order, so the result is deterministic.
    colours.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    colours.truncate(MAX_COLOURS);
    let mut fits = Vec::new();
    for kind in candidates(layout) {
        let m = kind.matrices();
        let (rank, volume) = span(&m);
        for linear_light in [false, true] {
            let explained = colours
                .iter()
                .filter(|(c, _)| produces(&m, linear_light, *c))
                .count();
            fits.push(MethodFit {
                kind,
                linear_light,
                explained: if colours.is_empty() {
                    0.0
                } else {
                    explained as f64 / colours.len() as f64
                },
                rank,
                volume,
            });
        }
    }
    // Those that explain, narrowest first; then the rest, best first. Stable: ties keep the
    // candidates' order.
    fits.sort_by(|a, b| {
        let (ea, eb) = (a.explained >= EXPLAINS, b.explained >= EXPLAINS);
        eb.cmp(&ea).then(if ea && eb {
            a.rank.cmp(&b.rank).then(a.volume.total_cmp(&b.volume))
        } else {
            b.explained.total_cmp(&a.explained)
        })
    });
    MethodEstimate {
        pixels,
        colours: colours.len(),
        fits,
    }
}

/// The rank of `S = ML + MR` and, at rank 3, the share of a 16³ grid of colours (cell
/// centres) that `S⁻¹` maps into the unit cube: how much of the cube the method produces.
pub fn span(m: &AnaglyphMatrices) -> (u8, f64) {
    let s = glam::DMat3::from_cols_array_2d(&std::array::from_fn(|j| {
        std::array::from_fn(|i| f64::from(m.left[i][j] + m.right[i][j]))
    }));
    const EPS: f64 = 1e-6;
    if s.determinant().abs() < EPS {
        // Rank 2 when some 2×2 minor is non-zero.
        let a = s.transpose().to_cols_array_2d(); // rows
        let minor = |r: [usize; 2], c: [usize; 2]| {
            a[r[0]][c[0]] * a[r[1]][c[1]] - a[r[0]][c[1]] * a[r[1]][c[0]]
        };
        let pairs = [[0, 1], [0, 2], [1, 2]];
        let two = pairs
            .iter()
            .any(|&r| pairs.iter().any(|&c| minor(r, c).abs() > EPS));
        return (if two { 2 } else { 1 }, 0.0);
    }
    let inverse = s.inverse();
    let n = 16;
    let mut inside = 0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let t = glam::DVec3::new(i as f64, j as f64, k as f64) / n as f64
                    + glam::DVec3::splat(0.5 / n as f64);
                let u = inverse * t;
                inside += usize::from(u.min_element() >= 0.0 && u.max_element() <= 1.0);
            }
        }
    }
    (3, inside as f64 / (n * n * n) as f64)
}

/// Whether `m` (mixing in linear light or not) produces `target` within [`TOLERANCE`] levels
/// from one colour seen by both eyes: the colour `u` in the unit cube minimising
/// `|clamp(S·u) − t|²` (`S = ML + MR`, `t` the target in the mix's values; a channel at 0 or 255
/// counts only where `S·u` passes its limit) by projected gradient descent, then the anaglyph
/// of that colour computed by stereolab's own pixel function and compared.
pub fn produces(m: &AnaglyphMatrices, linear_light: bool, target: [u8; 3]) -> bool {
    let s: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| f64::from(m.left[i][j] + m.right[i][j])));
    let decode = |v: u8| {
        let c = f64::from(v) / 255.0;
        if linear_light {
            f64::from(srgb_to_linear(c as f32))
        } else {
            c
        }
    };
    let t = target.map(decode);
    // The step: 1 / the largest eigenvalue of SᵀS, bounded by its Frobenius norm².
    let lipschitz: f64 = s.iter().flatten().map(|v| v * v).sum::<f64>().max(1e-9);
    let mut u = [0.5f64; 3];
    for _ in 0..400 {
        let y: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| s[i][j] * u[j]).sum());
        let r: [f64; 3] = std::array::from_fn(|i| {
            let e = y[i] - t[i];
            match target[i] {
                0 => e.max(0.0),
                255 => e.min(0.0),
                _ => e,
            }
        });
        for (j, uj) in u.iter_mut().enumerate() {
            let g: f64 = (0..3).map(|i| s[i][j] * r[i]).sum();
            *uj = (*uj - g / lipschitz).clamp(0.0, 1.0);
        }
    }
    let stored = u.map(|v| {
        let c = if linear_light {
            f64::from(linear_to_srgb(v as f32))
        } else {
            v
        };
        (c * 255.0).round().clamp(0.0, 255.0) as u8
    });
    let pixel = [stored[0], stored[1], stored[2], 255];
    let options = AnaglyphOptions {
        linear_light,
        ..AnaglyphOptions::default()
    };
    let out = anaglyph_pixel_with(m, pixel, pixel, options);
    (0..3).all(|c| out[c].abs_diff(target[c]) <= TOLERANCE)
}

impl MethodEstimate {
    /// The fits that explain the picture ([`EXPLAINS`]).
    pub fn explaining(&self) -> Vec<&MethodFit> {
        self.fits
            .iter()
            .filter(|f| f.explained >= EXPLAINS)
            .collect()
    }

    /// The report's line.
    pub fn describe(&self) -> String {
        if self.pixels < 500 || self.colours < 3 {
            return format!(
                "  anaglyph method: too few uniform areas to tell ({} pixels, {} colours)\n",
                self.pixels, self.colours
            );
        }
        let fitting = self.explaining();
        let read = format!(
            "{} uniform colours over {} pixels",
            self.colours, self.pixels
        );
        let Some(first) = fitting.first() else {
            let best = &self.fits[0];
            return format!(
                "  anaglyph method: none of the {} known methods explains the colours (best: {}, \
                 {:.0}% of {read}): another matrix, or the picture was edited after mixing\n",
                self.fits.len(),
                best.name(),
                100.0 * best.explained
            );
        };
        if first.rank == 3 {
            // Full-colour methods overlap too much for uniform areas to rank them.
            let names: Vec<String> = fitting.iter().take(8).map(|f| f.name()).collect();
            return format!(
                "  anaglyph method: one of {}{} ({} of {} known methods produce the {read}; \
                 methods that keep full colour cannot be told apart from uniform areas)\n",
                names.join(", "),
                if fitting.len() > 8 { ", …" } else { "" },
                fitting.len(),
                self.fits.len()
            );
        }
        let likely: Vec<String> = fitting
            .iter()
            .take_while(|f| f.rank == first.rank && (f.volume - first.volume).abs() < 1e-3)
            .map(|f| f.name())
            .collect();
        let others: Vec<String> = fitting[likely.len()..]
            .iter()
            .take(4)
            .map(|f| f.name())
            .collect();
        format!(
            "  anaglyph method: most likely {} (its colours span {}, the narrowest of the {} of {} \
             known methods that produce the {read}){}\n",
            likely.join(" or "),
            if first.rank == 1 { "a line" } else { "a plane" },
            fitting.len(),
            self.fits.len(),
            if others.is_empty() {
                String::new()
            } else {
                format!(
                    "; also possible: {}{}",
                    others.join(", "),
                    if fitting.len() > likely.len() + 4 {
                        ", …"
                    } else {
                        ""
                    }
                )
            }
        )
    }
}
