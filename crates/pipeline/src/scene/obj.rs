//! OBJ loading: a pass over the file's lines that checks each one (naming the file, line and
//! value), counts what the triangle budget allows as it goes, and hands tobj the checked lines.

use std::borrow::Cow;
use std::io::{BufRead, Read};
use std::path::Path;

use glam::{Vec2, Vec3};

use super::DEFAULT_MAX_TRIANGLES;
use super::mesh::Mesh;
use super::polygon;
use stereolab_core::{Error, Result, excerpt};

/// Refuse OBJ files above this size before reading them (the largest real model we ship is < 1 MB).
const MAX_OBJ_BYTES: u64 = 512 * 1024 * 1024;

/// Loads every object of an OBJ file as one mesh (polygons triangulated keeping their winding,
/// single index, smooth normals computed where the file has none), with the default triangle
/// budget ([`DEFAULT_MAX_TRIANGLES`]). Materials are ignored: the scene gives the color, so a
/// missing, empty or unreadable material library is no error.
///
/// Each line is UTF-8 when it is valid UTF-8 (a leading byte-order mark is dropped), else
/// Latin-1 (ISO 8859-1, one byte per character), as OBJ only needs ASCII for its keywords and
/// numbers and names or comments in an 8-bit encoding are common; a file that starts with a
/// UTF-16 byte-order mark is decoded as UTF-16. Messages quote such text escaped.
///
/// # Errors
/// Unreadable file, a vertex coordinate that is not a finite number, a `v`, `vt` or `vn` line
/// with a number of coordinates the format does not have, a face index out of range or
/// malformed, more than the budget allows (see [`load_obj_within`]), or no triangles at all:
/// each names the file and line.
pub fn load_obj(path: &Path) -> Result<Mesh> {
    load_obj_within(path, DEFAULT_MAX_TRIANGLES).map(|(mesh, _)| mesh)
}

/// [`load_obj`], and the notes on what was read in an unusual way: each names the file and
/// line (a coordinate like `3.1+e2`, read as assimp's `fast_atof` reads it).
/// `stereolab render` prints them.
///
/// # Errors
/// As [`load_obj`].
pub fn load_obj_with_notes(path: &Path) -> Result<(Mesh, Vec<String>)> {
    load_obj_within(path, DEFAULT_MAX_TRIANGLES)
}

/// [`load_obj_with_notes`] with the triangle budget `max_triangles` (`--max-triangles`),
/// enforced while the file is read, before anything is kept for a line past it: the faces'
/// triangles (n − 2 for a face of n corners) may not pass `max_triangles`, nor the `v`, `vt`
/// or `vn` lines each 3 × `max_triangles` (the most corners that many triangles have). The
/// file is read line by line; only the checked lines are kept.
///
/// # Errors
/// As [`load_obj`]; over the budget, the line that passed it, the budget and what to do.
pub fn load_obj_within(path: &Path, max_triangles: u64) -> Result<(Mesh, Vec<String>)> {
    let too_large = |size: u64| {
        Error::parse(
            path,
            None,
            format!("file is {size} bytes, more than the {MAX_OBJ_BYTES} accepted"),
        )
    };
    let size = stereolab_core::check_input(path)?;
    if size > MAX_OBJ_BYTES {
        return Err(too_large(size));
    }
    let io = |e| Error::io(path, e);
    let file = std::fs::File::open(path).map_err(io)?;
    let mut input = std::io::BufReader::new(file.take(MAX_OBJ_BYTES + 1));
    let head = input.fill_buf().map_err(io)?;
    if head.starts_with(&[0xFE, 0xFF]) || head.starts_with(&[0xFF, 0xFE]) {
        let mut bytes = Vec::new();
        input.read_to_end(&mut bytes).map_err(io)?;
        if bytes.len() as u64 > MAX_OBJ_BYTES {
            return Err(too_large(bytes.len() as u64)); // it grew while being read
        }
        let text = decode_utf16(path, &bytes)?;
        drop(bytes);
        return parse_obj_within(path, stereolab_core::without_bom(text), max_triangles);
    }
    let mut reader = Reader::new(path, max_triangles);
    let mut buf = Vec::new();
    let mut read = 0u64;
    for line in 1.. {
        buf.clear();
        let n = input.read_until(b'\n', &mut buf).map_err(io)?;
        if n == 0 {
            break;
        }
        read += n as u64;
        if read > MAX_OBJ_BYTES {
            return Err(too_large(read)); // it grew while being read
        }
        let mut bytes = buf.strip_suffix(b"\n").unwrap_or(&buf);
        bytes = bytes.strip_suffix(b"\r").unwrap_or(bytes);
        if line == 1 {
            bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
        }
        let text = match std::str::from_utf8(bytes) {
            Ok(text) => Cow::Borrowed(text),
            Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
        };
        reader.line(line, &text)?;
    }
    reader.finish()
}

