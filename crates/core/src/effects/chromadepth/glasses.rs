//! What each eye sees through ChromaDepth glasses, so a viewer without them can be shown the
//! effect as an ordinary stereo pair.
//!
//! The model (the ChromaDepth article): each lens is a thin diffraction grating with its lines vertical, so it
//! bends light sideways, towards the nose. A grating deflects wavelength λ by `sin θ = λ / p`
//! (first order, line period p); for the small angles of the glasses `θ ≈ λ / p`, so the
//! apparent shift on the screen grows linearly with λ: red (long) is bent most, blue (short)
//! least. The part of the shift every color shares is a uniform sideways move of the whole view
//! that the eyes absorb by converging; only the excess over blue matters, so blue is taken as
//! unshifted.
//!
//! A display pixel emits three primaries. We treat each as one wavelength (the dominant
//! wavelengths of the sRGB primaries, about 612, 547 and 465 nm) and place the pixel at the
//! intensity-weighted centroid of its three deflected copies:
//!
//! ```text
//! shift = max_shift · (R w_R + G w_G + B w_B) / (R + G + B),   w_c = (λ_c − λ_B)/(λ_R − λ_B)
//! ```
//!
//! so pure red moves `max_shift`, green about 0.56 of it, blue and black not at all, and the
//! shift falls monotonically along both ramps (HSV and red–white–blue) from near to far. The left
//! eye's view moves right and the right eye's left (inward), so red gets the most negative
//! (crossed) parallax `x_R − x_L = −2 shift`: red appears nearest, as the ChromaDepth article says.

use crate::framebuffer::Framebuffer;

/// Dominant wavelengths (nm) taken for the R, G, B primaries (sRGB's primaries).
pub const PRIMARY_WAVELENGTHS_NM: [f32; 3] = [612.0, 547.0, 465.0];

/// Which eye's view to simulate: the left eye's lens bends the view to the right (towards the
/// nose), the right eye's to the left.
pub use crate::eye::Eye;

/// Each primary's shift as a fraction of the reddest shift: `(λ_c − λ_B)/(λ_R − λ_B)`.
pub fn channel_weights() -> [f32; 3] {
    let [r, _, b] = PRIMARY_WAVELENGTHS_NM;
    PRIMARY_WAVELENGTHS_NM.map(|l| (l - b) / (r - b))
}

/// The inward shift (pixels, ≥ 0) the glasses give a pixel of color `rgba`: the
/// intensity-weighted centroid of its primaries' shifts. Black emits nothing and stays put.
pub fn pixel_shift(rgba: [u8; 4], max_shift_px: f32) -> f32 {
    let w = channel_weights();
    let c = [rgba[0], rgba[1], rgba[2]].map(f32::from);
    let total = c[0] + c[1] + c[2];
    if total == 0.0 {
        return 0.0;
    }
    max_shift_px * (c[0] * w[0] + c[1] * w[1] + c[2] * w[2]) / total
}

/// The inward shift of every pixel of `fb`, row-major.
pub fn shift_map(fb: &Framebuffer, max_shift_px: f32) -> Vec<f32> {
    fb.color
        .iter()
        .map(|c| pixel_shift(*c, max_shift_px))
        .collect()
}

/// The view of `eye` through the glasses: every pixel of the ChromaDepth image `fb` moved
/// horizontally inward by [`pixel_shift`] (rounded to whole pixels, ties to even).
///
/// Where two pixels land on the same spot the one shifted more (nearer) wins, as a depth test
/// would; spots nothing lands on (disocclusions) take the neighbor shifted less (farther), the
/// usual fill for uncovered background. The depth buffer travels with the colors.
pub fn glasses_view(fb: &Framebuffer, eye: Eye, max_shift_px: f32) -> Framebuffer {
    warp(fb, eye, &shift_map(fb, max_shift_px))
}

/// Both eyes' views through the glasses (left, right), the shift map computed once.
pub fn glasses_pair(fb: &Framebuffer, max_shift_px: f32) -> [Framebuffer; 2] {
    let shifts = shift_map(fb, max_shift_px);
    [warp(fb, Eye::Left, &shifts), warp(fb, Eye::Right, &shifts)]
}

/// Moves every pixel of `fb` by its entry in `shifts`, inward for `eye` (see [`glasses_view`]).
fn warp(fb: &Framebuffer, eye: Eye, shifts: &[f32]) -> Framebuffer {
    // Inward: the left eye's view moves right, the right eye's left.
    let direction = -eye.sign();
    let w = fb.width as usize;
    let mut out = fb.clone();
    // Per destination: the source index and its shift.
    let mut landed: Vec<Option<(usize, f32)>> = vec![None; w];
    for y in 0..fb.height as usize {
        landed.iter_mut().for_each(|l| *l = None);
        for x in 0..w {
            let src = y * w + x;
            let dest = (x as f32 + direction * shifts[src]).round_ties_even();
            if dest < 0.0 || dest >= w as f32 {
                continue;
            }
            let slot = &mut landed[dest as usize];
            if slot.is_none_or(|(_, s)| shifts[src] > s) {
                *slot = Some((src, shifts[src]));
            }
        }
        // Nearest landed source at or left of x, and at or right of x: O(width) hole filling.
        let mut from_left = landed.clone();
        for x in 1..w {
            from_left[x] = from_left[x].or(from_left[x - 1]);
        }
        let mut from_right = landed.clone();
        for x in (0..w.saturating_sub(1)).rev() {
            from_right[x] = from_right[x].or(from_right[x + 1]);
        }
        for x in 0..w {
            let pick = match (from_left[x], from_right[x]) {
                (Some(a), Some(b)) => Some(if b.1 < a.1 { b } else { a }),
                (a, b) => a.or(b),
            };
            if let Some((src, _)) = pick {
                out.color[y * w + x] = fb.color[src];
                out.depth[y * w + x] = fb.depth[src];
            }
        }
    }
    out
}
