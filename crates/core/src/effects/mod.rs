//! The effects: pure functions of framebuffers, matrices and their own settings types (never a
//! `Scene`, `Frame`, `Plan` or `Output`): anaglyphs, remapping and the visibility check,
//! occlusion, parallax and its budget, layouts, ChromaDepth's ramp, texgen and glasses, and the
//! SIRDS pieces (pattern, disparity, TIW linking, depth maps, decoding).

pub mod anaglyph;
pub mod calibration;
pub mod chromadepth;
pub mod eye_input;
pub mod frame_sequential;
pub mod ghosting;
pub mod layout;
pub mod legend;
pub mod occlusion;
pub mod parallax;
pub mod rds;
pub mod remap;
pub mod shear_rotate;
pub mod sirds;

/// Rows per task of [`par_fill_rows`] and of the parallax map's rows: about
/// [`PIXELS_PER_TASK`] pixels. Rayon splits a range into a few pieces per thread and splits a
/// piece again only when another thread steals it, so with its default pieces the thread that
/// finishes first would sit idle while the other runs its last piece, up to a quarter of the
/// rows, whenever rows cost unequal work (an anaglyph's flat background against the model's
/// pixels). Small tasks keep both busy to the end; the bytes do not depend on the split.
pub(crate) fn rows_per_task(width: usize) -> usize {
    (PIXELS_PER_TASK / width.max(1)).max(1)
}

/// Pixels per task of [`par_fill_rows`]: a few microseconds of the cheapest finalize pass.
const PIXELS_PER_TASK: usize = 16 * 1024;

/// A new RGBA8 buffer of `pixels` pixels (bytes in memory order), filled row by row in
/// parallel by `fill(y, row)` on rows of `width` pixels (the last one shorter when `width`
/// does not divide `pixels`), without being zeroed first: the finalize passes write every byte
/// anyway, and zeroing a frame-sized buffer is a serial pass over it before the parallel one.
/// Rows are split between threads, never pixels, so the bytes do not depend on the thread
/// count.
///
/// # Safety
/// `fill` must initialize every element of each row it is given (`MaybeUninit::write`, or
/// stores through the row's pointer); the buffer is read as initialized afterwards.
pub(crate) unsafe fn par_fill_rows(
    pixels: usize,
    width: usize,
    fill: impl Fn(usize, &mut [std::mem::MaybeUninit<[u8; 4]>]) + Sync,
) -> Vec<u8> {
    use rayon::prelude::*;
    let mut out: Vec<[u8; 4]> = Vec::with_capacity(pixels);
    out.spare_capacity_mut()[..pixels]
        .par_chunks_mut(width.max(1))
        .enumerate()
        .with_max_len(rows_per_task(width))
        .for_each(|(y, row)| fill(y, row));
    // SAFETY: the first `pixels` elements are within the capacity, and `fill` initialized
    // every one of them (the caller's promise; a panic in `fill` propagates before this).
    unsafe { out.set_len(pixels) };
    out.into_flattened()
}
