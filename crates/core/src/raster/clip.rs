//! Homogeneous clipping against the view frustum (Sutherland–Hodgman), as llvmpipe's draw
//! module does: geometrically, against all six planes, no guard band (`llvmpipe_create_context`
//! sets `draw_set_driver_clipping(draw, false, false, false, true)`). llvmpipe clips in f32
//! (`draw_pipe_clip.c`); this clipper works in f64, which places the new vertices within a
//! subpixel step up to far larger coordinates ([`ClipRange`]).

use glam::{DVec4, Vec4};

use crate::shade::{MAX_VARYINGS, Varyings};

/// A vertex after the vertex stage: clip position and varyings.
#[derive(Clone, Copy, Debug)]
pub struct ClipVertex {
    /// Clip-space position.
    pub pos: Vec4,
    /// Varyings.
    pub var: Varyings,
}

/// Distance of `p` to each of the six OpenGL clip planes (inside ≥ 0):
/// w+x, w−x, w+y, w−y, w+z, w−z.
#[inline]
fn plane_distance(p: DVec4, plane: usize) -> f64 {
    match plane {
        0 => p.w + p.x,
        1 => p.w - p.x,
        2 => p.w + p.y,
        3 => p.w - p.y,
        4 => p.w + p.z,
        _ => p.w - p.z,
    }
}

/// Bit i set when `p` is outside plane i. (The sign of `w ± x` is exact in any precision: a
/// rounded sum is zero only when the exact one is.)
#[inline]
pub fn outcode(p: Vec4) -> u8 {
    let p = p.as_dvec4();
    (0..6).fold(0, |code, i| {
        code | (((plane_distance(p, i) < 0.0) as u8) << i)
    })
}

/// Most vertices a triangle can have after six clip planes (3 + 6).
pub const MAX_CLIPPED: usize = 9;

/// Clips triangle `tri` against the frustum; writes the polygon into `out`, returns its length
/// (0 when nothing remains). Only the first `nvar` varyings are interpolated.
///
/// Sutherland–Hodgman (Sutherland and Hodgman, "Reentrant polygon clipping", CACM 17(1),
/// 1974) in homogeneous coordinates (Blinn and Newell, "Clipping using homogeneous
/// coordinates", SIGGRAPH 1978), computed in f64 from the f32 vertices:
/// - each intersection is interpolated from the edge's inside vertex, so that an edge shared
///   by two triangles clips to the same point in both;
/// - a clip distance `w ± x` of two f32 values is exact in f64 while `|x| / |w| < 2²⁹`, and
///   the interpolated point is then within about `2⁻⁵²·|p|` of the exact intersection, `|p|`
///   the largest coordinate (in f32 the same sum loses `w` entirely once `|x| > 2²⁴·|w|`,
///   and a triangle of extent 1e8 was cut half a screen off);
/// - the coordinate the plane constrains is then set exactly onto the plane (`x = −w` for
///   `w + x = 0`), so the next planes see the vertex on it, not a rounding to either side.
///
/// How far that carries is [`ClipRange`]'s business.
pub fn clip_triangle(
    tri: [ClipVertex; 3],
    nvar: usize,
    out: &mut [ClipVertex; MAX_CLIPPED + 3],
) -> usize {
    type Vertex = (DVec4, [f64; MAX_VARYINGS]);
    let widen = |v: &ClipVertex| (v.pos.as_dvec4(), v.var.map(f64::from));
    let mut a: [Vertex; MAX_CLIPPED + 3] = [widen(&tri[0]); MAX_CLIPPED + 3];
    for (slot, v) in a.iter_mut().zip(&tri) {
        *slot = widen(v);
    }
    let mut n = 3;
    let mut b = a;
    for plane in 0..6 {
        let mut m = 0;
        for i in 0..n {
            let cur = a[i];
            let next = a[(i + 1) % n];
            let dc = plane_distance(cur.0, plane);
            let dn = plane_distance(next.0, plane);
            if dc >= 0.0 {
                b[m] = cur;
                m += 1;
            }
            if (dc >= 0.0) != (dn >= 0.0) {
                let (inside, outside, di, dout) = if dc >= 0.0 {
                    (cur, next, dc, dn)
                } else {
                    (next, cur, dn, dc)
                };
                let t = di / (di - dout);
                let mut v = inside;
                v.0 = on_plane(inside.0 + (outside.0 - inside.0) * t, plane);
                for k in 0..nvar {
                    v.1[k] = inside.1[k] + (outside.1[k] - inside.1[k]) * t;
                }
                b[m] = v;
                m += 1;
            }
        }
        n = m;
        std::mem::swap(&mut a, &mut b);
        if n < 3 {
            return 0;
        }
    }
    for (slot, (pos, var)) in out.iter_mut().zip(&a[..n]) {
        *slot = ClipVertex {
            pos: pos.as_vec4(),
            var: var.map(|x| x as f32),
        };
    }
    n
}

