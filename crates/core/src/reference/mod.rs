//! The f64 reference: the same rig and the same rules as the renderer, in double precision and
//! written to be read, not to be fast. The hard cases (`tests/hard_cases.rs`) and the depth
//! benchmark (`stereolab bench --only depth`) measure the f32 pipeline against it.
//!
//! - [`frustum`], [`look_at`] and [`eye`] are the renderer's `math::frustum`, `math::look_at`
//!   and the stereo rig's eye matrices (off-axis, toe-in, parallel; the StereoGraphics guide's
//!   frustum shift, the SGI course notes' toe-in look-at) in f64, from the same scene numbers.
//! - [`visible`] is visibility without a depth buffer's rounding: each triangle clipped against
//!   the six planes of the frustum in homogeneous coordinates (so triangles crossing `w = 0`
//!   are cut where they cross the near plane), divided, mapped to the window; a pixel is
//!   covered when its centre lies inside (no subpixel snapping), and the surface that wins is
//!   the one with the smallest eye depth `w`, computed from `1/w` interpolated linearly in
//!   screen space (exact for a plane seen in perspective).
//! - Where the rules themselves leave the answer open, the pixel is marked *ambiguous* and not
//!   counted: its centre lies within [`EDGE_MARGIN`] pixels of a triangle's edge (the renderer
//!   snaps vertices to 1/256 pixel, so either answer is right there), or two different surfaces
//!   there are within [`TIE`] of each other in eye depth (a true tie).

use glam::{DMat4, DVec3, DVec4, Mat4, Vec3, Vec4};

use crate::eye::Eye;
use crate::framebuffer::Framebuffer;
use crate::math::{Camera, CameraMode, StereoRig, ZeroParallax};
use crate::shade::{Fragment, Shader, Varyings};

/// A pixel centre nearer than this to a triangle edge (in pixels) is ambiguous: twice the
/// renderer's vertex snapping step of 1/256 pixel.
pub const EDGE_MARGIN: f64 = 2.0 / 256.0;

/// Two surfaces closer than this relative eye-depth difference at a pixel tie.
pub const TIE: f64 = 1e-12;

/// `P_frustum(l, r, b, t, n, f)` (OpenGL's `glFrustum`) in f64.
pub fn frustum(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
        DVec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
        DVec4::new(
            (r + l) / (r - l),
            (t + b) / (t - b),
            (n + f) / (n - f),
            -1.0,
        ),
        DVec4::new(0.0, 0.0, 2.0 * n * f / (n - f), 0.0),
    )
}

