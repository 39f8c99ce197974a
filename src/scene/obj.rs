//! OBJ loading: a line-by-line check that names the file, line and value, then tobj.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::mesh::Mesh;
use super::polygon;
use crate::error::{Error, Result};
use crate::files::excerpt;

/// Refuse OBJ files above this size before reading them (the largest real model we ship is < 1 MB).
const MAX_OBJ_BYTES: u64 = 512 * 1024 * 1024;

/// Loads every object of an OBJ file as one mesh (polygons triangulated keeping their winding,
/// single index, smooth normals computed where the file has none). Materials are ignored: the
/// scene gives the color, so a missing, empty or unreadable material library is no error.
///
/// The text is UTF-8 (a leading byte-order mark is dropped); UTF-16 with a byte-order mark is
/// decoded; any other bytes are read as Latin-1 (ISO 8859-1, one byte per character), as OBJ
/// only needs ASCII for its keywords and numbers and names or comments in an 8-bit encoding
/// are common. Messages quote such text escaped.
///
/// # Errors
/// Unreadable file, a vertex coordinate that is not a finite number, a face index out of range
/// or malformed, or no triangles at all: each names the file and line.
pub fn load_obj(path: &Path) -> Result<Mesh> {
    let bytes = crate::files::read_input(path, MAX_OBJ_BYTES)?;
    let text = decode(path, bytes)?;
    parse_obj(path, crate::files::without_bom(text))
}

/// Text of an OBJ file's bytes: UTF-8, else UTF-16 if it starts with a byte-order mark
/// (FE FF big-endian, FF FE little-endian), else Latin-1.
///
/// # Errors
/// UTF-16 that is cut off or holds an unpaired surrogate.
fn decode(path: &Path, bytes: Vec<u8>) -> Result<String> {
    let bytes = match String::from_utf8(bytes) {
        Ok(text) => return Ok(text),
        Err(e) => e.into_bytes(),
    };
    let big_endian = match bytes.get(..2) {
        Some([0xFE, 0xFF]) => Some(true),
        Some([0xFF, 0xFE]) => Some(false),
        _ => None,
    };
    let Some(big_endian) = big_endian else {
        return Ok(bytes.iter().map(|&b| char::from(b)).collect());
    };
    let body = &bytes[2..];
    if body.len() % 2 != 0 {
        return Err(Error::parse(
            path,
            None,
            format!("UTF-16 text with an odd number of bytes ({})", bytes.len()),
        ));
    }
    let units = body.chunks_exact(2).map(|u| {
        if big_endian {
            u16::from_be_bytes([u[0], u[1]])
        } else {
            u16::from_le_bytes([u[0], u[1]])
        }
    });
    char::decode_utf16(units)
        .enumerate()
        .map(|(i, c)| {
            c.map_err(|e| {
                Error::parse(
                    path,
                    None,
                    format!(
                        "UTF-16 text with an unpaired surrogate 0x{:04X} (byte {})",
                        e.unpaired_surrogate(),
                        2 + 2 * i
                    ),
                )
            })
        })
        .collect()
}

