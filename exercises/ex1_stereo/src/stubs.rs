//! Your code: complete every `todo!`. Each doc comment states the task, where its formula comes
//! from, and the conventions; `stereolab grade ex1` scores each function on its own and
//! `stereolab grade points` prints each task's points.

use exercise_api::Lighting;
use exercise_api::{
    AnaglyphKind, AnaglyphMatrices, Eye, EyeView, ScreenSetup, StereoSetup, Texture,
};
use glam::{Mat4, Vec2, Vec3};

/// Task `frustum`: the projection matrix `P_frustum(l, r, b, t, n, f)`.
///
/// Source: the exercise slides, "Projection Matrix – View Frustum" (OpenGL's `glFrustum`):
/// ```text
/// | 2n/(r-l)    0      (r+l)/(r-l)      0        |
/// |    0     2n/(t-b)  (t+b)/(t-b)      0        |
/// |    0        0      (n+f)/(n-f)  2nf/(n-f)    |
/// |    0        0         -1            0        |
/// ```
/// `l, r, b, t` lie on the near plane; `n, f` are positive distances along −Z. Right-handed eye
/// space, NDC Z in [−1, 1]. `glam::Mat4` is column-major: `Mat4::from_cols(c0, c1, c2, c3)`
/// takes columns, so the matrix above is not typed row by row.
pub fn frustum(l: f32, r: f32, b: f32, t: f32, n: f32, f: f32) -> Mat4 {
    // TODO: build P_frustum column by column.
    todo!("P_frustum(l={l:?}, r={r:?}, b={b:?}, t={t:?}, n={n:?}, f={f:?})")
}

/// Task `stereo_frustum`: the arguments `[l, r, b, t, n, f]` of eye `eye`'s
/// `P_frustum±` in the off-axis (parallel-axis, asymmetric frustum) stereo rig.
///
/// Source: the exercise slides, "Projection Matrix Stereo Case": the mono frustum has
/// `t = n · tan(fov_y / 2)`, `b = −t`, `r = t · aspect`, `l = −r`; each eye's frustum is
/// translated by ∓d/2 and sheared by ±d/(2 z0), so on the near plane `l` and `r` move by
/// `± (d/2) · n / z0` (intercept theorem): the left eye ([`Eye::Left`], at x = −d/2) moves them
/// by `+(d/2)·n/z0`, the right eye ([`Eye::Right`], at x = +d/2) by `−(d/2)·n/z0`. `t, b, n, f`
/// do not change. Toe-in (rotating the eyes) is wrong: it gives vertical parallax (the StereoGraphics guide (Akka)).
pub fn stereo_frustum(setup: &StereoSetup, eye: Eye) -> [f32; 6] {
    // TODO: the mono frustum, then shift l and r for this eye.
    todo!("frustum bounds of eye {eye:?} for {setup:?}")
}

/// Task `sheet_frustum`: the arguments `[l, r, b, t, n, f]` of eye `eye`'s
/// `P_frustum±` in the exercise slides' own, screen-relative terms.
///
/// Source: the exercise slides, "Projection Matrix – View Frustum" and "Projection Matrix Stereo
/// Case". The screen (width w, height h) stands at the zero-parallax distance z0; the eye
/// separation d is a fraction of the screen width, so the eyes sit at x = ∓½·d·w. By the
/// intercept theorem the screen seen from the eye shrinks by n/z0 on the near plane:
/// - `t = ½·h·n/z0`, `b = −t`;
/// - the mono `r = ½·w·n/z0`, `l = −r`; each eye's `l` and `r` are translated by
///   `±½·d·w·n/z0`: the left eye ([`Eye::Left`], at x = −½·d·w) moves them by `+½·d·w·n/z0`, the
///   right eye ([`Eye::Right`], at x = +½·d·w) by `−½·d·w·n/z0`;
/// - `n`, `f` unchanged.
///
/// (The slides' matching `T±` is the translation by `½·d·w` in x that moves this eye to the
/// origin: `T_left = translate(+½·d·w, 0, 0)` for the left eye at x = −½·d·w,
/// `T_right = translate(−½·d·w, 0, 0)`, as in [`stereo_matrices`].)
pub fn sheet_frustum(screen: &ScreenSetup, eye: Eye) -> [f32; 6] {
    // TODO: t from h, l and r from w, then shift l and r for this eye; all scaled by n/z0.
    todo!("frustum bounds of eye {eye:?} for {screen:?}")
}

/// Task `stereo_matrices` (image check): eye `eye`'s view and projection, given the
/// camera's (cyclopean) modelview `modelview`.
///
/// Source: the exercise slides, "Transformation Matrices – Effect on lighting". `T±` moves the world so
/// that the eye at x = ∓d/2 (eye space) becomes the origin: `T_left = translate(+d/2, 0, 0)`,
/// `T_right = translate(−d/2, 0, 0)`. With `P±` = [`frustum`] of [`stereo_frustum`]:
/// - per-eye lighting: `view = T± · MV`, `projection = P±`;
/// - cyclopic lighting: `view = MV`, `projection = P± · T±`.
///
/// Both give the same MVP; they differ in where the shading sees the eye.
pub fn stereo_matrices(
    setup: &StereoSetup,
    modelview: Mat4,
    eye: Eye,
    lighting: Lighting,
) -> EyeView {
    // TODO: T± from the eye, then combine as the lighting variant asks.
    todo!("view and projection of eye {eye:?}, {lighting:?}, {setup:?}, MV = {modelview:?}")
}

