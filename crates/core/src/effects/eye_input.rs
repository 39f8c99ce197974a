//! Checks on the framebuffers a finalize mode reads, so bad input is a clear error, never a
//! panic or a silently wrong image.

use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;

/// Checks that `left` and `right` have the same size and color buffers of that size.
///
/// # Errors
/// `Invalid` naming both sizes, or the eye whose color buffer has the wrong length.
pub fn check_same_size(left: &Framebuffer, right: &Framebuffer) -> Result<()> {
    if (left.width, left.height) != (right.width, right.height) {
        return Err(Error::invalid(
            "eye framebuffers",
            format!(
                "{}x{} vs {}x{}",
                left.width, left.height, right.width, right.height
            ),
            "left and right must have the same size",
        ));
    }
    for (name, fb) in [("left", left), ("right", right)] {
        let n = fb.width as usize * fb.height as usize;
        if fb.color.len() != n {
            return Err(Error::invalid(
                format!("{name} eye color"),
                format!("{} pixels", fb.color.len()),
                format!("a {}x{} framebuffer needs {n}", fb.width, fb.height),
            ));
        }
    }
    Ok(())
}

/// Checks that `fb` (called `name` in messages) has a depth buffer of its size whose values are
/// all window depths in [0, 1] (`glDepthRange(0, 1)`): no NaN, no infinity.
///
/// # Errors
/// `Invalid` for a missing or short depth buffer, or naming the first bad pixel and its value.
pub fn check_depth(name: &str, fb: &Framebuffer) -> Result<()> {
    check_depth_len(name, fb)?;
    if let Some(i) = first_outside_unit(&fb.depth) {
        let (x, y) = (i % fb.width as usize, i / fb.width as usize);
        return Err(Error::invalid(
            format!("{name} eye depth at pixel ({x}, {y})"),
            fb.depth[i],
            "window depth must be a number in [0, 1] (NaN or out of range found)",
        ));
    }
    Ok(())
}

/// The length part of [`check_depth`]: a depth buffer of `fb`'s size, values not read. A mode
/// that reads every depth value anyway tests them in its own pass ([`all_in_unit`], a row
/// at a time while it is in cache) and calls [`check_depth`] for the error when one fails: the
/// same error as checking first, one pass over the buffer fewer.
///
/// # Errors
/// `Invalid` for a missing or short depth buffer.
pub(crate) fn check_depth_len(name: &str, fb: &Framebuffer) -> Result<()> {
    let n = fb.width as usize * fb.height as usize;
    if fb.depth.len() != n {
        return Err(Error::invalid(
            format!("{name} eye depth"),
            format!("{} values", fb.depth.len()),
            format!(
                "missing depth: a {}x{} framebuffer needs {n} depth values",
                fb.width, fb.height
            ),
        ));
    }
    Ok(())
}

/// The index of the first value of `depth` outside [0, 1] (NaN included), if any.
///
/// Blocks of 4096 values are tested without an early exit (so the test vectorizes), in
/// parallel; only a failing block is searched value by value. The first failing block is the
/// one `position_first` finds, whatever the thread count, so the answer is
/// `depth.iter().position(|d| !(0.0..=1.0).contains(d))`.
fn first_outside_unit(depth: &[f32]) -> Option<usize> {
    use rayon::prelude::*;
    const BLOCK: usize = 4096;
    let inside = |d: &f32| (*d >= 0.0) & (*d <= 1.0);
    let block = depth
        .par_chunks(BLOCK)
        .position_first(|c| !all_in_unit(c))?;
    let start = block * BLOCK;
    depth[start..]
        .iter()
        .position(|d| !inside(d))
        .map(|i| start + i)
}

/// Whether every value of `c` lies in [0, 1] (NaN does not), with no early exit, compiled for
/// AVX2 where the CPU has it, so the loop vectorizes eight wide: [`check_depth`]'s test, also
/// for a mode that tests each row as it reads it (see [`check_depth_len`]).
pub(crate) fn all_in_unit(c: &[f32]) -> bool {
    #[inline(always)]
    fn body(c: &[f32]) -> bool {
        // An integer OR reduction: LLVM vectorizes it (a fold of `bool`s it does not).
        c.iter()
            .fold(0u32, |bad, d| bad | !((*d >= 0.0) & (*d <= 1.0)) as u32)
            == 0
    }
    #[cfg(target_arch = "x86_64")]
    if crate::simd::kernels().avx2() {
        #[target_feature(enable = "avx2")]
        fn avx2(c: &[f32]) -> bool {
            body(c)
        }
        // SAFETY: the CPU has AVX2 (`Kernels::avx2`), `avx2`'s only requirement.
        return unsafe { avx2(c) };
    }
    body(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The blocked search finds the first bad value wherever it is (in the first block, at a
    /// block's edge, in the last partial block), NaN and ±∞ included, and nothing in good input.
    #[test]
    fn first_outside_unit_finds_the_first_bad_value() {
        let n = 3 * 4096 + 17;
        let good: Vec<f32> = (0..n).map(|i| (i % 1001) as f32 / 1000.0).collect();
        assert_eq!(first_outside_unit(&good), None);
        assert_eq!(first_outside_unit(&[]), None);
        for (at, bad) in [
            (0, -0.5),
            (4095, f32::NAN),
            (4096, 1.0f32.next_up()),
            (2 * 4096 + 3, f32::INFINITY),
            (n - 1, f32::NEG_INFINITY),
        ] {
            let mut v = good.clone();
            v[at] = bad;
            // A later bad value must not be reported instead.
            v[n - 1] = if at == n - 1 { bad } else { 2.0 };
            assert_eq!(first_outside_unit(&v), Some(at), "{bad} at {at}");
        }
        // -0.0 is a window depth (it compares equal to 0).
        assert_eq!(first_outside_unit(&[-0.0, 1.0]), None);
    }
}
