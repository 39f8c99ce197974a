//! The similarity report of a batch (`similarity.csv`): which submitted functions look like the
//! instructor's reference or like a classmate's, for the instructor to look at. It never changes
//! a score, and a high similarity is a reason to read two functions side by side, not proof of
//! copying (short formulas from the same paper can look alike).
//!
//! The method is winnowing: Schleimer, Wilkerson and Aiken, "Winnowing: Local Algorithms for
//! Document Fingerprinting", SIGMOD 2003 (the algorithm behind MOSS). Step by step, each a
//! function below:
//!
//! 1. [`tokenize`]: Rust source to tokens; comments and whitespace are dropped.
//! 2. [`normalise`]: every identifier (other than keywords and primitive type names) becomes
//!    `I`, every literal `L`; keywords and punctuation stay. Renaming variables or functions,
//!    changing numbers, comments or layout changes nothing.
//! 3. [`kgram_hashes`]: a hash of every run of [`K`] consecutive normalised tokens.
//! 4. [`winnow`]: in every window of [`W`] consecutive hashes the smallest (the rightmost on a
//!    tie) is kept as a fingerprint. The paper's guarantee: two functions sharing a run of at
//!    least `W + K − 1` normalised tokens share a fingerprint; runs shorter than `K` are
//!    ignored as noise.
//! 5. Base code: fingerprints that are k-gram hashes of the handout's own stubs (signatures,
//!    doc comments, `todo!()` bodies) are removed, as MOSS removes base code, so the template
//!    every student starts from matches nothing.
//! 6. [`score`]: two functions' similarity is `shared / min(|A|, |B|)`, the fingerprints they
//!    share over the fingerprints of the smaller one: 1.0 when one function's fingerprints all
//!    occur in the other. Only functions with at least [`MIN_FINGERPRINTS`] fingerprints are
//!    compared, so a one-line function does not match everything.
//!
//! Files are split into their functions ([`functions`]: `fn` items, also inside `impl` blocks
//! and modules, by brace matching on tokens) and every function of a submission is compared with
//! every function of the reference solution and of every other submission of the same exercise:
//! by fingerprints, not by name, so a renamed function or a reordered file is still found.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::Exercise;
use super::batch::{csv_field, submission_root};
use stereolab_core::{Error, Result};

/// The default threshold of `--similarity-threshold`: pairs at or above it are flagged. At 0.8
/// four fifths of the smaller function's fingerprints (each one a run of [`K`] tokens) occur in
/// the other; the reference solution's functions and independently written versions of them
/// stay well below it, copies with renamed identifiers and changed comments score 1.0.
pub const DEFAULT_THRESHOLD: f64 = 0.8;

/// Tokens per k-gram: matches shorter than this are noise (`I . I ( ) ;` is in every file).
pub const K: usize = 10;

/// Hashes per winnowing window: any shared run of `W + K − 1` tokens yields a shared fingerprint.
pub const W: usize = 4;

/// The fewest fingerprints (after removing the handout's) a function needs to be compared:
/// about five lines of code (winnowing keeps about `2 / (W + 1)` of the k-grams). A function
/// that is one short formula (`texgen` as the ChromaDepth article gives it: 13 fingerprints) is
/// written alike by everyone who gets it right, so it is not compared.
pub const MIN_FINGERPRINTS: usize = 16;

/// The name of the report in the results folder.
pub const FILE_NAME: &str = "similarity.csv";

/// The largest file read (as the grader's build reads stubs).
const MAX_SOURCE_BYTES: u64 = 1 << 20;

/// What a token is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A name: a variable, function, type, field, macro or lifetime.
    Ident,
    /// A number, string (also raw and byte strings) or character.
    Literal,
    /// A Rust keyword or primitive type name (`let`, `fn`, `f32`, `self`, …).
    Keyword,
    /// One punctuation character.
    Punct,
}

/// One token of a Rust source.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    /// Its kind.
    pub kind: Kind,
    /// Its text as written (a literal's whole text, a raw identifier without `r#`).
    pub text: String,
    /// Its line, from 1.
    pub line: u32,
}

/// Rust's keywords (strict, reserved and weak) and primitive type names: kept by [`normalise`].
const KEYWORDS: [&str; 71] = [
    "_", "abstract", "as", "async", "await", "become", "box", "break", "const", "continue",
    "crate", "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if",
    "impl", "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub",
    "ref", "return", "self", "Self", "static", "struct", "super", "trait", "true", "try", "type",
    "typeof", "union", "unsafe", "unsized", "use", "virtual", "where", "while", "yield", "bool",
    "char", "str", "i8", "i16", "i32", "i64", "i128", "isize", "u8", "u16", "u32", "u64", "u128",
    "usize", "f32", "f64",
];

/// A cursor over a source's characters that counts lines.
struct Cursor {
    chars: Vec<char>,
    pos: usize,
    line: u32,
}

impl Cursor {
    fn peek(&self, ahead: usize) -> Option<char> {
        self.chars.get(self.pos + ahead).copied()
    }

    fn bump(&mut self) {
        if self.peek(0) == Some('\n') {
            self.line = self.line.saturating_add(1);
        }
        self.pos = (self.pos + 1).min(self.chars.len());
    }

    fn bump_while(&mut self, keep: impl Fn(char) -> bool) {
        while self.peek(0).is_some_and(&keep) {
            self.bump();
        }
    }

    fn text_from(&self, start: usize) -> String {
        self.chars[start..self.pos].iter().collect()
    }
}

fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Step 1: the tokens of `src`, comments (line, block, nested, doc) and whitespace dropped. Any
/// text is accepted: an unterminated string or comment runs to the end, an unknown character is
/// punctuation.
pub fn tokenize(src: &str) -> Vec<Token> {
    let mut cur = Cursor {
        chars: src.chars().collect(),
        pos: 0,
        line: 1,
    };
    let mut tokens = Vec::new();
    while let Some(c) = cur.peek(0) {
        let (start, line) = (cur.pos, cur.line);
        let kind = if c.is_whitespace() {
            cur.bump();
            continue;
        } else if c == '/' && cur.peek(1) == Some('/') {
            cur.bump_while(|c| c != '\n');
            continue;
        } else if c == '/' && cur.peek(1) == Some('*') {
            block_comment(&mut cur);
            continue;
        } else if let Some(prefix) = raw_string_prefix(&cur) {
            raw_string(&mut cur, prefix);
            Kind::Literal
        } else if (c == 'b' || c == 'c') && cur.peek(1) == Some('"') {
            cur.bump();
            quoted(&mut cur, '"');
            Kind::Literal
        } else if c == 'b' && cur.peek(1) == Some('\'') {
            cur.bump();
            quoted(&mut cur, '\'');
            Kind::Literal
        } else if c == 'r' && cur.peek(1) == Some('#') && cur.peek(2).is_some_and(is_ident_start) {
            cur.bump();
            cur.bump();
            let name_start = cur.pos;
            cur.bump_while(is_ident_char);
            tokens.push(Token {
                kind: Kind::Ident,
                text: cur.text_from(name_start),
                line,
            });
            continue;
        } else if is_ident_start(c) {
            cur.bump_while(is_ident_char);
            if KEYWORDS.contains(&cur.text_from(start).as_str()) {
                Kind::Keyword
            } else {
                Kind::Ident
            }
        } else if c.is_ascii_digit() {
            number(&mut cur);
            Kind::Literal
        } else if c == '"' {
            quoted(&mut cur, '"');
            Kind::Literal
        } else if c == '\'' {
            char_or_lifetime(&mut cur)
        } else {
            cur.bump();
            Kind::Punct
        };
        tokens.push(Token {
            kind,
            text: cur.text_from(start),
            line,
        });
    }
    tokens
}

/// `/* … */`, nested ones included; an unterminated comment runs to the end.
fn block_comment(cur: &mut Cursor) {
    let mut depth = 0usize;
    while let Some(c) = cur.peek(0) {
        if c == '/' && cur.peek(1) == Some('*') {
            depth += 1;
            cur.bump();
        } else if c == '*' && cur.peek(1) == Some('/') {
            depth = depth.saturating_sub(1);
            cur.bump();
            if depth == 0 {
                cur.bump();
                return;
            }
        }
        cur.bump();
    }
}

/// The length of `r`, `br` or `cr` when a raw string starts here (`r"`, `r#"`, `br##"`, …).
fn raw_string_prefix(cur: &Cursor) -> Option<usize> {
    let prefix = match (cur.peek(0)?, cur.peek(1)) {
        ('r', _) => 1,
        ('b' | 'c', Some('r')) => 2,
        _ => return None,
    };
    let mut k = prefix;
    while cur.peek(k) == Some('#') {
        k += 1;
    }
    (cur.peek(k) == Some('"')).then_some(prefix)
}

/// A raw string: its prefix, `n` hashes, `"`, up to `"` followed by `n` hashes.
fn raw_string(cur: &mut Cursor, prefix: usize) {
    for _ in 0..prefix {
        cur.bump();
    }
    let mut hashes = 0;
    while cur.peek(0) == Some('#') {
        hashes += 1;
        cur.bump();
    }
    cur.bump();
    while let Some(c) = cur.peek(0) {
        cur.bump();
        if c == '"' && (0..hashes).all(|k| cur.peek(k) == Some('#')) {
            for _ in 0..hashes {
                cur.bump();
            }
            return;
        }
    }
}

/// A string or character from its opening `quote` to the closing one, escapes skipped.
fn quoted(cur: &mut Cursor, quote: char) {
    cur.bump();
    while let Some(c) = cur.peek(0) {
        cur.bump();
        if c == '\\' {
            cur.bump();
        } else if c == quote {
            return;
        }
    }
}

/// `'x'`, `'\n'`, `'\u{…}'` (a literal) or `'a`, `'static` (a lifetime: a name).
fn char_or_lifetime(cur: &mut Cursor) -> Kind {
    let escaped = cur.peek(1) == Some('\\');
    let one_char = cur.peek(1).is_some() && cur.peek(2) == Some('\'');
    if escaped || one_char {
        quoted(cur, '\'');
        Kind::Literal
    } else if cur.peek(1).is_some_and(is_ident_start) {
        cur.bump();
        cur.bump_while(is_ident_char);
        Kind::Ident
    } else {
        cur.bump();
        Kind::Punct
    }
}

/// `42`, `0x1F`, `1_000u32`, `2.5e-3`, `1.0f32` (not the `..` of `1..2`, not a method call
/// `1.max(x)`).
fn number(cur: &mut Cursor) {
    let start = cur.pos;
    let mut seen_dot = false;
    while let Some(c) = cur.peek(0) {
        let after_exponent = cur.pos > start + 1
            && matches!(cur.chars[cur.pos - 1], 'e' | 'E')
            && cur.chars[start..cur.pos - 1]
                .iter()
                .all(|d| d.is_ascii_digit() || *d == '_' || *d == '.');
        let fraction = c == '.' && !seen_dot && cur.peek(1).is_some_and(|d| d.is_ascii_digit());
        if is_ident_char(c) || fraction || ((c == '+' || c == '-') && after_exponent) {
            seen_dot |= fraction;
            cur.bump();
        } else {
            break;
        }
    }
}

