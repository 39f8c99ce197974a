//! Perception and parallax: positive, zero and negative parallax (the StereoGraphics guide's
//! Fig. 1–2), convergence against accommodation, p(z) against depth with the ±3% budget, and
//! the per-pixel parallax map of the course scene.

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, LEFT, RIGHT, SMALL};
use super::thumbs::{image_of, rendered};
use stereolab::plan::{Output, View};
use stereolab::scene::Scene;
use stereolab_core::{
    CameraMode, Error, PARALLAX_BUDGET_PERCENT, ParallaxRig, Result, StereoRig, TextAlign,
    parallax_budget_of,
};

/// The curve of the `parallax_vs_depth` figure: `steps + 1` points `(z, p)` from near to far, `p` the
/// screen parallax of a point at eye distance z in percent of the image width. It is the
/// renderer's own `p(z) = d·(b − z0/z)` ([`ParallaxRig::parallax`], balance b and parallel
/// axes included), never a copy of the formula.
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

/// The schematic rig of the parallax diagrams: eyes 1 unit apart, the screen (zero-parallax
/// plane) 4 units away, balance 1 — exaggerated so the rays are visible.
fn schematic_rig() -> ParallaxRig {
    ParallaxRig {
        eye_separation: 1.0,
        zero_parallax_distance: 4.0,
        balance: 1.0,
        near: 1.0,
        far: 10.0,
        pixels_per_unit: 1.0,
        width: 1,
        height: 1,
    }
}

/// The points of the parallax diagram: `(z, x_left, x_right)` for a point on the center line at
/// eye distance z, where `x_left`, `x_right` are where each eye's image of it lies on the screen
/// (`∓ p(z)/2`, p from [`ParallaxRig::parallax`]). Behind the screen, on it, in front.
pub fn parallax_types_geometry() -> [(f64, f64, f64); 3] {
    let rig = schematic_rig();
    [7.0, 4.0, 2.5].map(|z| {
        let p = rig.parallax(z);
        (z, -p / 2.0, p / 2.0)
    })
}

/// One panel of eyes, screen and a point: the eyes at the bottom, z up the page.
fn eyes_and_point(c: &mut Canvas, frame: (f32, f32, f32, f32), z: f64, xl: f64, xr: f64) {
    let rig = schematic_rig();
    let (d, z0) = (rig.eye_separation, rig.zero_parallax_distance);
    let a = Axes {
        frame,
        x: (-2.2, 2.2),
        y: (-0.6, 8.0),
    };
    let (l, _, r, _) = frame;
    let (_, sy) = a.px(0.0, z0);
    c.line((l, sy), (r, sy), INK, 2.5);
    c.text(l + 2.0, sy + 3.0, SMALL, "screen", INK, TextAlign::Left);
    for (ex, sx, rgb) in [(-d / 2.0, xl, LEFT), (d / 2.0, xr, RIGHT)] {
        // The ray from the eye through its image point on the screen, on to the point.
        // The ray runs on to the point, or to the screen when the point is in front of it.
        let t = (z / z0).max(1.0);
        let end = (ex + (sx - ex) * t, z0 * t);
        c.line(a.px(ex, 0.0), a.px(end.0, end.1), rgb, 1.5);
        c.dot(a.px(sx, z0), 4.0, rgb);
        c.dot(a.px(ex, 0.0), 6.0, rgb);
    }
    c.text(
        a.px(-d / 2.0, 0.0).0,
        a.px(0.0, 0.0).1 + 9.0,
        SMALL,
        "L",
        LEFT,
        TextAlign::Center,
    );
    c.text(
        a.px(d / 2.0, 0.0).0,
        a.px(0.0, 0.0).1 + 9.0,
        SMALL,
        "R",
        RIGHT,
        TextAlign::Center,
    );
    c.dot(a.px(0.0, z), 5.0, INK);
}

