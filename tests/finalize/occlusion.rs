//! The visibility check and the occlusion map: an occluder in front of a wall marks exactly
//! the strips the rig predicts; flat planes are never flagged; near/far ratios 10 to 1e5.

use stereolab::plan::Output;
use stereolab_core::{
    DEPTH_PRECISION, EyeMatrices, Framebuffer, OCCLUSION_OCCLUDED_COLOR,
    OCCLUSION_OUT_OF_VIEW_COLOR, Precision, Remapper, Visibility, classify_visibility, depth_slope,
    occlusion_image, remap_tolerance, visibility_map,
};

use super::{Rig, eyes, plane, render_outputs, scene};

const RATIOS: [f32; 5] = [10.0, 1e2, 1e3, 1e4, 1e5];
const WALL_Z: f64 = 9.0;

/// Window x of an eye-space point (x, z) (camera axes = world axes) in eye `e`.
fn window_x(e: &EyeMatrices, x: f64, z: f64, width: u32) -> f64 {
    let [l, r, _, _, n, _] = e.frustum.map(f64::from);
    let x_near = (x - e.eye_world.x as f64) * n / z;
    (x_near - l) / (r - l) * width as f64
}

/// World x on the plane at distance z seen through window x `xw` of eye `e`.
fn unproject_x(e: &EyeMatrices, xw: f64, z: f64, width: u32) -> f64 {
    let [l, r, _, _, n, _] = e.frustum.map(f64::from);
    let x_near = l + xw / width as f64 * (r - l);
    e.eye_world.x as f64 + x_near * z / n
}

/// Window y of eye-space height y at distance z (identical in both off-axis eyes).
fn window_y(e: &EyeMatrices, y: f64, z: f64, height: u32) -> f64 {
    let [_, _, b, t, n, _] = e.frustum.map(f64::from);
    (t - y * n / z) / (t - b) * height as f64
}

/// Fails loudly when a pixel center or a sample lies within 0.01 px of an edge, so the
/// prediction below is exact rather than lucky.
fn clear_of(v: f64, edge: f64, what: &str) {
    assert!(
        (v - edge).abs() > 0.01,
        "ambiguous test geometry: {what} {v} within 0.01 px of edge {edge}"
    );
}

/// The square occluder: center (cx, cy) at distance z, half edge h.
#[derive(Clone, Copy)]
struct Occluder {
    cx: f64,
    cy: f64,
    z: f64,
    h: f64,
}

impl Occluder {
    /// Does eye `e` draw the occluder at pixel (px, py)? Pixel centers inside the projected
    /// square (no center lies on an edge, see `clear_of`).
    fn covers(&self, e: &EyeMatrices, px: u32, py: u32, w: u32, h: u32) -> bool {
        let (x0, x1) = (
            window_x(e, self.cx - self.h, self.z, w),
            window_x(e, self.cx + self.h, self.z, w),
        );
        let (y0, y1) = (
            window_y(e, self.cy + self.h, self.z, h),
            window_y(e, self.cy - self.h, self.z, h),
        );
        let (xc, yc) = (px as f64 + 0.5, py as f64 + 0.5);
        for edge in [x0, x1] {
            clear_of(xc, edge, "pixel center x");
        }
        for edge in [y0, y1] {
            clear_of(yc, edge, "pixel center y");
        }
        xc > x0 && xc < x1 && yc > y0 && yc < y1
    }
}

/// What the rig predicts for pixel (px, py) of eye `this` against eye `other`: `None` for an
/// occluder pixel (visible, or a silhouette artifact), else the wall point's class.
fn predict(
    this: &EyeMatrices,
    other: &EyeMatrices,
    occ: Option<Occluder>,
    (px, py): (u32, u32),
    (w, h): (u32, u32),
) -> Option<Visibility> {
    if occ.is_some_and(|o| o.covers(this, px, py, w, h)) {
        return None;
    }
    // The wall point behind this pixel, seen from the other eye (no vertical parallax).
    let x_world = unproject_x(this, px as f64 + 0.5, WALL_Z, w);
    let xr = window_x(other, x_world, WALL_Z, w);
    clear_of(xr, xr.round(), "remapped x");
    if xr < 0.0 || xr >= w as f64 {
        return Some(Visibility::OutOfView);
    }
    let texel = xr.floor() as u32;
    Some(match occ {
        Some(o) if o.covers(other, texel, py, w, h) => Visibility::Occluded,
        _ => Visibility::Visible,
    })
}

fn count(map: &[Visibility], v: Visibility) -> usize {
    map.iter().filter(|m| **m == v).count()
}

