//! The scene file's optional `[sirds]` table, and its validated form.

use std::path::Path;

use serde::Deserialize;

use super::depthmap::DepthRange;
use super::disparity::{DisparityModel, Geometry};
use super::pattern::{GuideBoxes, GuidePlace, MAX_GUIDE_SIZE, Pattern};
use super::per_pixel::{MAX_OVERSAMPLE, PLANES, PerPixelOptions};
use crate::error::{Error, Result};
use crate::files::InputRoot;

/// Where the pattern strip sits (the SIRDS paper's Fig. 7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Start {
    /// At the left edge; iterations propagate right (§3).
    Left,
    /// In the center; iterations propagate right in the right half, left in the left half (§4:
    /// less blur far from the initial strip).
    #[default]
    Center,
}

/// How a fragment samples the previous image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Filter {
    /// The nearest pixel: exact copies, separations rounded to whole pixels (discrete depth
    /// layers, Fig. 5 bottom).
    Nearest,
    /// Linear between the two nearest pixels: smooth depth, some blur (Fig. 5 top).
    #[default]
    Bilinear,
}

/// Options of the strip algorithm.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PerVertexOptions {
    /// Left or center start.
    pub start: Start,
    /// Nearest or bilinear sampling.
    pub filter: Filter,
    /// Iterations k (the strip width is ⌈W / k⌉); `None`: the fewest the geometry allows.
    pub iterations: Option<u32>,
}

/// Which algorithm turns depth into an autostereogram.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    /// The SIRDS paper's strip algorithm: the scene rendered k times with shifted vertices.
    #[default]
    PerVertex,
    /// Thimbleby–Inglis–Witten on the depth pass's depth map.
    PerPixel,
}

/// Random-dot kinds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DotKind {
    /// Black and white dots.
    #[default]
    BlackWhite,
    /// Gray levels.
    Gray,
    /// RGB colors.
    Color,
}

/// `[sirds]` as written. Every field is optional; the defaults are TIW's set-up.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SirdsSpec {
    /// `per-vertex` (default) or `per-pixel`.
    #[serde(default)]
    pub algorithm: Algorithm,
    /// `eye-distance` (eq. 3, default) or `view-angle` (eq. 1).
    #[serde(default, deserialize_with = "model_names::deserialize")]
    pub model: DisparityModel,
    /// Eye separation in inches (2.5).
    pub eye_separation_in: Option<f32>,
    /// Output resolution (72 DPI).
    pub dpi: Option<f32>,
    /// Eye to image plane, inches (12).
    pub viewing_distance_in: Option<f32>,
    /// Depth behind the image plane of the nearest scene point, inches (8).
    pub depth_near_in: Option<f32>,
    /// Depth behind the image plane of the background plane, inches (12).
    pub depth_far_in: Option<f32>,
    /// Eq. 1's angle φ, degrees (default: eq. 2 at the background plane).
    pub view_angle_deg: Option<f32>,
    /// Eye-space distance shown at the front of the depth range (default: nearest visible).
    pub front: Option<f32>,
    /// Eye-space distance of the background plane (default: 10% behind the farthest visible).
    pub back: Option<f32>,
    /// `left` or `center` (default).
    #[serde(default, deserialize_with = "start_names::deserialize")]
    pub start: Start,
    /// `nearest` or `bilinear` (default).
    #[serde(default, deserialize_with = "filter_names::deserialize")]
    pub filter: Filter,
    /// Strip iterations k (default: the fewest the front separation allows).
    pub iterations: Option<u32>,
    /// TIW hidden-surface removal (default true).
    pub hidden_surface: Option<bool>,
    /// TIW horizontal oversampling (default 1).
    pub oversample: Option<u32>,
    /// `black-white` (default), `gray` or `color` random dots.
    #[serde(default)]
    pub dots: DotKind,
    /// A pattern image to tile instead of random dots (relative to the scene file).
    pub pattern_image: Option<String>,
    /// Random-dot seed (default 1).
    pub seed: Option<u64>,
    /// Draw two guide dots near the top.
    #[serde(default)]
    pub guide_dots: bool,
    /// View cross-eyed (inverts depth) instead of wall-eyed.
    #[serde(default)]
    pub cross_eyed: bool,
    /// A texture image (relative to the scene file) for a mapped-texture stereogram
    /// (per-pixel only).
    pub texture: Option<String>,
    /// The texture's background color, `[r, g, b]` 0..=255 (default: its top-left pixel).
    pub texture_background: Option<[u8; 3]>,
    /// Links wrap around each row, so the image tiles horizontally (per-pixel only).
    #[serde(default)]
    pub tileable: bool,
    /// Depth quantised to this many planes, 2..=255 (per-pixel only).
    pub planes: Option<u32>,
    /// pamstereogram's guide boxes: `top`, `bottom` or `both`.
    #[serde(default, deserialize_with = "guide_names::deserialize")]
    pub guides: Option<GuidePlace>,
    /// Side of each guide box in pixels (default 20).
    pub guide_size: Option<u32>,
}

