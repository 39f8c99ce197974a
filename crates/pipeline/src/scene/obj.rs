//! OBJ loading: a line-by-line check that names the file, line and value, then tobj.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::mesh::Mesh;
use super::polygon;
use stereolab_core::{Error, Result, excerpt};

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
    load_obj_with_notes(path).map(|(mesh, _)| mesh)
}

/// [`load_obj`], and the notes on what was read in an unusual way: each names the file and
/// line (a coordinate like `3.1+e2`, read as assimp's `fast_atof` reads it).
/// `stereolab render` prints them.
///
/// # Errors
/// As [`load_obj`].
pub fn load_obj_with_notes(path: &Path) -> Result<(Mesh, Vec<String>)> {
    let bytes = stereolab_core::read_input(path, MAX_OBJ_BYTES)?;
    let text = decode(path, bytes)?;
    parse_obj_with_notes(path, stereolab_core::without_bom(text))
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
    parse_obj_with_notes(path, text).map(|(mesh, _)| mesh)
}

/// [`load_obj_with_notes`] on text already read.
///
/// # Errors
/// As [`load_obj`], but for reading the file.
pub fn parse_obj_with_notes(path: &Path, text: String) -> Result<(Mesh, Vec<String>)> {
    let checked = check_lines(path, &text)?;
    let text = with_lines_replaced(&text, &checked.replaced);

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
    Ok((mesh, checked.notes))
}

/// How much of a coordinate word assimp's OBJ reader uses, and where it stops.
///
/// assimp reads each whitespace-separated word of a `v`/`vt`/`vn` line with `fast_atof`
/// (`ObjFileParser::getVector3` in `code/AssetLib/Obj/ObjFileParser.cpp` copies the word, then
/// calls `fast_atof` on it), which is `fast_atoreal_move` in `include/assimp/fast_atof.h`. That
/// reader takes the longest prefix of this form and ignores the rest of the word:
///
/// ```text
/// [+-] ( digits [ ('.' | ',') digits | '.' ]  |  ('.' | ',') digits )  [ ('e' | 'E') [+-] digits ]
/// ```
///
/// so `3.1+e2` is 3.1 (it stops at `+`), `0x10` is 0, `2.` is 2 and `1,5` is 1.5 (a comma is a
/// decimal point there). A word that does not start that way, or an `e` without digits after
/// it, makes assimp refuse the file (its `strtoul10_64` throws): `None` here.
///
/// Returns the prefix's length in bytes (the word's `&word[..len]`).
fn assimp_number_len(word: &str) -> Option<usize> {
    let b = word.as_bytes();
    let digits_from = |i: usize| i + b[i..].iter().take_while(|c| c.is_ascii_digit()).count();
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let point = |i: usize| matches!(b.get(i), Some(b'.' | b','));
    let digit = |i: usize| b.get(i).is_some_and(u8::is_ascii_digit);
    if !(digit(i) || (point(i) && digit(i + 1))) {
        return None;
    }
    i = digits_from(i);
    if point(i) && digit(i + 1) {
        i = digits_from(i + 1);
    } else if b.get(i) == Some(&b'.') {
        i += 1; // "2." is 2; a trailing comma is not eaten
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        i += 1;
        if matches!(b.get(i), Some(b'+' | b'-')) {
            i += 1;
        }
        if !digit(i) {
            return None;
        }
        i = digits_from(i);
    }
    Some(i)
}

/// A coordinate word read as assimp reads it (see [`assimp_number_len`]): the value, and
/// whether that is unusual — part of the word left unread, or a comma as the decimal point —
/// (then the caller notes it and hands tobj the number instead of the word).
///
/// The value is the prefix rounded correctly to `f32` (with a comma read as the decimal
/// point). assimp computes it as integer part + fraction part in `f32`
/// (`f += static_cast<Real>(pl)`) and the exponent with `pow`, which can differ from the
/// correctly rounded value in the last bit; and it reads at most 15 digits after the point.
/// Neither changes a vertex by more than one unit in the last place of an `f32`.
///
/// # Errors
/// The reason, when assimp would refuse the word too (it does not start as a number, or has
/// an exponent without digits), or when the number is not finite in `f32` (`inf`, `nan`, 1e39:
/// assimp reads those, and `vt` coordinates it turns into 0, but a vertex there draws nothing
/// sensible, so they are refused).
fn read_coordinate(word: &str) -> std::result::Result<(f32, bool), String> {
    let finite = |v: f32| v.is_finite().then_some(v);
    let Some(len) = assimp_number_len(word) else {
        return Err(String::new());
    };
    let prefix = word[..len].replace(',', ".");
    match prefix.parse::<f32>().ok().and_then(finite) {
        Some(v) => Ok((
            v,
            len < word.len() || prefix.len() != len || word[..len].contains(','),
        )),
        None => Err(" (out of the range of a 32-bit float)".into()),
    }
}

