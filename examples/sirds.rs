//! A single-image random-dot stereogram of a mesh: one depth pass from the cyclopean eye, the
//! depth mapped between the nearest point and a background plane, then TIW's linking per row
//! (the SIRDS paper, Petz et al., §2).
//!
//! `cargo run --release --example sirds -- out/sirds.png`

use glam::Mat4;
use stereolab::scene::Mesh;
use stereolab_core::{
    Camera, DepthMap, DepthOnly, Framebuffer, RasterOptions, SirdsSettings, StereoRig, depth_range,
    from_depth_map, rasterize,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or("sirds.png".into());
    let (width, height) = (800, 500);
    let camera = Camera {
        eye: [0.0, 0.0, 5.0],
        target: [0.0, 0.0, 0.0],
        up: [0.0, 1.0, 0.0],
        fov_y: 40.0,
        near: 1.0,
        far: 12.0,
    };
    // The cyclopean eye: a SIRDS is one image; the disparity comes from the depth.
    let center = StereoRig::center(&camera, width as f32 / height as f32)?;
    let torus = Mesh::torus(1.2, 0.45, 96, 48);
    let shader = DepthOnly {
        positions: &torus.positions,
        mvp: center.mvp * Mat4::from_rotation_x(1.1),
    };
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255])?;
    let opts = RasterOptions::default();
    rasterize(
        &torus.triangles,
        torus.positions.len(),
        &shader,
        &mut fb,
        &opts,
    );

    let settings = SirdsSettings::default();
    let range = depth_range(&settings, &fb, camera.near, camera.far)?;
    let depth = DepthMap::from_framebuffer(&fb, camera.near, camera.far, &range);
    let stereogram = from_depth_map(depth, &settings)?;
    let bytes = stereogram.pixels.concat();
    image::RgbaImage::from_raw(width, height, bytes)
        .ok_or("pixel count")?
        .save(&out)?;
    println!("wrote {out}: stare through the screen to see the torus");
    Ok(())
}