/// Task `anaglyph_matrices` (image check): the matrices `ML`, `MR` of
/// `out = clamp(ML · left + MR · right)` for `kind`.
///
/// Source: the exercise slides, "Anaglyph" (after 3dtv.at): true, gray, color and half-color anaglyphs for
/// red (left eye, index 0) / cyan (right eye) glasses. Luminance weights `0.299, 0.587, 0.114`.
/// `ColorMatrix` is written as on the slides: `m[row][column]`, rows are output R, G, B.
pub fn anaglyph_matrices(kind: AnaglyphKind) -> AnaglyphMatrices {
    // TODO: one match arm per kind.
    todo!("ML and MR of the {kind:?} anaglyph")
}

/// Task `finalize_pixel` (image check): one pixel of the finalize shader, the pass
/// that combines the two eyes' color textures into the anaglyph.
///
/// Source: the exercise slides, "Multi Pass Rendering" (a final shader program combining the two
/// views) and "Anaglyph": `out = clamp(ML · left + MR · right, 0, 1)`, each channel clamped to
/// [0, 1]. `left` and `right` are the two eyes' colors (R, G, B in [0, 1]) at the same pixel;
/// `m.left[row][column]` is `ML` written as on the slides (rows are the output R, G, B), so
/// `out[i] = Σ_j ML[i][j]·left[j] + MR[i][j]·right[j]`. Matrices with negative entries (such
/// as Dubois') or large ones give values outside [0, 1]: those are clamped.
pub fn finalize_pixel(left: [f32; 3], right: [f32; 3], m: &AnaglyphMatrices) -> [f32; 3] {
    // TODO: two matrix-vector products, a sum, a clamp per channel.
    todo!("finalize left {left:?}, right {right:?} with {m:?}")
}

/// Bonus task `dubois_matrices`: Dubois' least-squares red-cyan matrices.
///
/// Source: Eric Dubois (2001), the CRT-derived numbers as in three.js' `AnaglyphEffect.js`
/// (listed in `stereolab/docs/anaglyph-matrices.md` of the handout): six significant digits.
/// Same layout as [`anaglyph_matrices`].
pub fn dubois_matrices() -> AnaglyphMatrices {
    // TODO: copy the numbers carefully (public copies contain typos).
    todo!("Dubois red-cyan ML and MR")
}

/// Task `remap` (image check): where the surface point seen by the left eye at
/// texture coordinate `uv_left` with stored depth `depth_left` appears in the right image.
///
/// Source: the exercise slides, "Stereo Rendering – Remapping":
/// `clip_r = MVP_r · MVP_l⁻¹ · (x_ndc,l, y_ndc,l, z_ndc,l, 1)`, `ndc_r = clip_r.xyz / clip_r.w`,
/// `τ = ((x_ndc,r + 1)/2, (y_ndc,r + 1)/2)`.
/// Conventions: `uv_left` and the returned `u, v` are texture coordinates in [0, 1]
/// (v = 0 bottom); `depth_left` is a depth-texture value in [0, 1] (window depth), while NDC
/// z lies in [−1, 1]. Returns `Some((u, v, depth_right))` with `depth_right` the point's window
/// depth in [0, 1] as the right eye would store it, or `None` when `clip_r.w ≤ 0` (behind the
/// right eye).
pub fn remap(mvp_left: Mat4, mvp_right: Mat4, uv_left: Vec2, depth_left: f32) -> Option<Vec3> {
    // TODO: texture coordinates and depth to NDC, through MVP_r · MVP_l⁻¹, w-divide, back.
    todo!("remap uv {uv_left:?} depth {depth_left:?} with MVP_l {mvp_left:?}, MVP_r {mvp_right:?}")
}

/// Task `remap_right_to_left` (image check): the other direction of [`remap`]: where
/// the surface point seen by the RIGHT eye at texture coordinate `uv_right` with stored depth
/// `depth_right` appears in the LEFT image.
///
/// Source: the exercise slides, "Stereo Rendering – Remapping" (both directions: `p_0` into the
/// right image and `p_1` into the left one): `clip_l = MVP_l · MVP_r⁻¹ · (x_ndc,r, y_ndc,r,
/// z_ndc,r, 1)`, then the w-clip and the texture coordinates as in [`remap`]. The arguments
/// come in the same order as [`remap`]'s (`mvp_left` first). Returns `Some((u, v, depth_left))`
/// with `depth_left` the point's window depth in [0, 1] as the left eye would store it, or
/// `None` when `clip_l.w ≤ 0` (behind the left eye).
pub fn remap_right_to_left(
    mvp_left: Mat4,
    mvp_right: Mat4,
    uv_right: Vec2,
    depth_right: f32,
) -> Option<Vec3> {
    // TODO: the same chain as remap, with the eyes' roles exchanged.
    todo!(
        "remap uv {uv_right:?} depth {depth_right:?} from the right eye, MVP_l {mvp_left:?}, MVP_r {mvp_right:?}"
    )
}

