//! ChromaDepth (the ChromaDepth article): depth coded as a red → green → blue ramp in one center-eye pass, and
//! the glasses simulation that turns it into a stereo pair for viewers without the glasses.
//!
//! - [`ramp`]: the 1D texture (HSV red–green–blue or red–white–blue), clamped at both ends.
//! - [`texgen`]: the eye-linear plane `s = A x + B y + C z + D`, D1/D2 from the scene or from the
//!   bounding sphere.
//! - the pass itself (per-vertex or per-pixel texgen, optionally lit) is
//!   `render::chromadepth` (the `stereolab` crate).
//! - [`glasses`]: each eye's view through the diffraction-grating lenses.

pub mod glasses;
pub mod ramp;
pub mod texgen;

use serde::Deserialize;

use crate::effects::anaglyph::{self, AnaglyphKind, AnaglyphOptions};
use crate::error::{Error, Result};
use crate::framebuffer::Framebuffer;
use ramp::{DEFAULT_TEXELS, RampKind, Sampling};

/// Where `s` is evaluated.
///
/// Measured (`stereolab bench`, plane slanted 70°): per-vertex with perspective-correct
/// interpolation is exact to rounding (`s` is affine in eye space) and a little faster than
/// per-pixel, whose depth round trip costs a division and a few ulps; only affine interpolation
/// makes per-vertex visibly wrong. Hence per-vertex is the default, as in OpenGL.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TexgenMode {
    /// OpenGL's texgen: `s` at the vertices, interpolated across the triangle.
    #[default]
    PerVertex,
    /// `s` from each pixel's own eye depth, whatever the varying interpolation does.
    PerPixel,
}

/// The scene's `[chromadepth]` table (all optional), also adjustable with
/// `--set chromadepth.d1=…`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChromaDepthSettings {
    /// Distance in front of the eye where the ramp starts (red); automatic when absent.
    pub d1: Option<f32>,
    /// Distance in front of the eye where the ramp ends (blue); automatic when absent.
    pub d2: Option<f32>,
    /// `hsv` (red–green–blue, default) or `red-white-blue`.
    pub ramp: RampKind,
    /// Texels in the ramp texture (default 256).
    pub texels: usize,
    /// `linear` (default) or `nearest`.
    pub sampling: Sampling,
    /// `per-vertex` (default) or `per-pixel`.
    pub texgen: TexgenMode,
    /// Modulate the ramp by diffuse lighting, keeping its hue.
    pub lit: bool,
    /// How far the glasses move the reddest pixel inward in each eye, as a fraction of the image
    /// width (default 0.01: red–blue parallax 2% of the width, inside the StereoGraphics guide's ~3% budget).
    pub glasses_shift: f32,
    /// The anaglyph that shows the simulated glasses pair, by kind name (`gray` default: every
    /// ChromaDepth hue reaches both eyes, where a color anaglyph shows pure red to the left eye
    /// only and pure blue to the right eye only, so those regions cannot fuse).
    pub anaglyph: String,
}

impl Default for ChromaDepthSettings {
    fn default() -> Self {
        ChromaDepthSettings {
            d1: None,
            d2: None,
            ramp: RampKind::Hsv,
            texels: DEFAULT_TEXELS,
            sampling: Sampling::Linear,
            texgen: TexgenMode::PerVertex,
            lit: false,
            glasses_shift: 0.01,
            anaglyph: "gray".into(),
        }
    }
}

impl ChromaDepthSettings {
    /// Checks what can be checked before rendering (automatic D1/D2 are checked when resolved).
    ///
    /// # Errors
    /// `Invalid` naming the field: non-finite D1/D2, D1/D2 ≤ 0 (behind the eye), D1 == D2, D1 > D2, texels outside
    /// 2..=65536, glasses shift outside 0..=0.1.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("chromadepth.d1", self.d1), ("chromadepth.d2", self.d2)] {
            if let Some(v) = v.filter(|v| !v.is_finite()) {
                return Err(Error::invalid(name, v, "must be a finite distance"));
            }
            if let Some(v) = v.filter(|v| *v <= 0.0) {
                return Err(Error::invalid(
                    name,
                    v,
                    "must be a distance > 0 in front of the eye (eye-space depth; behind the \
                     eye nothing is drawn); leave it out for the automatic range",
                ));
            }
        }
        if let (Some(d1), Some(d2)) = (self.d1, self.d2) {
            texgen::Texgen::from_range(d1, d2)?;
        }
        ramp::Ramp::new(self.ramp, self.texels)?;
        self.anaglyph_kind()?;
        if !(0.0..=0.1).contains(&self.glasses_shift) {
            return Err(Error::invalid(
                "chromadepth.glasses_shift",
                self.glasses_shift,
                "must lie in 0..=0.1 (fraction of the image width)",
            ));
        }
        Ok(())
    }

    /// The anaglyph kind named by `anaglyph`.
    ///
    /// # Errors
    /// An unknown kind name.
    pub fn anaglyph_kind(&self) -> Result<AnaglyphKind> {
        let every = || AnaglyphKind::ALL.into_iter().chain(AnaglyphKind::THREE_JS);
        every()
            .find(|k| k.output_name().strip_prefix("anaglyph_") == Some(self.anaglyph.as_str()))
            .ok_or_else(|| {
                let known: Vec<&str> = every()
                    .filter_map(|k| k.output_name().strip_prefix("anaglyph_"))
                    .collect();
                Error::invalid(
                    "chromadepth.anaglyph",
                    format!("\"{}\"", self.anaglyph),
                    format!("known kinds: {}", known.join(", ")),
                )
            })
    }

    /// The glasses' largest inward shift in pixels for an image `width` pixels wide.
    pub fn max_shift_px(&self, width: u32) -> f32 {
        self.glasses_shift * width as f32
    }
}

/// Which image to make from the ChromaDepth pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChromaDepthView {
    /// The ChromaDepth image itself (what the glasses look at).
    Image,
    /// The left eye's view through the glasses.
    Left,
    /// The right eye's view through the glasses.
    Right,
    /// Both views as an anaglyph (`chromadepth.anaglyph`, default gray).
    Anaglyph,
}

/// Makes `view` from the ChromaDepth pass `fb`: the image itself, one eye's view through the
/// glasses, or both views as an anaglyph.
///
/// # Errors
/// An unknown `chromadepth.anaglyph` kind, or an anaglyph error.
pub fn chromadepth_view(
    fb: &Framebuffer,
    view: ChromaDepthView,
    settings: &ChromaDepthSettings,
) -> Result<Framebuffer> {
    let shift = settings.max_shift_px(fb.width);
    let eye = |eye| glasses::glasses_view(fb, eye, shift);
    Ok(match view {
        ChromaDepthView::Image => fb.clone(),
        ChromaDepthView::Left => eye(glasses::Eye::Left),
        ChromaDepthView::Right => eye(glasses::Eye::Right),
        ChromaDepthView::Anaglyph => {
            let [left, right] = glasses::glasses_pair(fb, shift);
            let image = anaglyph::anaglyph(
                &left,
                &right,
                settings.anaglyph_kind()?,
                AnaglyphOptions::default(),
            )?;
            let mut out = right;
            for (o, p) in out.color.iter_mut().zip(image.pixels()) {
                *o = p.0;
            }
            out
        }
    })
}
