//! A ChromaDepth image: each vertex gets the texture coordinate `s = C·z_eye + D` of the eye
//! plane (OpenGL's eye-linear texgen), each pixel the HSV ramp's colour at its `s`: red near,
//! blue far (the ChromaDepth article, "Creating ChromaDepth Scenes with OpenGL").
//!
//! `cargo run --release --example chromadepth -- out/chromadepth.png`

use glam::{Mat4, Vec3, Vec4};
use stereolab::scene::Mesh;
use stereolab_core::{
    Fragment, Framebuffer, Ramp, RampKind, RampSampling, RasterOptions, Shader, Texgen, Varyings,
    auto_range, look_at, perspective, rasterize, to_rgba8,
};

/// The texgen pass: one varying, `s`, from the eye-space position.
struct ChromaDepth<'a> {
    positions: &'a [Vec3],
    modelview: Mat4,
    projection: Mat4,
    texgen: Texgen,
    ramp: Ramp,
}

impl Shader for ChromaDepth<'_> {
    fn varying_count(&self) -> usize {
        1
    }
    fn vertex(&self, index: u32, varyings: &mut Varyings) -> Vec4 {
        let eye = self.modelview * self.positions[index as usize].extend(1.0);
        varyings[0] = self.texgen.s(eye.truncate());
        self.projection * eye
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        Some(to_rgba8(
            self.ramp.sample(f.varyings[0], RampSampling::Linear),
        ))
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or("chromadepth.png".into());
    let (width, height, near, far) = (640, 480, 0.5, 30.0);
    // A ring in the XZ plane seen from above and in front: its near side is nearer the eye.
    let mesh = Mesh::torus(1.5, 0.5, 96, 48);
    let view = look_at(Vec3::new(0.0, 4.0, 3.0), Vec3::ZERO, Vec3::Y);
    // D1 and D2 from the bounding sphere: the ramp spans exactly the object.
    let (d1, d2) = auto_range(&mesh.positions, view, near, far)?;
    let shader = ChromaDepth {
        positions: &mesh.positions,
        modelview: view,
        projection: perspective(50.0, width as f32 / height as f32, near, far),
        texgen: Texgen::from_range(d1, d2)?,
        ramp: Ramp::new(RampKind::Hsv, 256)?,
    };
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255])?;
    let (opts, count) = (RasterOptions::default(), mesh.positions.len());
    rasterize(&mesh.triangles, count, &shader, &mut fb, &opts);
    fb.to_rgba_image().save(&out)?;
    println!("wrote {out}: D1 = {d1:.2}, D2 = {d2:.2}");
    Ok(())
}
