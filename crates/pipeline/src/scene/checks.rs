//! The hard cases a scene can ask for that single precision cannot render faithfully: refused
//! when the output would be wrong everywhere, warned about (in [`Scene::notes`], each line
//! starting `warning:`) when only part of it suffers. Every message names the field and the
//! remedy.
//!
//! The numbers are those of the rasterizer's own pipeline (f32 throughout):
//! - window depth of a surface at eye depth `z` under `frustum(…, n, f)` and
//!   `glDepthRange(0, 1)`: `z_w = f (z − n) / ((f − n) z)`, so `dz_w/dz = f n / ((f − n) z²)`;
//! - one step of the f32 depth buffer at `z_w` is `ulp(z_w)` (2⁻²⁴ just below 1), so two
//!   surfaces closer than `Δz = ulp(z_w) · (f − n) z² / (f n)` in eye depth share a depth value
//!   (the classic `z²/n` law of the perspective depth buffer);
//! - a surface whose `z_w` rounds to 1.0 loses the `<` test against the clear value 1.0 and is
//!   never drawn;
//! - an f32 coordinate of magnitude `m` is spaced `ulp(m) ≈ m · 2⁻²³` from its neighbours.

use glam::DVec3;

use super::{Object, Scene, file::LightSpec, file::RasterSpec};
use crate::plan::Output;
use stereolab_core::{Camera, DepthMode, Error, Result, SirdsAlgorithm, SirdsSettings};

/// Warn when two surfaces must be further apart in depth than this fraction of the smallest
/// object's size to be told apart: a cube 1 unit wide z-fights where its faces come within
/// 1/1000 of a unit.
pub const DEPTH_RESOLUTION_WARN: f64 = 1e-3;

/// Warn when an object's coordinates are spaced more coarsely than this fraction of its size
/// (1/10 000: a pixel of a 10 000-pixel-wide view of it).
pub const ORIGIN_PRECISION_WARN: f64 = 1e-4;

/// `[light]`: every factor finite and ≥ 0 (a NaN or negative factor turns objects black
/// without an error anywhere else).
/// `[multiview] views`: 2 to [`MAX_VIEWS`](stereolab_core::MAX_VIEWS) cameras (each one a
/// full pass and an eye-sized image).
pub(super) fn multiview_views(views: u32) -> Result<u8> {
    let max = stereolab_core::MAX_VIEWS;
    u8::try_from(views)
        .ok()
        .filter(|n| (2..=max).contains(&u32::from(*n)))
        .ok_or_else(|| {
            Error::invalid(
                "multiview.views",
                views,
                format!(
                    "must be 2 to {max} cameras (2 is the rig's own left/right pair; \
                     lenticular sheets use about 4 to 12)"
                ),
            )
        })
}

/// The `view_tiles` image of `views` views of a `width`×`height` image within the output
/// bounds ([`MAX_OUTPUT_SIDE`](stereolab_core::MAX_OUTPUT_SIDE),
/// [`MAX_OUTPUT_PIXELS`](stereolab_core::MAX_OUTPUT_PIXELS)).
pub(super) fn check_view_tiles(views: u8, width: u32, height: u32) -> Result<()> {
    let (columns, rows) = stereolab_core::view_grid(u32::from(views));
    let (w, h) = (u64::from(columns * width), u64::from(rows * height));
    let max_side = u64::from(stereolab_core::MAX_OUTPUT_SIDE);
    if w > max_side || h > max_side || w * h > stereolab_core::MAX_OUTPUT_PIXELS {
        return Err(Error::invalid(
            "multiview.views",
            views,
            format!(
                "tiles a {w}x{h} view_tiles image ({columns}x{rows} views of {width}x{height}), \
                 over the output limit ({max_side} a side, {} pixels); use fewer views or a \
                 smaller image",
                stereolab_core::MAX_OUTPUT_PIXELS
            ),
        ));
    }
    Ok(())
}

