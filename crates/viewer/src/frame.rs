//! One viewer frame: the plan for the one output shown, its passes, the output image, and the
//! readouts that teach (passes run and their times, the parallax range against the budget).
//! All of it is the library's own work ([`Plan::new`], [`stereolab::render()`],
//! [`output::produce`], [`stereolab::info::parallax_range`]); the viewer adds timing and nothing else.

use std::time::{Duration, Instant};

use glam::Vec3;

use stereolab::info::{ParallaxRange, parallax_range};
use stereolab::output::{self, Image};
use stereolab::plan::{Output, Plan, Shading, View};
use stereolab::render::chromadepth::resolve_texgen;
use stereolab::render::{Frame, render};
use stereolab::scene::Scene;
use stereolab_core::{Framebuffer, ParallaxRig, Result};

use super::session::{Params, point_parallax_pixels, unproject};

/// A finished frame and what the viewer shows beside it.
pub struct Shown {
    /// The parameters it was rendered with.
    pub params: Params,
    /// The output image, as `stereolab render` would write it.
    pub image: Image,
    /// The rendered passes (framebuffers with depth, matrices): what a click looks into.
    pub frame: Frame,
    /// Each pass: a name (`Left Color`) and its time.
    pub passes: Vec<(String, Duration)>,
    /// Making the output from the passes (finalize, layouts, ChromaDepth glasses, SIRDS
    /// strips or TIW).
    pub effect: Duration,
    /// Passes and effect together: the library's render, what `stereolab render` spends.
    pub total: Duration,
    /// What the viewer adds to each frame: the readouts below (parallax range of every vertex,
    /// the per-pixel budget, the ChromaDepth range, the clicked point).
    pub readouts: Duration,
    /// Parallax of every vertex seen by both eyes (`stereolab info`'s range); also the
    /// vertical parallax toe-in makes.
    pub range: ParallaxRange,
    /// Window violations (border pixels with negative parallax: left, right, top, bottom) of
    /// an eye the plan rendered, if any did.
    pub window_violations: Option<[usize; 4]>,
    /// Screen parallax in pixels of the point last clicked, under this frame's rig.
    pub picked_parallax: Option<f32>,
    /// Image width (the parallax readouts' pixels are of this width).
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The ChromaDepth D1, D2 (set, or fitted to the bounding sphere) a ChromaDepth pass uses.
    pub chromadepth: Option<[f32; 2]>,
}

/// Renders `scene` (already set to `params`) for its one output and measures the readouts;
/// `picked` is the world point last clicked.
///
/// # Errors
/// Whatever rendering or the output fails with (an invalid rig, a ChromaDepth range outside
/// the clip planes, …).
pub fn render_shown(scene: &Scene, params: &Params, picked: Option<Vec3>) -> Result<Shown> {
    // A multiview output renders the scene's `multiview.views` cameras.
    let shown = params.output.with_views(scene.views);
    let plan = Plan::new(&[shown]);
    let start = Instant::now();
    let frame = render(scene, &plan)?;
    let passes_done = Instant::now();
    let image = output::produce(shown, &frame, scene)?;
    let effect = passes_done.elapsed();
    let total = start.elapsed();
    let readouts_start = Instant::now();
    let passes = frame
        .passes
        .iter()
        .map(|p| (format!("{:?} {:?}", p.pass.view, p.pass.shading), p.time))
        .collect();
    let range = parallax_range(scene)?;
    let rig = scene.parallax_rig()?;
    let window_violations = [View::Left, View::Right]
        .into_iter()
        .find_map(|v| frame.view(v))
        .map(|fb| window_violations(fb, &rig));
    // The D1/D2 a ChromaDepth pass uses (set, or fitted to the bounding sphere), also for the
    // other outputs, so the sliders start where the ramp would be; `None` where no range fits.
    let chromadepth = match frame.plan.pass(View::Center) {
        Some(p) if p.shading == Shading::ChromaDepth => {
            let t = resolve_texgen(scene, &frame.views.center, &scene.chromadepth)?;
            Some([t.d1, t.d2])
        }
        _ => resolve_texgen(scene, &frame.views.center, &scene.chromadepth)
            .ok()
            .map(|t| [t.d1, t.d2]),
    };
    let picked_parallax =
        picked.and_then(|p| point_parallax_pixels(&frame.views.eyes, p, scene.width));
    let readouts = readouts_start.elapsed();
    Ok(Shown {
        params: params.clone(),
        image,
        frame,
        passes,
        effect,
        total,
        readouts,
        range,
        window_violations,
        picked_parallax,
        width: scene.width,
        height: scene.height,
        chromadepth,
    })
}