/// Checks both eyes' maps of a wall (plus an optional occluder) against the prediction;
/// returns the occluded-pixel counts per occluder row of the left eye.
fn check_scene(rig: &Rig, occ: Option<Occluder>, precision: Precision) -> Vec<usize> {
    let mut meshes = plane(60.0, [0.0, 0.0, -WALL_Z as f32], [0.0; 3]);
    if let Some(o) = occ {
        meshes += &plane(
            2.0 * o.h as f32,
            [o.cx as f32, o.cy as f32, -o.z as f32],
            [0.0; 3],
        );
    }
    let s = scene(rig, &meshes, &["occlusion"]);
    let frame = render_outputs(&s, &[Output::Occlusion]);
    let (left, right) = eyes(&frame);
    let (w, h) = (left.width(), left.height());
    let mut strip_rows = Vec::new();
    for (k, (this, other)) in [(left, right), (right, left)].into_iter().enumerate() {
        let (e_this, e_other) = (&frame.views.eyes[k], &frame.views.eyes[1 - k]);
        let map =
            visibility_map(this, other, &e_this.mvp, &e_other.mvp, precision).expect("visibility");
        for py in 0..h {
            let mut occluded_in_row = 0;
            for px in 0..w {
                let got = map[this.index(px, py)];
                match predict(e_this, e_other, occ, (px, py), (w, h)) {
                    Some(want) => assert_eq!(
                        got,
                        want,
                        "ratio {}, eye {k}, pixel ({px}, {py}), {precision:?}",
                        rig.far / rig.near
                    ),
                    None => {
                        // Occluder pixel: visible, or (the exercise slides: never "farther" off a
                        // silhouette) a nearest-sampling artifact next to the wall.
                        let next_to_wall = [px.wrapping_sub(1), px + 1]
                            .iter()
                            .any(|&x| x < w && !occ.is_some_and(|o| o.covers(e_this, x, py, w, h)));
                        assert!(
                            got == Visibility::Visible
                                || (got == Visibility::Farther && next_to_wall),
                            "occluder pixel ({px}, {py}) eye {k}: {got:?}"
                        );
                    }
                }
                occluded_in_row += (got == Visibility::Occluded) as usize;
            }
            if k == 0 && occluded_in_row > 0 {
                strip_rows.push(occluded_in_row);
            }
        }
    }
    strip_rows
}

fn rig_with_ratio(ratio: f32) -> Rig {
    let far = 40.0;
    Rig {
        near: far / ratio,
        far,
        ..Rig::default()
    }
}

#[test]
fn occluder_marks_exactly_the_predicted_strips_for_near_far_10_to_1e5() {
    let cases = [
        Occluder {
            cx: 0.137,
            cy: -0.213,
            z: 5.0,
            h: 0.9,
        },
        // Barely in front of the wall: a strip under one pixel wide, 40 ulps of depth apart
        // at near/far 1e5.
        Occluder {
            cx: -0.311,
            cy: 0.171,
            z: 8.5,
            h: 1.3,
        },
    ];
    for ratio in RATIOS {
        let rig = rig_with_ratio(ratio);
        for occ in cases {
            let rows = check_scene(&rig, Some(occ), Precision::F64);
            assert_eq!(rows, check_scene(&rig, Some(occ), Precision::F32));
            // The strip is as wide as the parallax difference of wall and occluder.
            let width = rig.parallax_px(WALL_Z) - rig.parallax_px(occ.z);
            if occ.z == 5.0 {
                assert!(!rows.is_empty(), "ratio {ratio}: occluder missed");
            }
            for n in &rows {
                assert!(
                    (*n as f64 - width).abs() <= 1.0,
                    "ratio {ratio}, z {}: strip {n} px vs p(wall) − p(occluder) = {width:.3}",
                    occ.z
                );
            }
            println!(
                "near/far 1/{ratio}: occluder at z = {}: {} rows with a strip, widths {:?} px (predicted {width:.3})",
                occ.z,
                rows.len(),
                {
                    let mut u = rows.clone();
                    u.sort();
                    u.dedup();
                    u
                }
            );
        }
    }
}

#[test]
fn flat_planes_are_never_flagged_for_near_far_10_to_1e5() {
    for ratio in RATIOS {
        let rig = rig_with_ratio(ratio);
        // A fronto-parallel wall: checked pixel by pixel (only the border strip is out of view).
        check_scene(&rig, None, Precision::F64);
        // A plane slanted 35° about y and 20° about x: depth varies across the whole view.
        let s = scene(
            &rig,
            &plane(60.0, [0.0, 0.0, -12.0], [20.0, 35.0, 0.0]),
            &["occlusion"],
        );
        let frame = render_outputs(&s, &[Output::Occlusion]);
        let (left, right) = eyes(&frame);
        assert!(
            left.depth().iter().all(|d| *d < 1.0),
            "plane must fill the view"
        );
        for precision in [Precision::F64, Precision::F32] {
            let map = visibility_map(
                left,
                right,
                &frame.views.eyes[0].mvp,
                &frame.views.eyes[1].mvp,
                precision,
            )
            .expect("visibility");
            let (occluded, farther) = (
                count(&map, Visibility::Occluded),
                count(&map, Visibility::Farther),
            );
            println!(
                "near/far 1/{ratio}, slanted plane, {precision:?}: occluded {occluded}, farther {farther}, out of view {}",
                count(&map, Visibility::OutOfView)
            );
            assert_eq!((occluded, farther), (0, 0), "ratio {ratio}, {precision:?}");
        }
    }
}

