//! Your code: complete every `todo!`. Each doc comment states the task, where its formula comes
//! from, and the conventions; `stereolab grade ex3` scores each function on its own and
//! `stereolab grade points` prints each task's points.

use exercise_api::{SirdsGeometry, SirdsSetup};

/// Task `disparity_constant_direction`: the distance between the two projections of a
/// point at depth `z` behind the image plane, assuming every eye ray meets the image plane at
/// the angle `phi` (radians).
///
/// Source: the SIRDS paper (Petz et al.), §2.1, Eq. (1): `d = 2 z / tan(φ)`.
pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {
    // TODO: Eq. (1).
    todo!("d for z = {z:?}, phi = {phi:?} rad")
}

/// Task `disparity_constant_eyes`: the same distance for eyes `a` apart at distance
/// `f` in front of the image plane (all in pixels), the point centered in front of the eyes.
///
/// Source: the SIRDS paper (Petz et al.), §2.2, Eq. (3): `d = a z / (z + f)`.
pub fn disparity_constant_eyes(z: f32, geometry: &SirdsGeometry) -> f32 {
    // TODO: Eq. (3).
    todo!("d for z = {z:?} with {geometry:?}")
}

/// Task `link_row` (image check): the per-scan-line constraints of a SIRDS with
/// hidden-surface removal (the SIRDS paper's §2–3, after its reference 5: Thimbleby, Inglis and Witten,
/// "Displaying 3D images", IEEE Computer 27(10), 1994).
///
/// `nearness[x]` in [0, 1] is the surface seen through pixel `x` of image row `row`: 1 is the
/// front of the depth range (`setup.depth_near` pixels behind the image plane), 0 the background
/// plane (`setup.depth_far`). Return `same` with `same[x] ≥ x`: pixel `x` must have the color of
/// pixel `same[x]` (`same[x] == x`: free). For each `x` from left to right:
/// 1. depth `t = depth_far − z (depth_far − depth_near)`, separation `s = ⌊d + ½⌋` with `d` from
///    [`disparity_constant_eyes`]; the pair is `left = x − (s + (s & row & 1)) / 2` (integer
///    division: for odd `s` the extra pixel alternates between rows), `right = left + s`;
///    skip `x` unless `0 ≤ left` and `right < nearness.len()`.
/// 2. Hidden-surface removal: the rays from the point to the eyes rise by
///    `rise = (2 (t + f) / a) / (depth_far − depth_near)` nearness per pixel (the SIRDS paper's Eq. (2));
///    for `k = 1, 2, …`: `zk = z + k · rise`; the point is hidden (skip `x`) when
///    `nearness[x − k] ≥ zk` or `nearness[x + k] ≥ zk` (indices inside the row); it is visible
///    once `zk ≥ 1` (checked after the test).
/// 3. Link `left` and `right` keeping `same` a chain towards the right:
///    ```text
///    k = same[left]
///    while k ≠ left and k ≠ right:
///        if k < right: left = k
///        else: left = right; right = k
///        k = same[left]
///    same[left] = right
///    ```
pub fn link_row(nearness: &[f32], row: u32, setup: &SirdsSetup) -> Vec<usize> {
    // TODO: the three steps above.
    todo!(
        "links of row {row:?} ({} pixels) with {setup:?}: {nearness:?}",
        nearness.len()
    )
}
