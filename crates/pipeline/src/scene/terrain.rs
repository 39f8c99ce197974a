//! Terrain from scattered `(x, y, height)` points (the ChromaDepth article's fault valley and map images):
//! read from CSV, triangulated by Delaunay (spade) over the map plane, heights lifted onto the
//! world's up axis.

use std::path::Path;

use glam::{Vec2, Vec3};
use spade::{DelaunayTriangulation, HierarchyHintGenerator, Point2, Triangulation};

use super::mesh::Mesh;
use stereolab_core::{Error, Result, excerpt};

/// Refuse CSV files above this size before reading them.
const MAX_CSV_BYTES: u64 = 256 * 1024 * 1024;

/// The columns a terrain CSV must have, in the order used when it has no header.
pub const COLUMNS: [&str; 3] = ["x", "y", "height"];

/// One row of a terrain CSV.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TerrainPoint {
    /// Map east coordinate.
    pub x: f64,
    /// Map north coordinate.
    pub y: f64,
    /// Height above the map plane.
    pub height: f64,
    /// 1-based line in the file it came from.
    pub line: usize,
}

/// A triangulated terrain.
#[derive(Clone, Debug)]
pub struct Terrain {
    /// The mesh: vertices at [`map_to_world`] of the points, counter-clockwise seen from above.
    pub mesh: Mesh,
    /// For every input point, in input order, the mesh vertex it became.
    pub vertex_of_point: Vec<u32>,
    /// Input points that repeated an earlier point's `(x, y)` and were merged into its vertex.
    pub duplicates: usize,
}

/// Map coordinates to world space: east → +X, north → −Z (away from a camera on +Z), height →
/// +Y (the world's up), so a terrain lies on the ground like the scenes' other objects.
pub fn map_to_world(x: f64, y: f64, height: f64) -> Vec3 {
    Vec3::new(x as f32, height as f32, -y as f32)
}

/// Reads a terrain CSV file and triangulates it.
///
/// # Errors
/// Unreadable or oversized file, and everything [`parse_csv`] and [`triangulate`] refuse, each
/// naming the file (and line).
pub fn load_terrain_csv(path: &Path) -> Result<Terrain> {
    load_terrain_csv_within(path, u64::MAX)
}

/// [`load_terrain_csv`] refusing, while the rows are read, a file whose points would make more
/// than `max_triangles` triangles (a Delaunay triangulation of n points has fewer than 2n):
/// [`parse_csv_within`].
///
/// # Errors
/// As [`load_terrain_csv`], and the row that passed the budget.
pub fn load_terrain_csv_within(path: &Path, max_triangles: u64) -> Result<Terrain> {
    let text = stereolab_core::read_text(path, MAX_CSV_BYTES)?;
    let points = parse_csv_within(path, &text, max_triangles)?;
    drop(text);
    triangulate(path, &points)
}

/// Parses CSV text: one point per line, comma-separated; blank lines and lines starting with `#`
/// are skipped. An optional header names the columns (`x`, `y`, `height`, in any order, extra
/// columns ignored; `z` is accepted for `height`); without one the first three columns are
/// `x, y, height`.
///
/// # Errors
/// `Parse` naming `path` and the line: a header without one of the columns, a row with too few
/// fields, a field that is not a number, or a NaN/infinite value.
pub fn parse_csv(path: &Path, text: &str) -> Result<Vec<TerrainPoint>> {
    parse_csv_within(path, text, u64::MAX)
}

/// [`parse_csv`] refusing the row that makes more points than `max_triangles / 2` (whose
/// triangulation could pass `max_triangles` triangles), before it is kept.
///
/// # Errors
/// As [`parse_csv`]; over the budget, the row, the budget and what to do.
pub fn parse_csv_within(path: &Path, text: &str, max_triangles: u64) -> Result<Vec<TerrainPoint>> {
    let most_points = max_triangles / 2;
    let mut columns: Option<[usize; 3]> = None;
    let mut points = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let trimmed = raw.trim();
        if trimmed.is_empty() || trimmed.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = trimmed.split(',').map(str::trim).collect();
        let cols = match columns {
            Some(c) => c,
            None if fields.iter().any(|f| f.parse::<f64>().is_err()) => {
                columns = Some(header_columns(path, line, &fields)?);
                continue;
            }
            None => *columns.insert([0, 1, 2]),
        };
        let needed = cols.iter().max().map_or(3, |m| m + 1);
        if fields.len() < needed {
            return Err(Error::parse(
                path,
                Some(line),
                format!(
                    "expected {needed} columns ({}), found {}: \"{trimmed}\"",
                    COLUMNS.join(", "),
                    fields.len()
                ),
            ));
        }
        let mut v = [0.0f64; 3];
        for (k, &c) in cols.iter().enumerate() {
            let text = fields[c];
            let value: f64 = text.parse().map_err(|_| {
                Error::parse(
                    path,
                    Some(line),
                    format!(
                        "column {}: \"{}\" is not a number",
                        COLUMNS[k],
                        excerpt(text)
                    ),
                )
            })?;
            if !value.is_finite() {
                return Err(Error::parse(
                    path,
                    Some(line),
                    format!(
                        "column {} = {}: must be a finite number",
                        COLUMNS[k],
                        excerpt(text)
                    ),
                ));
            }
            v[k] = value;
        }
        if points.len() as u64 == most_points {
            return Err(Error::parse(
                path,
                Some(line),
                format!(
                    "more than {most_points} points, which could make more than the scene's \
                     budget of {max_triangles} triangles (up to 2 per point): thin the data, or \
                     raise the budget with --max-triangles"
                ),
            ));
        }
        points.push(TerrainPoint {
            x: v[0],
            y: v[1],
            height: v[2],
            line,
        });
    }
    Ok(points)
}

