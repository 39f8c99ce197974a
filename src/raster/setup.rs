//! Fixed-point triangle setup and traversal: llvmpipe's rules, written out in DESIGN.md.

use crate::framebuffer::Framebuffer;
use crate::shade::{Fragment, MAX_VARYINGS, Shader, Varyings};

use super::RasterOptions;
use super::clip::ClipVertex;

/// A vertex in window space: x right, y down (row 0 at the top), z in [0, 1], and 1/w.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowVertex {
    /// Window x in pixels (pixel centers at +0.5).
    pub x: f32,
    /// Window y in pixels, downwards.
    pub y: f32,
    /// Window depth, `glDepthRange(0, 1)`.
    pub z: f32,
    /// 1 / clip w, for perspective-correct varyings.
    pub inv_w: f32,
}

impl WindowVertex {
    /// Perspective divide and viewport transform: `x_win = (x/w)·W/2 + W/2`,
    /// `y_win = (y/w)·(−H/2) + H/2` (NDC y = +1 is the top row), `z_win = (z/w)/2 + 1/2`.
    /// `None` when w ≤ 0 (only possible for unclipped input).
    pub fn from_clip(v: &ClipVertex, width: u32, height: u32) -> Option<Self> {
        let p = v.pos;
        if p.w <= 0.0 {
            return None;
        }
        let (hw, hh) = (width as f32 * 0.5, height as f32 * 0.5);
        Some(WindowVertex {
            x: (p.x / p.w) * hw + hw,
            y: (p.y / p.w) * -hh + hh,
            z: (p.z / p.w) * 0.5 + 0.5,
            inv_w: 1.0 / p.w,
        })
    }
}

/// Snaps a window coordinate to the subpixel grid so that pixel `p` samples at `p << bits`:
/// `round((c − 0.5) · 2^bits)`, rounding half to even as SSE `cvtps2dq` does.
#[inline]
pub fn snap(coord: f32, bits: u32) -> i64 {
    ((coord - 0.5) * (1u32 << bits) as f32).round_ties_even() as i64
}

/// What one window-space triangle did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TriangleStats {
    /// 1 when back-face culling removed it.
    pub culled: usize,
    /// Fragments that passed the depth test.
    pub fragments: usize,
}

/// A linear function of window position, `a0 + dadx (x − x0) + dady (y − y0)`.
#[derive(Clone, Copy)]
struct Plane {
    a0: f32,
    dadx: f32,
    dady: f32,
}

