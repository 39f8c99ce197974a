//! Rasterization conformance in the style of dEQP-VK.rasterization.fill_rules: coverage counted
//! per pixel; every pixel covered at most once, exactly once inside a closed surface.

use std::sync::atomic::{AtomicU32, Ordering};

use glam::{Mat4, Vec2, Vec3, Vec4};
use proptest::prelude::*;
use stereolab::compare::ascii_map;
use stereolab_core::{Fragment, Framebuffer, RasterOptions, Shader, Varyings, rasterize};

use crate::common::failure_dir;

/// Counts how often each pixel is shaded; no depth test.
struct Counter {
    clip: Vec<Vec4>,
    width: u32,
    counts: Vec<AtomicU32>,
}

impl Counter {
    fn new(clip: Vec<Vec4>, width: u32, height: u32) -> Self {
        Counter {
            clip,
            width,
            counts: (0..width * height).map(|_| AtomicU32::new(0)).collect(),
        }
    }
    fn counts(&self) -> Vec<u32> {
        self.counts
            .iter()
            .map(|c| c.load(Ordering::Relaxed))
            .collect()
    }
}

impl Shader for Counter {
    fn vertex(&self, i: u32, _: &mut Varyings) -> Vec4 {
        self.clip[i as usize]
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        self.counts[(f.y * self.width + f.x) as usize].fetch_add(1, Ordering::Relaxed);
        Some([255, 255, 255, 255])
    }
}

const W: u32 = 64;
const H: u32 = 48;

/// Rasterizes clip-space triangles into a W×H target, returns per-pixel counts.
fn count(clip: Vec<Vec4>, tris: &[[u32; 3]], width: u32, height: u32) -> Vec<u32> {
    let shader = Counter::new(clip, width, height);
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255]).unwrap();
    let opts = RasterOptions {
        depth_test: false,
        ..RasterOptions::default()
    };
    rasterize(tris, shader.clip.len(), &shader, &mut fb, &opts);
    shader.counts()
}

/// Window position (pixels, y down) → clip position with w = 1, z = 0.
fn win(x: f32, y: f32) -> Vec4 {
    Vec4::new(x / W as f32 * 2.0 - 1.0, 1.0 - y / H as f32 * 2.0, 0.0, 1.0)
}

/// Asserts counts against an expectation; on failure prints the ASCII map and writes a PNG
/// strip (expected | diff | actual) to tests/failures/.
fn check(name: &str, counts: &[u32], expected: impl Fn(usize) -> u32, width: u32) {
    let height = counts.len() as u32 / width;
    let bad: Vec<usize> = (0..counts.len())
        .filter(|&i| counts[i] != expected(i))
        .collect();
    if bad.is_empty() {
        return;
    }
    let exp: Vec<bool> = (0..counts.len()).map(|i| expected(i) > 0).collect();
    let act: Vec<bool> = counts.iter().map(|&c| c > 0).collect();
    let to_fb = |cov: &[bool]| {
        let color = cov
            .iter()
            .map(|&c| if c { [255; 4] } else { [0, 0, 0, 255] })
            .collect();
        let depth = cov.iter().map(|&c| if c { 0.5 } else { 1.0 }).collect();
        Framebuffer::from_buffers(width, height, color, depth).unwrap()
    };
    let mut actual_fb = to_fb(&act);
    for (i, &c) in counts.iter().enumerate() {
        if c > 1 {
            actual_fb.color_mut()[i] = [255, 0, 255, 255]; // double hits in magenta
        }
    }
    let path =
        stereolab::compare::write_diff_strip(&to_fb(&exp), &actual_fb, &failure_dir(), name).ok();
    let doubles = counts.iter().filter(|&&c| c > 1).count();
    panic!(
        "{name}: {} pixels differ ({doubles} double hits); first at ({}, {}): count {} expected {}\n{}\nwrote {:?}",
        bad.len(),
        bad[0] % width as usize,
        bad[0] / width as usize,
        counts[bad[0]],
        expected(bad[0]),
        ascii_map(&exp, &act, width as usize, 80),
        path
    );
}

#[test]
fn full_screen_clipped_quad_covers_every_pixel_exactly_once() {
    // Corners far outside the viewport: both triangles are clipped.
    let clip = vec![
        Vec4::new(-3.0, -3.0, 0.0, 1.0),
        Vec4::new(3.0, -3.0, 0.0, 1.0),
        Vec4::new(3.0, 3.0, 0.0, 1.0),
        Vec4::new(-3.0, 3.0, 0.0, 1.0),
    ];
    let counts = count(clip, &[[0, 1, 2], [0, 2, 3]], W, H);
    check("full_screen_quad", &counts, |_| 1, W);
}

