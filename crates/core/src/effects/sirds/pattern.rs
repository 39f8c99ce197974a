//! What fills the free pixels: seeded random dots or a tiled pattern image, plus guide dots.

use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Result};

/// The source of colors for pixels no constraint fixes.
#[derive(Clone, Debug, PartialEq)]
pub enum Pattern {
    /// Random black or white dots.
    BlackWhite {
        /// Seed (the scene file's `sirds.seed`).
        seed: u64,
    },
    /// Random gray levels.
    Gray {
        /// Seed.
        seed: u64,
    },
    /// Random RGB colors.
    Color {
        /// Seed.
        seed: u64,
    },
    /// A pattern image tiled over the plane; at least as wide as the largest separation.
    Image(Arc<image::RgbaImage>),
    /// A mapped-texture stereogram (`sirds.texture`): the texture colors the linked pixels,
    /// the inner pattern the pixels whose texels are all background.
    Textured(Arc<Textured>),
}

/// Largest side of a `sirds.texture` image, in pixels.
pub const MAX_TEXTURE_SIDE: u32 = 4096;

/// The texture of a mapped-texture stereogram (pamstereogram's `-texfile`, netpbm's
/// pamstereogram manual by Scott Pakin, "Mapped-texture Stereograms"): image pixel (x, y)
/// samples texel (x mod width, y mod height), so a texture of the depth map's size lies on it
/// pixel for pixel (pamstereogram requires that size; a smaller one repeats). Every set of
/// pixels the links force to one color takes the mean of its members' texels, leaving out
/// texels of the background color (as pamstereogram ignores "the texture image's background
/// color when blending colors"); a set whose texels are all background takes `base`.
#[derive(Clone, Debug, PartialEq)]
pub struct Textured {
    /// The texture.
    pub texture: image::RgbaImage,
    /// Its background color: `sirds.texture_background`, else its top-left pixel
    /// (pamstereogram picks one automatically; `-bgcolor` sets it).
    pub background: [u8; 4],
    /// The pattern of the background sets.
    pub base: Pattern,
}

impl Textured {
    /// Texel of image pixel (x, y): (x mod width, y mod height).
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> [u8; 4] {
        let (w, h) = self.texture.dimensions();
        self.texture.get_pixel(x % w, y % h).0
    }
}

