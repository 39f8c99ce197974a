//! From an autostereogram to a stereo pair: the views a viewer's two eyes see when they fuse
//! it, so that it can be shown with glasses or in a stereo viewer (`stereolab sirds --decode X
//! --pair DIR`).
//!
//! A decoded separation `s` at pair middle `m` says: the left eye looks through pixel
//! `m − s/2`, the right eye through `m + s/2`, and both see the same surface point, of that
//! pixel's color, at the depth `s` encodes. In a stereo pair the same point is drawn at
//! `m ∓ δ/2` in the left and right views, with screen parallax `δ = s − s₀` for a wall-eyed
//! autostereogram (near points repeat sooner: smaller `s`, crossed parallax, in front of the
//! screen) and `δ = s₀ − s` for a cross-eyed one. `s₀` is the background's separation (the
//! largest wall-eyed, the smallest cross-eyed: the 99th or 1st percentile, not a stray
//! extreme), so the background sits on the screen and the rest stands out in front of it.
//! Points are drawn nearest last (a z-test on `−δ`); holes the near points uncover take the
//! color of their nearest drawn neighbour on the same row.

use super::decode::Decoded;
use crate::error::{Error, Result};

/// The two views, row-major RGBA, each the size of the autostereogram.
#[derive(Clone, Debug, PartialEq)]
pub struct Views {
    /// What the left eye sees.
    pub left: Vec<[u8; 4]>,
    /// What the right eye sees.
    pub right: Vec<[u8; 4]>,
    /// The separation drawn at zero parallax (the background), pixels.
    pub zero_parallax_separation: f32,
}

/// The left and right views of `pixels` (the autostereogram `decoded` came from).
///
/// # Errors
/// `Invalid` when `pixels` does not match `decoded`'s size or nothing at all was decoded.
pub fn views(pixels: &[[u8; 4]], decoded: &Decoded, cross_eyed: bool) -> Result<Views> {
    let (w, h) = (decoded.width as usize, decoded.height as usize);
    if pixels.len() != w * h || decoded.separation.len() != w * h {
        return Err(Error::invalid(
            "stereo pair",
            format!("{} pixels", pixels.len()),
            format!("the image and its decoded separations must both be {w}×{h}"),
        ));
    }
    let mut finite: Vec<f32> = decoded
        .separation
        .iter()
        .copied()
        .filter(|s| s.is_finite())
        .collect();
    if finite.is_empty() {
        return Err(Error::invalid(
            "stereo pair",
            "no separation decoded",
            "the image is not an autostereogram (nothing repeats): there is no pair to show",
        ));
    }
    // The background: the 99th percentile of the separations wall-eyed, the 1st cross-eyed
    // (not the extreme, which may be a stray match).
    let k = (finite.len() - 1) * if cross_eyed { 1 } else { 99 } / 100;
    let s0 = *finite.select_nth_unstable_by(k, f32::total_cmp).1;
    let mut left = vec![[0u8; 4]; w * h];
    let mut right = vec![[0u8; 4]; w * h];
    let mut sep = vec![s0; w];
    let (mut key_l, mut key_r) = (vec![f32::NEG_INFINITY; w], vec![f32::NEG_INFINITY; w]);
    for y in 0..h {
        let row = &pixels[y * w..(y + 1) * w];
        fill_row(&decoded.separation[y * w..(y + 1) * w], s0, &mut sep);
        key_l.fill(f32::NEG_INFINITY);
        key_r.fill(f32::NEG_INFINITY);
        let (out_l, out_r) = (
            &mut left[y * w..(y + 1) * w],
            &mut right[y * w..(y + 1) * w],
        );
        for (m, &s) in sep.iter().enumerate() {
            // The left eye's pixel, or the right eye's where that falls off the image (both
            // show the same point).
            let (l, r) = ((m as f32 - s / 2.0).round(), (m as f32 + s / 2.0).round());
            let source = if l >= 0.0 { l } else { r };
            let color = row[(source.max(0.0) as usize).min(w - 1)];
            let delta = if cross_eyed { s0 - s } else { s - s0 };
            // Nearer (more negative δ) wins.
            for (x, out, key) in [
                (m as f32 - delta / 2.0, &mut *out_l, &mut key_l),
                (m as f32 + delta / 2.0, &mut *out_r, &mut key_r),
            ] {
                let x = x.round();
                if x >= 0.0 && (x as usize) < w && -delta > key[x as usize] {
                    key[x as usize] = -delta;
                    out[x as usize] = color;
                }
            }
        }
        fill_holes(out_l, &key_l);
        fill_holes(out_r, &key_r);
    }
    Ok(Views {
        left,
        right,
        zero_parallax_separation: s0,
    })
}

/// One row's separations with the undecoded (`NaN`) ones filled from the nearest decoded one
/// to the left (to the right at the row's start); `s0` for a row with none.
fn fill_row(row: &[f32], s0: f32, out: &mut [f32]) {
    let first = row.iter().copied().find(|s| s.is_finite()).unwrap_or(s0);
    let mut last = first;
    for (o, &s) in out.iter_mut().zip(row) {
        if s.is_finite() {
            last = s;
        }
        *o = last;
    }
}

/// Pixels no point landed on take the nearest drawn pixel to their left (right at the start).
fn fill_holes(row: &mut [[u8; 4]], key: &[f32]) {
    let Some(first) = key.iter().position(|k| k.is_finite()) else {
        return;
    };
    let mut last = row[first];
    for (p, k) in row.iter_mut().zip(key) {
        if k.is_finite() {
            last = *p;
        } else {
            *p = last;
        }
    }
}