#[test]
fn fan_around_shared_vertex_has_no_cracks_or_double_hits() {
    // 24 triangles around an off-grid center, outer ring far outside the viewport.
    let center = win(27.3, 19.7);
    let mut clip = vec![center];
    for k in 0..24 {
        let a = k as f32 / 24.0 * std::f32::consts::TAU + 0.1;
        clip.push(center + Vec4::new(a.cos() * 4.0, a.sin() * 4.0, 0.0, 0.0));
    }
    let tris: Vec<[u32; 3]> = (0..24).map(|k| [0, 1 + k, 1 + (k + 1) % 24]).collect();
    check("fan", &count(clip, &tris, W, H), |_| 1, W);
}

#[test]
fn grid_of_quads_covers_each_pixel_once() {
    // 7×5 quads on non-integer boundaries, extended beyond the viewport on all sides.
    let (nx, ny) = (7, 5);
    let xs: Vec<f32> = (0..=nx)
        .map(|i| -5.3 + i as f32 * (W as f32 + 10.0) / nx as f32)
        .collect();
    let ys: Vec<f32> = (0..=ny)
        .map(|j| -4.1 + j as f32 * (H as f32 + 8.0) / ny as f32)
        .collect();
    let mut clip = Vec::new();
    for y in &ys {
        for x in &xs {
            clip.push(win(*x, *y));
        }
    }
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let a = (j * (nx + 1) + i) as u32;
            let b = a + nx as u32 + 1;
            tris.push([a, a + 1, b + 1]);
            tris.push([a, b + 1, b]);
        }
    }
    check("grid", &count(clip, &tris, W, H), |_| 1, W);
}

#[test]
fn rotated_grids_at_15_degree_steps_cover_each_pixel_once() {
    for step in 0..24 {
        let angle = (step as f32 * 15.0).to_radians();
        let rot = glam::Mat2::from_angle(angle);
        let c = Vec2::new(W as f32 / 2.0 + 0.37, H as f32 / 2.0 - 0.21);
        let n = 6;
        let cell = 27.3f32;
        let mut clip = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let p =
                    c + rot * (Vec2::new(i as f32, j as f32) - Vec2::splat(n as f32 / 2.0)) * cell;
                clip.push(win(p.x, p.y));
            }
        }
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = (j * (n + 1) + i) as u32;
                let b = a + n as u32 + 1;
                tris.push([a, a + 1, b + 1]);
                tris.push([a, b + 1, b]);
            }
        }
        check(
            &format!("rotated_{}deg", step * 15),
            &count(clip, &tris, W, H),
            |_| 1,
            W,
        );
    }
}

#[test]
fn random_w_changes_nothing_in_coverage() {
    // The same NDC positions with w in [0.1, 4]: coverage must be identical and still exactly once.
    let mut rng = 0x2545F4914F6CDD1Du64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 40) as f32 / (1u64 << 24) as f32
    };
    let base = [
        Vec4::new(-3.0, -3.0, 0.0, 1.0),
        Vec4::new(3.0, -3.0, 0.0, 1.0),
        Vec4::new(3.0, 3.0, 0.0, 1.0),
        Vec4::new(-3.0, 3.0, 0.0, 1.0),
    ];
    let inner = [
        win(10.2, 7.7),
        win(50.6, 9.1),
        win(44.4, 40.3),
        win(13.9, 37.5),
    ];
    let tris = [[0, 1, 2], [0, 2, 3]];
    let reference = count(inner.to_vec(), &tris, W, H);
    for trial in 0..20 {
        let clip: Vec<Vec4> = base.iter().map(|v| *v * (0.1 + 3.9 * next())).collect();
        check(
            &format!("random_w_full_{trial}"),
            &count(clip, &tris, W, H),
            |_| 1,
            W,
        );
        let clip: Vec<Vec4> = inner.iter().map(|v| *v * (0.1 + 3.9 * next())).collect();
        let counts = count(clip, &tris, W, H);
        check(
            &format!("random_w_inner_{trial}"),
            &counts,
            |i| reference[i],
            W,
        );
    }
}

