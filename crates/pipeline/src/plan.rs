//! Outputs → the passes they need, nothing more (standing demand 3: simulate only the effects
//! a scene calls for).

use std::fmt::Write as _;

use stereolab_core::{
    AnaglyphGlasses, AnaglyphKind, AnaglyphMethod, Error, Eye, MAX_VIEWS, Result,
};

/// The views a multiview output renders when the scene has no `[multiview]` section: the rig's
/// own two eyes (Blender's default multi-view setup, "Stereo 3D", is the left/right pair).
pub const DEFAULT_VIEWS: u8 = 2;

/// Everything a scene can ask `stereolab render` to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Output {
    /// Left eye color.
    Left,
    /// Right eye color.
    Right,
    /// Left eye depth (16-bit grayscale).
    LeftDepth,
    /// Right eye depth (16-bit grayscale).
    RightDepth,
    /// Left | right, for parallel (wall-eyed) free viewing.
    SideBySide,
    /// Right | left, for cross-eyed free viewing.
    CrossEyed,
    /// Left on top of right, each full size.
    AboveBelow,
    /// The StereoGraphics guide's sync-doubling format: both eyes squashed 1:2 into one frame, left on top,
    /// separated by a black blank interval.
    AboveBelowSquashed,
    /// Frame-compatible half side by side (3D TVs, projectors, Bino): both views squeezed to
    /// half the width in one eye-sized frame, left on the left (box filter in linear light).
    HalfSideBySide,
    /// Frame-compatible half above-below (top-and-bottom): both views squeezed to half the
    /// height in one eye-sized frame, left on top (box filter in linear light).
    HalfAboveBelow,
    /// HDMI 1.4a frame packing: left view, active space (black: 45 rows at 1080p, 30 at 720p),
    /// right view, full size (1920×2205 for 1080p).
    FramePacking,
    /// Even rows left, odd rows right (row-interleaved polarized displays).
    InterlacedRows,
    /// Even columns left, odd columns right (column-interleaved displays).
    InterlacedColumns,
    /// Left where x + y is even, right elsewhere (DLP checkerboard).
    Checkerboard,
    /// The ChromaDepth article's ChromaDepth image: depth as a red → green → blue ramp, one center-eye pass.
    ChromaDepth,
    /// The left eye's view of the ChromaDepth image through the glasses (simulated).
    ChromaDepthLeft,
    /// The right eye's view of the ChromaDepth image through the glasses (simulated).
    ChromaDepthRight,
    /// Both simulated views as a red–cyan anaglyph, for viewers without ChromaDepth glasses.
    ChromaDepthAnaglyph,
    /// `anaglyph_<kind>`: both eyes' colors mixed by the kind's matrices (the exercise slides;
    /// three.js's method × glasses table as `anaglyph_<method>_<glasses>`).
    Anaglyph(AnaglyphKind),
    /// The left eye's view recolored from the right eye by remapping (the exercise slides).
    RemapLeft,
    /// The right eye's view recolored from the left eye.
    RemapRight,
    /// Per eye, what it sees that the other eye cannot (remapping + visibility check).
    Occlusion,
    /// The left eye's parallax `p(z) = d(1 − z0/z)` as color with a legend (the exercise slides).
    Parallax,
    /// Single-image random-dot stereogram of the cyclopean view (the SIRDS paper (Petz et al.)).
    Sirds,
    /// The depth map the SIRDS encodes (16-bit, white = near).
    SirdsDepth,
    /// The SIRDS paper's Fig. 5: the scene's SIRDS in three horizontal bands, eq. 3 bilinear
    /// (top), eq. 1 bilinear (middle), eq. 3 nearest (bottom: discrete depth layers).
    SirdsFig5,
    /// Left and right as a CIPA DC-007 multi-picture JPEG (`mpo.mpo`), what stereo cameras
    /// write and 3D viewers open.
    Mpo,
    /// Right | left side by side in one JPEG (`jps.jps`), the cross-eyed order viewers expect.
    Jps,
    /// Right | left side by side in one PNG (`pns.pns`).
    Pns,
    /// The SGI course notes' §4.1.3 "Rotate vs. Shear" side by side: the same frame from the
    /// off-axis (shear) and toe-in (rotate) rigs, toe-in's vertical parallax per pixel, and the
    /// difference of the two rigs' left images.
    ShearVsRotate,
    /// Julesz's random-dot stereo pair, left eye: a seeded random-dot texture, no shape in it.
    RdsLeft,
    /// The right eye's view of the left eye's dots through the remap: the scene's depth as
    /// parallax only.
    RdsRight,
    /// Both random-dot images as a gray red–cyan anaglyph.
    RdsAnaglyph,
    /// Both eyes as an animated PNG alternating left, right, … at the scene's rate: the
    /// quad-buffered (`BACK_LEFT` / `BACK_RIGHT`) shutter-glasses display, emulated.
    FrameSequential,
    /// The left eye with a share of the right eye leaking in per channel (crosstalk, the
    /// StereoGraphics guide's ghosting).
    GhostingLeft,
    /// The right eye with a share of the left eye leaking in.
    GhostingRight,
    /// The left eye corrected for crosstalk (`ghosting.cancel`), as sent to the display:
    /// crosstalk cancellation by subtraction with black lifted (Bino's ghostbusting).
    CancelledLeft,
    /// The right eye corrected for crosstalk, as sent to the display.
    CancelledRight,
    /// The StereoGraphics guide's above-below calibration screen: two arrows that line up when
    /// `layout.blank_interval` matches the display's blank interval. Needs no pass.
    AboveBelowCalibration,
    /// Wiggle stereoscopy as StereoPhoto Maker (Masuji Suto) exports it: left and right
    /// alternating forever, `wiggle.frame_ms` each, as an animated GIF (`wiggle_gif.gif`).
    WiggleGif,
    /// The same wiggle as an animated PNG (`wiggle_apng.png`), lossless.
    WiggleApng,
    /// The scene's N views (`multiview.views`, N cameras on the rig's baseline) as tiles of
    /// one image, row-major from the top left (`view_grid`).
    ViewTiles(u8),
    /// The N views interleaved column by column for a lenticular sheet, the rightmost view
    /// first under each lenticule (`lenticular_view`).
    ViewInterleaved(u8),
}

