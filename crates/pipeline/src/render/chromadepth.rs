//! The ChromaDepth pass: one center-eye rasterization whose fragments take their color from the
//! ramp at the eye-linear texture coordinate `s`.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::scene::{Object, Scene};
use stereolab_core::{
    ChromaDepthSettings, EyeMatrices, Fragment, Framebuffer, Ramp, RampSampling, RasterStats,
    Result, Shader, Texgen, TexgenMode, Varyings, auto_range, rasterize, to_rgba8,
};

/// The fragment program of one object in the ChromaDepth pass.
///
/// Per-vertex texgen (OpenGL's `GL_EYE_LINEAR`): `s` is computed at each vertex and interpolated
/// as a varying, perspective-correctly unless the pass asks for affine interpolation. Because
/// `s` is affine in eye space, perspective-correct interpolation reproduces it exactly (up to
/// rounding) on every planar triangle; affine interpolation bends it on slanted triangles.
///
/// Per-pixel texgen: `s` from the fragment's own eye depth, recovered from its window depth by
/// inverting the projection: `z_ndc = 2 z_win − 1`, `z_eye = −P₃₄ / (z_ndc + P₃₃)` (column-major
/// `P[3][2]`, `P[2][2]` of the OpenGL frustum), then `s = C z_eye + D`. Independent of how
/// varyings are interpolated.
pub struct ChromaDepthShader<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    modelview: Mat4,
    normal_matrix: Mat3,
    projection: Mat4,
    texgen: Texgen,
    ramp: &'a Ramp,
    sampling: RampSampling,
    mode: TexgenMode,
    /// `(light position in eye space, ambient)` for lit ChromaDepth.
    lighting: Option<(Vec3, f32)>,
}

impl<'a> ChromaDepthShader<'a> {
    /// The program for `object` seen with `m` (the center eye): the texgen plane is applied to
    /// `m.view · object.model · p`, so the object's transform moves it through the ramp.
    pub fn new(
        object: &'a Object,
        m: &EyeMatrices,
        texgen: Texgen,
        ramp: &'a Ramp,
        settings: &ChromaDepthSettings,
        scene: &Scene,
    ) -> Self {
        let modelview = m.view * object.model;
        ChromaDepthShader {
            positions: &object.mesh.positions,
            normals: &object.mesh.normals,
            modelview,
            normal_matrix: Mat3::from_mat4(modelview).inverse().transpose(),
            projection: m.projection,
            texgen,
            ramp,
            sampling: settings.sampling,
            mode: settings.texgen,
            lighting: settings.lit.then(|| {
                (
                    m.view.transform_point3(scene.light.position),
                    scene.light.ambient,
                )
            }),
        }
    }

    /// The texture coordinate of a fragment, before clamping.
    #[inline]
    pub(crate) fn s_at(&self, f: &Fragment) -> f32 {
        match self.mode {
            TexgenMode::PerVertex => f.varyings[0],
            TexgenMode::PerPixel => {
                let z_ndc = 2.0 * f.depth - 1.0;
                let z_eye = -self.projection.w_axis.z / (z_ndc + self.projection.z_axis.z);
                self.texgen.plane.z * z_eye + self.texgen.plane.w
            }
        }
    }
}

impl Shader for ChromaDepthShader<'_> {
    fn varying_count(&self) -> usize {
        match (self.lighting.is_some(), self.mode) {
            (true, _) => 7,
            (false, TexgenMode::PerVertex) => 1,
            (false, TexgenMode::PerPixel) => 0,
        }
    }

    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        let i = index as usize;
        let p_eye = self.modelview.transform_point3(self.positions[i]);
        out[0] = self.texgen.s(p_eye);
        if self.lighting.is_some() {
            out[1..4].copy_from_slice(&p_eye.to_array());
            out[4..7].copy_from_slice(&(self.normal_matrix * self.normals[i]).to_array());
        }
        self.projection * p_eye.extend(1.0)
    }

    #[inline]
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let color = self.ramp.sample(self.s_at(f), self.sampling);
        let Some((light_eye, ambient)) = self.lighting else {
            return Some(to_rgba8(color));
        };
        // Lit ChromaDepth: scale the ramp color by a gray diffuse intensity. A uniform scale of
        // R, G, B keeps the hue (and so the depth the glasses show); no specular, whose white
        // would wash the hue out.
        let v = f.varyings;
        let p = Vec3::new(v[1], v[2], v[3]);
        let mut n = Vec3::new(v[4], v[5], v[6]).normalize_or_zero();
        if !f.front_facing {
            n = -n;
        }
        let diffuse = n.dot((light_eye - p).normalize_or_zero()).max(0.0);
        Some(to_rgba8(color * (ambient + (1.0 - ambient) * diffuse)))
    }
}

