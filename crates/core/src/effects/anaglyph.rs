//! Anaglyphs: `out = clamp(ML · left + MR · right)` per pixel (the exercise slides, "Anaglyph").
//!
//! Written as the finalize fragment shader would be: [`mix`] is the whole shader body for one
//! pixel, [`srgb_to_linear`] / [`linear_to_srgb`] the optional decode/encode around it, and
//! [`anaglyph`] only loops over the pixels. Every matrix is stored row-major: row i gives output
//! channel i (R, G, B), column j multiplies that eye's input channel j. Where each matrix comes
//! from is said at [`AnaglyphKind::matrices`].

use std::mem::MaybeUninit;

use image::RgbaImage;

#[cfg(target_arch = "x86_64")]
mod avx2;

use super::eye_input::check_same_size;
use super::par_fill_rows;
use crate::error::Result;
use crate::framebuffer::Framebuffer;
use crate::simd::{Kernels, kernels};

/// A 3×3 color matrix, row-major: `out[i] = Σ_j m[i][j] · in[j]`.
pub type ColorMatrix = [[f32; 3]; 3];

/// The pair of matrices of one anaglyph kind: `ML` for the left eye, `MR` for the right.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnaglyphMatrices {
    /// `ML`, applied to the left eye's color.
    pub left: ColorMatrix,
    /// `MR`, applied to the right eye's color.
    pub right: ColorMatrix,
}

/// Every anaglyph stereolab can produce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AnaglyphKind {
    /// The exercise slides' "true": luma to red (left) and blue (right). Dark; white becomes magenta.
    True,
    /// The exercise slides' "gray": luma to red (left) and to green and blue (right).
    Gray,
    /// The exercise slides' "color": red from the left eye, green and blue from the right.
    Color,
    /// The exercise slides' "half color": luma to red (left), green and blue from the right.
    HalfColor,
    /// 3dtv.at "optimized": red = 0.7 G + 0.3 B of the left eye, green and blue from the right.
    Optimized,
    /// Dubois least-squares red-cyan, CRT primaries (full precision, three.js).
    DuboisRedCyan,
    /// Dubois red-cyan, 2009 LCD revision.
    DuboisRedCyanLcd,
    /// Dubois green-magenta.
    DuboisGreenMagenta,
    /// Dubois amber-blue (ColorCode-style glasses).
    DuboisAmberBlue,
}

/// Rec. 601 luma weights, as the exercise slides write them (0,299 0,587 0,114).
const LUMA: [f32; 3] = [0.299, 0.587, 0.114];
const ZERO: [f32; 3] = [0.0, 0.0, 0.0];

impl AnaglyphKind {
    /// Every kind, in the order outputs list them.
    pub const ALL: [AnaglyphKind; 9] = [
        AnaglyphKind::True,
        AnaglyphKind::Gray,
        AnaglyphKind::Color,
        AnaglyphKind::HalfColor,
        AnaglyphKind::Optimized,
        AnaglyphKind::DuboisRedCyan,
        AnaglyphKind::DuboisRedCyanLcd,
        AnaglyphKind::DuboisGreenMagenta,
        AnaglyphKind::DuboisAmberBlue,
    ];

