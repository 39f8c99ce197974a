//! Fixed-point triangle setup: snapping, orientation, the edge functions and their coverage
//! rule ([`SetupTriangle::covers`]), and the attribute planes. llvmpipe's rules, written out in
//! docs/ARCHITECTURE.md "Rasterization rules"; walking the covered pixels is in `traverse.rs`.

use crate::shade::{MAX_VARYINGS, Varyings};
use std::mem::MaybeUninit;

use super::RasterOptions;
use super::clip::ClipVertex;

/// A vertex in window space: x right, y down (row 0 at the top), z in [0, 1], and 1/w.
///
/// Two versions of x and y: `x`, `y` place the vertex for coverage and the varyings; `depth_x`,
/// `depth_y` are the same point as llvmpipe's viewport transform rounds it, for the depth
/// plane alone (see `WindowVertex::from_clip` and [`DepthPlane`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowVertex {
    /// Window x in pixels (pixel centers at +0.5).
    pub x: f32,
    /// Window y in pixels, downwards.
    pub y: f32,
    /// Window depth, `glDepthRange(0, 1)`, rounded as lavapipe rounds it.
    pub z: f32,
    /// 1 / clip w, for perspective-correct varyings.
    pub inv_w: f32,
    /// Window x as llvmpipe computes it: `fma(x·(1/w), W/2, W/2)`.
    pub depth_x: f32,
    /// Window y as llvmpipe computes it: `fma(y·(1/w), −H/2, H/2)`.
    pub depth_y: f32,
}

impl WindowVertex {
    /// Perspective divide and viewport transform: mathematically `x_win = (x/w)·W/2 + W/2`,
    /// `y_win = (y/w)·(−H/2) + H/2` (NDC y = +1 is the top row), `z_win = (z/w)/2 + 1/2`.
    /// `None` when w ≤ 0 (only possible for unclipped input).
    ///
    /// The depth plane's inputs are rounded as lavapipe rounds them, so that depth can match
    /// it bit for bit (docs/gpu-parity.md "Depth bit for bit"):
    /// - `z_win = (0.5·(z + w))·(1/w)`: the GPU path's vertex stage turns OpenGL's clip z
    ///   into wgpu's as `0.5·(z + w)` (`gpu::GL_TO_WGPU_DEPTH`'s row, `gl_to_wgpu_depth` in
    ///   the shaders), and llvmpipe's viewport (`generate_viewport` in Mesa's `draw_llvm.c`)
    ///   multiplies by its `1/w` (an IEEE division), then applies Vulkan's depth scale 1 and
    ///   offset 0, which change nothing. Mathematically this is `(z/w)/2 + 1/2`.
    /// - `depth_x = fma(x·(1/w), W/2, W/2)`, `depth_y = fma(y·(1/w), −H/2, H/2)`: the same
    ///   viewport code computes `(c·(1/w))·scale + translate` with `lp_build_fmuladd`, which
    ///   LLVM fuses into one FMA instruction on a CPU that has it.
    ///
    /// `x` and `y` (coverage and varyings) are computed the same way, then clamped to the
    /// viewport. They do not keep the division `(x/w)` of OpenGL's formula: snapped to 1/256
    /// pixel the last bit almost never matters, but on one shipped view
    /// (`wuson_zero_parallax_fit`) it does: with the division a snapped vertex lands on the
    /// other side of a pixel centre, and a different triangle wins that pixel on the GPU.
    pub(crate) fn from_clip(v: &ClipVertex, width: u32, height: u32) -> Option<Self> {
        let p = v.pos;
        if p.w <= 0.0 {
            return None;
        }
        let (hw, hh) = (width as f32 * 0.5, height as f32 * 0.5);
        let inv_w = 1.0 / p.w;
        if !inv_w.is_finite() {
            return None; // w so small its reciprocal overflows: nothing sensible to draw
        }
        // After clipping |x|, |y|, |z| ≤ w holds mathematically; with extreme magnitudes the
        // intersection rounding can leave a vertex far outside. Clamping NDC to [−1, 1] changes
        // no sample point inside the viewport and keeps the fixed-point math from overflowing.
        // The depth plane's positions are not clamped (llvmpipe does not): they only enter
        // float arithmetic, whose overflow setup turns into an empty triangle.
        // Positions as llvmpipe's viewport computes them: `fma(x·(1/w), W/2, W/2)`. Clamping
        // the window position to [0, W] is clamping NDC to [−1, 1] (the map is monotonic and
        // sends ±1 exactly to the edges), so one evaluation serves both.
        let depth_x = (p.x * inv_w).mul_add(hw, hw);
        let depth_y = (p.y * inv_w).mul_add(-hh, hh);
        Some(WindowVertex {
            x: depth_x.clamp(0.0, width as f32),
            y: depth_y.clamp(0.0, height as f32),
            z: (0.5 * (p.z + p.w)) * inv_w,
            inv_w,
            depth_x,
            depth_y,
        })
    }
}

