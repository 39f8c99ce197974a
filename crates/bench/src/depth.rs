//! `bench --only depth`: the `[raster] depth` knob (standard, reversed-Z with a finite or an
//! infinite far plane, f64) across near/far ratios from 10 to 1e12, measured for z-fighting and
//! lost fragments against the f64 reference (`stereolab_core::visible_f64`), with its cost in time.
//!
//! The scene: six pairs of fronto-parallel squares at eye depths 2 to 90 (far plane 100), the
//! front square of each pair 1/10 000 of its depth in front of the back one (a decal, a
//! coplanar detail: where z-fighting shows first). The near plane is `100 / ratio`. The error
//! is the share of the pixels the reference decides and covers that the render gets wrong: a
//! different square won (z-fighting) or nothing was drawn (a lost fragment).

use glam::{DVec3, Mat4, Vec3};

use super::{Row, median_ms, row};
use stereolab_core::{
    DepthMode, Framebuffer, IdShader, RasterOptions, Result, compare_with_reference, frustum,
    rasterize, triangle_soup, visible_f64,
};

/// One measurement of the depth knob.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthRow {
    /// The knob's setting (`standard`, `reversed-z`, `reversed-z, infinite far`, `f64`).
    pub setting: String,
    /// far / near.
    pub ratio: f64,
    /// Wrong or lost pixels, percent of the covered pixels the reference decides.
    pub error: f64,
    /// The unit of `error`.
    pub unit: &'static str,
    /// Median seconds of one pass.
    pub seconds: f64,
}

/// The far plane of the benchmark scene.
pub const FAR: f32 = 100.0;

/// The near/far ratios measured.
pub const RATIOS: [f64; 12] = [
    10.0, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
];

/// The squares: at each depth a back square and, 1/10 000 of the depth in front, a smaller
/// front square, both spanning the same share of the view (positions, triangles).
pub fn scene() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (k, z) in [2.0f32, 5.0, 10.0, 20.0, 50.0, 90.0]
        .into_iter()
        .enumerate()
    {
        // Column k of six across the view (the frustum below is ±1 wide at depth 1).
        let x0 = -1.0 + k as f32 / 3.0 + 0.02;
        for (scale, gap) in [(1.0f32, 0.0f32), (0.6, 1e-4)] {
            let zz = -z * (1.0 - gap);
            let (l, r) = (x0 * z, (x0 + 0.3 * scale) * z);
            let (b, t) = (-0.6 * scale * z, 0.6 * scale * z);
            let i = positions.len() as u32;
            positions.extend([
                Vec3::new(l, b, zz),
                Vec3::new(r, b, zz),
                Vec3::new(r, t, zz),
                Vec3::new(l, t, zz),
            ]);
            triangles.extend([[i, i + 1, i + 2], [i, i + 2, i + 3]]);
        }
    }
    (positions, triangles)
}

/// The depth modes measured for a near plane `near`.
pub fn modes(near: f32) -> [DepthMode; 4] {
    [
        DepthMode::Standard,
        DepthMode::ReversedZ { near, far: FAR },
        DepthMode::ReversedZ {
            near,
            far: f32::INFINITY,
        },
        DepthMode::F64,
    ]
}

/// Every mode at every ratio on a `width`×`height` view: the error against the f64 reference
/// and the median time of `iters` passes.
///
/// # Errors
/// A framebuffer of that size cannot be made.
pub fn measure(width: u32, height: u32, iters: usize) -> Result<Vec<DepthRow>> {
    let (positions, triangles) = scene();
    let soup_positions = triangle_soup(&positions, &triangles);
    let soup_triangles: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let world: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let aspect = f64::from(width) / f64::from(height);
    let mut out = Vec::new();
    for ratio in RATIOS {
        let near = (f64::from(FAR) / ratio) as f32;
        let (n, f) = (f64::from(near), f64::from(FAR));
        let mvp64 = stereolab_core::frustum_f64(-n * aspect, n * aspect, -n, n, n, f);
        let reference = visible_f64(&world, &triangles, &mvp64, width, height);
        let a = near * aspect as f32;
        let shader = IdShader {
            positions: &soup_positions,
            mvp: frustum(-a, a, -near, near, near, FAR) * Mat4::IDENTITY,
        };
        for mode in modes(near) {
            let opts = RasterOptions {
                depth: mode,
                ..RasterOptions::default()
            };
            let draw = || -> Result<Framebuffer> {
                let mut fb = Framebuffer::new(width, height, [0, 0, 0, 255])?;
                rasterize(
                    &soup_triangles,
                    soup_positions.len(),
                    &shader,
                    &mut fb,
                    &opts,
                );
                Ok(fb)
            };
            let fb = draw()?;
            let m = compare_with_reference(&fb, &reference);
            let seconds = median_ms(iters, draw) * 1e-3;
            out.push(DepthRow {
                setting: mode.name().to_string(),
                ratio,
                error: 100.0 * (m.lost + m.wrong) as f64 / m.covered.max(1) as f64,
                unit: "% px wrong or lost",
                seconds,
            });
        }
    }
    Ok(out)
}

/// The rows of `stereolab bench --only depth` (a 192×128 view).
///
/// # Errors
/// As [`measure`].
pub fn rows(iters: usize) -> Result<Vec<Row>> {
    Ok(measure(192, 128, iters)?
        .into_iter()
        .map(|r| {
            row(
                "depth",
                &format!("depth, near/far 1/{:.0e}", r.ratio),
                r.setting,
                Some(r.error),
                r.unit,
                r.seconds * 1e3,
                format!("ratio {:.0e}", r.ratio),
            )
        })
        .collect())
}
