//! SIRDS: linked pixels (the SIRDS paper's Fig. 1–3), both disparity models as curves, the
//! strip algorithm's k passes, left against center start (Fig. 7) and filtering (Fig. 5).

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, LEFT, RIGHT, SMALL};
use super::thumbs::{grid, rendered};
use stereolab::output::sirds::{from_frame, scene_depth};
use stereolab::plan::Output;
use stereolab_core::{DisparityModel, Result, SirdsGeometry, StripFilter, StripStart, TextAlign};
use stereolab_core::{StripGeometry, per_vertex};

/// The SIRDS paper's Fig. 1–3 with TIW's set-up: two surface points, the rays to both eyes,
/// and the two linked pixels on the image plane, `d` apart ([`stereolab_core::Disparity::separation`]).
///
/// # Errors
/// Invalid geometry.
pub fn linked_pixels(_: &Context) -> Result<Canvas> {
    let g = SirdsGeometry::default();
    let d = g.to_pixels()?;
    let (a, f) = (f64::from(d.eye_separation), f64::from(d.viewing_distance));
    let mut c = Canvas::new(760, 440)?;
    // x exaggerated: lateral pixels ×4 against depth pixels.
    let ax = Axes {
        frame: (130.0, 30.0, 610.0, 400.0),
        x: (-150.0, 150.0),
        y: (-f64::from(d.t_far) - 40.0, f + 40.0),
    };
    let (l, _, r, _) = ax.frame;
    let plane = ax.px(0.0, 0.0).1;
    let back = ax.px(0.0, -f64::from(d.t_far)).1;
    c.line((l, plane), (r, plane), INK, 2.5);
    c.text(
        r + 6.0,
        plane - 8.0,
        SMALL,
        "image plane",
        INK,
        TextAlign::Left,
    );
    c.dashed((l, back), (r, back), GRAY, 1.0);
    c.text(
        r + 6.0,
        back - 8.0,
        SMALL,
        "background z = 0",
        GRAY,
        TextAlign::Left,
    );
    let front = ax.px(0.0, -f64::from(d.t_near)).1;
    c.dashed((l, front), (r, front), GRAY, 1.0);
    c.text(
        r + 6.0,
        front - 8.0,
        SMALL,
        "front z = 1",
        GRAY,
        TextAlign::Left,
    );
    let eyes = [(-a / 2.0, LEFT, "L"), (a / 2.0, RIGHT, "R")];
    for (ex, rgb, name) in eyes {
        c.dot(ax.px(ex, f), 6.0, rgb);
        c.text(
            ax.px(ex, f).0,
            ax.px(ex, f).1 - 22.0,
            SMALL,
            name,
            rgb,
            TextAlign::Center,
        );
    }
    for (z, x) in [(0.3f32, -60.0f64), (0.9, 70.0)] {
        let t = f64::from(d.depth_of(z));
        let sep = f64::from(d.separation(z));
        let p = ax.px(x, -t);
        // Each linked pixel: where a ray from the point to one eye crosses the image plane,
        // placed `sep` apart around the point's foot (x scaled by f/(t+f) towards the center).
        let foot = x * f / (t + f);
        for ((ex, rgb, _), sx) in eyes.iter().zip([foot - sep / 2.0, foot + sep / 2.0]) {
            c.line(p, ax.px(*ex, f), *rgb, 1.0);
            c.dot(ax.px(sx, 0.0), 4.0, *rgb);
        }
        c.dot(p, 5.0, INK);
        c.text(
            p.0 + 8.0,
            p.1 - 6.0,
            SMALL,
            &format!("z = {z}"),
            INK,
            TextAlign::Left,
        );
        let y = plane - 26.0;
        c.dimension(
            (ax.px(foot - sep / 2.0, 0.0).0, y),
            (ax.px(foot + sep / 2.0, 0.0).0, y),
            INK,
        );
        c.text(
            ax.px(foot, 0.0).0,
            y - 18.0,
            SMALL,
            &format!("d = {sep:.1} px"),
            INK,
            TextAlign::Center,
        );
    }
    let x_dim = l - 40.0;
    c.dimension((x_dim, plane), (x_dim, ax.px(0.0, f).1), INK);
    c.vertical_text(
        x_dim - 22.0,
        (plane + ax.px(0.0, f).1) / 2.0,
        SMALL,
        "f (eyes to image)",
        INK,
    );
    c.dimension((x_dim, plane), (x_dim, back), GRAY);
    c.vertical_text(
        x_dim - 22.0,
        (plane + back) / 2.0,
        SMALL,
        "t (depth behind)",
        GRAY,
    );
    c.text(
        380.0,
        414.0,
        SMALL,
        &format!(
            "eq. 3: d = a t/(t + f); a = {a:.0} px, f = {f:.0} px ({} in at {} dpi); lateral ×4",
            g.viewing_distance_in, g.dpi
        ),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// Separation against nearness for both models (eq. 1 and eq. 3), TIW's set-up; eq. 1's angle
/// from eq. 2 at the background so they meet there.
///
/// # Errors
/// Invalid geometry.
pub fn disparity_models(_: &Context) -> Result<Canvas> {
    let g = SirdsGeometry::default();
    let models = [
        (
            DisparityModel::EyeDistance,
            "eq. 3: d = a t/(t + f)",
            (30, 30, 160),
        ),
        (
            DisparityModel::ViewAngle,
            "eq. 1: d = 2t/tan φ",
            (200, 120, 0),
        ),
    ];
    let mut curves = Vec::new();
    for (model, name, rgb) in models {
        let d = SirdsGeometry { model, ..g }.to_pixels()?;
        let pts: Vec<(f64, f64)> = (0..=100)
            .map(|i| {
                let z = i as f32 / 100.0;
                (f64::from(z), f64::from(d.separation(z)))
            })
            .collect();
        curves.push((name, pts, rgb));
    }
    let lo = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(f64::MAX, f64::min);
    let hi = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(0.0, f64::max);
    let mut c = Canvas::new(720, 380)?;
    let a = Axes {
        frame: (80.0, 20.0, 700.0, 300.0),
        x: (0.0, 1.0),
        y: ((lo - 5.0).floor(), (hi + 5.0).ceil()),
    };
    a.draw(
        &mut c,
        "nearness z (0 = background, 1 = front)",
        "separation d (px)",
        (10.0, 6.0),
    );
    for (_, pts, rgb) in &curves {
        a.curve(&mut c, pts, *rgb, 2.0);
    }
    let entries: Vec<(&str, (u8, u8, u8))> = curves.iter().map(|(n, _, rgb)| (*n, *rgb)).collect();
    a.legend(&mut c, &entries, true);
    c.text(
        390.0,
        348.0,
        SMALL,
        &format!(
            "TIW set-up: a = {} in, f = {} in, depth {}…{} in behind the image, {} dpi",
            g.eye_separation_in, g.viewing_distance_in, g.depth_near_in, g.depth_far_in, g.dpi
        ),
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// The strip algorithm on the course scene: the depth it encodes, and the SIRDS with its k
/// strips marked (each strip one render pass with shifted vertices).
///
/// # Errors
/// A render error.
pub fn passes(ctx: &Context) -> Result<Canvas> {
    let (s, frame) = rendered(ctx.scene, 400, 200, &[Output::Sirds], |s| {
        s.sirds.per_vertex.start = StripStart::Left;
    })?;
    let (depth, range) = scene_depth(&frame, &s)?;
    let d = s.sirds.geometry.to_pixels()?;
    let g = StripGeometry::new(
        &s.strip_objects(),
        &frame.views.center,
        &range,
        &d,
        s.sirds.cross_eyed,
    );
    let r = per_vertex(
        &g,
        s.width,
        s.height,
        &d,
        &s.sirds.pattern,
        &s.sirds.per_vertex,
        false,
    )?;
    let img = image::RgbaImage::from_raw(
        s.width,
        s.height,
        r.pixels.iter().flatten().copied().collect(),
    )
    .unwrap_or_default();
    let depth_img = image::RgbaImage::from_fn(s.width, s.height, |x, y| {
        let v = (depth.z[(y * s.width + x) as usize].clamp(0.0, 1.0) * 255.0).round() as u8;
        image::Rgba([v, v, v, 255])
    });
    let mut c = Canvas::new(s.width * 2 + 36, s.height + 90)?;
    c.text(
        12.0 + s.width as f32 / 2.0,
        6.0,
        LABEL,
        "nearness z (depth pass)",
        INK,
        TextAlign::Center,
    );
    c.text(
        24.0 + s.width as f32 * 1.5,
        6.0,
        LABEL,
        &format!("SIRDS: k = {} strips of {} px", r.iterations, r.strip_width),
        INK,
        TextAlign::Center,
    );
    c.image(&depth_img, 12, 30, 1);
    let x0 = 24 + s.width;
    c.image(&img, x0, 30, 1);
    for i in 0..r.iterations {
        let x = (x0 + i * r.strip_width) as f32;
        c.line((x, 30.0), (x, 30.0 + s.height as f32), (255, 200, 0), 1.5);
        let width = r.strip_width.min(s.width - i * r.strip_width);
        c.boxed_text(
            x + width as f32 / 2.0,
            34.0,
            SMALL,
            &format!("{}", i + 1),
            INK,
            TextAlign::Center,
        );
    }
    c.text(
        c.width() / 2.0,
        s.height as f32 + 40.0,
        SMALL,
        "strip 1 is the random pattern; pass i renders the scene shifted by d/2 (vertex right, texture",
        INK,
        TextAlign::Center,
    );
    c.text(
        c.width() / 2.0,
        s.height as f32 + 58.0,
        SMALL,
        &format!(
            "coordinate left) and copies from strip i − 1; strip width ≤ the front separation {:.0} px − 1",
            d.min_separation()
        ),
        INK,
        TextAlign::Center,
    );
    Ok(c)
}

fn sirds_variants(
    ctx: &Context,
    variants: &[(&str, StripStart, StripFilter)],
    crop: Option<(u32, u32, u32, u32)>,
    scale: u32,
) -> Result<Canvas> {
    let mut cells = Vec::new();
    for (name, start, filter) in variants {
        let (s, frame) = rendered(ctx.scene, 400, 200, &[Output::Sirds], |s| {
            s.sirds.per_vertex.start = *start;
            s.sirds.per_vertex.filter = *filter;
            s.sirds.guide_dots = true;
        })?;
        let mut img = from_frame(&frame, &s)?.to_rgba_image();
        if let Some((x, y, w, h)) = crop {
            img = image::imageops::crop_imm(&img, x, y, w, h).to_image();
        }
        cells.push((name.to_string(), img));
    }
    grid(&cells, 2, scale)
}

/// Left start against center start (the SIRDS paper's Fig. 7): distortion gathers on one side,
/// or is split between both.
///
/// # Errors
/// A render error.
pub fn start(ctx: &Context) -> Result<Canvas> {
    sirds_variants(
        ctx,
        &[
            ("start = \"left\"", StripStart::Left, StripFilter::Bilinear),
            (
                "start = \"center\"",
                StripStart::Center,
                StripFilter::Bilinear,
            ),
        ],
        None,
        1,
    )
}

/// Nearest against bilinear filtering of the copied strip (the SIRDS paper's Fig. 5), 3× crops.
///
/// # Errors
/// A render error.
pub fn filter(ctx: &Context) -> Result<Canvas> {
    sirds_variants(
        ctx,
        &[
            (
                "filter = \"nearest\" (3×)",
                StripStart::Left,
                StripFilter::Nearest,
            ),
            (
                "filter = \"bilinear\" (3×)",
                StripStart::Left,
                StripFilter::Bilinear,
            ),
        ],
        Some((200, 60, 80, 60)),
        3,
    )
}