/// [`load_obj`] on text already read (`path` names it in messages).
///
/// # Errors
/// As [`load_obj`], but for reading the file.
pub fn parse_obj(path: &Path, text: String) -> Result<Mesh> {
    check_lines(path, &text)?;
    let text = without_empty_usemtl(&text);

    let opts = tobj::LoadOptions {
        // Polygons come back whole and are triangulated below, keeping concave faces right.
        triangulate: false,
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
        // tobj leaves `face_arities` empty when every face is a triangle.
        let mut start = 0;
        let arities = m.face_arities.iter().map(|&a| a as usize);
        let arities: Box<dyn Iterator<Item = usize>> = if m.face_arities.is_empty() {
            Box::new(std::iter::repeat_n(3, m.indices.len() / 3))
        } else {
            Box::new(arities)
        };
        for arity in arities {
            let face = &m.indices[start..start + arity];
            start += arity;
            let corners: Vec<Vec3> = face
                .iter()
                .map(|&i| mesh.positions[(base + i) as usize])
                .collect();
            mesh.triangles.extend(
                polygon::triangulate(&corners)
                    .into_iter()
                    .map(|t| [base + face[t[0]], base + face[t[1]], base + face[t[2]]]),
            );
        }
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

/// For a word that starts with a number and goes on with something else (`3.1+e2`), what a
/// reader that stops at the first character it cannot use (assimp's `fast_atof`) takes from
/// it. Such words are refused here rather than read as the prefix: `3.1+e2` was most likely
/// meant as `3.1e+2`, and reading 3.1 would move the vertex silently.
fn number_prefix_hint(word: &str) -> String {
    let longest = (1..word.len())
        .rev()
        .filter(|&k| word.is_char_boundary(k))
        .find(|&k| word[..k].parse::<f32>().is_ok_and(f32::is_finite));
    match longest {
        Some(k) => format!(
            " (only '{}' is a number: assimp reads that and ignores '{}')",
            excerpt(&word[..k]),
            excerpt(&word[k..])
        ),
        None => String::new(),
    }
}

/// The text with each `usemtl` line that names no material blanked (line numbers kept): tobj
/// refuses those ("material parse error"), and materials are ignored here anyway.
fn without_empty_usemtl(text: &str) -> std::borrow::Cow<'_, str> {
    let empty = |line: &str| line.split_whitespace().eq(["usemtl"]);
    if !text.lines().any(empty) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        if empty(line) {
            out.push_str(if line.ends_with("\r\n") {
                "\r\n"
            } else if line.ends_with('\n') {
                "\n"
            } else {
                ""
            });
        } else {
            out.push_str(line);
        }
    }
    std::borrow::Cow::Owned(out)
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
                            format!(
                                "'{tag}' coordinate '{}' is not a finite number{}",
                                excerpt(w),
                                number_prefix_hint(w)
                            ),
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

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

    fn path() -> &'static Path {
        Path::new("t.obj")
    }

    #[test]
    fn latin1_names_are_read_byte_for_byte() {
        let mut bytes = b"# Terraind".to_vec();
        bytes.extend([0xE6, b'k', b'\n']); // "æ" in Latin-1, not valid UTF-8
        bytes.extend(SQUARE.bytes());
        let text = decode(path(), bytes).unwrap();
        assert!(text.starts_with("# Terraindæk\n"), "{text:?}");
        assert_eq!(parse_obj(path(), text).unwrap().triangles.len(), 2);
    }

    #[test]
    fn utf16_with_a_byte_order_mark_is_decoded_either_way_round() {
        let units: Vec<u16> = "\u{feff}# ä\n"
            .encode_utf16()
            .chain(SQUARE.encode_utf16())
            .collect();
        let be: Vec<u8> = units.iter().flat_map(|u| u.to_be_bytes()).collect();
        let le: Vec<u8> = units.iter().flat_map(|u| u.to_le_bytes()).collect();
        for bytes in [be, le] {
            let text = crate::files::without_bom(decode(path(), bytes).unwrap());
            assert!(text.starts_with("# ä\n"), "{text:?}");
            assert_eq!(parse_obj(path(), text).unwrap().triangles.len(), 2);
        }
    }

    #[test]
    fn broken_utf16_is_refused_with_the_reason() {
        let odd = decode(path(), vec![0xFE, 0xFF, 0x00, 0x23, 0x00]).unwrap_err();
        assert!(odd.to_string().contains("odd number of bytes (5)"), "{odd}");
        let lone =
            decode(path(), vec![0xFF, 0xFE, 0x23, 0x00, 0x00, 0xD8, 0x23, 0x00]).unwrap_err();
        assert!(
            lone.to_string()
                .contains("unpaired surrogate 0xD800 (byte 4)"),
            "{lone}"
        );
    }

    #[test]
    fn a_usemtl_without_a_name_is_ignored_like_any_material() {
        let text = format!("mtllib missing.mtl\nusemtl \r\n{SQUARE}usemtl\n");
        let stripped = without_empty_usemtl(&text);
        assert_eq!(
            stripped.lines().count(),
            text.lines().count(),
            "line numbers are kept"
        );
        assert_eq!(parse_obj(path(), text).unwrap().triangles.len(), 2);
    }

    #[test]
    fn a_number_with_trailing_junk_names_what_a_prefix_reader_would_take() {
        let err = parse_obj(path(), "v 1 2 3.1+e2\nf 1 1 1\n".into()).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("t.obj:1:"), "{msg}");
        assert!(
            msg.contains("'3.1+e2' is not a finite number (only '3.1' is a number: assimp reads that and ignores '+e2')"),
            "{msg}"
        );
        let plain = parse_obj(path(), "v 1 2 x\n".into())
            .unwrap_err()
            .to_string();
        assert!(plain.ends_with("'x' is not a finite number"), "{plain}");
    }

    #[test]
    fn a_concave_face_is_triangulated_inside_its_outline() {
        // An L shape, counter-clockwise, starting at the reflex corner's neighbour so that
        // the fan from corner 1 would reach across the notch.
        let text = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 2 3 4 5 6 1\n";
        let mesh = parse_obj(path(), text.into()).unwrap();
        let tris: Vec<[Vec3; 3]> = mesh
            .triangles
            .iter()
            .map(|t| t.map(|i| mesh.positions[i as usize]))
            .collect();
        let twice = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).z;
        // The notch's centre: the fan (2,0)-(1,1)-(1,2) would cover it.
        let notch = Vec3::new(1.5, 1.5, 0.0);
        for &[a, b, c] in &tris {
            assert!(twice(a, b, c) > 0.0, "faces backwards: {tris:?}");
            let inside =
                twice(a, b, notch) > 0.0 && twice(b, c, notch) > 0.0 && twice(c, a, notch) > 0.0;
            assert!(!inside, "covers the notch: {tris:?}");
        }
        let area: f32 = tris.iter().map(|&[a, b, c]| twice(a, b, c) / 2.0).sum();
        assert!((area - 3.0).abs() < 1e-6, "{area}");
    }
}
