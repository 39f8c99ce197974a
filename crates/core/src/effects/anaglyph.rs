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
    /// One cell of three.js's method × glasses table ([`threejs_anaglyph`]):
    /// `anaglyph_<method>_<glasses>`, e.g. `anaglyph_compromise_red_cyan`.
    ThreeJs(AnaglyphMethod, AnaglyphGlasses),
}

/// three.js's anaglyph methods (`AnaglyphAlgorithm`), spelled as three.js spells them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AnaglyphMethod {
    /// `TRUE`: red from the left eye, the right eye's luma in the other filter's channels.
    True,
    /// `GREY`: luma only.
    Grey,
    /// `COLOUR`: full colour, each channel from the eye whose filter passes it.
    Colour,
    /// `HALF_COLOUR`: the left eye's luma, the right eye in colour.
    HalfColour,
    /// `DUBOIS`: Dubois' least-squares matrices (three.js's default).
    Dubois,
    /// `OPTIMISED`: the left eye's green and blue as red (3dtv.at's optimized).
    Optimised,
    /// `COMPROMISE`: Ahtik's balance of colour reproduction and stereo effect.
    Compromise,
}

/// The glasses three.js's table is written for (`AnaglyphColorMode`), left filter first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AnaglyphGlasses {
    /// `RED_CYAN`.
    RedCyan,
    /// `MAGENTA_CYAN`: both filters pass blue, so each eye gets half of the blue channel.
    MagentaCyan,
    /// `MAGENTA_GREEN`.
    MagentaGreen,
}

impl AnaglyphMethod {
    /// Every method, in three.js's order.
    pub const ALL: [AnaglyphMethod; 7] = [
        AnaglyphMethod::True,
        AnaglyphMethod::Grey,
        AnaglyphMethod::Colour,
        AnaglyphMethod::HalfColour,
        AnaglyphMethod::Dubois,
        AnaglyphMethod::Optimised,
        AnaglyphMethod::Compromise,
    ];
}

impl AnaglyphGlasses {
    /// Every pair of glasses, in three.js's order.
    pub const ALL: [AnaglyphGlasses; 3] = [
        AnaglyphGlasses::RedCyan,
        AnaglyphGlasses::MagentaCyan,
        AnaglyphGlasses::MagentaGreen,
    ];
}