/// Which camera a pass renders from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum View {
    /// The left eye (index 0).
    Left,
    /// The right eye (index 1).
    Right,
    /// The cyclopean eye: the camera itself.
    Center,
    /// The scene's rig as off-axis (shear), left eye: one side of [`Output::ShearVsRotate`].
    ShearLeft,
    /// The scene's rig as off-axis (shear), right eye.
    ShearRight,
    /// The scene's rig as toe-in (rotate), left eye: the other side of [`Output::ShearVsRotate`].
    RotateLeft,
    /// The scene's rig as toe-in (rotate), right eye.
    RotateRight,
    /// Camera `i` of the scene's N multiview cameras on the rig's baseline, 0 the leftmost
    /// (`StereoRig::views`).
    Multi(u8),
}

impl From<Eye> for View {
    /// The pass of one eye of the scene's rig.
    fn from(eye: Eye) -> View {
        match eye {
            Eye::Left => View::Left,
            Eye::Right => View::Right,
        }
    }
}

/// What a pass computes per fragment.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Shading {
    /// Depth only: no fragment shading at all.
    DepthOnly,
    /// Shaded color (and depth).
    Color,
    /// ChromaDepth: color from the depth ramp (and depth), the ChromaDepth article.
    ChromaDepth,
}

/// One rasterization pass over the whole scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Pass {
    /// The camera.
    pub view: View,
    /// Depth only, or shaded.
    pub shading: Shading,
}

