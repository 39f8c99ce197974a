//! What accuracy costs in time: the rows of `stereolab bench --csv` (committed as
//! `slides/data/bench.csv`, with the machine they were measured on in `slides/README.md`)
//! plotted as error against median time, one panel per accuracy knob.

use super::Context;
use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, SMALL};
use stereolab_core::{Error, Result, TextAlign};

/// One row of `stereolab bench --csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    /// Area (`raster`, `finalize`, `sirds`, …).
    pub area: String,
    /// The knob.
    pub knob: String,
    /// Its setting.
    pub setting: String,
    /// Error against the most accurate setting; `None` for pure timings.
    pub error: Option<f64>,
    /// What the error measures.
    pub error_unit: String,
    /// Median time, ms.
    pub ms: f64,
}

/// Splits one CSV line (fields optionally in double quotes, `""` an escaped quote).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars().peekable());
    while let Some(ch) = chars.next() {
        match (ch, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(ch),
        }
    }
    out.push(cur);
    out
}

/// Parses the text of `stereolab bench --csv` (`area,knob,setting,error,error_unit,ms,note`).
///
/// # Errors
/// `Parse` naming the line of a row with too few fields or a number that is not one.
pub fn parse_csv(text: &str, file: &std::path::Path) -> Result<Vec<BenchRow>> {
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let f = fields(line);
        let bad = |what: &str| Error::parse(file, Some(i + 1), format!("{what}: {line}"));
        if f.len() < 6 {
            return Err(bad("expected area,knob,setting,error,error_unit,ms,note"));
        }
        let error = if f[3].is_empty() {
            None
        } else {
            Some(
                f[3].parse::<f64>()
                    .map_err(|_| bad("error is not a number"))?,
            )
        };
        let ms = f[5].parse::<f64>().map_err(|_| bad("ms is not a number"))?;
        rows.push(BenchRow {
            area: f[0].clone(),
            knob: f[1].clone(),
            setting: f[2].clone(),
            error,
            error_unit: f[4].clone(),
            ms,
        });
    }
    Ok(rows)
}

/// The panels: (knob, setting filter, title).
const PANELS: [(&str, &str, &str); 4] = [
    ("subpixel bits", "", "raster: subpixel bits"),
    (
        "remap unproject",
        "1e-5",
        "remap precision, near/far = 1e-5",
    ),
    ("strip start/filter", "", "SIRDS strips: start and filter"),
    (
        "TIW hsr/oversample",
        "",
        "SIRDS per pixel (TIW): oversampling",
    ),
];

/// Error against time for four accuracy knobs, from the committed benchmark rows.
///
/// # Errors
/// No rows for a panel (the CSV lacks a group: rerun `stereolab bench --only raster,finalize,sirds --csv`).
pub fn accuracy_time(ctx: &Context) -> Result<Canvas> {
    let mut c = Canvas::new(900, 640)?;
    for (i, (knob, filter, title)) in PANELS.iter().enumerate() {
        let rows: Vec<&BenchRow> = ctx
            .bench
            .iter()
            .filter(|r| r.knob == *knob && r.setting.contains(filter) && r.error.is_some())
            .collect();
        if rows.is_empty() {
            return Err(Error::invalid(
                "bench data",
                *knob,
                "has no rows: regenerate slides/data/bench.csv with `stereolab bench --only raster,finalize,sirds --csv slides/data/bench.csv`",
            ));
        }
        let (col, row) = ((i % 2) as f32, (i / 2) as f32);
        let (x0, y0) = (90.0 + col * 450.0, 40.0 + row * 300.0);
        let max_ms = rows.iter().map(|r| r.ms).fold(0.0, f64::max) * 1.15;
        let max_err = rows
            .iter()
            .filter_map(|r| r.error)
            .fold(0.0, f64::max)
            .max(1e-12)
            * 1.25;
        let a = Axes {
            frame: (x0, y0, x0 + 330.0, y0 + 200.0),
            x: (0.0, max_ms),
            y: (0.0, max_err),
        };
        a.draw(&mut c, "median time (ms)", &rows[0].error_unit, (5.0, 4.0));
        c.text(x0 + 165.0, y0 - 26.0, LABEL, title, INK, TextAlign::Center);
        for r in &rows {
            c.dot(a.px(r.ms, r.error.unwrap_or(0.0)), 4.5, (30, 30, 160));
        }
        // Labels after the dots, alternately above and below their point.
        for (j, r) in rows.iter().enumerate() {
            let p = a.px(r.ms, r.error.unwrap_or(0.0));
            let label = r
                .setting
                .replace(", near/far 1e-5", "")
                .replace("the exercise slides", "slides");
            let right = p.0 > x0 + 220.0;
            c.boxed_text(
                p.0 + if right { -8.0 } else { 8.0 },
                p.1 + if j % 2 == 0 { -22.0 } else { 6.0 },
                SMALL,
                &label,
                INK,
                if right {
                    TextAlign::Right
                } else {
                    TextAlign::Left
                },
            );
        }
    }
    c.text(
        450.0,
        616.0,
        SMALL,
        "stereolab bench --csv (slides/data/bench.csv): median of 15 runs, 1024×768 unless noted; shared 2-core machine",
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}
