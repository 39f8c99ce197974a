//! Depth precision as an accuracy knob (`[raster] depth`): the depth test on a key other than
//! lavapipe's f32 window depth. [`DepthMode::Standard`] never comes here: `rasterize` keeps its
//! own (lavapipe's) path for it, so the default's bytes do not depend on this file.
//!
//! Why it matters. The perspective window depth `z_w = f (z − n) / ((f − n) z)` crowds every
//! distant surface just below 1.0, where f32 is spaced 2⁻²⁴ apart: two surfaces at eye depth `z`
//! closer than about `2⁻²⁴ z² / n` get the same depth value and fight, and with a tiny near
//! plane every surface rounds to 1.0 and is lost against the cleared buffer. The remedies:
//!
//! - **Reversed-Z** (`DepthMode::ReversedZ`): store `1 − z_w`, i.e. the key
//!   `k = n f / (f − n) · (1/w) − n / (f − n)` (1 at the near plane, 0 at the far plane),
//!   computed from the clip `w` (the eye depth, exact to an ulp) so that no `1 − z_w`
//!   cancellation happens, and test GREATER against a buffer cleared to 0. Floats are densest
//!   near 0, which is where distant surfaces now land: their spacing cancels the `z²/n` law and
//!   the resolution becomes about `2⁻²⁴ z` relative, whatever `n`. With an infinite far plane
//!   (`far = ∞`) the key is `n / w` exactly: no subtraction at all.
//! - **f64** (`DepthMode::F64`): the key `1/w` (which orders surfaces as `z_w` does, reversed)
//!   set up from the clip coordinates and interpolated in f64, tested in an f64 buffer.
//!
//! Coverage, varyings and the fragment stage are the standard path's ([`setup_triangle`],
//! [`SetupTriangle::spans`]); only the depth key and its test differ. What is stored in the
//! framebuffer's depth (which the effects read) is still the standard f32 window depth of the
//! fragment that won the test, so depth outputs keep their meaning (and their f32 precision).
//! One thread, no SIMD: the knob trades time for accuracy, and `stereolab bench --only depth`
//! measures by how much.

use glam::Vec4;

use super::clip::{ClipRange, ClipVertex, MAX_CLIPPED, clip_triangle, outcode};
use super::setup::{DepthPlane, Setup, SetupTriangle, WindowVertex, setup_triangle};
use super::{RasterOptions, RasterStats};
use crate::framebuffer::Framebuffer;
use crate::shade::{Fragment, MAX_VARYINGS, Shader, Varyings};

/// Which depth the depth test compares (`[raster] depth`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum DepthMode {
    /// lavapipe's: f32 window depth `z_w`, test LESS, cleared to 1.0. The default.
    #[default]
    Standard,
    /// Reversed-Z in an f32 buffer: key `n f/(f − n)·(1/w) − n/(f − n)`, test GREATER, cleared
    /// to 0. `far = f32::INFINITY` is the infinite far plane (key `n/w`). `near`, `far` are the
    /// camera's clip distances (the scene sets them).
    ReversedZ {
        /// Near plane distance n.
        near: f32,
        /// Far plane distance f, or infinity.
        far: f32,
    },
    /// The key `1/w` set up and interpolated in f64, tested in an f64 buffer.
    F64,
}

impl DepthMode {
    /// The name the scene file uses.
    pub fn name(&self) -> &'static str {
        match self {
            DepthMode::Standard => "standard",
            DepthMode::ReversedZ { far, .. } if far.is_infinite() => "reversed-z, infinite far",
            DepthMode::ReversedZ { .. } => "reversed-z",
            DepthMode::F64 => "f64",
        }
    }

    /// The reversed-Z key's affine map `k = a·(1/w) + b`, from the clip distances (in f64,
    /// rounded once).
    fn reversed_coefficients(near: f32, far: f32) -> (f32, f32) {
        let (n, f) = (f64::from(near), f64::from(far));
        if f.is_infinite() {
            (near, 0.0)
        } else {
            ((n * f / (f - n)) as f32, (-n / (f - n)) as f32)
        }
    }
}