/// Snaps a window coordinate to the subpixel grid so that pixel `p` samples at `p << bits`:
/// `round((c − 0.5) · 2^bits)`, rounding half to even as SSE `cvtps2dq` does.
#[inline]
pub(crate) fn snap(coord: f32, bits: u32) -> i64 {
    round_ties_even((coord - 0.5) * (1u32 << bits) as f32) as i64
}

/// `v.round_ties_even()` without the libm call it is on baseline x86-64 (no SSE4.1 `roundss`):
/// adding and subtracting 1.5·2²³ rounds to a whole number in the FPU's ties-to-even mode,
/// exactly, while `|v| < 2²²`; larger values (and NaN) take the library path.
#[inline]
fn round_ties_even(v: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0; // 1.5 · 2²³
    if v.abs() < 4_194_304.0 {
        (v + MAGIC) - MAGIC
    } else {
        v.round_ties_even()
    }
}

/// A linear function of window position, `a0 + dadx (x − x0) + dady (y − y0)`, evaluated as
/// `(a0 + dadx·fx) + dady·fy` (a SIMD evaluation must keep that order to give the same bits).
#[derive(Clone, Copy, Debug)]
pub struct Plane {
    /// Value at the origin (vertex 0).
    pub a0: f32,
    /// Change per pixel to the right.
    pub dadx: f32,
    /// Change per pixel down.
    pub dady: f32,
}

impl Plane {
    /// The value at offset (`fx`, `fy`) from the origin.
    #[inline]
    pub fn at(&self, fx: f32, fy: f32) -> f32 {
        self.a0 + self.dadx * fx + self.dady * fy
    }
}

/// The window-depth plane as llvmpipe sets it up and evaluates it, so that depth matches
/// lavapipe's bit for bit: `z(px, py) = fma(dzdy, py, fma(dzdx, px, a0))` at pixel (`px`,
/// `py`) given by its integer column and row, with `a0` the depth at the point (−½, −½), so
/// that the integers land on pixel centres.
///
/// From Mesa 22.3's llvmpipe, which lavapipe runs:
/// - setup (`init_args` and `calc_coef4` in `lp_state_setup.c`), from the window positions
///   of the vertices in llvmpipe's order (below): `dxy01 = v0 − v1`, `dxy20 = v2 − v0`,
///   `ooa = 1 / (dx01·dy20 − dy01·dx20)`, the four differences times `ooa`, then
///   `dzdx = dz01·(dy20·ooa) − dz20·(dy01·ooa)`, `dzdy = dz20·(dx01·ooa) − dz01·(dx20·ooa)`
///   and `a0 = z0 − (dzdx·(x0 − ½) + dzdy·(y0 − ½))`, each operation rounded on its own;
/// - evaluation (`attribs_update_simple` in `lp_bld_interp.c`): `a0 + dadx·x + dady·y` as two
///   `lp_build_fmuladd`, fused by LLVM into FMA instructions on a CPU that has them (here
///   `f32::mul_add`: the same correctly rounded fused operation, on every CPU);
/// - the vertex order (`triangle_both` in `lp_setup_tri.c`): as submitted when the snapped
///   triangle is counter-clockwise on screen (our area `A < 0`), else `v0, v2, v1` (Vulkan's
///   first provoking vertex: `rotate_fixed_position_12`);
/// - then clamped to [0, 1] (`lp_build_depth_clamp` in `lp_state_fs.c`) and stored in the
///   32-bit float depth buffer as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthPlane {
    /// Depth at the point (−½, −½): pixel (0, 0)'s centre minus one step in x and y.
    pub a0: f32,
    /// Change per pixel to the right.
    pub dzdx: f32,
    /// Change per pixel down.
    pub dzdy: f32,
}

