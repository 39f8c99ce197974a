//! Triangle rasterization with llvmpipe's exact fixed-point rules (docs/ARCHITECTURE.md
//! "Rasterization rules").
//!
//! Pipeline per triangle: vertex stage → clip → perspective divide → viewport → snap to the
//! subpixel grid → orient → edge functions with the top-left tie-break → depth test LESS →
//! fragment stage. Nothing here knows about stereo.

#[cfg(target_arch = "x86_64")]
pub mod avx2;
mod clip;
mod depth_modes;
mod setup;
#[cfg(target_arch = "x86_64")]
mod shade_avx2;
mod traverse;

pub use clip::ClipRange;
pub(crate) use clip::{ClipVertex, MAX_CLIPPED, clip_triangle, outcode};
pub use depth_modes::DepthMode;
pub use setup::{DepthPlane, Plane, Setup, SetupTriangle, WindowVertex, setup_triangle};
use setup::{Outcome, setup_into};
pub use traverse::{Band, SmallBox, traverse};

use rayon::prelude::*;

use crate::framebuffer::Framebuffer;
use crate::shade::{BlinnPhong, Shader, Varyings};
#[cfg(target_arch = "x86_64")]
use shade_avx2::Uniforms as BlinnPhongUniforms;
/// No vector fragment stage off x86-64.
#[cfg(not(target_arch = "x86_64"))]
enum BlinnPhongUniforms {}

use crate::simd::{Kernels, kernels};

/// Rasterizer knobs. The defaults are what lavapipe does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterOptions {
    /// Skip triangles whose front face (counter-clockwise in NDC) points away.
    pub cull_back: bool,
    /// Subpixel precision of the snapped window coordinates (llvmpipe: 8). 1..=16.
    pub subpixel_bits: u32,
    /// Perspective-correct varyings (true) or affine screen-space interpolation (false).
    pub perspective_correct: bool,
    /// Depth test LESS with depth writes (true), or no depth test and no depth writes.
    pub depth_test: bool,
    /// Which depth the depth test compares: lavapipe's f32 window depth (the default), or
    /// reversed-Z or f64 for scenes whose near/far ratio the standard buffer cannot resolve
    /// (`[raster] depth`, see `depth_modes`).
    pub depth: DepthMode,
}

impl Default for RasterOptions {
    fn default() -> Self {
        RasterOptions {
            cull_back: false,
            subpixel_bits: 8,
            perspective_correct: true,
            depth_test: true,
            depth: DepthMode::Standard,
        }
    }
}

/// Counts from one `rasterize` call.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RasterStats {
    /// Triangles submitted.
    pub triangles: usize,
    /// Triangles dropped because a vertex had a NaN or infinite clip coordinate.
    pub non_finite: usize,
    /// Triangles that needed clipping.
    pub clipped: usize,
    /// Clipped triangles whose coordinates are too large to clip within a subpixel step.
    pub clip_range: ClipRange,
    /// Triangles removed by back-face culling.
    pub culled: usize,
    /// Fragments that passed the depth test.
    pub fragments: usize,
}

/// Rows per band when a pass is split across threads. Each band sees every triangle in
/// submission order, so the result is the same for any number of threads.
pub(crate) const BAND_ROWS: usize = 32;

/// Rasterizes `triangles` (indices into the shader's vertices) into `fb`.
///
/// Vertex stage and setup run once; traversal runs in parallel over bands of `BAND_ROWS`
/// rows, each band applying the triangles in order, so the bytes never depend on the thread
/// count. Each triangle goes through [`traverse`], the scalar reference, or, in a depth-only
/// pass where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)), through its AVX2 twin with the same bits
/// (see `traverse_band`).
pub fn rasterize<S: Shader>(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    shader: &S,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
) -> RasterStats {
    rasterize_bands(triangles, vertex_count, shader, None, fb, opts, kernels())
}

