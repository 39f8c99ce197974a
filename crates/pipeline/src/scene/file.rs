//! The TOML scene format (serde), before validation.

use serde::Deserialize;

use stereolab_core::{Camera, CameraMode, ChromaDepthSettings, Lighting, Viewer};

/// A scene file as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneFile {
    /// Output image.
    pub image: ImageSpec,
    /// The (cyclopean) camera.
    pub camera: Camera,
    /// The stereo rig.
    #[serde(default)]
    pub stereo: StereoSpec,
    /// The light.
    #[serde(default)]
    pub light: LightSpec,
    /// Layout options.
    #[serde(default)]
    pub layout: LayoutSpec,
    /// Rasterizer options.
    #[serde(default)]
    pub raster: RasterSpec,
    /// ChromaDepth options (the ChromaDepth article).
    #[serde(default)]
    pub chromadepth: ChromaDepthSettings,
    /// Finalize-pass options (anaglyphs).
    #[serde(default)]
    pub finalize: FinalizeSpec,
    /// Autostereogram options.
    #[serde(default)]
    pub sirds: stereolab_core::SirdsSpec,
    /// Random-dot stereo pair options (`rds_left`, `rds_right`, `rds_anaglyph`).
    #[serde(default)]
    pub rds: stereolab_core::RdsSettings,
    /// Crosstalk options (`ghosting_left`, `ghosting_right`).
    #[serde(default)]
    pub ghosting: stereolab_core::GhostingSettings,
    /// Frame-sequential animation options (`frame_sequential`).
    #[serde(default)]
    pub frame_sequential: stereolab_core::FrameSequentialSettings,
    /// Wiggle animation options (`wiggle_gif`, `wiggle_apng`).
    #[serde(default)]
    pub wiggle: stereolab_core::WiggleSettings,
    /// Multiview options (`view_tiles`, `view_interleaved`).
    #[serde(default)]
    pub multiview: MultiviewSpec,
    /// Objects, in `[[mesh]]` tables.
    #[serde(default, rename = "mesh")]
    pub meshes: Vec<MeshSpec>,
    /// Requested outputs by name.
    pub outputs: Vec<String>,
}

/// `[multiview]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MultiviewSpec {
    /// Cameras on the rig's baseline, 2 to `MAX_VIEWS`, adjacent ones the rig's separation
    /// apart.
    pub views: u32,
}

impl Default for MultiviewSpec {
    fn default() -> Self {
        MultiviewSpec {
            views: u32::from(crate::plan::DEFAULT_VIEWS),
        }
    }
}

/// `[image]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ImageSpec {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Clear color, 0..1. Default mid-gray (the StereoGraphics guide (Akka): a gray background reduces ghosting).
    #[serde(default = "default_background")]
    pub background: [f32; 3],
}

fn default_background() -> [f32; 3] {
    [0.5, 0.5, 0.5]
}

/// Eye separation: a number or `"auto"`.
#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
pub(crate) enum SeparationSpec {
    /// World units.
    Value(f32),
    /// Should be `"auto"`.
    Word(String),
}

/// `[stereo]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct StereoSpec {
    /// `off-axis` (default), `toe-in`, `parallel`, `image-shift`.
    #[serde(default)]
    pub mode: CameraMode,
    /// Number or `"auto"` (default).
    #[serde(default)]
    pub eye_separation: Option<SeparationSpec>,
    /// Absolute zero-parallax distance, `"auto"` (the camera target's distance) or `"fit"`
    /// (the distance that centres the scene's depth range in the parallax budget).
    #[serde(default)]
    pub zero_parallax: Option<SeparationSpec>,
    /// Zero-parallax position between near (0) and far (1); default 0.5 if neither is given.
    #[serde(default)]
    pub zero_parallax_fraction: Option<f32>,
    /// The StereoGraphics guide's `UserOffsetAdjustment`.
    #[serde(default = "one")]
    pub user_offset: f32,
    /// The StereoGraphics guide's `UserBalanceAdjustment`.
    #[serde(default = "one")]
    pub user_balance: f32,
    /// `per-eye` (default) or `cyclopic`.
    #[serde(default)]
    pub lighting: Lighting,
    /// Where the camera position sits: `midpoint` (default, between the eyes) or `left-eye`.
    #[serde(default)]
    pub viewer: Viewer,
}