/// SplitMix64's finalizer: a well-mixed 64-bit hash, so every pixel's dot is a pure function of
/// (seed, x, y) — the same bytes for any thread count.
#[inline]
pub(crate) fn mix(mut v: u64) -> u64 {
    v = (v ^ (v >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    v = (v ^ (v >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    v ^ (v >> 31)
}

#[inline]
fn random(seed: u64, x: u32, y: u32) -> u64 {
    mix(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (((y as u64) << 32) | x as u64))
}

impl Pattern {
    /// Loads a pattern image.
    ///
    /// # Errors
    /// The file cannot be read or decoded.
    pub fn load_image(path: &Path) -> Result<Pattern> {
        let img = crate::framebuffer::open_image(path, "pattern image")?;
        Ok(Pattern::Image(Arc::new(img.to_rgba8())))
    }

    /// `base` with the texture at `path` (`sirds.texture`): a mapped-texture stereogram whose
    /// background color is `background` (`sirds.texture_background`, pamstereogram's
    /// `-bgcolor`), or the texture's top-left pixel.
    ///
    /// # Errors
    /// `Invalid` naming `sirds.texture` for a file that is not a readable image or has a side
    /// above [`MAX_TEXTURE_SIDE`].
    pub fn textured(path: &Path, base: Pattern, background: Option<[u8; 3]>) -> Result<Pattern> {
        let img = crate::framebuffer::open_image(path, "texture").map_err(|e| {
            Error::invalid(
                "sirds.texture",
                path.display(),
                format!("must be a readable PNG, JPEG or netpbm image ({e})"),
            )
        })?;
        let (w, h) = (img.width(), img.height());
        if w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
            return Err(Error::invalid(
                "sirds.texture",
                format!("{w}×{h} image"),
                format!("must be at most {MAX_TEXTURE_SIDE} pixels a side: scale it down"),
            ));
        }
        let texture = img.to_rgba8();
        let background = match background {
            Some([r, g, b]) => [r, g, b, 255],
            None => texture.get_pixel(0, 0).0,
        };
        Ok(Pattern::Textured(Arc::new(Textured {
            texture,
            background,
            base,
        })))
    }

    /// The same kind of pattern with another seed (animation: a new pattern per frame).
    pub fn reseeded(&self, seed: u64) -> Pattern {
        match self {
            Pattern::BlackWhite { .. } => Pattern::BlackWhite { seed },
            Pattern::Gray { .. } => Pattern::Gray { seed },
            Pattern::Color { .. } => Pattern::Color { seed },
            Pattern::Image(i) => Pattern::Image(i.clone()),
            Pattern::Textured(t) => Pattern::Textured(Arc::new(Textured {
                base: t.base.reseeded(seed),
                ..(**t).clone()
            })),
        }
    }

    /// Checks that the pattern suits separations up to `max_separation` pixels: a pattern image
    /// narrower than that would repeat inside one link and show a false depth plane.
    ///
    /// # Errors
    /// `Invalid` naming `sirds.pattern` for an empty or too narrow image.
    pub fn check(&self, max_separation: f32) -> Result<()> {
        if let Pattern::Image(img) = self {
            let (w, h) = img.dimensions();
            if w == 0 || h == 0 || (w as f32) < max_separation {
                return Err(Error::invalid(
                    "sirds.pattern",
                    format!("{w}×{h} image"),
                    format!(
                        "must be at least the largest separation ({max_separation:.1} px) wide"
                    ),
                ));
            }
        }
        if let Pattern::Textured(t) = self {
            let (w, h) = t.texture.dimensions();
            if w == 0 || h == 0 || (w as f32) < max_separation {
                return Err(Error::invalid(
                    "sirds.texture",
                    format!("{w}×{h} image"),
                    format!(
                        "must be at least the largest separation ({max_separation:.1} px) wide: \
                         use a wider texture (best the depth map's size)"
                    ),
                ));
            }
            t.base.check(max_separation)?;
        }
        Ok(())
    }

    /// Whether every color of the pattern is a gray (R = G = B): black-white and gray dots.
    /// (A pattern image is not asked; it may hold colors.)
    pub fn is_gray(&self) -> bool {
        matches!(self, Pattern::BlackWhite { .. } | Pattern::Gray { .. })
    }

    /// Color of pattern pixel (x, y).
    #[inline]
    pub fn color(&self, x: u32, y: u32) -> [u8; 4] {
        match self {
            Pattern::BlackWhite { seed } => {
                let v = if random(*seed, x, y) & 1 == 0 { 0 } else { 255 };
                [v, v, v, 255]
            }
            Pattern::Gray { seed } => {
                let v = (random(*seed, x, y) >> 24) as u8;
                [v, v, v, 255]
            }
            Pattern::Color { seed } => {
                let r = random(*seed, x, y);
                [(r >> 8) as u8, (r >> 24) as u8, (r >> 40) as u8, 255]
            }
            Pattern::Image(img) => {
                let (w, h) = img.dimensions();
                img.get_pixel(x % w, y % h).0
            }
            Pattern::Textured(t) => t.base.color(x, y),
        }
    }

    /// Row `y` of the pattern into `row` (columns `0..row.len()`): the same colors as
    /// [`Pattern::color`], with the pattern kind decided once per row.
    pub fn fill_row(&self, y: u32, row: &mut [[u8; 4]]) {
        self.fill_span(0, y, row);
    }

    /// Columns `x0 .. x0 + span.len()` of row `y` into `span`: the same colors as
    /// [`Pattern::color`], with the pattern kind decided once per span.
    pub fn fill_span(&self, x0: u32, y: u32, span: &mut [[u8; 4]]) {
        self.fill_span_inline(x0, y, span);
    }

    /// [`Pattern::fill_span`] compiled for AVX2, for the AVX2 loops: the same code, which the
    /// compiler then runs four random dots at a time.
    ///
    /// # Safety
    /// The CPU must support AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(crate) unsafe fn fill_span_avx2(&self, x0: u32, y: u32, span: &mut [[u8; 4]]) {
        self.fill_span_inline(x0, y, span);
    }

    #[inline(always)]
    fn fill_span_inline(&self, x0: u32, y: u32, span: &mut [[u8; 4]]) {
        let xs = span.iter_mut().zip(x0..);
        match self {
            Pattern::BlackWhite { seed } => {
                for (p, x) in xs {
                    let v = if random(*seed, x, y) & 1 == 0 { 0 } else { 255 };
                    *p = [v, v, v, 255];
                }
            }
            Pattern::Gray { seed } => {
                for (p, x) in xs {
                    let v = (random(*seed, x, y) >> 24) as u8;
                    *p = [v, v, v, 255];
                }
            }
            Pattern::Color { seed } => {
                for (p, x) in xs {
                    let r = random(*seed, x, y);
                    *p = [(r >> 8) as u8, (r >> 24) as u8, (r >> 40) as u8, 255];
                }
            }
            Pattern::Image(_) | Pattern::Textured(_) => {
                for (p, x) in xs {
                    *p = self.color(x, y);
                }
            }
        }
    }

    /// A whole `width × height` image of the pattern (the strip algorithm's starting image).
    pub fn fill(&self, width: u32, height: u32) -> Vec<[u8; 4]> {
        let mut img = vec![[0u8; 4]; width as usize * height as usize];
        for (y, row) in img.chunks_exact_mut(width.max(1) as usize).enumerate() {
            self.fill_row(y as u32, row);
        }
        img
    }
}

/// Draws the two guide dots (tiny-skia): black discs with a white rim, centered horizontally,
/// `separation` pixels apart (the background plane's), near the top. Fusing them into three
/// dots puts the eyes at the right convergence.
pub fn draw_guide_dots(pixels: &mut [[u8; 4]], width: u32, height: u32, separation: f32) {
    let Some(mut pixmap) = tiny_skia::Pixmap::new(width, height) else {
        return;
    };
    // Opaque pixels: premultiplied and straight RGBA are the same bytes.
    for (dst, src) in pixmap.data_mut().chunks_exact_mut(4).zip(pixels.iter()) {
        dst.copy_from_slice(src);
    }
    let radius = (width.min(height) as f32 * 0.015).clamp(2.0, 12.0);
    let cy = (height as f32 * 0.05).max(radius + 2.0);
    let cx = width as f32 * 0.5;
    let mut paint = tiny_skia::Paint {
        anti_alias: true,
        ..Default::default()
    };
    for (r, color) in [
        (radius + 1.5, tiny_skia::Color::WHITE),
        (radius, tiny_skia::Color::BLACK),
    ] {
        paint.set_color(color);
        for x in [cx - separation * 0.5, cx + separation * 0.5] {
            if let Some(circle) = tiny_skia::PathBuilder::from_circle(x, cy, r) {
                pixmap.fill_path(
                    &circle,
                    &paint,
                    tiny_skia::FillRule::Winding,
                    tiny_skia::Transform::identity(),
                    None,
                );
            }
        }
    }
    for (dst, src) in pixels.iter_mut().zip(pixmap.data().chunks_exact(4)) {
        dst.copy_from_slice(src);
    }
}

/// Where the guide boxes go (`sirds.guides`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidePlace {
    /// A band at the top (pamstereogram's `-guidetop`).
    Top,
    /// A band at the bottom (`-guidebottom`).
    Bottom,
    /// Both bands (`-guidetop -guidebottom`).
    Both,
}

/// pamstereogram's guide boxes: a place and the side of each box in pixels (`sirds.guides`,
/// `sirds.guide_size`; pamstereogram's default side is 20).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GuideBoxes {
    /// Top, bottom or both.
    pub place: GuidePlace,
    /// Side of each box, pixels.
    pub size: u32,
}