/// The StereoGraphics guide's window violations of one eye's framebuffer: border pixels with
/// negative parallax (in front of the screen, cut by the window's edge), per side (left, right,
/// top, bottom). The same count as
/// [`parallax_budget_of`](stereolab_core::parallax_budget_of)`(fb, rig).window_violations`, which maps
/// every pixel's parallax; this looks at the border pixels only, as only they can violate
/// (a unit test holds the two equal).
pub fn window_violations(fb: &Framebuffer, rig: &ParallaxRig) -> [usize; 4] {
    let (w, h) = (fb.width() as usize, fb.height() as usize);
    let negative = |x: usize, y: usize| {
        fb.depth()
            .get(y * w + x)
            .and_then(|&d| rig.parallax_pixels(d))
            .is_some_and(|p| p < 0.0)
    };
    let column = |x: usize| (0..h).filter(|&y| negative(x, y)).count();
    let row = |y: usize| (0..w).filter(|&x| negative(x, y)).count();
    if w == 0 || h == 0 {
        return [0; 4];
    }
    [column(0), column(w - 1), row(0), row(h - 1)]
}

/// `image` as egui's texture pixels, made on the worker thread so the window only moves it
/// into its texture. An RGBA output is converted in one pass over its bytes (no intermediate
/// copy); depth (16 bits, shown by the high byte) and stereo photos go through
/// [`Image::to_display_rgba`] first.
pub fn display_image(image: &Image) -> eframe::egui::ColorImage {
    use eframe::egui::ColorImage;
    match image {
        Image::Rgba(i) => ColorImage::from_rgba_unmultiplied(
            [i.width() as usize, i.height() as usize],
            i.as_raw(),
        ),
        other => {
            let rgba = other.to_display_rgba();
            ColorImage::from_rgba_unmultiplied(
                [rgba.width() as usize, rgba.height() as usize],
                rgba.as_raw(),
            )
        }
    }
}

impl Shown {
    /// Width of the output image (side by side is twice the scene's width).
    pub fn image_width(&self) -> u32 {
        self.image.display_size().0
    }

    /// Height of the output image.
    pub fn image_height(&self) -> u32 {
        self.image.display_size().1
    }

    /// The scene's width / height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The ChromaDepth range of this frame's camera (set, or fitted), if one fits.
    pub fn chromadepth_range(&self) -> Option<[f32; 2]> {
        self.chromadepth
    }

    /// The world point under pixel (`x`, `y`) of the output image, if the model is there: the
    /// pixel is traced back to the pass it came from (the left half of a side-by-side image is
    /// the left eye, …) and that pass's depth is unprojected.
    pub fn pick(&self, x: u32, y: u32) -> Option<Vec3> {
        let (w, h) = (self.width, self.height);
        let (view, px, py) = match self.params.output {
            Output::SideBySide => (if x < w { View::Left } else { View::Right }, x % w, y),
            Output::CrossEyed => (if x < w { View::Right } else { View::Left }, x % w, y),
            Output::AboveBelow => (if y < h { View::Left } else { View::Right }, x, y % h),
            // Both views squashed 1:2, the left on top: a rough pick in the top view.
            Output::AboveBelowSquashed => (View::Left, x, (y * 2).min(h - 1)),
            // Each view squeezed 2:1: a pixel covers two of its view's.
            Output::HalfSideBySide => {
                let view = if x < w / 2 { View::Left } else { View::Right };
                (view, (x % (w / 2).max(1)) * 2, y)
            }
            Output::HalfAboveBelow => {
                let view = if y < h / 2 { View::Left } else { View::Right };
                (view, x, (y % (h / 2).max(1)) * 2)
            }
            // Left, the black active space (nothing to pick), right.
            Output::FramePacking => {
                let below = h + stereolab_core::frame_packing_active_space(h);
                match y {
                    y if y < h => (View::Left, x, y),
                    y if y >= below => (View::Right, x, y - below),
                    _ => return None,
                }
            }
            // The tile's camera, row-major in the tiles' grid.
            Output::ViewTiles(_) => {
                let n = self.frame.views.multi.len() as u32;
                let (columns, _) = stereolab_core::view_grid(n);
                let i = (y / h) * columns + x / w;
                if i >= n {
                    return None;
                }
                (View::Multi(i as u8), x % w, y % h)
            }
            Output::ViewInterleaved(_) => {
                let n = self.frame.views.multi.len() as u32;
                let i = stereolab_core::lenticular_view(x, n.max(1));
                (View::Multi(i as u8), x, y)
            }
            _ => {
                let view = [View::Left, View::Center, View::Right]
                    .into_iter()
                    .find(|&v| self.frame.view(v).is_some())?;
                (view, x, y)
            }
        };
        let fb = self.frame.view(view)?;
        if px >= fb.width() || py >= fb.height() {
            return None;
        }
        let d = *fb.depth().get((py * fb.width() + px) as usize)?;
        (d < 1.0).then(|| {
            unproject(
                &self.frame.matrices(view).mvp,
                px,
                py,
                d,
                fb.width(),
                fb.height(),
            )
        })
    }