#[test]
fn occlusion_image_shows_both_eyes_maps_side_by_side() {
    let rig = Rig::default();
    let occ = plane(1.8, [0.137, -0.213, -5.0], [0.0; 3]);
    let meshes = plane(60.0, [0.0, 0.0, -WALL_Z as f32], [0.0; 3]) + &occ;
    let s = scene(&rig, &meshes, &["occlusion"]);
    let frame = render_outputs(&s, &[Output::Occlusion]);
    let (left, right) = eyes(&frame);
    let img = occlusion_image(
        left,
        right,
        [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp],
        Precision::F64,
    )
    .expect("occlusion");
    assert_eq!((img.width(), img.height()), (2 * rig.width, rig.height));
    for k in 0..2u32 {
        let (this, other) = if k == 0 { (left, right) } else { (right, left) };
        let map = visibility_map(
            this,
            other,
            &frame.views.eyes[k as usize].mvp,
            &frame.views.eyes[1 - k as usize].mvp,
            Precision::F64,
        )
        .expect("visibility");
        let red = (0..rig.height)
            .flat_map(|y| (0..rig.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(k * rig.width + x, y).0 == OCCLUSION_OCCLUDED_COLOR)
            .count();
        let blue = (0..rig.height)
            .flat_map(|y| (0..rig.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.get_pixel(k * rig.width + x, y).0 == OCCLUSION_OUT_OF_VIEW_COLOR)
            .count();
        assert_eq!(red, count(&map, Visibility::Occluded));
        assert_eq!(blue, count(&map, Visibility::OutOfView));
        assert!(
            red > 0 && blue > 0,
            "eye {k}: {red} occluded, {blue} out of view"
        );
    }
    let _ = std::fs::create_dir_all("target/test-out/finalize");
    img.save("target/test-out/finalize/occlusion.png")
        .expect("save");
}

/// The visibility map with a tolerance of our choosing, the loop of `visibility_map` spelled out.
fn map_with_tolerance(
    this: &Framebuffer,
    other: &Framebuffer,
    mvp: [&glam::Mat4; 2],
    tol: &dyn Fn(&Framebuffer, u32, u32) -> f64,
) -> Vec<Visibility> {
    let (w, h) = (this.width(), this.height());
    let r = Remapper::new(mvp[0], mvp[1], w, h, Precision::F64).expect("remapper");
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let d = this.depth()[this.index(x, y)];
            let target = r.remap(x, y, d).and_then(|m| {
                m.texel(w, h)
                    .map(|(tx, ty)| (m, other.depth()[other.index(tx, ty)]))
            });
            classify_visibility(d, target, tol(this, x, y))
        })
        .collect()
}

#[test]
fn tolerance_is_neither_too_tight_nor_too_loose() {
    // Too tight: without the slope term a slanted plane is flagged (nearest sampling lands up
    // to half a pixel off on a sloped depth).
    let rig = rig_with_ratio(10.0);
    let s = scene(
        &rig,
        &plane(60.0, [0.0, 0.0, -12.0], [20.0, 35.0, 0.0]),
        &["occlusion"],
    );
    let frame = render_outputs(&s, &[Output::Occlusion]);
    let (left, right) = eyes(&frame);
    let mvp = [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp];
    let tight = map_with_tolerance(left, right, mvp, &|_, _, _| DEPTH_PRECISION);
    let ours = map_with_tolerance(left, right, mvp, &|fb, x, y| {
        remap_tolerance(depth_slope(fb, x, y))
    });
    let flagged = |m: &[Visibility]| count(m, Visibility::Occluded) + count(m, Visibility::Farther);
    println!(
        "slanted plane, near/far 1/10: flagged {} px with DEPTH_PRECISION alone, {} with the slope term",
        flagged(&tight),
        flagged(&ours)
    );
    assert!(flagged(&tight) > 100);
    assert_eq!(flagged(&ours), 0);

    // Too loose: a fixed 1e-5 misses the occluder 0.5 units in front of the wall at 1/1e5
    // (their window depths differ by ~2.6e-6), which ours (8·2⁻²⁴ ≈ 4.8e-7) finds.
    let rig = rig_with_ratio(1e5);
    let meshes = plane(60.0, [0.0, 0.0, -WALL_Z as f32], [0.0; 3])
        + &plane(2.6, [-0.311, 0.171, -8.5], [0.0; 3]);
    let s = scene(&rig, &meshes, &["occlusion"]);
    let frame = render_outputs(&s, &[Output::Occlusion]);
    let (left, right) = eyes(&frame);
    let mvp = [&frame.views.eyes[0].mvp, &frame.views.eyes[1].mvp];
    let loose = map_with_tolerance(left, right, mvp, &|_, _, _| 1e-5);
    let ours = map_with_tolerance(left, right, mvp, &|fb, x, y| {
        remap_tolerance(depth_slope(fb, x, y))
    });
    println!(
        "occluder 0.5 in front of the wall, near/far 1/1e5: {} occluded px with tolerance 1e-5, {} with ours",
        count(&loose, Visibility::Occluded),
        count(&ours, Visibility::Occluded)
    );
    assert_eq!(count(&loose, Visibility::Occluded), 0);
    assert!(count(&ours, Visibility::Occluded) > 40);
}