    /// The output name a scene file asks for: `anaglyph_<kind>`.
    pub fn output_name(self) -> &'static str {
        match self {
            AnaglyphKind::True => "anaglyph_true",
            AnaglyphKind::Gray => "anaglyph_gray",
            AnaglyphKind::Color => "anaglyph_color",
            AnaglyphKind::HalfColor => "anaglyph_half_color",
            AnaglyphKind::Optimized => "anaglyph_optimized",
            AnaglyphKind::DuboisRedCyan => "anaglyph_dubois",
            AnaglyphKind::DuboisRedCyanLcd => "anaglyph_dubois_lcd",
            AnaglyphKind::DuboisGreenMagenta => "anaglyph_green_magenta",
            AnaglyphKind::DuboisAmberBlue => "anaglyph_amber_blue",
        }
    }

    /// `(ML, MR)` of this kind, and where the numbers come from:
    ///
    /// - `True`, `Gray`, `Color`, `HalfColor`: the exercise slides (after 3dtv.at's anaglyph
    ///   comparison), luma weights 0.299 / 0.587 / 0.114.
    /// - `Optimized`: 3dtv.at's comparison (linked from the exercise slides): `R = 0.7·G_l + 0.3·B_l`,
    ///   G and B from the right eye.
    /// - `DuboisRedCyan`: Eric Dubois' least-squares red-cyan matrices for CRT primaries, at the
    ///   full precision three.js's `AnaglyphEffect` uses (there written column-major with
    ///   `Matrix3.fromArray`). Public copies often write `-0.400822` for `ML[1][0] =
    ///   -0.0400822`; the row sums below catch that.
    /// - `DuboisRedCyanLcd`: Dubois' 2009 LCD revision (dolphin-emu's
    ///   `Data/Sys/Shaders/Anaglyph/dubois.glsl`).
    /// - `DuboisGreenMagenta`: Dubois' green-magenta matrices, with `MR[1][2] = -0.065` (copies
    ///   disagree on its sign; only −0.065 keeps the green row's sum at 1).
    /// - `DuboisAmberBlue`: Dubois' amber-blue matrices as vpinball ships them (dolphin's
    ///   LCD amber-blue copy has rows summing to 1.035 and 0.523, a transcription error).
    pub fn matrices(self) -> AnaglyphMatrices {
        let (left, right) = match self {
            AnaglyphKind::True => ([LUMA, ZERO, ZERO], [ZERO, ZERO, LUMA]),
            AnaglyphKind::Gray => ([LUMA, ZERO, ZERO], [ZERO, LUMA, LUMA]),
            AnaglyphKind::Color => (
                [[1.0, 0.0, 0.0], ZERO, ZERO],
                [ZERO, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ),
            AnaglyphKind::HalfColor => {
                ([LUMA, ZERO, ZERO], [ZERO, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
            }
            AnaglyphKind::Optimized => (
                [[0.0, 0.7, 0.3], ZERO, ZERO],
                [ZERO, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ),
            AnaglyphKind::DuboisRedCyan => (
                [
                    [0.456100, 0.500484, 0.176381],
                    [-0.0400822, -0.0378246, -0.0157589],
                    [-0.0152161, -0.0205971, -0.00546856],
                ],
                [
                    [-0.0434706, -0.0879388, -0.00155529],
                    [0.378476, 0.73364, -0.0184503],
                    [-0.0721527, -0.112961, 1.2264],
                ],
            ),
            AnaglyphKind::DuboisRedCyanLcd => (
                [
                    [0.437, 0.449, 0.164],
                    [-0.062, -0.062, -0.024],
                    [-0.048, -0.050, -0.017],
                ],
                [
                    [-0.011, -0.032, -0.007],
                    [0.377, 0.761, 0.009],
                    [-0.026, -0.093, 1.234],
                ],
            ),
            AnaglyphKind::DuboisGreenMagenta => (
                [
                    [-0.062, -0.158, -0.039],
                    [0.284, 0.668, 0.143],
                    [-0.015, -0.027, 0.021],
                ],
                [
                    [0.529, 0.705, 0.024],
                    [-0.016, -0.015, -0.065],
                    [0.009, 0.075, 0.937],
                ],
            ),
            AnaglyphKind::DuboisAmberBlue => (
                [
                    [1.062, -0.205, 0.299],
                    [-0.026, 0.908, 0.068],
                    [-0.038, -0.173, 0.022],
                ],
                [
                    [-0.016, -0.123, -0.017],
                    [0.006, 0.062, -0.017],
                    [0.094, 0.185, 0.911],
                ],
            ),
        };
        AnaglyphMatrices { left, right }
    }

    /// Whether the source claims white stays white, i.e. every row of `ML + MR` sums to about 1.
    ///
    /// Every kind except `True`: the exercise slides' true anaglyph sends luma to red and blue only, so
    /// white becomes magenta (1, 0, 1). The Dubois matrices are least-squares fits, so their
    /// rows sum to 1 only within rounding of the published digits (the CRT blue row sums to
    /// 0.9960).
    pub fn preserves_white(self) -> bool {
        self != AnaglyphKind::True
    }
}

/// Finalize options for anaglyphs (the scene's optional `[finalize]` table).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnaglyphOptions {
    /// Apply the matrices to linear-light values (decode sRGB, mix, encode, as three.js does)
    /// instead of to the stored 8-bit values (as vpinball does). Sources disagree; the
    /// benchmark measures both.
    pub linear_light: bool,
    /// Swap the eyes: `ML` reads the right eye and `MR` the left (glasses worn the other way
    /// round).
    pub swap_eyes: bool,
}

impl AnaglyphOptions {
    /// The eyes in the order the matrices read them: `(ML's input, MR's input)`, that is
    /// `(left, right)`, or `(right, left)` with `swap_eyes`.
    pub fn eyes<'a, T>(&self, left: &'a T, right: &'a T) -> (&'a T, &'a T) {
        if self.swap_eyes {
            (right, left)
        } else {
            (left, right)
        }
    }
}

/// The IEC 61966-2-1 sRGB decoding of one channel in [0, 1]:
/// `c ≤ 0.04045 ? c/12.92 : ((c + 0.055)/1.055)^2.4`.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The IEC 61966-2-1 sRGB encoding of one channel in [0, 1]:
/// `l ≤ 0.0031308 ? 12.92 l : 1.055 l^(1/2.4) − 0.055`.
#[inline]
pub fn linear_to_srgb(l: f32) -> f32 {
    if l <= 0.0031308 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The finalize shader's body for one pixel: `clamp(ML · left + MR · right, 0, 1)`, both inputs
/// in [0, 1] (stored or linear values alike).
#[inline]
pub fn mix(m: &AnaglyphMatrices, left: [f32; 3], right: [f32; 3]) -> [f32; 3] {
    let row = |i: usize| {
        let (l, r) = (m.left[i], m.right[i]);
        let v = l[0] * left[0]
            + l[1] * left[1]
            + l[2] * left[2]
            + r[0] * right[0]
            + r[1] * right[1]
            + r[2] * right[2];
        v.clamp(0.0, 1.0)
    };
    [row(0), row(1), row(2)]
}

/// One channel in [0, 1] to 8 bits, rounding to nearest (as [`crate::shade::to_rgba8`]).
#[inline]
fn to_u8(c: f32) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// One pixel of an anaglyph from two 8-bit colors: decode (÷255, then sRGB→linear when
/// `linear_light`), [`mix`], encode back. Alpha is opaque.
#[inline]
pub fn anaglyph_pixel(
    m: &AnaglyphMatrices,
    left: [u8; 4],
    right: [u8; 4],
    linear_light: bool,
) -> [u8; 4] {
    let decode = |p: [u8; 4]| {
        let c = [p[0], p[1], p[2]].map(|v| v as f32 / 255.0);
        if linear_light {
            c.map(srgb_to_linear)
        } else {
            c
        }
    };
    let out = mix(m, decode(left), decode(right));
    let out = if linear_light {
        out.map(linear_to_srgb)
    } else {
        out
    };
    [to_u8(out[0]), to_u8(out[1]), to_u8(out[2]), 255]
}

/// A left and a right eye's pixel.
type PixelPair = ([u8; 4], [u8; 4]);

/// The anaglyph of two eye images (color only; depth is not read), on the scalar loop: the
/// definition [`anaglyph`] runs faster with the same bytes (the benchmark times both).
///
/// # Errors
/// The eyes differ in size, or a color buffer does not match its size.
pub fn anaglyph_reference(
    left: &Framebuffer,
    right: &Framebuffer,
    kind: AnaglyphKind,
    options: AnaglyphOptions,
) -> Result<RgbaImage> {
    anaglyph_on(left, right, kind, options, Kernels::Scalar)
}

/// The anaglyph of two eye images (color only; depth is not read): [`anaglyph_reference`]'s
/// bytes, stored values on the AVX2 rows where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)).
///
/// # Errors
/// As [`anaglyph_reference`].
pub fn anaglyph(
    left: &Framebuffer,
    right: &Framebuffer,
    kind: AnaglyphKind,
    options: AnaglyphOptions,
) -> Result<RgbaImage> {
    anaglyph_on(left, right, kind, options, kernels())
}

/// The anaglyph on the loops `kernels` names (the linear-light loop is scalar on both).
fn anaglyph_on(
    left: &Framebuffer,
    right: &Framebuffer,
    kind: AnaglyphKind,
    options: AnaglyphOptions,
    kernels: Kernels,
) -> Result<RgbaImage> {
    check_same_size(left, right)?;
    let (left, right) = options.eyes(left, right);
    let m = kind.matrices();
    // Rows in parallel (every pixel is independent, so the bytes do not depend on the thread
    // count).
    let w = left.width.max(1) as usize;
    let eyes = |y: usize, len: usize| {
        let r = y * w..y * w + len;
        (&left.color[r.clone()], &right.color[r])
    };
    let bytes = if options.linear_light {
        // A GPU decodes an sRGB texture in the sampler; a 256-entry table is the same thing.
        let decode: Vec<f32> = (0..=255u8)
            .map(|v| srgb_to_linear(v as f32 / 255.0))
            .collect();
        let lin = |p: &[u8; 4]| [p[0], p[1], p[2]].map(|v| decode[v as usize]);
        let fill = |y: usize, out: &mut [MaybeUninit<[u8; 4]>]| {
            let (l, r) = eyes(y, out.len());
            // A pixel's result depends on its pair alone: a run of equal pairs (a flat
            // background in both eyes) reuses the last result instead of three more `powf`.
            let mut last: Option<(PixelPair, [u8; 4])> = None;
            for (out, (l, r)) in out.iter_mut().zip(l.iter().zip(r)) {
                let px = match last {
                    Some((pair, px)) if pair == (*l, *r) => px,
                    _ => {
                        let c = mix(&m, lin(l), lin(r)).map(|c| to_u8(linear_to_srgb(c)));
                        let px = [c[0], c[1], c[2], 255];
                        last = Some(((*l, *r), px));
                        px
                    }
                };
                out.write(px);
            }
        };
        // SAFETY: `fill` writes one pixel per pixel of the eyes' rows, which are as long as the
        // output row (`check_same_size`: both color buffers hold width × height pixels).
        unsafe { par_fill_rows(left.color.len(), w, fill) }
    } else {
        let avx2 = kernels.avx2();
        #[cfg(not(target_arch = "x86_64"))]
        let _ = avx2;
        let fill = |y: usize, out: &mut [MaybeUninit<[u8; 4]>]| {
            let (l, r) = eyes(y, out.len());
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: `avx2::row` requires AVX2 (its only safety condition), which
                // `Kernels::avx2` found on this CPU. The same bytes as the loop below
                // (`avx2_rows_match_anaglyph_pixel`).
                unsafe { avx2::row(&m, l, r, out) };
                return;
            }
            for (out, (l, r)) in out.iter_mut().zip(l.iter().zip(r)) {
                out.write(anaglyph_pixel(&m, *l, *r, false));
            }
        };
        // SAFETY: as above; `avx2::row` writes every pixel of a row as long as its inputs.
        unsafe { par_fill_rows(left.color.len(), w, fill) }
    };
    Ok(RgbaImage::from_raw(left.width, left.height, bytes).expect("4 bytes per pixel"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both anaglyph loops (linear light, stored values on the AVX2 rows and on the scalar
    /// loop) give `anaglyph_pixel`'s bytes on rows with runs of equal pixel pairs, where the
    /// last result is reused, broken by a change in one eye only, and on an odd width.
    #[test]
    fn runs_of_equal_pixels_give_anaglyph_pixel() {
        let (w, h) = (29, 3);
        let mut left = Framebuffer::new(w, h, [24, 24, 24, 255]).unwrap();
        let mut right = Framebuffer::new(w, h, [24, 24, 24, 255]).unwrap();
        for (i, (l, r)) in left.color.iter_mut().zip(&mut right.color).enumerate() {
            match i % 29 {
                0..=9 => {}
                10..=12 => r[0] = 200,
                13..=20 => *l = [i as u8, 7, 99, 255],
                _ => *r = [3, (i * 5) as u8, 250, 255],
            }
        }
        for kind in AnaglyphKind::ALL {
            for linear_light in [false, true] {
                for kernels in [Kernels::Avx2, Kernels::Scalar] {
                    let options = AnaglyphOptions {
                        linear_light,
                        swap_eyes: false,
                    };
                    let img = anaglyph_on(&left, &right, kind, options, kernels).unwrap();
                    for (i, px) in img.pixels().enumerate() {
                        let want = anaglyph_pixel(
                            &kind.matrices(),
                            left.color[i],
                            right.color[i],
                            linear_light,
                        );
                        assert_eq!(
                            px.0, want,
                            "{kind:?} linear {linear_light} {kernels:?}: pixel {i}"
                        );
                    }
                }
            }
        }
    }
}
