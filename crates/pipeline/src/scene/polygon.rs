//! Triangulation of one polygon face, keeping its winding.
//!
//! OBJ faces may have any number of corners. A convex face is split into the fan
//! `(0, i, i + 1)`, which is what tobj's own triangulation gives (so meshes made only of
//! convex faces come out exactly as before). A concave face is split by ear clipping in the
//! face's own plane: the plane's normal is the Newell normal, the face is projected onto the
//! coordinate plane most facing it, and ears are cut off one at a time. Every triangle keeps
//! the face's winding, so a counter-clockwise (front-facing) face gives counter-clockwise
//! triangles.
//!
//! Faces that are degenerate (no area), self-intersecting, or larger than
//! [`MAX_EAR_CLIP_CORNERS`] fall back to the fan: the same, deterministic answer as before.

use glam::{DVec2, DVec3, Vec3};

/// Concave faces with more corners than this are fanned. Each ear test scans the remaining
/// corners and the simplicity check compares every pair of edges, so the work grows at least
/// as n²: a 1024-corner concave star takes 5–9 ms (4096 corners: about 130 ms) in the test
/// profile. (A hostile file made only of such faces costs about 1–2 ms per KB of face text.)
pub const MAX_EAR_CLIP_CORNERS: usize = 1024;

/// Triangles of the polygon `corners` (in order), as index triples into `corners`, with the
/// polygon's winding. Fewer than 3 corners give no triangles.
pub fn triangulate(corners: &[Vec3]) -> Vec<[usize; 3]> {
    let n = corners.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let Some(flat) = project(corners) else {
        return fan(n);
    };
    if is_convex(&flat) || n > MAX_EAR_CLIP_CORNERS || !is_simple(&flat) {
        return fan(n);
    }
    match ear_clip(&flat) {
        Some(tris) if covers_area(&flat, &tris) => tris,
        _ => fan(n),
    }
}

/// A last check on ear clipping's answer: its triangles' areas add up to the polygon's area
/// (to a relative 1e-9). Rounding on nearly-degenerate corners can otherwise let a wrong
/// triangulation through; the fan is then the deterministic fallback.
fn covers_area(pts: &[DVec2], tris: &[[usize; 3]]) -> bool {
    let n = pts.len();
    let polygon: f64 = (0..n).map(|i| pts[i].perp_dot(pts[(i + 1) % n])).sum();
    let sum: f64 = tris
        .iter()
        .map(|&[a, b, c]| turn(pts[a], pts[b], pts[c]))
        .sum();
    (sum - polygon).abs() <= 1e-9 * polygon.abs()
}

/// The fan `(0, i, i + 1)`: right for convex faces.
fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n - 1).map(|i| [0, i, i + 1]).collect()
}

/// The corners in 2D, in the coordinate plane most facing the polygon, oriented so that the
/// polygon is counter-clockwise (positive area). `None` when the polygon has no area.
fn project(corners: &[Vec3]) -> Option<Vec<DVec2>> {
    let pts: Vec<DVec3> = corners.iter().map(|p| p.as_dvec3()).collect();
    // Newell's normal: twice the vector area of the polygon, robust for non-planar faces.
    let mut normal = DVec3::ZERO;
    for (i, a) in pts.iter().enumerate() {
        let b = pts[(i + 1) % pts.len()];
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let abs = normal.abs();
    let scale = pts.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let largest = abs.max_element();
    if largest.is_nan() || largest <= 1e-12 * scale * scale {
        return None;
    }
    // Drop the dominant axis; the other two, in cyclic order, form a right-handed plane whose
    // normal is that axis, so the 2D orientation is the sign of the normal's component.
    let (axis, sign) = if abs.z >= abs.x && abs.z >= abs.y {
        (2, normal.z)
    } else if abs.x >= abs.y {
        (0, normal.x)
    } else {
        (1, normal.y)
    };
    let flip = if sign < 0.0 { -1.0 } else { 1.0 };
    Some(
        pts.iter()
            .map(|p| match axis {
                0 => DVec2::new(p.y, flip * p.z),
                1 => DVec2::new(p.z, flip * p.x),
                _ => DVec2::new(p.x, flip * p.y),
            })
            .collect(),
    )
}

/// `(b - a) × (c - b)`: positive for a left (counter-clockwise) turn at `b`.
fn turn(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - b)
}

/// A counter-clockwise polygon is convex when no corner turns right (straight corners allowed).
fn is_convex(pts: &[DVec2]) -> bool {
    let n = pts.len();
    (0..n).all(|i| turn(pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]) >= 0.0)
}