pub(super) fn check_light(l: &LightSpec) -> Result<()> {
    for (name, v) in [
        ("light.ambient", l.ambient),
        ("light.specular", l.specular),
        ("light.shininess", l.shininess),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::invalid(
                name,
                v,
                "must be a finite number ≥ 0 (ambient and specular are 0..1 factors, \
                 shininess the Blinn-Phong exponent)",
            ));
        }
    }
    Ok(())
}

/// `[raster] depth` and `infinite_far` as a [`DepthMode`] (reversed-Z takes the camera's clip
/// distances).
pub(super) fn depth_mode(spec: &RasterSpec, camera: &Camera) -> Result<DepthMode> {
    let mode = match spec.depth.as_deref() {
        None | Some("standard") => DepthMode::Standard,
        Some("reversed-z") => DepthMode::ReversedZ {
            near: camera.near,
            far: if spec.infinite_far {
                f32::INFINITY
            } else {
                camera.far
            },
        },
        Some("f64") => DepthMode::F64,
        Some(other) => {
            return Err(Error::invalid(
                "raster.depth",
                other,
                "one of \"standard\" (lavapipe's f32 window depth), \"reversed-z\" (f32, \
                 resolves far surfaces at any near plane), \"f64\"",
            ));
        }
    };
    if spec.infinite_far && !matches!(mode, DepthMode::ReversedZ { .. }) {
        return Err(Error::invalid(
            "raster.infinite_far",
            true,
            "needs raster.depth = \"reversed-z\" (the standard depth stays lavapipe's, and f64 \
             depth needs no far plane to be precise)",
        ));
    }
    Ok(mode)
}

/// Per-vertex SIRDS renders the background plane at `sirds.back` and maps `sirds.front` to the
/// nearest depth: both must lie inside the camera's clip range, or the plane is clipped away
/// and the image is no autostereogram.
pub(super) fn check_sirds_clip(s: &SirdsSettings, camera: &Camera) -> Result<()> {
    if s.algorithm != SirdsAlgorithm::PerVertex {
        return Ok(());
    }
    for (name, v) in [("sirds.front", s.front), ("sirds.back", s.back)] {
        // At (or just before) the far plane the window depth rounds to 1.0 in f32 and the
        // plane loses the LESS test against the cleared depth: as lost as if clipped.
        let lost = |v: f32| {
            window_depth(f64::from(v), f64::from(camera.near), f64::from(camera.far)) as f32 >= 1.0
        };
        if let Some(v) = v.filter(|v| !(*v >= camera.near && *v <= camera.far) || lost(*v)) {
            return Err(Error::invalid(
                name,
                v,
                format!(
                    "lies outside the clip range [camera.near, camera.far] = [{}, {}] (or so \
                     near camera.far that its f32 window depth is 1.0): the per-vertex SIRDS would clip its background plane away; move {name} \
                     inside that range or widen camera.near/camera.far",
                    camera.near, camera.far
                ),
            ));
        }
    }
    Ok(())
}

/// The eye-depth range `(nearest, farthest)` of all vertices in front of the cyclopean camera,
/// in f64. Eye depth is affine across a triangle, so the vertices bound every surface.
fn eye_depth_range(scene: &Scene) -> Option<(f64, f64)> {
    let view = scene.camera.view().as_dmat4();
    let mut range: Option<(f64, f64)> = None;
    for p in scene.world_points() {
        let z = -view.transform_point3(p.as_dvec3()).z;
        if z.is_finite() {
            range = Some(range.map_or((z, z), |(a, b)| (a.min(z), b.max(z))));
        }
    }
    range
}

/// Window depth `z_w = f (z − n) / ((f − n) z)` of eye depth `z`, in f64.
fn window_depth(z: f64, n: f64, f: f64) -> f64 {
    f * (z - n) / ((f - n) * z)
}

/// The eye-depth distance `Δz` two surfaces at eye depth `z` need to get different f32 window
/// depths: `ulp(z_w) · (f − n) z² / (f n)`.
pub fn depth_resolution(z: f64, n: f64, f: f64) -> f64 {
    let zw = window_depth(z, n, f) as f32;
    let ulp = f64::from(f32::from_bits(zw.to_bits() + 1) - zw);
    ulp * (f - n) * z * z / (f * n)
}