impl Output {
    /// Every output, in the order `--help` lists them.
    pub const ALL: &'static [Output] = &[
        Output::Left,
        Output::Right,
        Output::LeftDepth,
        Output::RightDepth,
        Output::SideBySide,
        Output::CrossEyed,
        Output::AboveBelow,
        Output::AboveBelowSquashed,
        Output::HalfSideBySide,
        Output::HalfAboveBelow,
        Output::FramePacking,
        Output::InterlacedRows,
        Output::InterlacedColumns,
        Output::Checkerboard,
        Output::ChromaDepth,
        Output::ChromaDepthLeft,
        Output::ChromaDepthRight,
        Output::ChromaDepthAnaglyph,
        Output::Anaglyph(AnaglyphKind::True),
        Output::Anaglyph(AnaglyphKind::Gray),
        Output::Anaglyph(AnaglyphKind::Color),
        Output::Anaglyph(AnaglyphKind::HalfColor),
        Output::Anaglyph(AnaglyphKind::Optimized),
        Output::Anaglyph(AnaglyphKind::DuboisRedCyan),
        Output::Anaglyph(AnaglyphKind::DuboisRedCyanLcd),
        Output::Anaglyph(AnaglyphKind::DuboisGreenMagenta),
        Output::Anaglyph(AnaglyphKind::DuboisAmberBlue),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::True,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::True,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::True,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Grey,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Grey,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Grey,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Colour,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Colour,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Colour,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::HalfColour,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::HalfColour,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::HalfColour,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Dubois,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Dubois,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Dubois,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Optimised,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Optimised,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Optimised,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Compromise,
            AnaglyphGlasses::RedCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Compromise,
            AnaglyphGlasses::MagentaCyan,
        )),
        Output::Anaglyph(AnaglyphKind::ThreeJs(
            AnaglyphMethod::Compromise,
            AnaglyphGlasses::MagentaGreen,
        )),
        Output::RemapLeft,
        Output::RemapRight,
        Output::Occlusion,
        Output::Parallax,
        Output::Sirds,
        Output::SirdsDepth,
        Output::SirdsFig5,
        Output::Mpo,
        Output::Jps,
        Output::Pns,
        Output::ShearVsRotate,
        Output::RdsLeft,
        Output::RdsRight,
        Output::RdsAnaglyph,
        Output::FrameSequential,
        Output::GhostingLeft,
        Output::GhostingRight,
        Output::CancelledLeft,
        Output::CancelledRight,
        Output::AboveBelowCalibration,
        Output::WiggleGif,
        Output::WiggleApng,
        Output::ViewTiles(DEFAULT_VIEWS),
        Output::ViewInterleaved(DEFAULT_VIEWS),
    ];

    /// Everything this output is, in one row: its name, its file, the passes it reads.
    /// [`output::produce`](crate::output::produce) makes it from those passes.
    pub fn spec(self) -> OutputSpec {
        use View::{Center, Left, Right, RotateLeft, RotateRight, ShearLeft, ShearRight};
        const PAIR: &[Pass] = &[color(Left), color(Right)];
        const CENTER_DEPTH: &[Pass] = &[depth(Center)];
        // One center pass, no stereo pair: the glasses make the pair (the ChromaDepth article).
        const CHROMADEPTH: &[Pass] = &[Pass {
            view: Center,
            shading: Shading::ChromaDepth,
        }];
        let png = |name, needs| OutputSpec {
            name,
            extension: "png",
            needs,
        };
        match self {
            Output::Left => png("left", const { &[color(Left)] }),
            Output::Right => png("right", const { &[color(Right)] }),
            Output::LeftDepth => png("left_depth", const { &[depth(Left)] }),
            Output::RightDepth => png("right_depth", const { &[depth(Right)] }),
            Output::SideBySide => png("side_by_side", PAIR),
            Output::CrossEyed => png("cross_eyed", PAIR),
            Output::AboveBelow => png("above_below", PAIR),
            Output::AboveBelowSquashed => png("above_below_squashed", PAIR),
            Output::HalfSideBySide => png("half_side_by_side", PAIR),
            Output::HalfAboveBelow => png("half_above_below", PAIR),
            Output::FramePacking => png("frame_packing", PAIR),
            Output::InterlacedRows => png("interlaced_rows", PAIR),
            Output::InterlacedColumns => png("interlaced_columns", PAIR),
            Output::Checkerboard => png("checkerboard", PAIR),
            Output::ChromaDepth => png("chromadepth", CHROMADEPTH),
            Output::ChromaDepthLeft => png("chromadepth_left", CHROMADEPTH),
            Output::ChromaDepthRight => png("chromadepth_right", CHROMADEPTH),
            Output::ChromaDepthAnaglyph => png("chromadepth_anaglyph", CHROMADEPTH),
            Output::Anaglyph(kind) => png(kind.output_name(), PAIR),
            // Remapping unprojects this eye's depth and fetches the other eye's color.
            Output::RemapLeft => png("remap_left", const { &[depth(Left), color(Right)] }),
            Output::RemapRight => png("remap_right", const { &[color(Left), depth(Right)] }),
            // The visibility check compares depths only.
            Output::Occlusion => png("occlusion", const { &[depth(Left), depth(Right)] }),
            // p(z) needs the left eye's depth and the rig, nothing else.
            Output::Parallax => png("parallax", const { &[depth(Left)] }),
            // One depth pass of the cyclopean view; no color shading at all (the SIRDS paper
            // (Petz et al.)).
            Output::Sirds => png("sirds", CENTER_DEPTH),
            Output::SirdsDepth => png("sirds_depth", CENTER_DEPTH),
            Output::SirdsFig5 => png("sirds_fig5", CENTER_DEPTH),
            Output::Mpo => OutputSpec {
                name: "mpo",
                extension: "mpo",
                needs: PAIR,
            },
            Output::Jps => OutputSpec {
                name: "jps",
                extension: "jps",
                needs: PAIR,
            },
            Output::Pns => OutputSpec {
                name: "pns",
                extension: "pns",
                needs: PAIR,
            },
            // Both rigs' eye passes, whatever the scene's own mode: the comparison is the point.
            Output::ShearVsRotate => png(
                "shear_vs_rotate",
                const {
                    &[
                        color(ShearLeft),
                        color(ShearRight),
                        color(RotateLeft),
                        color(RotateRight),
                    ]
                },
            ),
            // The left eye's dots are the texture itself, whatever the scene holds.
            Output::RdsLeft => png("rds_left", &[]),
            // The dots are painted, not shaded: the remap needs both eyes' depths only.
            Output::RdsRight => png("rds_right", const { &[depth(Left), depth(Right)] }),
            Output::RdsAnaglyph => png("rds_anaglyph", const { &[depth(Left), depth(Right)] }),
            Output::FrameSequential => png("frame_sequential", PAIR),
            Output::GhostingLeft => png("ghosting_left", PAIR),
            Output::GhostingRight => png("ghosting_right", PAIR),
            Output::CancelledLeft => png("cancelled_left", PAIR),
            Output::CancelledRight => png("cancelled_right", PAIR),
            // A test pattern of the layout alone: no pass at all.
            Output::AboveBelowCalibration => png("above_below_calibration", &[]),
            Output::WiggleGif => OutputSpec {
                name: "wiggle_gif",
                extension: "gif",
                needs: PAIR,
            },
            Output::WiggleApng => png("wiggle_apng", PAIR),
            // The first N of the multiview passes, N the scene's `multiview.views`.
            Output::ViewTiles(n) => png("view_tiles", multi_passes(n)),
            Output::ViewInterleaved(n) => png("view_interleaved", multi_passes(n)),
        }
    }

    /// The name used in scene files and for the file written.
    pub fn name(self) -> &'static str {
        self.spec().name
    }

    /// The file an output is written to: `<name>.png`, or `<name>.mpo|jps|pns` for the
    /// stereo photo formats.
    pub fn file_name(self) -> String {
        let spec = self.spec();
        format!("{}.{}", spec.name, spec.extension)
    }

    /// Parses a name as written in a scene file.
    ///
    /// # Errors
    /// `Invalid` listing the known names.
    pub fn parse(name: &str) -> Result<Output> {
        Output::ALL
            .iter()
            .copied()
            .find(|o| o.name() == name)
            .ok_or_else(|| {
                let known: Vec<&str> = Output::ALL.iter().map(|o| o.name()).collect();
                Error::invalid(
                    "outputs",
                    format!("\"{}\"", stereolab_core::excerpt(name)),
                    format!("unknown output; known: {}", known.join(", ")),
                )
            })
    }

    /// How many multiview cameras this output renders (`multiview.views`); `None` for the
    /// outputs of the stereo pair and the center eye.
    pub fn views(self) -> Option<u8> {
        match self {
            Output::ViewTiles(n) | Output::ViewInterleaved(n) => Some(n),
            _ => None,
        }
    }

    /// This output with its multiview camera count set to `views` (others as they are).
    pub fn with_views(self, views: u8) -> Output {
        match self {
            Output::ViewTiles(_) => Output::ViewTiles(views),
            Output::ViewInterleaved(_) => Output::ViewInterleaved(views),
            o => o,
        }
    }

    /// The passes this output reads.
    pub fn needs(self) -> Vec<Pass> {
        self.spec().needs.to_vec()
    }
}