/// Right-handed look-at (`gluLookAt`) in f64.
pub fn look_at(eye: DVec3, target: DVec3, up: DVec3) -> DMat4 {
    let f = (target - eye).normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    DMat4::from_cols(
        DVec4::new(s.x, u.x, -f.x, 0.0),
        DVec4::new(s.y, u.y, -f.y, 0.0),
        DVec4::new(s.z, u.z, -f.z, 0.0),
        DVec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// One eye's world → clip matrix in f64. `separation` is the resolved eye separation and `z0`
/// the zero-parallax distance (the rig's `resolve`, which only reads the scene's numbers); the
/// rest is the rig's `eye` in f64.
pub fn eye(
    rig: &StereoRig,
    camera: &Camera,
    aspect: f64,
    separation: f64,
    z0: f64,
    eye: Eye,
) -> DMat4 {
    let side = f64::from(eye.sign());
    let v = |a: [f32; 3]| DVec3::from(a.map(f64::from));
    let mv = look_at(v(camera.eye), v(camera.target), v(camera.up));
    let (n, f) = (f64::from(camera.near), f64::from(camera.far));
    let h = n * (f64::from(camera.fov_y).to_radians() * 0.5).tan();
    let w = h * aspect;
    let half = 0.5 * separation;
    let t = DMat4::from_translation(DVec3::new(-side * half, 0.0, 0.0));
    let (view, shift) = match rig.mode {
        // Image-shift moves the parallel rig's image sideways; unrounded, that move is exactly
        // off-axis's frustum shift (the renderer rounds it to whole pixels, its `ImageShift`).
        CameraMode::OffAxis | CameraMode::ImageShift => {
            (t * mv, -side * half * f64::from(rig.user_balance) * n / z0)
        }
        CameraMode::Parallel => (t * mv, 0.0),
        CameraMode::ToeIn => {
            let inv = mv.inverse();
            let eye = inv.transform_point3(DVec3::new(side * half, 0.0, 0.0));
            let fusion = inv.transform_point3(DVec3::new(0.0, 0.0, -z0));
            let up = inv.transform_vector3(DVec3::Y);
            (look_at(eye, fusion, up), 0.0)
        }
    };
    frustum(-w + shift, w + shift, -h, h, n, f) * view
}

/// The zero-parallax distance of `rig` for `camera`, in f64 (the rig's `resolve`).
pub fn zero_parallax(rig: &StereoRig, camera: &Camera) -> f64 {
    match rig.zero_parallax {
        ZeroParallax::Distance(z) => f64::from(z),
        ZeroParallax::Fraction(t) => {
            let (n, f) = (f64::from(camera.near), f64::from(camera.far));
            n + f64::from(t) * (f - n)
        }
    }
}

/// What the reference sees at each pixel (row-major).
#[derive(Clone, Debug)]
pub struct Visible {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Index of the triangle that wins the pixel, `None` for the background.
    pub id: Vec<Option<u32>>,
    /// Its eye depth `w` (infinity for the background).
    pub eye_depth: Vec<f64>,
    /// Whether the rules leave the pixel open (module docs).
    pub ambiguous: Vec<bool>,
}

/// Distance from `p` to the six clip planes (inside ≥ 0), as the renderer's clipper orders them.
fn plane_distance(p: DVec4, plane: usize) -> f64 {
    match plane {
        0 => p.w + p.x,
        1 => p.w - p.x,
        2 => p.w + p.y,
        3 => p.w - p.y,
        4 => p.w + p.z,
        _ => p.w - p.z,
    }
}

/// Sutherland–Hodgman against the six planes, in f64; each new vertex is set exactly onto its
/// plane (`x = −w` on `w + x = 0`, ...), where `w ± x` may have lost `w` (coordinates past
/// `2⁵³·w`).
fn clip(tri: [DVec4; 3]) -> Vec<DVec4> {
    let mut poly = tri.to_vec();
    for plane in 0..6 {
        let mut out = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let (da, db) = (plane_distance(a, plane), plane_distance(b, plane));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let mut p = a + (b - a) * (da / (da - db));
                let on = if plane.is_multiple_of(2) { -p.w } else { p.w };
                p[plane / 2] = on;
                out.push(p);
            }
        }
        poly = out;
        if poly.len() < 3 {
            return Vec::new();
        }
    }
    poly
}

