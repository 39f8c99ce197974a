//! Figures for the slides, drawn with tiny-skia from a scene's real rig: a top view of both eyes'
//! frusta and a plot of parallax against depth. `stereolab figures SCENE --out slides/figures`.

use std::path::{Path, PathBuf};

use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::effects::parallax::PARALLAX_BUDGET_PERCENT;
use crate::error::{Error, Result};
use crate::math::{CameraMode, StereoRig};
use crate::scene::Scene;

const LEFT_COLOR: (u8, u8, u8) = (220, 40, 40);
const RIGHT_COLOR: (u8, u8, u8) = (20, 170, 200);

fn paint(rgb: (u8, u8, u8), alpha: u8) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb.0, rgb.1, rgb.2, alpha);
    p.anti_alias = true;
    p
}

fn line(pm: &mut Pixmap, a: (f32, f32), b: (f32, f32), rgb: (u8, u8, u8), width: f32) {
    let mut pb = PathBuilder::new();
    pb.move_to(a.0, a.1);
    pb.line_to(b.0, b.1);
    if let Some(path) = pb.finish() {
        pm.stroke_path(
            &path,
            &paint(rgb, 255),
            &Stroke {
                width,
                ..Stroke::default()
            },
            Transform::identity(),
            None,
        );
    }
}