/// One output's row: what [`Output::spec`] gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutputSpec {
    /// The name in scene files and of the file written.
    pub name: &'static str,
    /// The file's extension: `png`, or the stereo photo format's.
    pub extension: &'static str,
    /// The passes the output reads (none for the random-dot texture and the calibration screen).
    pub needs: &'static [Pass],
}

/// The shaded passes of every multiview camera: [`multi_passes`] slices the first N.
static MULTI_PASSES: [Pass; MAX_VIEWS as usize] = {
    let mut passes = [color(View::Multi(0)); MAX_VIEWS as usize];
    let mut i = 0;
    while i < passes.len() {
        passes[i] = color(View::Multi(i as u8));
        i += 1;
    }
    passes
};

/// The shaded passes of the first `views` multiview cameras (at most [`MAX_VIEWS`]).
fn multi_passes(views: u8) -> &'static [Pass] {
    &MULTI_PASSES[..usize::from(views).min(MULTI_PASSES.len())]
}

/// A shaded pass of `view` (color and depth).
const fn color(view: View) -> Pass {
    Pass {
        view,
        shading: Shading::Color,
    }
}

/// A depth-only pass of `view`.
const fn depth(view: View) -> Pass {
    Pass {
        view,
        shading: Shading::DepthOnly,
    }
}

