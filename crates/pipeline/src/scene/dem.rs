//! Terrain from a digital elevation model (DEM): a grayscale height image, sampled at scattered
//! points and Delaunay-triangulated like the CSV terrains ([`super::terrain`]). This is how the
//! ChromaDepth article's maps and fault valley are built from real survey data: the shipped
//! grids in `assets/scenes/terrain/` are USGS and NOAA elevation models (their README says
//! where they come from).
//!
//! The image: 8- or 16-bit gray PNG (or any format the image crate reads as gray), row 0 =
//! north, column 0 = west. Gray `g` (0..1 of full scale) is the height
//! `heights[0] + g · (heights[1] − heights[0])`; the grid spans `extent[0]` east by `extent[1]`
//! north, centred on the origin. Heights between grid nodes are bilinear.

use std::path::Path;

use super::terrain::{Terrain, TerrainPoint, triangulate};
use super::terrain_data::SplitMix64;
use stereolab_core::{Error, Result};

/// The largest DEM image side accepted (read from the header, before decoding).
pub const MAX_DEM_SIDE: u32 = 8192;
/// The most DEM pixels accepted.
pub const MAX_DEM_PIXELS: u64 = 16 * 1024 * 1024;
/// The most scattered points a DEM may be sampled at. With the border points
/// ([`sample_points`]) they make up to [`most_triangles`]`(2 000 000)` = 4 005 658 triangles,
/// a little over the default budget: the default budget takes up to
/// [`most_points_within`]`(4 000 000)` = 1 997 173 points, and `--max-triangles 4005658` takes
/// the maximum.
pub const MAX_DEM_POINTS: u32 = 2_000_000;

/// The border points [`sample_points`] adds to `points` scattered ones: each edge of the
/// rectangle split into `⌈√points⌉` steps.
pub fn border_points(points: u32) -> u64 {
    4 * u64::from((f64::from(points).sqrt().ceil() as u32).max(1))
}

/// The most triangles a DEM sampled at `points` scattered points makes: a Delaunay
/// triangulation of `n` distinct points, `h` of them on the boundary of their convex hull, has
/// `2n − 2 − h` triangles; the border points lie on that boundary, so with `b` of them (and
/// scattered points that may fall on an edge too) there are at most
/// `2 (points + b) − 2 − b = 2 · points + b − 2`.
pub fn most_triangles(points: u32) -> u64 {
    2 * u64::from(points) + border_points(points) - 2
}

/// The most scattered points whose [`most_triangles`] fit `max_triangles` (0 when not even one
/// point does), at most [`MAX_DEM_POINTS`].
pub fn most_points_within(max_triangles: u64) -> u32 {
    let (mut lo, mut hi) = (0u32, MAX_DEM_POINTS);
    if most_triangles(hi) <= max_triangles {
        return hi;
    }
    // most_triangles grows with points: the last count that fits lies in [lo, hi).
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if most_triangles(mid) <= max_triangles {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    if lo == 0 || most_triangles(lo) > max_triangles {
        0
    } else {
        lo
    }
}

/// How a DEM image becomes points (the `[[mesh]] kind = "dem"` fields).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemOptions {
    /// The grid's size on the map, east and north, in scene units.
    pub extent: [f64; 2],
    /// The heights of gray 0 and of full-scale white, scene units.
    pub heights: [f64; 2],
    /// Scattered points drawn inside the grid (plus the border points, see [`sample_points`]).
    pub points: u32,
    /// Seed of the point scatter.
    pub seed: u64,
}

/// A height grid: `width × height` samples, row 0 north, each 0..1 of full scale.
#[derive(Clone, Debug, PartialEq)]
pub struct DemGrid {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major samples, 0..1.
    pub samples: Vec<f32>,
}

impl DemGrid {
    /// Bilinear height fraction at continuous grid position `(u, v)` (columns, rows), clamped
    /// to the grid.
    pub fn bilinear(&self, u: f64, v: f64) -> f64 {
        let (w, h) = (self.width as usize, self.height as usize);
        let u = u.clamp(0.0, (w - 1) as f64);
        let v = v.clamp(0.0, (h - 1) as f64);
        let (c0, r0) = (u.floor() as usize, v.floor() as usize);
        let (c1, r1) = ((c0 + 1).min(w - 1), (r0 + 1).min(h - 1));
        let (fu, fv) = (u - c0 as f64, v - r0 as f64);
        let at = |c: usize, r: usize| f64::from(self.samples[r * w + c]);
        let top = at(c0, r0) + (at(c1, r0) - at(c0, r0)) * fu;
        let bottom = at(c0, r1) + (at(c1, r1) - at(c0, r1)) * fu;
        top + (bottom - top) * fv
    }
}