impl DepthPlane {
    /// llvmpipe's setup of the plane through three (x, y, z) window points, in that order;
    /// `None` when the triangle has no area in floating point or a coefficient is not finite.
    pub fn new(v: [(f32, f32, f32); 3]) -> Option<DepthPlane> {
        let [(x0, y0, z0), (x1, y1, z1), (x2, y2, z2)] = v;
        let (x0_center, y0_center) = (x0 - 0.5, y0 - 0.5);
        let (dx01, dy01) = (x0 - x1, y0 - y1);
        let (dx20, dy20) = (x2 - x0, y2 - y0);
        let ooa = 1.0 / (dx01 * dy20 - dy01 * dx20);
        let (dx20_ooa, dy20_ooa) = (dx20 * ooa, dy20 * ooa);
        let (dx01_ooa, dy01_ooa) = (dx01 * ooa, dy01 * ooa);
        let (dz01, dz20) = (z0 - z1, z2 - z0);
        let dzdx = dz01 * dy20_ooa - dz20 * dy01_ooa;
        let dzdy = dz20 * dx01_ooa - dz01 * dx20_ooa;
        let a0 = z0 - (dzdx * x0_center + dzdy * y0_center);
        let plane = DepthPlane { a0, dzdx, dzdy };
        (a0.is_finite() && dzdx.is_finite() && dzdy.is_finite()).then_some(plane)
    }

    /// The depth at pixel (`px`, `py`), before clamping: `fma(dzdy, py, fma(dzdx, px, a0))`.
    #[inline]
    pub fn at_pixel(&self, px: f32, py: f32) -> f32 {
        self.dzdy.mul_add(py, self.dzdx.mul_add(px, self.a0))
    }
}

/// A triangle after setup: fixed-point edge functions, its pixel bounds, and the attribute
/// planes. Traversal needs nothing else, so one setup serves every band of rows.
#[derive(Clone, Debug)]
pub struct SetupTriangle {
    /// Edge `i` at subpixel grid point `(x, y)` is `c[i] + dcdy[i]·y − dcdx[i]·x`, with
    /// llvmpipe's `c + bias − 1` stored as `c` (see [`SetupTriangle::covers`]).
    pub(super) c: [i64; 3],
    pub(super) dcdx: [i64; 3],
    pub(super) dcdy: [i64; 3],
    /// Subpixel bits: pixel `p` samples at grid position `p << bits`.
    pub(super) bits: u32,
    /// Pixel bounds, inclusive, clamped to the target.
    pub(super) px0: i64,
    pub(super) px1: i64,
    pub(super) py0: i64,
    pub(super) py1: i64,
    pub(super) front_facing: bool,
    /// Window position of vertex 0: the planes' origin.
    pub(super) x0: f32,
    pub(super) y0: f32,
    pub(super) z: DepthPlane,
    pub(super) inv_w: Plane,
    pub(super) var: [Plane; MAX_VARYINGS],
    pub(super) nvar: usize,
}

/// The outcome of [`setup_triangle`]. Not boxed: setup runs once per triangle per pass, and a
/// heap allocation each time cost more than moving the larger value.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub enum Setup {
    /// Covers no sample point (zero area on the grid, outside the target, degenerate).
    Empty,
    /// Back-facing and culled.
    Culled,
    /// Ready to traverse.
    Triangle(SetupTriangle),
}

/// Triangle setup: snap to the subpixel grid, orient, build the edge functions with the
/// top-left tie-break, clamp the bounds to a `width`×`height` target, and build the attribute
/// planes from the float window positions (as llvmpipe's coefficient setup does).
///
/// A small triangle (a box of at most eight pixel centers) that covers none of them is `Empty`
/// before its planes are built.
pub fn setup_triangle(
    v: [WindowVertex; 3],
    var: [&Varyings; 3],
    nvar: usize,
    width: u32,
    height: u32,
    opts: &RasterOptions,
) -> Setup {
    setup_triangle_culling(v, var, nvar, (width, height), opts, true)
}

/// What [`setup_into`] made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Outcome {
    /// [`Setup::Empty`].
    Empty,
    /// [`Setup::Culled`].
    Culled,
    /// [`Setup::Triangle`]: `out` now holds it.
    Triangle,
}