/// The eye-depth distance two surfaces at eye depth `z` need to be told apart by the depth test
/// of `mode` (near and far planes `n`, `f`):
/// - standard: [`depth_resolution`], `≈ 2⁻²⁴ z²/n`;
/// - reversed-Z: the key `k = a/z + b` (`a = n f/(f − n)`, `b = −n/(f − n)`; `a = n`, `b = 0`
///   for an infinite far plane) is spaced `ulp(k)` and rounded once from `a/z` and `b`, so
///   `Δz = max(ulp(k), ulp(a/z), ulp(b)) · z²/a`: about `2⁻²³ z` with an infinite far plane;
/// - f64: the key `1/z` in f64, `Δz ≈ 2⁻⁵² z`.
pub fn resolution_of(mode: DepthMode, z: f64, n: f64, f: f64) -> f64 {
    match mode {
        DepthMode::Standard => depth_resolution(z, n, f),
        DepthMode::ReversedZ { far, .. } => {
            let (a, b) = if far.is_infinite() {
                (n, 0.0)
            } else {
                (n * f / (f - n), -n / (f - n))
            };
            let k = a / z + b;
            let ulp = [k, a / z, b]
                .map(|v| f64::from(ulp_f32(v as f32)))
                .into_iter()
                .fold(0.0, f64::max);
            ulp * z * z / a
        }
        DepthMode::F64 => z * f64::EPSILON,
    }
}

/// The bounding-box diagonal and the largest coordinate magnitude of one object, in world space.
fn extent(o: &Object) -> Option<(f64, f64)> {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in &o.mesh.positions {
        let w = o.model.transform_point3(*p).as_dvec3();
        lo = lo.min(w);
        hi = hi.max(w);
    }
    (lo.x <= hi.x).then(|| ((hi - lo).length(), lo.abs().max(hi.abs()).max_element()))
}

