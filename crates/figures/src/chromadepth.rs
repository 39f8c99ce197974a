//! ChromaDepth: the eye-linear texgen plane over the scene's bounding sphere, the ramp against
//! distance with D1 and D2, the glasses' grating model, and what each eye sees.

use glam::Vec3;

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, SMALL};
use super::thumbs::{grid, image_of, rendered};
use stereolab::plan::Output;
use stereolab::render::chromadepth::resolve_texgen;
use stereolab::scene::Scene;
use stereolab_core::{
    Error, Ramp, RampKind, Result, StereoRig, Texgen, TextAlign, bounding_sphere, pixel_shift,
};

fn to_rgb(v: Vec3) -> (u8, u8, u8) {
    let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    (c(v.x), c(v.y), c(v.z))
}

/// The texgen the ChromaDepth pass of `scene` uses (D1/D2 given or from the bounding sphere).
fn texgen(scene: &Scene) -> Result<Texgen> {
    let m = StereoRig::center(&scene.camera, scene.aspect())?;
    resolve_texgen(scene, &m, &scene.chromadepth)
}

fn ramp(scene: &Scene) -> Result<Ramp> {
    Ramp::new(scene.chromadepth.ramp, scene.chromadepth.texels)
}

/// Top view of the center camera: its frustum, the scene's bounding sphere, and the texgen's
/// `s = 0` (D1) and `s = 1` (D2) planes with the ramp painted between them.
///
/// # Errors
/// Invalid camera, no scene points.
pub fn texgen_top_view(ctx: &Context) -> Result<Canvas> {
    let s = ctx.scene;
    let tg = texgen(s)?;
    let ramp = ramp(s)?;
    let view = s.camera.view();
    let eye_points: Vec<Vec3> = s.world_points().map(|p| view.transform_point3(p)).collect();
    let (center, radius) = bounding_sphere(&eye_points)
        .ok_or_else(|| Error::invalid("scene", "no points", "needs a mesh"))?;
    let depth = f64::from(tg.d2) * 1.25;
    let mut c = Canvas::new(620, 490)?;
    let frame = (70.0, 20.0, 440.0, 420.0);
    let half = 0.5 * depth * f64::from((frame.2 - frame.0) / (frame.3 - frame.1));
    let a = Axes {
        frame,
        x: (-half, half),
        y: (0.0, depth),
    };
    a.draw(
        &mut c,
        "eye x (world units)",
        "distance in front of the eye −z",
        (6.0, 6.0),
    );
    // The ramp between D1 and D2: each depth row colored by the texture at s(distance).
    let rows = 200;
    for i in 0..rows {
        let d0 = f64::from(tg.d1) + (f64::from(tg.d2 - tg.d1)) * i as f64 / rows as f64;
        let d1 = f64::from(tg.d1) + (f64::from(tg.d2 - tg.d1)) * (i + 1) as f64 / rows as f64;
        let sv = tg.s(Vec3::new(0.0, 0.0, -(d0 as f32 + d1 as f32) / 2.0));
        let col = to_rgb(ramp.sample(sv, s.chromadepth.sampling));
        c.fill_rect(a.px(-half, d0), a.px(half, d1), col, 110);
    }
    let (w, _) = s.camera.near_half_extents(s.aspect());
    let slope = f64::from(w / s.camera.near);
    let reach = depth.min(half / slope); // the frustum edge, cut at the panel's side
    c.line(a.px(0.0, 0.0), a.px(-slope * reach, reach), INK, 1.5);
    c.line(a.px(0.0, 0.0), a.px(slope * reach, reach), INK, 1.5);
    c.dot(a.px(0.0, 0.0), 5.0, INK);
    let (cx, cy) = a.px(f64::from(center.x), f64::from(-center.z));
    let r_px = radius / depth as f32 * (frame.3 - frame.1);
    c.circle((cx, cy), r_px, INK, 1.5);
    c.dot((cx, cy), 3.0, INK);
    for (d, name, sval) in [(tg.d1, "D1", 0), (tg.d2, "D2", 1)] {
        let (x0, y) = a.px(-half, f64::from(d));
        c.line((x0, y), (frame.2, y), INK, 1.5);
        c.text(
            frame.2 + 8.0,
            y - 8.0,
            SMALL,
            &format!("{name} = {d:.2}  (s = {sval})"),
            INK,
            TextAlign::Left,
        );
    }
    c.text(
        frame.2 + 8.0,
        cy - 8.0,
        SMALL,
        &format!("bounding sphere, r = {radius:.2}"),
        INK,
        TextAlign::Left,
    );
    let [pa, pb, pc, pd] = tg.plane.to_array();
    c.text(
        310.0,
        466.0,
        SMALL,
        &format!("eye plane (A, B, C, D) = ({pa:.0}, {pb:.0}, {pc:.4}, {pd:.4}); s = C·z + D"),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// The ramp's three channels and its color against eye distance, D1 and D2 marked: the texture
/// sampled where texgen puts each distance.
///
/// # Errors
/// Invalid settings.
pub fn ramp_against_distance(ctx: &Context) -> Result<Canvas> {
    let s = ctx.scene;
    let tg = texgen(s)?;
    let ramp = ramp(s)?;
    let span = f64::from(tg.d2 - tg.d1);
    let (x0, x1) = (f64::from(tg.d1) - 0.3 * span, f64::from(tg.d2) + 0.3 * span);
    let mut c = Canvas::new(720, 400)?;
    let a = Axes {
        frame: (80.0, 70.0, 700.0, 320.0),
        x: (x0, x1),
        y: (0.0, 1.05),
    };
    let n = 400;
    let samples: Vec<(f64, Vec3)> = (0..=n)
        .map(|i| {
            let d = x0 + (x1 - x0) * i as f64 / n as f64;
            let sv = tg.s(Vec3::new(0.0, 0.0, -(d as f32)));
            (d, ramp.sample(sv, s.chromadepth.sampling))
        })
        .collect();
    // The color band above the plot.
    for w in samples.windows(2) {
        let (xa, _) = a.px(w[0].0, 0.0);
        let (xb, _) = a.px(w[1].0, 0.0);
        c.fill_rect((xa, 20.0), (xb + 0.5, 56.0), to_rgb(w[0].1), 255);
    }
    a.draw(
        &mut c,
        "distance in front of the eye (world units)",
        "channel value",
        (8.0, 5.0),
    );
    for (k, rgb) in [(0, (220, 30, 30)), (1, (20, 160, 40)), (2, (30, 30, 220))] {
        let pts: Vec<(f64, f64)> = samples.iter().map(|(d, v)| (*d, f64::from(v[k]))).collect();
        a.curve(&mut c, &pts, rgb, 2.0);
    }
    for (d, name) in [(tg.d1, "D1"), (tg.d2, "D2")] {
        let d = f64::from(d);
        c.dashed(a.px(d, 0.0), (a.px(d, 0.0).0, 20.0), INK, 1.0);
        c.boxed_text(
            a.px(d, 0.0).0 + 4.0,
            76.0,
            SMALL,
            &format!("{name} = {d:.2}"),
            INK,
            TextAlign::Left,
        );
    }
    let kind = match ramp.kind() {
        RampKind::Hsv => "hsv",
        RampKind::RedWhiteBlue => "red-white-blue",
    };
    c.text(
        390.0,
        370.0,
        SMALL,
        &format!(
            "s = (distance − D1)/(D2 − D1), clamped; ramp \"{kind}\", {} texels; red near, blue far",
            ramp.texels().len()
        ),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// The glasses' model: the inward shift of each ramp color (both ramps) against the ramp
/// position s, for the course scene's width; the parallax is −2× the shift.
///
/// # Errors
/// Invalid settings.
pub fn glasses_shift(ctx: &Context) -> Result<Canvas> {
    let s = ctx.scene;
    let max_shift = s.chromadepth.max_shift_px(s.width);
    let mut c = Canvas::new(720, 380)?;
    let a = Axes {
        frame: (80.0, 20.0, 700.0, 300.0),
        x: (0.0, 1.0),
        y: (0.0, f64::from(max_shift) * 1.1),
    };
    a.draw(
        &mut c,
        "ramp position s (0 = D1, red; 1 = D2, blue)",
        "inward shift (px)",
        (10.0, 5.0),
    );
    let mut entries = Vec::new();
    for (kind, name, rgb) in [
        (RampKind::Hsv, "hsv ramp", (30, 30, 160)),
        (RampKind::RedWhiteBlue, "red-white-blue ramp", (200, 120, 0)),
    ] {
        let r = Ramp::new(kind, s.chromadepth.texels)?;
        let pts: Vec<(f64, f64)> = (0..=200)
            .map(|i| {
                let sv = i as f32 / 200.0;
                let col = r.sample(sv, s.chromadepth.sampling);
                let (cr, cg, cb) = to_rgb(col);
                (
                    f64::from(sv),
                    f64::from(pixel_shift([cr, cg, cb, 255], max_shift)),
                )
            })
            .collect();
        a.curve(&mut c, &pts, rgb, 2.0);
        entries.push((name, rgb));
    }
    a.legend(&mut c, &entries, true);
    c.text(
        390.0,
        348.0,
        SMALL,
        &format!(
            "grating: shift ∝ (λ − λ_B); red moves {max_shift:.1} px inward per eye ({} px wide), blue stays",
            s.width
        ),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// The ChromaDepth image and the two simulated views through the glasses, and their anaglyph.
///
/// # Errors
/// A render error.
pub fn views(ctx: &Context) -> Result<Canvas> {
    let outs = [
        Output::ChromaDepth,
        Output::ChromaDepthLeft,
        Output::ChromaDepthRight,
        Output::ChromaDepthAnaglyph,
    ];
    let (s, frame) = rendered(ctx.scene, 240, 180, &outs, |_| {})?;
    let cells = [
        ("chromadepth", outs[0]),
        ("left eye through the glasses", outs[1]),
        ("right eye through the glasses", outs[2]),
        ("both as a gray anaglyph", outs[3]),
    ]
    .into_iter()
    .map(|(t, o)| Ok((t.to_string(), image_of(o, &frame, &s)?)))
    .collect::<Result<Vec<_>>>()?;
    grid(&cells, 2, 1)
}