/// Whether the polygon is weakly simple, as far as ear clipping needs: no two edges cross or
/// overlap, except that edges may meet at corners with the same position and an edge may be
/// walked back exactly (a "bridge" joining a hole to the outline, as in assimp's
/// `concave_polygon.obj`). O(n²).
fn is_simple(pts: &[DVec2]) -> bool {
    let n = pts.len();
    for i in 0..n {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        for j in i + 1..n {
            let (c, d) = (pts[j], pts[(j + 1) % n]);
            if (a == d && b == c) || (a == c && b == d) {
                continue; // a bridge, or a repeated edge
            }
            let shared = [(a, c), (a, d), (b, c), (b, d)]
                .iter()
                .filter(|(p, q)| p == q)
                .count();
            if shared > 0 {
                // Edges meeting at a corner: only a collinear overlap beyond it is a problem.
                if shared == 1 && overlaps_beyond_corner(a, b, c, d) {
                    return false;
                }
                continue;
            }
            if segments_touch(a, b, c, d) {
                return false;
            }
        }
    }
    true
}

/// Two edges that share exactly one endpoint overlap along a stretch: they are collinear and
/// point the same way from the shared corner.
fn overlaps_beyond_corner(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (corner, u, v) = if a == c {
        (a, b, d)
    } else if a == d {
        (a, b, c)
    } else if b == c {
        (b, a, d)
    } else {
        (b, a, c)
    };
    let (u, v) = (u - corner, v - corner);
    u.perp_dot(v) == 0.0 && u.dot(v) > 0.0
}

/// Whether segments `ab` and `cd` share any point (including touching and collinear overlap).
fn segments_touch(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o1 = (b - a).perp_dot(c - a);
    let o2 = (b - a).perp_dot(d - a);
    let o3 = (d - c).perp_dot(a - c);
    let o4 = (d - c).perp_dot(b - c);
    if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
        && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
    {
        return true;
    }
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    (o1 == 0.0 && on(a, b, c))
        || (o2 == 0.0 && on(a, b, d))
        || (o3 == 0.0 && on(c, d, a))
        || (o4 == 0.0 && on(c, d, b))
}

/// Whether `p` lies inside or on the counter-clockwise triangle `abc`.
fn in_triangle(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    (b - a).perp_dot(p - a) >= 0.0
        && (c - b).perp_dot(p - b) >= 0.0
        && (a - c).perp_dot(p - c) >= 0.0
}

