//! The wire protocol between the grader and an exercise crate's binary.
//!
//! The grader runs `<exercise binary> <task>` and writes a JSON array of inputs on stdin. The
//! binary answers on its own channel, never on stdout (a student's `println!` while debugging
//! must not be read as an answer): the file descriptor named by the environment variable
//! [`ANSWER_FD_ENV`], which the grader opens as a pipe (without it, as when you run the binary
//! yourself, the answers go to stdout). One JSON line per input, in order, flushed as it goes:
//! `{"ok": [numbers]}` with the answer flattened to numbers (see [`Answer`]; non-finite numbers
//! are the strings `"NaN"`, `"inf"`, `"-inf"` because JSON has no such numbers), or
//! `{"panic": "message"}`. A panic costs only that input; the grader kills a binary that runs
//! past its time limit and scores the inputs it answered so far.

use std::io::{Read, Write};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::process::ExitCode;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use serde::de::DeserializeOwned;
use serde_json::Value;

/// An answer the grader can compare: flattened to numbers in a documented order.
pub trait Answer {
    /// Appends this answer's numbers to `out`.
    fn flatten(&self, out: &mut Vec<f64>);
}

impl Answer for f32 {
    fn flatten(&self, out: &mut Vec<f64>) {
        out.push(f64::from(*self));
    }
}

impl Answer for f64 {
    fn flatten(&self, out: &mut Vec<f64>) {
        out.push(*self);
    }
}

impl Answer for bool {
    fn flatten(&self, out: &mut Vec<f64>) {
        out.push(if *self { 1.0 } else { 0.0 });
    }
}

impl Answer for usize {
    fn flatten(&self, out: &mut Vec<f64>) {
        out.push(*self as f64);
    }
}

impl<T: Answer, const N: usize> Answer for [T; N] {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.iter().for_each(|x| x.flatten(out));
    }
}

impl<T: Answer> Answer for Vec<T> {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.iter().for_each(|x| x.flatten(out));
    }
}

/// `None` flattens to nothing: the grader sees an empty answer.
impl<T: Answer> Answer for Option<T> {
    fn flatten(&self, out: &mut Vec<f64>) {
        if let Some(x) = self {
            x.flatten(out);
        }
    }
}

impl<A: Answer, B: Answer> Answer for (A, B) {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.0.flatten(out);
        self.1.flatten(out);
    }
}

impl Answer for Vec2 {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.to_array().flatten(out);
    }
}

impl Answer for Vec3 {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.to_array().flatten(out);
    }
}

impl Answer for Vec4 {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.to_array().flatten(out);
    }
}

/// Column-major, as glam stores it: element (row i, column j) is at `4 j + i`.
impl Answer for Mat4 {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.to_cols_array().flatten(out);
    }
}

/// Column-major: element (row i, column j) is at `3 j + i`.
impl Answer for Mat3 {
    fn flatten(&self, out: &mut Vec<f64>) {
        self.to_cols_array().flatten(out);
    }
}

/// The flattened answer, or the panic message.
pub type Reply = Result<Vec<f64>, String>;

/// One task an exercise binary can evaluate.
pub struct Task {
    name: &'static str,
    run: Box<dyn Fn(&Value) -> Reply>,
}

/// A task named `name` evaluating `f` on inputs of type `I` (deserialized from the grader's JSON).
pub fn task<I, O, F>(name: &'static str, f: F) -> Task
where
    I: DeserializeOwned,
    O: Answer,
    F: Fn(I) -> O + 'static,
{
    Task {
        name,
        run: Box::new(move |v| {
            let input: I = serde_json::from_value(v.clone())
                .map_err(|e| format!("the grader sent an input this task cannot read: {e}"))?;
            let answer = catch_unwind(AssertUnwindSafe(|| f(input))).map_err(panic_message)?;
            let mut out = Vec::new();
            answer.flatten(&mut out);
            Ok(out)
        }),
    }
}

fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "panicked".to_string()
    }
}

/// Encodes one reply line.
pub fn encode_reply(reply: &Result<Vec<f64>, String>) -> String {
    let v = match reply {
        Ok(nums) => {
            let arr = nums
                .iter()
                .map(|x| match serde_json::Number::from_f64(*x) {
                    Some(n) => Value::Number(n),
                    None if x.is_nan() => Value::String("NaN".into()),
                    None if *x > 0.0 => Value::String("inf".into()),
                    None => Value::String("-inf".into()),
                })
                .collect();
            serde_json::json!({ "ok": Value::Array(arr) })
        }
        Err(msg) => serde_json::json!({ "panic": msg }),
    };
    v.to_string()
}