/// The visible surface at every pixel of a `width`×`height` view of `triangles` (indices into
/// `positions`, world space) through `mvp`, in f64 (module docs).
pub fn visible(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    mvp: &DMat4,
    width: u32,
    height: u32,
) -> Visible {
    let n = width as usize * height as usize;
    let mut id = vec![None; n];
    let mut eye_depth = vec![f64::INFINITY; n];
    let mut ambiguous = vec![false; n];
    // Every surface's eye depth at each pixel it covers, to find ties afterwards.
    let mut second = vec![f64::INFINITY; n];
    let (hw, hh) = (f64::from(width) * 0.5, f64::from(height) * 0.5);
    for (k, tri) in triangles.iter().enumerate() {
        let clip_pos = tri.map(|i| *mvp * positions[i as usize].extend(1.0));
        let poly = clip(clip_pos);
        // (window x, window y, 1/w) of each polygon vertex.
        let win: Vec<(f64, f64, f64)> = poly
            .iter()
            .map(|p| ((p.x / p.w) * hw + hw, (p.y / p.w) * -hh + hh, 1.0 / p.w))
            .collect();
        for j in 1..win.len().saturating_sub(1) {
            let t = [win[0], win[j], win[j + 1]];
            let area =
                (t[1].0 - t[0].0) * (t[2].1 - t[0].1) - (t[2].0 - t[0].0) * (t[1].1 - t[0].1);
            if area == 0.0 || !area.is_finite() {
                continue;
            }
            let x_lo = t.iter().map(|v| v.0).fold(f64::INFINITY, f64::min);
            let x_hi = t.iter().map(|v| v.0).fold(f64::NEG_INFINITY, f64::max);
            let y_lo = t.iter().map(|v| v.1).fold(f64::INFINITY, f64::min);
            let y_hi = t.iter().map(|v| v.1).fold(f64::NEG_INFINITY, f64::max);
            let px0 = ((x_lo - 1.0).floor().max(0.0)) as u32;
            let py0 = ((y_lo - 1.0).floor().max(0.0)) as u32;
            let px1 = ((x_hi + 1.0).ceil().min(f64::from(width) - 1.0)).max(0.0) as u32;
            let py1 = ((y_hi + 1.0).ceil().min(f64::from(height) - 1.0)).max(0.0) as u32;
            for py in py0..=py1 {
                for px in px0..=px1 {
                    let (sx, sy) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
                    // Signed distance of the sample to each edge, positive inside.
                    let mut dist = [0.0; 3];
                    let mut bary = [0.0; 3];
                    for e in 0..3 {
                        let (a, b) = (t[(e + 1) % 3], t[(e + 2) % 3]);
                        let cross = (b.0 - a.0) * (sy - a.1) - (b.1 - a.1) * (sx - a.0);
                        bary[e] = cross / area;
                        dist[e] = cross * area.signum() / (b.0 - a.0).hypot(b.1 - a.1);
                    }
                    let min = dist.iter().copied().fold(f64::INFINITY, f64::min);
                    if min > -EDGE_MARGIN && min < EDGE_MARGIN {
                        ambiguous[py as usize * width as usize + px as usize] = true;
                    }
                    if min < 0.0 {
                        continue;
                    }
                    let inv_w = bary[0] * t[0].2 + bary[1] * t[1].2 + bary[2] * t[2].2;
                    let w = 1.0 / inv_w;
                    let i = py as usize * width as usize + px as usize;
                    if id[i] == Some(k as u32) {
                        continue; // the other half of this triangle's clipped fan
                    }
                    if w < eye_depth[i] {
                        second[i] = eye_depth[i];
                        eye_depth[i] = w;
                        id[i] = Some(k as u32);
                    } else {
                        second[i] = second[i].min(w);
                    }
                }
            }
        }
    }
    for i in 0..n {
        if second[i].is_finite() && (second[i] - eye_depth[i]) <= TIE * eye_depth[i] {
            ambiguous[i] = true;
        }
    }
    Visible {
        width,
        height,
        id,
        eye_depth,
        ambiguous,
    }
}

/// A triangle soup: every triangle gets its own three vertices, so that a vertex stage can
/// tell triangles apart ([`IdShader`]).
pub fn soup(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    triangles
        .iter()
        .flat_map(|t| t.map(|i| positions[i as usize]))
        .collect()
}

/// The renderer's side of a comparison: draws each triangle of a [`soup`] in a color that
/// encodes its index (`index + 1` in red, green, blue; black is the background), so a pass
/// with any depth mode can be read back as "which triangle won each pixel".
pub struct IdShader<'a> {
    /// [`soup`] positions, three per triangle.
    pub positions: &'a [Vec3],
    /// World → clip, f32: what the renderer uses.
    pub mvp: Mat4,
}

