//! The programmable stages as a trait, so a pass is `rasterize(triangles, &shader, &mut fb)`,
//! and the default Blinn-Phong shader.

use glam::{Mat3, Mat4, Vec3, Vec4};

/// How many f32 varyings a vertex can hand to the fragment stage.
pub const MAX_VARYINGS: usize = 8;

/// The varyings of one vertex or fragment; a shader uses the first [`Shader::varying_count`].
pub type Varyings = [f32; MAX_VARYINGS];

/// What the fragment stage sees of one covered, depth-passing pixel.
#[derive(Clone, Copy, Debug)]
pub struct Fragment<'a> {
    /// Pixel column.
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// Window depth in [0, 1].
    pub depth: f32,
    /// Interpolated varyings (perspective-correct unless the pass asked for affine).
    pub varyings: &'a Varyings,
    /// Counter-clockwise in NDC (OpenGL's default front face).
    pub front_facing: bool,
}

/// A vertex + fragment program pair, like a GL program object.
pub trait Shader: Sync {
    /// Number of varyings `vertex` writes (≤ [`MAX_VARYINGS`]); only these are interpolated.
    fn varying_count(&self) -> usize {
        0
    }
    /// Vertex stage: returns the clip-space position of vertex `index`, writes its varyings.
    fn vertex(&self, index: u32, varyings: &mut Varyings) -> Vec4;
    /// Fragment stage: the color, or `None` to discard (then neither color nor depth is written).
    fn fragment(&self, fragment: &Fragment) -> Option<[u8; 4]>;
    /// `false` for depth-only passes: the fragment stage is skipped entirely.
    fn writes_color(&self) -> bool {
        true
    }
}

/// A point light and the ambient term, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Light position (world).
    pub position: Vec3,
    /// Ambient intensity, 0..1.
    pub ambient: f32,
    /// Specular intensity, 0..1.
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Default for Light {
    fn default() -> Self {
        Light {
            position: Vec3::new(5.0, 8.0, 10.0),
            ambient: 0.15,
            specular: 0.35,
            shininess: 32.0,
        }
    }
}

/// Blinn-Phong in eye space: the modelview it is given decides whether each eye lights from its
/// own position (per-eye) or both from the cyclopean eye (cyclopic), the exercise slides.
pub struct BlinnPhong<'a> {
    positions: &'a [Vec3],
    normals: &'a [Vec3],
    /// view · model.
    modelview: Mat4,
    /// Inverse transpose of the modelview's linear part: normals transform by it.
    normal_matrix: Mat3,
    projection: Mat4,
    color: Vec3,
    light: Light,
    /// The light position in the lighting eye's space.
    light_eye: Vec3,
}

impl<'a> BlinnPhong<'a> {
    /// A Blinn-Phong program for one object seen by one eye: `view` is the modelview the eye
    /// lights in, `projection` completes it so that `projection · view · model` is the eye's MVP.
    pub fn new(
        positions: &'a [Vec3],
        normals: &'a [Vec3],
        model: Mat4,
        view: Mat4,
        projection: Mat4,
        color: Vec3,
        light: Light,
    ) -> Self {
        let modelview = view * model;
        BlinnPhong {
            positions,
            normals,
            modelview,
            normal_matrix: Mat3::from_mat4(modelview).inverse().transpose(),
            projection,
            color,
            light,
            light_eye: view.transform_point3(light.position),
        }
    }

    /// `view · model`: object space to the lighting eye's space.
    pub fn modelview(&self) -> Mat4 {
        self.modelview
    }

    /// Inverse transpose of the modelview's linear part (normals go through it).
    pub fn normal_matrix(&self) -> Mat3 {
        self.normal_matrix
    }

    /// The projection that completes the modelview (OpenGL clip space).
    pub fn projection(&self) -> Mat4 {
        self.projection
    }

    /// The light position in the lighting eye's space.
    pub fn light_eye(&self) -> Vec3 {
        self.light_eye
    }

    /// The material color, 0..1.
    pub fn color(&self) -> Vec3 {
        self.color
    }

    /// The light's ambient, specular and shininess terms.
    pub fn light(&self) -> Light {
        self.light
    }
}