/// Text of UTF-16 bytes after their byte-order mark (FE FF big-endian, FF FE little-endian).
///
/// # Errors
/// UTF-16 that is cut off or holds an unpaired surrogate.
fn decode_utf16(path: &Path, bytes: &[u8]) -> Result<String> {
    let big_endian = bytes.starts_with(&[0xFE, 0xFF]);
    let body = &bytes[2..];
    if !body.len().is_multiple_of(2) {
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
    parse_obj_within(path, text, DEFAULT_MAX_TRIANGLES).map(|(mesh, _)| mesh)
}

/// [`load_obj_with_notes`] on text already read.
///
/// # Errors
/// As [`load_obj`], but for reading the file.
pub fn parse_obj_with_notes(path: &Path, text: String) -> Result<(Mesh, Vec<String>)> {
    parse_obj_within(path, text, DEFAULT_MAX_TRIANGLES)
}

/// [`load_obj_within`] on text already read.
///
/// # Errors
/// As [`load_obj_within`], but for reading the file.
pub fn parse_obj_within(
    path: &Path,
    text: String,
    max_triangles: u64,
) -> Result<(Mesh, Vec<String>)> {
    let mut reader = Reader::new(path, max_triangles);
    for (i, raw) in text.lines().enumerate() {
        reader.line(i + 1, raw)?;
    }
    drop(text);
    reader.finish()
}

/// The mesh of the lines a [`Reader`] kept, read by tobj and triangulated.
fn mesh_of(path: &Path, kept: &str) -> Result<Mesh> {
    let opts = tobj::LoadOptions {
        // Polygons come back whole and are triangulated below, keeping concave faces right.
        triangulate: false,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut lines = kept.as_bytes();
    // The kept lines name no material library; colors come from the scene.
    let (models, _materials) = tobj::load_obj_buf(&mut lines, &opts, |_| Ok(Default::default()))
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

/// The budget's advice, in every message that refuses a file for its size.
const BUDGET_ADVICE: &str = "simplify the model, or raise the budget with --max-triangles";

/// One pass over an OBJ file's lines: each is checked as it comes, what the budget allows is
/// counted, and the lines tobj needs are kept in a checked form (coordinates as the numbers
/// read, face indices resolved to absolute ones; names, comments, materials, points and
/// two-point lines left out), so nothing past the budget or malformed is ever held.
struct Reader<'p> {
    /// Named in messages.
    path: &'p Path,
    /// The most triangles the faces may make.
    max_triangles: u64,
    /// `v`, `vt` and `vn` lines so far.
    nv: u64,
    nvt: u64,
    nvn: u64,
    /// Triangles the faces so far make (n − 2 for n corners).
    triangles: u64,
    /// The lines kept for tobj, each ending in `\n`.
    kept: String,
    /// One per coordinate read in an unusual way.
    notes: Vec<String>,
}

impl<'p> Reader<'p> {
    fn new(path: &'p Path, max_triangles: u64) -> Self {
        Reader {
            path,
            max_triangles,
            nv: 0,
            nvt: 0,
            nvn: 0,
            triangles: 0,
            kept: String::new(),
            notes: Vec::new(),
        }
    }

    fn error(&self, line: usize, message: impl Into<String>) -> Error {
        Error::parse(self.path, Some(line), message)
    }

    /// Checks the 1-based line `line`, its text `raw` without the line ending.
    fn line(&mut self, line: usize, raw: &str) -> Result<()> {
        let mut words = raw.split_whitespace();
        match words.next() {
            Some(tag @ ("v" | "vt" | "vn")) => self.vertex(line, raw, tag, words),
            Some("f") => self.face(line, raw, words),
            // A polyline of 3 or more points is read as a polygon, as tobj reads it; shorter
            // ones (lines, points) draw nothing.
            Some("l") if words.clone().nth(2).is_some() => self.face(line, raw, words),
            // A new object or group: tobj keeps the faces of each apart (their vertices are
            // not shared); the name is of no use here.
            Some("o" | "g") => {
                self.kept.push_str("g\n");
                Ok(())
            }
            _ => Ok(()),
        }
    }

    /// A `v`, `vt` or `vn` line: coordinates read as assimp reads them ([`read_coordinate`]),
    /// as many as the keyword has (`v`: x y z, x y z w, or x y z r g b; `vt`: u v or u v w;
    /// `vn`: x y z), up to a comment.
    fn vertex<'a>(
        &mut self,
        line: usize,
        raw: &str,
        tag: &str,
        words: impl Iterator<Item = &'a str>,
    ) -> Result<()> {
        let mut values = Vec::with_capacity(6);
        // A comment after the coordinates ends the line, as in assimp.
        for w in words.take_while(|w| !w.starts_with('#')) {
            if values.len() == 7 {
                break; // too many, whatever follows
            }
            match read_coordinate(w) {
                Ok((value, unusual)) => {
                    if unusual {
                        let note = unusual_number_note(self.path, line, tag, w, value);
                        self.notes.push(note);
                    }
                    values.push(value);
                }
                Err(why) => {
                    return Err(self.error(
                        line,
                        format!(
                            "'{tag}' coordinate '{}' is not a finite number{why}",
                            excerpt(w)
                        ),
                    ));
                }
            }
        }
        let (allowed, what): (&[usize], &str) = match tag {
            "v" => (
                &[3, 4, 6],
                "3 coordinates (4 with a weight w, 6 with a color r g b)",
            ),
            "vt" => (&[2, 3], "2 or 3 coordinates"),
            _ => (&[3], "3 coordinates"),
        };
        if !allowed.contains(&values.len()) {
            let found = if values.len() == 7 {
                "more".to_string()
            } else {
                values.len().to_string()
            };
            return Err(self.error(
                line,
                format!("'{tag}' needs {what}, found {found}: '{}'", excerpt(raw)),
            ));
        }
        let count = match tag {
            "v" => &mut self.nv,
            "vt" => &mut self.nvt,
            _ => &mut self.nvn,
        };
        *count += 1;
        let (count, most) = (*count, self.max_triangles.saturating_mul(3));
        if count > most {
            return Err(self.error(
                line,
                format!(
                    "more than {most} '{tag}' lines, 3 per triangle of the scene's budget of {} \
                     triangles (a model within the budget needs no more): {BUDGET_ADVICE}",
                    self.max_triangles
                ),
            ));
        }
        let mut xyz = [values[0], values.get(1).copied().unwrap_or(0.0), 0.0];
        let n = if tag == "vt" { 2 } else { 3 };
        if n == 3 {
            xyz[2] = values[2];
        }
        if tag == "v" && values.len() == 4 {
            // A weight: the point is (x/w, y/w, z/w), as assimp and tobj read it.
            let w = values[3];
            let divided = xyz.map(|c| c / w);
            if w == 0.0 || !divided.iter().all(|c| c.is_finite()) {
                return Err(self.error(
                    line,
                    format!(
                        "'v' weight w = {w} makes the point x/w, y/w, z/w undefined or not a \
                         finite number: '{}'",
                        excerpt(raw)
                    ),
                ));
            }
            xyz = divided;
        }
        // Colors are left out: the scene gives the color.
        self.kept.push_str(tag);
        for c in &xyz[..n] {
            self.kept.push_str(&format!(" {c}"));
        }
        self.kept.push('\n');
        Ok(())
    }

    /// An `f` line: at least 3 corners, each `v`, `v/vt`, `v//vn` or `v/vt/vn` with indices
    /// defined so far (negative ones count back from the last), and the budget.
    fn face<'a>(
        &mut self,
        line: usize,
        raw: &str,
        words: impl Iterator<Item = &'a str>,
    ) -> Result<()> {
        let corners: Vec<&str> = words.collect();
        if corners.len() < 3 {
            return Err(self.error(
                line,
                format!(
                    "face needs at least 3 corners, found {}: '{}'",
                    corners.len(),
                    excerpt(raw)
                ),
            ));
        }
        self.triangles += corners.len() as u64 - 2;
        if self.triangles > self.max_triangles {
            return Err(self.error(
                line,
                format!(
                    "the faces so far make {} triangles, more than the scene's budget of {}: \
                     {BUDGET_ADVICE}",
                    self.triangles, self.max_triangles
                ),
            ));
        }
        self.kept.push('f');
        for corner in corners {
            let parts: Vec<&str> = corner.split('/').collect();
            if parts.len() > 3 {
                return Err(self.error(
                    line,
                    format!(
                        "face corner '{}' has {} parts: a corner is v, v/vt, v//vn or v/vt/vn",
                        excerpt(corner),
                        parts.len()
                    ),
                ));
            }
            self.kept.push(' ');
            for (k, part) in parts.into_iter().enumerate() {
                if k > 0 {
                    self.kept.push('/');
                }
                if part.is_empty() && k > 0 {
                    continue;
                }
                let (what, count) = match k {
                    0 => ("vertex", self.nv),
                    1 => ("texture", self.nvt),
                    _ => ("normal", self.nvn),
                };
                let idx: i64 = part.parse().map_err(|_| {
                    self.error(
                        line,
                        format!("face {what} index '{}' is not an integer", excerpt(part)),
                    )
                })?;
                let count = count as i64;
                let resolved = if idx < 0 { count + idx + 1 } else { idx };
                if idx == 0 || resolved < 1 || resolved > count {
                    return Err(self.error(
                        line,
                        format!(
                            "face {what} index {idx} out of range (1..={count} defined so far)"
                        ),
                    ));
                }
                self.kept.push_str(&resolved.to_string());
            }
        }
        self.kept.push('\n');
        Ok(())
    }

    /// The mesh of the lines kept, and the notes.
    ///
    /// # Errors
    /// No triangles, or a mesh [`Mesh::validate`] refuses.
    fn finish(self) -> Result<(Mesh, Vec<String>)> {
        let mesh = mesh_of(self.path, &self.kept)?;
        Ok((mesh, self.notes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";

    fn path() -> &'static Path {
        Path::new("t.obj")
    }

    /// A fresh file under the system's temporary folder holding `bytes`.
    /// `bytes` saved in the temporary folder, its name this process's and `name`.
    fn file(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let path =
            std::env::temp_dir().join(format!("stereolab-obj-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn latin1_names_are_read_byte_for_byte() {
        let mut bytes = b"# Terraind".to_vec();
        bytes.extend([0xE6, b'k', b'\n']); // "æ" in Latin-1, not valid UTF-8
        bytes.extend(SQUARE.bytes());
        bytes.extend(b"f 1 2 \xE6\n");
        let err = load_obj(&file("latin1.obj", &bytes))
            .unwrap_err()
            .to_string();
        assert!(
            err.ends_with("latin1.obj:7: face vertex index 'æ' is not an integer"),
            "{err}"
        );
        bytes.truncate(bytes.len() - 8);
        assert_eq!(
            load_obj(&file("latin1.obj", &bytes))
                .unwrap()
                .triangles
                .len(),
            2
        );
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
            let text = decode_utf16(path(), &bytes).unwrap();
            assert!(text.starts_with("# ä\n"), "{text:?}");
            assert_eq!(
                load_obj(&file("utf16.obj", &bytes))
                    .unwrap()
                    .triangles
                    .len(),
                2
            );
        }
    }

    #[test]
    fn broken_utf16_is_refused_with_the_reason() {
        let odd = decode_utf16(path(), &[0xFE, 0xFF, 0x00, 0x23, 0x00]).unwrap_err();
        assert!(odd.to_string().contains("odd number of bytes (5)"), "{odd}");
        let lone =
            decode_utf16(path(), &[0xFF, 0xFE, 0x23, 0x00, 0x00, 0xD8, 0x23, 0x00]).unwrap_err();
        assert!(
            lone.to_string()
                .contains("unpaired surrogate 0xD800 (byte 4)"),
            "{lone}"
        );
    }

    #[test]
    fn a_usemtl_without_a_name_is_ignored_like_any_material() {
        let text = format!("mtllib missing.mtl\nusemtl \r\n{SQUARE}usemtl\n");
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

    fn refusal(text: &str) -> String {
        parse_obj(path(), text.into()).unwrap_err().to_string()
    }

    #[test]
    fn a_vertex_line_with_a_count_the_format_lacks_is_refused_with_its_line() {
        for (text, says) in [
            (
                "v 0 0 0\nv 1 2 3 4 5 6 7\n",
                "t.obj:2: 'v' needs 3 coordinates (4 with a weight w, 6 with a color r g b), found more: 'v 1 2 3 4 5 6 7'",
            ),
            (
                "v 1 2 3 4 5\n",
                "t.obj:1: 'v' needs 3 coordinates (4 with a weight w, 6 with a color r g b), found 5: 'v 1 2 3 4 5'",
            ),
            (
                "v 1 2\n",
                "t.obj:1: 'v' needs 3 coordinates (4 with a weight w, 6 with a color r g b), found 2: 'v 1 2'",
            ),
            (
                "vt 0.5\n",
                "t.obj:1: 'vt' needs 2 or 3 coordinates, found 1: 'vt 0.5'",
            ),
            (
                "vn 0 0 1 1\n",
                "t.obj:1: 'vn' needs 3 coordinates, found 4: 'vn 0 0 1 1'",
            ),
            (
                "v 1 2 3 0\n",
                "t.obj:1: 'v' weight w = 0 makes the point x/w, y/w, z/w undefined or not a finite number: 'v 1 2 3 0'",
            ),
            (
                "v 1e30 2 3 1e-30\n",
                "t.obj:1: 'v' weight w = 0.000000000000000000000000000001 makes",
            ),
        ] {
            let err = refusal(text);
            assert!(err.starts_with(says), "{err}");
        }
        // A long line is quoted in part.
        let long = format!("v {}\n", "1 ".repeat(40));
        assert!(
            refusal(&long).ends_with("found more: 'v 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 1 …'")
        );
    }

    #[test]
    fn a_weight_divides_and_a_color_is_left_out() {
        let text = "v 2 4 6 2\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0 # c\nf 1 2 3\n";
        let mesh = parse_obj(path(), text.into()).unwrap();
        assert_eq!(mesh.positions, [Vec3::new(1.0, 2.0, 3.0), Vec3::X, Vec3::Y]);
    }

    #[test]
    fn a_face_corner_of_more_than_three_parts_is_refused_with_its_line() {
        let err = refusal("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1/1 2/1/1 3/1/1\n");
        assert_eq!(
            err,
            "t.obj:6: face corner '1/1/1/1' has 4 parts: a corner is v, v/vt, v//vn or v/vt/vn"
        );
        let err = refusal(&format!("{SQUARE}l 1/2/3/4/5 2\nf 1 2 x\n"));
        assert_eq!(err, "t.obj:7: face vertex index 'x' is not an integer");
        // A polyline of 3 or more points is a polygon.
        let mesh = parse_obj(path(), format!("{SQUARE}l 9 9\nl 1 2 3\n")).unwrap();
        assert_eq!(mesh.triangles.len(), 3);
    }

    #[test]
    fn indices_in_every_form_are_kept_resolved() {
        let mut reader = Reader::new(path(), 10);
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng a b\nf -3/1/-1 2//1 3/1/ \n";
        for (i, line) in text.lines().enumerate() {
            reader.line(i + 1, line).unwrap();
        }
        assert_eq!(
            reader.kept,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng\nf 1/1/1 2//1 3/1/\n"
        );
    }

    #[test]
    fn the_budget_is_kept_while_reading() {
        // Two squares: 4 triangles.
        let two = format!("{SQUARE}f 4 3 2 1\n");
        let (mesh, _) = parse_obj_within(path(), two.clone(), 4).unwrap();
        assert_eq!(mesh.triangles.len(), 4);
        let err = parse_obj_within(path(), two, 3).unwrap_err().to_string();
        assert_eq!(
            err,
            "t.obj:6: the faces so far make 4 triangles, more than the scene's budget of 3: \
             simplify the model, or raise the budget with --max-triangles"
        );
        // A 1024-gon is 1022 triangles.
        let gon: String = (0..1024)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 1024.0;
                format!("v {} {} 0\n", a.cos(), a.sin())
            })
            .chain(std::iter::once(format!(
                "f {}\n",
                (1..=1024)
                    .map(|i| i.to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            )))
            .collect();
        assert_eq!(
            parse_obj_within(path(), gon.clone(), 1022)
                .unwrap()
                .0
                .triangles
                .len(),
            1022
        );
        let err = parse_obj_within(path(), gon, 1021).unwrap_err().to_string();
        assert!(
            err.starts_with("t.obj:1025: the faces so far make 1022 triangles"),
            "{err}"
        );
        // Vertices: 3 per triangle of the budget, for each kind.
        for tag in ["v 0 0 0", "vt 0 0", "vn 0 0 1"] {
            let lines = format!("{tag}\n").repeat(7);
            let err = parse_obj_within(path(), lines, 2).unwrap_err().to_string();
            let word = tag.split(' ').next().unwrap();
            assert_eq!(
                err,
                format!(
                    "t.obj:7: more than 6 '{word}' lines, 3 per triangle of the scene's budget of \
                     2 triangles (a model within the budget needs no more): simplify the model, \
                     or raise the budget with --max-triangles"
                )
            );
        }
    }

    #[test]
    fn a_file_over_the_budget_is_refused_at_the_line_that_passes_it() {
        // The refusal comes from the line, whatever follows (here: a face out of range).
        let text = format!("{SQUARE}f 1 2 3\nf 1 2 99\n");
        let path = file("over.obj", text.as_bytes());
        let err = load_obj_within(&path, 2).unwrap_err().to_string();
        assert!(err.ends_with("over.obj:6: the faces so far make 3 triangles, more than the scene's budget of 2: simplify the model, or raise the budget with --max-triangles"), "{err}");
    }
}
