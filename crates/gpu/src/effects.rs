//! The finalize effects in WGSL: the anaglyph family, parallax color, remap and the
//! visibility/occlusion classes, each a [`FullscreenPass`] mirroring its CPU function in
//! `stereolab-core`'s `effects`. They take framebuffers as input, so feeding them the CPU path's eye
//! framebuffers compares the effect alone, apart from rasterization.
//!
//! Every number comes from the CPU modules (matrices from [`AnaglyphKind::matrices`], rig values
//! from [`ParallaxRig`], colors from `occlusion`, the tolerance from
//! [`DEPTH_PRECISION`]); the shaders hold formulas only.

use glam::{DMat4, Mat4};
use image::RgbaImage;

use stereolab_core::{
    AnaglyphKind, AnaglyphOptions, DEPTH_PRECISION, Error, Framebuffer, OCCLUSION_BACKGROUND_COLOR,
    OCCLUSION_FARTHER_COLOR, OCCLUSION_OCCLUDED_COLOR, OCCLUSION_OUT_OF_VIEW_COLOR,
    PARALLAX_BACKGROUND, ParallaxRig, Result, check_same_size,
};

use super::device::GpuRenderer;
use super::fullscreen::FullscreenPass;

/// The mirror of `anaglyph::anaglyph`.
const ANAGLYPH_WGSL: &str = concat!(
    include_str!("shaders/anaglyph_mix.wgsl"),
    include_str!("shaders/anaglyph.wgsl")
);
/// The mirror of `parallax::parallax_color` over `parallax_pixels`.
const PARALLAX_WGSL: &str = include_str!("shaders/parallax.wgsl");
/// The mirror of `remap_color` and `occlusion_image` (`Precision::F32Composed`).
const REMAP_WGSL: &str = include_str!("shaders/remap.wgsl");

/// The compiled finalize passes. Build once, run on any framebuffers.
pub struct GpuFinalize {
    /// The anaglyph on stored values, and in linear light (`LINEAR_LIGHT` false and true).
    anaglyph: [FullscreenPass; 2],
    parallax: FullscreenPass,
    pub(super) remap: FullscreenPass,
}

/// An 8-bit color as the shaders' 0..1 floats.
fn unit_color(c: [u8; 4]) -> [f32; 4] {
    c.map(|v| v as f32 / 255.0)
}

/// A framebuffer's color as an image.
fn image_of(fb: &Framebuffer) -> RgbaImage {
    fb.to_rgba_image()
}

/// The nearest and farthest window depth of the drawn pixels (as `occlusion::depth_extremes`):
/// a reduction over the input, done on the host.
fn depth_extremes(fb: &Framebuffer) -> (f32, f32) {
    fb.depth()
        .iter()
        .filter(|d| **d < 1.0)
        .fold((1.0f32, 0.0f32), |(lo, hi), d| (lo.min(*d), hi.max(*d)))
}

impl GpuFinalize {
    /// Compiles the passes.
    ///
    /// # Errors
    /// A shader that does not compile or validate (naga's message).
    pub fn new(r: &GpuRenderer) -> Result<GpuFinalize> {
        Ok(GpuFinalize {
            anaglyph: [anaglyph_pass(r, false)?, anaglyph_pass(r, true)?],
            parallax: FullscreenPass::new(r, "parallax.wgsl", PARALLAX_WGSL, 1)?,
            remap: FullscreenPass::new_color_only(r, "remap.wgsl", REMAP_WGSL, 2)?,
        })
    }

    /// The anaglyph of two eyes, as [`anaglyph::anaglyph`](stereolab_core::anaglyph):
    /// `clamp(ML · left + MR · right)` on stored values or in linear light, eyes swapped on
    /// request (the host swaps the inputs, as the CPU function does).
    ///
    /// # Errors
    /// Eyes of different sizes, `options.anti_rivalry` (Rendepth's gamma stage has no WGSL
    /// mirror: [`produce_wgsl`] leaves it to the CPU), or a GPU failure.
    pub fn anaglyph(
        &self,
        r: &GpuRenderer,
        left: &Framebuffer,
        right: &Framebuffer,
        kind: AnaglyphKind,
        options: AnaglyphOptions,
    ) -> Result<RgbaImage> {
        check_same_size(left, right)?;
        if !has_wgsl_anaglyph(options) {
            return Err(Error::invalid(
                "finalize.anti_rivalry",
                "true",
                "the WGSL anaglyph has no anti-rivalry stage; mix on the CPU",
            ));
        }
        let (left, right) = options.eyes(left, right);
        let params = anaglyph_params(kind);
        let pass = self.anaglyph_pass(options);
        Ok(image_of(&pass.run(r, &[left, right], &params)?))
    }

    /// The anaglyph pass for `options`' mode (stored values or linear light).
    pub(super) fn anaglyph_pass(&self, options: AnaglyphOptions) -> &FullscreenPass {
        &self.anaglyph[usize::from(options.linear_light)]
    }

