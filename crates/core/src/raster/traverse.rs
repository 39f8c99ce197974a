//! Traversal of set-up triangles: a tile's covered pixels row by row
//! ([`SetupTriangle::spans`]) or a small triangle's box at once ([`SetupTriangle::small_box`]),
//! and the scalar fragment loop ([`traverse`]). Both walks visit exactly the pixels of
//! [`SetupTriangle::covers`], the readable definition they are held to (tests/coverage.rs);
//! llvmpipe's rules are in docs/ARCHITECTURE.md "Rasterization rules".

use crate::shade::{Fragment, MAX_VARYINGS, Shader, Varyings};

use super::RasterOptions;
use super::setup::SetupTriangle;

/// A small triangle's box (see [`SetupTriangle::small_box`]): pixel `(x + j, y)` is covered
/// when `e[i] + dx[i]·j + dy[i]·(y − y0) ≥ 0` for all three edges, exactly
/// [`SetupTriangle::covers`] (and so the pixels of [`SetupTriangle::spans`]).
#[derive(Clone, Copy, Debug)]
pub struct SmallBox {
    /// First column.
    pub x: u32,
    /// Columns in the box (at most the lanes asked for).
    pub columns: u32,
    /// First row.
    pub y0: u32,
    /// Last row.
    pub y1: u32,
    /// Edge functions at `(x, y0)`.
    pub e: [i32; 3],
    /// Their change per column.
    pub dx: [i32; 3],
    /// Their change per row.
    pub dy: [i32; 3],
}

/// A tile of a framebuffer: columns `x0 .. x0 + width`, rows `y0 .. y0 + color.len() / width`
/// (a band of whole rows when `x0 = 0` and `width` is the target's). Traversal touches only
/// the tile's pixels, as a scissor rectangle would.
pub struct Band<'a> {
    /// Tile width in pixels (the row stride of `color` and `depth`).
    pub width: u32,
    /// First column of the tile.
    pub x0: u32,
    /// First row of the tile.
    pub y0: u32,
    /// The band's colors.
    pub color: &'a mut [[u8; 4]],
    /// The band's depths.
    pub depth: &'a mut [f32],
}

/// One edge's covered-span bound along a row, stepped from row to row without dividing.
///
/// Edge `i` at pixel `px0 + k` of a row is `e − m·k` with `m = dcdx·S`; the covered `k` satisfy
/// `e − m·k ≥ 0`. For `m > 0` that is `k ≤ ⌊e/m⌋`, for `m < 0` it is `k ≥ −⌊e/|m|⌋`. From one row
/// to the next `e` grows by `D = dcdy·S`, so `q = ⌊e/|m|⌋` and `r = e − q|m|` advance by the
/// precomputed `⌊D/|m|⌋` and `D mod |m|` with one carry: exact integers, as the per-row division
/// they replace.
#[derive(Clone, Copy)]
struct EdgeStep {
    /// `sign(m)`: +1 bounds `k` above, −1 below, 0 a horizontal-step edge (`e` alone decides).
    sign: i64,
    /// `|m|` (1 for `m = 0`, unused).
    m: i64,
    /// `⌊e/|m|⌋` and `e mod |m|` (for `m = 0`: `q = e`).
    q: i64,
    r: i64,
    /// Per-row increments.
    dq: i64,
    dr: i64,
}

impl EdgeStep {
    fn new(e: i64, m: i64, d: i64) -> EdgeStep {
        if m == 0 {
            return EdgeStep {
                sign: 0,
                m: 1,
                q: e,
                r: 0,
                dq: d,
                dr: 0,
            };
        }
        let a = m.abs();
        EdgeStep {
            sign: m.signum(),
            m: a,
            q: e.div_euclid(a),
            r: e.rem_euclid(a),
            dq: d.div_euclid(a),
            dr: d.rem_euclid(a),
        }
    }

    #[inline]
    fn advance(&mut self) {
        self.q += self.dq;
        self.r += self.dr;
        if self.r >= self.m {
            self.r -= self.m;
            self.q += 1;
        }
    }

    /// Narrows `[k0, k1]` to this edge's covered pixels.
    #[inline]
    fn bound(&self, k0: &mut i64, k1: &mut i64) {
        match self.sign {
            1 => *k1 = (*k1).min(self.q),
            -1 => *k0 = (*k0).max(-self.q),
            _ if self.q < 0 => *k1 = -1,
            _ => {}
        }
    }
}

impl SetupTriangle {
    /// The triangle's pixel bounds within a tile (columns `x0 .. x0 + width`, rows
    /// `y0 .. y0 + rows`): first and last column, first and last row; `None` when they miss it.
    fn clipped_box(&self, x0: u32, y0: u32, width: u32, rows: u32) -> Option<(i64, i64, i64, i64)> {
        let py0 = self.py0.max(y0 as i64);
        let py1 = self.py1.min(y0 as i64 + rows as i64 - 1);
        let cx0 = self.px0.max(x0 as i64);
        let cx1 = self.px1.min(x0 as i64 + width as i64 - 1);
        (py0 <= py1 && cx0 <= cx1).then_some((cx0, cx1, py0, py1))
    }

