//! The rig: top views of both eyes' frusta for each camera mode (the SGI course notes' Fig. 8
//! redrawn from the rig's own matrices), shear against rotate, and toe-in's vertical parallax
//! measured by projecting points through both eyes' matrices.

use glam::Vec3;

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, LEFT, RIGHT, SMALL};
use stereolab::scene::Scene;
use stereolab_core::{CameraMode, Result, StereoRig, TextAlign, project_ndc};

/// Draws the top view of `mode`'s frusta into the page box `frame`: eye space of the cyclopean
/// camera, x right, −z up the page, out to twice z0.
fn top_view(
    c: &mut Canvas,
    frame: (f32, f32, f32, f32),
    scene: &Scene,
    mode: CameraMode,
) -> Result<()> {
    let rig = StereoRig { mode, ..scene.rig };
    let r = rig.resolve(&scene.camera, scene.aspect())?;
    let eyes = rig.eyes(&scene.camera, scene.aspect())?;
    let center_view = scene.camera.view();
    let z0 = r.zero_parallax_distance;
    let depth = 2.0 * z0;
    let (l, t, rr, b) = frame;
    let half = 0.5 * depth * (rr - l) / (b - t); // equal scale on both axes
    let a = Axes {
        frame,
        x: (-f64::from(half), f64::from(half)),
        y: (0.0, f64::from(depth)),
    };
    let p = |x: f32, z: f32| a.px(f64::from(x), f64::from(-z));
    let n = scene.camera.near;
    c.line(p(-half, -n), p(half, -n), GRAY, 1.0);
    c.line(p(-half, -z0), p(half, -z0), INK, 2.0);
    // A ray from `origin` along `dir` (top-view x, z), cut where it leaves the panel.
    let cut = |origin: Vec3, dir: Vec3| {
        let mut t = depth / -dir.z.min(-1e-6);
        if dir.x.abs() > 1e-6 {
            t = t.min((half * dir.x.signum() - origin.x) / dir.x);
        }
        origin + dir * t.max(0.0)
    };
    for (i, (eye, rgb)) in eyes.iter().zip([LEFT, RIGHT]).enumerate() {
        // This eye's frustum edges, carried into the cyclopean eye space.
        let to_center = center_view * eye.view.inverse();
        let [fl, fr, _, _, fnear, _] = eye.frustum;
        let origin = to_center.transform_point3(Vec3::ZERO);
        for x_near in [fl, fr] {
            let dir = to_center
                .transform_vector3(Vec3::new(x_near, 0.0, -fnear))
                .normalize();
            let end = cut(origin, dir);
            c.line(p(origin.x, origin.z), p(end.x, end.z), rgb, 1.5);
        }
        let end = cut(origin, to_center.transform_vector3(Vec3::NEG_Z));
        c.dashed(p(origin.x, origin.z), p(end.x, end.z), rgb, 1.0);
        c.dot(p(origin.x, origin.z), 4.0, rgb);
        let (label, align, dx) = if i == 0 {
            ("left eye", TextAlign::Right, -4.0)
        } else {
            ("right eye", TextAlign::Left, 4.0)
        };
        c.text(
            p(origin.x, origin.z).0 + dx,
            b + 4.0,
            SMALL,
            label,
            rgb,
            align,
        );
    }
    c.boxed_text(
        rr - 4.0,
        p(0.0, -n).1 - 18.0,
        SMALL,
        &format!("near n = {n}"),
        GRAY,
        TextAlign::Right,
    );
    c.boxed_text(
        rr - 4.0,
        p(0.0, -z0).1 - 20.0,
        SMALL,
        &format!("zero parallax z0 = {z0:.2}"),
        INK,
        TextAlign::Right,
    );
    let (el, er) = (eyes[0].eye_world, eyes[1].eye_world);
    let iod = (er - el).length();
    c.text(
        (l + rr) / 2.0,
        b + 22.0,
        SMALL,
        &format!("d (IOD) = {iod:.3}"),
        INK,
        TextAlign::Center,
    );
    c.rect((l, t), (rr, b + 42.0), (200, 200, 200), 1.0);
    Ok(())
}

fn single(ctx: &Context, mode: CameraMode, title: &str) -> Result<Canvas> {
    let mut c = Canvas::new(480, 540)?;
    c.text(240.0, 8.0, LABEL, title, INK, TextAlign::Center);
    top_view(&mut c, (10.0, 34.0, 470.0, 494.0), ctx.scene, mode)?;
    Ok(c)
}

/// Off-axis: parallel axes, asymmetric frusta that share the zero-parallax window.
///
/// # Errors
/// Invalid rig.
pub fn off_axis(ctx: &Context) -> Result<Canvas> {
    single(
        ctx,
        CameraMode::OffAxis,
        "off-axis: parallel axes, sheared frusta",
    )
}

/// Toe-in: each eye rotated towards the fusion point.
///
/// # Errors
/// Invalid rig.
pub fn toe_in(ctx: &Context) -> Result<Canvas> {
    single(
        ctx,
        CameraMode::ToeIn,
        "toe-in: axes rotated to the fusion point",
    )
}

/// Parallel: symmetric frusta, zero parallax at infinity.
///
/// # Errors
/// Invalid rig.
pub fn parallel(ctx: &Context) -> Result<Canvas> {
    single(
        ctx,
        CameraMode::Parallel,
        "parallel: symmetric frusta, no shear",
    )
}