/// Reads a grayscale height image, refusing an oversized one from its header.
///
/// # Errors
/// Unreadable or oversized file; `Parse` for a color image or one smaller than 2×2.
pub fn load_grid(path: &Path) -> Result<DemGrid> {
    let img =
        stereolab_core::open_image_within(path, "elevation image", MAX_DEM_SIDE, MAX_DEM_PIXELS)?;
    if img.color().has_color() {
        return Err(Error::parse(
            path,
            None,
            format!(
                "an elevation image must be grayscale (one height per pixel), found {:?}; \
                 convert it to 8- or 16-bit gray",
                img.color()
            ),
        ));
    }
    let gray = img.into_luma16();
    let (width, height) = gray.dimensions();
    if width < 2 || height < 2 {
        return Err(Error::parse(
            path,
            None,
            format!("an elevation image needs at least 2×2 pixels, found {width}×{height}"),
        ));
    }
    Ok(DemGrid {
        width,
        height,
        samples: gray.pixels().map(|p| f32::from(p.0[0]) / 65535.0).collect(),
    })
}

/// The points a DEM is triangulated from: `opts.points` uniformly scattered (splitmix64 from
/// `opts.seed`), then the border: every edge split into `⌈√points⌉` equal steps, corners
/// included, so the triangulation covers the whole rectangle. Map coordinates centred on the
/// origin, x east, y north; heights bilinear between the grid nodes. `line` is the point's
/// 1-based index (what an error names).
pub fn sample_points(grid: &DemGrid, opts: &DemOptions) -> Vec<TerrainPoint> {
    let (cols, rows) = (f64::from(grid.width - 1), f64::from(grid.height - 1));
    let [ex, ey] = opts.extent;
    let [h0, h1] = opts.heights;
    let point = |u: f64, v: f64, i: usize| TerrainPoint {
        x: (u / cols - 0.5) * ex,
        y: (0.5 - v / rows) * ey,
        height: h0 + grid.bilinear(u, v) * (h1 - h0),
        line: i + 1,
    };
    let mut rng = SplitMix64(opts.seed);
    let mut out: Vec<TerrainPoint> = Vec::with_capacity(opts.points as usize + 64);
    for _ in 0..opts.points {
        let u = rng.next_f64() * cols;
        let v = rng.next_f64() * rows;
        out.push(point(u, v, out.len()));
    }
    let steps = (f64::from(opts.points).sqrt().ceil() as u32).max(1);
    for k in 0..steps {
        let t = f64::from(k) / f64::from(steps);
        // North edge west → east, east edge north → south, and so on round the rectangle.
        for (u, v) in [
            (t * cols, 0.0),
            (cols, t * rows),
            ((1.0 - t) * cols, rows),
            (0.0, (1.0 - t) * rows),
        ] {
            out.push(point(u, v, out.len()));
        }
    }
    out
}

/// Checks the options: finite positive extent, finite heights, points in
/// `1..=`[`MAX_DEM_POINTS`]. `field` prefixes the names in errors (`mesh[0]`).
///
/// # Errors
/// `Invalid` naming the field.
pub fn check_options(field: &str, opts: &DemOptions) -> Result<()> {
    if !opts.extent.iter().all(|e| e.is_finite() && *e > 0.0) {
        return Err(Error::invalid(
            format!("{field}.extent"),
            format!("{:?}", opts.extent),
            "must be two finite sizes > 0: [east, north] in scene units",
        ));
    }
    if !opts.heights.iter().all(|h| h.is_finite()) {
        return Err(Error::invalid(
            format!("{field}.heights"),
            format!("{:?}", opts.heights),
            "must be two finite heights: [at gray 0, at full-scale white]",
        ));
    }
    if !(1..=MAX_DEM_POINTS).contains(&opts.points) {
        return Err(Error::invalid(
            format!("{field}.count"),
            opts.points,
            format!("the number of scattered points must lie in 1..={MAX_DEM_POINTS}"),
        ));
    }
    Ok(())
}

/// Refuses `points` scattered points whose [`most_triangles`] pass `max_triangles`, naming
/// `{field}.count`, the triangles, the budget, the most points it takes and the budget the
/// count needs.
///
/// # Errors
/// `Invalid` over the budget.
pub fn check_budget(field: &str, points: u32, max_triangles: u64) -> Result<()> {
    let most = most_triangles(points);
    if most <= max_triangles {
        return Ok(());
    }
    Err(Error::invalid(
        format!("{field}.count"),
        points,
        format!(
            "{points} points and {} on the border make up to {most} triangles, over the \
             scene's budget of {max_triangles}: the budget takes count = {} at most; lower the \
             count, or raise the budget with --max-triangles {most}",
            border_points(points),
            most_points_within(max_triangles)
        ),
    ))
}