/// Step 2: the normalised token: `I` for a name, `L` for a literal, a keyword or punctuation as
/// written.
pub fn normalise(token: &Token) -> &str {
    match token.kind {
        Kind::Ident => "I",
        Kind::Literal => "L",
        Kind::Keyword | Kind::Punct => &token.text,
    }
}

/// FNV-1a, 64 bits: a hash that is the same on every machine and every run.
fn fnv1a(hash: u64, bytes: &[u8]) -> u64 {
    bytes.iter().fold(hash, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Step 3: the hash of every run of [`K`] consecutive normalised tokens, in order (none when
/// there are fewer than `K` tokens).
pub fn kgram_hashes(tokens: &[Token]) -> Vec<u64> {
    tokens
        .windows(K)
        .map(|gram| {
            gram.iter().fold(0xcbf2_9ce4_8422_2325, |h, t| {
                fnv1a(fnv1a(h, normalise(t).as_bytes()), &[0])
            })
        })
        .collect()
}

/// Step 4: winnowing with windows of `w` hashes: from each window the smallest hash (the
/// rightmost one on a tie), each selected position once. A sequence shorter than one window is
/// one window.
pub fn winnow(hashes: &[u64], w: usize) -> Vec<u64> {
    let w = w.clamp(1, hashes.len().max(1));
    let mut picked: Vec<u64> = Vec::new();
    let mut last = None;
    for start in 0..=hashes.len().saturating_sub(w) {
        let window = &hashes[start..(start + w).min(hashes.len())];
        let Some((offset, &h)) = window
            .iter()
            .enumerate()
            .min_by(|(i, a), (j, b)| a.cmp(b).then(j.cmp(i)))
        else {
            continue;
        };
        if last != Some(start + offset) {
            picked.push(h);
            last = Some(start + offset);
        }
    }
    picked
}

/// Step 6: `(shared, similarity)` of two fingerprint sets (each sorted, without repeats):
/// `shared / min(|a|, |b|)`; `None` when either has fewer than [`MIN_FINGERPRINTS`].
pub fn score(a: &[u64], b: &[u64]) -> Option<(usize, f64)> {
    let smaller = a.len().min(b.len());
    if smaller < MIN_FINGERPRINTS {
        return None;
    }
    let (mut i, mut j, mut shared) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                shared += 1;
                i += 1;
                j += 1;
            }
        }
    }
    Some((shared, shared as f64 / smaller as f64))
}

/// A function of a file: where it is, its tokens from `fn` to its closing brace.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FunctionSpan {
    /// Its name.
    pub name: String,
    /// The line of its `fn`.
    pub line: u32,
    /// Its tokens (`tokens[range]` of the file's).
    pub range: std::ops::Range<usize>,
}

/// The functions of a file's tokens: every `fn NAME … { … }` (also in `impl` blocks, traits and
/// modules; a function nested in another is part of the outer one), by brace matching. A body
/// left open runs to the end; `fn` without a body (a trait's declaration, a `fn(…)` type) is
/// none.
pub fn functions(tokens: &[Token]) -> Vec<FunctionSpan> {
    let mut found = Vec::new();
    let mut k = 0;
    while k < tokens.len() {
        let is_fn = tokens[k].kind == Kind::Keyword && tokens[k].text == "fn";
        let name = tokens.get(k + 1).filter(|t| t.kind == Kind::Ident);
        let (true, Some(name)) = (is_fn, name) else {
            k += 1;
            continue;
        };
        let Some(open) = body_start(tokens, k + 2) else {
            k += 2;
            continue;
        };
        let end = matching_brace(tokens, open);
        found.push(FunctionSpan {
            name: name.text.clone(),
            line: tokens[k].line,
            range: k..end,
        });
        k = end;
    }
    found
}

/// The `{` opening the body of a signature starting at `from`: the first one outside
/// parentheses and brackets; `None` at a `;` there (no body) or the end.
fn body_start(tokens: &[Token], from: usize) -> Option<usize> {
    let mut depth = 0i64;
    for (k, t) in tokens.iter().enumerate().skip(from) {
        if t.kind != Kind::Punct {
            continue;
        }
        match t.text.as_str() {
            "(" | "[" => depth += 1,
            ")" | "]" => depth -= 1,
            "{" if depth <= 0 => return Some(k),
            ";" if depth <= 0 => return None,
            _ => {}
        }
    }
    None
}

/// The end (one past the `}`) of the block opened at `open`, or the end of the tokens.
fn matching_brace(tokens: &[Token], open: usize) -> usize {
    let mut depth = 0usize;
    for (k, t) in tokens.iter().enumerate().skip(open) {
        if t.kind != Kind::Punct {
            continue;
        }
        if t.text == "{" {
            depth += 1;
        } else if t.text == "}" {
            depth -= 1;
            if depth == 0 {
                return k + 1;
            }
        }
    }
    tokens.len()
}

/// Step 5's base: every k-gram hash of the handout's file (not only its fingerprints, so a
/// template run is removed wherever winnowing picks it).
pub fn base_hashes(handout: &str) -> BTreeSet<u64> {
    kgram_hashes(&tokenize(handout)).into_iter().collect()
}

/// A function ready to compare.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    /// Its name.
    pub name: String,
    /// The line of its `fn`.
    pub line: u32,
    /// Its fingerprints without the base's, sorted, without repeats.
    pub fingerprints: Vec<u64>,
}

/// Steps 1–5 for a file: its functions with their fingerprints, `base` removed.
pub fn fingerprint_file(src: &str, base: &BTreeSet<u64>) -> Vec<Function> {
    let tokens = tokenize(src);
    functions(&tokens)
        .into_iter()
        .map(|f| {
            let mut fingerprints: Vec<u64> = winnow(&kgram_hashes(&tokens[f.range]), W)
                .into_iter()
                .filter(|h| !base.contains(h))
                .collect();
            fingerprints.sort_unstable();
            fingerprints.dedup();
            Function {
                name: f.name,
                line: f.line,
                fingerprints,
            }
        })
        .collect()
}