/// [`setup_triangle`], with the small-triangle test (`cull_small`) or without it.
fn setup_triangle_culling(
    v: [WindowVertex; 3],
    var: [&Varyings; 3],
    nvar: usize,
    size: (u32, u32),
    opts: &RasterOptions,
    cull_small: bool,
) -> Setup {
    let mut out = MaybeUninit::uninit();
    match setup_into(v, var, nvar, size, opts, cull_small, &mut out) {
        Outcome::Empty => Setup::Empty,
        Outcome::Culled => Setup::Culled,
        // SAFETY: `setup_into` wrote `out` (its outcome says so).
        Outcome::Triangle => Setup::Triangle(unsafe { out.assume_init() }),
    }
}

/// [`setup_triangle`] (with the small-triangle test when `cull_small`), the set-up triangle
/// written into `out` exactly when the outcome is [`Outcome::Triangle`]: a caller that keeps
/// it in a `Vec` writes it in place instead of moving the 248 bytes once more.
pub(crate) fn setup_into(
    v: [WindowVertex; 3],
    var: [&Varyings; 3],
    nvar: usize,
    (width, height): (u32, u32),
    opts: &RasterOptions,
    cull_small: bool,
    out: &mut MaybeUninit<SetupTriangle>,
) -> Outcome {
    let bits = opts.subpixel_bits.clamp(1, 16);
    let (mut xs, mut ys) = ([0i64; 3], [0i64; 3]);
    for i in 0..3 {
        xs[i] = snap(v[i].x, bits);
        ys[i] = snap(v[i].y, bits);
    }
    let area = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (xs[2] - xs[0]) * (ys[1] - ys[0]);
    if area == 0 {
        return Outcome::Empty; // zero area on the grid: draws nothing
    }
    // Counter-clockwise in NDC (y up) is a negative area in window space (y down).
    let front_facing = area < 0;
    if opts.cull_back && !front_facing {
        return Outcome::Culled;
    }
    if area > 0 {
        xs.swap(1, 2);
        ys.swap(1, 2);
    }
    // Edge functions, stored as c + bias − 1: the rule and its tie-break are written out in
    // `SetupTriangle::covers`.
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
    // Floor and ceiling division by the power of two S: shifts, not `idiv`.
    let floor_div = |a: i64| a >> bits;
    let ceil_div = |a: i64| (a >> bits) + (a & (s - 1) != 0) as i64;
    let px0 = ceil_div(xs[0].min(xs[1]).min(xs[2])).max(0);
    let py0 = ceil_div(ys[0].min(ys[1]).min(ys[2])).max(0);
    let px1 = floor_div(xs[0].max(xs[1]).max(xs[2])).min(width as i64 - 1);
    let py1 = floor_div(ys[0].max(ys[1]).max(ys[2])).min(height as i64 - 1);
    let bounds = [px0, px1, py0, py1];
    if px0 > px1 || py0 > py1 || (cull_small && covers_no_center(&c, &dcdx, &dcdy, bits, bounds)) {
        return Outcome::Empty;
    }
    let (dx1, dy1) = (v[1].x - v[0].x, v[1].y - v[0].y);
    let (dx2, dy2) = (v[2].x - v[0].x, v[2].y - v[0].y);
    let det = dx1 * dy2 - dx2 * dy1;
    if det == 0.0 || !det.is_finite() {
        return Outcome::Empty;
    }
    let plane = |a: [f32; 3]| {
        let (da1, da2) = (a[1] - a[0], a[2] - a[0]);
        Plane {
            a0: a[0],
            dadx: (da1 * dy2 - da2 * dy1) / det,
            dady: (da2 * dx1 - da1 * dx2) / det,
        }
    };
    // llvmpipe's vertex order: as submitted when counter-clockwise on screen, else v0, v2, v1.
    let order = if area > 0 { [0, 2, 1] } else { [0, 1, 2] };
    let Some(z) = DepthPlane::new(order.map(|i| (v[i].depth_x, v[i].depth_y, v[i].z))) else {
        return Outcome::Empty; // no area in floating point, or gradients that overflow f32
    };
    let inv_w = plane([v[0].inv_w, v[1].inv_w, v[2].inv_w]);
    let finite = |p: &Plane| p.a0.is_finite() && p.dadx.is_finite() && p.dady.is_finite();
    if !finite(&inv_w) {
        return Outcome::Empty; // a sliver so thin its gradients overflow f32
    }
    let mut var_planes = [inv_w; MAX_VARYINGS];
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
    out.write(SetupTriangle {
        c,
        dcdx,
        dcdy,
        bits,
        px0,
        px1,
        py0,
        py1,
        front_facing,
        x0: v[0].x,
        y0: v[0].y,
        z,
        inv_w,
        var: var_planes,
        nvar,
    });
    Outcome::Triangle
}

