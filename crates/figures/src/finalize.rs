//! Multi-pass stereo and the finalize shader (two eye framebuffers, layouts, every anaglyph with
//! its matrices as numbers, linear against stored light), and remapping with occlusion.

use glam::DVec4;
use image::RgbaImage;

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, LEFT, RIGHT, SMALL};
use super::thumbs::{grid, image_of, rendered};
use stereolab::plan::{Output, View};
use stereolab_core::{
    AnaglyphKind, ColorMatrix, Error, OCCLUSION_FARTHER_COLOR, OCCLUSION_OCCLUDED_COLOR,
    OCCLUSION_OUT_OF_VIEW_COLOR, Precision, Remapper, Result, TextAlign, linear_to_srgb,
    srgb_to_linear,
};

/// The two eye framebuffers of one frame: color and depth each.
///
/// # Errors
/// A render error.
pub fn eye_buffers(ctx: &Context) -> Result<Canvas> {
    let outs = [
        Output::Left,
        Output::Right,
        Output::LeftDepth,
        Output::RightDepth,
    ];
    let (s, frame) = rendered(ctx.scene, 240, 180, &outs, |_| {})?;
    let cells = [
        ("left eye FBO: color", Output::Left),
        ("right eye FBO: color", Output::Right),
        ("left eye: depth (window z)", Output::LeftDepth),
        ("right eye: depth", Output::RightDepth),
    ]
    .into_iter()
    .map(|(t, o)| Ok((t.to_string(), image_of(o, &frame, &s)?)))
    .collect::<Result<Vec<_>>>()?;
    grid(&cells, 2, 1)
}

/// Stereo layouts of the same two eyes.
///
/// # Errors
/// A render error.
pub fn layouts(ctx: &Context) -> Result<Canvas> {
    let outs = [
        Output::SideBySide,
        Output::AboveBelowSquashed,
        Output::InterlacedRows,
        Output::Checkerboard,
    ];
    let (s, frame) = rendered(ctx.scene, 160, 120, &outs, |_| {})?;
    let mut cells = vec![(
        "side_by_side (left | right)".to_string(),
        image_of(Output::SideBySide, &frame, &s)?,
    )];
    cells.push((
        "above_below_squashed".to_string(),
        image_of(Output::AboveBelowSquashed, &frame, &s)?,
    ));
    // Interleavings shown 2× so their rows and pixels are visible.
    cells.push((
        "interlaced_rows (2×)".to_string(),
        crop(
            &image_of(Output::InterlacedRows, &frame, &s)?,
            40,
            30,
            80,
            60,
        )?,
    ));
    cells.push((
        "checkerboard (2×)".to_string(),
        crop(&image_of(Output::Checkerboard, &frame, &s)?, 40, 30, 80, 60)?,
    ));
    let top = grid(&cells[..2], 2, 1)?.to_image();
    let bottom = grid(&cells[2..], 2, 2)?.to_image();
    let mut c = Canvas::new(
        top.width().max(bottom.width()),
        top.height() + bottom.height(),
    )?;
    c.image(&top, 0, 0, 1);
    c.image(&bottom, 0, top.height(), 1);
    Ok(c)
}

fn crop(img: &RgbaImage, x: u32, y: u32, w: u32, h: u32) -> Result<RgbaImage> {
    if x + w > img.width() || y + h > img.height() {
        return Err(Error::internal("figures", "crop outside the image"));
    }
    Ok(image::imageops::crop_imm(img, x, y, w, h).to_image())
}

fn matrix(c: &mut Canvas, x: f32, y: f32, m: &ColorMatrix, rgb: (u8, u8, u8)) {
    for (r, row) in m.iter().enumerate() {
        for (k, v) in row.iter().enumerate() {
            let s = format!("{v:.3}").replace('-', "−");
            c.text(
                x + 58.0 * (k as f32 + 1.0),
                y + r as f32 * 18.0,
                SMALL,
                &s,
                if *v == 0.0 { GRAY } else { rgb },
                TextAlign::Right,
            );
        }
    }
    c.line((x, y - 2.0), (x, y + 52.0), INK, 1.0);
    c.line((x + 182.0, y - 2.0), (x + 182.0, y + 52.0), INK, 1.0);
}