/// A plane `k(x, y) = k0 + dx (x − x0) + dy (y − y0)` in f64 through three window points.
#[derive(Clone, Copy, Debug)]
struct Plane64 {
    x0: f64,
    y0: f64,
    k0: f64,
    dx: f64,
    dy: f64,
}

impl Plane64 {
    /// Through `(x, y, k)` ×3; `None` for a triangle without area.
    fn new(p: [(f64, f64, f64); 3]) -> Option<Plane64> {
        let [(x0, y0, k0), (x1, y1, k1), (x2, y2, k2)] = p;
        let (dx1, dy1, dk1) = (x1 - x0, y1 - y0, k1 - k0);
        let (dx2, dy2, dk2) = (x2 - x0, y2 - y0, k2 - k0);
        let det = dx1 * dy2 - dx2 * dy1;
        let plane = Plane64 {
            x0,
            y0,
            k0,
            dx: (dk1 * dy2 - dk2 * dy1) / det,
            dy: (dk2 * dx1 - dk1 * dx2) / det,
        };
        (det != 0.0 && plane.dx.is_finite() && plane.dy.is_finite()).then_some(plane)
    }

    /// The key at pixel (`px`, `py`)'s centre.
    fn at(&self, px: u32, py: u32) -> f64 {
        let (x, y) = (f64::from(px) + 0.5, f64::from(py) + 0.5);
        self.k0 + self.dx * (x - self.x0) + self.dy * (y - self.y0)
    }
}

/// One sub-triangle's depth key.
enum Key {
    F32(DepthPlane),
    F64(Plane64),
}

