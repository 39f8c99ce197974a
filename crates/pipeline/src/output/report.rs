//! Lines of the render report that come from the outputs' effects: the ChromaDepth range the
//! pass used and the crosstalk (ghosting) contrast warning. `stereolab render` prints them after
//! the passes and the parallax budget.

use crate::plan::{Output, View};
use crate::render::Frame;
use crate::render::chromadepth::resolve_texgen;
use crate::scene::Scene;
use stereolab_core::{GhostingSettings, Result, contrast_warning, ghost_risk, linear_to_srgb};

/// The report lines for `frame` (each without indentation or newline):
///
/// - when a ChromaDepth pass ran: the D1/D2 it used (the ChromaDepth article's texgen range,
///   red at D1, blue at D2) and where each came from (the scene, or the bounding sphere);
/// - when a ghosting output was asked for: the leak per channel;
/// - when a ghosting or cancelled output was asked for and `ghosting.cancel` is above 0: how
///   far the cancellation lifted black (`cancel · leak` in linear light, and as 8-bit sRGB);
/// - when both eyes were rendered in color: the ghosting contrast warning of each eye whose
///   dark pixels lie under bright ones of the other eye in a band at least 1% of the width
///   wide ([`ghost_risk`]); nothing for a scene without such edges.
///
/// # Errors
/// The ChromaDepth range cannot be resolved, or the eyes differ in size.
pub fn effect_lines(frame: &Frame, scene: &Scene) -> Result<Vec<String>> {
    let mut lines = Vec::new();
    let chroma = [
        Output::ChromaDepth,
        Output::ChromaDepthLeft,
        Output::ChromaDepthRight,
        Output::ChromaDepthAnaglyph,
    ];
    if frame.plan.outputs.iter().any(|o| chroma.contains(o)) {
        let s = &scene.chromadepth;
        let t = resolve_texgen(scene, &frame.views.center, s)?;
        let from = |given: Option<f32>| {
            if given.is_some() {
                "scene"
            } else {
                "bounding sphere"
            }
        };
        lines.push(format!(
            "chromadepth: D1 = {:.4} ({}), D2 = {:.4} ({}): red at D1, blue at D2 (eye distances)",
            t.d1,
            from(s.d1),
            t.d2,
            from(s.d2)
        ));
    }
    if frame
        .plan
        .outputs
        .iter()
        .any(|o| matches!(o, Output::GhostingLeft | Output::GhostingRight))
    {
        let [r, g, b] = scene.ghosting.leak;
        lines.push(format!(
            "ghosting: leak of the other eye in linear light R {r}, G {g}, B {b}"
        ));
    }
    let cancelling = frame.plan.outputs.iter().any(|o| {
        matches!(
            o,
            Output::GhostingLeft
                | Output::GhostingRight
                | Output::CancelledLeft
                | Output::CancelledRight
        )
    });
    if cancelling && scene.ghosting.cancel > 0.0 {
        lines.push(black_lift_line(&scene.ghosting));
    }
    let color = |v| {
        frame
            .passes
            .iter()
            .find(|p| p.pass.view == v && p.pass.shading == crate::plan::Shading::Color)
            .map(|p| &p.framebuffer)
    };
    if let (Some(left), Some(right)) = (color(View::Left), color(View::Right)) {
        for (this, other, name, other_name) in [
            (left, right, "left", "right"),
            (right, left, "right", "left"),
        ] {
            if let Some(w) = contrast_warning(name, other_name, &ghost_risk(this, other)?) {
                lines.push(w);
            }
        }
    }
    Ok(lines)
}

/// The report's line on crosstalk cancellation: black lifted to `cancel · leak` per channel
/// (the darkest each eye can be seen once the other eye's leak is cancelled).
pub fn black_lift_line(s: &GhostingSettings) -> String {
    let lift = s.cancelled_leak();
    let [r, g, b] = lift;
    let [r8, g8, b8] = lift.map(|l| (linear_to_srgb(l) * 255.0).round() as u8);
    format!(
        "ghosting: cancel {}: black lifted to linear R {r}, G {g}, B {b} (8-bit sRGB {r8}, {g8}, \
         {b8}); each eye is seen as lift + (1 - lift) x its own image",
        s.cancel
    )
}