/// The note for a coordinate word read in an unusual way: the line, the word, the value read,
/// what is ignored, and — when the rest looks like an exponent with its sign on the wrong side
/// (`3.1+e2`) — what was probably meant.
fn unusual_number_note(path: &Path, line: usize, tag: &str, word: &str, value: f32) -> String {
    let len = assimp_number_len(word).unwrap_or(word.len());
    let (head, rest) = word.split_at(len);
    let mut note = format!(
        "{}:{line}: '{tag}' coordinate '{}' read as {value}, as assimp reads it",
        path.display(),
        excerpt(word),
    );
    if head.contains(',') {
        note.push_str(" (a comma as the decimal point)");
    }
    if !rest.is_empty() {
        note.push_str(&format!(": it stops before '{}'", excerpt(rest)));
    }
    let r = rest.as_bytes();
    if r.len() > 2
        && matches!(r[0], b'+' | b'-')
        && matches!(r[1], b'e' | b'E')
        && r[2..].iter().all(u8::is_ascii_digit)
    {
        note.push_str(&format!(
            " (if {head}{}{}{} was meant, write that)",
            char::from(r[1]),
            char::from(r[0]),
            &rest[2..]
        ));
    }
    note
}

/// The text with the given lines (0-based, sorted) replaced, line numbers and line endings
/// kept: what tobj reads after [`check_lines`].
fn with_lines_replaced<'a>(
    text: &'a str,
    replaced: &[(usize, String)],
) -> std::borrow::Cow<'a, str> {
    if replaced.is_empty() {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    let mut next = replaced.iter().peekable();
    for (i, line) in text.split_inclusive('\n').enumerate() {
        match next.next_if(|(k, _)| *k == i) {
            Some((_, new)) => {
                out.push_str(new);
                let body = line.trim_end_matches(['\n', '\r']);
                out.push_str(&line[body.len()..]);
            }
            None => out.push_str(line),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// What [`check_lines`] found: lines to give tobj in another form, and notes for the user.
#[derive(Debug, Default)]
struct Checked {
    /// (0-based line, its new text without the line ending), in line order: a `usemtl` that
    /// names no material becomes empty (tobj refuses it with "material parse error", and
    /// materials are ignored here anyway); a coordinate read in part, as assimp does, is
    /// written as the number read.
    replaced: Vec<(usize, String)>,
    /// One per coordinate read in part.
    notes: Vec<String>,
}

/// Checks what tobj would accept silently or report without a line: coordinates that are not
/// finite numbers, and face indices that are malformed or out of range. Coordinates are read
/// as assimp reads them ([`read_coordinate`]); those it reads only in part are noted and
/// handed to tobj as the number read.
fn check_lines(path: &Path, text: &str) -> Result<Checked> {
    let mut checked = Checked::default();
    let (mut nv, mut nvt, mut nvn) = (0i64, 0i64, 0i64);
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let mut words = raw.split_whitespace();
        let Some(tag) = words.next() else { continue };
        match tag {
            "usemtl" if words.clone().next().is_none() => {
                checked.replaced.push((i, String::new()));
            }
            "v" | "vt" | "vn" => {
                let need = if tag == "vt" { 1 } else { 3 };
                let mut count = 0;
                let mut read = vec![tag.to_string()];
                let mut partial = false;
                for w in words.by_ref().take(3) {
                    match read_coordinate(w) {
                        Ok((_, false)) => read.push(w.to_string()),
                        Ok((value, true)) => {
                            checked
                                .notes
                                .push(unusual_number_note(path, line, tag, w, value));
                            read.push(value.to_string());
                            partial = true;
                        }
                        Err(why) => {
                            return Err(Error::parse(
                                path,
                                Some(line),
                                format!(
                                    "'{tag}' coordinate '{}' is not a finite number{why}",
                                    excerpt(w)
                                ),
                            ));
                        }
                    }
                    count += 1;
                }
                // A comment after the coordinates (assimp stops there) would be read by tobj
                // as more components.
                let comment = words.clone().any(|w| w.starts_with('#'));
                if partial || comment {
                    read.extend(
                        words
                            .clone()
                            .take_while(|w| !w.starts_with('#'))
                            .map(str::to_string),
                    );
                    checked.replaced.push((i, read.join(" ")));
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
    Ok(checked)
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
            let text = stereolab_core::without_bom(decode(path(), bytes).unwrap());
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
        let checked = check_lines(path(), &text).unwrap();
        assert_eq!(checked.replaced, [(1, String::new()), (7, String::new())]);
        let stripped = with_lines_replaced(&text, &checked.replaced);
        assert_eq!(stripped, format!("mtllib missing.mtl\n\r\n{SQUARE}\n"));
        assert_eq!(parse_obj(path(), text).unwrap().triangles.len(), 2);
    }

    #[test]
    fn numbers_are_read_as_far_as_assimp_reads_them() {
        fn read(w: &str) -> Option<&str> {
            assimp_number_len(w).map(|n| &w[..n])
        }
        // fast_atoreal_move's grammar, case by case (include/assimp/fast_atof.h).
        for (word, prefix) in [
            ("3.1+e2", Some("3.1")),
            ("-3.1-e2", Some("-3.1")),
            ("+1e+2", Some("+1e+2")),
            ("2.e1", Some("2.e1")),
            ("2.", Some("2.")),
            ("2.x", Some("2.")),
            (".5", Some(".5")),
            ("-,5", Some("-,5")),
            ("1,5", Some("1,5")),
            ("1,", Some("1")),
            ("0x10", Some("0")),
            ("1E2", Some("1E2")),
            ("1e", None),
            ("1e+", None),
            ("1ex", None),
            (".", None),
            ("+", None),
            ("x", None),
            ("e5", None),
            ("inf", None),
            ("nan", None),
            ("", None),
        ] {
            assert_eq!(read(word), prefix, "{word}");
        }
        assert_eq!(read_coordinate("3.1+e2"), Ok((3.1, true)));
        assert_eq!(read_coordinate("1,5"), Ok((1.5, true)));
        assert_eq!(read_coordinate("-1.25e-1"), Ok((-0.125, false)));
        assert_eq!(read_coordinate("2.e+1"), Ok((20.0, false)));
        assert!(
            read_coordinate("1e39")
                .unwrap_err()
                .contains("range of a 32-bit float")
        );
        assert!(read_coordinate("inf").is_err());
    }

    #[test]
    fn a_number_with_trailing_junk_is_read_as_assimp_reads_it_with_a_note() {
        let (mesh, notes) = parse_obj_with_notes(
            path(),
            "v 0 0 0\nv 1 0 3.1+e2 # c\r\nv 0 1,5 0x10\nf 1 2 3\n".into(),
        )
        .unwrap();
        assert_eq!(
            mesh.positions,
            [
                Vec3::ZERO,
                Vec3::new(1.0, 0.0, 3.1),
                Vec3::new(0.0, 1.5, 0.0)
            ]
        );
        assert_eq!(notes.len(), 3, "{notes:?}");
        assert_eq!(
            notes[0],
            "t.obj:2: 'v' coordinate '3.1+e2' read as 3.1, as assimp reads it: it stops before \
             '+e2' (if 3.1e+2 was meant, write that)"
        );
        assert_eq!(
            notes[1],
            "t.obj:3: 'v' coordinate '1,5' read as 1.5, as assimp reads it (a comma as the \
             decimal point)"
        );
        assert_eq!(
            notes[2],
            "t.obj:3: 'v' coordinate '0x10' read as 0, as assimp reads it: it stops before 'x10'"
        );
        let plain = parse_obj(path(), "v 1 2 x\n".into())
            .unwrap_err()
            .to_string();
        assert!(plain.ends_with("'x' is not a finite number"), "{plain}");
        let exp = parse_obj(path(), "v 1 2 1e+\n".into())
            .unwrap_err()
            .to_string();
        assert!(
            exp.contains(":1:") && exp.ends_with("'1e+' is not a finite number"),
            "{exp}"
        );
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