/// `p` with the coordinate that `plane` constrains set onto it: `x = −w` for `w + x = 0`, and
/// so on (the order of [`plane_distance`]).
fn on_plane(mut p: DVec4, plane: usize) -> DVec4 {
    let side = if plane.is_multiple_of(2) { -p.w } else { p.w };
    match plane / 2 {
        0 => p.x = side,
        1 => p.y = side,
        _ => p.z = side,
    }
    p
}

/// Clipped triangles with clip coordinates too large for `clip_triangle` to place their new
/// vertices within a subpixel step (1/256 px), and the worst of them (`RasterStats`).
///
/// The f64 clipper's new vertices lie within a few roundings, `2⁻⁵⁰·|p|` here, of the exact
/// intersections, `|p|` the triangle's largest clip coordinate; at a new vertex of clip `w` on
/// a target whose larger side is `side` pixels that is `2⁻⁵⁰·|p|·(side/2)/w` px. It stays
/// below 1/256 px while `|p| ≤ 2⁴³·w/side`: a triangle of extent 1e10 seen from 3 units
/// covers a 1024-pixel view as it should, one of extent 1e30 does not (nor would any f32 or
/// f64 clipper).
///
/// `w` is the smallest of the clipped polygon's and of the points where the triangle's edges
/// cross the near plane (`w + z = 0`). In a perspective view every point of the near plane has
/// `w = near`; where the f32 vertex stage has rounded the near plane away (a ground of extent
/// 1e8 under an eye with `near = 0.1`: `z = a·z_eye + b` loses `b`), they land on `w = 0`,
/// the triangle clips to nothing, and the limit is 0.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClipRange {
    /// Clipped triangles beyond their limit.
    pub triangles: usize,
    /// The largest clip coordinate `|p|` of the worst of them (largest `|p|` / limit).
    pub coordinate: f32,
    /// Its limit `2⁴³·w/side`.
    pub limit: f32,
}

impl ClipRange {
    /// `2⁴³`: the clip coordinates up to `2⁴³·w/side` are clipped within 1/256 px.
    pub const SCALE: f64 = (1u64 << 43) as f64;

    /// The range of triangle `tri` clipped to `poly` on a `width`×`height` target: one
    /// triangle beyond its limit, or nothing.
    pub fn of(tri: &[ClipVertex; 3], poly: &[ClipVertex], width: u32, height: u32) -> ClipRange {
        let coordinate = tri
            .iter()
            .map(|v| v.pos.abs().max_element())
            .fold(0.0, f32::max);
        // Where the edges cross the near plane (plane 4), interpolated as the clipper does.
        let near = (0..3).filter_map(|i| {
            let (a, b) = (tri[i].pos.as_dvec4(), tri[(i + 1) % 3].pos.as_dvec4());
            let (da, db) = (plane_distance(a, 4), plane_distance(b, 4));
            ((da >= 0.0) != (db >= 0.0)).then(|| (a.w + (b.w - a.w) * (da / (da - db))) as f32)
        });
        let w = poly
            .iter()
            .map(|v| v.pos.w)
            .chain(near)
            .fold(f32::INFINITY, f32::min);
        if w == f32::INFINITY {
            return ClipRange::default(); // nothing left and no edge through the near plane
        }
        let limit = (Self::SCALE * f64::from(w.max(0.0)) / f64::from(width.max(height))) as f32;
        if coordinate <= limit {
            return ClipRange::default();
        }
        ClipRange {
            triangles: 1,
            coordinate,
            limit,
        }
    }

    /// Adds `other`'s triangles and keeps the worse of the two.
    pub fn merge(&mut self, other: ClipRange) {
        let ratio = |r: &ClipRange| f64::from(r.coordinate) / f64::from(r.limit);
        if other.triangles > 0 && (self.triangles == 0 || ratio(&other) > ratio(self)) {
            (self.coordinate, self.limit) = (other.coordinate, other.limit);
        }
        self.triangles += other.triangles;
    }
}

#[cfg(test)]
mod tests {
    use super::ClipRange;

    /// `merge` adds the counts and keeps the triangle furthest past its limit, also when a
    /// limit is 0.
    #[test]
    fn merge_keeps_the_worst() {
        let r = |coordinate, limit| ClipRange {
            triangles: 1,
            coordinate,
            limit,
        };
        let mut m = ClipRange::default();
        for x in [r(10.0, 5.0), r(1e9, 0.0), r(1e12, 1e3)] {
            m.merge(x);
        }
        assert_eq!(
            m,
            ClipRange {
                triangles: 3,
                ..r(1e9, 0.0)
            }
        );
        m.merge(ClipRange::default());
        assert_eq!(m.triangles, 3);
    }
}