/// The passes a set of outputs needs. A color pass also produces depth, so a depth-only pass of
/// the same view is dropped when a color pass of it runs anyway; two different shadings of one
/// view (e.g. Blinn-Phong and ChromaDepth) stay separate passes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Requested outputs, deduplicated, in request order.
    pub outputs: Vec<Output>,
    /// Passes to run, sorted by view.
    pub passes: Vec<Pass>,
}

impl Plan {
    /// Builds the plan for `outputs`.
    pub fn new(outputs: &[Output]) -> Plan {
        let mut uniq: Vec<Output> = Vec::new();
        for o in outputs {
            if !uniq.contains(o) {
                uniq.push(*o);
            }
        }
        let mut passes: Vec<Pass> = uniq.iter().flat_map(|o| o.needs()).collect();
        passes.sort();
        passes.dedup();
        // Fold depth-only passes into a shaded pass of the same view.
        let mut merged: Vec<Pass> = Vec::new();
        for p in passes {
            let absorbs = |m: &Pass| {
                m.view == p.view
                    && (m.shading == Shading::DepthOnly || p.shading == Shading::DepthOnly)
            };
            match merged.iter_mut().find(|m| absorbs(m)) {
                Some(m) => m.shading = m.shading.max(p.shading),
                None => merged.push(p),
            }
        }
        Plan {
            outputs: uniq,
            passes: merged,
        }
    }

    /// The pass that renders `view`, if any.
    pub fn pass(&self, view: View) -> Option<Pass> {
        self.passes.iter().copied().find(|p| p.view == view)
    }

    /// Human-readable: which passes run, for which outputs, and which do not run.
    pub fn explain(&self) -> String {
        let mut s = String::from("plan:\n");
        for p in &self.passes {
            let users: Vec<&str> = self
                .outputs
                .iter()
                .filter(|o| {
                    o.needs().iter().any(|n| {
                        n.view == p.view
                            && (n.shading == p.shading || n.shading == Shading::DepthOnly)
                    })
                })
                .map(|o| o.name())
                .collect();
            let _ = writeln!(
                s,
                "  pass {:?} eye, {}: for {}",
                p.view,
                shading_name(p.shading),
                users.join(", ")
            );
        }
        for view in [View::Left, View::Right, View::Center] {
            if self.pass(view).is_none() {
                let _ = writeln!(s, "  not run: {view:?} eye (no requested output needs it)");
            }
        }
        let _ = writeln!(s, "  passes run: {}", self.passes.len());
        s
    }
}

fn shading_name(s: Shading) -> &'static str {
    match s {
        Shading::Color => "color + depth (shaded)",
        Shading::DepthOnly => "depth only (no shading)",
        Shading::ChromaDepth => "ChromaDepth ramp + depth (texgen)",
    }
}