#[test]
fn axis_aligned_edges_follow_top_left_rule() {
    // A square whose edges pass exactly through pixel centers 2.5 and 6.5: the left and top
    // edges own their pixels, the right and bottom edges do not.
    let clip = vec![win(2.5, 2.5), win(6.5, 2.5), win(6.5, 6.5), win(2.5, 6.5)];
    let counts = count(clip, &[[0, 2, 1], [0, 3, 2]], W, H);
    check(
        "top_left",
        &counts,
        |i| ((2..6).contains(&(i as u32 % W)) && (2..6).contains(&(i as u32 / W))) as u32,
        W,
    );
}

#[test]
fn zero_area_and_subpixel_triangles_cover_nothing() {
    let cases = [
        vec![win(10.0, 10.0), win(10.0, 10.0), win(10.0, 10.0)], // a point
        vec![win(3.0, 3.0), win(20.0, 20.0), win(40.0, 40.0)],   // collinear
        vec![win(10.6, 10.6), win(10.9, 10.6), win(10.6, 10.9)], // between sample points
        vec![win(10.5, 10.5), win(10.5, 10.5), win(10.50001, 10.5)], // rounds to zero area
    ];
    for (k, clip) in cases.into_iter().enumerate() {
        check(
            &format!("degenerate_{k}"),
            &count(clip, &[[0, 1, 2]], W, H),
            |_| 0,
            W,
        );
    }
}

#[test]
fn non_finite_vertices_are_dropped_not_drawn() {
    let clip = vec![
        Vec4::new(f32::NAN, 0.0, 0.0, 1.0),
        Vec4::new(1.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, f32::INFINITY, 1.0),
    ];
    let shader = Counter::new(clip, W, H);
    let mut fb = Framebuffer::new(W, H, [0, 0, 0, 255]).unwrap();
    let stats = rasterize(
        &[[0, 1, 2], [1, 2, 3], [1, 2, 7]],
        4,
        &shader,
        &mut fb,
        &RasterOptions::default(),
    );
    assert_eq!(stats.non_finite, 3, "{stats:?}");
    assert!(shader.counts().iter().all(|&c| c == 0));
}

/// A triangle in eye space rendered with a perspective projection.
fn eye_triangle(tri: [Vec3; 3], width: u32, height: u32) -> Framebuffer {
    struct Eye {
        clip: Vec<Vec4>,
    }
    impl Shader for Eye {
        fn vertex(&self, i: u32, _: &mut Varyings) -> Vec4 {
            self.clip[i as usize]
        }
        fn fragment(&self, _: &Fragment) -> Option<[u8; 4]> {
            Some([255; 4])
        }
    }
    let p: Mat4 = stereolab_core::perspective(60.0, width as f32 / height as f32, 1.0, 50.0);
    let shader = Eye {
        clip: tri.iter().map(|v| p * v.extend(1.0)).collect(),
    };
    let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255]).unwrap();
    rasterize(&[[0, 1, 2]], 3, &shader, &mut fb, &RasterOptions::default());
    fb
}

