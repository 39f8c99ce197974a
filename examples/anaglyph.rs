//! Two eyes of an off-axis rig, rasterized with Blinn-Phong, mixed into a Dubois anaglyph.
//!
//! `cargo run --release --example anaglyph -- out/anaglyph.png`

use glam::{Mat4, Vec3};
use stereolab::scene::Mesh;
use stereolab_core::{
    AnaglyphKind, AnaglyphOptions, BlinnPhong, Camera, Framebuffer, Light, RasterOptions,
    StereoRig, ZeroParallax, anaglyph, rasterize_blinn_phong,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or("anaglyph.png".into());
    let (width, height) = (640, 480);
    let (eye, target, up) = ([0.0, 0.6, 4.0], [0.0; 3], [0.0, 1.0, 0.0]);
    let camera = Camera {
        eye,
        target,
        up,
        fov_y: 50.0,
        near: 0.5,
        far: 20.0,
    };
    // Off-axis, the StereoGraphics guide's automatic separation, the screen (zero parallax)
    // through the torus's centre: its near half comes out of the screen, the far half behind.
    let rig = StereoRig {
        zero_parallax: ZeroParallax::Distance(4.0),
        ..StereoRig::default()
    };
    let eyes = rig.eyes(&camera, width as f32 / height as f32)?;
    let torus = Mesh::torus(1.0, 0.35, 64, 32);
    let model = Mat4::from_rotation_x(0.9);
    let mut views = Vec::new();
    for eye in &eyes {
        let mut fb = Framebuffer::new(width, height, [20, 20, 30, 255])?;
        let shader = BlinnPhong::new(
            &torus.positions,
            &torus.normals,
            model,
            eye.view,
            eye.projection,
            Vec3::new(0.9, 0.7, 0.3),
            Light::default(),
        );
        let (opts, count) = (RasterOptions::default(), torus.positions.len());
        rasterize_blinn_phong(&torus.triangles, count, &shader, &mut fb, &opts);
        views.push(fb);
    }
    let kind = AnaglyphKind::DuboisRedCyan;
    anaglyph(&views[0], &views[1], kind, AnaglyphOptions::default())?.save(&out)?;
    println!("wrote {out}");
    Ok(())
}