/// [`rasterize`] with [`BlinnPhong`]: the same pixels and depths, its fragment stage eight
/// pixels wide (AVX2) where the AVX2 loops run ([`uses_avx2`](crate::uses_avx2)) and the specular
/// exponent is a whole number (`shade_avx2`, held to [`BlinnPhong`]'s own stage by
/// `avx2_blinn_phong_matches_traverse`).
pub fn rasterize_blinn_phong(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    shader: &BlinnPhong,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
) -> RasterStats {
    #[cfg(target_arch = "x86_64")]
    let uniforms = shade_avx2::Uniforms::of(shader);
    #[cfg(not(target_arch = "x86_64"))]
    let uniforms: Option<BlinnPhongUniforms> = None;
    rasterize_bands(
        triangles,
        vertex_count,
        shader,
        uniforms.as_ref(),
        fb,
        opts,
        kernels(),
    )
}

/// Setup once, then the bands in parallel, on the loops `kernels` names; `blinn_phong`: the
/// AVX2 fragment stage's uniforms when the shader is [`BlinnPhong`].
fn rasterize_bands<S: Shader>(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    shader: &S,
    blinn_phong: Option<&BlinnPhongUniforms>,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
    kernels: Kernels,
) -> RasterStats {
    if opts.depth != DepthMode::Standard {
        return depth_modes::rasterize(triangles, vertex_count, shader, fb, opts);
    }
    let (setups, mut stats) =
        setup_triangles(triangles, vertex_count, shader, fb.width, fb.height, opts);
    let width = fb.width as usize;
    let bins = bin_rows(&setups, BAND_ROWS as u32, fb.height);
    stats.fragments = fb
        .color
        .par_chunks_mut(width * BAND_ROWS)
        .zip(fb.depth.par_chunks_mut(width * BAND_ROWS))
        .zip(&bins)
        .enumerate()
        .with_max_len(1)
        .map(|(b, ((color, depth), bin))| {
            let mut band = Band {
                width: fb.width,
                x0: 0,
                y0: (b * BAND_ROWS) as u32,
                color,
                depth,
            };
            traverse_band(bin, shader, blinn_phong, &mut band, opts, kernels)
        })
        .sum();
    stats
}

