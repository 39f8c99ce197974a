//! serde's errors for a scene table, reworded: the field's dotted path, the value as written
//! (escaped, at most [`EXCERPT_CHARS`] characters) and what the field accepts, in the scene
//! format's words instead of Rust's type names.

use stereolab_core::{EXCERPT_CHARS, excerpt};

use super::file::SceneFile;

/// Accepted forms of the fields whose Rust type says nothing to a scene's author (an untagged
/// enum, a list of names).
const FORMS: &[(&str, &str)] = &[
    (
        "stereo.eye_separation",
        "a number (world units) or \"auto\"",
    ),
    (
        "stereo.zero_parallax",
        "a distance, \"auto\" (the camera target's distance) or \"fit\"",
    ),
    (
        "outputs",
        "a list of output names in quotes, e.g. [\"left\", \"right\"]",
    ),
    (
        "mesh",
        "[[mesh]] tables, each with a kind (obj, sphere, cube, torus, plane, triangles, \
         terrain, dem, pdb)",
    ),
    (
        "mesh.kind",
        "one of \"obj\", \"sphere\", \"cube\", \"torus\", \"plane\", \"triangles\", \"terrain\", \
         \"dem\", \"pdb\"",
    ),
];

/// A scene table's deserialization error, located and reworded.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FieldError {
    /// The dotted path of the field (`mesh.0.color`), array entries by index.
    pub path: Vec<String>,
    /// The value as written, escaped and cut to an excerpt; `None` when the field is missing.
    pub value: Option<String>,
    /// Why it is refused and what is accepted.
    pub reason: String,
}

impl FieldError {
    /// The dotted path, array entries as `[i]` (`mesh[0].color`), as the scene's checks name them.
    pub fn field(&self) -> String {
        let mut out = String::new();
        for k in &self.path {
            if k.parse::<usize>().is_ok() {
                out.push_str(&format!("[{k}]"));
            } else {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(&excerpt(k));
            }
        }
        out
    }

    /// `field = value: reason`, or `field: reason` when there is no value.
    pub fn message(&self) -> String {
        match &self.value {
            Some(v) => format!("{} = {v}: {}", self.field(), self.reason),
            None => format!("{}: {}", self.field(), self.reason),
        }
    }
}

/// Locates and rewords `e`, the error of deserializing `table` as a [`SceneFile`].
pub(crate) fn describe(table: &toml::Table, e: &toml::de::Error) -> FieldError {
    let mut path = keys_of(e);
    let message = e.message();
    // serde reports an unknown or missing field at the table that holds it.
    let named = backticked(message).map(str::to_string);
    let unknown = message.starts_with("unknown field");
    let missing = message.starts_with("missing field");
    if let Some(name) = named.clone().filter(|_| unknown || missing) {
        path.push(name);
    }
    index_arrays(table, &mut path);
    let written = lookup(table, &path);
    let value = if missing { None } else { written.map(quote) };
    let reason = if unknown {
        let holder = &path[..path.len() - 1];
        let known = listed(message);
        match holder {
            [] => format!("no such table or field; a scene file has {known}"),
            _ => format!(
                "no such field in [{}]; it has {known}",
                holder
                    .iter()
                    .filter(|k| k.parse::<usize>().is_err())
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(".")
            ),
        }
    } else if missing {
        match form_of(&path) {
            Some(form) => format!("missing; give {form}"),
            None => "missing; the field is required".to_string(),
        }
    } else {
        format!("must be {}", accepted(table, &path, message))
    };
    FieldError {
        path,
        value,
        reason,
    }
}

/// The keys toml names in its message's last line, `in `a.b``.
fn keys_of(e: &toml::de::Error) -> Vec<String> {
    let shown = e.to_string();
    shown
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("in `")?.strip_suffix('`'))
        .map(|k| k.split('.').map(str::to_string).collect())
        .unwrap_or_default()
}

/// The first `` `name` `` in serde's message.
fn backticked(message: &str) -> Option<&str> {
    let (_, rest) = message.split_once('`')?;
    Some(rest.split_once('`')?.0)
}

