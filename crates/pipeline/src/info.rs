//! `stereolab info`: the derived cameras and the scene's parallax range (the StereoGraphics guide's budget).

use std::fmt::Write as _;

use crate::plan::{Shading, View};
use crate::render::{Frame, render_view};
use crate::scene::Scene;
use stereolab_core::{
    CameraMode, ParallaxBudget, Result, StereoRig, Viewer, parallax_budget_of, project_ndc,
};

use stereolab_core::PARALLAX_BUDGET_PERCENT;

/// Horizontal and vertical parallax range over the scene's vertices, in percent of image width
/// (horizontal) and height (vertical): `(x_right − x_left)` in NDC / 2 · 100.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParallaxRange {
    /// Most negative horizontal parallax (in front of the screen), % of width.
    pub min_percent: f32,
    /// Most positive horizontal parallax (behind the screen), % of width.
    pub max_percent: f32,
    /// Largest |vertical parallax|, % of height (non-zero only for toe-in).
    pub max_vertical_percent: f32,
    /// Vertices visible in both eyes that were measured.
    pub vertices: usize,
}

/// Parallax of every scene vertex that lies inside both eyes' frusta.
///
/// # Errors
/// Invalid camera or rig.
pub fn parallax_range(scene: &Scene) -> Result<ParallaxRange> {
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let mut r = ParallaxRange {
        min_percent: f32::INFINITY,
        max_percent: f32::NEG_INFINITY,
        max_vertical_percent: 0.0,
        vertices: 0,
    };
    let inside = |p: glam::Vec3| p.abs().max_element() <= 1.0;
    for p in scene.world_points() {
        let (Some(l), Some(rr)) = (project_ndc(&eyes[0].mvp, p), project_ndc(&eyes[1].mvp, p))
        else {
            continue;
        };
        if !inside(l) || !inside(rr) {
            continue;
        }
        let h = (rr.x - l.x) * 50.0;
        r.min_percent = r.min_percent.min(h);
        r.max_percent = r.max_percent.max(h);
        r.max_vertical_percent = r.max_vertical_percent.max(((rr.y - l.y) * 50.0).abs());
        r.vertices += 1;
    }
    Ok(r)
}