    /// Calls `span(py, x_lo, x_hi)` for every row of the tile (columns `x0 .. x0 + width`, rows
    /// `y0 .. y0 + rows`) in which the triangle covers pixels: exactly the covered pixels
    /// `x_lo ..= x_hi` (never empty), top row first. Coverage is [`covers`](Self::covers)'s,
    /// solved per row in integers instead of tested pixel by pixel (see `EdgeStep`).
    pub fn spans(
        &self,
        x0: u32,
        y0: u32,
        width: u32,
        rows: u32,
        mut span: impl FnMut(u32, u32, u32),
    ) {
        let Some((cx0, cx1, py0, py1)) = self.clipped_box(x0, y0, width, rows) else {
            return;
        };
        let s = 1i64 << self.bits;
        let last = self.px1 - self.px0;
        // Edge i at pixel px0 + k of row py is c + dcdy·py·S − dcdx·(px0 + k)·S: solved for k
        // exactly in integers, so only covered pixels are visited.
        let mut edges: [EdgeStep; 3] = std::array::from_fn(|i| {
            let e = self.c[i] + self.dcdy[i] * py0 * s - self.dcdx[i] * self.px0 * s;
            EdgeStep::new(e, self.dcdx[i] * s, self.dcdy[i] * s)
        });
        for py in py0..=py1 {
            let (mut k0, mut k1) = (0i64, last);
            for e in &mut edges {
                e.bound(&mut k0, &mut k1);
                e.advance();
            }
            let (x_lo, x_hi) = ((self.px0 + k0).max(cx0), (self.px0 + k1).min(cx1));
            if k0 <= k1 && x_lo <= x_hi {
                span(py as u32, x_lo as u32, x_hi as u32);
            }
        }
    }

    /// The triangle's box within a tile (columns `x0 .. x0 + width`, rows `y0 .. y0 + rows`)
    /// when it is at most `lanes` columns wide and its edge functions fit in `i32` there: a
    /// vector of `lanes` pixels then covers a whole row, tested for coverage at once (llvmpipe's
    /// small-triangle path). `None` otherwise, or when the box is empty.
    pub fn small_box(
        &self,
        x0: u32,
        y0: u32,
        width: u32,
        rows: u32,
        lanes: u32,
    ) -> Option<SmallBox> {
        let (cx0, cx1, py0, py1) = self.clipped_box(x0, y0, width, rows)?;
        if cx1 - cx0 >= lanes as i64 {
            return None;
        }
        let s = 1i64 << self.bits;
        let fits = |v: i64| v.unsigned_abs() < (1 << 30);
        let mut e = [0i32; 3];
        let mut dx = [0i32; 3];
        let mut dy = [0i32; 3];
        for i in 0..3 {
            let at = |px: i64, py: i64| self.c[i] + self.dcdy[i] * py * s - self.dcdx[i] * px * s;
            // Linear, so its extremes over the box (every lane included) lie at the corners.
            let last = cx0 + lanes as i64 - 1;
            let corners = [at(cx0, py0), at(last, py0), at(cx0, py1), at(last, py1)];
            let (m, d) = (-self.dcdx[i] * s, self.dcdy[i] * s);
            if !corners.into_iter().all(fits) || !fits(m) || !fits(d) {
                return None;
            }
            (e[i], dx[i], dy[i]) = (corners[0] as i32, m as i32, d as i32);
        }
        Some(SmallBox {
            x: cx0 as u32,
            columns: (cx1 - cx0 + 1) as u32,
            y0: py0 as u32,
            y1: py1 as u32,
            e,
            dx,
            dy,
        })
    }
}

/// Traverses a set-up triangle over the rows of `band`: coverage from the edge functions, then
/// depth test LESS, then the fragment stage. Returns the fragments written.
pub fn traverse<S: Shader>(
    t: &SetupTriangle,
    shader: &S,
    band: &mut Band,
    opts: &RasterOptions,
) -> usize {
    let rows = (band.depth.len() / band.width.max(1) as usize) as u32;
    let writes_color = shader.writes_color();
    // The shader's own count (a constant once inlined, so the loop below unrolls). `t` must
    // have been set up with the same varyings (planes past its count copy the depth plane).
    let nvar = shader.varying_count().min(MAX_VARYINGS);
    debug_assert!(
        nvar <= t.nvar,
        "traversed with more varyings than were set up"
    );
    let mut frag_var: Varyings = [0.0; MAX_VARYINGS];
    let mut fragments = 0;
    let (bx0, by0, bw) = (band.x0, band.y0, band.width as usize);
    t.spans(bx0, by0, band.width, rows, |py, x_lo, x_hi| {
        let fy = t.fy(py);
        // Index of pixel (px, py) in the tile: row + px − x0.
        let row = (py - by0) as usize * bw;
        let (i_lo, i_hi) = (row + (x_lo - bx0) as usize, row + (x_hi - bx0) as usize);
        if !writes_color && opts.depth_test {
            // Depth only: a branch-free span the compiler vectorizes; z is the same expression
            // as below, so the bits are the same.
            for (k, d) in band.depth[i_lo..=i_hi].iter_mut().enumerate() {
                let z = t.depth_at(x_lo + k as u32, py);
                let pass = z < *d;
                *d = if pass { z } else { *d };
                fragments += pass as usize;
            }
            return;
        }
        for (px, idx) in (x_lo..=x_hi).zip(i_lo..=i_hi) {
            let fx = t.fx(px);
            let z = t.depth_at(px, py);
            if opts.depth_test && z >= band.depth[idx] {
                continue;
            }
            if writes_color {
                // Perspective correction: divide the interpolated a/w by the interpolated 1/w
                // (one reciprocal per fragment, one multiply per varying).
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
                // A discarded fragment writes neither color nor depth.
                let Some(col) = shader.fragment(&f) else {
                    continue;
                };
                band.color[idx] = col;
            }
            if opts.depth_test {
                band.depth[idx] = z;
            }
            fragments += 1;
        }
    });
    fragments
}