/// Ear clipping of a simple counter-clockwise polygon: repeatedly cut off a corner that turns
/// left and whose triangle holds no other remaining corner. Straight corners (no turn) are
/// dropped without a triangle, which changes no area. `None` if no ear is found in a full
/// round, which floating-point rounding can cause; the caller then fans.
fn ear_clip(pts: &[DVec2]) -> Option<Vec<[usize; 3]>> {
    let mut ring: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::with_capacity(pts.len() - 2);
    let mut i = 0;
    let mut misses = 0;
    while ring.len() > 3 {
        let m = ring.len();
        let (p, c, n) = (ring[(i + m - 1) % m], ring[i % m], ring[(i + 1) % m]);
        let t = turn(pts[p], pts[c], pts[n]);
        if t == 0.0 {
            ring.remove(i % m);
            misses = 0;
            continue;
        }
        let is_ear = t > 0.0
            && ring.iter().all(|&q| {
                q == p
                    || q == c
                    || q == n
                    || pts[q] == pts[p]
                    || pts[q] == pts[c]
                    || pts[q] == pts[n]
                    || !in_triangle(pts[q], pts[p], pts[c], pts[n])
            });
        if is_ear {
            out.push([p, c, n]);
            ring.remove(i % m);
            misses = 0;
            // Stay at the same position: the next corner moved into it.
            i %= ring.len();
        } else {
            misses += 1;
            if misses > m {
                return None;
            }
            i = (i + 1) % m;
        }
    }
    if turn(pts[ring[0]], pts[ring[1]], pts[ring[2]]) > 0.0 {
        out.push([ring[0], ring[1], ring[2]]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area2(pts: &[Vec3], t: [usize; 3], normal: Vec3) -> f32 {
        (pts[t[1]] - pts[t[0]])
            .cross(pts[t[2]] - pts[t[0]])
            .dot(normal)
    }

    #[test]
    fn convex_faces_keep_the_fan() {
        let quad = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        assert_eq!(triangulate(&quad), vec![[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn concave_arrow_is_clipped_facing_forward() {
        // A dart (arrow head) starting at a foot: the fan from there would cover the notch
        // and its second triangle would face backwards.
        let dart = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 0.5, 0.0),
        ];
        // The dart is clockwise seen from +z, so every triangle must face -z.
        let tris = triangulate(&dart);
        assert_eq!(tris.len(), 2);
        let total: f32 = tris.iter().map(|&t| area2(&dart, t, -Vec3::Z)).sum();
        assert!(
            tris.iter().all(|&t| area2(&dart, t, -Vec3::Z) > 0.0),
            "{tris:?}"
        );
        // The dart's area is 1.5 (shoelace), so the doubled areas sum to 3.
        assert!((total - 3.0).abs() < 1e-5, "{total}");
    }

    #[test]
    fn degenerate_and_self_intersecting_faces_fan() {
        let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::X * 3.0];
        assert_eq!(triangulate(&line), fan(4));
        let bowtie = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 2.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        assert_eq!(triangulate(&bowtie), fan(4));
    }

    #[test]
    fn concave_faces_above_the_bound_are_fanned() {
        // A star whose corners alternate between two radii: concave, and the fan from corner 0
        // is not what ear clipping gives.
        let star = |n: usize| -> Vec<Vec3> {
            (0..n)
                .map(|i| {
                    let a = i as f32 / n as f32 * std::f32::consts::TAU;
                    let r = if i % 2 == 0 { 1.0 } else { 0.5 };
                    Vec3::new(r * a.cos(), r * a.sin(), 0.0)
                })
                .collect()
        };
        assert_ne!(
            triangulate(&star(MAX_EAR_CLIP_CORNERS)),
            fan(MAX_EAR_CLIP_CORNERS)
        );
        let n = MAX_EAR_CLIP_CORNERS + 2;
        assert_eq!(triangulate(&star(n)), fan(n));
    }

    /// Whether `p` is strictly inside the counter-clockwise triangle `abc`.
    fn strictly_in(p: DVec2, [a, b, c]: [DVec2; 3]) -> bool {
        [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(u, v)| (v - u).perp_dot(p - u) > 0.0)
    }

    /// Distance from `p` to segment `ab`.
    fn to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
        let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        (a + (b - a) * t).distance(p)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(300))]

        /// Random simple polygons: star-shaped around the origin (increasing angles, random
        /// radii), either winding, rotated and moved into 3D. The triangles must face the
        /// polygon's way, and every sample point away from the edges must lie in exactly one
        /// triangle if it is inside the polygon and in none if outside: the triangles cover
        /// the polygon exactly, without overlap. Their areas must add up to the polygon's.
        #[test]
        fn triangles_tile_random_simple_polygons(
            steps in proptest::collection::vec(0.2f64..1.0, 4..40),
            radii in proptest::collection::vec(0.15f64..1.0, 40),
            axis in (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
            angle in 0.0f32..std::f32::consts::TAU,
            offset in (-5.0f32..5.0, -5.0f32..5.0, -5.0f32..5.0),
            reversed in proptest::bool::ANY,
            samples in proptest::collection::vec((-1.0f64..1.0, -1.0f64..1.0), 300),
        ) {
            let total: f64 = steps.iter().sum();
            let mut flat: Vec<DVec2> = steps
                .iter()
                .scan(0.0, |a, s| { *a += s; Some(*a) })
                .zip(&radii)
                .map(|(a, &r)| {
                    let a = a / total * std::f64::consts::TAU;
                    DVec2::new(r * a.cos(), r * a.sin())
                })
                .collect();
            if reversed {
                flat.reverse();
            }
            let axis = Vec3::new(axis.0, axis.1, axis.2).try_normalize().unwrap_or(Vec3::Z);
            let rot = glam::Quat::from_axis_angle(axis, angle);
            let offset = Vec3::new(offset.0, offset.1, offset.2);
            let corners: Vec<Vec3> = flat
                .iter()
                .map(|p| rot * Vec3::new(p.x as f32, p.y as f32, 0.0) + offset)
                .collect();
            let facing = rot * if reversed { -Vec3::Z } else { Vec3::Z };

            let tris = triangulate(&corners);
            // The triangles in the polygon's own plane, made counter-clockwise for the checks
            // (each is checked to face the polygon's way first).
            let mut local = Vec::new();
            for &[a, b, c] in &tris {
                let n = (corners[b] - corners[a]).cross(corners[c] - corners[a]).dot(facing);
                proptest::prop_assert!(n >= -1e-5, "triangle {:?} faces backwards ({})", [a, b, c], n);
                let t = [flat[a], flat[b], flat[c]];
                local.push(if reversed { [t[0], t[2], t[1]] } else { t });
            }
            let area: f64 = local.iter().map(|t| (t[1] - t[0]).perp_dot(t[2] - t[0]) / 2.0).sum();
            let m = flat.len();
            let poly_area = (0..m).map(|i| flat[i].perp_dot(flat[(i + 1) % m])).sum::<f64>().abs() / 2.0;
            proptest::prop_assert!((area - poly_area).abs() < 1e-4, "area {} vs {}", area, poly_area);

            let eps = 1e-3;
            for &(x, y) in &samples {
                let p = DVec2::new(x, y);
                if (0..m).any(|i| to_segment(p, flat[i], flat[(i + 1) % m]) < eps)
                    || local.iter().any(|t| (0..3).any(|k| to_segment(p, t[k], t[(k + 1) % 3]) < eps))
                {
                    continue; // too close to an edge to call
                }
                // Inside the star-shaped polygon: the winding number around p is not zero.
                let winding: f64 = (0..m)
                    .map(|i| {
                        let (u, v) = (flat[i] - p, flat[(i + 1) % m] - p);
                        u.perp_dot(v).atan2(u.dot(v))
                    })
                    .sum();
                let inside = winding.abs() > 1.0;
                let hits = local.iter().filter(|&&t| strictly_in(p, t)).count();
                proptest::prop_assert_eq!(hits, usize::from(inside), "point {:?}", p);
            }
        }
    }
}