fn anaglyph_table(ctx: &Context, kinds: &[AnaglyphKind]) -> Result<Canvas> {
    let outs: Vec<Output> = kinds.iter().map(|k| Output::Anaglyph(*k)).collect();
    let (s, frame) = rendered(ctx.scene, 120, 90, &outs, |_| {})?;
    let row_h = 100.0;
    let mut c = Canvas::new(720, (40.0 + row_h * kinds.len() as f32) as u32)?;
    c.text(235.0, 8.0, LABEL, "M_L (left eye)", LEFT, TextAlign::Center);
    c.text(
        445.0,
        8.0,
        LABEL,
        "M_R (right eye)",
        RIGHT,
        TextAlign::Center,
    );
    for (i, kind) in kinds.iter().enumerate() {
        let y = 34.0 + i as f32 * row_h;
        let img = image_of(Output::Anaglyph(*kind), &frame, &s)?;
        c.image(&img, 8, y as u32, 1);
        let m = kind.matrices();
        c.text(
            140.0,
            y + 2.0,
            LABEL,
            kind.output_name(),
            INK,
            TextAlign::Left,
        );
        matrix(&mut c, 140.0, y + 28.0, &m.left, LEFT);
        matrix(&mut c, 350.0, y + 28.0, &m.right, RIGHT);
        c.text(
            560.0,
            y + 46.0,
            SMALL,
            "out = clamp(",
            GRAY,
            TextAlign::Left,
        );
        c.text(
            560.0,
            y + 62.0,
            SMALL,
            " M_L·l + M_R·r)",
            GRAY,
            TextAlign::Left,
        );
    }
    Ok(c)
}

/// The first five anaglyphs with their matrices (the exercise slides' four, 3dtv.at's optimized).
///
/// # Errors
/// A render error.
pub fn anaglyphs_1(ctx: &Context) -> Result<Canvas> {
    anaglyph_table(ctx, &AnaglyphKind::ALL[..5])
}

/// The other four anaglyphs with their matrices (Dubois, green–magenta, amber–blue).
///
/// # Errors
/// A render error.
pub fn anaglyphs_2(ctx: &Context) -> Result<Canvas> {
    anaglyph_table(ctx, &AnaglyphKind::ALL[5..])
}

/// Stored (sRGB) against linear light: the transfer curve the finalize shader uses with
/// `linear_light`, and the Dubois anaglyph mixed both ways.
///
/// # Errors
/// A render error.
pub fn linear_light(ctx: &Context) -> Result<Canvas> {
    let kind = AnaglyphKind::DuboisRedCyan;
    let out = [Output::Anaglyph(kind)];
    let (s0, f0) = rendered(ctx.scene, 160, 120, &out, |s| {
        s.finalize.linear_light = false
    })?;
    let (s1, f1) = rendered(ctx.scene, 160, 120, &out, |s| {
        s.finalize.linear_light = true
    })?;
    let mut c = Canvas::new(720, 330)?;
    let a = Axes {
        frame: (70.0, 20.0, 330.0, 260.0),
        x: (0.0, 1.0),
        y: (0.0, 1.0),
    };
    a.draw(&mut c, "stored value (sRGB)", "light (linear)", (5.0, 5.0));
    let pts: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let v = i as f32 / 100.0;
            (f64::from(v), f64::from(srgb_to_linear(v)))
        })
        .collect();
    a.curve(&mut c, &pts, (30, 30, 160), 2.0);
    a.curve(&mut c, &[(0.0, 0.0), (1.0, 1.0)], GRAY, 1.0);
    // The inverse drawn from the library too: must overlay the mirror image.
    let back: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let l = i as f32 / 100.0;
            (f64::from(linear_to_srgb(l)), f64::from(l))
        })
        .collect();
    a.curve(&mut c, &back, (200, 120, 0), 1.0);
    a.legend(
        &mut c,
        &[
            ("srgb_to_linear", (30, 30, 160)),
            ("linear_to_srgb⁻¹", (200, 120, 0)),
        ],
        false,
    );
    let img0 = image_of(out[0], &f0, &s0)?;
    let img1 = image_of(out[0], &f1, &s1)?;
    c.text(
        460.0,
        14.0,
        SMALL,
        "mixed as stored",
        INK,
        TextAlign::Center,
    );
    c.image(&img0, 380, 34, 1);
    c.text(
        640.0,
        14.0,
        SMALL,
        "mixed in linear light",
        INK,
        TextAlign::Center,
    );
    c.image(&img1, 560, 34, 1);
    c.text(
        550.0,
        170.0,
        SMALL,
        "anaglyph_dubois, [finalize] linear_light",
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}