/// Shear (off-axis) and rotate (toe-in) side by side, zoomed on the eyes and z0.
///
/// # Errors
/// Invalid rig.
pub fn shear_vs_rotate(ctx: &Context) -> Result<Canvas> {
    let mut c = Canvas::new(900, 540)?;
    c.text(
        225.0,
        8.0,
        LABEL,
        "shear (off-axis)",
        INK,
        TextAlign::Center,
    );
    c.text(675.0, 8.0, LABEL, "rotate (toe-in)", INK, TextAlign::Center);
    top_view(
        &mut c,
        (10.0, 34.0, 440.0, 494.0),
        ctx.scene,
        CameraMode::OffAxis,
    )?;
    top_view(
        &mut c,
        (460.0, 34.0, 890.0, 494.0),
        ctx.scene,
        CameraMode::ToeIn,
    )?;
    Ok(c)
}

/// Vertical parallax in pixels, `(y_R − y_L)·H/2` in window units, of points on the
/// zero-parallax plane seen through the center of each of `cols`×`rows` cells of the view,
/// projected by both eyes' MVP matrices (row-major, top row first).
///
/// # Errors
/// Invalid rig.
pub fn vertical_parallax_grid(
    scene: &Scene,
    mode: CameraMode,
    cols: u32,
    rows: u32,
) -> Result<Vec<f32>> {
    let rig = StereoRig { mode, ..scene.rig };
    let r = rig.resolve(&scene.camera, scene.aspect())?;
    let eyes = rig.eyes(&scene.camera, scene.aspect())?;
    let inv = scene.camera.view().inverse();
    let (w, h) = scene.camera.near_half_extents(scene.aspect());
    let k = r.zero_parallax_distance / scene.camera.near;
    let mut out = Vec::with_capacity((cols * rows) as usize);
    for row in 0..rows {
        for col in 0..cols {
            let nx = 2.0 * (col as f32 + 0.5) / cols as f32 - 1.0;
            let ny = 1.0 - 2.0 * (row as f32 + 0.5) / rows as f32;
            let p =
                inv.transform_point3(Vec3::new(nx * w * k, ny * h * k, -r.zero_parallax_distance));
            let y = |i: usize| project_ndc(&eyes[i].mvp, p).map_or(f32::NAN, |v| v.y);
            out.push((y(1) - y(0)) * 0.5 * scene.height as f32);
        }
    }
    Ok(out)
}

/// Toe-in's vertical parallax across the screen plane against off-axis's (zero), as maps.
///
/// # Errors
/// Invalid rig.
pub fn toe_in_vertical_parallax(ctx: &Context) -> Result<Canvas> {
    let (cols, rows, cell) = (40u32, 30u32, 8.0f32);
    let maps = [
        (
            "toe-in",
            vertical_parallax_grid(ctx.scene, CameraMode::ToeIn, cols, rows)?,
        ),
        (
            "off-axis",
            vertical_parallax_grid(ctx.scene, CameraMode::OffAxis, cols, rows)?,
        ),
    ];
    let scale = maps[0]
        .1
        .iter()
        .fold(0.0f32, |m, v| m.max(v.abs()))
        .max(1e-3);
    let color = |v: f32| -> (u8, u8, u8) {
        let t = (v / scale).clamp(-1.0, 1.0);
        let fade = |x: f32| (255.0 * (1.0 - x.abs())).round() as u8;
        if t >= 0.0 {
            (255, fade(t), fade(t))
        } else {
            (fade(t), fade(t), 255)
        }
    };
    let mut c = Canvas::new(740, 360)?;
    for (i, (name, map)) in maps.iter().enumerate() {
        let x0 = 20.0 + i as f32 * 350.0;
        let y0 = 34.0;
        for row in 0..rows {
            for col in 0..cols {
                let v = map[(row * cols + col) as usize];
                let (x, y) = (x0 + col as f32 * cell, y0 + row as f32 * cell);
                c.fill_rect((x, y), (x + cell, y + cell), color(v), 255);
            }
        }
        c.rect(
            (x0, y0),
            (x0 + cols as f32 * cell, y0 + rows as f32 * cell),
            INK,
            1.0,
        );
        let worst = map.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        c.text(x0 + 160.0, 8.0, LABEL, name, INK, TextAlign::Center);
        c.text(
            x0 + 160.0,
            y0 + rows as f32 * cell + 6.0,
            SMALL,
            &format!("max |y_R − y_L| = {worst:.2} px"),
            INK,
            TextAlign::Center,
        );
    }
    // Color bar.
    let (bx, by) = (690.0, 34.0);
    for i in 0..240 {
        let v = scale * (1.0 - 2.0 * i as f32 / 239.0);
        c.fill_rect(
            (bx, by + i as f32),
            (bx + 14.0, by + i as f32 + 1.0),
            color(v),
            255,
        );
    }
    c.text(
        bx + 7.0,
        by - 16.0,
        SMALL,
        &format!("+{scale:.1}"),
        INK,
        TextAlign::Center,
    );
    c.text(
        bx + 7.0,
        by + 242.0,
        SMALL,
        &format!("−{scale:.1}"),
        INK,
        TextAlign::Center,
    );
    c.text(
        370.0,
        305.0,
        SMALL,
        &format!(
            "vertical parallax (px) of points on the zero-parallax plane, {}×{} image,",
            ctx.scene.width, ctx.scene.height
        ),
        INK,
        TextAlign::Center,
    );
    c.text(
        370.0,
        323.0,
        SMALL,
        "projected through both eyes' MVP matrices (StereoRig::eyes); red: the right eye's image is higher",
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}