/// [`traverse`] of `triangles`, in order, over `band`; returns the fragments written. A
/// Blinn-Phong pass ([`rasterize_blinn_phong`]) with the depth test on goes through the AVX2
/// fragment stage `shade_avx2::shade_triangle` under the same conditions, with the same color
/// and depth bits (`avx2_blinn_phong_matches_traverse`). In a
/// depth-only pass (the shader writes no color, depth test on) where `kernels` names the
/// AVX2 loops and [`crate::simd::avx2_available`], each
/// triangle goes through the AVX2 kernel `avx2::depth_triangle` instead, which writes the same
/// depth bits and counts the same fragments (`avx2_depth_bands_match_traverse`): `traverse`
/// stays the scalar reference.
fn traverse_band<S: Shader>(
    triangles: &[&SetupTriangle],
    shader: &S,
    blinn_phong: Option<&BlinnPhongUniforms>,
    band: &mut Band,
    opts: &RasterOptions,
    kernels: Kernels,
) -> usize {
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (kernels, blinn_phong);
    #[cfg(target_arch = "x86_64")]
    if !shader.writes_color() && opts.depth_test && kernels.avx2() {
        // SAFETY: `depth_triangle` requires AVX2 and POPCNT (its only safety condition),
        // which `Kernels::avx2` has just found on this CPU (`avx2_available`).
        return triangles
            .iter()
            .map(|t| unsafe { avx2::depth_triangle(t, band) })
            .sum();
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(u) = blinn_phong
        && opts.depth_test
        && kernels.avx2()
    {
        // SAFETY: `shade_triangle` requires AVX2, FMA and POPCNT (its only safety condition),
        // which `Kernels::avx2` has just found on this CPU (`avx2_available`).
        let (mut pending, pc) = (shade_avx2::Pending::new(), opts.perspective_correct);
        let passed = triangles
            .iter()
            .map(|t| unsafe { shade_avx2::shade_triangle(t, u, band, &mut pending, pc) })
            .sum();
        // SAFETY: as above (`flush` requires AVX2 and FMA).
        unsafe { pending.flush(u, band, pc) };
        return passed;
    }
    triangles
        .iter()
        .map(|t| traverse(t, shader, band, opts))
        .sum()
}

/// The triangles of each band of `band_rows` rows (of a `height`-row target), in submission
/// order: every band then walks its own short list instead of testing every triangle, which
/// for thousands of small triangles read the whole setup array once per band.
pub fn bin_rows(setups: &Setups, band_rows: u32, height: u32) -> Vec<Vec<&SetupTriangle>> {
    let band_rows = band_rows.max(1);
    let mut bins = vec![Vec::new(); height.div_ceil(band_rows) as usize];
    for t in setups {
        let (r0, r1) = t.rows();
        for bin in &mut bins[(r0 / band_rows) as usize..=(r1 / band_rows) as usize] {
            bin.push(t);
        }
    }
    bins
}

/// Vertex stage, clipping, perspective divide and triangle setup for every triangle, in
/// submission order, for a `width`×`height` target: what [`traverse`] needs, for callers that
/// traverse tiles themselves.
pub fn setup_triangles<S: Shader>(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    shader: &S,
    width: u32,
    height: u32,
    opts: &RasterOptions,
) -> (Setups, RasterStats) {
    // Vertex stage, once per vertex (a post-transform cache, like a GPU's), in parallel; with
    // each vertex's outcode and window position, which every unclipped triangle sharing it
    // reuses.
    let verts: Vec<PostVertex> = (0..vertex_count as u32)
        .into_par_iter()
        .with_min_len(SETUP_CHUNK)
        .map(|i| {
            let mut var: Varyings = [0.0; crate::shade::MAX_VARYINGS];
            let pos = shader.vertex(i, &mut var);
            let clip = ClipVertex { pos, var };
            PostVertex {
                code: outcode(pos),
                window: WindowVertex::from_clip(&clip, width, height),
                clip,
            }
        })
        .collect();
    let nvar = shader.varying_count().min(crate::shade::MAX_VARYINGS);
    // Chunks of triangles set up in parallel and concatenated in order: the same list for
    // any thread count.
    let parts: Vec<(Vec<SetupTriangle>, RasterStats)> = triangles
        .par_chunks(SETUP_CHUNK)
        .with_max_len(1)
        .map(|chunk| setup_chunk(chunk, &verts, nvar, width, height, opts))
        .collect();
    let mut stats = RasterStats {
        triangles: triangles.len(),
        ..Default::default()
    };
    let mut setups = Vec::with_capacity(parts.len());
    for (part, s) in parts {
        setups.push(part);
        stats.non_finite += s.non_finite;
        stats.clipped += s.clipped;
        stats.clip_range.merge(s.clip_range);
        stats.culled += s.culled;
    }
    (Setups(setups), stats)
}

/// Set-up triangles in submission order, kept in the chunks that were set up in parallel
/// (concatenating them moved every triangle once more, for nothing).
pub struct Setups(Vec<Vec<SetupTriangle>>);

impl Setups {
    /// Every triangle, in submission order.
    pub fn iter(&self) -> impl Iterator<Item = &SetupTriangle> {
        self.0.iter().flatten()
    }
}

impl<'a> IntoIterator for &'a Setups {
    type Item = &'a SetupTriangle;
    type IntoIter = std::iter::Flatten<std::slice::Iter<'a, Vec<SetupTriangle>>>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter().flatten()
    }
}

/// Triangles per setup task.
const SETUP_CHUNK: usize = 256;