    /// Parallax in pixels per pixel of `fb` on the GPU (NaN on the background), and the image
    /// area of the parallax color image (without the legend bar, which tiny-skia draws on the
    /// CPU). The color scale is the largest |p| of the GPU's own values (at least ½ pixel,
    /// as [`color_scale`](stereolab_core::parallax_color_scale)): a reduction done on the host
    /// between two runs of the pass.
    ///
    /// # Errors
    /// A size other than the rig's, a missing or bad depth buffer, or a GPU failure.
    pub fn parallax(
        &self,
        r: &GpuRenderer,
        fb: &Framebuffer,
        rig: &ParallaxRig,
    ) -> Result<(Vec<f32>, RgbaImage)> {
        if (fb.width(), fb.height()) != (rig.width, rig.height) {
            return Err(Error::invalid(
                "parallax framebuffer",
                format!("{}x{}", fb.width(), fb.height()),
                format!("the rig was resolved for {}x{}", rig.width, rig.height),
            ));
        }
        let (n, f, z0) = (rig.near, rig.far, rig.zero_parallax_distance);
        let k = rig.pixels_per_unit * rig.eye_separation;
        let a = k * (rig.balance - z0 / n);
        let b = k * z0 * (f - n) / (n * f);
        let params = |scale: f32| {
            let mut p = vec![a as f32, b as f32, scale, 0.0];
            p.extend(unit_color(PARALLAX_BACKGROUND));
            p
        };
        // The pass writes p(z) where a depth would be: read back as values, not depths.
        let first = self.parallax.run_readback(r, &[fb], &params(1.0))?;
        let scale = parallax_scale(&first.values);
        let colored = self.parallax.run_readback(r, &[fb], &params(scale))?;
        Ok((first.values, colored.to_rgba_image()))
    }

    /// `this` eye recolored from `other`, as [`remap_color`](stereolab_core::remap_color)
    /// with [`Precision::F32Composed`](stereolab_core::Precision::F32Composed).
    ///
    /// # Errors
    /// Different sizes, a missing or bad depth buffer, a singular MVP, or a GPU failure.
    pub fn remap_color(
        &self,
        r: &GpuRenderer,
        this: &Framebuffer,
        other: &Framebuffer,
        this_mvp: &Mat4,
        other_mvp: &Mat4,
    ) -> Result<RgbaImage> {
        check_same_size(this, other)?;
        let params = remap_params(this_mvp, other_mvp, 0.0, (0.0, 1.0))?;
        Ok(image_of(&self.remap.run(r, &[this, other], &params)?))
    }

    /// Both eyes' occlusion maps side by side, as
    /// [`occlusion_image`](stereolab_core::occlusion_image) with
    /// `Precision::F32Composed`. The depth extremes that scale the gray are a host reduction.
    ///
    /// # Errors
    /// Different sizes, a missing or bad depth buffer, a singular MVP, or a GPU failure.
    pub fn occlusion_image(
        &self,
        r: &GpuRenderer,
        left: &Framebuffer,
        right: &Framebuffer,
        mvps: [&Mat4; 2],
    ) -> Result<RgbaImage> {
        check_same_size(left, right)?;
        let eyes = [left, right];
        let (w, h) = (left.width(), left.height());
        let mut out = RgbaImage::new(2 * w, h);
        for k in 0..2 {
            let params = remap_params(mvps[k], mvps[1 - k], 1.0, depth_extremes(eyes[k]))?;
            let map = self.remap.run(r, &[eyes[k], eyes[1 - k]], &params)?;
            for y in 0..h {
                for x in 0..w {
                    out.put_pixel(k as u32 * w + x, y, image::Rgba(map.pixel(x, y)));
                }
            }
        }
        Ok(out)
    }
}

/// Whether anaglyph.wgsl mirrors the anaglyph with `options`: every kind and mode but
/// Rendepth's gamma stage (`anti_rivalry`), which the CPU applies to the GPU's eyes instead.
pub fn has_wgsl_anaglyph(options: AnaglyphOptions) -> bool {
    !options.anti_rivalry
}

/// anaglyph.wgsl's parameters: the kind's ML and MR rows.
pub(super) fn anaglyph_params(kind: AnaglyphKind) -> Vec<f32> {
    let m = kind.matrices();
    let mut params = Vec::with_capacity(24);
    for row in m.left.iter().chain(&m.right) {
        params.extend([row[0], row[1], row[2], 0.0]);
    }
    params
}

/// anaglyph.wgsl compiled for one mode: `LINEAR_LIGHT` is a constant of the shader, so the
/// stored-value pipeline has no sRGB curves in it at all (llvmpipe may run both sides of a
/// uniform branch under an execution mask).
///
/// # Errors
/// As [`FullscreenPass::new`].
fn anaglyph_pass(r: &GpuRenderer, linear_light: bool) -> Result<FullscreenPass> {
    let source = format!("const LINEAR_LIGHT: bool = {linear_light};\n{ANAGLYPH_WGSL}");
    let label = if linear_light {
        "anaglyph.wgsl (linear light)"
    } else {
        "anaglyph.wgsl"
    };
    FullscreenPass::new_color_only(r, label, &source, 2)
}