/// One pixel through `MVP_r · MVP_l⁻¹`, step by step, with the numbers of the course scene,
/// checked against [`Remapper::remap`] (the remap output's own shader).
///
/// # Errors
/// A render error, or the step-by-step numbers disagree with the remapper (a bug).
pub fn remap_one_pixel(ctx: &Context) -> Result<Canvas> {
    let (w, h) = (240u32, 180u32);
    let (s, frame) = rendered(ctx.scene, w, h, &[Output::Left, Output::Right], |_| {})?;
    let left = frame
        .view(View::Left)
        .ok_or_else(|| Error::internal("figures", "no left pass"))?;
    // The covered pixel nearest the image center.
    let (x, y) = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| left.depth()[left.index(x, y)] < 1.0)
        .min_by_key(|&(x, y)| {
            let (dx, dy) = (
                i64::from(x) - i64::from(w / 2 - 30),
                i64::from(y) - i64::from(h / 2),
            );
            dx * dx + dy * dy
        })
        .ok_or_else(|| Error::internal("figures", "the left eye sees nothing"))?;
    let depth = left.depth()[left.index(x, y)];
    let (ml, mr) = (frame.views.eyes[0].mvp, frame.views.eyes[1].mvp);
    let r = Remapper::new(&ml, &mr, w, h, Precision::F64)?;
    let remapped = r
        .remap(x, y, depth)
        .ok_or_else(|| Error::internal("figures", "pixel behind the right eye"))?;
    // The same steps written out.
    let ndc_l = DVec4::new(
        2.0 * (f64::from(x) + 0.5) / f64::from(w) - 1.0,
        1.0 - 2.0 * (f64::from(y) + 0.5) / f64::from(h),
        2.0 * f64::from(depth) - 1.0,
        1.0,
    );
    let clip = mr.as_dmat4() * ml.as_dmat4().inverse() * ndc_l;
    let ndc_r = clip.truncate() / clip.w;
    let tex = [0.5 * (ndc_r.x + 1.0), 0.5 * (ndc_r.y + 1.0)];
    if (tex[0] - remapped.tex[0]).abs() > 1e-9 || (tex[1] - remapped.tex[1]).abs() > 1e-9 {
        return Err(Error::internal(
            "figures",
            format!(
                "remap steps {tex:?} disagree with Remapper {:?}",
                remapped.tex
            ),
        ));
    }
    let [wx, wy] = remapped.window(w, h);
    let lines = [
        format!("1. left pixel (x, y) = ({x}, {y}), window depth d = {depth:.5}"),
        format!(
            "2. NDC_l = (2(x+½)/W − 1, 1 − 2(y+½)/H, 2d − 1, 1) = ({:.4}, {:.4}, {:.4}, 1)",
            ndc_l.x, ndc_l.y, ndc_l.z
        ),
        format!(
            "3. clip_r = MVP_r · MVP_l⁻¹ · NDC_l = ({:.4}, {:.4}, {:.4}, {:.4})",
            clip.x, clip.y, clip.z, clip.w
        ),
        format!(
            "4. NDC_r = clip_r.xyz / clip_r.w = ({:.4}, {:.4}, {:.4})",
            ndc_r.x, ndc_r.y, ndc_r.z
        ),
        format!(
            "5. τ = ½(NDC_r.xy + 1) = ({:.4}, {:.4}) → right pixel ({wx:.2}, {wy:.2})",
            tex[0], tex[1]
        ),
        format!(
            "   horizontal shift {:+.2} px; depth in the right eye {:.5}",
            wx - (f64::from(x) + 0.5),
            remapped.depth
        ),
    ];
    let mut c = Canvas::new(540, 200 + 26 * lines.len() as u32 + 10)?;
    let li = image_of(Output::Left, &frame, &s)?;
    let ri = image_of(Output::Right, &frame, &s)?;
    c.text(130.0, 6.0, LABEL, "left eye", LEFT, TextAlign::Center);
    c.text(400.0, 6.0, LABEL, "right eye", RIGHT, TextAlign::Center);
    c.image(&li, 10, 26, 1);
    c.image(&ri, 280, 26, 1);
    let pl = (10.0 + x as f32 + 0.5, 26.0 + y as f32 + 0.5);
    let pr = (280.0 + wx as f32, 26.0 + wy as f32);
    c.circle(pl, 6.0, (255, 220, 0), 2.0);
    c.circle(pr, 6.0, (255, 220, 0), 2.0);
    c.arrow((pl.0 + 8.0, pl.1), (pr.0 - 8.0, pr.1), (255, 220, 0), 1.5);
    for (i, l) in lines.iter().enumerate() {
        c.text(
            10.0,
            214.0 + 26.0 * i as f32,
            SMALL,
            l,
            INK,
            TextAlign::Left,
        );
    }
    Ok(c)
}

