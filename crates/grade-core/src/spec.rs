//! What a task is to the grader: inputs, expected answers, tolerance, known mistakes, images.

use std::path::Path;

use serde_json::Value;

/// A numeric tolerance: an answer element `a` matches `e` when `|a − e| ≤ abs + rel · |e|`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Absolute part.
    pub abs: f64,
    /// Relative part.
    pub rel: f64,
    /// Where the numbers come from (printed with every failure).
    pub why: &'static str,
}

impl Tolerance {
    /// Exact equality (integers, booleans, indices).
    pub const EXACT: Tolerance = Tolerance {
        abs: 0.0,
        rel: 0.0,
        why: "exact: integers and booleans",
    };

    /// Whether `actual` matches `expected` element by element (same length, all finite where
    /// expected is finite).
    pub fn accepts(&self, expected: &[f64], actual: &[f64]) -> bool {
        expected.len() == actual.len()
            && expected
                .iter()
                .zip(actual)
                .all(|(e, a)| (a - e).abs() <= self.abs + self.rel * e.abs())
    }

    /// Human-readable: `1e-4·|expected| + 1e-6`.
    pub fn describe(&self) -> String {
        match (self.abs, self.rel) {
            (0.0, 0.0) => "exact".to_string(),
            (a, 0.0) => format!("{a:e}"),
            (0.0, r) => format!("{r:e}·|expected|"),
            (a, r) => format!("{r:e}·|expected| + {a:e}"),
        }
    }
}

/// One numeric check: an input and the reference's answer to it.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Names the input for the student (`eye 0, per-eye lighting`).
    pub label: String,
    /// The input as the exercise binary reads it.
    pub input: Value,
    /// The reference's answer, flattened (empty: `None`).
    pub expected: Vec<f64>,
}

/// A known wrong formula: what it answers for each case. When a student's failing answers all
/// match it, the grader names it.
#[derive(Clone, Debug, PartialEq)]
pub struct Mistake {
    /// Short stable name, printed in brackets (`[swapped-eyes]`).
    pub id: &'static str,
    /// What to check, in words a student can act on.
    pub hint: &'static str,
    /// The mistaken answer per case (same order as the task's cases).
    pub answers: Vec<Vec<f64>>,
}

/// Judges an image check: given the exercise's id, the student's answers to
/// [`ImageCheck::inputs`] (`None` where the code panicked or gave no answer), and the folder for
/// pictures, says whether the pictures match, adding lines to the details.
pub type Judge = Box<dyn Fn(&str, &[Option<Vec<f64>>], &Path, &mut Vec<String>) -> bool>;

/// Shows an image check's pictures (`render --exercise`): every picture written to the folder,
/// one line each.
pub type Show = Box<dyn Fn(&[Option<Vec<f64>>], &Path) -> Vec<String>>;

/// An image check: the student's functions plugged into the real pipeline vs the reference
/// (the instructor's grader), or, where no renderer is at hand (a handout's grader), the
/// answers its pictures are drawn from against the reference's.
pub struct ImageCheck {
    /// Inputs whose answers the pictures are built from.
    pub inputs: Vec<Value>,
    /// The judge.
    pub judge: Judge,
    /// Every picture, for `render --exercise` (`None` where no renderer is at hand).
    pub show: Option<Show>,
    /// Writes the reference pictures to the folder and returns their file names (for a
    /// handout's data; `None` where no renderer is at hand).
    pub reference: Option<Show>,
}

/// A task: one stub, scored on its own.
pub struct TaskSpec {
    /// The stub's name and the task name in the protocol.
    pub name: &'static str,
    /// Points for a complete answer.
    pub points: f64,
    /// Bonus points count towards the score but not towards the total to reach.
    pub bonus: bool,
    /// For the numeric checks.
    pub tolerance: Tolerance,
    /// The numeric checks.
    pub cases: Vec<Case>,
    /// Known mistakes, most specific first.
    pub mistakes: Vec<Mistake>,
    /// Optional image check.
    pub image: Option<ImageCheck>,
    /// Tasks of the same exercise whose functions this one calls (the solution's and the
    /// stubs' call graph): when one of them fails, this task's hint says to fix that one first.
    pub depends_on: &'static [&'static str],
    /// Hidden cases: generated from the instructor's seed ([`grader_seed`]), never shipped,
    /// scored apart (see [`HIDDEN_SHARE`]). Empty when no seed is set.
    pub hidden: Vec<Case>,
}

