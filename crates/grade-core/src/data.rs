//! Task specs as data: what a student's handout carries instead of the reference code. The
//! instructor's stereolab writes, for each exercise, the public cases with their expected
//! answers, the known mistakes' answers and hints, the points and tolerances, and for an image
//! check the reference's answers to its inputs with the reference pictures (`export`); the
//! handout's grader reads them back ([`tasks_from_data`]) and scores exactly as the instructor's
//! grader does, except that it cannot draw a student's picture: its image check compares the
//! answers the picture would be drawn from with the reference's (see [`answers_judge`]).
//!
//! Hidden cases are never written: they come from the instructor's seed, at grading time only.

use std::path::Path;

use serde_json::{Value, json};

use crate::spec::{Case, ImageCheck, Mistake, TaskSpec, Tolerance};
use crate::{Error, Exercise, Result};

/// The data format's version (`"format"`): a grader refuses any other.
pub const FORMAT: u64 = 1;

/// The data of one task: `image_expected` is the reference's answer to each image input,
/// `pictures` the reference pictures' file names (beside the data file).
pub fn task_to_data(
    spec: &TaskSpec,
    image_expected: Option<&[Option<Vec<f64>>]>,
    pictures: &[String],
) -> Value {
    let image = spec.image.as_ref().map(|img| {
        json!({
            "inputs": img.inputs,
            "expected": image_expected.map_or_else(Vec::new, <[_]>::to_vec),
            "pictures": pictures,
        })
    });
    json!({
        "name": spec.name,
        "points": spec.points,
        "bonus": spec.bonus,
        "tolerance": {
            "abs": spec.tolerance.abs,
            "rel": spec.tolerance.rel,
            "why": spec.tolerance.why,
        },
        "cases": spec.cases.iter().map(|c| json!({
            "label": c.label,
            "input": c.input,
            "expected": c.expected,
        })).collect::<Vec<_>>(),
        "mistakes": spec.mistakes.iter().map(|m| json!({
            "id": m.id,
            "hint": m.hint,
            "answers": m.answers,
        })).collect::<Vec<_>>(),
        "depends_on": spec.depends_on,
        "image": image,
    })
}

/// One exercise's data file: its tasks' data under a format version.
pub fn exercise_data(ex: Exercise, tasks: Vec<Value>) -> Value {
    json!({ "format": FORMAT, "exercise": ex.id(), "tasks": tasks })
}

/// Text read from the data, kept for the life of the process (the specs borrow their names,
/// hints and tolerance notes as `&'static str`; a grading run reads each file once).
fn keep(s: &str) -> &'static str {
    Box::leak(s.to_owned().into_boxed_str())
}

fn bad(path: &Path, what: impl std::fmt::Display) -> Error {
    Error::parse(
        path,
        None,
        format!("{what}: the handout's grading data is damaged; export it again"),
    )
}

fn numbers(v: &Value) -> Option<Vec<f64>> {
    v.as_array()?.iter().map(Value::as_f64).collect()
}

/// The task specs of the data file `path` (see the module documentation).
///
/// # Errors
/// An unreadable file, another format version, a field missing or of the wrong type.
pub fn tasks_from_data(path: &Path, ex: Exercise) -> Result<Vec<TaskSpec>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let v: Value = serde_json::from_str(&text).map_err(|e| bad(path, e))?;
    if v["format"].as_u64() != Some(FORMAT) || v["exercise"].as_str() != Some(ex.id()) {
        return Err(bad(
            path,
            format!("expected format {FORMAT} for {}", ex.id()),
        ));
    }
    v["tasks"]
        .as_array()
        .ok_or_else(|| bad(path, "no tasks"))?
        .iter()
        .map(|t| task_from_data(t).ok_or_else(|| bad(path, format!("task {}", t["name"]))))
        .collect()
}

fn task_from_data(t: &Value) -> Option<TaskSpec> {
    let tolerance = Tolerance {
        abs: t["tolerance"]["abs"].as_f64()?,
        rel: t["tolerance"]["rel"].as_f64()?,
        why: keep(t["tolerance"]["why"].as_str()?),
    };
    let cases = t["cases"]
        .as_array()?
        .iter()
        .map(|c| {
            Some(Case {
                label: c["label"].as_str()?.to_string(),
                input: c["input"].clone(),
                expected: numbers(&c["expected"])?,
            })
        })
        .collect::<Option<Vec<_>>>()?;
    let mistakes = t["mistakes"]
        .as_array()?
        .iter()
        .map(|m| {
            Some(Mistake {
                id: keep(m["id"].as_str()?),
                hint: keep(m["hint"].as_str()?),
                answers: m["answers"]
                    .as_array()?
                    .iter()
                    .map(numbers)
                    .collect::<Option<_>>()?,
            })
        })
        .collect::<Option<Vec<_>>>()?;
    let depends_on: Vec<&'static str> = t["depends_on"]
        .as_array()?
        .iter()
        .map(|d| d.as_str().map(keep))
        .collect::<Option<_>>()?;
    let image = match &t["image"] {
        Value::Null => None,
        img => {
            let inputs = img["inputs"].as_array()?.clone();
            let expected: Vec<Option<Vec<f64>>> = img["expected"]
                .as_array()?
                .iter()
                .map(|e| {
                    if e.is_null() {
                        Some(None)
                    } else {
                        numbers(e).map(Some)
                    }
                })
                .collect::<Option<_>>()?;
            let pictures: Vec<String> = img["pictures"]
                .as_array()?
                .iter()
                .map(|p| p.as_str().map(str::to_string))
                .collect::<Option<_>>()?;
            if expected.len() != inputs.len() {
                return None;
            }
            Some(ImageCheck {
                inputs,
                judge: answers_judge(expected, tolerance, pictures),
                show: None,
                reference: None,
            })
        }
    };
    Some(TaskSpec {
        name: keep(t["name"].as_str()?),
        points: t["points"].as_f64()?,
        bonus: t["bonus"].as_bool()?,
        tolerance,
        cases,
        mistakes,
        image,
        depends_on: Box::leak(depends_on.into_boxed_slice()),
        hidden: Vec::new(),
    })
}