/// A vertex after the vertex stage: clip position and varyings, outcode, window position.
#[derive(Clone, Copy)]
struct PostVertex {
    clip: ClipVertex,
    code: u8,
    window: Option<WindowVertex>,
}

/// Clipping, perspective divide and setup of one chunk of triangles, in order.
fn setup_chunk(
    triangles: &[[u32; 3]],
    verts: &[PostVertex],
    nvar: usize,
    width: u32,
    height: u32,
    opts: &RasterOptions,
) -> (Vec<SetupTriangle>, RasterStats) {
    let mut stats = RasterStats::default();
    let mut setups = Vec::with_capacity(triangles.len());
    let blank = ClipVertex {
        pos: glam::Vec4::ZERO,
        var: [0.0; crate::shade::MAX_VARYINGS],
    };
    let mut poly = [blank; MAX_CLIPPED + 3];
    let mut win: [Option<WindowVertex>; MAX_CLIPPED + 3] = [None; MAX_CLIPPED + 3];
    for tri in triangles {
        let (Some(a), Some(b), Some(c)) = (
            verts.get(tri[0] as usize),
            verts.get(tri[1] as usize),
            verts.get(tri[2] as usize),
        ) else {
            stats.non_finite += 1; // an index past the vertex count: nothing sensible to draw
            continue;
        };
        if [a, b, c].iter().any(|v| !v.clip.pos.is_finite()) {
            stats.non_finite += 1;
            continue;
        }
        if a.code & b.code & c.code != 0 {
            continue; // all three outside the same plane
        }
        let mut add = |w: [WindowVertex; 3], var: [&Varyings; 3]| {
            // Set up in the list's next slot (`setup_triangle`, without moving the result).
            setups.reserve(1);
            let slot = &mut setups.spare_capacity_mut()[0];
            match setup_into(w, var, nvar, (width, height), opts, true, slot) {
                // SAFETY: the slot past the list's end was just written (the outcome says so).
                Outcome::Triangle => unsafe { setups.set_len(setups.len() + 1) },
                Outcome::Culled => return true,
                Outcome::Empty => {}
            }
            false
        };
        if a.code | b.code | c.code == 0 {
            // Inside: the cached window positions.
            if let (Some(wa), Some(wb), Some(wc)) = (a.window, b.window, c.window) {
                let culled = add([wa, wb, wc], [&a.clip.var, &b.clip.var, &c.clip.var]);
                stats.culled += culled as usize;
            }
            continue;
        }
        stats.clipped += 1;
        let tri = [a.clip, b.clip, c.clip];
        let n = clip_triangle(tri, nvar, &mut poly);
        let range = ClipRange::of(&tri, &poly[..n], width, height);
        stats.clip_range.merge(range);
        for k in 0..n {
            win[k] = WindowVertex::from_clip(&poly[k], width, height);
        }
        // The clipped polygon is convex: draw it as a fan around its first vertex.
        let mut culled = false;
        for k in 1..n.saturating_sub(1) {
            let (Some(a), Some(b), Some(c)) = (win[0], win[k], win[k + 1]) else {
                continue;
            };
            culled |= add([a, b, c], [&poly[0].var, &poly[k].var, &poly[k + 1].var]);
        }
        stats.culled += culled as usize;
    }
    (setups, stats)
}

/// For a test comparing the AVX2 loops with the scalar ones: whether there are AVX2 loops to
/// compare, that is whether they run ([`uses_avx2`](crate::uses_avx2)) (the tests reach them through the public
/// functions). Without them (a CPU without AVX2, or `STEREOLAB_SCALAR` set) it says so on
/// stderr and the test has nothing to hold: every path that runs is then the scalar one, which
/// the other tests cover. (Unlike lavapipe, which `.ci/run` installs, AVX2 is the hardware's.)
#[cfg(test)]
pub(crate) fn avx2_to_compare(test: &str) -> bool {
    if kernels().avx2() {
        return true;
    }
    eprintln!(
        "{test}: NOT RUN: no AVX2 loops here (no AVX2, or STEREOLAB_SCALAR set), nothing to compare"
    );
    false
}