/// The output names of three.js's table, `[method][glasses]` in the order of the two `ALL`s.
const THREE_JS_NAMES: [[&str; 3]; 7] = [
    [
        "anaglyph_true_red_cyan",
        "anaglyph_true_magenta_cyan",
        "anaglyph_true_magenta_green",
    ],
    [
        "anaglyph_grey_red_cyan",
        "anaglyph_grey_magenta_cyan",
        "anaglyph_grey_magenta_green",
    ],
    [
        "anaglyph_colour_red_cyan",
        "anaglyph_colour_magenta_cyan",
        "anaglyph_colour_magenta_green",
    ],
    [
        "anaglyph_half_colour_red_cyan",
        "anaglyph_half_colour_magenta_cyan",
        "anaglyph_half_colour_magenta_green",
    ],
    [
        "anaglyph_dubois_red_cyan",
        "anaglyph_dubois_magenta_cyan",
        "anaglyph_dubois_magenta_green",
    ],
    [
        "anaglyph_optimised_red_cyan",
        "anaglyph_optimised_magenta_cyan",
        "anaglyph_optimised_magenta_green",
    ],
    [
        "anaglyph_compromise_red_cyan",
        "anaglyph_compromise_magenta_cyan",
        "anaglyph_compromise_magenta_green",
    ],
];

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

    /// three.js's whole table, method by method, glasses within each method: 21 kinds.
    pub const THREE_JS: [AnaglyphKind; 21] = {
        let mut all = [AnaglyphKind::True; 21];
        let mut i = 0;
        while i < 21 {
            all[i] = AnaglyphKind::ThreeJs(AnaglyphMethod::ALL[i / 3], AnaglyphGlasses::ALL[i % 3]);
            i += 1;
        }
        all
    };

    /// The output name a scene file asks for: `anaglyph_<kind>`.
    pub fn output_name(self) -> &'static str {
        match self {
            AnaglyphKind::ThreeJs(method, glasses) => {
                THREE_JS_NAMES[method as usize][glasses as usize]
            }
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
    /// - `ThreeJs(method, glasses)`: [`threejs_anaglyph`].
    pub fn matrices(self) -> AnaglyphMatrices {
        let (left, right) = match self {
            AnaglyphKind::ThreeJs(method, glasses) => return threejs_anaglyph(method, glasses),
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
    /// 0.9960). In three.js's table white stays white except in three cells: Dubois and
    /// Compromise for magenta-cyan (the blue rows sum to 0.962 and 0.648) and Dubois for
    /// magenta-green (the blue row is the left eye's alone and sums to −0.133: white becomes
    /// yellow).
    pub fn preserves_white(self) -> bool {
        use AnaglyphGlasses::{MagentaCyan, MagentaGreen};
        use AnaglyphMethod::{Compromise, Dubois};
        !matches!(
            self,
            AnaglyphKind::True
                | AnaglyphKind::ThreeJs(Dubois | Compromise, MagentaCyan)
                | AnaglyphKind::ThreeJs(Dubois, MagentaGreen)
        )
    }
}

/// `(ML, MR)` of one cell of three.js's method × glasses table (`ANAGLYPH_MATRICES` of
/// `examples/jsm/tsl/display/AnaglyphPassNode.js`, MIT licence; the numbers are reproduced in
/// `docs/anaglyph-matrices.md` with their sources). Rows are output channels, as everywhere
/// here; three.js stores the same numbers column-major.
///
/// - Red-cyan: `True` differs from the exercise slides' true anaglyph (three.js sends the
///   left eye's red, not its luma, to red, and the right eye's luma to green and blue);
///   `Grey`, `Colour`, `HalfColour`, `Optimised` and `Dubois` are the slides', 3dtv.at's and
///   Dubois' CRT matrices ([`AnaglyphKind::Gray`] and the others, tested equal).
/// - `Compromise`: J. Ahtik, "Introducing a New Anaglyph Method: Compromise Anaglyph":
///   `R = 0.439 R_l + 0.447 G_l + 0.148 B_l`, `G = 0.095 R_r + 0.934 G_r + 0.005 B_r`,
///   `B = 0.018 R_r + 0.028 G_r + 1.057 B_r`.
/// - Magenta-cyan (R. Lobel, "Magenta-Cyan Anaglyphs"): both filters pass blue, so the blue
///   output is shared between the eyes, half each (for Grey and HalfColour half of the luma,
///   written 0.15, 0.29, 0.06); for Compromise three.js writes 0.009, 0.014, 0.074 (left)
///   and 0.009, 0.014, 0.528 (right), for Dubois 0.088, 0.088, −0.003 (left) and 0.088,
///   0.088, 0.613 (right).
/// - Magenta-green: the left eye's red row also drives blue (the magenta filter passes both),
///   the green row takes what red-cyan's green and blue rows took, or for Dubois and
///   Compromise the sum of the left's red row and the right's green row. three.js's Dubois
///   magenta-green gives the left eye the right eye's red row (negative) as blue, so white
///   becomes yellow ([`AnaglyphKind::preserves_white`]).
pub fn threejs_anaglyph(method: AnaglyphMethod, glasses: AnaglyphGlasses) -> AnaglyphMatrices {
    use AnaglyphGlasses::{MagentaCyan, MagentaGreen, RedCyan};
    use AnaglyphMethod as M;
    const R: [f32; 3] = [1.0, 0.0, 0.0];
    const G: [f32; 3] = [0.0, 1.0, 0.0];
    const B: [f32; 3] = [0.0, 0.0, 1.0];
    const HALF_B: [f32; 3] = [0.0, 0.0, 0.5];
    const HALF_LUMA: [f32; 3] = [0.15, 0.29, 0.06];
    const DUBOIS_L: ColorMatrix = [
        [0.456100, 0.500484, 0.176381],
        [-0.0400822, -0.0378246, -0.0157589],
        [-0.0152161, -0.0205971, -0.00546856],
    ];
    const DUBOIS_R: ColorMatrix = [
        [-0.0434706, -0.0879388, -0.00155529],
        [0.378476, 0.73364, -0.0184503],
        [-0.0721527, -0.112961, 1.2264],
    ];
    const AHTIK_R: [f32; 3] = [0.439, 0.447, 0.148];
    const AHTIK_G: [f32; 3] = [0.095, 0.934, 0.005];
    const AHTIK_B: [f32; 3] = [0.018, 0.028, 1.057];
    let sum = |a: [f32; 3], b: [f32; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let (left, right) = match (method, glasses) {
        (M::True, RedCyan) => ([R, ZERO, ZERO], [ZERO, LUMA, LUMA]),
        (M::True, MagentaCyan) => ([R, ZERO, HALF_B], [ZERO, LUMA, HALF_B]),
        (M::True, MagentaGreen) => ([R, ZERO, LUMA], [ZERO, LUMA, ZERO]),
        (M::Grey, RedCyan) => ([LUMA, ZERO, ZERO], [ZERO, LUMA, LUMA]),
        (M::Grey, MagentaCyan) => ([LUMA, ZERO, HALF_LUMA], [ZERO, LUMA, HALF_LUMA]),
        (M::Grey, MagentaGreen) => ([LUMA, ZERO, LUMA], [ZERO, LUMA, ZERO]),
        (M::Colour, RedCyan) => ([R, ZERO, ZERO], [ZERO, G, B]),
        (M::Colour, MagentaCyan) => ([R, ZERO, HALF_B], [ZERO, G, HALF_B]),
        (M::Colour, MagentaGreen) => ([R, ZERO, B], [ZERO, G, ZERO]),
        (M::HalfColour, RedCyan) => ([LUMA, ZERO, ZERO], [ZERO, G, B]),
        (M::HalfColour, MagentaCyan) => ([LUMA, ZERO, HALF_LUMA], [ZERO, G, HALF_LUMA]),
        (M::HalfColour, MagentaGreen) => ([LUMA, ZERO, LUMA], [ZERO, G, ZERO]),
        (M::Dubois, RedCyan) => (DUBOIS_L, DUBOIS_R),
        (M::Dubois, MagentaCyan) => (
            [DUBOIS_L[0], DUBOIS_L[1], [0.088, 0.088, -0.003]],
            [DUBOIS_R[0], DUBOIS_R[1], [0.088, 0.088, 0.613]],
        ),
        (M::Dubois, MagentaGreen) => (
            [DUBOIS_L[0], ZERO, DUBOIS_R[0]],
            [ZERO, sum(DUBOIS_R[1], DUBOIS_L[0]), ZERO],
        ),
        (M::Optimised, RedCyan) => ([[0.0, 0.7, 0.3], ZERO, ZERO], [ZERO, G, B]),
        (M::Optimised, MagentaCyan) => ([[0.0, 0.7, 0.3], ZERO, HALF_B], [ZERO, G, HALF_B]),
        (M::Optimised, MagentaGreen) => ([[0.0, 0.7, 0.3], ZERO, B], [ZERO, G, ZERO]),
        (M::Compromise, RedCyan) => ([AHTIK_R, ZERO, ZERO], [ZERO, AHTIK_G, AHTIK_B]),
        (M::Compromise, MagentaCyan) => (
            [AHTIK_R, ZERO, [0.009, 0.014, 0.074]],
            [ZERO, AHTIK_G, [0.009, 0.014, 0.528]],
        ),
        (M::Compromise, MagentaGreen) => (
            [AHTIK_R, ZERO, AHTIK_B],
            [ZERO, sum(AHTIK_G, AHTIK_R), ZERO],
        ),
    };
    AnaglyphMatrices { left, right }
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
    /// Rendepth's anti-rivalry stage after the mix: each output channel raised to
    /// `1/γ` with γ = [`ANTI_RIVALRY_GAMMA`] ([`anti_rivalry`]).
    pub anti_rivalry: bool,
}

/// Rendepth's per-channel gamma map (R, G, B): red brightened, green darkened, blue kept, so
/// the eye behind the red filter is not the darker one (A. Hernandez (Cybereality), "Rendepth:
/// Red/Cyan Anaglyph Filter Optimized for Stereoscopic 3D on LCD Monitors", after Peter
/// Wimmer's optimized anaglyphs).
pub const ANTI_RIVALRY_GAMMA: [f32; 3] = [1.6, 0.8, 1.0];

/// Rendepth's anti-rivalry stage on one mixed color in [0, 1]: `c_i^(1/γ_i)` with
/// γ = [`ANTI_RIVALRY_GAMMA`] (Rendepth's `correct_color`). Applied to the display's
/// (stored) values, after the sRGB encoding where the mix ran in linear light.
#[inline]
pub fn anti_rivalry(c: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|i| c[i].powf(1.0 / ANTI_RIVALRY_GAMMA[i]))
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
    let options = AnaglyphOptions {
        linear_light,
        ..AnaglyphOptions::default()
    };
    anaglyph_pixel_with(m, left, right, options)
}

/// [`anaglyph_pixel`] with every option that changes a pixel's value: `linear_light` and
/// `anti_rivalry` (Rendepth's gamma stage, [`anti_rivalry`], after the encoding). The
/// definition the image loops are held to.
#[inline]
pub fn anaglyph_pixel_with(
    m: &AnaglyphMatrices,
    left: [u8; 4],
    right: [u8; 4],
    options: AnaglyphOptions,
) -> [u8; 4] {
    let linear_light = options.linear_light;
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
    let out = if options.anti_rivalry {
        anti_rivalry(out)
    } else {
        out
    };
    [to_u8(out[0]), to_u8(out[1]), to_u8(out[2]), 255]
}

/// The guard of the AVX2 loop's fused path for one output channel with coefficients `c`
/// (`ML`'s row, then `MR`'s): wherever `t = ½ + Σ c_j·v_j`, computed with six fused
/// multiply-adds on the 8-bit values `v_j`, lies at least this far from every integer, `⌊t⌋`
/// saturated to 0..255 is [`anaglyph_pixel`]'s byte. With `K = Σ|c_j|` and `u = 2⁻²⁴` (f32's
/// unit roundoff):
///
/// `g = E_fused + E_pixel`, `E_fused = 6.0001·u·(255·K + ½)`,
/// `E_pixel = u·(7.0001·255·K + 511)`.
///
/// Each `E` bounds one computation's distance to the exact `t* = ½ + Σ c_j·v_j` (Higham,
/// *Accuracy and Stability of Numerical Algorithms*, 2nd ed., §3.1: `n` roundings of relative
/// size `u` multiply by at most `1 + γ_n`, `γ_n = n·u/(1 − n·u)`). The fused chain rounds six
/// times, each by at most `u` times a partial sum no larger than `255·K + ½`. The pixel
/// function rounds `v/255` and the product (two per term) and sums left to right (five more):
/// its sum is within `γ_7·K` of `Σ c_j·v_j/255`, within `γ_7·255·K` after `·255`, whose
/// rounding adds at most `255·u`, and `+ ½` at most `256·u`. Both bounds are strict
/// (`6.0001·u` exceeds `γ_6`, `7.0001·u` exceeds `γ_7`), so when `t` is at least `g` from every
/// integer, `t*` is farther than `E_pixel` from every one, and both round down to the same
/// integer. Where the clamp acts (the sum below 0 or above 1) the byte is 0 or 255, and `t` is
/// below 1 or above 255, which saturate to the same.
pub(crate) fn fused_guard(c: [f32; 6]) -> f32 {
    let u = 2f64.powi(-24);
    let k: f64 = c.iter().map(|c| f64::from(c.abs())).sum();
    let e_fused = 6.0001 * u * (255.0 * k + 0.5);
    let e_pixel = u * (7.0001 * 255.0 * k + 511.0);
    // Rounded up, so the f32 guard is no smaller.
    ((e_fused + e_pixel) as f32).next_up()
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
    let bytes = if options.linear_light || options.anti_rivalry {
        // A GPU decodes an sRGB texture in the sampler; a 256-entry table is the same thing.
        let decode: Vec<f32> = (0..=255u8)
            .map(|v| {
                let c = v as f32 / 255.0;
                if options.linear_light {
                    srgb_to_linear(c)
                } else {
                    c
                }
            })
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
                        let c = mix(&m, lin(l), lin(r));
                        let c = if options.linear_light {
                            c.map(linear_to_srgb)
                        } else {
                            c
                        };
                        let c = if options.anti_rivalry {
                            anti_rivalry(c)
                        } else {
                            c
                        };
                        let px = [to_u8(c[0]), to_u8(c[1]), to_u8(c[2]), 255];
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
        #[cfg(target_arch = "x86_64")]
        let fused = avx2::Fused::new(&m);
        let fill = |y: usize, out: &mut [MaybeUninit<[u8; 4]>]| {
            let (l, r) = eyes(y, out.len());
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: `avx2::row` requires AVX2 and FMA (its only safety condition),
                // which `Kernels::avx2` found on this CPU. The same bytes as the loop below
                // (`avx2_rows_match_anaglyph_pixel`).
                unsafe { avx2::row(&m, &fused, l, r, out) };
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
        let kinds = AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS);
        for kind in kinds {
            for (linear_light, anti_rivalry) in [(false, false), (true, false), (false, true)] {
                for kernels in [Kernels::Avx2, Kernels::Scalar] {
                    let options = AnaglyphOptions {
                        linear_light,
                        swap_eyes: false,
                        anti_rivalry,
                    };
                    let img = anaglyph_on(&left, &right, kind, options, kernels).unwrap();
                    for (i, px) in img.pixels().enumerate() {
                        let want = anaglyph_pixel_with(
                            &kind.matrices(),
                            left.color[i],
                            right.color[i],
                            options,
                        );
                        assert_eq!(px.0, want, "{kind:?} {options:?} {kernels:?}: pixel {i}");
                    }
                }
            }
        }
    }

    /// On random colours (no two neighbours equal, so no result is reused), every kind with
    /// every option gives `anaglyph_pixel_with`'s bytes on both loops, on a width that ends
    /// mid-vector.
    #[test]
    fn random_colors_give_anaglyph_pixel_with_every_option() {
        let (w, h) = (203, 5);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut eye = || {
            let mut fb = Framebuffer::new(w, h, [0, 0, 0, 255]).unwrap();
            for c in &mut fb.color {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let b = state.to_le_bytes();
                *c = [b[0], b[1], b[2], b[3]];
            }
            fb
        };
        let (left, right) = (eye(), eye());
        for kind in AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS) {
            for bits in 0..8 {
                let options = AnaglyphOptions {
                    linear_light: bits & 1 != 0,
                    swap_eyes: bits & 2 != 0,
                    anti_rivalry: bits & 4 != 0,
                };
                let (a, b) = options.eyes(&left, &right);
                for kernels in [Kernels::Avx2, Kernels::Scalar] {
                    let img = anaglyph_on(&left, &right, kind, options, kernels).unwrap();
                    for (i, px) in img.pixels().enumerate() {
                        let want =
                            anaglyph_pixel_with(&kind.matrices(), a.color[i], b.color[i], options);
                        assert_eq!(px.0, want, "{kind:?} {options:?} {kernels:?}: pixel {i}");
                    }
                }
            }
        }
    }
}
