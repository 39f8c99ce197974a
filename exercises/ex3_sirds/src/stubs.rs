//! Your code: complete every `todo!`. Each doc comment states the task, where its formula comes
//! from, and the conventions; `stereolab grade ex3` scores each function on its own.

use stereolab::exercise::SirdsGeometry;

/// Task `disparity_constant_direction` (1 point): the distance between the two projections of a
/// point at depth `z` behind the image plane, assuming every eye ray meets the image plane at
/// the angle `phi` (radians).
///
/// Source: seed 002, §2.1, Eq. (1): `d = 2 z / tan(φ)`.
pub fn disparity_constant_direction(z: f32, phi: f32) -> f32 {
    // TODO: Eq. (1).
    todo!("d for z = {z:?}, phi = {phi:?} rad")
}

/// Task `disparity_constant_eyes` (1 point): the same distance for eyes `a` apart at distance
/// `f` in front of the image plane (all in pixels), the point centered in front of the eyes.
///
/// Source: seed 002, §2.2, Eq. (3): `d = a z / (z + f)`.
pub fn disparity_constant_eyes(z: f32, geometry: &SirdsGeometry) -> f32 {
    // TODO: Eq. (3).
    todo!("d for z = {z:?} with {geometry:?}")
}

/// Task `link_row` (3 points, image check): the per-scan-line constraints of a SIRDS with
/// hidden-surface removal (seed 002 §2–3; the linking of Thimbleby, Inglis and Witten, 1994).
///
/// `depths[x]` is the depth (pixels, ≥ 0) behind the image plane of the surface seen through
/// pixel `x`. Return `same` with `same[x] ≥ x`: pixel `x` must have the color of pixel
/// `same[x]` (`same[x] == x`: free). For each `x`:
/// 1. `s = round(d)` with `d` from [`disparity_constant_eyes`]; the pair is
///    `left = x − s/2` (integer division), `right = left + s`; skip it unless both lie in the row.
/// 2. Hidden-surface removal: the point (x, z) must see both eyes. The ray to an eye at offset
///    `t = 1, 2, …` pixels has depth `z − t (z + f) / (a/2)`; stop when it reaches the image
///    plane (depth ≤ 0) or leaves the row; if `depths[x − t]` or `depths[x + t]` is nearer
///    (smaller) than the ray, the point is hidden: skip it.
/// 3. Link `left` and `right` keeping `same` a chain towards the right:
///    ```text
///    k = same[left]
///    while k ≠ left and k ≠ right:
///        if k < right: left = k
///        else: same[left] = right; left = right; right = k
///        k = same[left]
///    same[left] = right
///    ```
pub fn link_row(depths: &[f32], geometry: &SirdsGeometry) -> Vec<usize> {
    // TODO: the three steps above.
    todo!(
        "links of a row of {} depths with {geometry:?}: {depths:?}",
        depths.len()
    )
}