macro_rules! names {
    ($module:ident, $ty:ty, $($name:literal => $value:expr),+) => {
        mod $module {
            use super::*;
            pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<$ty, D::Error> {
                let s = String::deserialize(d)?;
                match s.as_str() {
                    $($name => Ok($value),)+
                    other => Err(serde::de::Error::custom(format!(
                        "unknown value \"{other}\"; known: {}", [$($name),+].join(", ")
                    ))),
                }
            }
        }
    };
}
names!(model_names, DisparityModel, "eye-distance" => DisparityModel::EyeDistance, "view-angle" => DisparityModel::ViewAngle);
names!(start_names, Start, "left" => Start::Left, "center" => Start::Center);
names!(filter_names, Filter, "nearest" => Filter::Nearest, "bilinear" => Filter::Bilinear);
names!(guide_names, Option<GuidePlace>, "top" => Some(GuidePlace::Top), "bottom" => Some(GuidePlace::Bottom), "both" => Some(GuidePlace::Both));

/// `[sirds]` validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Algorithm.
    pub algorithm: Algorithm,
    /// Physical set-up.
    pub geometry: Geometry,
    /// Fixed front distance, if given.
    pub front: Option<f32>,
    /// Fixed background-plane distance, if given.
    pub back: Option<f32>,
    /// Strip algorithm options.
    pub per_vertex: PerVertexOptions,
    /// TIW options.
    pub per_pixel: PerPixelOptions,
    /// Free-pixel pattern.
    pub pattern: Pattern,
    /// Guide dots.
    pub guide_dots: bool,
    /// Cross-eyed viewing.
    pub cross_eyed: bool,
    /// pamstereogram's guide boxes, if asked.
    pub guide_boxes: Option<GuideBoxes>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings::from_spec(&SirdsSpec::default(), &InputRoot::anywhere(Path::new("")))
            .expect("defaults are valid")
    }
}

impl Settings {
    /// One line for `stereolab render --explain`: the algorithm and the options of
    /// pamstereogram's set in use (texture, tileable, planes, guides).
    pub fn describe(&self) -> String {
        let mut parts = vec![match self.algorithm {
            Algorithm::PerVertex => "per-vertex strips".to_string(),
            Algorithm::PerPixel => "per-pixel (TIW)".to_string(),
        }];
        if let Pattern::Textured(t) = &self.pattern {
            let (w, h) = t.texture.dimensions();
            parts.push(format!("mapped texture {w}×{h}"));
        }
        if self.per_pixel.tileable {
            parts.push("tileable".to_string());
        }
        if let Some(n) = self.per_pixel.planes {
            parts.push(format!("{n} depth planes"));
        }
        if self.guide_dots {
            parts.push("guide dots".to_string());
        }
        if let Some(g) = self.guide_boxes {
            let place = match g.place {
                GuidePlace::Top => "top",
                GuidePlace::Bottom => "bottom",
                GuidePlace::Both => "top and bottom",
            };
            parts.push(format!("guide boxes {place}, {} px", g.size));
        }
        parts.join(", ")
    }

