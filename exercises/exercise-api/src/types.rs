//! The values stubs take and return, shared with the grader so both sides read the same JSON.

use glam::Mat4;
use serde::{Deserialize, Serialize};

use super::protocol::Answer;

/// A 3×3 color matrix, row-major as on the slides: `out[i] = Σ_j m[i][j] · in[j]`; rows are the
/// output R, G, B.
pub type ColorMatrix = [[f32; 3]; 3];

/// The pair of matrices of one anaglyph: `ML` for the left eye's color, `MR` for the right's.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AnaglyphMatrices {
    /// `ML`, applied to the left eye's color.
    pub left: ColorMatrix,
    /// `MR`, applied to the right eye's color.
    pub right: ColorMatrix,
}

/// Which modelview the shading sees (the exercise slides' "Effect on lighting").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Lighting {
    /// `view = T±·MV`, `projection = P±`: each eye lights from its own position.
    #[default]
    PerEye,
    /// `view = MV`, `projection = P±·T±`: both eyes shade as the cyclopean eye does.
    Cyclopic,
}

/// The view matrix of a camera at `eye` looking at `target` with `up` roughly up
/// (`gluLookAt`: right-handed, the camera looks down −Z).
pub fn look_at(eye: glam::Vec3, target: glam::Vec3, up: glam::Vec3) -> Mat4 {
    let f = (target - eye).normalize();
    let s = f.cross(up).normalize();
    let u = s.cross(f);
    Mat4::from_cols(
        glam::Vec4::new(s.x, u.x, -f.x, 0.0),
        glam::Vec4::new(s.y, u.y, -f.y, 0.0),
        glam::Vec4::new(s.z, u.z, -f.z, 0.0),
        glam::Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
    )
}

/// A mono camera's symmetric frustum plus the stereo rig (the exercise slides' parameters).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StereoSetup {
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
    /// Image width / height.
    pub aspect: f32,
    /// Near plane distance n (> 0).
    pub near: f32,
    /// Far plane distance f (> n).
    pub far: f32,
    /// Eye separation d: the eyes sit at x = −d/2 (left, index 0) and x = +d/2 (right, index 1).
    pub eye_separation: f32,
    /// Zero-parallax (screen) distance z0, between near and far.
    pub zero_parallax: f32,
}

/// The exercise slides' screen-relative stereo parameters ("Projection Matrix Stereo Case"): the
/// screen, of width w and height h, stands at the zero-parallax distance z0 in front of the eyes,
/// and the eye separation d is a fraction of the screen width, so the eyes sit at x = ∓½·d·w.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScreenSetup {
    /// Screen width w (in the scene's units, at the distance `zero_parallax`).
    pub width: f32,
    /// Screen height h (in the scene's units, at the distance `zero_parallax`).
    pub height: f32,
    /// Near plane distance n (> 0).
    pub near: f32,
    /// Far plane distance f (> n).
    pub far: f32,
    /// Zero-parallax (screen) distance z0 (> 0).
    pub zero_parallax: f32,
    /// Eye separation d as a fraction of the screen width: the eyes are d·w apart.
    pub eye_separation_fraction: f32,
}

/// The two matrices one eye renders with: `projection · view` is its MVP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeView {
    /// The modelview the shading happens in.
    pub view: Mat4,
    /// The projection completing it.
    pub projection: Mat4,
}

/// Flattens as `view` then `projection`, each column-major.
impl Answer for EyeView {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.view.flatten(out);
        self.projection.flatten(out);
    }
}

/// The four anaglyph kinds of the exercise slides (after 3dtv.at's comparison).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AnaglyphKind {
    /// True anaglyph: left luminance to red, right luminance to blue.
    True,
    /// Gray anaglyph: left luminance to red, right luminance to green and blue.
    Gray,
    /// Color anaglyph: left red, right green and blue.
    Color,
    /// Half-color anaglyph: left luminance to red, right green and blue.
    HalfColor,
}

impl AnaglyphKind {
    /// All four, in the exercise slides' order.
    pub const ALL: [AnaglyphKind; 4] = [
        AnaglyphKind::True,
        AnaglyphKind::Gray,
        AnaglyphKind::Color,
        AnaglyphKind::HalfColor,
    ];
}

/// Flattens as `left` then `right`, each row by row (`m[row][column]`, rows are the output
/// R, G, B, as on the slides).
impl Answer for AnaglyphMatrices {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.left.flatten(out);
        self.right.flatten(out);
    }
}

/// The SIRDS paper's viewing geometry for a scan line, in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SirdsGeometry {
    /// Distance a between the eyes.
    pub eye_distance: f32,
    /// Distance f from the eyes to the image plane.
    pub focal_length: f32,
}

/// What one SIRDS scan line needs: the SIRDS paper's eye geometry and the depth range the nearness
/// values span, all in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SirdsSetup {
    /// Distance a between the eyes.
    pub eye_distance: f32,
    /// Distance f from the eyes to the image plane.
    pub focal_length: f32,
    /// Depth behind the image plane of nearness 1 (the front of the range).
    pub depth_near: f32,
    /// Depth behind the image plane of nearness 0 (the background plane).
    pub depth_far: f32,
}

/// A `width`×`height` texture stored row by row from the TOP row, as a framebuffer and a PNG
/// store it: texel (x, y) is `texels[y · width + x]`, y = 0 is the top row. Texture
/// coordinates are OpenGL's: v = 0 at the BOTTOM row, so pixel (x, y)'s center is at
/// `u = (x + ½)/width`, `v = 1 − (y + ½)/height`, and nearest filtering fetches texel
/// `(⌊u · width⌋, ⌊(1 − v) · height⌋)` when that lies inside the image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Texture<T> {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width · height` texels, top row first.
    pub texels: Vec<T>,
}

impl<T: Copy> Texture<T> {
    /// A texture of `width`×`height` texels, all `fill`.
    pub fn new(width: usize, height: usize, fill: T) -> Texture<T> {
        Texture {
            width,
            height,
            texels: vec![fill; width * height],
        }
    }

    /// Texel (x, y), y = 0 the top row. Panics outside the texture (as an out-of-bounds index
    /// does).
    pub fn get(&self, x: usize, y: usize) -> T {
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside a {}×{} texture",
            self.width,
            self.height
        );
        self.texels[y * self.width + x]
    }

    /// Sets texel (x, y). Panics outside the texture.
    pub fn set(&mut self, x: usize, y: usize, value: T) {
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside a {}×{} texture",
            self.width,
            self.height
        );
        self.texels[y * self.width + x] = value;
    }
}

/// Flattens the texels, top row first (the size is not part of the answer: a texture of the
/// wrong size has the wrong number of numbers).
impl<T: Answer> Answer for Texture<T> {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.texels.flatten(out);
    }
}