/// One side of a pair.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Side {
    /// The submission's folder name, or `reference` for the instructor's solution.
    pub submission: String,
    /// The function's name.
    pub function: String,
    /// The line of its `fn`.
    pub line: u32,
}

/// Two similar functions of one exercise.
#[derive(Clone, Debug, PartialEq)]
pub struct Pair {
    /// The exercise.
    pub exercise: Exercise,
    /// A submission's function.
    pub a: Side,
    /// Another submission's (named after `a`'s) or the reference's.
    pub b: Side,
    /// `shared / min(|A|, |B|)`.
    pub similarity: f64,
    /// Fingerprints they share.
    pub shared: usize,
    /// `similarity ≥` the threshold.
    pub flagged: bool,
}

/// The submission name of the instructor's solution in the report.
pub const REFERENCE: &str = "reference";

/// A scored pair by position: function `a.1` of submission `a.0`, function `b.1` of submission
/// `b.0` (`None`: the reference).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Candidate {
    similarity: f64,
    shared: usize,
    a: (usize, usize),
    b: (Option<usize>, usize),
}

impl Candidate {
    /// More similar, or as similar with more fingerprints shared.
    fn beats(&self, other: &Candidate) -> bool {
        (self.similarity, self.shared) > (other.similarity, other.shared)
    }
}

/// The order of the report: most similar first, then most shared, then by exercise and names.
fn report_order(p: &Pair, q: &Pair) -> std::cmp::Ordering {
    q.similarity
        .total_cmp(&p.similarity)
        .then(q.shared.cmp(&p.shared))
        .then_with(|| p.exercise.id().cmp(q.exercise.id()))
        .then_with(|| (&p.a, &p.b).cmp(&(&q.a, &q.b)))
}

/// The pairs to report among the functions of `submissions` (name, functions) and of the
/// `reference`: every pair at or above `threshold` and each submission's closest pair (when it
/// shares anything), most similar first.
pub fn compare(
    exercise: Exercise,
    submissions: &[(String, Vec<Function>)],
    reference: &[Function],
    threshold: f64,
) -> Vec<Pair> {
    let mut flagged = Vec::new();
    let mut closest: Vec<Option<Candidate>> = vec![None; submissions.len()];
    for (i, (_, funcs_a)) in submissions.iter().enumerate() {
        let others = (i + 1..submissions.len())
            .map(|j| (Some(j), submissions[j].1.as_slice()))
            .chain([(None, reference)]);
        for (j, funcs_b) in others {
            for (fa, func_a) in funcs_a.iter().enumerate() {
                for (fb, func_b) in funcs_b.iter().enumerate() {
                    let Some((shared, similarity)) =
                        score(&func_a.fingerprints, &func_b.fingerprints)
                    else {
                        continue;
                    };
                    if shared == 0 {
                        continue;
                    }
                    let c = Candidate {
                        similarity,
                        shared,
                        a: (i, fa),
                        b: (j, fb),
                    };
                    if similarity >= threshold {
                        flagged.push(c);
                    }
                    for s in [Some(i), j].into_iter().flatten() {
                        if closest[s].is_none_or(|best| c.beats(&best)) {
                            closest[s] = Some(c);
                        }
                    }
                }
            }
        }
    }
    for c in closest.into_iter().flatten() {
        if !flagged.contains(&c) {
            flagged.push(c);
        }
    }
    let side = |s: Option<usize>, f: usize| {
        let (name, funcs) = match s {
            Some(s) => (submissions[s].0.as_str(), submissions[s].1.as_slice()),
            None => (REFERENCE, reference),
        };
        Side {
            submission: name.to_string(),
            function: funcs[f].name.clone(),
            line: funcs[f].line,
        }
    };
    let mut pairs: Vec<Pair> = flagged
        .into_iter()
        .map(|c| Pair {
            exercise,
            a: side(Some(c.a.0), c.a.1),
            b: side(c.b.0, c.b.1),
            similarity: c.similarity,
            shared: c.shared,
            flagged: c.similarity >= threshold,
        })
        .collect();
    pairs.sort_by(report_order);
    pairs
}

/// A CSV field of text, escaped as `scores.csv`'s are (a formula-like name gets a `'`).
fn text_field(s: &str) -> String {
    csv_field(s)
}

/// The report: what was compared and the pairs found.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// What is missing for an exercise: no reference solution (classmates compared only), no
    /// handout stubs (the template not removed).
    pub notes: Vec<(Exercise, String)>,
    /// The pairs, most similar first (then most shared, then by exercise and names).
    pub pairs: Vec<Pair>,
}

/// The CSV's header.
pub const HEADER: &str = "exercise,submission_a,function_a,line_a,submission_b,function_b,line_b,similarity,shared,flagged";

impl Report {
    /// `similarity.csv`: [`HEADER`], a row per note (its text as `function_b`), then a row per
    /// pair (`similarity` with two decimals, `flagged` `yes` or `no`).
    pub fn csv(&self) -> String {
        let mut s = format!("{HEADER}\n");
        for (ex, note) in &self.notes {
            let _ = writeln!(s, "{},,,,{REFERENCE},{},,,,", ex.id(), text_field(note));
        }
        for p in &self.pairs {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{:.2},{},{}",
                p.exercise.id(),
                text_field(&p.a.submission),
                text_field(&p.a.function),
                p.a.line,
                text_field(&p.b.submission),
                text_field(&p.b.function),
                p.b.line,
                p.similarity,
                p.shared,
                if p.flagged { "yes" } else { "no" },
            );
        }
        s
    }

    /// The pairs at or above the threshold.
    pub fn flagged(&self) -> usize {
        self.pairs.iter().filter(|p| p.flagged).count()
    }
}