/// The text `stereolab info` prints.
///
/// # Errors
/// Invalid camera or rig.
pub fn describe(scene: &Scene) -> Result<String> {
    let mut s = String::new();
    let resolved = scene.rig.resolve(&scene.camera, scene.aspect())?;
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let center = StereoRig::center(&scene.camera, scene.aspect())?;
    let _ = writeln!(
        s,
        "image: {}x{}  aspect {:.4}",
        scene.width,
        scene.height,
        scene.aspect()
    );
    let _ = writeln!(
        s,
        "rig: {:?}, lighting {:?}{}",
        scene.rig.mode,
        scene.rig.lighting,
        match scene.rig.viewer {
            Viewer::Midpoint => "",
            Viewer::LeftEye => ", viewer at the left eye (camera.eye), right eye at +d",
        }
    );
    let _ = writeln!(
        s,
        "  eye separation d = {:.6} ({:?}, user_offset {})",
        resolved.eye_separation, scene.rig.separation, scene.rig.user_offset
    );
    let _ = writeln!(
        s,
        "  zero-parallax distance z0 = {:.6} ({:?}), user_balance {}",
        resolved.zero_parallax_distance, scene.rig.zero_parallax, scene.rig.user_balance
    );
    let _ = writeln!(s, "  view width at z0 (Xrange) = {:.6}", resolved.xrange);
    if let Some(line) = image_shift_line(scene)? {
        s.push_str(&line);
    }
    for (name, m) in [("center", center), ("left", eyes[0]), ("right", eyes[1])] {
        let f = m.frustum;
        let _ = write!(
            s,
            "  {name:6} eye at ({:.4}, {:.4}, {:.4})  frustum l={:.6} r={:.6} b={:.6} t={:.6} n={} f={}",
            m.eye_world.x, m.eye_world.y, m.eye_world.z, f[0], f[1], f[2], f[3], f[4], f[5]
        );
        if m.viewport_shift != 0 {
            let _ = write!(s, "  viewport moved {:+} px", m.viewport_shift);
        }
        s.push('\n');
    }
    let fov_x = horizontal_fov_degrees(scene.camera.fov_y, scene.aspect());
    let _ = writeln!(
        s,
        "  horizontal field of view {fov_x:.1}° (vertical {:.1}°)",
        scene.camera.fov_y
    );
    if fov_x < MIN_HORIZONTAL_FOV_DEGREES {
        let _ = writeln!(
            s,
            "warning: horizontal field of view {fov_x:.1}° is under {MIN_HORIZONTAL_FOV_DEGREES}°: \
             the StereoGraphics guide (Akka) §8 advises a wide angle (≥ {MIN_HORIZONTAL_FOV_DEGREES}°) \
             for strong depth cues; raise camera.fov_y"
        );
    }
    let budget = scene_budget(scene)?;
    s.push_str(&budget.report());
    if let Some(r) = budget_remedies(scene, &budget, resolved.eye_separation)? {
        s.push_str(&r);
    }
    let p = parallax_range(scene)?;
    if p.vertices == 0 {
        let _ = writeln!(s, "parallax: no vertex lies inside both frusta");
        return Ok(s);
    }
    let _ = writeln!(
        s,
        "parallax over {} vertices: {:+.3}% .. {:+.3}% of image width ({:+.1} .. {:+.1} px); max vertical {:.3}% of height",
        p.vertices,
        p.min_percent,
        p.max_percent,
        p.min_percent * scene.width as f32 / 100.0,
        p.max_percent * scene.width as f32 / 100.0,
        p.max_vertical_percent
    );
    if p.min_percent < -PARALLAX_BUDGET_PERCENT || p.max_percent > PARALLAX_BUDGET_PERCENT {
        let _ = writeln!(
            s,
            "warning: parallax exceeds the StereoGraphics guide's ~{PARALLAX_BUDGET_PERCENT}% budget; see the remedies above"
        );
    }
    if p.max_vertical_percent > 0.01 {
        let _ = writeln!(
            s,
            "warning: vertical parallax (toe-in?) of {:.3}% of height strains fusion (the StereoGraphics guide (Akka))",
            p.max_vertical_percent
        );
    }
    Ok(s)
}

/// For [`CameraMode::ImageShift`], the line saying how far each eye's image moved, how the
/// shift was rounded, and how many columns on each side hold one eye only; `None` otherwise.
///
/// # Errors
/// As [`StereoRig::image_shift`].
pub fn image_shift_line(scene: &Scene) -> Result<Option<String>> {
    if scene.rig.mode != CameraMode::ImageShift {
        return Ok(None);
    }
    let shift = scene
        .rig
        .image_shift(&scene.camera, scene.width, scene.height)?;
    Ok(Some(format!("  {}", shift.describe())))
}

/// The StereoGraphics guide (Akka) §8: stereo works best with a wide horizontal field of view.
pub const MIN_HORIZONTAL_FOV_DEGREES: f32 = 50.0;

/// Horizontal field of view from the vertical one: `2 atan(tan(fov_y/2) · aspect)`.
pub fn horizontal_fov_degrees(fov_y_degrees: f32, aspect: f32) -> f32 {
    2.0 * ((fov_y_degrees.to_radians() * 0.5).tan() * aspect)
        .atan()
        .to_degrees()
}