/// Where `x`, `y`, `height` are in a header row.
fn header_columns(path: &Path, line: usize, fields: &[&str]) -> Result<[usize; 3]> {
    let find = |names: &[&str]| {
        fields
            .iter()
            .position(|f| names.iter().any(|n| f.eq_ignore_ascii_case(n)))
    };
    let mut cols = [0usize; 3];
    for (k, names) in [&["x"][..], &["y"], &["height", "z"]].iter().enumerate() {
        cols[k] = find(names).ok_or_else(|| {
            Error::parse(
                path,
                Some(line),
                format!(
                    "missing column \"{}\" (the header names: {}; a terrain needs x, y, height)",
                    COLUMNS[k],
                    excerpt(&fields.join(", "))
                ),
            )
        })?;
    }
    Ok(cols)
}

/// Delaunay-triangulates the points' `(x, y)` with spade (incremental insertion in input order,
/// deterministic) and lifts each vertex to its height with [`map_to_world`]. Points sharing an
/// `(x, y)` become one vertex whose height is the mean of theirs. Normals are smooth (area
/// weighted), uvs span the points' bounding box.
///
/// # Errors
/// `Parse` naming `path`: fewer than 3 distinct points, all points on one line (no triangle), or
/// a coordinate spade cannot represent (naming the line).
pub fn triangulate(path: &Path, points: &[TerrainPoint]) -> Result<Terrain> {
    // The hierarchy finds where each point goes in O(log n) whatever the file's order; spade's
    // default walks from the last point inserted, which is quick for row-by-row files but
    // took 31 s of CPU for 300 000 points in random order (1.4 s with the hierarchy; 1M points in row order: 1.8 s before, 2.3 s now). Only the
    // search differs: the triangulation is the same.
    let mut dt: DelaunayTriangulation<Point2<f64>, (), (), (), HierarchyHintGenerator<f64>> =
        DelaunayTriangulation::new();
    let mut sums: Vec<(f64, f64, f64, u32)> = Vec::new(); // x, y, height sum, count
    let mut vertex_of_point = Vec::with_capacity(points.len());
    for p in points {
        let at = spade::mitigate_underflow(Point2::new(p.x, p.y));
        let handle = dt.insert(at).map_err(|e| {
            Error::parse(
                path,
                Some(p.line),
                format!("point ({}, {}) cannot be triangulated: {e}", p.x, p.y),
            )
        })?;
        let i = handle.index();
        if i == sums.len() {
            sums.push((p.x, p.y, p.height, 1));
        } else {
            sums[i].2 += p.height;
            sums[i].3 += 1;
        }
        vertex_of_point.push(i as u32);
    }
    if sums.len() < 3 {
        return Err(Error::parse(
            path,
            None,
            format!(
                "a terrain needs at least 3 distinct (x, y) points, found {} in {} rows",
                sums.len(),
                points.len()
            ),
        ));
    }
    let triangles: Vec<[u32; 3]> = dt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    if triangles.is_empty() {
        return Err(Error::parse(
            path,
            None,
            format!(
                "all {} distinct points lie on one line: no triangle to build",
                sums.len()
            ),
        ));
    }
    let (lo, hi) = sums.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), s| {
            (
                [lo[0].min(s.0), lo[1].min(s.1)],
                [hi[0].max(s.0), hi[1].max(s.1)],
            )
        },
    );
    let extent = [
        (hi[0] - lo[0]).max(f64::MIN_POSITIVE),
        (hi[1] - lo[1]).max(f64::MIN_POSITIVE),
    ];
    let mut mesh = Mesh {
        positions: sums
            .iter()
            .map(|s| map_to_world(s.0, s.1, s.2 / s.3 as f64))
            .collect(),
        normals: Vec::new(),
        uvs: sums
            .iter()
            .map(|s| {
                Vec2::new(
                    ((s.0 - lo[0]) / extent[0]) as f32,
                    ((s.1 - lo[1]) / extent[1]) as f32,
                )
            })
            .collect(),
        triangles,
    };
    mesh.compute_normals();
    mesh.validate(&path.display().to_string())
        .map_err(|e| e.in_file(path))?;
    Ok(Terrain {
        mesh,
        duplicates: points.len() - sums.len(),
        vertex_of_point,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_csv_over_the_budget_is_refused_at_the_row_that_passes_it() {
        let path = Path::new("t.csv");
        let text = "x,y,height\n0,0,0\n1,0,0\n# a comment\n0,1,0\n1,1,0\n";
        assert_eq!(parse_csv_within(path, text, 8).unwrap().len(), 4);
        assert_eq!(
            parse_csv_within(path, text, 7).unwrap_err().to_string(),
            "t.csv:6: more than 3 points, which could make more than the scene's budget of 7 \
             triangles (up to 2 per point): thin the data, or raise the budget with \
             --max-triangles"
        );
    }
}