/// `threshold` when it is a similarity in (0, 1].
///
/// # Errors
/// Anything else.
pub fn check_threshold(threshold: f64) -> Result<f64> {
    if threshold > 0.0 && threshold <= 1.0 {
        Ok(threshold)
    } else {
        Err(Error::invalid(
            "--similarity-threshold",
            threshold,
            "must be a similarity above 0 and at most 1",
        ))
    }
}

/// A file's text, `None` when it is missing or unreadable (the grading report says why); bytes
/// that are not UTF-8 become U+FFFD.
fn read_source(path: &Path) -> Option<String> {
    let bytes = stereolab_core::read_input(path, MAX_SOURCE_BYTES).ok()?;
    Some(String::from_utf8_lossy(&bytes).into_owned())
}

/// The exercises folder of the repository the grader was built from (reference solutions and
/// the handout's stubs).
pub fn repository_exercises() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../exercises")
}

/// Compares the submissions `subs` (name, folder; as [`super::batch::submissions`] lists them)
/// for `exercises`, with the references and handout stubs of `repository` (its
/// `<crate>/src/solution.rs` and `stubs.rs`).
///
/// # Errors
/// A threshold outside (0, 1].
pub fn batch_report(
    subs: &[(String, PathBuf)],
    exercises: &[Exercise],
    repository: &Path,
    threshold: f64,
) -> Result<Report> {
    let threshold = check_threshold(threshold)?;
    let mut report = Report::default();
    for &ex in exercises {
        let src = repository.join(ex.crate_name()).join("src");
        let base = match read_source(&src.join("stubs.rs")) {
            Some(stubs) => base_hashes(&stubs),
            None => {
                let missing = src.join("stubs.rs");
                report.notes.push((
                    ex,
                    format!(
                        "no handout stubs at {}: the template is not removed",
                        missing.display()
                    ),
                ));
                BTreeSet::new()
            }
        };
        let solution = src.join("solution.rs");
        let reference = match read_source(&solution) {
            Some(text) => fingerprint_file(&text, &base),
            None => {
                report.notes.push((
                    ex,
                    format!(
                        "no reference solution at {}: classmates compared only",
                        solution.display()
                    ),
                ));
                Vec::new()
            }
        };
        let files: Vec<(String, Vec<Function>)> = subs
            .iter()
            .filter_map(|(name, dir)| {
                let root = submission_root(dir, exercises).unwrap_or_else(|| dir.clone());
                let text = read_source(&super::stubs_path(&root, ex, false))?;
                Some((name.clone(), fingerprint_file(&text, &base)))
            })
            .collect();
        report
            .pairs
            .extend(compare(ex, &files, &reference, threshold));
    }
    report.pairs.sort_by(report_order);
    Ok(report)
}

/// `out/similarity.csv` for the submissions `subs` of a batch, references from
/// [`repository_exercises`].
///
/// # Errors
/// A threshold outside (0, 1], or the file cannot be written.
pub fn write_batch_report(
    subs: &[(String, PathBuf)],
    exercises: &[Exercise],
    threshold: f64,
    out: &Path,
) -> Result<Report> {
    let report = batch_report(subs, exercises, &repository_exercises(), threshold)?;
    stereolab_core::write_bytes(&out.join(FILE_NAME), report.csv().as_bytes())?;
    Ok(report)
}

/// The records of a CSV text (quoted fields with `""` for a quote, as [`Report::csv`] writes).
pub fn csv_records(text: &str) -> Vec<Vec<String>> {
    let (mut records, mut record, mut field) = (Vec::new(), Vec::new(), String::new());
    let mut quoted = false;
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') => quoted = true,
            (false, ',') => record.push(std::mem::take(&mut field)),
            (false, '\n') => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
            }
            (false, '\r') => {}
            (false, c) => field.push(c),
        }
    }
    if !field.is_empty() || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    records
}

/// What a written `similarity.csv` holds, for the command's summary line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// The pairs listed.
    pub pairs: usize,
    /// The pairs flagged.
    pub flagged: usize,
    /// The notes (a missing reference or handout), `exercise: text`.
    pub notes: Vec<String>,
}