/// Largest `sirds.guide_size`.
pub const MAX_GUIDE_SIZE: u32 = 256;

/// Columns of the two guide boxes' left edges for an image `width` wide, boxes `size` wide,
/// `separation` (the background plane's, rounded to whole pixels `S`) apart: the left box at
/// `⌊(width − S)/2 − size/2⌋`, the right one `S` further (pamstereogram's placement, read off
/// its output: width 300, S 128, size 10 → columns 81 and 209). `None` when they do not fit.
pub fn guide_box_columns(width: u32, size: u32, separation: f32) -> Option<(u32, u32)> {
    let s = separation.round();
    let left = ((width as f32 - s) / 2.0 - size as f32 / 2.0).floor();
    let right = left + s;
    (left >= 0.0 && right + size as f32 <= width as f32).then_some((left as u32, right as u32))
}

/// Draws pamstereogram's guide boxes (netpbm's pamstereogram manual by Scott Pakin,
/// `-guidetop`, `-guidebottom`, `-guidesize`): per band, `3·size` white rows, and in its middle
/// `size` rows two black `size × size` squares at [`guide_box_columns`]. pamstereogram appends
/// the bands below or above the stereogram; here they cover the image's top or bottom rows,
/// so the output keeps the scene's size. Fusing four squares into three puts the eyes at the
/// background plane's convergence.
///
/// # Errors
/// `Invalid` naming `sirds.guide_size` when the bands or the boxes do not fit the image.
pub fn draw_guide_boxes(
    pixels: &mut [[u8; 4]],
    width: u32,
    height: u32,
    separation: f32,
    boxes: GuideBoxes,
) -> Result<()> {
    let size = boxes.size;
    let bands: &[bool] = match boxes.place {
        GuidePlace::Top => &[true],
        GuidePlace::Bottom => &[false],
        GuidePlace::Both => &[true, false],
    };
    let band = 3 * size;
    let cols = guide_box_columns(width, size, separation);
    let Some((left, right)) = cols.filter(|_| band * bands.len() as u32 <= height) else {
        return Err(Error::invalid(
            "sirds.guide_size",
            size,
            format!(
                "the guide bands ({band} rows each) and two boxes {:.0} px apart must fit the \
                 {width}×{height} image: choose a smaller guide_size",
                separation.round()
            ),
        ));
    };
    let w = width as usize;
    for &top in bands {
        let y0 = if top { 0 } else { height - band };
        for y in y0..y0 + band {
            let row = &mut pixels[y as usize * w..(y as usize + 1) * w];
            row.fill([255, 255, 255, 255]);
            if (y0 + size..y0 + 2 * size).contains(&y) {
                for x0 in [left, right] {
                    row[x0 as usize..(x0 + size) as usize].fill([0, 0, 0, 255]);
                }
            }
        }
    }
    Ok(())
}