/// Rasterizes one window-space triangle: coverage from the snapped fixed-point edge functions,
/// depth and varyings from float plane equations evaluated at pixel centers.
pub fn rasterize_window_triangle<S: Shader>(
    v: [WindowVertex; 3],
    var: [&Varyings; 3],
    nvar: usize,
    shader: &S,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
) -> TriangleStats {
    let mut stats = TriangleStats::default();
    let bits = opts.subpixel_bits.clamp(1, 16);
    let (mut xs, mut ys) = ([0i64; 3], [0i64; 3]);
    for i in 0..3 {
        xs[i] = snap(v[i].x, bits);
        ys[i] = snap(v[i].y, bits);
    }
    let area = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (xs[2] - xs[0]) * (ys[1] - ys[0]);
    if area == 0 {
        return stats; // zero area on the grid: draws nothing
    }
    // Counter-clockwise in NDC (y up) is a negative area in window space (y down).
    let front_facing = area < 0;
    if opts.cull_back && !front_facing {
        stats.culled = 1;
        return stats;
    }
    if area > 0 {
        xs.swap(1, 2);
        ys.swap(1, 2);
    }
    // Edge functions: pixel (px, py) is covered when c + dcdy·py·S − dcdx·px·S − 1 ≥ 0 on all
    // three edges; the +1 on left/top edges is the top-left tie-break.
    let mut c = [0i64; 3];
    let mut dcdx = [0i64; 3];
    let mut dcdy = [0i64; 3];
    for i in 0..3 {
        let j = (i + 1) % 3;
        dcdx[i] = ys[i] - ys[j];
        dcdy[i] = xs[i] - xs[j];
        c[i] = dcdx[i] * xs[i] - dcdy[i] * ys[i];
        if dcdx[i] < 0 || (dcdx[i] == 0 && dcdy[i] > 0) {
            c[i] += 1;
        }
        c[i] -= 1;
    }
    let s = 1i64 << bits;
    let ceil_div = |a: i64| a.div_euclid(s) + (a.rem_euclid(s) != 0) as i64;
    let px0 = ceil_div(*xs.iter().min().unwrap_or(&0)).max(0);
    let py0 = ceil_div(*ys.iter().min().unwrap_or(&0)).max(0);
    let px1 = xs
        .iter()
        .max()
        .unwrap_or(&0)
        .div_euclid(s)
        .min(fb.width as i64 - 1);
    let py1 = ys
        .iter()
        .max()
        .unwrap_or(&0)
        .div_euclid(s)
        .min(fb.height as i64 - 1);
    if px0 > px1 || py0 > py1 {
        return stats;
    }

    // Attribute planes from the float window positions (as llvmpipe's coefficient setup does).
    let (dx1, dy1) = (v[1].x - v[0].x, v[1].y - v[0].y);
    let (dx2, dy2) = (v[2].x - v[0].x, v[2].y - v[0].y);
    let det = dx1 * dy2 - dx2 * dy1;
    if det == 0.0 || !det.is_finite() {
        return stats;
    }
    let plane = |a: [f32; 3]| {
        let (da1, da2) = (a[1] - a[0], a[2] - a[0]);
        Plane {
            a0: a[0],
            dadx: (da1 * dy2 - da2 * dy1) / det,
            dady: (da2 * dx1 - da1 * dx2) / det,
        }
    };
    let z_plane = plane([v[0].z, v[1].z, v[2].z]);
    let w_plane = plane([v[0].inv_w, v[1].inv_w, v[2].inv_w]);
    let mut var_planes = [z_plane; MAX_VARYINGS];
    for (k, p) in var_planes.iter_mut().enumerate().take(nvar) {
        *p = if opts.perspective_correct {
            plane([
                var[0][k] * v[0].inv_w,
                var[1][k] * v[1].inv_w,
                var[2][k] * v[2].inv_w,
            ])
        } else {
            plane([var[0][k], var[1][k], var[2][k]])
        };
    }
    let writes_color = shader.writes_color();
    let mut frag_var: Varyings = [0.0; MAX_VARYINGS];

    for py in py0..=py1 {
        let sy = py * s;
        let mut e = [0i64; 3];
        for i in 0..3 {
            e[i] = c[i] + dcdy[i] * sy - dcdx[i] * px0 * s;
        }
        let step = [dcdx[0] * s, dcdx[1] * s, dcdx[2] * s];
        let fy = py as f32 + 0.5 - v[0].y;
        let row = py as usize * fb.width as usize;
        for px in px0..=px1 {
            let inside = (e[0] | e[1] | e[2]) >= 0;
            for i in 0..3 {
                e[i] -= step[i];
            }
            if !inside {
                continue;
            }
            let fx = px as f32 + 0.5 - v[0].x;
            let z = (z_plane.a0 + z_plane.dadx * fx + z_plane.dady * fy).clamp(0.0, 1.0);
            let idx = row + px as usize;
            if opts.depth_test && z >= fb.depth[idx] {
                continue;
            }
            if writes_color {
                let inv_w = w_plane.a0 + w_plane.dadx * fx + w_plane.dady * fy;
                for k in 0..nvar {
                    let p = var_planes[k];
                    let a = p.a0 + p.dadx * fx + p.dady * fy;
                    frag_var[k] = if opts.perspective_correct {
                        a / inv_w
                    } else {
                        a
                    };
                }
                let f = Fragment {
                    x: px as u32,
                    y: py as u32,
                    depth: z,
                    varyings: &frag_var,
                    front_facing,
                };
                let Some(col) = shader.fragment(&f) else {
                    continue;
                }; // discard: no writes
                fb.color[idx] = col;
            }
            if opts.depth_test {
                fb.depth[idx] = z;
            }
            stats.fragments += 1;
        }
    }
    stats
}