impl Shader for IdShader<'_> {
    fn varying_count(&self) -> usize {
        1
    }
    fn vertex(&self, index: u32, var: &mut Varyings) -> Vec4 {
        var[0] = (index / 3) as f32;
        self.mvp * self.positions[index as usize].extend(1.0)
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let id = f.varyings[0].round() as u32 + 1;
        Some([(id >> 16) as u8, (id >> 8) as u8, id as u8, 255])
    }
}

/// The triangle index an [`IdShader`] pass drew at pixel `i`, `None` for the background.
pub fn drawn_id(fb: &Framebuffer, i: usize) -> Option<u32> {
    let [r, g, b, _] = fb.color[i];
    let id = (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b);
    id.checked_sub(1)
}

/// How a render differs from the reference, over the pixels the rules decide.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mismatch {
    /// Pixels the reference decides (not ambiguous).
    pub decided: usize,
    /// Of those, pixels the reference covers.
    pub covered: usize,
    /// Covered by the reference, background in the render: lost fragments.
    pub lost: usize,
    /// Covered by both, by another triangle in the render: z-fighting, a wrong winner.
    pub wrong: usize,
    /// Background in the reference, covered in the render.
    pub extra: usize,
}

impl Mismatch {
    /// Lost plus wrong plus extra pixels.
    pub fn total(&self) -> usize {
        self.lost + self.wrong + self.extra
    }
}

/// Compares an [`IdShader`] pass with the reference, pixel by pixel.
pub fn compare(fb: &Framebuffer, reference: &Visible) -> Mismatch {
    let mut m = Mismatch::default();
    for i in 0..reference.id.len() {
        if reference.ambiguous[i] {
            continue;
        }
        m.decided += 1;
        match (reference.id[i], drawn_id(fb, i)) {
            (Some(_), None) => {
                m.covered += 1;
                m.lost += 1;
            }
            (Some(a), Some(b)) => {
                m.covered += 1;
                m.wrong += (a != b) as usize;
            }
            (None, Some(_)) => m.extra += 1,
            (None, None) => {}
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The f64 matrices are the f32 ones, to f32 precision, on an ordinary view.
    #[test]
    fn f64_frustum_and_look_at_agree_with_the_renderers() {
        let p32 = crate::math::frustum(-0.3, 0.5, -0.4, 0.4, 1.0, 50.0);
        let p64 = frustum(-0.3, 0.5, -0.4, 0.4, 1.0, 50.0);
        let v32 = crate::math::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y);
        let v64 = look_at(DVec3::new(1.0, 2.0, 5.0), DVec3::ZERO, DVec3::Y);
        for (a, b) in [(p32, p64), (v32, v64)] {
            let d = (a.as_dmat4() - b).to_cols_array();
            assert!(d.iter().all(|x| x.abs() < 1e-6), "{d:?}");
        }
    }

    /// A square of two triangles straight on: every pixel inside is covered once by one of the
    /// two, the shared diagonal marks its pixels ambiguous, and the eye depth is the plane's.
    #[test]
    fn a_square_straight_on_is_covered_at_its_depth() {
        let p = [
            DVec3::new(-1.0, -1.0, -5.0),
            DVec3::new(1.0, -1.0, -5.0),
            DVec3::new(1.0, 1.0, -5.0),
            DVec3::new(-1.0, 1.0, -5.0),
        ];
        let mvp = frustum(-1.0, 1.0, -1.0, 1.0, 1.0, 10.0);
        let v = visible(&p, &[[0, 1, 2], [0, 2, 3]], &mvp, 20, 20);
        // The square spans NDC ±0.2: window 8..12.
        let covered = v.id.iter().filter(|i| i.is_some()).count();
        assert_eq!(covered, 16);
        for i in 0..400 {
            if v.id[i].is_some() {
                assert!((v.eye_depth[i] - 5.0).abs() < 1e-12);
            }
        }
        assert!(v.ambiguous.iter().any(|a| *a));
    }
}