impl Default for StereoSpec {
    fn default() -> Self {
        StereoSpec {
            mode: CameraMode::OffAxis,
            eye_separation: None,
            zero_parallax: None,
            zero_parallax_fraction: None,
            user_offset: 1.0,
            user_balance: 1.0,
            lighting: Lighting::PerEye,
            viewer: Viewer::Midpoint,
        }
    }
}

fn one() -> f32 {
    1.0
}

/// `[light]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightSpec {
    /// World position.
    pub position: [f32; 3],
    /// Ambient 0..1.
    #[serde(default = "ambient")]
    pub ambient: f32,
    /// Specular 0..1.
    #[serde(default = "specular")]
    pub specular: f32,
    /// Blinn-Phong exponent.
    #[serde(default = "shininess")]
    pub shininess: f32,
}

fn ambient() -> f32 {
    0.15
}
fn specular() -> f32 {
    0.35
}
fn shininess() -> f32 {
    32.0
}

impl Default for LightSpec {
    fn default() -> Self {
        LightSpec {
            position: [5.0, 8.0, 10.0],
            ambient: ambient(),
            specular: specular(),
            shininess: shininess(),
        }
    }
}

/// `[layout]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct LayoutSpec {
    /// Black rows between the two views of `above_below_squashed` (the StereoGraphics guide (Akka): 20–50 typical).
    #[serde(default)]
    pub blank_interval: u32,
}

/// `[raster]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct RasterSpec {
    /// Back-face culling.
    #[serde(default)]
    pub cull_back: bool,
    /// Depth test precision: `standard` (lavapipe's f32 window depth, default), `reversed-z`,
    /// `f64`.
    #[serde(default)]
    pub depth: Option<String>,
    /// Reversed-Z with the far plane at infinity (key `n/w`); needs `depth = "reversed-z"`.
    #[serde(default)]
    pub infinite_far: bool,
}

/// `[finalize]`.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(crate) struct FinalizeSpec {
    /// Apply anaglyph matrices to linear-light values (decode sRGB, mix, encode).
    #[serde(default)]
    pub linear_light: bool,
    /// Swap the eyes in anaglyphs (glasses worn the other way round).
    #[serde(default)]
    pub swap_eyes: bool,
    /// Rendepth's anti-rivalry gamma stage after every anaglyph's mix.
    #[serde(default)]
    pub anti_rivalry: bool,
}

/// One `[[mesh]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MeshSpec {
    /// `obj`, `sphere`, `cube`, `torus`, `plane`, `triangles`, `terrain`, `dem`, `pdb`.
    pub kind: String,
    /// OBJ path (or terrain CSV, DEM image, PDB file), relative to the scene file.
    #[serde(default)]
    pub path: Option<String>,
    /// Radius (sphere), edge (cube, plane), major radius (torus).
    #[serde(default)]
    pub size: Option<f32>,
    /// Torus tube radius.
    #[serde(default)]
    pub minor: Option<f32>,
    /// Tessellation (segments / divisions).
    #[serde(default)]
    pub detail: Option<u32>,
    /// Triangle count for `triangles`; scattered points for `dem`.
    #[serde(default)]
    pub count: Option<u32>,
    /// `dem`: the grid's size on the map, `[east, north]`, scene units.
    #[serde(default)]
    pub extent: Option<[f64; 2]>,
    /// `dem`: the heights of gray 0 and full-scale white, scene units.
    #[serde(default)]
    pub heights: Option<[f64; 2]>,
    /// `dem`: seed of the point scatter.
    #[serde(default)]
    pub seed: Option<u64>,
    /// Translation (world).
    #[serde(default)]
    pub translate: [f32; 3],
    /// Rotation in degrees about X, then Y, then Z.
    #[serde(default)]
    pub rotate: [f32; 3],
    /// Uniform scale.
    #[serde(default = "one")]
    pub scale: f32,
    /// Material color 0..1.
    #[serde(default = "default_color")]
    pub color: [f32; 3],
}

fn default_color() -> [f32; 3] {
    [0.8, 0.8, 0.8]
}
