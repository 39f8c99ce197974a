//! The image checks of the instructor's grader: the student's answers plugged into the real
//! pipeline, the pictures compared with the reference's (coverage and color), and a failing
//! one written as an `expected | diff | actual` strip with an ASCII map of its coverage.

use std::fmt::Write as _;
use std::path::Path;
use std::rc::Rc;

use serde_json::Value;
use stereolab::compare::{ascii_map, compare, coverage, write_diff_strip};
use stereolab_core::Framebuffer;
use stereolab_grade_core::spec::ImageCheck;

/// One image compared: the reference's and the one built from the student's answers.
#[derive(Clone, Debug)]
pub struct Picture {
    /// File-name-friendly name (`stereo_matrices_left_per_eye`).
    pub name: String,
    /// Reference.
    pub expected: Framebuffer,
    /// From the student's answers.
    pub actual: Framebuffer,
}

/// Builds the student's pictures from the answers to an image check's inputs (`None` where the
/// student's code panicked or gave no answer).
pub type PictureBuilder = Box<dyn Fn(&[Option<Vec<f64>>]) -> Vec<Picture>>;

/// Largest share of pixels whose coverage may differ, in percent. A matrix inside the numeric
/// tolerance (1e-4 relative) moves an edge by well under 0.01 pixel at these sizes, which flips
/// only pixels whose centers lie that close to an edge: a handful, far below 1%.
pub const IMAGE_MAX_COVERAGE_PERCENT: f64 = 1.0;
/// Largest mean RGB difference (0..255). Answers inside the numeric tolerances change an 8-bit
/// channel by at most one step on a few pixels; a real mistake changes whole regions.
pub const IMAGE_MAX_MEAN_DIFF: f64 = 1.0;
/// ASCII maps are printed for rasters up to this width.
const ASCII_MAX_WIDTH: u32 = 64;

/// The image check whose pictures `build` draws from the answers to `inputs`.
pub(crate) fn check(inputs: Vec<Value>, build: PictureBuilder) -> ImageCheck {
    let build = Rc::new(build);
    let shown = Rc::clone(&build);
    let reference = Rc::clone(&build);
    ImageCheck {
        inputs,
        judge: Box::new(move |exercise, answers, out_dir, details| {
            check_pictures(exercise, &build(answers), out_dir, details)
        }),
        show: Some(Box::new(move |answers, out| show(&shown(answers), out))),
        reference: Some(Box::new(move |answers, out| {
            write_references(&reference(answers), out)
        })),
    }
}

/// How much a reference picture is enlarged (nearest pixel) to be looked at: the grader's
/// pictures are a few dozen pixels wide.
const REFERENCE_SCALE: u32 = 4;

/// Writes each picture's reference as `<name>.png` in `out`, enlarged; the file names (an
/// entry starting with `error:` for one that could not be written).
fn write_references(pictures: &[Picture], out: &Path) -> Vec<String> {
    pictures
        .iter()
        .map(|p| {
            let img = p.expected.to_rgba_image();
            let big = image::imageops::resize(
                &img,
                img.width() * REFERENCE_SCALE,
                img.height() * REFERENCE_SCALE,
                image::imageops::FilterType::Nearest,
            );
            let name = format!("{}.png", p.name);
            match std::fs::create_dir_all(out)
                .map_err(|e| stereolab_core::Error::io(out, e))
                .and_then(|()| stereolab_core::write_png(&out.join(&name), &big))
            {
                Ok(()) => name,
                Err(e) => format!("error: {e}"),
            }
        })
        .collect()
}

/// Every picture written to `out` as `reference | diff | yours`, one line each.
fn show(pictures: &[Picture], out: &Path) -> Vec<String> {
    pictures
        .iter()
        .map(|p| {
            let shown = compare(&p.expected, &p.actual).and_then(|m| {
                write_diff_strip(&p.expected, &p.actual, out, &p.name).map(|path| (m, path))
            });
            match shown {
                Ok((m, path)) => format!(
                    "{:<34} coverage mismatch {:>6.2}%, mean channel difference {:>6.2}: {} \
                     (reference | diff | yours)",
                    p.name,
                    m.coverage_mismatch_percent(),
                    m.mean_channel_diff,
                    path.display()
                ),
                Err(e) => format!("{}: {e}", p.name),
            }
        })
        .collect()
}

/// Compares each picture; writes strips and ASCII maps for the failing ones.
fn check_pictures(
    exercise: &str,
    pictures: &[Picture],
    out_dir: &Path,
    details: &mut Vec<String>,
) -> bool {
    let mut all = true;
    let mut mapped = false;
    for p in pictures {
        let m = match compare(&p.expected, &p.actual) {
            Ok(m) => m,
            Err(e) => {
                details.push(format!("image {}: {e}", p.name));
                all = false;
                continue;
            }
        };
        let ok = m.coverage_mismatch_percent() <= IMAGE_MAX_COVERAGE_PERCENT
            && m.mean_channel_diff <= IMAGE_MAX_MEAN_DIFF;
        if ok {
            continue;
        }
        all = false;
        let mut line = format!(
            "image {}: coverage mismatch {:.2}% (tolerance {IMAGE_MAX_COVERAGE_PERCENT}%), mean channel difference {:.2} (tolerance {IMAGE_MAX_MEAN_DIFF}), max {}",
            p.name,
            m.coverage_mismatch_percent(),
            m.mean_channel_diff,
            m.max_channel_diff
        );
        match write_diff_strip(
            &p.expected,
            &p.actual,
            out_dir,
            &format!("{exercise}_{}", p.name),
        ) {
            Ok(path) => {
                let _ = write!(line, "; expected | diff | actual: {}", path.display());
            }
            Err(e) => {
                let _ = write!(line, "; diff image not written: {e}");
            }
        }
        // One map per task (the first failing picture): the others are in their strips.
        if p.expected.width() <= ASCII_MAX_WIDTH && m.coverage_mismatch > 0 && !mapped {
            mapped = true;
            let _ = write!(
                line,
                "\n  coverage (# both, ! extra, ? missed):\n{}",
                ascii_map(
                    &coverage(&p.expected),
                    &coverage(&p.actual),
                    p.expected.width() as usize,
                    ASCII_MAX_WIDTH as usize
                )
                .lines()
                .map(|l| format!("    {l}"))
                .collect::<Vec<_>>()
                .join("\n")
            );
        }
        details.push(line);
    }
    all
}