/// Reads a DEM image, samples it ([`sample_points`]) and triangulates the points
/// ([`triangulate`]), refusing before the image is read a count of points that could make
/// more than `max_triangles` triangles ([`check_budget`]).
///
/// # Errors
/// As [`load_grid`], [`check_options`], [`check_budget`] and [`triangulate`].
pub fn load_dem(path: &Path, opts: &DemOptions, max_triangles: u64) -> Result<Terrain> {
    check_options("dem", opts)?;
    check_budget("dem", opts.points, max_triangles)?;
    let grid = load_grid(path)?;
    let points = sample_points(&grid, opts);
    triangulate(path, &points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: u32, h: u32) -> DemGrid {
        DemGrid {
            width: w,
            height: h,
            samples: (0..w * h)
                .map(|i| (i % w) as f32 / (w - 1) as f32)
                .collect(),
        }
    }

    #[test]
    fn bilinear_interpolates_between_nodes_and_clamps_outside() {
        let g = ramp(5, 3);
        assert_eq!(g.bilinear(0.0, 0.0), 0.0);
        assert!((g.bilinear(2.5, 1.3) - 2.5 / 4.0).abs() < 1e-6);
        assert_eq!(g.bilinear(9.0, -3.0), 1.0);
    }

    #[test]
    fn points_cover_the_extent_with_heights_from_the_mapping() {
        let g = ramp(11, 7);
        let opts = DemOptions {
            extent: [20.0, 10.0],
            heights: [-1.0, 3.0],
            points: 400,
            seed: 1,
        };
        let p = sample_points(&g, &opts);
        assert_eq!(p.len(), 400 + 4 * 20);
        let xs = p.iter().map(|q| q.x);
        let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
        assert_eq!((lo, hi), (-10.0, 10.0));
        for q in &p {
            assert!((-5.0..=5.0).contains(&q.y));
            // The ramp rises west → east: height = −1 + 4 · (x + 10) / 20.
            let want = -1.0 + 4.0 * (q.x + 10.0) / 20.0;
            assert!((q.height - want).abs() < 1e-6, "{q:?}");
        }
        // Same seed, same points; another seed, others.
        assert_eq!(p, sample_points(&g, &opts));
        assert_ne!(p, sample_points(&g, &DemOptions { seed: 2, ..opts }));
    }

    #[test]
    fn the_triangle_bound_is_what_the_triangulation_makes() {
        let g = ramp(11, 7);
        for points in [1, 2, 3, 10, 50, 400, 1000] {
            let opts = DemOptions {
                extent: [20.0, 10.0],
                heights: [0.0, 1.0],
                points,
                seed: 3,
            };
            let t = triangulate(Path::new("t.png"), &sample_points(&g, &opts)).unwrap();
            // No scattered point of these seeds lies on the border: the bound is met exactly.
            assert_eq!(
                t.mesh.triangles.len() as u64,
                most_triangles(points),
                "{points}"
            );
        }
    }

    #[test]
    fn the_largest_count_and_the_budget_agree() {
        let default = crate::scene::DEFAULT_MAX_TRIANGLES;
        assert_eq!(most_triangles(MAX_DEM_POINTS), 4_005_658);
        assert_eq!(most_points_within(default), 1_997_173);
        assert!(most_triangles(1_997_173) <= default && most_triangles(1_997_174) > default);
        assert_eq!(most_points_within(4_005_658), MAX_DEM_POINTS);
        assert_eq!(most_points_within(4_005_657), MAX_DEM_POINTS - 1);
        assert_eq!(most_points_within(3), 0);
        assert_eq!(most_points_within(4), 1);
        let opts = |points| DemOptions {
            extent: [1.0, 1.0],
            heights: [0.0, 1.0],
            points,
            seed: 0,
        };
        check_options("mesh[0]", &opts(MAX_DEM_POINTS)).unwrap();
        let over = check_options("mesh[0]", &opts(MAX_DEM_POINTS + 1)).unwrap_err();
        assert!(over.to_string().contains("mesh[0].count"), "{over}");
        check_budget("mesh[0]", 1_997_173, default).unwrap();
        check_budget("mesh[0]", MAX_DEM_POINTS, 4_005_658).unwrap();
        let err = check_budget("mesh[0]", MAX_DEM_POINTS, default)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(
                "2000000 points and 5660 on the border make up to 4005658 triangles, over the \
                 scene's budget of 4000000: the budget takes count = 1997173 at most; lower the \
                 count, or raise the budget with --max-triangles 4005658"
            ),
            "{err}"
        );
    }

    #[test]
    fn the_largest_count_loads_with_the_budget_it_names() {
        let dir = std::env::temp_dir().join(format!("stereolab-dem-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ramp.png");
        image::GrayImage::from_fn(4, 3, |x, _| image::Luma([(x * 80) as u8]))
            .save(&path)
            .unwrap();
        let opts = DemOptions {
            extent: [1.0, 1.0],
            heights: [0.0, 1.0],
            points: MAX_DEM_POINTS,
            seed: 0,
        };
        let t = load_dem(&path, &opts, most_triangles(MAX_DEM_POINTS)).unwrap();
        let n = t.mesh.triangles.len() as u64;
        assert!(n <= most_triangles(MAX_DEM_POINTS) && n > 4_000_000, "{n}");
    }
}
