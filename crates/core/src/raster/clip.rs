//! Homogeneous clipping against the view frustum (Sutherland–Hodgman), as llvmpipe's draw
//! module does: geometrically, against all six planes, no guard band.

use glam::Vec4;

use crate::shade::Varyings;

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
fn plane_distance(p: Vec4, plane: usize) -> f32 {
    match plane {
        0 => p.w + p.x,
        1 => p.w - p.x,
        2 => p.w + p.y,
        3 => p.w - p.y,
        4 => p.w + p.z,
        _ => p.w - p.z,
    }
}

/// Bit i set when `p` is outside plane i.
#[inline]
pub fn outcode(p: Vec4) -> u8 {
    (0..6).fold(0, |code, i| {
        code | (((plane_distance(p, i) < 0.0) as u8) << i)
    })
}

/// Most vertices a triangle can have after six clip planes (3 + 6).
pub const MAX_CLIPPED: usize = 9;

/// Clips triangle `tri` against the frustum; writes the polygon into `out`, returns its length
/// (0 when nothing remains). Only the first `nvar` varyings are interpolated.
pub fn clip_triangle(
    tri: [ClipVertex; 3],
    nvar: usize,
    out: &mut [ClipVertex; MAX_CLIPPED + 3],
) -> usize {
    let mut a = [tri[0]; MAX_CLIPPED + 3];
    a[..3].copy_from_slice(&tri);
    let mut n = 3;
    let mut b = a;
    for plane in 0..6 {
        let mut m = 0;
        for i in 0..n {
            let cur = a[i];
            let next = a[(i + 1) % n];
            let dc = plane_distance(cur.pos, plane);
            let dn = plane_distance(next.pos, plane);
            if dc >= 0.0 {
                b[m] = cur;
                m += 1;
            }
            // The edge crosses the plane: emit the intersection, interpolated from the inside
            // vertex so that shared edges clip to the same point from both triangles.
            if (dc >= 0.0) != (dn >= 0.0) {
                let (inside, outside, di, dout) = if dc >= 0.0 {
                    (cur, next, dc, dn)
                } else {
                    (next, cur, dn, dc)
                };
                let t = di / (di - dout);
                let mut v = inside;
                v.pos = inside.pos + (outside.pos - inside.pos) * t;
                for k in 0..nvar {
                    v.var[k] = inside.var[k] + (outside.var[k] - inside.var[k]) * t;
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
    out[..n].copy_from_slice(&a[..n]);
    n
}