impl Summary {
    /// Reads `out/similarity.csv`.
    ///
    /// # Errors
    /// The file cannot be read.
    pub fn read(out: &Path) -> Result<Summary> {
        let path = out.join(FILE_NAME);
        let text = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
        let mut summary = Summary::default();
        for record in csv_records(&text).iter().skip(1) {
            match record.get(9).map(String::as_str) {
                Some("yes") => summary.flagged += 1,
                Some("no") => {}
                _ => {
                    let exercise = record.first().map_or("", String::as_str);
                    let note = record.get(5).map_or("", String::as_str);
                    summary.notes.push(format!("{exercise}: {note}"));
                    continue;
                }
            }
            summary.pairs += 1;
        }
        Ok(summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(src: &str) -> Vec<(Kind, String)> {
        tokenize(src)
            .into_iter()
            .map(|t| (t.kind, t.text))
            .collect()
    }

    fn normalised(src: &str) -> Vec<String> {
        tokenize(src)
            .iter()
            .map(|t| normalise(t).to_string())
            .collect()
    }

    #[test]
    fn comments_and_whitespace_are_dropped_nested_block_comments_included() {
        let src = "/// doc\n//! inner\nlet /* a /* nested */ still comment */ x // line\n= 1;";
        assert_eq!(normalised(src), ["let", "I", "=", "L", ";"]);
    }

    #[test]
    fn identifiers_become_i_literals_l_keywords_and_punctuation_stay() {
        let src = r###"fn f(v: f32) -> u8 { let s = r#"a "q" b"#; let c = '\''; 'x' ; b"z"; 1.5e-3f32 }"###;
        assert_eq!(
            normalised(src).join(" "),
            "fn I ( I : f32 ) - > u8 { let I = L ; let I = L ; L ; L ; L }"
        );
    }

    #[test]
    fn lifetimes_are_names_and_ranges_keep_their_dots() {
        assert_eq!(normalised("&'a str"), ["&", "I", "str"]);
        assert_eq!(normalised("0..n"), ["L", ".", ".", "I"]);
        assert_eq!(normalised("1.max(x)"), ["L", ".", "I", "(", "I", ")"]);
        assert_eq!(normalised("1usize-1"), ["L", "-", "L"]);
        assert_eq!(kinds("r#type")[0], (Kind::Ident, "type".to_string()));
    }

    #[test]
    fn tokens_carry_their_lines() {
        let lines: Vec<u32> = tokenize("a\n/* x\n y */ b\n\"s\nt\" c")
            .iter()
            .map(|t| t.line)
            .collect();
        assert_eq!(lines, [1, 3, 4, 5]);
    }

    /// A deterministic stream of pseudo-random numbers (xorshift64).
    fn xorshift(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    #[test]
    fn arbitrary_bytes_and_broken_rust_never_panic() {
        const PIECES: [&str; 24] = [
            "fn", " f", "(", ")", "{", "}", "[", "]", ";", "'", "\"", "\\", "r#", "#", "b'", "br",
            "/*", "*/", "//", "\n", "1e", "0x", ".", "é",
        ];
        let mut state = 0x9e37_79b9_7f4a_7c15;
        let base = base_hashes("fn f() { todo!() }");
        for _ in 0..3000 {
            let len = (xorshift(&mut state) % 40) as usize;
            let src: String = if xorshift(&mut state).is_multiple_of(2) {
                let bytes: Vec<u8> = (0..len).map(|_| xorshift(&mut state) as u8).collect();
                String::from_utf8_lossy(&bytes).into_owned()
            } else {
                (0..len)
                    .map(|_| PIECES[(xorshift(&mut state) % PIECES.len() as u64) as usize])
                    .collect()
            };
            let tokens = tokenize(&src);
            for f in functions(&tokens) {
                assert!(f.range.start < f.range.end && f.range.end <= tokens.len());
            }
            let _ = fingerprint_file(&src, &base);
        }
        for odd in [
            "", "'", "\"", "r#", "r#\"", "b'", "/*", "/* /*", "fn", "fn x(", "fn x() {", "}}}",
            "1e", "'\\",
        ] {
            let _ = fingerprint_file(odd, &base);
        }
    }

    #[test]
    fn functions_are_found_in_impl_blocks_and_modules_with_names_and_lines() {
        let src = "struct S;\nimpl S {\n    fn a(&self) -> [u8; 2] { [0; 2] }\n}\nmod m {\n    \
                   pub fn b() {\n        fn inner() {}\n    }\n}\ntrait T { fn c(); }\nfn d(f: fn(u8)) {}\n";
        let tokens = tokenize(src);
        let found: Vec<(String, u32)> = functions(&tokens)
            .into_iter()
            .map(|f| (f.name, f.line))
            .collect();
        let expected = [("a", 3), ("b", 6), ("d", 11)].map(|(n, l)| (n.to_string(), l));
        assert_eq!(found, expected);
    }

    #[test]
    fn winnowing_selects_the_papers_fingerprints() {
        // The example of Schleimer, Wilkerson and Aiken (2003), Fig. 2: windows of 4.
        let hashes = [
            77, 74, 42, 17, 98, 50, 17, 98, 8, 88, 67, 39, 77, 74, 42, 17, 98,
        ];
        assert_eq!(winnow(&hashes, 4), [17, 17, 8, 39, 17]);
        assert_eq!(winnow(&[5, 3], 4), [3]);
        assert!(winnow(&[], 4).is_empty());
    }

    #[test]
    fn score_is_shared_over_the_smaller_set_and_small_sets_are_not_compared() {
        let a: Vec<u64> = (0..20).collect();
        let b: Vec<u64> = (5..40).collect();
        assert_eq!(score(&a, &b), Some((15, 0.75)));
        assert_eq!(score(&a[..15], &b), None);
    }

    #[test]
    fn text_fields_are_escaped_and_never_read_as_formulas() {
        assert_eq!(text_field("alice"), "alice");
        assert_eq!(
            text_field("=HYPERLINK(\"x\")"),
            "\"'=HYPERLINK(\"\"x\"\")\""
        );
        for lead in ["+1", "-1", "@SUM(A1)", "=1"] {
            assert_eq!(text_field(lead), format!("'{lead}"));
        }
        let row = format!("{},{}\n", text_field("a,\"b\"\nc"), text_field("=x"));
        assert_eq!(csv_records(&row), [["a,\"b\"\nc", "'=x"]]);
    }

    /// A batch folder under the system's temporary folder, removed when dropped.
    struct Batch(PathBuf);

    impl Batch {
        fn new(tag: &str) -> Batch {
            let dir = std::env::temp_dir()
                .join(format!("stereolab-similarity-{tag}-{}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Batch(dir)
        }

        /// `submission`'s stubs file of `ex`.
        fn submit(&self, submission: &str, ex: Exercise, text: &str) {
            let src = self.0.join(submission).join(ex.crate_name()).join("src");
            std::fs::create_dir_all(&src).unwrap();
            std::fs::write(src.join("stubs.rs"), text).unwrap();
        }

        fn report(&self, exercises: &[Exercise]) -> Report {
            let subs = super::super::batch::submissions(&self.0).unwrap();
            batch_report(&subs, exercises, &repository_exercises(), DEFAULT_THRESHOLD).unwrap()
        }
    }

    impl Drop for Batch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn handout(ex: Exercise) -> String {
        let path = repository_exercises()
            .join(ex.crate_name())
            .join("src")
            .join("stubs.rs");
        std::fs::read_to_string(path).unwrap()
    }

    /// The handout's header, with `link_row` replaced by `body` (a whole `pub fn link_row …`).
    fn ex3_file(body: &str) -> String {
        let stubs = handout(Exercise::Ex3);
        let start = stubs.find("pub fn link_row").unwrap();
        format!("{}{body}\n", &stubs[..start])
    }

    /// The reference's `link_row`, `hidden` and `link` with every name changed, comments
    /// added and the layout changed.
    const RENAMED_REFERENCE: &str = r#"
pub fn link_row(near: &[f32], r: u32, cfg: &SirdsSetup) -> Vec<usize> {
    // number of pixels
    let count = near.len();
    let range = cfg.depth_far - cfg.depth_near;
    let geo = SirdsGeometry { eye_distance: cfg.eye_distance, focal_length: cfg.focal_length };
    let mut links: Vec<usize> = (0..count).collect();
    for (px, &nz) in near.iter().enumerate() {
        let depth = cfg.depth_far - nz * range; /* depth behind the plane */
        let sep = (disparity_constant_eyes(depth, &geo) + 0.5).max(0.0) as usize;
        let (lo, hi) = if planted("x") { (px.checked_sub(sep), px + sep) } else {
            let lo = px.checked_sub((sep + (sep & r as usize & 1)) / 2);
            (lo, lo.map_or(0, |v| v + sep))
        };
        let Some(lo) = lo else { continue };
        if hi >= count { continue; }
        let slope = 2.0 * (depth + cfg.focal_length) / cfg.eye_distance / range;
        if !planted("y") && blocked(near, px, slope) { continue; }
        join(&mut links, lo, hi);
    }
    links
}

fn blocked(near: &[f32], px: usize, slope: f32) -> bool {
    let base = near[px];
    for step in 1.. {
        let level = base + step as f32 * slope;
        let over = |q: Option<usize>| q.and_then(|q| near.get(q)).is_some_and(|&w| w >= level);
        if over(px.checked_sub(step)) || over(Some(px + step)) { return true; }
        if level >= 1.0 { return false; }
    }
    false
}

fn join(links: &mut [usize], mut lo: usize, mut hi: usize) {
    let mut at = links[lo];
    while at != lo && at != hi {
        if at < hi { lo = at; } else { lo = hi; hi = at; }
        at = links[lo];
    }
    links[lo] = hi;
}
"#;

    /// `link_row` written independently of the reference: index loops, the hidden-surface test
    /// inline, the linking as a loop with a flag.
    const INDEPENDENT: &str = r#"
pub fn link_row(nearness: &[f32], row: u32, setup: &SirdsSetup) -> Vec<usize> {
    let width = nearness.len();
    let mut same = vec![0usize; width];
    for i in 0..width {
        same[i] = i;
    }
    let mut x = 0;
    while x < width {
        let z = nearness[x];
        let t = setup.depth_far - z * (setup.depth_far - setup.depth_near);
        let g = SirdsGeometry {
            eye_distance: setup.eye_distance,
            focal_length: setup.focal_length,
        };
        let d = disparity_constant_eyes(t, &g);
        let s = (d + 0.5).floor() as i64;
        let left = x as i64 - (s + (s & row as i64 & 1)) / 2;
        let right = left + s;
        if left >= 0 && right < width as i64 {
            let rise = 2.0 * (t + setup.focal_length) / setup.eye_distance
                / (setup.depth_far - setup.depth_near);
            let mut visible = true;
            let mut k = 1usize;
            loop {
                let zk = z + rise * k as f32;
                if (k <= x && nearness[x - k] >= zk) || (x + k < width && nearness[x + k] >= zk) {
                    visible = false;
                    break;
                }
                if zk >= 1.0 {
                    break;
                }
                k += 1;
            }
            if visible {
                let mut l = left as usize;
                let mut r = right as usize;
                loop {
                    let k = same[l];
                    if k == l || k == r {
                        break;
                    }
                    if k < r {
                        l = k;
                    } else {
                        l = r;
                        r = k;
                    }
                }
                same[l] = r;
            }
        }
        x += 1;
    }
    same
}
"#;

    fn flagged_between<'a>(report: &'a Report, a: &str, b: &str) -> Vec<&'a Pair> {
        report
            .pairs
            .iter()
            .filter(|p| p.flagged && p.a.submission == a && p.b.submission == b)
            .collect()
    }

    #[test]
    fn a_renamed_copy_of_the_reference_is_flagged() {
        let batch = Batch::new("renamed");
        batch.submit("copier", Exercise::Ex3, &ex3_file(RENAMED_REFERENCE));
        batch.submit("honest", Exercise::Ex3, &ex3_file(INDEPENDENT));
        let report = batch.report(&[Exercise::Ex3]);
        let flagged = flagged_between(&report, "copier", REFERENCE);
        let names: BTreeSet<(&str, &str)> = flagged
            .iter()
            .map(|p| (p.a.function.as_str(), p.b.function.as_str()))
            .collect();
        assert!(names.contains(&("link_row", "link_row")), "{report:#?}");
        assert!(names.contains(&("blocked", "hidden")), "{report:#?}");
        assert!(names.contains(&("join", "link")), "{report:#?}");
        assert!(flagged.iter().all(|p| p.similarity >= DEFAULT_THRESHOLD));
    }

    #[test]
    fn independent_implementations_of_one_function_are_not_flagged() {
        let batch = Batch::new("independent");
        batch.submit("honest", Exercise::Ex3, &ex3_file(INDEPENDENT));
        let report = batch.report(&[Exercise::Ex3]);
        assert!(report.pairs.iter().all(|p| !p.flagged), "{report:#?}");
        let closest = report.pairs.first().map_or(0.0, |p| p.similarity);
        assert!(closest < 0.5, "{report:#?}");
    }

    #[test]
    fn a_reordered_copy_of_a_classmate_with_renamed_locals_is_flagged() {
        let alice = ex3_file(INDEPENDENT);
        // Bob: link_row first, the disparities after it in the other order, locals renamed.
        let stubs = handout(Exercise::Ex3);
        let header = &stubs[..stubs.find("/// Task").unwrap()];
        let bob = format!(
            "{header}{}\n{}\n{}\n",
            INDEPENDENT
                .replace("width", "n")
                .replace("same", "chain")
                .replace("rise", "slope"),
            "pub fn disparity_constant_eyes(depth: f32, g: &SirdsGeometry) -> f32 {\n    \
             g.eye_distance * depth / (depth + g.focal_length)\n}",
            "pub fn disparity_constant_direction(depth: f32, angle: f32) -> f32 {\n    \
             2.0 * depth / angle.tan()\n}",
        );
        let batch = Batch::new("reordered");
        batch.submit("alice", Exercise::Ex3, &alice);
        batch.submit("bob", Exercise::Ex3, &bob);
        let report = batch.report(&[Exercise::Ex3]);
        let flagged = flagged_between(&report, "alice", "bob");
        assert_eq!(flagged.len(), 1, "{report:#?}");
        assert_eq!(flagged[0].a.function, "link_row");
        assert_eq!(flagged[0].similarity, 1.0);
        assert!(
            flagged[0].b.line < flagged[0].a.line,
            "bob's link_row comes first"
        );
    }

    #[test]
    fn untouched_stubs_match_nothing() {
        let batch = Batch::new("stubs");
        for name in ["alice", "bob", "carol"] {
            for ex in Exercise::ALL {
                batch.submit(name, ex, &handout(ex));
            }
        }
        let report = batch.report(&Exercise::ALL);
        assert!(report.pairs.is_empty(), "{report:#?}");
    }

    #[test]
    fn the_handouts_functions_keep_no_fingerprints_and_the_references_do() {
        for ex in Exercise::ALL {
            let src = repository_exercises().join(ex.crate_name()).join("src");
            let solution = std::fs::read_to_string(src.join("solution.rs")).unwrap();
            let base = base_hashes(&handout(ex));
            let reference = fingerprint_file(&solution, &base);
            let comparable = reference
                .iter()
                .filter(|f| f.fingerprints.len() >= MIN_FINGERPRINTS)
                .count();
            assert!(comparable >= 2, "{ex:?}: {reference:?}");
            for f in fingerprint_file(&handout(ex), &base) {
                assert!(f.fingerprints.is_empty(), "{ex:?} {}", f.name);
            }
        }
    }

    #[test]
    fn the_written_report_says_when_no_reference_is_there() {
        let repo = Batch::new("repo");
        let stubs_dir = repo.0.join(Exercise::Ex3.crate_name()).join("src");
        std::fs::create_dir_all(&stubs_dir).unwrap();
        std::fs::write(stubs_dir.join("stubs.rs"), handout(Exercise::Ex3)).unwrap();
        let batch = Batch::new("no-reference");
        batch.submit("=alice", Exercise::Ex3, &ex3_file(INDEPENDENT));
        batch.submit("bob", Exercise::Ex3, &ex3_file(INDEPENDENT));
        let subs = super::super::batch::submissions(&batch.0).unwrap();
        let report = batch_report(&subs, &[Exercise::Ex3], &repo.0, DEFAULT_THRESHOLD).unwrap();
        assert!(report.pairs.iter().all(|p| p.b.submission != REFERENCE));
        let out = Batch::new("no-reference-out");
        std::fs::write(out.0.join(FILE_NAME), report.csv()).unwrap();
        let summary = Summary::read(&out.0).unwrap();
        assert_eq!(summary.flagged, 1, "{}", report.csv());
        assert_eq!(summary.pairs, report.pairs.len());
        assert_eq!(summary.notes.len(), 1);
        assert!(
            summary.notes[0].contains("no reference solution"),
            "{:?}",
            summary.notes
        );
        let records = csv_records(&report.csv());
        assert_eq!(records[0].join(","), HEADER);
        assert!(
            records.iter().any(|r| r[1] == "'=alice"),
            "{}",
            report.csv()
        );
    }

    #[test]
    fn a_threshold_outside_zero_to_one_is_an_error() {
        for bad in [0.0, -0.5, 1.5, f64::NAN] {
            assert!(check_threshold(bad).is_err());
        }
        assert_eq!(check_threshold(1.0).unwrap(), 1.0);
    }

    #[test]
    fn the_same_batch_gives_the_same_bytes() {
        let batch = Batch::new("deterministic");
        batch.submit("a", Exercise::Ex3, &ex3_file(INDEPENDENT));
        batch.submit("b", Exercise::Ex3, &ex3_file(RENAMED_REFERENCE));
        batch.submit("c", Exercise::Ex3, &ex3_file(INDEPENDENT));
        let first = batch.report(&[Exercise::Ex3]).csv();
        assert_eq!(first, batch.report(&[Exercise::Ex3]).csv());
        assert!(first.lines().count() > 2, "{first}");
    }
}