/// Boxes of at most this many pixel centers are tested by [`covers_no_center`].
const SMALL_BOX: i64 = 8;

/// Whether a small triangle covers none of the pixel centers in its box `[px0, px1, py0, py1]`
/// (inclusive), tested as [`SetupTriangle::covers`] tests one: such a triangle draws nothing,
/// so setup drops it before building its planes (small-triangle culling, as GPUs do; at a
/// million triangles on a 1024×768 image most triangles are smaller than a pixel). Boxes of more
/// than [`SMALL_BOX`] centers are not tested (`false`).
fn covers_no_center(
    c: &[i64; 3],
    dcdx: &[i64; 3],
    dcdy: &[i64; 3],
    bits: u32,
    b: [i64; 4],
) -> bool {
    let [px0, px1, py0, py1] = b;
    if (px1 - px0 + 1) * (py1 - py0 + 1) > SMALL_BOX {
        return false;
    }
    for py in py0..=py1 {
        for px in px0..=px1 {
            let (x, y) = (px << bits, py << bits);
            let e = |i: usize| c[i] + dcdy[i] * y - dcdx[i] * x;
            if (e(0) >= 0) & (e(1) >= 0) & (e(2) >= 0) {
                return false;
            }
        }
    }
    true
}

impl SetupTriangle {
    /// Whether the triangle covers pixel (`px`, `py`): the definition of coverage, tested edge
    /// by edge from the stored values. The fast walks ([`spans`](Self::spans),
    /// [`small_box`](Self::small_box) and the AVX2 loops built on them) are held to it pixel
    /// for pixel (tests/coverage.rs).
    ///
    /// llvmpipe's rule (docs/ARCHITECTURE.md "Rasterization rules"): the vertices are snapped
    /// to a grid of `S = 2^bits` steps per pixel, placed so that pixel `p`'s center is grid
    /// point `p·S` (`snap`), and ordered so that the inside is on the positive side. Edge `i`,
    /// from vertex `i` to vertex `i + 1`, has `dcdx = Y_i − Y_{i+1}`, `dcdy = X_i − X_{i+1}` and
    /// `c = dcdx·X_i − dcdy·Y_i`; the pixel is covered when, on all three edges,
    /// `c + bias + dcdy·py·S − dcdx·px·S − 1 ≥ 0`, in 64-bit integers.
    ///
    /// Tie-break: the value is 0 exactly when the pixel center lies on the edge. The `− 1`
    /// leaves such a pixel out, unless the edge has `bias = 1`: llvmpipe's left edges
    /// (`dcdx < 0`) and, of the horizontal ones, its top edges (`dcdy > 0`). An edge shared by
    /// two triangles is a left or top edge for exactly one of them, which alone gets the
    /// pixels on it: a top-left rule (window y down). Setup stores `c + bias − 1` as `c`.
    ///
    /// Pixels outside the target are tested the same way; the walks visit only a tile's.
    pub fn covers(&self, px: u32, py: u32) -> bool {
        let s = 1i64 << self.bits;
        // The pixel's center on the subpixel grid.
        let (x, y) = (px as i64 * s, py as i64 * s);
        (0..3).all(|i| self.c[i] + self.dcdy[i] * y - self.dcdx[i] * x >= 0)
    }

    /// First and last pixel row the triangle may cover.
    pub fn rows(&self) -> (u32, u32) {
        (self.py0 as u32, self.py1 as u32)
    }

    /// Pixel column `x`'s center relative to the planes' origin (the `fx` of the `*_at`
    /// functions). Through `i32`, which converts to `f32` in vector lanes; exact below 2²⁴.
    #[inline]
    pub fn fx(&self, x: u32) -> f32 {
        x as i32 as f32 + 0.5 - self.x0
    }

    /// Pixel row `y`'s center relative to the planes' origin.
    #[inline]
    pub fn fy(&self, y: u32) -> f32 {
        y as i32 as f32 + 0.5 - self.y0
    }

