//! Triangle meshes and the procedural shapes.

use glam::{Vec2, Vec3};

use stereolab_core::{Error, Result};

/// An indexed triangle mesh with per-vertex normals and texture coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position.
    pub uvs: Vec<Vec2>,
    /// Counter-clockwise (front-facing) triangles as indices into the vertex arrays.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Checks sizes, indices and that every position is finite.
    ///
    /// # Errors
    /// `Invalid` naming `what`, the vertex or triangle and the value.
    pub fn validate(&self, what: &str) -> Result<()> {
        let n = self.positions.len();
        if self.normals.len() != n || self.uvs.len() != n {
            return Err(Error::invalid(
                what,
                n,
                "normals/uvs must match positions in count",
            ));
        }
        if let Some((i, p)) = self
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| !p.is_finite())
        {
            return Err(Error::invalid(
                format!("{what}: vertex {i}"),
                format!("{p}"),
                "positions must be finite (NaN/Inf found)",
            ));
        }
        if let Some((i, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&k| k as usize >= n))
        {
            return Err(Error::invalid(
                format!("{what}: triangle {i}"),
                format!("{t:?}"),
                format!("index out of range (mesh has {n} vertices)"),
            ));
        }
        if self.triangles.is_empty() {
            return Err(Error::invalid(
                what,
                "0 triangles",
                "a mesh needs at least one triangle",
            ));
        }
        Ok(())
    }

    /// Replaces the normals with area-weighted smooth vertex normals.
    pub fn compute_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                acc[i as usize] += n;
            }
        }
        self.normals = acc
            .into_iter()
            .map(|n| n.try_normalize().unwrap_or(Vec3::Z))
            .collect();
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }

    /// A UV sphere of `radius` with `segments` around and `rings` from pole to pole.
    pub fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
        let (segments, rings) = (segments.max(3), rings.max(2));
        let mut m = Mesh::default();
        for r in 0..=rings {
            let v = r as f32 / rings as f32;
            let theta = v * std::f32::consts::PI;
            for s in 0..=segments {
                let u = s as f32 / segments as f32;
                let phi = u * std::f32::consts::TAU;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    -theta.sin() * phi.sin(),
                );
                m.positions.push(n * radius);
                m.normals.push(n);
                m.uvs.push(Vec2::new(u, v));
            }
        }
        let row = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let (a, b) = (r * row + s, (r + 1) * row + s);
                m.triangles.push([a, b, a + 1]);
                m.triangles.push([a + 1, b, b + 1]);
            }
        }
        m
    }

    /// An axis-aligned cube of edge `size` centered at the origin, flat-shaded (24 vertices).
    pub fn cube(size: f32) -> Mesh {
        let h = size * 0.5;
        let mut m = Mesh::default();
        let faces = [
            (Vec3::X, Vec3::Y),
            (Vec3::NEG_X, Vec3::Y),
            (Vec3::Y, Vec3::NEG_Z),
            (Vec3::NEG_Y, Vec3::Z),
            (Vec3::Z, Vec3::Y),
            (Vec3::NEG_Z, Vec3::Y),
        ];
        for (n, up) in faces {
            let right = up.cross(n);
            let base = m.positions.len() as u32;
            for (du, dv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                m.positions.push((n + right * du + up * dv) * h);
                m.normals.push(n);
                m.uvs.push(Vec2::new((du + 1.0) * 0.5, (dv + 1.0) * 0.5));
            }
            m.triangles.push([base, base + 1, base + 2]);
            m.triangles.push([base, base + 2, base + 3]);
        }
        m
    }

    /// A torus in the XZ plane: ring radius `major`, tube radius `minor`.
    pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
        let (segments, sides) = (segments.max(3), sides.max(3));
        let mut m = Mesh::default();
        for i in 0..=segments {
            let u = i as f32 / segments as f32;
            let a = u * std::f32::consts::TAU;
            let center = Vec3::new(a.cos(), 0.0, -a.sin()) * major;
            for j in 0..=sides {
                let v = j as f32 / sides as f32;
                let b = v * std::f32::consts::TAU;
                let n = Vec3::new(a.cos() * b.cos(), b.sin(), -a.sin() * b.cos());
                m.positions.push(center + n * minor);
                m.normals.push(n);
                m.uvs.push(Vec2::new(u, v));
            }
        }
        let row = sides + 1;
        for i in 0..segments {
            for j in 0..sides {
                let (a, b) = (i * row + j, (i + 1) * row + j);
                m.triangles.push([a, b, a + 1]);
                m.triangles.push([a + 1, b, b + 1]);
            }
        }
        m
    }

    /// A square in the XY plane facing +Z, edge `size`, split into `divisions`² quads.
    pub fn plane(size: f32, divisions: u32) -> Mesh {
        let d = divisions.max(1);
        let mut m = Mesh::default();
        for j in 0..=d {
            for i in 0..=d {
                let (u, v) = (i as f32 / d as f32, j as f32 / d as f32);
                m.positions
                    .push(Vec3::new((u - 0.5) * size, (v - 0.5) * size, 0.0));
                m.normals.push(Vec3::Z);
                m.uvs.push(Vec2::new(u, v));
            }
        }
        for j in 0..d {
            for i in 0..d {
                let a = j * (d + 1) + i;
                let b = a + d + 1;
                m.triangles.push([a, a + 1, b + 1]);
                m.triangles.push([a, b + 1, b]);
            }
        }
        m
    }

    /// Exactly `count` triangles for benchmarks: a height-field grid over [−1, 1]² (deterministic,
    /// no randomness), the last row trimmed so the count is exact.
    pub fn triangle_grid(count: u32) -> Mesh {
        let count = count.max(1);
        let quads = count.div_ceil(2);
        let side = (quads as f32).sqrt().ceil() as u32;
        let mut m = Mesh::default();
        for j in 0..=side {
            for i in 0..=side {
                let (u, v) = (i as f32 / side as f32, j as f32 / side as f32);
                let h = 0.15 * ((u * 9.0).sin() * (v * 7.0).cos());
                m.positions.push(Vec3::new(u * 2.0 - 1.0, v * 2.0 - 1.0, h));
                m.uvs.push(Vec2::new(u, v));
            }
        }
        'outer: for j in 0..side {
            for i in 0..side {
                let a = j * (side + 1) + i;
                let b = a + side + 1;
                for t in [[a, a + 1, b + 1], [a, b + 1, b]] {
                    if m.triangles.len() as u32 == count {
                        break 'outer;
                    }
                    m.triangles.push(t);
                }
            }
        }
        m.compute_normals();
        m
    }
}