/// Task `visible` (image check): is the left eye's surface point also visible to the
/// right eye?
///
/// Source: the exercise slides, "Visibility Check": look up the right eye's depth texture at the remapped
/// coordinate (`stored_depth`) and compare with the point's own remapped depth
/// (`remapped_depth`, from [`remap`]): visible when they agree within `tolerance`
/// (`|stored − remapped| ≤ tolerance`). Otherwise only `stored < remapped` is possible: the
/// right eye sees something nearer, the point is occluded. A point that remaps outside the
/// image (`u` or `v` outside [0, 1], or `uv_right == None`) is not visible either.
pub fn visible(
    uv_right: Option<Vec2>,
    remapped_depth: f32,
    stored_depth: f32,
    tolerance: f32,
) -> bool {
    // TODO: out of the image → false; then compare the depths.
    todo!(
        "visible? uv {uv_right:?}, remapped {remapped_depth:?}, stored {stored_depth:?}, tolerance {tolerance:?}"
    )
}

/// Task `rds_right` (image check): the right image of Julesz's random-dot stereo
/// pair, built from your [`remap_right_to_left`] and [`visible`].
///
/// Source: the SIRDS paper (Petz et al.), §1 (Julesz's random-dot stereograms: depth from
/// stereopsis alone), with the exercise slides' remapping and visibility check. The left image
/// is random dots (`left_dots`, true = white), which show no shape. The right image is the
/// same dots as the right eye sees them: for every right pixel (x, y)
/// 1. its texture coordinate is the pixel's center, `u = (x + ½)/width`, `v = 1 − (y + ½)/height`
///    (v = 0 is the bottom row; texel (x, y) counts rows from the top, see [`Texture`]), and its
///    stored depth is `right_depth.get(x, y)`;
/// 2. [`remap_right_to_left`] gives where that surface point lies in the left image and its
///    left window depth (`None`: behind the left eye);
/// 3. the left texel there is the nearest one, `(⌊u_l · width⌋, ⌊(1 − v_l) · height⌋)`, when it
///    lies inside the image; the left eye's stored depth there is `left_depth` at that texel;
/// 4. when [`visible`] says the left eye sees the same point (`tolerance` as given), the right
///    pixel takes the left dot at that texel;
/// 5. otherwise (occluded in the left eye, outside the left image, behind the left eye) the right
///    eye sees something the left eye does not: the pixel takes `fresh_dots.get(x, y)`, an
///    independent random dot (Julesz's uncorrelated region).
///
/// Background pixels (depth 1) lie on the far plane and follow the same rule. Viewed as a pair
/// (or as the red-cyan anaglyph `stereolab grade` draws), the dots shift by the parallax p(z)
/// and the scene appears in depth. All textures have the same size; return one of that size.
#[allow(clippy::too_many_arguments)]
pub fn rds_right(
    mvp_left: Mat4,
    mvp_right: Mat4,
    left_depth: &Texture<f32>,
    right_depth: &Texture<f32>,
    left_dots: &Texture<bool>,
    fresh_dots: &Texture<bool>,
    tolerance: f32,
) -> Texture<bool> {
    // TODO: for each right pixel: remap into the left image, look up the left texel, check
    // visibility, take the left dot or the fresh one.
    todo!(
        "right dots of a {}×{} pair (tolerance {tolerance:?}, MVP_l {mvp_left:?}, MVP_r {mvp_right:?}, {} left dots, {} fresh dots, {} right depths)",
        left_depth.width,
        left_depth.height,
        left_dots.texels.len(),
        fresh_dots.texels.len(),
        right_depth.texels.len()
    )
}

/// Task `parallax`: the screen parallax of a point at eye distance `z`.
///
/// Source: the exercise slides, "Parallax and Eye Separation": `p(z) = d · (1 − z0 / z)` with `z` and
/// `z0` positive distances in front of the eyes and `d` the eye separation. Negative in front
/// of the screen (`z < z0`), zero on it, positive behind it, approaching `d` at infinity.
pub fn parallax(z: f32, zero_parallax: f32, eye_separation: f32) -> f32 {
    // TODO: one line.
    todo!("p(z = {z:?}) with z0 = {zero_parallax:?}, d = {eye_separation:?}")
}

/// Task `parallax_color` (image check): parallax shown as color (the exercise slides: "blue
/// negative, red positive").
///
/// The mapping: `t = clamp(p / max_abs, −1, 1)`; positive `t` gives `[t, 0, 0]` (red), negative
/// `t` gives `[0, 0, −t]` (blue), zero gives black. Components in [0, 1].
pub fn parallax_color(p: f32, max_abs: f32) -> [f32; 3] {
    // TODO: scale, clamp, pick the channel by the sign.
    todo!("color of parallax {p:?} scaled by {max_abs:?}")
}