/// Checks depth precision, distance from the origin and the ChromaDepth range once the meshes
/// are loaded; returns the warnings.
///
/// # Errors
/// `camera.near` when every surface's window depth rounds to 1.0 (nothing would be drawn).
pub(super) fn precision_warnings(scene: &Scene) -> Result<Vec<String>> {
    let mut warnings = Vec::new();
    let sizes: Vec<(String, f64, f64)> = scene
        .objects
        .iter()
        .filter_map(|o| extent(o).map(|(d, m)| (o.name.clone(), d, m)))
        .collect();
    for (name, size, mag) in &sizes {
        let spacing = f64::from(ulp_f32(*mag as f32));
        if *size > 0.0 && spacing > ORIGIN_PRECISION_WARN * size {
            warnings.push(format!(
                "warning: {name} lies up to {mag:.3e} from the origin, {:.0} times its size \
                 ({size:.3e}): single precision spaces coordinates there {spacing:.3e} apart, \
                 {:.2e} of its size, so its vertices snap visibly; move it (its translate) and \
                 camera.eye/target nearer the origin",
                mag / size,
                spacing / size
            ));
        }
    }
    let Some((z_lo, z_hi)) = eye_depth_range(scene) else {
        return Ok(warnings);
    };
    let (n, f) = (f64::from(scene.camera.near), f64::from(scene.camera.far));
    let (near32, far32) = (scene.camera.near, scene.camera.far);
    let (near_s, far_s) = (z_lo.max(n), z_hi.min(f));
    if near_s <= far_s {
        // The raise of `near` that brings the farthest surface's resolution to the warning
        // threshold (Δz ≈ 2⁻²⁴ z²/n for f ≫ n).
        let smallest = sizes
            .iter()
            .map(|s| s.1)
            .filter(|d| *d > 0.0)
            .fold(f64::INFINITY, f64::min);
        let tol = DEPTH_RESOLUTION_WARN * if smallest.is_finite() { smallest } else { 1.0 };
        let suggest = (f64::from(f32::EPSILON) * 0.5 * far_s * far_s / tol).min(0.5 * near_s);
        let remedy = format!(
            "raise camera.near (now {near32:e}) towards {suggest:.3e}: the perspective depth buffer \
             resolves about 2^-24 z^2/near in eye depth"
        );
        let mode = scene.raster.depth;
        if window_depth(near_s, n, f) as f32 >= 1.0 {
            if mode == DepthMode::Standard {
                return Err(Error::invalid(
                    "camera.near",
                    near32,
                    format!(
                        "with camera.far = {far32:e} every surface (eye depth {near_s:.4e} to \
                         {far_s:.4e}) gets window depth 1.0 in the f32 depth buffer and loses to \
                         the cleared depth: nothing would be drawn; {remedy}, or set \
                         raster.depth = \"reversed-z\""
                    ),
                ));
            }
            warnings.push(format!(
                "warning: camera.near = {near32:e}: raster.depth = {} keeps visibility right, \
                 but every surface's f32 window depth is 1.0, so outputs that read depth \
                 (*_depth, parallax, remap, occlusion, sirds) see only background; {remedy}",
                mode.name()
            ));
            return Ok(warnings);
        }
        let (r_near, r_far) = (
            resolution_of(mode, near_s, n, f),
            resolution_of(mode, far_s, n, f),
        );
        if r_far > tol {
            let switch = if mode == DepthMode::Standard {
                ", or set raster.depth = \"reversed-z\""
            } else {
                ""
            };
            warnings.push(format!(
                "warning: camera.near = {near32:e} is too close for the depth buffer \
                 (raster.depth = {}): surfaces closer than {r_near:.3e} in depth at the nearest \
                 surface (eye depth {near_s:.4}) and {r_far:.3e} at the farthest ({far_s:.4}) \
                 share a depth value and fight, or are lost; {remedy}{switch}",
                mode.name()
            ));
        }
    }
    let chroma = scene.outputs.iter().any(|o| {
        matches!(
            o,
            Output::ChromaDepth
                | Output::ChromaDepthLeft
                | Output::ChromaDepthRight
                | Output::ChromaDepthAnaglyph
        )
    });
    if chroma {
        let (d1, d2) = (scene.chromadepth.d1, scene.chromadepth.d2);
        let side = match (d1, d2) {
            (Some(d1), _) if z_hi < f64::from(d1) => Some(("nearer than chromadepth.d1", "red")),
            (_, Some(d2)) if z_lo > f64::from(d2) => Some(("beyond chromadepth.d2", "blue")),
            _ => None,
        };
        if let Some((where_, color)) = side {
            warnings.push(format!(
                "warning: the whole scene (eye depth {z_lo:.4} to {z_hi:.4}) lies {where_} \
                 (D1 = {}, D2 = {}): the ChromaDepth image is all {color}; set \
                 chromadepth.d1/d2 around the scene or leave them out for the automatic range",
                d1.map_or("auto".into(), |v| v.to_string()),
                d2.map_or("auto".into(), |v| v.to_string()),
            ));
        }
    }
    Ok(warnings)
}

/// The gap from `x` to the next larger f32 (`x ≥ 0`).
fn ulp_f32(x: f32) -> f32 {
    let x = x.abs();
    if x.is_finite() {
        f32::from_bits(x.to_bits() + 1) - x
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_resolution_follows_the_z_squared_over_near_law() {
        // n = 1, f = 100, z = 10: Δz ≈ ulp(z_w) · 99 · 100 / 100.
        let r = depth_resolution(10.0, 1.0, 100.0);
        let zw = window_depth(10.0, 1.0, 100.0);
        assert!((zw - 100.0 * 9.0 / (99.0 * 10.0)).abs() < 1e-12);
        assert!(r > 1e-6 && r < 1e-5, "{r}");
        // A hundred times nearer near plane: about a hundred times coarser.
        let r2 = depth_resolution(10.0, 0.01, 100.0);
        assert!(r2 / r > 50.0, "{r2} vs {r}");
    }

    #[test]
    fn ulp_of_one_million_is_a_sixteenth() {
        assert_eq!(ulp_f32(1.0e6), 0.0625);
    }
}