    /// The planes' origin: vertex 0's window position.
    pub fn origin(&self) -> (f32, f32) {
        (self.x0, self.y0)
    }

    /// The window-depth plane (before clamping).
    pub(crate) fn depth_plane(&self) -> DepthPlane {
        self.z
    }

    /// The 1/w plane.
    pub fn inv_w_plane(&self) -> Plane {
        self.inv_w
    }

    /// Varying `k`'s plane (of `a/w` when set up perspective-correct).
    pub fn varying_plane(&self, k: usize) -> Plane {
        self.var[k]
    }

    /// Window depth at pixel (`px`, `py`), clamped to [0, 1]: what the depth test compares
    /// (llvmpipe's evaluation, [`DepthPlane`]). The AVX2 loops compute the same lanes.
    #[inline]
    pub fn depth_at(&self, px: u32, py: u32) -> f32 {
        self.z
            .at_pixel(px as i32 as f32, py as i32 as f32)
            .clamp(0.0, 1.0)
    }

    /// The factor that turns an interpolated `a/w` back into `a` at (`fx`, `fy`): `w`, the
    /// reciprocal of the interpolated `1/w` (1 for affine interpolation).
    #[inline]
    pub(crate) fn w_at(&self, fx: f32, fy: f32, perspective_correct: bool) -> f32 {
        if perspective_correct {
            1.0 / self.inv_w.at(fx, fy)
        } else {
            1.0
        }
    }

