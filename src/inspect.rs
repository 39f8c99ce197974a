//! `stereolab inspect`: another program's stereo picture read back as two views, its layout
//! given or detected, and the views written out.

use std::path::PathBuf;

use clap::Args;
use stereolab::inspect::{self, Layout};
use stereolab_core::{Error, OutputSet, Result};

/// Arguments of `stereolab inspect`.
#[derive(Args)]
pub struct InspectArgs {
    /// One picture holding both views (any layout `--layout` names, or .mpo/.jps/.pns), or a
    /// left and a right picture.
    #[arg(required = true, num_args = 1..=2)]
    pub images: Vec<PathBuf>,
    /// The layout instead of detecting it: side_by_side, cross_eyed, half_side_by_side,
    /// above_below, half_above_below, above_below_squashed, frame_packing, interlaced_rows,
    /// interlaced_columns, checkerboard, anaglyph_red_cyan, anaglyph_green_magenta,
    /// anaglyph_amber_blue.
    #[arg(long)]
    pub layout: Option<String>,
    /// A scene whose rig the pair should have: its exact parallax is compared with the
    /// measured one, and a disagreement named (swapped eyes, a shift, a wrong separation or
    /// zero-parallax distance).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// With --scene: override a scene field (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE", requires = "scene")]
    pub sets: Vec<String>,
    /// Warnings (parallax past the guide's budget, window violations) fail the run too.
    #[arg(long)]
    pub strict: bool,
    /// Folder for the two views read back (`left.png`, `right.png`), the disparity map with
    /// its legend (`disparity.png`), and both beside the left view with the findings drawn on
    /// it (`inspect.png`: vertical disparity as arrows, window violations).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Then open the viewer on the pair (`stereolab view --images`): anaglyphs, side by side,
    /// the disparity map, the image shift.
    #[cfg(feature = "viewer")]
    #[arg(long)]
    pub view: bool,
}

/// Runs `stereolab inspect`: `Ok(false)` when a finding is an error (or, with `--strict`, a
/// warning), so the exit status tells another project's CI.
///
/// # Errors
/// An unreadable picture, a layout that does not fit it, or none found.
pub fn run(args: InspectArgs) -> Result<bool> {
    let layout = args.layout.as_deref().map(Layout::parse).transpose()?;
    let views = inspect::read(&args.images, layout)?;
    let names: Vec<String> = args
        .images
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    outln!("inspect: {}", names.join(", "));
    outln!("  layout: {} ({})", views.layout.name(), views.evidence);
    let (w, h) = views.left.dimensions();
    outln!(
        "  views: {w}×{h} each{}",
        if views.layout.gray_views() {
            ", gray (each eye's filter channels)"
        } else {
            ""
        }
    );
    let measured = inspect::measure(&views)?;
    out!("{}", inspect::describe(&measured));
    let mut findings = inspect::findings(&measured);
    let samples = inspect::vertical_samples(&views, &measured);
    let fit = inspect::fit_vertical(&samples, w, h);
    out!("{}", inspect::describe_vertical(fit.as_ref(), w));
    findings.extend(inspect::vertical_findings(fit.as_ref(), w));
    if views.layout.gray_views()
        && let [picture] = args.images.as_slice()
    {
        let img = inspect::open(picture)?;
        let estimate = inspect::anaglyph::estimate(&img, views.layout, inspect::reach(&measured));
        out!("{}", estimate.describe());
    }
    let order = inspect::eyes::eye_order(&views, &measured);
    out!("{}", order.describe());
    out!("{}", inspect::findings::lines(&order.findings()));
    findings.extend(order.findings());
    if let Some(path) = &args.scene {
        let scene = super::load_scene(path, &args.sets, None)?;
        let (reference, at_infinity) = inspect::reference_parallax(&scene, w, h)?;
        match inspect::compare_reference(&measured, &reference, at_infinity) {
            Some(r) => {
                out!("{}", inspect::describe_reference(&r));
                findings.extend(inspect::reference_findings(&r));
            }
            None => outln!(
                "  against the scene: fewer than 100 pixels both matched and drawn by the scene"
            ),
        }
    }
    if let Some(dir) = &args.out {
        let paths = [
            dir.join("left.png"),
            dir.join("right.png"),
            dir.join("disparity.png"),
            dir.join("inspect.png"),
        ];
        for p in &paths {
            stereolab_core::check_output_path(p)?;
        }
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let mut set = OutputSet::new();
        set.stage_png(&paths[0], &views.left)?;
        set.stage_png(&paths[1], &views.right)?;
        set.stage_png(&paths[2], &inspect::disparity_image(&measured)?)?;
        let picture =
            inspect::picture::findings_picture(&views.left, &measured, &samples, &findings)?;
        set.stage_png(&paths[3], &picture)?;
        for p in set.commit()? {
            outln!("  wrote {}", p.display());
        }
    }
    let (verdict, passed) = inspect::findings::verdict(&findings, args.strict);
    out!("{verdict}");
    #[cfg(feature = "viewer")]
    if args.view {
        super::view::view_inspected(views, &args.images, measured)?;
    }
    Ok(passed)
}
