//! What `inspect` finds wrong with a pair, each with a name, a severity and a remedy.

/// How much a finding matters. An error is a mistake in the pair (swapped eyes, toe-in, a
/// misaligned camera, a disagreement with the scene's rig): `stereolab inspect` exits non-zero
/// on one. A warning is past a comfort guideline (the StereoGraphics guide's parallax budget, a
/// window violation); `--strict` makes warnings errors too.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// A mistake: the exit status says so.
    Error,
    /// Past a guideline.
    Warning,
}

/// One finding: its name (`toe-in`, `eyes swapped`, …), its severity, and what was measured
/// with the remedy.
#[derive(Clone, Debug, PartialEq)]
pub struct Finding {
    /// The mistake's name, as the report and the tests spell it.
    pub name: &'static str,
    /// Error or warning.
    pub severity: Severity,
    /// The measurement and the remedy.
    pub detail: String,
}

impl Finding {
    /// An error named `name`.
    pub fn error(name: &'static str, detail: impl Into<String>) -> Finding {
        Finding {
            name,
            severity: Severity::Error,
            detail: detail.into(),
        }
    }

    /// A warning named `name`.
    pub fn warning(name: &'static str, detail: impl Into<String>) -> Finding {
        Finding {
            name,
            severity: Severity::Warning,
            detail: detail.into(),
        }
    }

    /// The report's line: `  finding: NAME: DETAIL` (a warning says so after the name).
    pub fn line(&self) -> String {
        match self.severity {
            Severity::Error => format!("  finding: {}: {}\n", self.name, self.detail),
            Severity::Warning => format!("  finding: {} (warning): {}\n", self.name, self.detail),
        }
    }
}

/// The report's lines for `findings`.
pub fn lines(findings: &[Finding]) -> String {
    findings.iter().map(Finding::line).collect()
}

/// The report's last line: how many errors and warnings, by name, and whether the exit status
/// is a failure (`strict`: warnings count as errors). Returns the line and whether the pair
/// passed.
pub fn verdict(findings: &[Finding], strict: bool) -> (String, bool) {
    // Each name once (a window violation at both edges is one name).
    let names = |s: Severity| -> Vec<&str> {
        let mut v: Vec<&str> = Vec::new();
        for f in findings.iter().filter(|f| f.severity == s) {
            if !v.contains(&f.name) {
                v.push(f.name);
            }
        }
        v
    };
    let (errors, warnings) = (names(Severity::Error), names(Severity::Warning));
    let passed = errors.is_empty() && (!strict || warnings.is_empty());
    let list = |v: &[&str]| {
        if v.is_empty() {
            String::new()
        } else {
            format!(" ({})", v.join(", "))
        }
    };
    let count = |s: Severity| findings.iter().filter(|f| f.severity == s).count();
    let (e, w) = (count(Severity::Error), count(Severity::Warning));
    let line = format!(
        "  result: {e} error{}{}, {w} warning{}{}{}\n",
        if e == 1 { "" } else { "s" },
        list(&errors),
        if w == 1 { "" } else { "s" },
        list(&warnings),
        if passed {
            ""
        } else if strict && errors.is_empty() {
            ": fails (--strict)"
        } else {
            ": fails"
        }
    );
    (line, passed)
}