#[cfg(test)]
mod tests {
    use glam::{Mat4, Vec3};

    use super::*;
    use crate::math::{look_at, perspective};
    use crate::shade::DepthOnly;

    /// `count` triangles of a bumpy height-field grid over [−1, 1]² (the raster layer knows no
    /// meshes; this is the scene's `triangles` kind, positions and indices only).
    fn grid(count: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let side = (count.div_ceil(2) as f32).sqrt().ceil() as u32;
        let mut positions = Vec::new();
        for j in 0..=side {
            for i in 0..=side {
                let (u, v) = (i as f32 / side as f32, j as f32 / side as f32);
                let h = 0.15 * ((u * 9.0).sin() * (v * 7.0).cos());
                positions.push(Vec3::new(u * 2.0 - 1.0, v * 2.0 - 1.0, h));
            }
        }
        let triangles = (0..side * side)
            .flat_map(|q| {
                let a = q / side * (side + 1) + q % side;
                let b = a + side + 1;
                [[a, a + 1, b + 1], [a, b + 1, b]]
            })
            .take(count as usize)
            .collect();
        (positions, triangles)
    }

    /// The AVX2 depth-only bands (one or two vectors per row for small triangles, spans for the
    /// rest, unmasked loads and stores where eight fit) write the scalar `traverse`'s depth bits and
    /// count the same fragments: grids from 2 to 10,000 triangles, seen straight on and at a
    /// slant (partly clipped), on sizes that end mid-vector.
    #[test]
    fn avx2_depth_bands_match_traverse() {
        if !avx2_to_compare("avx2_depth_bands_match_traverse") {
            return;
        }
        let opts = RasterOptions::default();
        for (w, h, count, tilt) in [
            (512, 256, 2_500, 0.0),
            (301, 77, 400, 50.0),
            (64, 64, 10_000, 20.0),
            (97, 203, 2, 80.0),
        ] {
            let (positions, triangles) = grid(count);
            let view = look_at(Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO, Vec3::Y);
            let model = Mat4::from_rotation_y(f32::to_radians(tilt));
            let mvp = perspective(45.0, w as f32 / h as f32, 1.0, 10.0) * view * model;
            let shader = DepthOnly {
                positions: &positions,
                mvp,
            };
            let mut fast = Framebuffer::new(w, h, [0, 0, 0, 255]).expect("size");
            let stats = rasterize(&triangles, positions.len(), &shader, &mut fast, &opts);
            let (setups, _) = setup_triangles(&triangles, positions.len(), &shader, w, h, &opts);
            let mut plain = Framebuffer::new(w, h, [0, 0, 0, 255]).expect("size");
            let mut band = Band {
                width: w,
                x0: 0,
                y0: 0,
                color: &mut plain.color,
                depth: &mut plain.depth,
            };
            let fragments: usize = setups
                .iter()
                .map(|t| traverse(t, &shader, &mut band, &opts))
                .sum();
            let bits = |fb: &Framebuffer| fb.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert!(fragments > 0, "{w}x{h} {count}: nothing drawn");
            assert_eq!(
                stats.fragments, fragments,
                "{w}x{h} {count}: fragment count"
            );
            assert!(
                bits(&fast) == bits(&plain),
                "{w}x{h} {count} tilt {tilt}: depth bits differ"
            );
        }
    }