fn dot(pm: &mut Pixmap, c: (f32, f32), r: f32, rgb: (u8, u8, u8)) {
    if let Some(path) = PathBuilder::from_circle(c.0, c.1, r) {
        pm.fill_path(
            &path,
            &paint(rgb, 255),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

fn save(pm: &Pixmap, path: &Path) -> Result<PathBuf> {
    let png = pm
        .encode_png()
        .map_err(|e| Error::io(path, std::io::Error::other(e.to_string())))?;
    crate::files::write_bytes(path, &png)?;
    Ok(path.to_path_buf())
}

/// Top view (eye space x right, −z up the page) of both eyes' frusta out to twice the
/// zero-parallax distance, with the near plane and the zero-parallax plane.
///
/// # Errors
/// Invalid rig.
pub fn rig_top_view(scene: &Scene, mode: CameraMode, size: u32) -> Result<Pixmap> {
    let rig = StereoRig { mode, ..scene.rig };
    let r = rig.resolve(&scene.camera, scene.aspect())?;
    let eyes = rig.eyes(&scene.camera, scene.aspect())?;
    let center_view = scene.camera.view();
    let depth = 2.0 * r.zero_parallax_distance;
    let half_width = r.xrange; // world units shown left and right of the axis
    let mut pm = Pixmap::new(size, size)
        .ok_or_else(|| Error::invalid("figure size", size, "must be > 0"))?;
    pm.fill(Color::WHITE);
    let margin = 0.08 * size as f32;
    let scale = (size as f32 - 2.0 * margin) / depth.max(2.0 * half_width);
    // Eye-space (x, z) → pixel: eyes at the bottom center, −z upward.
    let to_px = |x: f32, z: f32| {
        (
            size as f32 * 0.5 + x * scale,
            size as f32 - margin + z * scale,
        )
    };
    line(
        &mut pm,
        to_px(-half_width, -r.zero_parallax_distance),
        to_px(half_width, -r.zero_parallax_distance),
        (0, 0, 0),
        2.0,
    );
    line(
        &mut pm,
        to_px(-half_width, -scene.camera.near),
        to_px(half_width, -scene.camera.near),
        (150, 150, 150),
        1.0,
    );
    for (eye, rgb) in eyes.iter().zip([LEFT_COLOR, RIGHT_COLOR]) {
        // This eye's frustum edges, mapped into the cyclopean eye space.
        let to_center = center_view * eye.view.inverse();
        let [l, rr, _, _, n, _] = eye.frustum;
        let origin = to_center.transform_point3(glam::Vec3::ZERO);
        for x_near in [l, rr] {
            let dir = to_center
                .transform_vector3(glam::Vec3::new(x_near, 0.0, -n))
                .normalize();
            let t = depth / -dir.z.min(-1e-6);
            let end = origin + dir * t;
            line(
                &mut pm,
                to_px(origin.x, origin.z),
                to_px(end.x, end.z),
                rgb,
                1.5,
            );
        }
        let axis = to_center.transform_vector3(glam::Vec3::NEG_Z) * depth;
        line(
            &mut pm,
            to_px(origin.x, origin.z),
            to_px(origin.x + axis.x, origin.z + axis.z),
            rgb,
            0.75,
        );
        dot(&mut pm, to_px(origin.x, origin.z), 4.0, rgb);
    }
    Ok(pm)
}

/// The curve [`parallax_plot`] draws: `steps + 1` points `(z, p)` from near to far, `p` the
/// screen parallax of a point at eye distance z in percent of the image width. It is the
/// renderer's own `p(z) = d·(b − z0/z)` ([`ParallaxRig::parallax`](crate::effects::parallax::ParallaxRig::parallax),
/// balance b and parallel axes included), never a copy of the formula.
///
/// # Errors
/// Invalid camera or rig.
pub fn parallax_curve(scene: &Scene, steps: usize) -> Result<Vec<(f64, f64)>> {
    let rig = scene.parallax_rig()?;
    let (near, far) = (rig.near, rig.far);
    let steps = steps.max(1);
    Ok((0..=steps)
        .map(|i| {
            let z = near + (far - near) * i as f64 / steps as f64;
            let percent = 100.0 * rig.parallax(z) * rig.pixels_per_unit / f64::from(rig.width);
            (z, percent)
        })
        .collect())
}

/// Parallax in percent of image width against eye depth z from near to far (the exercise
/// slides' `p(z) = d (1 − z0/z)`, with the StereoGraphics guide's balance b:
/// [`parallax_curve`]); the ±3% budget shaded.
///
/// # Errors
/// Invalid rig.
pub fn parallax_plot(scene: &Scene, width: u32, height: u32) -> Result<Pixmap> {
    let r = scene.rig.resolve(&scene.camera, scene.aspect())?;
    let mut pm = Pixmap::new(width, height)
        .ok_or_else(|| Error::invalid("figure size", width, "must be > 0"))?;
    pm.fill(Color::WHITE);
    let (near, far) = (scene.camera.near, scene.camera.far);
    let steps = 400;
    let curve: Vec<(f32, f32)> = parallax_curve(scene, steps)?
        .into_iter()
        .map(|(z, p)| (z as f32, p as f32))
        .collect();
    let (p_near, p_far) = (curve[0].1, curve[steps].1);
    let (lo, hi) = (
        p_near.min(-2.0 * PARALLAX_BUDGET_PERCENT),
        p_far.max(2.0 * PARALLAX_BUDGET_PERCENT),
    );
    let (w, h) = (width as f32, height as f32);
    let to_px = |z: f32, v: f32| {
        (
            0.05 * w + (z - near) / (far - near) * 0.9 * w,
            0.95 * h - (v - lo) / (hi - lo) * 0.9 * h,
        )
    };
    let (x0, top) = to_px(near, PARALLAX_BUDGET_PERCENT);
    let (x1, bottom) = to_px(far, -PARALLAX_BUDGET_PERCENT);
    if let Some(rect) = Rect::from_ltrb(x0, top, x1, bottom) {
        pm.fill_rect(
            rect,
            &paint((120, 200, 120), 80),
            Transform::identity(),
            None,
        );
    }
    line(&mut pm, to_px(near, 0.0), to_px(far, 0.0), (0, 0, 0), 1.0);
    line(
        &mut pm,
        to_px(r.zero_parallax_distance, lo),
        to_px(r.zero_parallax_distance, hi),
        (120, 120, 120),
        1.0,
    );
    let mut pb = PathBuilder::new();
    for (i, &(z, p)) in curve.iter().enumerate() {
        let (x, y) = to_px(z, p.clamp(lo, hi));
        if i == 0 {
            pb.move_to(x, y)
        } else {
            pb.line_to(x, y)
        }
    }
    if let Some(path) = pb.finish() {
        pm.stroke_path(
            &path,
            &paint((30, 30, 160), 255),
            &Stroke {
                width: 2.0,
                ..Stroke::default()
            },
            Transform::identity(),
            None,
        );
    }
    Ok(pm)
}

/// Writes every figure into `dir`; returns the paths.
///
/// # Errors
/// Invalid rig or an unwritable folder.
pub fn write_all(scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    Ok(vec![
        save(
            &rig_top_view(scene, CameraMode::OffAxis, 480)?,
            &dir.join("rig_off_axis.png"),
        )?,
        save(
            &rig_top_view(scene, CameraMode::ToeIn, 480)?,
            &dir.join("rig_toe_in.png"),
        )?,
        save(
            &rig_top_view(scene, CameraMode::Parallel, 480)?,
            &dir.join("rig_parallel.png"),
        )?,
        save(
            &parallax_plot(scene, 640, 360)?,
            &dir.join("parallax_vs_depth.png"),
        )?,
    ])
}