/// The image check of a grader without a renderer: it passes when every answer its pictures are
/// drawn from matches the reference's within the task's tolerance (answers inside the tolerance
/// draw the reference's picture within the image check's own limits), and names the reference
/// pictures to look at (`pictures`: their paths in the handout's data folder). The instructor's
/// grader draws the student's picture and compares it
/// instead, so an answer off in a way no pixel shows passes there and fails here.
pub fn answers_judge(
    expected: Vec<Option<Vec<f64>>>,
    tolerance: Tolerance,
    pictures: Vec<String>,
) -> crate::spec::Judge {
    Box::new(move |_exercise, answers, _out, details| {
        let off = expected
            .iter()
            .zip(answers)
            .filter(|(e, a)| match (e, a) {
                (Some(e), Some(a)) => !tolerance.accepts(e, a),
                (Some(_), None) => true,
                (None, _) => false,
            })
            .count();
        if off == 0 {
            return true;
        }
        let names: Vec<String> = pictures
            .iter()
            .map(|p| format!("stereolab/data/{p}"))
            .collect();
        details.push(format!(
            "image check: {off} of the {} answers its pictures are drawn from differ from the \
             reference's (this grader has no renderer to draw yours; the official grade does); \
             the reference pictures: {}",
            expected.len(),
            names.join(", ")
        ));
        false
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> TaskSpec {
        TaskSpec {
            name: "texgen",
            points: 2.0,
            bonus: false,
            tolerance: Tolerance {
                abs: 1e-6,
                rel: 1e-4,
                why: "f32 arithmetic",
            },
            cases: vec![Case {
                label: "near 1, far 3".into(),
                input: json!([1.0, 3.0]),
                expected: vec![0.0, 0.0, -0.5, -0.5],
            }],
            mistakes: vec![Mistake {
                id: "texgen-sign",
                hint: "the sign",
                answers: vec![vec![0.0, 0.0, 0.5, -0.5]],
            }],
            image: Some(ImageCheck {
                inputs: vec![json!([1.0, 3.0]), json!([2.0, 5.0])],
                judge: Box::new(|_, _, _, _| true),
                show: None,
                reference: None,
            }),
            depends_on: &["depth_range"],
            hidden: vec![Case {
                label: "hidden".into(),
                input: json!([7.0, 9.0]),
                expected: vec![1.0],
            }],
        }
    }

    #[test]
    fn a_task_comes_back_from_its_data_without_its_hidden_cases() {
        let s = spec();
        let expected = vec![Some(vec![1.0, 2.0]), None];
        let data = exercise_data(
            Exercise::Ex2,
            vec![task_to_data(
                &s,
                Some(&expected),
                &["pictures/ex2/t.png".into()],
            )],
        );
        let text = data.to_string();
        assert!(!text.contains("hidden") && !text.contains("7.0"), "{text}");
        let dir = std::env::temp_dir().join(format!("stereolab-data-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ex2.json");
        std::fs::write(&path, &text).unwrap();
        let back = tasks_from_data(&path, Exercise::Ex2).unwrap();
        assert_eq!(back.len(), 1);
        let b = &back[0];
        assert_eq!((b.name, b.points, b.bonus), ("texgen", 2.0, false));
        assert_eq!(b.tolerance, s.tolerance);
        assert_eq!(b.cases, s.cases);
        assert_eq!(b.mistakes, s.mistakes);
        assert_eq!(b.depends_on, s.depends_on);
        assert!(b.hidden.is_empty());
        let img = b.image.as_ref().unwrap();
        assert_eq!(img.inputs, s.image.as_ref().unwrap().inputs);
        let mut details = Vec::new();
        let right = [Some(vec![1.0, 2.0]), None];
        assert!((img.judge)("ex2", &right, &dir, &mut details));
        let wrong = [Some(vec![1.0, 2.1]), Some(vec![0.0])];
        assert!(!(img.judge)("ex2", &wrong, &dir, &mut details));
        assert!(
            details[0].contains("1 of the 2 answers")
                && details[0].contains("stereolab/data/pictures/ex2/t.png")
        );
        // Another exercise's file, or another format, is refused with a message.
        assert!(tasks_from_data(&path, Exercise::Ex1).is_err());
        std::fs::write(&path, text.replace("\"format\":1", "\"format\":2")).unwrap();
        let Err(err) = tasks_from_data(&path, Exercise::Ex2) else {
            panic!("another format is refused");
        };
        let err = err.to_string();
        assert!(err.contains("export it again"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