/// The output made by its WGSL mirror on the GPU, for the finalize outputs that have one
/// (anaglyphs, remap, occlusion, parallax color; the parallax legend is tiny-skia's, drawn on
/// the host at the GPU's color scale); `None` for every other output (layouts stay on the
/// CPU). `stereolab render --backend gpu` uses it.
///
/// # Errors
/// A missing eye pass, or the pass fails.
pub fn produce_wgsl(
    r: &GpuRenderer,
    fin: &GpuFinalize,
    output: stereolab::plan::Output,
    frame: &stereolab::render::Frame,
    scene: &stereolab::scene::Scene,
) -> Result<Option<RgbaImage>> {
    use stereolab::plan::{Output, View};
    let eye = |v: View| {
        frame.view(v).ok_or_else(|| {
            Error::internal(
                "plan",
                format!("{}: the {v:?} pass was not run", output.name()),
            )
        })
    };
    let mvps = [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp];
    Ok(Some(match output {
        // Rendepth's gamma stage has no WGSL mirror: the CPU mixes the GPU's eyes.
        Output::Anaglyph(_) if !has_wgsl_anaglyph(scene.finalize) => return Ok(None),
        Output::Anaglyph(kind) => {
            fin.anaglyph(r, eye(View::Left)?, eye(View::Right)?, kind, scene.finalize)?
        }
        Output::RemapLeft => {
            fin.remap_color(r, eye(View::Left)?, eye(View::Right)?, mvps[0], mvps[1])?
        }
        Output::RemapRight => {
            fin.remap_color(r, eye(View::Right)?, eye(View::Left)?, mvps[1], mvps[0])?
        }
        Output::Occlusion => fin.occlusion_image(r, eye(View::Left)?, eye(View::Right)?, mvps)?,
        Output::Parallax => {
            let left = eye(View::Left)?;
            let (values, area) = fin.parallax(r, left, &scene.parallax_rig()?)?;
            // The same scale the pass used.
            let scale = f64::from(parallax_scale(&values));
            let legend = stereolab_core::draw_legend(left.width(), scale, &|p| {
                stereolab_core::parallax_color(p, scale)
            })?;
            let mut bytes = area.into_raw();
            // The window violations, marked on the host from the GPU's own values.
            let map: Vec<Option<f64>> = values
                .iter()
                .map(|v| (!v.is_nan()).then_some(f64::from(*v)))
                .collect();
            let marks = stereolab_core::window_violation_marks(&map, left.width(), left.height());
            for i in marks {
                bytes[4 * i..4 * i + 4].copy_from_slice(&stereolab_core::PARALLAX_VIOLATION_COLOR);
            }
            bytes.extend_from_slice(legend.data());
            RgbaImage::from_raw(left.width(), left.height() + legend.height(), bytes)
                .ok_or_else(|| Error::internal("parallax", "image and legend size mismatch"))?
        }
        _ => return Ok(None),
    }))
}

/// The parallax color scale from the GPU's own parallax values (NaN on the background): the
/// largest |p|, at least half a pixel, as
/// [`color_scale`](stereolab_core::parallax_color_scale) on the CPU.
fn parallax_scale(values: &[f32]) -> f32 {
    values
        .iter()
        .filter(|p| !p.is_nan())
        .fold(0.5f32, |m, p| m.max(p.abs()))
}

/// remap.wgsl's parameters: `MVP_other · MVP_this⁻¹` composed in f64 and rounded to f32 (as
/// `Remapper` does for `F32Composed`), the mode, the tolerance, the depth extremes, the colors.
///
/// # Errors
/// `this_mvp` not finite or singular.
pub(super) fn remap_params(
    this_mvp: &Mat4,
    other_mvp: &Mat4,
    mode: f32,
    (near, far): (f32, f32),
) -> Result<Vec<f32>> {
    let this64 = this_mvp.as_dmat4();
    let det = this64.determinant();
    if !(det.is_finite() && det != 0.0 && other_mvp.is_finite()) {
        return Err(Error::invalid(
            "eye matrices",
            format!("det(MVP) = {det}"),
            "the eye's MVP must be finite and invertible to unproject its pixels",
        ));
    }
    let composed: DMat4 = other_mvp.as_dmat4() * this64.inverse();
    let mut p: Vec<f32> = composed.as_mat4().to_cols_array().to_vec();
    p.extend([mode, DEPTH_PRECISION as f32, near, far]);
    for c in [
        OCCLUSION_BACKGROUND_COLOR,
        OCCLUSION_OUT_OF_VIEW_COLOR,
        OCCLUSION_OCCLUDED_COLOR,
        OCCLUSION_FARTHER_COLOR,
    ] {
        p.extend(unit_color(c));
    }
    Ok(p)
}