/// The depth-key buffer of one pass: f32 for reversed-Z, f64 for [`DepthMode::F64`], cleared
/// to 0 (the far side, as the keys grow towards the eye).
enum KeyBuffer {
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// Window position in f64 of a clip position (the f64 twin of `WindowVertex::from_clip`).
fn window64(p: Vec4, width: u32, height: u32) -> (f64, f64, f64) {
    let (x, y, w) = (f64::from(p.x), f64::from(p.y), f64::from(p.w));
    let (hw, hh) = (f64::from(width) * 0.5, f64::from(height) * 0.5);
    ((x / w) * hw + hw, (y / w) * -hh + hh, 1.0 / w)
}

/// [`super::rasterize`] for a [`RasterOptions::depth`] other than `Standard`: the same
/// clipping, coverage and fragment stage, the depth test on the mode's key (module docs).
pub(super) fn rasterize<S: Shader>(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    shader: &S,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
) -> RasterStats {
    let (width, height) = (fb.width, fb.height);
    let nvar = shader.varying_count().min(MAX_VARYINGS);
    let verts: Vec<ClipVertex> = (0..vertex_count as u32)
        .map(|i| {
            let mut var: Varyings = [0.0; MAX_VARYINGS];
            let pos = shader.vertex(i, &mut var);
            ClipVertex { pos, var }
        })
        .collect();
    let mut keys = match opts.depth {
        DepthMode::F64 => KeyBuffer::F64(vec![0.0; fb.depth.len()]),
        _ => KeyBuffer::F32(vec![0.0; fb.depth.len()]),
    };
    let mut stats = RasterStats {
        triangles: triangles.len(),
        ..Default::default()
    };
    let blank = ClipVertex {
        pos: Vec4::ZERO,
        var: [0.0; MAX_VARYINGS],
    };
    let mut poly = [blank; MAX_CLIPPED + 3];
    for tri in triangles {
        let (Some(a), Some(b), Some(c)) = (
            verts.get(tri[0] as usize),
            verts.get(tri[1] as usize),
            verts.get(tri[2] as usize),
        ) else {
            stats.non_finite += 1;
            continue;
        };
        if [a, b, c].iter().any(|v| !v.pos.is_finite()) {
            stats.non_finite += 1;
            continue;
        }
        let codes = [outcode(a.pos), outcode(b.pos), outcode(c.pos)];
        if codes[0] & codes[1] & codes[2] != 0 {
            continue;
        }
        let n = if codes[0] | codes[1] | codes[2] == 0 {
            poly[..3].copy_from_slice(&[*a, *b, *c]);
            3
        } else {
            stats.clipped += 1;
            let n = clip_triangle([*a, *b, *c], nvar, &mut poly);
            let range = ClipRange::of(&[*a, *b, *c], &poly[..n], width, height);
            stats.clip_range.merge(range);
            n
        };
        let mut culled = false;
        for k in 1..n.saturating_sub(1) {
            let fan = [poly[0], poly[k], poly[k + 1]];
            let w = fan.map(|v| WindowVertex::from_clip(&v, width, height));
            let (Some(w0), Some(w1), Some(w2)) = (w[0], w[1], w[2]) else {
                continue;
            };
            let var = [&fan[0].var, &fan[1].var, &fan[2].var];
            let t = match setup_triangle([w0, w1, w2], var, nvar, width, height, opts) {
                Setup::Triangle(t) => t,
                Setup::Culled => {
                    culled = true;
                    continue;
                }
                Setup::Empty => continue,
            };
            let key = match opts.depth {
                DepthMode::F64 => {
                    Plane64::new(fan.map(|v| window64(v.pos, width, height))).map(Key::F64)
                }
                DepthMode::ReversedZ { near, far } => {
                    let (ka, kb) = DepthMode::reversed_coefficients(near, far);
                    let k = |v: &WindowVertex| (v.depth_x, v.depth_y, ka.mul_add(v.inv_w, kb));
                    DepthPlane::new([k(&w0), k(&w1), k(&w2)]).map(Key::F32)
                }
                DepthMode::Standard => None,
            };
            let Some(key) = key else { continue };
            stats.fragments += traverse_keyed(&t, &key, &mut keys, shader, fb, opts);
        }
        stats.culled += culled as usize;
    }
    stats
}

/// Walks one set-up triangle: coverage as [`SetupTriangle::spans`], depth test GREATER on the
/// key, then the fragment stage as `traverse` runs it; the framebuffer's depth gets the
/// standard window depth of each fragment written.
fn traverse_keyed<S: Shader>(
    t: &SetupTriangle,
    key: &Key,
    keys: &mut KeyBuffer,
    shader: &S,
    fb: &mut Framebuffer,
    opts: &RasterOptions,
) -> usize {
    let width = fb.width;
    let writes_color = shader.writes_color();
    let nvar = shader.varying_count().min(MAX_VARYINGS);
    let mut frag_var: Varyings = [0.0; MAX_VARYINGS];
    let mut fragments = 0;
    t.spans(0, 0, width, fb.height, |py, x_lo, x_hi| {
        for px in x_lo..=x_hi {
            let idx = py as usize * width as usize + px as usize;
            let (pass, k) = match (key, &*keys) {
                (Key::F32(p), KeyBuffer::F32(buf)) => {
                    let k = p.at_pixel(px as i32 as f32, py as i32 as f32);
                    (!opts.depth_test || k > buf[idx], f64::from(k))
                }
                (Key::F64(p), KeyBuffer::F64(buf)) => {
                    let k = p.at(px, py);
                    (!opts.depth_test || k > buf[idx], k)
                }
                _ => (false, 0.0),
            };
            if !pass {
                continue;
            }
            let z = t.depth_at(px, py);
            if writes_color {
                let (fx, fy) = (t.fx(px), t.fy(py));
                let w = t.w_at(fx, fy, opts.perspective_correct);
                for (out, plane) in frag_var.iter_mut().zip(&t.var[..nvar]) {
                    *out = plane.at(fx, fy) * w;
                }
                let f = Fragment {
                    x: px,
                    y: py,
                    depth: z,
                    varyings: &frag_var,
                    front_facing: t.front_facing,
                };
                let Some(col) = shader.fragment(&f) else {
                    continue;
                };
                fb.color[idx] = col;
            }
            if opts.depth_test {
                match keys {
                    KeyBuffer::F32(buf) => buf[idx] = k as f32,
                    KeyBuffer::F64(buf) => buf[idx] = k,
                }
                fb.depth[idx] = z;
            }
            fragments += 1;
        }
    });
    fragments
}
