//! Molecules from Protein Data Bank files: the `ATOM` and `HETATM` records (element and
//! position), each atom drawn as a sphere of its van der Waals (CPK space-filling) radius, as
//! in the ChromaDepth article's protein images.
//!
//! A record is fixed-column text (the PDB format, version 3.3, "Coordinate Section"): columns
//! 13–16 the atom name, 18–20 the residue name, 31–38 / 39–46 / 47–54 the orthogonal
//! coordinates x, y, z in ångströms, 77–78 the element symbol. Older files (such as PyMOL's
//! tutorial copy of 1HPV) put a line number in 73–80 instead of the element; then the element
//! is read from the atom name as the format defines it: right-justified in columns 13–14 (a
//! space in column 13 means a one-letter element in column 14).

use std::path::Path;

use glam::Vec3;

use super::mesh::Mesh;
use stereolab_core::{Error, Result, excerpt};

/// Refuse PDB files above this size before reading them (the largest entries in the archive
/// that still use the PDB format are a few tens of megabytes).
pub const MAX_PDB_BYTES: u64 = 64 * 1024 * 1024;

/// The most atoms a PDB file may give (the format's serial numbers stop at 99 999).
pub const MAX_ATOMS: usize = 100_000;

/// One atom.
#[derive(Clone, Debug, PartialEq)]
pub struct Atom {
    /// Element symbol, capitalised as usual (`C`, `N`, `Fe`).
    pub element: String,
    /// Position, ångströms.
    pub position: Vec3,
    /// 1-based line in the file.
    pub line: usize,
}

/// Van der Waals radius in ångströms (Bondi 1964, the radii of CPK space-filling models);
/// 1.7 Å (carbon's) for an element not in the table.
pub fn cpk_radius(element: &str) -> f32 {
    match element {
        "H" => 1.20,
        "C" => 1.70,
        "N" => 1.55,
        "O" => 1.52,
        "F" => 1.47,
        "P" => 1.80,
        "S" => 1.80,
        "Cl" => 1.75,
        "Br" => 1.85,
        "I" => 1.98,
        "Se" => 1.90,
        "Na" => 2.27,
        "Mg" => 1.73,
        "K" => 2.75,
        "Zn" => 1.39,
        "Cu" => 1.40,
        "Fe" => 1.94,
        _ => 1.70,
    }
}

/// The record's columns `a..=b` (1-based, as the format counts them), `""` past the line's end.
fn columns(line: &str, a: usize, b: usize) -> &str {
    let bytes = line.as_bytes();
    if a > bytes.len() {
        return "";
    }
    line.get(a - 1..b.min(bytes.len())).unwrap_or("")
}

/// `Xy` capitalisation of a one- or two-letter element symbol.
fn capitalised(symbol: &str) -> String {
    let mut c = symbol.chars();
    c.next()
        .map(|first| first.to_ascii_uppercase().to_string() + &c.as_str().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Parses the `ATOM` and `HETATM` records of PDB text; water (residues `HOH`, `WAT`) is left
/// out, as molecular pictures leave it out. Other records are ignored.
///
/// # Errors
/// `Parse` naming `path` and the line: a record too short to hold its coordinates, a
/// coordinate that is not a finite number, no element to be found; no atoms at all; more than
/// [`MAX_ATOMS`].
pub fn parse_pdb(path: &Path, text: &str) -> Result<Vec<Atom>> {
    let mut atoms = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        if !(line.starts_with("ATOM  ") || line.starts_with("HETATM")) {
            continue;
        }
        if matches!(columns(line, 18, 20).trim(), "HOH" | "WAT") {
            continue;
        }
        if line.len() < 54 {
            return Err(Error::parse(
                path,
                Some(n),
                format!(
                    "an ATOM/HETATM record needs its coordinates in columns 31-54, the line has \
                     {} characters: \"{}\"",
                    line.len(),
                    excerpt(line)
                ),
            ));
        }
        let mut p = [0f32; 3];
        for (k, (a, b)) in [(31, 38), (39, 46), (47, 54)].into_iter().enumerate() {
            let field = columns(line, a, b).trim();
            p[k] = field
                .parse::<f32>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    Error::parse(
                        path,
                        Some(n),
                        format!(
                            "coordinate {} (columns {a}-{b}) \"{}\" is not a finite number",
                            ["x", "y", "z"][k],
                            excerpt(field)
                        ),
                    )
                })?;
        }
        let element = element_of(line).ok_or_else(|| {
            Error::parse(
                path,
                Some(n),
                format!(
                    "no element: columns 77-78 and the atom name (columns 13-14) hold no \
                     letters: \"{}\"",
                    excerpt(line)
                ),
            )
        })?;
        if atoms.len() == MAX_ATOMS {
            return Err(Error::parse(
                path,
                Some(n),
                format!("more than {MAX_ATOMS} atoms (the PDB format's limit)"),
            ));
        }
        atoms.push(Atom {
            element,
            position: Vec3::from(p),
            line: n,
        });
    }
    if atoms.is_empty() {
        return Err(Error::parse(
            path,
            None,
            "no ATOM or HETATM records (other than water): not a PDB coordinate file",
        ));
    }
    Ok(atoms)
}