/// When the measured budget is exceeded, both remedies with numbers: the zero-parallax distance
/// `"fit"` would choose, and the eye separation that scales the present range into ±3%
/// (parallax is proportional to d at a fixed z0). `None` within budget.
///
/// # Errors
/// Invalid camera or rig.
pub fn budget_remedies(
    scene: &Scene,
    budget: &ParallaxBudget,
    eye_separation: f32,
) -> Result<Option<String>> {
    if budget.drawn == 0 {
        return Ok(None);
    }
    let worst = budget
        .percent(budget.min_pixels)
        .abs()
        .max(budget.percent(budget.max_pixels).abs());
    if worst <= PARALLAX_BUDGET_PERCENT as f64 {
        return Ok(None);
    }
    let mut s = format!(
        "  remedies (parallax reaches {worst:.2}% of width, budget ±{PARALLAX_BUDGET_PERCENT}%):\n"
    );
    if let Ok(z0) = scene.fitted_zero_parallax() {
        let _ = writeln!(
            s,
            "    move the zero-parallax plane: stereo.zero_parallax = {z0:.3} (or \"fit\")"
        );
    }
    let d = eye_separation as f64 * PARALLAX_BUDGET_PERCENT as f64 / worst;
    let _ = writeln!(
        s,
        "    or reduce the eye separation: stereo.eye_separation = {d:.4} (now {eye_separation:.4})"
    );
    Ok(Some(s))
}

/// The budget of a scene: renders the left eye depth-only (all `p(z)` needs) and measures it.
/// What `stereolab info` prints.
///
/// # Errors
/// Invalid camera or rig, or an image size refused by [`stereolab_core::Framebuffer::new`].
pub fn scene_budget(scene: &Scene) -> Result<ParallaxBudget> {
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let (fb, _) = render_view(scene, &eyes[0], Shading::DepthOnly)?;
    parallax_budget_of(&fb, &scene.parallax_rig()?)
}

/// The budget lines of the render report, from the frame's left eye depth (or the right eye's
/// when only that one was rendered); `None` when no eye pass ran.
///
/// # Errors
/// As [`parallax_budget_of`].
pub fn frame_budget_report(frame: &Frame, scene: &Scene) -> Result<Option<String>> {
    let rig = scene.parallax_rig()?;
    for (view, name) in [(View::Left, "left"), (View::Right, "right")] {
        if let Some(fb) = frame.view(view) {
            let b = parallax_budget_of(fb, &rig)?;
            let shift = image_shift_line(scene)?.unwrap_or_default();
            let step = depth_step_parallax(fb, &rig);
            let uncertain = if step > DEPTH_STEP_PARALLAX_WARN {
                format!(
                    "\n  warning: one step of the f32 depth buffer at the scene's nearest or \
                     farthest surface is worth {step:.2} px of parallax, so these parallax \
                     figures (read back from depth) are uncertain by that much; raise \
                     camera.near (or set raster.depth = \"reversed-z\"; `stereolab info` \
                     computes the range from the vertices instead)"
                )
            } else {
                String::new()
            };
            return Ok(Some(format!(
                "  {name} eye {}{shift}{uncertain}",
                b.report()
            )));
        }
    }
    Ok(None)
}

/// A depth step worth more parallax than this (pixels) makes the budget's figures uncertain.
pub const DEPTH_STEP_PARALLAX_WARN: f64 = 0.1;

/// The parallax, in pixels, of one step of the f32 depth buffer at the nearest and at the
/// farthest drawn depth of `fb` (the larger of the two): how far a budget read back from the
/// depth buffer can be off. 0 when nothing is drawn.
pub fn depth_step_parallax(
    fb: &stereolab_core::Framebuffer,
    rig: &stereolab_core::ParallaxRig,
) -> f64 {
    let drawn = fb.depth().iter().copied().filter(|d| *d < 1.0);
    let (lo, hi) = drawn.fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
        (lo.min(d), hi.max(d))
    });
    [lo, hi]
        .into_iter()
        .filter(|d| d.is_finite())
        .filter_map(|d| {
            let next = d.next_up();
            Some((rig.parallax_pixels(next)? - rig.parallax_pixels(d)?).abs())
        })
        .fold(0.0, f64::max)
}
