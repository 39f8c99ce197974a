//! Huge triangles clip to what the f64 reference covers: triangles of extent 2e8 and 1e10
//! covering the view cover every pixel, a ground of extent 1e6 covers the reference's rows,
//! and coordinates beyond the clipper's exact range are counted (`RasterStats::clip_range`).

use glam::{DMat4, DVec3, Vec3};
use stereolab_core::{
    ClipRange, Framebuffer, IdShader, RasterOptions, RasterStats, drawn_id, frustum_f64, look_at,
    look_at_f64, perspective, rasterize, triangle_soup as soup, visible_f64 as visible,
};

const SIZE: (u32, u32) = (64, 48);

/// A view of `triangles` from `eye` towards `target`: the renderer's pass (an [`IdShader`]
/// pass, its covered pixels and stats) and the f64 reference's covered pixels.
fn both(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    eye: Vec3,
    target: Vec3,
    (near, far): (f32, f32),
) -> (Vec<bool>, Vec<bool>, RasterStats) {
    let (w, h) = SIZE;
    let aspect = w as f32 / h as f32;
    let mvp = perspective(45.0, aspect, near, far) * look_at(eye, target, Vec3::Y);
    let p = soup(positions, triangles);
    let ids: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let mut fb = Framebuffer::new(w, h, [0, 0, 0, 0]).unwrap();
    let shader = IdShader { positions: &p, mvp };
    let stats = rasterize(&ids, p.len(), &shader, &mut fb, &RasterOptions::default());
    let drawn = (0..fb.color().len())
        .map(|i| drawn_id(&fb, i).is_some())
        .collect();
    let v64 = |v: Vec3| DVec3::from(v.to_array().map(f64::from));
    let (n, f) = (f64::from(near), f64::from(far));
    let half_h = n * (45f64.to_radians() * 0.5).tan();
    let half_w = half_h * f64::from(w) / f64::from(h);
    let mvp64: DMat4 = frustum_f64(-half_w, half_w, -half_h, half_h, n, f)
        * look_at_f64(v64(eye), v64(target), DVec3::Y);
    let p64: Vec<DVec3> = positions.iter().map(|v| v64(*v)).collect();
    let r = visible(&p64, triangles, &mvp64, w, h);
    (drawn, r.id.iter().map(Option::is_some).collect(), stats)
}

/// A triangle of extent `e` in the plane z = 0, seen from 3 units: it covers the view.
fn covering(e: f32) -> (Vec<bool>, Vec<bool>, RasterStats) {
    let p = [
        Vec3::new(-e, -e, 0.0),
        Vec3::new(e, -e, 0.0),
        Vec3::new(0.0, e, 0.0),
    ];
    both(
        &p,
        &[[0, 1, 2]],
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::ZERO,
        (1.0, 10.0),
    )
}

/// A ground square of half-extent `e` one unit under an eye looking at the horizon.
fn ground(e: f32) -> (Vec<bool>, Vec<bool>, RasterStats) {
    let p = [
        Vec3::new(-e, 0.0, e),
        Vec3::new(e, 0.0, e),
        Vec3::new(e, 0.0, -e),
        Vec3::new(-e, 0.0, -e),
    ];
    let eye = Vec3::new(0.0, 1.0, 0.0);
    both(
        &p,
        &[[0, 1, 2], [0, 2, 3]],
        eye,
        Vec3::new(0.0, 1.0, -1.0),
        (0.1, 1000.0),
    )
}

fn count(v: &[bool]) -> usize {
    v.iter().filter(|c| **c).count()
}

/// Triangles of extent 2e8 and 1e10 covering the view cover every pixel, as the f64
/// reference does, with no range warning (in f32 the clip distance `w + x` loses `w` and
/// the intersection lands half a screen off: 37.5% covered).
#[test]
fn huge_triangles_covering_the_view_cover_every_pixel() {
    for e in [2e8, 1e10] {
        let (drawn, reference, stats) = covering(e);
        assert_eq!(count(&reference), drawn.len(), "reference at {e:e}");
        assert_eq!(count(&drawn), drawn.len(), "extent {e:e}: {stats:?}");
        assert_eq!(stats.clipped, 1);
        assert_eq!(stats.clip_range, ClipRange::default(), "extent {e:e}");
    }
}

/// A ground of extent 1e6 covers exactly the pixels the f64 reference covers (the rows
/// below the horizon; pixels the reference leaves open at an edge are not counted).
#[test]
fn a_huge_ground_covers_the_rows_the_reference_covers() {
    let (drawn, reference, stats) = ground(1e6);
    assert_eq!(count(&reference), drawn.len() / 2, "the lower half");
    let differ: Vec<usize> = (0..drawn.len())
        .filter(|&i| drawn[i] != reference[i])
        .collect();
    assert!(differ.is_empty(), "pixels that differ: {differ:?}");
    assert_eq!(stats.clip_range, ClipRange::default());
}

/// Past the clipper's range the pass says so: a covering triangle of extent 1e30 (no f32
/// or f64 clipper places its edges within a pixel; here they lie outside the view, so it
/// still covers everything) and grounds of extent 1e8 and 1e10, whose near plane the f32
/// vertex stage has rounded away (`z = a·z_eye + b` loses `b`; the reference, in f64
/// from the scene, still covers the lower half, the renderer and lavapipe nothing).
#[test]
fn coordinates_beyond_the_clippers_range_are_counted() {
    let (drawn, _, stats) = covering(1e30);
    assert_eq!(count(&drawn), drawn.len());
    let r = stats.clip_range;
    assert_eq!(r.triangles, 1, "{stats:?}");
    assert!(r.coordinate > 1e30 && r.coordinate > r.limit, "{r:?}");
    // 2⁴³ · w / side with w = 3 (the plane's distance) and a 64-pixel side.
    assert_eq!(r.limit, (ClipRange::SCALE * 3.0 / 64.0) as f32);
    for e in [1e8, 1e10] {
        let (drawn, reference, stats) = ground(e);
        assert_eq!(count(&reference), drawn.len() / 2, "reference at {e:e}");
        assert_eq!(count(&drawn), 0, "extent {e:e}");
        let r = stats.clip_range;
        assert_eq!(r.triangles, 2, "extent {e:e}: {stats:?}");
        assert!(r.coordinate >= e && r.limit == 0.0, "extent {e:e}: {r:?}");
    }
}

/// Ordinary clipped triangles stay in range: a ground of extent 100 and a triangle of
/// extent 1e4 through the near plane.
#[test]
fn ordinary_clipped_triangles_are_in_range() {
    let (_, _, stats) = ground(100.0);
    assert_eq!(stats.clipped, 2);
    assert_eq!(stats.clip_range, ClipRange::default());
    let p = [
        Vec3::new(-1e4, -1.0, 1e4),
        Vec3::new(1e4, -1.0, 1e4),
        Vec3::new(0.0, 2.0, -1e4),
    ];
    let (_, _, stats) = both(&p, &[[0, 1, 2]], Vec3::ZERO, -Vec3::Z, (0.1, 100.0));
    assert_eq!(stats.clipped, 1);
    assert_eq!(stats.clip_range, ClipRange::default());
}