    /// The passes run, one per line with its time, then the effect and the total.
    pub fn timing_lines(&self) -> Vec<String> {
        let ms = |d: Duration| d.as_secs_f64() * 1e3;
        let mut lines: Vec<String> = self
            .passes
            .iter()
            .map(|(name, t)| format!("pass {name}: {:.1} ms", ms(*t)))
            .collect();
        lines.push(format!(
            "{}: {:.1} ms",
            self.params.output.name(),
            ms(self.effect)
        ));
        lines.push(format!("library frame: {:.1} ms", ms(self.total)));
        lines.push(format!("readouts: {:.1} ms", ms(self.readouts)));
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereolab_core::{Camera, StereoRig, ZeroParallax, parallax_budget_of};

    /// The viewer shows the scene's N views, and a pick in a tile finds the point the tile's
    /// camera sees there: projected by that camera, the point lands back on the pixel.
    #[test]
    fn multiview_tiles_show_the_scenes_views_and_pick_their_cameras() {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../assets/scenes/multiview.toml");
        let mut scene = Scene::load(&path, &[]).unwrap();
        scene.set_size(64, 48).unwrap();
        let session = crate::session::Session::new(&scene, &path, &[]).unwrap();
        let mut p = session.initial.clone();
        p.output = Output::ViewTiles(2);
        session.apply(&p, &mut scene);
        let shown = render_shown(&scene, &p, None).unwrap();
        // Five views: a 3×2 grid of 64×48 tiles, the sixth empty.
        assert_eq!(shown.image.display_size(), (3 * 64, 2 * 48));
        assert_eq!(shown.frame.views.multi.len(), 5);
        assert!(shown.pick(2 * 64 + 32, 48 + 24).is_none(), "the empty tile");
        let mut hits = 0;
        for i in 0..5u32 {
            let (tx, ty) = (i % 3, i / 3);
            for (x, y) in [(20, 10), (32, 24), (44, 30), (50, 20)] {
                let Some(q) = shown.pick(tx * 64 + x, ty * 48 + y) else {
                    continue;
                };
                let ndc = shown.frame.views.multi[i as usize].mvp.project_point3(q);
                let px = (ndc.x + 1.0) * 0.5 * 64.0;
                let py = (1.0 - ndc.y) * 0.5 * 48.0;
                assert!(
                    (px - (x as f32 + 0.5)).abs() < 0.01 && (py - (y as f32 + 0.5)).abs() < 0.01,
                    "view {i} at ({x}, {y}): projects to ({px}, {py})"
                );
                hits += 1;
            }
        }
        assert!(hits >= 5, "{hits} picks hit the model");
    }

    #[test]
    fn window_violations_count_as_the_budget_does() {
        let camera = Camera {
            eye: [0.0, 0.0, 5.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y: 50.0,
            near: 1.0,
            far: 20.0,
        };
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for (w, h, z0) in [(7, 5, 2.0), (16, 9, 6.0), (1, 1, 10.0), (33, 2, 19.0)] {
            let depth: Vec<f32> = (0..w * h)
                .map(|_| {
                    let d = next();
                    if d > 0.8 { 1.0 } else { d * 1.2 }
                })
                .map(|d: f32| d.min(1.0))
                .collect();
            let fb = Framebuffer::from_buffers(w, h, vec![[0; 4]; (w * h) as usize], depth)
                .expect("depths in [0, 1]");
            let rig = StereoRig {
                zero_parallax: ZeroParallax::Distance(z0),
                ..StereoRig::default()
            };
            let prig = ParallaxRig::new(&rig, &camera, w, h).unwrap();
            let expected = parallax_budget_of(&fb, &prig).unwrap().window_violations;
            assert_eq!(window_violations(&fb, &prig), expected, "{w}x{h} z0 {z0}");
            if z0 > 5.0 && w > 2 {
                assert!(
                    expected.iter().sum::<usize>() > 0,
                    "{w}x{h}: nothing to count"
                );
            }
        }
    }
}