    /// `triangles` drawn with `shader` on a black `w`×`h` target by the AVX2 Blinn-Phong stage
    /// (`rasterize_blinn_phong`) and by the scalar `traverse`: each framebuffer and its stats.
    fn blinn_phong_both_ways(
        triangles: &[[u32; 3]],
        vertex_count: usize,
        shader: &crate::shade::BlinnPhong,
        (w, h): (u32, u32),
        opts: &RasterOptions,
    ) -> ((Framebuffer, RasterStats), (Framebuffer, RasterStats)) {
        let mut fast = Framebuffer::new(w, h, [0, 0, 0, 255]).expect("size");
        let stats = rasterize_blinn_phong(triangles, vertex_count, shader, &mut fast, opts);
        let mut plain = Framebuffer::new(w, h, [0, 0, 0, 255]).expect("size");
        let plain_stats = rasterize_bands(
            triangles,
            vertex_count,
            shader,
            None,
            &mut plain,
            opts,
            Kernels::Scalar,
        );
        ((fast, stats), (plain, plain_stats))
    }

    /// The AVX2 Blinn-Phong stage writes the scalar `traverse`'s color and depth bits and
    /// counts the same fragments: grids seen from the front and from behind (back faces, lit
    /// two-sided), slanted and partly clipped, with normals of every length including zero
    /// (`normalize_or_zero`'s fallback), perspective-correct and affine, odd sizes, a light
    /// inside the surface and a specular power of 0, 1, 32 and 1024; triangles smaller than a
    /// pixel, whose fragments are shaded in batches.
    #[test]
    fn avx2_blinn_phong_matches_traverse() {
        use crate::shade::{BlinnPhong, Light};
        if !avx2_to_compare("avx2_blinn_phong_matches_traverse") {
            return;
        }
        for (w, h, count, tilt, perspective_correct, shininess) in [
            (512, 256, 2_500, 0.0, true, 32.0),
            (301, 77, 400, 50.0, true, 1.0),
            (64, 64, 10_000, 20.0, false, 0.0),
            (97, 203, 2, 80.0, true, 1024.0),
            (256, 192, 900, 160.0, true, 32.0),
            // Triangles far smaller than a pixel, folded over one another at a grazing angle:
            // fragments wait to be shaded eight at a time, and later ones cover earlier ones.
            (160, 120, 60_000, 78.0, true, 32.0),
            (96, 64, 40_000, 200.0, false, 1.0),
        ] {
            let (positions, triangles) = grid(count);
            // Normals of varied length and direction; every 7th vertex has none.
            let normals: Vec<Vec3> = positions
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    if i % 7 == 0 {
                        Vec3::ZERO
                    } else {
                        Vec3::new(p.x * 3.0, (p.y * 5.0).sin(), 1.0 + p.z) * (1 + i % 5) as f32
                    }
                })
                .collect();
            let view = look_at(Vec3::new(0.0, 0.0, 2.5), Vec3::ZERO, Vec3::Y);
            let model = Mat4::from_rotation_y(f32::to_radians(tilt));
            let projection = perspective(45.0, w as f32 / h as f32, 1.0, 10.0);
            let light = Light {
                position: Vec3::new(0.3, -0.2, 0.05),
                shininess,
                ..Light::default()
            };
            let shader = BlinnPhong::new(
                &positions,
                &normals,
                model,
                view,
                projection,
                Vec3::new(0.9, 0.5, 0.2),
                light,
            );
            let opts = RasterOptions {
                perspective_correct,
                ..RasterOptions::default()
            };
            let ((fast, stats), (plain, plain_stats)) =
                blinn_phong_both_ways(&triangles, positions.len(), &shader, (w, h), &opts);
            let what = format!("{w}x{h} {count} tilt {tilt} shininess {shininess}");
            assert!(stats.fragments > 0, "{what}: nothing drawn");
            assert_eq!(
                stats.fragments, plain_stats.fragments,
                "{what}: fragment count"
            );
            let bits = |fb: &Framebuffer| fb.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert!(bits(&fast) == bits(&plain), "{what}: depth bits differ");
            let differ = fast
                .color
                .iter()
                .zip(&plain.color)
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(differ, 0, "{what}: {differ} colors differ");
            let distinct: std::collections::HashSet<_> = fast.color.iter().collect();
            assert!(
                distinct.len() > 20,
                "{what}: only {} colors: not shaded",
                distinct.len()
            );
        }
    }

    /// Fragments that wait to be shaded in batches keep the scalar stage's order: thousands of
    /// triangles of one to seven pixels stacked over a few pixels, each pixel won many times
    /// over; and tiny triangles each followed by a wide one in front, whose fragments are
    /// shaded at once while the tiny one's still waits (a batch that wrote every waiting
    /// fragment's color would leave the tiny triangles' colors there). Colors, depths and the
    /// fragment count equal the scalar stage's.
    #[test]
    fn avx2_blinn_phong_batches_keep_the_last_fragment() {
        use crate::shade::{BlinnPhong, Light};
        if !avx2_to_compare("avx2_blinn_phong_batches_keep_the_last_fragment") {
            return;
        }
        let mut next = super::setup::tests::uniform(0x2545_f491_4f6c_dd1d);
        let (w, h) = (48, 32);
        let (mut positions, mut normals, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
        let mut add = |corners: [(f32, f32); 3], z: f32, next: &mut dyn FnMut() -> f32| {
            let base = positions.len() as u32;
            for (x, y) in corners {
                positions.push(Vec3::new(x, y, z));
                normals.push(Vec3::new(next() - 0.5, next() - 0.5, 1.0));
            }
            triangles.push([base, base + 1, base + 2]);
        };
        // Over a patch of about 6×4 pixels in the middle of the view (a pixel is about 0.078
        // units wide at distance 3), triangles from under one pixel to about seven, nearer as
        // they come, give or take: later ones mostly pass, some fail.
        for t in 0..6_000 {
            let (cx, cy) = ((next() - 0.5) * 0.47, (next() - 0.5) * 0.31);
            let z = -0.7 + 1.4 * t as f32 / 6_000.0 + (next() - 0.5) * 0.01;
            let size = 0.05 + next() * 0.5;
            let corners = [(); 3].map(|_| (cx + (next() - 0.5) * size, cy + (next() - 0.5) * size));
            add(corners, z, &mut next);
        }
        // Elsewhere, a triangle of about a pixel (its fragment waits), then at once a wide one
        // in front of it (its fragments are shaded at once): the wide one's colors must stay.
        for cy in [-0.85, 0.6] {
            for cx in [-1.35, -0.45, 0.45, 1.35] {
                let tiny = [
                    (cx - 0.06, cy - 0.05),
                    (cx + 0.06, cy - 0.05),
                    (cx, cy + 0.07),
                ];
                add(tiny, 0.0, &mut next);
                let wide = [(cx - 0.4, cy - 0.15), (cx + 0.4, cy - 0.15), (cx, cy + 0.3)];
                add(wide, 0.1, &mut next);
            }
        }
        let view = look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
        let projection = perspective(45.0, w as f32 / h as f32, 1.0, 10.0);
        let shader = BlinnPhong::new(
            &positions,
            &normals,
            Mat4::IDENTITY,
            view,
            projection,
            Vec3::new(0.3, 0.7, 0.9),
            Light::default(),
        );
        let opts = RasterOptions {
            cull_back: false,
            ..RasterOptions::default()
        };
        let ((fast, stats), (plain, plain_stats)) =
            blinn_phong_both_ways(&triangles, positions.len(), &shader, (w, h), &opts);
        let drawn = plain.color.iter().filter(|c| **c != [0, 0, 0, 255]).count();
        assert!(
            stats.fragments > 10 * drawn && drawn > 100,
            "{} fragments over {drawn} pixels: too little overlap",
            stats.fragments
        );
        assert_eq!(stats.fragments, plain_stats.fragments, "fragment count");
        let bits = |fb: &Framebuffer| fb.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
        assert!(bits(&fast) == bits(&plain), "depth bits differ");
        let differ = (fast.color.iter().zip(&plain.color))
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "{differ} colors differ");
    }
}