/// Decodes one reply line; `Err` carries the panic message (or why the line is unreadable).
pub fn decode_reply(line: &str) -> Result<Vec<f64>, String> {
    let v: Value = serde_json::from_str(line).map_err(|e| format!("unreadable reply: {e}"))?;
    if let Some(msg) = v.get("panic") {
        return Err(msg.as_str().unwrap_or("panicked").to_string());
    }
    let arr = v
        .get("ok")
        .and_then(Value::as_array)
        .ok_or_else(|| format!("unreadable reply: {line}"))?;
    arr.iter()
        .map(|x| match x {
            Value::Number(n) => n.as_f64().ok_or_else(|| format!("bad number {n}")),
            Value::String(s) if s == "NaN" => Ok(f64::NAN),
            Value::String(s) if s == "inf" => Ok(f64::INFINITY),
            Value::String(s) if s == "-inf" => Ok(f64::NEG_INFINITY),
            other => Err(format!("bad value {other}")),
        })
        .collect()
}

/// Names the file descriptor the answers go to (set by the grader).
pub const ANSWER_FD_ENV: &str = "STEREOLAB_ANSWER_FD";

/// Where the answers go: the grader's channel when it named one, else stdout.
fn answer_channel() -> Box<dyn Write> {
    #[cfg(unix)]
    if let Some(fd) = std::env::var(ANSWER_FD_ENV)
        .ok()
        .and_then(|v| v.parse::<i32>().ok())
        .filter(|fd| *fd > 2)
    {
        use std::os::fd::FromRawFd;
        // SAFETY: the grader opened this descriptor for us and nothing else in this process
        // uses it; if it is not open, the first write fails and `serve` exits with code 3.
        return Box::new(unsafe { std::fs::File::from_raw_fd(fd) });
    }
    Box::new(std::io::stdout())
}

/// The `main` of an exercise binary: `BINARY TASK < inputs.json`, `BINARY --list` or
/// `BINARY --source-hash` (the hash of the sources the grader built it from, so it can prove
/// it runs the submission's code and not a stale build). Panics inside the student's code are
/// caught per input and reported, never printed.
pub fn serve(source_hash: &str, tasks: Vec<Task>) -> ExitCode {
    let args: Vec<String> = std::env::args().collect();
    let Some(name) = args.get(1) else {
        eprintln!("usage: {} TASK < inputs.json  (or --list)", args[0]);
        return ExitCode::from(2);
    };
    if name == "--list" {
        for t in &tasks {
            println!("{}", t.name);
        }
        return ExitCode::SUCCESS;
    }
    if name == "--source-hash" {
        let mut out = answer_channel();
        return match writeln!(out, "{source_hash}").and_then(|()| out.flush()) {
            Ok(()) => ExitCode::SUCCESS,
            Err(_) => ExitCode::from(3),
        };
    }
    let Some(task) = tasks.iter().find(|t| t.name == name) else {
        eprintln!("unknown task {name}");
        return ExitCode::from(2);
    };
    let mut text = String::new();
    if let Err(e) = std::io::stdin().read_to_string(&mut text) {
        eprintln!("cannot read the inputs: {e}");
        return ExitCode::from(2);
    }
    let inputs: Vec<Value> = match serde_json::from_str(&text) {
        Ok(v) => v,
        Err(e) => {
            eprintln!("the inputs are not a JSON array: {e}");
            return ExitCode::from(2);
        }
    };
    // The grader reports panics itself; the default hook would only clutter stderr.
    std::panic::set_hook(Box::new(|_| {}));
    let mut out = answer_channel();
    for input in &inputs {
        let line = encode_reply(&(task.run)(input));
        if writeln!(out, "{line}").and_then(|()| out.flush()).is_err() {
            return ExitCode::from(3); // the grader went away
        }
    }
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_numbers_survive_the_round_trip() {
        let r = Ok(vec![1.5, f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
        let back = decode_reply(&encode_reply(&r)).unwrap();
        assert_eq!(back[0], 1.5);
        assert!(back[1].is_nan());
        assert_eq!(back[2], f64::INFINITY);
        assert_eq!(back[3], f64::NEG_INFINITY);
    }

    #[test]
    fn a_panic_is_caught_and_reported_with_its_message() {
        let t = task("t", |x: f32| -> f32 { todo!("compute with {x:?}") });
        let r = (t.run)(&serde_json::json!(2.0));
        let msg = decode_reply(&encode_reply(&r)).unwrap_err();
        assert!(msg.contains("compute with 2.0"), "{msg}");
    }

    #[test]
    fn matrices_flatten_column_major() {
        let m = Mat4::from_cols_array(&std::array::from_fn(|i| i as f32));
        let mut v = Vec::new();
        m.flatten(&mut v);
        assert_eq!(v[1], 1.0); // row 1, column 0
        assert_eq!(v[4], 4.0); // row 0, column 1
    }
}