    /// Varying `k` at (`fx`, `fy`), perspective-corrected when set up so (one reciprocal, one
    /// multiply, as the fragment stage of [`traverse`](super::traverse)).
    #[inline]
    pub fn varying_at(&self, k: usize, fx: f32, fy: f32, perspective_correct: bool) -> f32 {
        self.var[k].at(fx, fy) * self.w_at(fx, fy, perspective_correct)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::{DepthPlane, RasterOptions, Setup, WindowVertex, round_ties_even};
    use super::{SMALL_BOX, setup_triangle_culling};

    /// A xorshift generator of numbers in [0, 1) (24 bits), the same sequence for a seed.
    pub(in crate::raster) fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// The small-triangle test drops only triangles that draw nothing: on random triangles of
    /// up to three pixels (most of them covering no pixel center, some one or a few; half of
    /// them with corners on half pixels, pixel centers on their edges), every
    /// triangle it drops covers no pixel of its box when set up without it, and every other
    /// triangle is set up exactly as without it. Both outcomes occur many times.
    #[test]
    fn small_triangles_are_dropped_only_when_they_cover_no_pixel() {
        let mut next = uniform(0x9e37_79b9_7f4a_7c15u64);
        let opts = RasterOptions::default();
        let var = [0.25f32; crate::shade::MAX_VARYINGS];
        let (mut dropped, mut kept) = (0, 0);
        for n in 0..20_000 {
            let (cx, cy, size) = (next() * 40.0 - 4.0, next() * 30.0 - 4.0, next() * 3.0);
            // Every other triangle on a grid of half pixels, so that pixel centers often lie
            // exactly on its edges (the top-left rule decides those).
            let at = |c: f32| {
                if n % 2 == 0 {
                    (c * 2.0).round() / 2.0
                } else {
                    c
                }
            };
            let v: [WindowVertex; 3] = std::array::from_fn(|_| WindowVertex {
                x: at(cx + next() * size),
                y: at(cy + next() * size),
                z: next(),
                inv_w: 0.5 + next(),
                depth_x: 0.0,
                depth_y: 0.0,
            });
            let v = v.map(|w| WindowVertex {
                depth_x: w.x,
                depth_y: w.y,
                ..w
            });
            let setup = |cull| setup_triangle_culling(v, [&var; 3], 6, (32, 24), &opts, cull);
            match (setup(true), setup(false)) {
                (Setup::Empty, Setup::Triangle(t)) => {
                    dropped += 1;
                    let (r0, r1) = t.rows();
                    assert!((t.px1 - t.px0 + 1) * (r1 - r0 + 1) as i64 <= SMALL_BOX);
                    for y in r0..=r1 {
                        for x in t.px0 as u32..=t.px1 as u32 {
                            assert!(!t.covers(x, y), "dropped, yet covers ({x}, {y}): {v:?}");
                        }
                    }
                }
                (Setup::Triangle(a), Setup::Triangle(b)) => {
                    kept += 1;
                    assert_eq!(format!("{a:?}"), format!("{b:?}"));
                }
                (Setup::Empty, Setup::Empty) | (Setup::Culled, Setup::Culled) => {}
                (a, b) => panic!("with the test {a:?}, without it {b:?}"),
            }
        }
        assert!(
            dropped > 1000 && kept > 1000,
            "dropped {dropped}, kept {kept}"
        );
    }

    /// llvmpipe's plane is the triangle's plane: at random pixels it agrees with the exact
    /// plane (in f64, through the same three points) to within a few units in the last place,
    /// and it does not depend on which vertex comes first beyond that rounding.
    #[test]
    fn depth_plane_is_the_plane_through_the_three_points() {
        let mut next = uniform(0x1234_5678_9abc_def1u64);
        for _ in 0..2000 {
            let v: [(f32, f32, f32); 3] =
                std::array::from_fn(|_| (next() * 300.0, next() * 200.0, next()));
            let exact = |px: f64, py: f64| {
                // The plane through the points, evaluated at the pixel centre (px + ½, py + ½).
                let [(x0, y0, z0), (x1, y1, z1), (x2, y2, z2)] =
                    v.map(|(x, y, z)| (x as f64, y as f64, z as f64));
                let det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
                let a = ((z1 - z0) * (y2 - y0) - (z2 - z0) * (y1 - y0)) / det;
                let b = ((z2 - z0) * (x1 - x0) - (z1 - z0) * (x2 - x0)) / det;
                (
                    z0 + a * (px + 0.5 - x0) + b * (py + 0.5 - y0),
                    a.abs() + b.abs(),
                )
            };
            let (Some(p), Some(q)) = (DepthPlane::new(v), DepthPlane::new([v[1], v[2], v[0]]))
            else {
                continue; // no area in f32
            };
            let [(x0, y0, _), (x1, y1, _), (x2, y2, _)] = v;
            if ((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)).abs() < 2000.0 {
                continue; // slivers: an ulp of position moves their plane by far more
            }
            // A pixel within the triangle's bounds.
            let (lo_x, hi_x) = (x0.min(x1).min(x2), x0.max(x1).max(x2));
            let (lo_y, hi_y) = (y0.min(y1).min(y2), y0.max(y1).max(y2));
            let px = (lo_x + next() * (hi_x - lo_x)).floor();
            let py = (lo_y + next() * (hi_y - lo_y)).floor();
            let (want, slope) = exact(px as f64, py as f64);
            if slope > 1.0 {
                continue; // steep: a position error of an ulp moves depth by slope × ulp
            }
            for plane in [p, q] {
                let got = plane.at_pixel(px, py) as f64;
                // A few ulps of the terms summed (far from the origin `a0` and the products
                // grow, and so does the rounding: llvmpipe's own FIXME in lp_state_setup.c).
                let terms = (plane.a0.abs() + (plane.dzdx * px).abs() + (plane.dzdy * py).abs())
                    as f64
                    + 1.0;
                assert!(
                    (got - want).abs() <= 16.0 * f32::EPSILON as f64 * terms,
                    "{v:?} at ({px}, {py}): {got} vs {want}"
                );
            }
        }
    }

    /// The magic-number rounding snaps as `f32::round_ties_even` does: every quarter step
    /// around zero, around the 2²² switch-over and the snapping range of a 16384-pixel
    /// target at 8 subpixel bits, and every float between two ties.
    #[test]
    fn magic_rounding_matches_round_ties_even() {
        let check = |v: f32| {
            assert_eq!(
                round_ties_even(v) as i64,
                v.round_ties_even() as i64,
                "v = {v}"
            );
        };
        for centre in [0.0f32, 4_194_304.0, -4_194_304.0, 2_097_152.0, -2_097_152.0] {
            for k in -4096..=4096 {
                check(centre + k as f32 * 0.25);
            }
        }
        let mut v = 1.5f32;
        while v < 2.5 {
            check(v);
            check(-v);
            v = f32::from_bits(v.to_bits() + 1);
        }
        // Only the integer reaches the rasterizer, so −0.3 → +0 (not −0) is the same snap.
        for v in [
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1e30,
            -1e30,
            -0.0,
            -0.3,
        ] {
            check(v);
        }
    }
}