/// Clips an eye-space polygon against z = −near analytically.
fn clip_near(poly: &[Vec3], near: f32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (da, db) = (-a.z - near, -b.z - near);
        if da >= 0.0 {
            out.push(a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
    }
    out
}

#[test]
fn triangles_crossing_the_near_plane_or_behind_the_eye_match_the_clipped_result() {
    let (w, h) = (96, 72);
    let cases = [
        [
            Vec3::new(-1.0, -1.0, -4.0),
            Vec3::new(1.5, -0.5, -0.5),
            Vec3::new(0.0, 1.0, -3.0),
        ], // crosses near
        [
            Vec3::new(-2.0, -1.0, -5.0),
            Vec3::new(2.0, -1.0, -5.0),
            Vec3::new(0.3, 0.5, 3.0),
        ], // one vertex behind the eye
        [
            Vec3::new(-2.0, -1.0, 2.0),
            Vec3::new(2.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, -6.0),
        ], // two behind
    ];
    for (k, tri) in cases.iter().enumerate() {
        let fb = eye_triangle(*tri, w, h);
        assert!(
            fb.depth()
                .iter()
                .all(|d| d.is_finite() && (0.0..=1.0).contains(d)),
            "case {k}: depth out of range"
        );
        let poly = clip_near(tri, 1.0);
        let mut depth = vec![1.0f32; (w * h) as usize];
        for i in 1..poly.len() - 1 {
            let part = eye_triangle([poly[0], poly[i], poly[i + 1]], w, h);
            for (e, p) in depth.iter_mut().zip(part.depth()) {
                *e = e.min(*p);
            }
        }
        let expected =
            Framebuffer::from_buffers(w, h, vec![[0, 0, 0, 255]; (w * h) as usize], depth).unwrap();
        let (a, b) = (
            stereolab::compare::coverage(&expected),
            stereolab::compare::coverage(&fb),
        );
        let covered = a.iter().filter(|c| **c).count();
        let diff = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        // Clipping in clip space vs in eye space rounds differently: allow edge pixels only.
        assert!(covered > 100, "case {k}: only {covered} pixels covered");
        assert!(
            diff <= 3,
            "case {k}: {diff} pixels differ from the analytically clipped triangle\n{}",
            ascii_map(&a, &b, w as usize, 96)
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn triangles_sharing_an_edge_never_double_cover(
        ax in -10.0f32..74.0, ay in -10.0f32..58.0,
        bx in -10.0f32..74.0, by in -10.0f32..58.0,
        cx in -10.0f32..74.0, cy in -10.0f32..58.0,
        dx in -10.0f32..74.0, dy in -10.0f32..58.0,
    ) {
        // Two triangles on opposite sides of edge AB (if C and D are on opposite sides).
        let side = |px: f32, py: f32| (bx - ax) * (py - ay) - (by - ay) * (px - ax);
        prop_assume!(side(cx, cy) * side(dx, dy) < 0.0);
        let clip = vec![win(ax, ay), win(bx, by), win(cx, cy), win(dx, dy)];
        let counts = count(clip, &[[0, 1, 2], [1, 0, 3]], W, H);
        prop_assert!(counts.iter().all(|&c| c <= 1), "a pixel was covered twice");
    }
}

/// Colors each fragment by its interpolated varyings, so that any difference in coverage,
/// depth or interpolation shows in the bytes.
struct Gradient {
    clip: Vec<Vec4>,
}

impl Shader for Gradient {
    fn varying_count(&self) -> usize {
        2
    }
    fn vertex(&self, i: u32, out: &mut Varyings) -> Vec4 {
        out[0] = (i % 7) as f32 / 6.0;
        out[1] = (i % 5) as f32 / 4.0;
        self.clip[i as usize]
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0) as u8;
        Some([q(f.varyings[0]), q(f.varyings[1]), q(f.depth), 255])
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Traversing a frame tile by tile (a column and row scissor per tile, as the strip
    /// algorithm does) gives the bytes of the whole-frame pass: coverage, depth and varyings.
    #[test]
    fn tiles_give_the_bytes_of_the_whole_frame(
        verts in proptest::collection::vec((-1.3f32..1.3, -1.3f32..1.3, -0.9f32..0.9, 0.5f32..3.0), 30),
        tile_w in 5u32..40,
        tile_h in 3u32..30,
    ) {
        use stereolab_core::{RasterBand, setup_triangles, traverse};
        let clip: Vec<Vec4> = verts.iter().map(|&(x, y, z, w)| Vec4::new(x * w, y * w, z * w, w)).collect();
        let tris: Vec<[u32; 3]> = (0..10).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let shader = Gradient { clip };
        let opts = RasterOptions::default();
        let mut whole = Framebuffer::new(W, H, [0, 0, 0, 255]).unwrap();
        rasterize(&tris, shader.clip.len(), &shader, &mut whole, &opts);
        let (setups, _) = setup_triangles(&tris, shader.clip.len(), &shader, W, H, &opts);
        let n = (W * H) as usize;
        let (mut tiled_color, mut tiled_depth) = (vec![[0, 0, 0, 255]; n], vec![1.0f32; n]);
        for y0 in (0..H).step_by(tile_h as usize) {
            for x0 in (0..W).step_by(tile_w as usize) {
                let (tw, th) = (tile_w.min(W - x0), tile_h.min(H - y0));
                let n = (tw * th) as usize;
                let (mut color, mut depth) = (vec![[0, 0, 0, 255]; n], vec![1.0f32; n]);
                let mut tile = RasterBand { width: tw, x0, y0, color: &mut color, depth: &mut depth };
                for t in &setups {
                    traverse(t, &shader, &mut tile, &opts);
                }
                for r in 0..th {
                    for c in 0..tw {
                        let i = ((y0 + r) * W + x0 + c) as usize;
                        tiled_color[i] = color[(r * tw + c) as usize];
                        tiled_depth[i] = depth[(r * tw + c) as usize];
                    }
                }
            }
        }
        let tiled = Framebuffer::from_buffers(W, H, tiled_color, tiled_depth).unwrap();
        prop_assert_eq!(tiled.color(), whole.color());
        let bits = |d: &[f32]| d.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        prop_assert_eq!(bits(tiled.depth()), bits(whole.depth()));
    }
}
