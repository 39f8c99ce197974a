//! OBJ loading: a line-by-line check that names the file, line and value, then tobj.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::mesh::Mesh;
use crate::error::{Error, Result};
use crate::files::excerpt;

/// Refuse OBJ files above this size before reading them (the largest real model we ship is < 1 MB).
const MAX_OBJ_BYTES: u64 = 512 * 1024 * 1024;

/// Loads every object of an OBJ file as one mesh (triangulated, single index, smooth normals
/// computed where the file has none). Materials are ignored: the scene gives the color.
///
/// # Errors
/// Unreadable file, a vertex coordinate that is not a finite number, a face index out of range
/// or malformed, or no triangles at all: each names the file and line.
pub fn load_obj(path: &Path) -> Result<Mesh> {
    let bytes = crate::files::read_input(path, MAX_OBJ_BYTES)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        Error::parse(
            path,
            None,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })?;
    parse_obj(path, crate::files::without_bom(text))
}

/// [`load_obj`] on text already read (`path` names it in messages).
///
/// # Errors
/// As [`load_obj`], but for reading the file.
pub fn parse_obj(path: &Path, text: String) -> Result<Mesh> {
    check_lines(path, &text)?;

    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    // Missing material libraries are not an error for us: colors come from the scene.
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &opts, |_| Ok(Default::default()))
        .map_err(|e| Error::parse(path, None, format!("OBJ: {e}")))?;

    let mut mesh = Mesh::default();
    let mut has_normals = true;
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let n = m.positions.len() / 3;
        mesh.positions.extend((0..n).map(|i| {
            Vec3::new(
                m.positions[3 * i],
                m.positions[3 * i + 1],
                m.positions[3 * i + 2],
            )
        }));
        if m.normals.len() == m.positions.len() {
            mesh.normals.extend((0..n).map(|i| {
                Vec3::new(m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2])
                    .normalize_or_zero()
            }));
        } else {
            has_normals = false;
        }
        if m.texcoords.len() == 2 * n {
            mesh.uvs
                .extend((0..n).map(|i| Vec2::new(m.texcoords[2 * i], m.texcoords[2 * i + 1])));
        } else {
            mesh.uvs.extend(std::iter::repeat_n(Vec2::ZERO, n));
        }
        mesh.triangles.extend(
            m.indices
                .chunks_exact(3)
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if !has_normals || mesh.normals.contains(&Vec3::ZERO) {
        mesh.compute_normals();
    }
    if mesh.triangles.is_empty() {
        return Err(Error::parse(
            path,
            None,
            "no triangles (empty file, or only points/lines)",
        ));
    }
    mesh.validate(&path.display().to_string())?;
    Ok(mesh)
}

/// Checks what tobj would accept silently or report without a line: coordinates that are not
/// finite numbers, and face indices that are malformed or out of range.
fn check_lines(path: &Path, text: &str) -> Result<()> {
    let (mut nv, mut nvt, mut nvn) = (0i64, 0i64, 0i64);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let mut words = raw.split_whitespace();
        let Some(tag) = words.next() else { continue };
        match tag {
            "v" | "vt" | "vn" => {
                let need = if tag == "vt" { 1 } else { 3 };
                let mut count = 0;
                for w in words.by_ref().take(3) {
                    let ok = w.parse::<f32>().map(f32::is_finite).unwrap_or(false);
                    if !ok {
                        return Err(Error::parse(
                            path,
                            Some(line),
                            format!("'{tag}' coordinate '{}' is not a finite number", excerpt(w)),
                        ));
                    }
                    count += 1;
                }
                if count < need {
                    return Err(Error::parse(
                        path,
                        Some(line),
                        format!(
                            "'{tag}' needs {need} coordinates, found {count}: '{}'",
                            excerpt(raw)
                        ),
                    ));
                }
                match tag {
                    "v" => nv += 1,
                    "vt" => nvt += 1,
                    _ => nvn += 1,
                }
            }
            "f" => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(Error::parse(
                        path,
                        Some(line),
                        format!(
                            "face needs at least 3 corners, found {}: '{}'",
                            corners.len(),
                            excerpt(raw)
                        ),
                    ));
                }
                for corner in corners {
                    for (k, part) in corner.split('/').enumerate() {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let (what, count) = match k {
                            0 => ("vertex", nv),
                            1 => ("texture", nvt),
                            _ => ("normal", nvn),
                        };
                        let idx: i64 = part.parse().map_err(|_| {
                            Error::parse(
                                path,
                                Some(line),
                                format!("face {what} index '{}' is not an integer", excerpt(part)),
                            )
                        })?;
                        let resolved = if idx < 0 { count + idx + 1 } else { idx };
                        if idx == 0 || resolved < 1 || resolved > count {
                            return Err(Error::parse(
                                path,
                                Some(line),
                                format!(
                                    "face {what} index {idx} out of range (1..={count} defined so far)"
                                ),
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}