    /// The options that only TIW (per-pixel) makes: the first one set, by its field name.
    pub fn per_pixel_only(&self) -> Option<&'static str> {
        if matches!(self.pattern, Pattern::Textured(_)) {
            Some("sirds.texture")
        } else if self.per_pixel.tileable {
            Some("sirds.tileable")
        } else if self.per_pixel.planes.is_some() {
            Some("sirds.planes")
        } else {
            None
        }
    }

    /// Validates `spec`; a pattern image path is resolved by `root` (the scene's folder).
    ///
    /// # Errors
    /// The first invalid `sirds.*` field, or an unreadable pattern image.
    pub fn from_spec(spec: &SirdsSpec, root: &InputRoot) -> Result<Settings> {
        let g = Geometry::default();
        let geometry = Geometry {
            model: spec.model,
            eye_separation_in: spec.eye_separation_in.unwrap_or(g.eye_separation_in),
            dpi: spec.dpi.unwrap_or(g.dpi),
            viewing_distance_in: spec.viewing_distance_in.unwrap_or(g.viewing_distance_in),
            depth_near_in: spec.depth_near_in.unwrap_or(g.depth_near_in),
            depth_far_in: spec.depth_far_in.unwrap_or(g.depth_far_in),
            view_angle_deg: spec.view_angle_deg,
        };
        geometry.to_pixels()?;
        if let (Some(front), Some(back)) = (spec.front, spec.back) {
            DepthRange { front, back }.validate()?;
        }
        for (name, v) in [("sirds.front", spec.front), ("sirds.back", spec.back)] {
            if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(Error::invalid(name, v, "must be a finite distance > 0"));
            }
        }
        let oversample = spec.oversample.unwrap_or(1);
        if !(1..=MAX_OVERSAMPLE).contains(&oversample) {
            return Err(Error::invalid(
                "sirds.oversample",
                oversample,
                format!("must lie in 1..={MAX_OVERSAMPLE}"),
            ));
        }
        if spec.iterations == Some(0) {
            return Err(Error::invalid("sirds.iterations", 0, "must be at least 1"));
        }
        if let Some(n) = spec.planes.filter(|n| !PLANES.contains(n)) {
            return Err(Error::invalid(
                "sirds.planes",
                n,
                format!(
                    "must lie in {}..={} (the number of depth planes)",
                    PLANES.start(),
                    PLANES.end()
                ),
            ));
        }
        let guide_size = spec.guide_size.unwrap_or(20);
        if !(1..=MAX_GUIDE_SIZE).contains(&guide_size) {
            return Err(Error::invalid(
                "sirds.guide_size",
                guide_size,
                format!("must lie in 1..={MAX_GUIDE_SIZE} pixels"),
            ));
        }
        if spec.guide_size.is_some() && spec.guides.is_none() {
            return Err(Error::invalid(
                "sirds.guide_size",
                guide_size,
                "sizes the guide boxes: set sirds.guides = \"top\", \"bottom\" or \"both\" too",
            ));
        }
        let seed = spec.seed.unwrap_or(1);
        let pattern = match &spec.pattern_image {
            Some(p) => Pattern::load_image(&root.resolve("sirds.pattern_image", p)?)?,
            None => match spec.dots {
                DotKind::BlackWhite => Pattern::BlackWhite { seed },
                DotKind::Gray => Pattern::Gray { seed },
                DotKind::Color => Pattern::Color { seed },
            },
        };
        let pattern = match &spec.texture {
            Some(p) => {
                let path = root.resolve("sirds.texture", p)?;
                Pattern::textured(&path, pattern, spec.texture_background)?
            }
            None if spec.texture_background.is_some() => {
                return Err(Error::invalid(
                    "sirds.texture_background",
                    format!("{:?}", spec.texture_background.unwrap_or_default()),
                    "is the background color of sirds.texture: set sirds.texture too",
                ));
            }
            None => pattern,
        };
        Ok(Settings {
            algorithm: spec.algorithm,
            geometry,
            front: spec.front,
            back: spec.back,
            per_vertex: PerVertexOptions {
                start: spec.start,
                filter: spec.filter,
                iterations: spec.iterations,
            },
            per_pixel: PerPixelOptions {
                hidden_surface: spec.hidden_surface.unwrap_or(true),
                oversample,
                tileable: spec.tileable,
                planes: spec.planes,
            },
            pattern,
            guide_dots: spec.guide_dots,
            cross_eyed: spec.cross_eyed,
            guide_boxes: spec.guides.map(|place| GuideBoxes {
                place,
                size: guide_size,
            }),
        })
    }
}