/// The names after "expected" in serde's message, as a list: `a, b or c`.
fn listed(message: &str) -> String {
    let Some((_, names)) = message.split_once("expected ") else {
        return "other fields".to_string();
    };
    let names: Vec<String> = names.split('`').skip(1).step_by(2).map(excerpt).collect();
    match names.as_slice() {
        [] => "no fields".to_string(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// toml does not name array entries: finds the entry of each array of tables on `path` that
/// fails, by deserializing the scene with one entry at a time.
fn index_arrays(table: &toml::Table, path: &mut Vec<String>) {
    let Some(first) = path.first() else {
        return;
    };
    let Some(toml::Value::Array(entries)) = table.get(first) else {
        return;
    };
    if path.get(1).is_some_and(|k| k.parse::<usize>().is_ok()) {
        return;
    }
    for (i, entry) in entries.iter().enumerate() {
        let mut one = table.clone();
        one.insert(first.clone(), toml::Value::Array(vec![entry.clone()]));
        if toml::Value::Table(one).try_into::<SceneFile>().is_err() {
            path.insert(1, i.to_string());
            return;
        }
    }
}

/// The value at `path` (numeric segments index arrays).
fn lookup<'a>(table: &'a toml::Table, path: &[String]) -> Option<&'a toml::Value> {
    let (first, rest) = path.split_first()?;
    let mut cur = table.get(first)?;
    for k in rest {
        cur = match cur {
            toml::Value::Table(t) => t.get(k)?,
            toml::Value::Array(a) => a.get(k.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    Some(cur)
}

/// A value as TOML writes it, control characters escaped, cut to [`EXCERPT_CHARS`].
pub(crate) fn quote(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("\"{}\"", excerpt(s)),
        other => {
            let text = other.to_string();
            let mut out = String::new();
            for (i, c) in text.chars().enumerate() {
                if i == EXCERPT_CHARS {
                    out.push('…');
                    break;
                }
                if c.is_control() {
                    out.extend(c.escape_default());
                } else {
                    out.push(c);
                }
            }
            out
        }
    }
}

/// The entry of [`FORMS`] for `path`, array indices left out.
fn form_of(path: &[String]) -> Option<&'static str> {
    let key: Vec<&str> = path
        .iter()
        .map(String::as_str)
        .filter(|k| k.parse::<usize>().is_err())
        .collect();
    let key = key.join(".");
    FORMS.iter().find(|(k, _)| *k == key).map(|(_, f)| *f)
}

/// What the field at `path` accepts, from [`FORMS`] or from what serde expected.
fn accepted(table: &toml::Table, path: &[String], message: &str) -> String {
    if let Some(form) = form_of(path) {
        return form.to_string();
    }
    // A name list from a custom reader (`unknown value "x"; known: a, b`).
    if let Some((_, known)) = message.split_once("; known: ") {
        let names: Vec<String> = known
            .split(", ")
            .map(|n| format!("\"{}\"", excerpt(n)))
            .collect();
        return format!("one of {}", names.join(", "));
    }
    // An enum's own names (`unknown variant `x`, expected one of `a`, `b``).
    if message.starts_with("unknown variant") {
        return one_of(message);
    }
    // An enum given a number or a list: ask serde for its names with a string no name matches.
    if message.starts_with("wanted ")
        || message.ends_with("expected string only")
        || message.contains("expected enum")
    {
        if let Some(names) = variant_names(table, path) {
            return names;
        }
        return "one of the names the scene format lists for it".to_string();
    }
    let expected = message
        .split_once(", expected ")
        .map_or(message, |(_, e)| e)
        .trim();
    plain(expected)
}

/// `one of "a", "b"` from serde's `expected one of `a`, `b`` (or `expected `a` or `b``).
fn one_of(message: &str) -> String {
    let Some((_, names)) = message.split_once("expected ") else {
        return "one of the names the scene format lists for it".to_string();
    };
    let names: Vec<String> = names
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|n| format!("\"{}\"", excerpt(n)))
        .collect();
    match names.as_slice() {
        [one] => one.clone(),
        _ => format!("one of {}", names.join(", ")),
    }
}

/// The names of the enum at `path`, by deserializing the scene with a string there that no
/// name matches.
fn variant_names(table: &toml::Table, path: &[String]) -> Option<String> {
    let mut probe = toml::Value::Table(table.clone());
    let mut cur = &mut probe;
    for k in path {
        cur = match cur {
            toml::Value::Table(t) => t.get_mut(k)?,
            toml::Value::Array(a) => a.get_mut(k.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    *cur = toml::Value::String("\u{1}".to_string());
    let e = probe.try_into::<SceneFile>().err()?;
    e.message()
        .starts_with("unknown variant")
        .then(|| one_of(e.message()))
}

/// serde's description of an expected type in the scene format's words.
fn plain(expected: &str) -> String {
    let integer = |bits: u32, signed: bool| match (bits, signed) {
        (8, false) => "a whole number from 0 to 255".to_string(),
        (16, false) => "a whole number from 0 to 65535".to_string(),
        (32, false) => "a whole number from 0 to 4294967295".to_string(),
        (64, false) => "a whole number from 0 to 18446744073709551615".to_string(),
        _ => "a whole number".to_string(),
    };
    match expected {
        "f32" | "f64" => "a number".to_string(),
        "u8" => integer(8, false),
        "u16" => integer(16, false),
        "u32" => integer(32, false),
        "u64" | "usize" => integer(64, false),
        "i8" | "i16" | "i32" | "i64" | "isize" => integer(64, true),
        "a boolean" => "true or false".to_string(),
        "a string" | "a borrowed string" => "text in quotes".to_string(),
        "a character" => "one character in quotes".to_string(),
        "a sequence" => "a list in brackets, e.g. [1, 2]".to_string(),
        e if e.starts_with("an array of length ") => {
            let n = e.trim_start_matches("an array of length ");
            format!("a list of {n} numbers, e.g. [{}]", example_list(n))
        }
        e if e.starts_with("struct ") || e == "a map" => {
            "a table (a [name] section, or { key = value, … })".to_string()
        }
        // A reader's own words (a custom message) are kept, escaped.
        e => excerpt(e),
    }
}

/// `0, 0, 0` for `n = 3`.
fn example_list(n: &str) -> String {
    let n: usize = n.parse().unwrap_or(3).min(4);
    vec!["0"; n].join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "outputs = [\"left\"]\n[image]\nwidth = 32\nheight = 24\n\
        [camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n\
        [[mesh]]\nkind = \"sphere\"\n[[mesh]]\nkind = \"cube\"\n";

    fn described(extra: &[(&[&str], toml::Value)]) -> FieldError {
        let mut table: toml::Table = toml::from_str(SCENE).unwrap();
        for (path, v) in extra {
            let mut cur = &mut table;
            let (last, init) = path.split_last().unwrap();
            for k in init {
                let entry = cur
                    .entry(k.to_string())
                    .or_insert_with(|| toml::Value::Table(toml::Table::new()));
                cur = match entry {
                    toml::Value::Table(t) => t,
                    toml::Value::Array(a) => match &mut a[1] {
                        toml::Value::Table(t) => t,
                        _ => unreachable!(),
                    },
                    _ => unreachable!(),
                };
            }
            cur.insert(last.to_string(), v.clone());
        }
        let e = toml::Value::Table(table.clone())
            .try_into::<SceneFile>()
            .unwrap_err();
        describe(&table, &e)
    }

    #[test]
    fn untagged_fields_name_their_forms() {
        let d = described(&[(&["stereo", "eye_separation"], toml::Value::Boolean(true))]);
        assert_eq!(
            d.message(),
            "stereo.eye_separation = true: must be a number (world units) or \"auto\""
        );
    }

    #[test]
    fn wrong_types_say_what_is_accepted_without_type_names() {
        let d = described(&[(&["image", "width"], toml::Value::Float(64.5))]);
        assert_eq!(
            d.message(),
            "image.width = 64.5: must be a whole number from 0 to 4294967295"
        );
        let d = described(&[(&["camera"], toml::Value::Integer(5))]);
        assert!(
            d.message().starts_with("camera = 5: must be a table"),
            "{d:?}"
        );
        assert!(!d.message().contains("Camera"), "{d:?}");
        let d = described(&[(&["stereo", "mode"], toml::Value::Integer(3))]);
        assert!(
            d.message()
                .starts_with("stereo.mode = 3: must be one of \"off-axis\""),
            "{d:?}"
        );
    }

    #[test]
    fn array_entries_are_named_by_index_and_values_escaped() {
        let d = described(&[(
            &["mesh", "color"],
            toml::Value::String("\u{1b}[2J".repeat(20)),
        )]);
        assert_eq!(d.field(), "mesh[1].color");
        let v = d.value.clone().unwrap();
        assert!(v.starts_with("\"\\u{1b}[2J"), "{v}");
        assert!(v.ends_with("…\""), "{v}");
        assert!(!v.contains('\u{1b}'), "{v}");
        assert!(d.reason.contains("a list of 3 numbers"), "{d:?}");
    }

    #[test]
    fn unknown_and_missing_fields_name_the_table() {
        let d = described(&[(&["camera", "fovy"], toml::Value::Float(1.0))]);
        assert_eq!(d.field(), "camera.fovy");
        assert!(
            d.reason.starts_with("no such field in [camera]; it has "),
            "{d:?}"
        );
        assert!(d.reason.contains("fov_y"), "{d:?}");
        let d = described(&[(&["camra"], toml::Value::Table(toml::Table::new()))]);
        assert_eq!(d.field(), "camra");
        assert!(d.reason.contains("a scene file has"), "{d:?}");
    }
}