impl Shader for BlinnPhong<'_> {
    fn varying_count(&self) -> usize {
        6
    }

    fn vertex(&self, index: u32, out: &mut Varyings) -> Vec4 {
        let i = index as usize;
        let p_eye = self.modelview.transform_point3(self.positions[i]);
        let n_eye = self.normal_matrix * self.normals[i];
        out[..3].copy_from_slice(&p_eye.to_array());
        out[3..6].copy_from_slice(&n_eye.to_array());
        self.projection * p_eye.extend(1.0)
    }

    #[inline]
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let v = f.varyings;
        let p = Vec3::new(v[0], v[1], v[2]);
        let mut n = Vec3::new(v[3], v[4], v[5]).normalize_or_zero();
        if !f.front_facing {
            n = -n; // two-sided lighting: back faces lit as seen
        }
        let l = (self.light_eye - p).normalize_or_zero();
        let h = (l + (-p).normalize_or_zero()).normalize_or_zero();
        let diffuse = n.dot(l).max(0.0);
        let spec = if diffuse > 0.0 {
            specular_power(n.dot(h).max(0.0), self.light.shininess) * self.light.specular
        } else {
            0.0
        };
        let c = self.color * (self.light.ambient + (1.0 - self.light.ambient) * diffuse)
            + Vec3::splat(spec);
        Some(to_rgba8(c))
    }
}

/// `x^shininess`: by repeated squaring when the exponent is a whole number up to 1024 (the
/// usual case, several times cheaper than `powf` and within a few ulps of it), `powf` otherwise.
#[inline]
pub fn specular_power(x: f32, shininess: f32) -> f32 {
    // A whole number in range, checked with casts (`fract` is a libm call on baseline x86-64).
    if (0.0..=1024.0).contains(&shininess) && (shininess as u32) as f32 == shininess {
        powi(x, shininess as u32)
    } else {
        x.powf(shininess)
    }
}

/// `x^n` by repeated squaring, the same multiplications in the same order as `f32::powi`
/// (compiler-builtins' `__powisf2`), so the same bits, but inlined instead of a library call
/// per fragment.
#[inline]
pub fn powi(mut x: f32, mut n: u32) -> f32 {
    let mut r = 1.0f32;
    loop {
        if n & 1 != 0 {
            r *= x;
        }
        n >>= 1;
        if n == 0 {
            return r;
        }
        x *= x;
    }
}

/// Converts a 0..1 color to RGBA8 (alpha 255), rounding to nearest.
#[inline]
pub fn to_rgba8(c: Vec3) -> [u8; 4] {
    let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    [q(c.x), q(c.y), q(c.z), 255]
}

/// Depth only: no fragment stage at all (SIRDS and depth outputs need nothing else).
pub struct DepthOnly<'a> {
    /// Object positions.
    pub positions: &'a [Vec3],
    /// Full model-view-projection.
    pub mvp: Mat4,
}

impl Shader for DepthOnly<'_> {
    fn vertex(&self, index: u32, _: &mut Varyings) -> Vec4 {
        self.mvp * self.positions[index as usize].extend(1.0)
    }
    fn fragment(&self, _: &Fragment) -> Option<[u8; 4]> {
        None
    }
    fn writes_color(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inlined_powi_gives_the_bits_of_std_powi() {
        for n in 0..=1024u32 {
            for k in 0..200 {
                let x = k as f32 / 199.0 * 1.01;
                assert_eq!(
                    powi(x, n).to_bits(),
                    x.powi(std::hint::black_box(n as i32)).to_bits(),
                    "x = {x}, n = {n}"
                );
            }
        }
    }

    #[test]
    fn specular_power_takes_powf_for_fractional_or_huge_exponents() {
        assert_eq!(specular_power(0.5, 2.5), 0.5f32.powf(2.5));
        assert_eq!(specular_power(0.9, 2000.0), 0.9f32.powf(2000.0));
        // Against the runtime library call (a constant exponent would be folded at compile
        // time by another method, which can differ in the last bit).
        let n = std::hint::black_box(32);
        assert_eq!(
            specular_power(0.9, 32.0).to_bits(),
            0.9f32.powi(n).to_bits()
        );
    }
}