/// Records `s` instead of a color: the f32's bytes go into the RGBA8 target, so the depth test
/// decides which surface's `s` survives, exactly as in the colored pass.
struct RecordS<'a>(ChromaDepthShader<'a>);

impl Shader for RecordS<'_> {
    fn varying_count(&self) -> usize {
        self.0.varying_count()
    }
    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        self.0.vertex(index, out)
    }

    #[inline]
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        Some(self.0.s_at(f).to_le_bytes())
    }
}

/// D1/D2 for the pass: the scene's values where given, the ChromaDepth article's bounding sphere for the rest
/// (see [`auto_range`]), checked by [`Texgen::from_range`].
///
/// # Errors
/// As [`auto_range`] and [`Texgen::from_range`].
pub fn resolve_texgen(
    scene: &Scene,
    m: &EyeMatrices,
    settings: &ChromaDepthSettings,
) -> Result<Texgen> {
    let (d1, d2) = match (settings.d1, settings.d2) {
        (Some(d1), Some(d2)) => (d1, d2),
        (d1, d2) => {
            let points: Vec<Vec3> = scene.world_points().collect();
            let auto = auto_range(&points, m.view, m.frustum[4], m.frustum[5])?;
            (d1.unwrap_or(auto.0), d2.unwrap_or(auto.1))
        }
    };
    Texgen::from_range(d1, d2)
}

/// Renders the ChromaDepth pass of `scene` from `m` (the center eye) with the scene's settings.
///
/// # Errors
/// As [`render_center_with`].
pub(crate) fn render_center(scene: &Scene, m: &EyeMatrices) -> Result<(Framebuffer, RasterStats)> {
    render_center_with(scene, m, &scene.chromadepth)
}

/// Renders the ChromaDepth pass with explicit settings (the benchmark varies them).
///
/// # Errors
/// Bad D1/D2 (see [`resolve_texgen`]), a bad texel count, or an image size refused by
/// [`Framebuffer::new`].
pub fn render_center_with(
    scene: &Scene,
    m: &EyeMatrices,
    settings: &ChromaDepthSettings,
) -> Result<(Framebuffer, RasterStats)> {
    let texgen = resolve_texgen(scene, m, settings)?;
    let ramp = Ramp::new(settings.ramp, settings.texels)?;
    let mut fb = Framebuffer::new(scene.width, scene.height, scene.background)?;
    let stats = draw_objects(scene, m, texgen, &ramp, settings, &mut fb, |s| s);
    Ok((fb, stats))
}

/// The texture coordinate `s` (unclamped) of every pixel the pass covers, row-major; NaN where
/// no surface is. For comparing texgen modes without the ramp's quantization.
///
/// # Errors
/// As [`render_center_with`].
pub fn texgen_map(
    scene: &Scene,
    m: &EyeMatrices,
    settings: &ChromaDepthSettings,
) -> Result<Vec<f32>> {
    let texgen = resolve_texgen(scene, m, settings)?;
    let ramp = Ramp::new(settings.ramp, settings.texels)?;
    // 0xFFFFFFFF is a NaN bit pattern: uncovered pixels read back as NaN.
    let mut fb = Framebuffer::new(scene.width, scene.height, [0xFF; 4])?;
    draw_objects(scene, m, texgen, &ramp, settings, &mut fb, RecordS);
    Ok(fb.color().iter().map(|c| f32::from_le_bytes(*c)).collect())
}

/// Rasterizes every object with the ChromaDepth program, wrapped by `wrap`.
fn draw_objects<'a, S: Shader>(
    scene: &'a Scene,
    m: &EyeMatrices,
    texgen: Texgen,
    ramp: &'a Ramp,
    settings: &ChromaDepthSettings,
    fb: &mut Framebuffer,
    wrap: impl Fn(ChromaDepthShader<'a>) -> S,
) -> RasterStats {
    let mut total = RasterStats::default();
    for o in &scene.objects {
        let shader = wrap(ChromaDepthShader::new(o, m, texgen, ramp, settings, scene));
        let s = rasterize(
            &o.mesh.triangles,
            o.mesh.positions.len(),
            &shader,
            fb,
            &scene.raster,
        );
        total.triangles += s.triangles;
        total.non_finite += s.non_finite;
        total.clipped += s.clipped;
        total.clip_range.merge(s.clip_range);
        total.culled += s.culled;
        total.fragments += s.fragments;
    }
    total
}