/// The element of a record: columns 77–78 when they hold letters, else the atom name's
/// columns 13–14 (letters only, so `1HG1`'s hydrogen is `H`).
fn element_of(line: &str) -> Option<String> {
    let letters = |s: &str| -> String { s.chars().filter(char::is_ascii_alphabetic).collect() };
    let symbol = letters(columns(line, 77, 78));
    if !symbol.is_empty() {
        return Some(capitalised(&symbol));
    }
    let name = letters(columns(line, 13, 14));
    match name.len() {
        0 => None,
        // A letter in column 13 with one in 14 is a two-letter element only when column 13 is
        // not a digit or blank; hydrogens named like "HG11" are written from column 13 too, so
        // names starting with H are hydrogen (the common convention of PDB readers).
        _ if name.starts_with('H') => Some("H".into()),
        1 => Some(capitalised(&name)),
        _ if columns(line, 13, 13) == " " => Some(capitalised(&name[..1])),
        _ => Some(capitalised(&name)),
    }
}

/// Reads and parses a PDB file.
///
/// # Errors
/// Unreadable or oversized file, and what [`parse_pdb`] refuses.
pub fn load_pdb(path: &Path) -> Result<Vec<Atom>> {
    let text = stereolab_core::read_text(path, MAX_PDB_BYTES)?;
    parse_pdb(path, &text)
}

/// Triangles [`atoms_mesh`] makes for `atoms` atoms at `detail` (for the budget check before
/// anything is built).
pub fn planned_triangles(atoms: usize, detail: u32) -> u64 {
    atoms as u64 * 2 * u64::from(detail) * u64::from(detail / 2)
}

/// One sphere per atom ([`Mesh::sphere`] with `detail` segments and `detail / 2` rings) of
/// `radius_scale ×` its [`cpk_radius`], centred on the atoms' centroid (so a scene places the
/// molecule by `translate`), in ångströms.
pub fn atoms_mesh(atoms: &[Atom], detail: u32, radius_scale: f32) -> Mesh {
    let centroid = atoms.iter().map(|a| a.position).sum::<Vec3>() / atoms.len().max(1) as f32;
    let mut mesh = Mesh::default();
    for a in atoms {
        let sphere = Mesh::sphere(radius_scale * cpk_radius(&a.element), detail, detail / 2);
        let base = mesh.positions.len() as u32;
        let at = a.position - centroid;
        mesh.positions
            .extend(sphere.positions.iter().map(|p| *p + at));
        mesh.normals.extend(sphere.normals);
        mesh.uvs.extend(sphere.uvs);
        mesh.triangles
            .extend(sphere.triangles.iter().map(|t| t.map(|k| k + base)));
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    const RECORDS: &str = "\
HEADER    TEST
ATOM      1  N   PRO A   1      -3.022   4.020  30.100  1.00 28.38      1HPV 146
ATOM      2  CA  PRO A   1      -3.889   3.120  30.881  1.00 27.31           C
HETATM    3 FE   HEM A   2       1.000   2.000   3.000  1.00 10.00
HETATM    4  O   HOH A   3       9.000   9.000   9.000  1.00 10.00           O
ATOM      5 1HG1 VAL A   4       0.000   0.000   0.000  1.00 10.00
END
";

    #[test]
    fn reads_elements_from_either_place_and_skips_water() {
        let atoms = parse_pdb(Path::new("t.pdb"), RECORDS).unwrap();
        let elements: Vec<&str> = atoms.iter().map(|a| a.element.as_str()).collect();
        assert_eq!(elements, ["N", "C", "Fe", "H"]);
        assert_eq!(atoms[0].position, Vec3::new(-3.022, 4.020, 30.100));
        assert_eq!(atoms[2].line, 4);
    }

    #[test]
    fn bad_records_are_refused_naming_the_line() {
        let bad = "ATOM      1  N   PRO A   1      -3.022   x.020  30.100  1.00 28.38\n";
        let e = parse_pdb(Path::new("t.pdb"), bad).unwrap_err().to_string();
        assert!(e.contains(":1") && e.contains("coordinate y"), "{e}");
        let short = "ATOM      1  N   PRO A   1      -3.022\n";
        let e = parse_pdb(Path::new("t.pdb"), short)
            .unwrap_err()
            .to_string();
        assert!(e.contains("columns 31-54"), "{e}");
        let e = parse_pdb(Path::new("t.pdb"), "HEADER\nEND\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no ATOM or HETATM"), "{e}");
    }

    #[test]
    fn spheres_have_the_cpk_radius_about_each_atom() {
        let atoms = parse_pdb(Path::new("t.pdb"), RECORDS).unwrap();
        let m = atoms_mesh(&atoms, 8, 1.0);
        assert_eq!(m.triangles.len() as u64, planned_triangles(atoms.len(), 8));
        let centroid = atoms.iter().map(|a| a.position).sum::<Vec3>() / 4.0;
        let per = m.positions.len() / atoms.len();
        for (k, a) in atoms.iter().enumerate() {
            for p in &m.positions[k * per..(k + 1) * per] {
                let r = (*p - (a.position - centroid)).length();
                assert!((r - cpk_radius(&a.element)).abs() < 1e-4, "{r}");
            }
        }
    }
}