/// Positive, zero and negative parallax side by side (the StereoGraphics guide, Fig. 1–2): the
/// point behind, on and in front of the screen, each eye's image of it on the screen.
///
/// # Errors
/// None in practice (a fixed page).
pub fn parallax_types(_: &Context) -> Result<Canvas> {
    let mut c = Canvas::new(780, 400)?;
    let titles = [
        "positive: behind the screen",
        "zero: on the screen",
        "negative: in front",
    ];
    for (i, ((z, xl, xr), title)) in parallax_types_geometry()
        .into_iter()
        .zip(titles)
        .enumerate()
    {
        let x0 = 10.0 + i as f32 * 258.0;
        let frame = (x0, 40.0, x0 + 240.0, 340.0);
        eyes_and_point(&mut c, frame, z, xl, xr);
        c.text(x0 + 120.0, 10.0, LABEL, title, INK, TextAlign::Center);
        let p = xr - xl;
        c.text(
            x0 + 120.0,
            362.0,
            LABEL,
            &format!(
                "p = x_R − x_L = {:+.2} d",
                p / schematic_rig().eye_separation
            )
            .replace('-', "−"),
            INK,
            TextAlign::Center,
        );
    }
    c.text(
        390.0,
        382.0,
        SMALL,
        "p(z) = d (1 − z0/z) from ParallaxRig::parallax; schematic rig: d = 1, z0 = 4, points at z = 7, 4, 2.5",
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// Convergence against accommodation: the eyes converge on the point in front of the screen
/// but must keep the screen in focus.
///
/// # Errors
/// None in practice.
pub fn vergence_accommodation(_: &Context) -> Result<Canvas> {
    let mut c = Canvas::new(560, 400)?;
    let [_, _, (z, xl, xr)] = parallax_types_geometry();
    // The upper part of the panel (beyond z = 5) is left off the page.
    let frame = (150.0, -150.0, 470.0, 350.0);
    eyes_and_point(&mut c, frame, z, xl, xr);
    let a = Axes {
        frame,
        x: (-2.2, 2.2),
        y: (-0.6, 8.0),
    };
    let z0 = schematic_rig().zero_parallax_distance;
    let (x_dim, x_dim2) = (a.px(-2.2, 0.0).0 - 20.0, a.px(-2.2, 0.0).0 - 60.0);
    c.dimension((x_dim, a.px(0.0, 0.0).1), (x_dim, a.px(0.0, z).1), INK);
    c.dimension((x_dim2, a.px(0.0, 0.0).1), (x_dim2, a.px(0.0, z0).1), GRAY);
    c.vertical_text(x_dim - 18.0, a.px(0.0, z / 2.0).1, SMALL, "vergence", INK);
    c.vertical_text(
        x_dim2 - 18.0,
        a.px(0.0, z0 / 2.0).1,
        SMALL,
        "accommodation",
        GRAY,
    );
    c.text(
        a.px(0.25, z).0,
        a.px(0.0, z).1 - 8.0,
        SMALL,
        &format!("eyes converge here: z = {z}"),
        INK,
        TextAlign::Left,
    );
    c.text(
        a.px(0.0, z0).0,
        a.px(0.0, z0).1 - 24.0,
        SMALL,
        &format!("eyes focus here: the screen, z0 = {z0}"),
        GRAY,
        TextAlign::Center,
    );
    c.text(
        280.0,
        380.0,
        SMALL,
        "negative parallax: the two distances differ (the conflict grows with |p|)",
        INK,
        TextAlign::Center,
    );
    Ok(c)
}

/// Parallax in percent of the image width against eye distance z, from near to far, for the
/// scene's rig, a lower balance and parallel axes ([`parallax_curve`]); the ±3% budget shaded,
/// z0 marked.
///
/// # Errors
/// Invalid rig.
pub fn parallax_vs_depth(ctx: &Context) -> Result<Canvas> {
    let scene = ctx.scene;
    let r = scene.rig.resolve(&scene.camera, scene.aspect())?;
    let variant = |mode: CameraMode, balance: f32| -> Result<Vec<(f64, f64)>> {
        let mut s = scene.clone();
        s.rig = StereoRig {
            mode,
            user_balance: balance,
            ..scene.rig
        };
        parallax_curve(&s, 400)
    };
    let curves = [
        (
            format!("off-axis, b = {}", scene.rig.user_balance),
            variant(CameraMode::OffAxis, scene.rig.user_balance)?,
            (30, 30, 160),
        ),
        (
            "off-axis, b = 0.5".to_string(),
            variant(CameraMode::OffAxis, 0.5)?,
            (200, 120, 0),
        ),
        (
            "parallel (b = 0)".to_string(),
            variant(CameraMode::Parallel, 1.0)?,
            (150, 40, 150),
        ),
    ];
    let (near, far) = (f64::from(scene.camera.near), f64::from(scene.camera.far));
    let budget = f64::from(PARALLAX_BUDGET_PERCENT);
    let lo = curves[0].1[0].1.max(-6.0 * budget).min(-2.0 * budget);
    let hi = curves
        .iter()
        .map(|c| c.1[c.1.len() - 1].1)
        .fold(2.0 * budget, f64::max);
    let mut c = Canvas::new(720, 420)?;
    let a = Axes {
        frame: (80.0, 20.0, 700.0, 350.0),
        x: (near, far),
        y: (lo, hi),
    };
    c.fill_rect(a.px(near, budget), a.px(far, -budget), (120, 200, 120), 70);
    a.draw(
        &mut c,
        "eye distance z (world units)",
        "parallax p (% of image width)",
        (8.0, 6.0),
    );
    c.line(a.px(near, 0.0), a.px(far, 0.0), INK, 1.0);
    let z0 = f64::from(r.zero_parallax_distance);
    c.dashed(a.px(z0, lo), a.px(z0, hi), GRAY, 1.0);
    c.boxed_text(
        a.px(z0, 0.0).0 + 4.0,
        a.px(z0, lo).1 - 22.0,
        SMALL,
        &format!("z0 = {z0:.2}"),
        GRAY,
        TextAlign::Left,
    );
    c.boxed_text(
        a.px(far, budget).0 - 6.0,
        a.px(far, budget).1 + 3.0,
        SMALL,
        "±3% budget",
        (40, 120, 40),
        TextAlign::Right,
    );
    for (_, pts, rgb) in &curves {
        a.curve(&mut c, pts, *rgb, 2.0);
    }
    let entries: Vec<(&str, (u8, u8, u8))> = curves
        .iter()
        .map(|(l, _, rgb)| (l.as_str(), *rgb))
        .collect();
    a.legend(&mut c, &entries, false);
    c.text(
        390.0,
        398.0,
        SMALL,
        &format!(
            "p(z) = d (b − z0/z), d = {:.3}, scene {}×{}; ParallaxRig::parallax",
            r.eye_separation, scene.width, scene.height
        ),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// The course scene's left-eye parallax map (the `parallax` output: blue negative, red
/// positive, with its legend) and the measured range against the budget.
///
/// # Errors
/// A render error.
pub fn parallax_map(ctx: &Context) -> Result<Canvas> {
    let (s, frame) = rendered(ctx.scene, 320, 240, &[Output::Parallax], |_| {})?;
    let img = image_of(Output::Parallax, &frame, &s)?;
    let fb = frame
        .view(View::Left)
        .ok_or_else(|| Error::internal("figures", "no left pass"))?;
    let b = parallax_budget_of(fb, &s.parallax_rig()?)?;
    let caption = format!(
        "measured: {:+.2}% … {:+.2}% of the width; {:.1}% of pixels beyond ±3%",
        b.percent(b.min_pixels),
        b.percent(b.max_pixels),
        100.0 * b.share_beyond()
    )
    .replace('-', "−");
    let width =
        (stereolab_core::text_width(&caption, SMALL).ceil() as u32 + 24).max(img.width() + 20);
    let mut c = Canvas::new(width, img.height() + 40)?;
    c.image(&img, (width - img.width()) / 2, 10, 1);
    c.text(
        c.width() / 2.0,
        img.height() as f32 + 16.0,
        SMALL,
        &caption,
        INK,
        TextAlign::Center,
    );
    Ok(c)
}