/// Remapping and the visibility check on the course scene: the left eye, the left eye
/// recolored from the right, and the occlusion map with its legend.
///
/// # Errors
/// A render error.
pub fn remap_occlusion(ctx: &Context) -> Result<Canvas> {
    let outs = [Output::Left, Output::RemapLeft, Output::Occlusion];
    let (s, frame) = rendered(ctx.scene, 200, 150, &outs, |_| {})?;
    let occ = image_of(Output::Occlusion, &frame, &s)?;
    let cells = [
        ("left eye".to_string(), image_of(Output::Left, &frame, &s)?),
        (
            "remap_left: from the right eye".to_string(),
            image_of(Output::RemapLeft, &frame, &s)?,
        ),
        ("occlusion (left | right)".to_string(), occ),
    ];
    let top = grid(&cells[..2], 2, 1)?.to_image();
    let bottom = grid(&cells[2..], 1, 1)?.to_image();
    let mut c = Canvas::new(
        top.width().max(bottom.width()),
        top.height() + bottom.height() + 84,
    )?;
    c.image(&top, 0, 0, 1);
    c.image(&bottom, 0, top.height(), 1);
    let y0 = (top.height() + bottom.height()) as f32;
    let rgb = |c: [u8; 4]| (c[0], c[1], c[2]);
    for (i, (label, color)) in [
        (
            "seen by both eyes (gray: nearer is lighter)",
            (170, 170, 170),
        ),
        ("occluded in the other eye", rgb(OCCLUSION_OCCLUDED_COLOR)),
        (
            "outside the other eye's view",
            rgb(OCCLUSION_OUT_OF_VIEW_COLOR),
        ),
        (
            "farther there: a silhouette sampling artifact",
            rgb(OCCLUSION_FARTHER_COLOR),
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let y = y0 + i as f32 * 20.0;
        c.fill_rect((14.0, y + 2.0), (28.0, y + 16.0), color, 255);
        c.text(36.0, y, SMALL, label, INK, TextAlign::Left);
    }
    Ok(c)
}

/// Julesz's random-dot pair of the course scene (the `rds_*` outputs): random dots in the left
/// eye, the same dots through the remap and the visibility check in the right (fresh dots where
/// only the right eye sees), and their anaglyph, where the shape appears in depth.
///
/// # Errors
/// A render error.
pub fn rds_pair(ctx: &Context) -> Result<Canvas> {
    let outs = [Output::RdsLeft, Output::RdsRight, Output::RdsAnaglyph];
    let (s, frame) = rendered(ctx.scene, 240, 180, &outs, |_| {})?;
    let cells = [
        (
            "rds_left: random dots".to_string(),
            image_of(Output::RdsLeft, &frame, &s)?,
        ),
        (
            "rds_right: remapped dots".to_string(),
            image_of(Output::RdsRight, &frame, &s)?,
        ),
        (
            "rds_anaglyph: the pair".to_string(),
            image_of(Output::RdsAnaglyph, &frame, &s)?,
        ),
    ];
    grid(&cells, 3, 1)
}
