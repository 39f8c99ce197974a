//! The finalize pass: anaglyphs, remapping, the visibility check and occlusion map,
//! parallax as color and the StereoGraphics guide's budget. Helpers here; tests in `tests/finalize/`.

mod anaglyph;
mod crosstalk;
mod inputs;
mod occlusion;
mod parallax;
mod remap;
mod threejs;

use std::path::Path;

use stereolab::plan::{Output, Plan, View};
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::Framebuffer;

/// A test rig: camera at the origin looking down −Z, absolute eye separation and zero-parallax
/// distance, so every expected number can be computed by hand from these fields.
#[derive(Clone, Copy, Debug)]
pub struct Rig {
    pub width: u32,
    pub height: u32,
    pub fov_y: f32,
    pub near: f32,
    pub far: f32,
    pub zero_parallax: f32,
    pub separation: f32,
    pub mode: &'static str,
}

impl Default for Rig {
    fn default() -> Self {
        Rig {
            width: 160,
            height: 120,
            fov_y: 40.0,
            near: 1.0,
            far: 40.0,
            zero_parallax: 6.0,
            separation: 0.5,
            mode: "off-axis",
        }
    }
}

impl Rig {
    /// Pixels per world unit at the zero-parallax plane: W / Xrange, Xrange = 2 z0 tan(fov/2) aspect.
    pub fn pixels_per_unit(&self) -> f64 {
        let aspect = self.width as f64 / self.height as f64;
        let xrange =
            2.0 * self.zero_parallax as f64 * (self.fov_y as f64 / 2.0).to_radians().tan() * aspect;
        self.width as f64 / xrange
    }

    /// The exercise slides: p(z) = d (1 − z0/z), in pixels.
    pub fn parallax_px(&self, z: f64) -> f64 {
        self.separation as f64 * (1.0 - self.zero_parallax as f64 / z) * self.pixels_per_unit()
    }
}

/// A `[[mesh]]` plane of edge `size` centered at `translate`, rotated by `rotate` degrees.
pub fn plane(size: f32, translate: [f32; 3], rotate: [f32; 3]) -> String {
    format!(
        "[[mesh]]\nkind = \"plane\"\nsize = {size}\ndetail = 3\ntranslate = {translate:?}\nrotate = {rotate:?}\ncolor = [0.9, 0.5, 0.2]\n"
    )
}

/// The scene of `rig` with `meshes` (TOML) and `outputs`.
pub fn scene(rig: &Rig, meshes: &str, outputs: &[&str]) -> Scene {
    let text = format!(
        "outputs = {outputs:?}\n\
         [image]\nwidth = {}\nheight = {}\n\
         [camera]\neye = [0.0, 0.0, 0.0]\ntarget = [0.0, 0.0, -1.0]\nfov_y = {}\nnear = {:e}\nfar = {}\n\
         [stereo]\nmode = \"{}\"\neye_separation = {}\nzero_parallax = {}\n\
         {meshes}",
        rig.width,
        rig.height,
        rig.fov_y,
        rig.near,
        rig.far,
        rig.mode,
        rig.separation,
        rig.zero_parallax
    );
    Scene::from_toml(&text, Path::new("finalize-test.toml"), Path::new("."), &[])
        .unwrap_or_else(|e| panic!("test scene: {e}\n{text}"))
}

/// Renders the passes `outputs` need.
pub fn render_outputs(scene: &Scene, outputs: &[Output]) -> Frame {
    render(scene, &Plan::new(outputs)).expect("render")
}

/// Both eye framebuffers of a frame that rendered them.
pub fn eyes(frame: &Frame) -> (&Framebuffer, &Framebuffer) {
    (
        frame.view(View::Left).expect("left pass"),
        frame.view(View::Right).expect("right pass"),
    )
}

/// Centroid (window coordinates, pixel centers at +0.5) of the pixels with depth < 1.
pub fn drawn_centroid(fb: &Framebuffer) -> [f64; 2] {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0usize);
    for y in 0..fb.height() {
        for x in 0..fb.width() {
            if fb.depth()[fb.index(x, y)] < 1.0 {
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
                n += 1;
            }
        }
    }
    assert!(n > 0, "nothing drawn");
    [sx / n as f64, sy / n as f64]
}