/// Share of a task's points the image check carries when the task has one.
pub const IMAGE_SHARE: f64 = 0.3;

/// Share of a task's points its hidden cases carry when it has some; the public cases and the
/// image check share the rest as before (so without a seed a task scores exactly as it did).
pub const HIDDEN_SHARE: f64 = 0.3;

/// The environment variable holding the instructor's seed for the hidden cases (a u64).
pub const SEED_VAR: &str = "STEREOLAB_GRADER_SEED";

/// The instructor's seed from [`SEED_VAR`]; `None` (no hidden cases) when unset or not a u64,
/// so students' local runs and the repository's tests see exactly the public cases.
pub fn grader_seed() -> Option<u64> {
    std::env::var(SEED_VAR).ok()?.trim().parse().ok()
}

/// A small deterministic generator for hidden cases: splitmix64 (Steele, Lea and Flood,
/// "Fast splittable pseudorandom number generators", 2014; the seeding generator of
/// xoshiro). The same seed and task name give the same cases on every machine.
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator for `task`'s hidden cases under `seed` (the name is hashed in with FNV-1a so
    /// that tasks draw different numbers).
    pub fn for_task(seed: u64, task: &str) -> SplitMix64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in task.bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        SplitMix64(seed ^ h)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[lo, hi)`, rounded to 3 decimals so that a case prints readably.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let x = f64::from(lo) + u * f64::from(hi - lo);
        ((x * 1000.0).round() / 1000.0).clamp(f64::from(lo), f64::from(hi)) as f32
    }
}

/// `count` hidden cases for `task` from `make` (given the generator and the case number), or
/// none when no seed is set.
pub fn hidden_cases(
    task: &str,
    count: usize,
    mut make: impl FnMut(&mut SplitMix64, usize) -> Case,
) -> Vec<Case> {
    let Some(seed) = grader_seed() else {
        return Vec::new();
    };
    let mut rng = SplitMix64::for_task(seed, task);
    (0..count).map(|i| make(&mut rng, i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerance_is_absolute_plus_relative_and_refuses_nan_and_length_mismatch() {
        let t = Tolerance {
            abs: 1e-3,
            rel: 1e-2,
            why: "test",
        };
        assert!(t.accepts(&[100.0], &[100.9]));
        assert!(!t.accepts(&[100.0], &[101.1]));
        assert!(!t.accepts(&[1.0], &[f64::NAN]));
        assert!(!t.accepts(&[1.0, 2.0], &[1.0]));
        assert!(Tolerance::EXACT.accepts(&[3.0], &[3.0]));
        assert_eq!(t.describe(), "1e-2·|expected| + 1e-3");
    }

    #[test]
    fn splitmix64_matches_its_published_sequence_and_task_streams_differ() {
        // The reference implementation's first outputs for state 0.
        let mut r = SplitMix64(0);
        assert_eq!(r.next_u64(), 0xe220_a839_7b1d_cdaf);
        assert_eq!(r.next_u64(), 0x6e78_9e6a_a1b9_65f4);
        let a = SplitMix64::for_task(7, "frustum").next_u64();
        let b = SplitMix64::for_task(7, "remap").next_u64();
        assert_ne!(a, b);
        assert_eq!(a, SplitMix64::for_task(7, "frustum").next_u64());
        let mut r = SplitMix64::for_task(1, "x");
        for _ in 0..1000 {
            let x = r.range(-2.0, 3.0);
            assert!((-2.0..=3.0).contains(&x), "{x}");
        }
    }
}
