//! The scene as the strip passes see it (the SIRDS paper's Fig. 4 vertex program's inputs):
//! cyclopean clip positions, each vertex's separation, and the shift both the fast path and the
//! reference apply.

use glam::{Mat4, Vec3, Vec4};

use crate::{DepthRange, Disparity, EyeMatrices};

/// One object of the scene as the strip passes take it: its model matrix and its mesh.
#[derive(Clone, Copy, Debug)]
pub struct StripObject<'a> {
    /// Model → world.
    pub model: Mat4,
    /// The mesh's vertex positions (model space).
    pub positions: &'a [Vec3],
    /// The mesh's triangles (indices into `positions`).
    pub triangles: &'a [[u32; 3]],
}

/// The scene as the strip passes see it: cyclopean clip positions, each vertex's separation,
/// and the triangles, the background plane last (drawn last, most of it fails the depth test).
pub struct StripGeometry {
    pub(super) clip: Vec<Vec4>,
    pub(super) separation: Vec<f32>,
    pub(super) triangles: Vec<[u32; 3]>,
}

impl StripGeometry {
    /// Transforms every object (its model matrix and its mesh's positions and triangles) with
    /// the cyclopean `center` matrices, gives each vertex the separation of its eye-space
    /// distance (`clip.w`) mapped through `range`, and adds the background plane at
    /// `range.back` covering the whole view (the SIRDS paper's §3).
    pub fn new(
        objects: &[StripObject<'_>],
        center: &EyeMatrices,
        range: &DepthRange,
        d: &Disparity,
        cross_eyed: bool,
    ) -> StripGeometry {
        let nearness = |distance: f32| {
            let z = range.nearness(distance);
            if cross_eyed { 1.0 - z } else { z }
        };
        let mut g = StripGeometry {
            clip: Vec::new(),
            separation: Vec::new(),
            triangles: Vec::new(),
        };
        for o in objects {
            let mvp = center.mvp * o.model;
            let base = g.clip.len() as u32;
            for p in o.positions {
                let c = mvp * p.extend(1.0);
                g.clip.push(c);
                g.separation.push(d.separation(nearness(c.w)));
            }
            g.triangles
                .extend(o.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        // The plane, 5% larger than the frustum's cross-section at its distance.
        let [_, r, _, t, n, _] = center.frustum;
        let (hx, hy) = (r * range.back / n * 1.05, t * range.back / n * 1.05);
        let base = g.clip.len() as u32;
        for (x, y) in [(-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)] {
            let c = center.projection * Vec4::new(x, y, -range.back, 1.0);
            g.clip.push(c);
            g.separation.push(d.separation(nearness(c.w)));
        }
        g.triangles.push([base, base + 1, base + 2]);
        g.triangles.push([base, base + 2, base + 3]);
        g
    }

    /// Per-vertex separation in pixels.
    pub fn separation(&self) -> &[f32] {
        &self.separation
    }

    /// Triangles (vertex indices), the background plane last.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Fig. 4's vertex shift for a `width`-pixel image: every clip position moved
    /// `toward · s/2` pixels, i.e. `x + toward · s · w / W` in clip space (+1: right-going strips,
    /// −1: left-going). The CPU and GPU strips both take their vertices from here.
    pub fn shifted(&self, toward: f32, width: u32) -> Vec<Vec4> {
        let wf = width as f32;
        self.clip
            .iter()
            .zip(&self.separation)
            .map(|(c, s)| shift(*c, *s, toward, wf))
            .collect()
    }
}

/// Fig. 4's vertex shift of one clip position `c` with separation `s` on a `wf`-pixel-wide
/// image: `toward · s/2` pixels, `x + toward · s · w / W` in clip space (the NDC width 2 spans
/// W pixels). [`StripGeometry::shifted`] and the reference's vertex stage
/// ([`reference`]) both shift with it.
#[inline]
pub(super) fn shift(c: Vec4, s: f32, toward: f32, wf: f32) -> Vec4 {
    Vec4::new(c.x + toward * s * c.w / wf, c.y, c.z, c.w)
}
