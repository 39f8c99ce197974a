//! The scene the image checks render, and what the reference renders of it.

use std::path::Path;

use glam::{Mat4, Vec3};

use crate::exercise::StereoSetup;
use stereolab::plan::Shading;
use stereolab::render::render_view;
use stereolab::scene::Scene;
use stereolab_core::{
    EyeMatrices, Framebuffer, Lighting, Result, Separation, StereoRig, ZeroParallax,
};

/// The built-in grading scene: small (fast, ASCII maps fit a terminal), with depth in front of
/// and behind the screen (parallax of both signs), occluders in front of a backdrop (remapping,
/// visibility) and a background plane behind everything (the SIRDS paper's SIRDS bound).
pub(crate) const GRADING_SCENE: &str = r#"
outputs = ["left", "right"]
[image]
width = 64
height = 48
[camera]
eye = [0.0, 0.6, 5.0]
target = [0.0, 0.0, 0.0]
fov_y = 50.0
near = 1.0
far = 20.0
[stereo]
eye_separation = 0.4
zero_parallax = 5.0
[light]
position = [4.0, 6.0, 6.0]
[[mesh]]
kind = "sphere"
size = 0.8
translate = [-0.7, 0.0, 1.2]
color = [0.9, 0.5, 0.3]
[[mesh]]
kind = "cube"
size = 1.2
rotate = [20.0, 35.0, 0.0]
translate = [0.9, 0.1, -0.6]
color = [0.3, 0.7, 0.9]
[[mesh]]
kind = "plane"
size = 8.0
detail = 4
translate = [0.0, 0.0, -2.5]
color = [0.6, 0.6, 0.5]
"#;

/// The grading scene, parsed.
///
/// # Errors
/// Never in practice (the text is a constant); kept as `Result` like every scene load.
pub fn grading_scene() -> Result<Scene> {
    Scene::from_toml(
        GRADING_SCENE,
        Path::new("<grading scene>"),
        Path::new("."),
        &[],
    )
}

/// A scene and what the reference renders of it, shared by the tasks' image checks.
pub(crate) struct Fixture {
    /// The scene.
    pub scene: Scene,
    /// Its stereo parameters as the exercises take them.
    pub setup: StereoSetup,
    /// The camera's (cyclopean) modelview.
    pub modelview: Mat4,
    /// The reference off-axis eyes (per-eye lighting), index 0 left.
    pub eyes: [EyeMatrices; 2],
    /// Shaded left and right eye renders.
    pub views: [Framebuffer; 2],
    /// The cyclopean eye's shaded render (its depth is what ChromaDepth and SIRDS read).
    pub center: Framebuffer,
    /// The cyclopean eye's matrices.
    pub center_matrices: EyeMatrices,
}

/// The reference rig of the exercises: off-axis with the scene's separation and screen distance,
/// no user adjustments (the exercise slides' rig).
pub(crate) fn reference_rig(setup: &StereoSetup, lighting: Lighting) -> StereoRig {
    StereoRig {
        separation: Separation::Absolute(setup.eye_separation),
        zero_parallax: ZeroParallax::Distance(setup.zero_parallax),
        lighting,
        ..StereoRig::default()
    }
}

/// `scene`'s camera and resolved rig as the exercises take them.
///
/// # Errors
/// An invalid camera or rig.
pub(crate) fn stereo_setup(scene: &Scene) -> Result<StereoSetup> {
    let aspect = scene.aspect();
    let resolved = scene.rig.resolve(&scene.camera, aspect)?;
    Ok(StereoSetup {
        fov_y_degrees: scene.camera.fov_y,
        aspect,
        near: scene.camera.near,
        far: scene.camera.far,
        eye_separation: resolved.eye_separation,
        zero_parallax: resolved.zero_parallax_distance,
    })
}

impl Fixture {
    /// Renders the reference views of `scene`.
    ///
    /// # Errors
    /// An invalid camera or rig.
    pub fn new(scene: Scene) -> Result<Fixture> {
        let aspect = scene.aspect();
        let setup = stereo_setup(&scene)?;
        let eyes = reference_rig(&setup, Lighting::PerEye).eyes(&scene.camera, aspect)?;
        let center_matrices = StereoRig::center(&scene.camera, aspect)?;
        let views = [
            render_view(&scene, &eyes[0], Shading::Color)?.0,
            render_view(&scene, &eyes[1], Shading::Color)?.0,
        ];
        let center = render_view(&scene, &center_matrices, Shading::Color)?.0;
        Ok(Fixture {
            modelview: scene.camera.view(),
            scene,
            setup,
            eyes,
            views,
            center,
            center_matrices,
        })
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.scene.width, self.scene.height)
    }

    /// A framebuffer of the scene's size filled with `color` at depth 0 (fully "covered"), for
    /// pictures that are not renders.
    pub(crate) fn canvas(&self, color: [u8; 4]) -> Framebuffer {
        let (w, h) = self.size();
        let mut fb = Framebuffer::new(w, h, color).expect("the scene's size was validated");
        fb.cover_all();
        fb
    }

    /// A picture over `view`'s depth: `view`'s size and depths, every pixel `color`.
    pub(crate) fn canvas_over(&self, view: &Framebuffer, color: [u8; 4]) -> Framebuffer {
        let mut fb = view.clone();
        fb.color_mut().fill(color);
        fb
    }

    /// Texture coordinate (OpenGL: v = 0 at the bottom row) of pixel (x, y)'s center.
    pub fn uv(&self, x: u32, y: u32) -> [f32; 2] {
        pixel_uv(self.scene.width, self.scene.height, x, y)
    }

    /// Eye-space position of a covered pixel of a render made with `m` (`None` for background).
    pub(crate) fn unproject(
        &self,
        m: &EyeMatrices,
        fb: &Framebuffer,
        x: u32,
        y: u32,
    ) -> Option<Vec3> {
        unproject(m, fb, x, y)
    }
}

/// Texture coordinate (OpenGL: v = 0 at the bottom row) of pixel (x, y)'s center in a w × h image.
pub(crate) fn pixel_uv(w: u32, h: u32, x: u32, y: u32) -> [f32; 2] {
    [
        (x as f32 + 0.5) / w as f32,
        1.0 - (y as f32 + 0.5) / h as f32,
    ]
}

/// Eye-space position (in `m.view`'s space) of a covered pixel of `fb`, rendered with `m`;
/// `None` for background.
pub(crate) fn unproject(m: &EyeMatrices, fb: &Framebuffer, x: u32, y: u32) -> Option<Vec3> {
    let d = fb.depth()[fb.index(x, y)];
    if d >= 1.0 {
        return None;
    }
    let [u, v] = pixel_uv(fb.width(), fb.height(), x, y);
    let ndc = glam::Vec4::new(2.0 * u - 1.0, 2.0 * v - 1.0, 2.0 * d - 1.0, 1.0);
    let p = m.projection.inverse() * ndc;
    Some(p.truncate() / p.w)
}
