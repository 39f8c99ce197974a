//! Error against time for one accuracy knob: the plots of the accuracy report
//! (`stereolab bench --report DIR`). A [`Knob`] is generic — a name, an error unit, a time
//! unit, measured points (label, error, seconds) and notes — so any benchmark group can be
//! plotted by building one; [`pareto_front`] marks the settings no other setting beats on both
//! error and time, and [`knob_plot`] draws it with this module's [`Canvas`].

use super::canvas::{Axes, Canvas, GRAY, INK, LABEL, Rgb, SMALL, nice_step, tick_label};
use stereolab_core::{Result, TextAlign, text_width};

/// One measured setting of a knob.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    /// The setting, as a reader would write it (`8 bits`, `per-pixel`).
    pub label: String,
    /// Its error against the reference, in the knob's `error_unit` (0 = exact).
    pub error: f64,
    /// Median wall time of one run, seconds.
    pub seconds: f64,
}

/// One accuracy knob: every setting measured for error and time in the same run.
#[derive(Clone, Debug, PartialEq)]
pub struct Knob {
    /// File stem of its plot (`subpixel_bits`), letters, digits, `_` and `-` only.
    pub id: String,
    /// Title (`raster: subpixel bits`).
    pub title: String,
    /// What the error measures, with its unit (`max hue error (degrees)`).
    pub error_unit: String,
    /// What one timing covers (`one 1024×768 depth-only pass`).
    pub time_unit: String,
    /// The settings measured.
    pub points: Vec<Point>,
    /// How it was measured: scene, size, reference.
    pub notes: String,
    /// An error at or below this is negligible for a course (in `error_unit`): the reading
    /// recommends the fastest setting within it.
    pub negligible: f64,
}

/// Which points lie on the Pareto front of (time, error), both to be small: a point is on the
/// front when no other point is at least as fast and at least as accurate and strictly better
/// in one of the two. Equal points are all on the front. Points with a non-finite error or
/// time are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    points
        .iter()
        .map(|p| {
            ok(p)
                && !points
                    .iter()
                    .any(|q| ok(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect()
}

impl Knob {
    /// The points as (seconds, error) pairs, for [`pareto_front`].
    pub fn pairs(&self) -> Vec<(f64, f64)> {
        self.points.iter().map(|p| (p.seconds, p.error)).collect()
    }

    /// [`pareto_front`] of the points.
    pub fn front(&self) -> Vec<bool> {
        pareto_front(&self.pairs())
    }
}

/// The time unit that shows `max_seconds` with a leading digit: (name, seconds per unit).
pub fn time_scale(max_seconds: f64) -> (&'static str, f64) {
    if max_seconds >= 1.0 {
        ("s", 1.0)
    } else if max_seconds >= 1e-3 {
        ("ms", 1e-3)
    } else {
        ("µs", 1e-6)
    }
}

/// The front's color (filled dots and the staircase through them).
pub const FRONT: Rgb = (205, 70, 20);

/// How the error axis is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
enum YScale {
    /// 0 to `max`.
    Linear { max: f64 },
    /// Decades `lo` to `hi` (powers of ten); an error of 0 sits on a row of its own below.
    Log { lo: i32, hi: i32 },
}

fn y_scale(errors: &[f64]) -> YScale {
    let max = errors.iter().copied().fold(0.0, f64::max);
    let min_pos = errors
        .iter()
        .copied()
        .filter(|e| *e > 0.0)
        .fold(f64::INFINITY, f64::min);
    if max > 0.0 && min_pos.is_finite() && max / min_pos > 100.0 {
        YScale::Log {
            lo: min_pos.log10().floor() as i32,
            hi: max.log10().ceil().max(min_pos.log10().floor() + 1.0) as i32,
        }
    } else {
        YScale::Linear {
            max: if max > 0.0 { max * 1.2 } else { 1.0 },
        }
    }
}

/// Error against time for `knob`: each setting a numbered dot (the key on the right names
/// it), the Pareto front filled and joined by a staircase, dominated settings hollow; time
/// on x from 0, error on y (linear from 0, or by decades when the errors span more than a
/// factor 100, with exact settings on a row marked 0).
///
/// # Errors
/// Only a canvas failure (a bug).
pub fn knob_plot(knob: &Knob) -> Result<Canvas> {
    let mut c = Canvas::new(960, 460)?;
    let (l, t, r, b) = (96.0f32, 48.0f32, 600.0f32, 380.0f32);
    let valid: Vec<usize> = (0..knob.points.len())
        .filter(|&i| knob.points[i].error.is_finite() && knob.points[i].seconds.is_finite())
        .collect();
    let max_s = valid
        .iter()
        .map(|&i| knob.points[i].seconds)
        .fold(0.0, f64::max);
    let (unit, per) = time_scale(max_s);
    let x_max = (max_s / per * 1.15).max(1e-9);
    let errors: Vec<f64> = valid.iter().map(|&i| knob.points[i].error).collect();
    let ys = y_scale(&errors);
    let zero_row = b - 18.0;
    let px = |s: f64, e: f64| -> (f32, f32) {
        let x = l + (s / per / x_max) as f32 * (r - l);
        let y = match ys {
            YScale::Linear { max } => b - (e / max) as f32 * (b - t),
            YScale::Log { lo, hi } => {
                if e <= 0.0 {
                    zero_row
                } else {
                    let f = (e.log10() - lo as f64) / (hi - lo) as f64;
                    (b - 36.0) - f as f32 * (b - 36.0 - t)
                }
            }
        };
        (x, y)
    };
    // Grid, ticks and tick values.
    let xs = nice_step(x_max, 6.0);
    let mut v = 0.0;
    while v <= x_max + 1e-9 * xs {
        let x = l + (v / x_max) as f32 * (r - l);
        c.line((x, t), (x, b), (232, 232, 232), 1.0);
        c.line((x, b), (x, b + 5.0), INK, 1.0);
        c.text(
            x,
            b + 7.0,
            SMALL,
            &tick_label(v, xs),
            INK,
            TextAlign::Center,
        );
        v += xs;
    }
    let mut y_ticks: Vec<(f32, String)> = Vec::new();
    match ys {
        YScale::Linear { max } => {
            let step = nice_step(max, 5.0);
            let mut v = 0.0;
            while v <= max + 1e-9 * step {
                // Tiny steps in scientific notation (2.0e−7, not 0.00000020).
                let label = if step >= 1e-3 || v == 0.0 {
                    tick_label(v, step)
                } else {
                    format!("{v:.1e}").replace('-', "−")
                };
                y_ticks.push((px(0.0, v).1, label));
                v += step;
            }
        }
        YScale::Log { lo, hi } => {
            y_ticks.push((zero_row, "0".into()));
            for d in lo..=hi {
                y_ticks.push((px(0.0, 10f64.powi(d)).1, format!("1e{d}").replace('-', "−")));
            }
            c.dashed((l, b - 27.0), (r, b - 27.0), GRAY, 1.0);
        }
    }
    let mut widest = 0.0f32;
    for (y, s) in &y_ticks {
        c.line((l, *y), (r, *y), (232, 232, 232), 1.0);
        c.line((l - 5.0, *y), (l, *y), INK, 1.0);
        c.text(l - 8.0, y - SMALL * 0.6, SMALL, s, INK, TextAlign::Right);
        widest = widest.max(text_width(s, SMALL));
    }
    c.rect((l, t), (r, b), INK, 1.0);
    c.text(
        (l + r) / 2.0,
        b + 26.0,
        LABEL,
        &format!("median time ({unit}), {}", knob.time_unit),
        INK,
        TextAlign::Center,
    );
    let y_label = if matches!(ys, YScale::Log { .. }) {
        format!("{} (log scale)", knob.error_unit)
    } else {
        knob.error_unit.clone()
    };
    c.vertical_text(
        l - 14.0 - widest - LABEL * 1.2,
        (t + b) / 2.0,
        LABEL,
        &y_label,
        INK,
    );
    c.text(l, 14.0, LABEL + 2.0, &knob.title, INK, TextAlign::Left);
    // The front as a staircase (fastest first: each step is more accurate and slower).
    let front = knob.front();
    let mut on: Vec<usize> = valid.iter().copied().filter(|&i| front[i]).collect();
    on.sort_by(|&a, &b| {
        knob.points[a]
            .seconds
            .total_cmp(&knob.points[b].seconds)
            .then(knob.points[b].error.total_cmp(&knob.points[a].error))
    });
    let mut stairs = Vec::new();
    for (k, &i) in on.iter().enumerate() {
        let p = px(knob.points[i].seconds, knob.points[i].error);
        if k > 0 {
            let prev: (f32, f32) = stairs[stairs.len() - 1];
            stairs.push((p.0, prev.1));
        }
        stairs.push(p);
    }
    if stairs.len() > 1 {
        c.polyline(&stairs, FRONT, 1.5);
    }
    // Dots, then numbers beside them (moved down while they would overlap an earlier one).
    let mut placed: Vec<(f32, f32)> = Vec::new();
    for (n, &i) in valid.iter().enumerate() {
        let p = px(knob.points[i].seconds, knob.points[i].error);
        if front[i] {
            c.dot(p, 5.0, FRONT);
        } else {
            c.circle(p, 5.0, GRAY, 1.5);
        }
        let mut at = (p.0 + 7.0, p.1 - 17.0);
        while placed
            .iter()
            .any(|q| (q.0 - at.0).abs() < 18.0 && (q.1 - at.1).abs() < 14.0)
        {
            at.1 += 14.0;
        }
        placed.push(at);
        let color = if front[i] { FRONT } else { INK };
        c.boxed_text(
            at.0,
            at.1,
            SMALL,
            &(n + 1).to_string(),
            color,
            TextAlign::Left,
        );
    }
    // The key: number, setting, on the front or not.
    let kx = r + 24.0;
    c.text(
        kx,
        t - 4.0,
        SMALL,
        "settings (filled: Pareto front)",
        INK,
        TextAlign::Left,
    );
    for (n, &i) in valid.iter().enumerate() {
        let y = t + 16.0 + n as f32 * (SMALL + 5.0);
        let (color, mark) = if front[i] {
            (FRONT, "●")
        } else {
            (GRAY, "○")
        };
        let label = &knob.points[i].label;
        let label = if text_width(label, SMALL) > 300.0 {
            let mut s: String = label.chars().take(40).collect();
            s.push('…');
            s
        } else {
            label.clone()
        };
        c.text(kx, y, SMALL, mark, color, TextAlign::Left);
        c.text(
            kx + 16.0,
            y,
            SMALL,
            &format!("{}  {label}", n + 1),
            INK,
            TextAlign::Left,
        );
    }
    let skipped = knob.points.len() - valid.len();
    if skipped > 0 {
        let y = t + 16.0 + valid.len() as f32 * (SMALL + 5.0) + 6.0;
        c.text(
            kx,
            y,
            SMALL,
            &format!("{skipped} setting(s) not measured"),
            GRAY,
            TextAlign::Left,
        );
    }
    c.text(
        l,
        b + 52.0,
        SMALL,
        "Pareto front: no other setting is both at least as fast and at least as accurate",
        GRAY,
        TextAlign::Left,
    );
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_exactly_the_undominated_points() {
        // (seconds, error)
        let pts = [
            (1.0, 5.0), // fastest: front
            (2.0, 1.0), // front
            (3.0, 1.0), // dominated by (2, 1): slower, same error
            (2.5, 3.0), // dominated by (2, 1)
            (4.0, 0.0), // most accurate: front
            (1.0, 5.0), // equal to the first: front too
            (f64::NAN, 0.0),
            (0.5, f64::INFINITY),
        ];
        assert_eq!(
            pareto_front(&pts),
            vec![true, true, false, false, true, true, false, false]
        );
        assert_eq!(pareto_front(&[]), Vec::<bool>::new());
        assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![true]);
        // Same time: only the most accurate; same error: only the fastest.
        assert_eq!(pareto_front(&[(1.0, 2.0), (1.0, 1.0)]), vec![false, true]);
        assert_eq!(pareto_front(&[(1.0, 1.0), (2.0, 1.0)]), vec![true, false]);
    }

    #[test]
    fn the_front_agrees_with_a_brute_force_definition_on_random_points() {
        // A tiny LCG: deterministic points on a coarse grid, so ties happen.
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) % 6) as f64
        };
        for _ in 0..200 {
            let pts: Vec<(f64, f64)> = (0..7).map(|_| (next(), next())).collect();
            let front = pareto_front(&pts);
            for (i, p) in pts.iter().enumerate() {
                // On the front ⇔ every other point is slower or less accurate, or equal.
                let undominated = pts
                    .iter()
                    .all(|q| q.0 > p.0 || q.1 > p.1 || (q.0 == p.0 && q.1 == p.1));
                assert_eq!(front[i], undominated, "{pts:?} point {i}");
            }
            // The most accurate of the fastest is always on the front.
            let fastest = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
            let best = pts
                .iter()
                .filter(|p| p.0 == fastest)
                .map(|p| p.1)
                .fold(f64::INFINITY, f64::min);
            assert!(
                pts.iter()
                    .zip(&front)
                    .any(|(p, f)| *f && p.0 == fastest && p.1 == best)
            );
        }
    }

    #[test]
    fn scales_pick_log_only_for_wide_error_ranges() {
        assert_eq!(y_scale(&[0.0, 1.0, 2.0]), YScale::Linear { max: 2.4 });
        assert_eq!(y_scale(&[0.0, 0.0]), YScale::Linear { max: 1.0 });
        assert_eq!(y_scale(&[0.0, 2e-6, 0.5]), YScale::Log { lo: -6, hi: 0 });
        assert_eq!(time_scale(0.5), ("ms", 1e-3));
        assert_eq!(time_scale(2e-4), ("µs", 1e-6));
        assert_eq!(time_scale(3.0), ("s", 1.0));
    }
}

/// One measured curve of a [`log_log`] panel.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Its name in the legend (`CPU pair + Dubois`).
    pub label: String,
    /// Its color.
    pub rgb: Rgb,
    /// (x, y) points, both positive; others are left out.
    pub points: Vec<(f64, f64)>,
}

/// One panel of a [`log_log`] figure: its curves over a shared title and axis names.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Title above the panel.
    pub title: String,
    /// What x counts (`triangles per pair`).
    pub x_label: String,
    /// What y measures, with its unit (`median time (ms)`).
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
}

/// A decade's tick value as a reader writes it: 1k, 10k, 1M, 0.1, 1, 10, 100.
fn decade_label(d: i32) -> String {
    match d {
        d if d >= 9 => format!("{}G", 10i64.pow((d - 9) as u32)),
        d if d >= 6 => format!("{}M", 10i64.pow((d - 6) as u32)),
        d if d >= 3 => format!("{}k", 10i64.pow((d - 3) as u32)),
        d if d >= 0 => 10i64.pow(d as u32).to_string(),
        d => format!("{}", 10f64.powi(d)),
    }
}

/// Panels side by side, each with both axes by decades (a cost that grows in proportion to
/// the work is a line of slope 1), dots at the measured points joined by lines, a legend per
/// panel, and `footer` in gray below.
///
/// # Errors
/// Only a canvas failure (a bug).
pub fn log_log(panels: &[Panel], footer: &str) -> Result<Canvas> {
    let (pw, ph) = (450.0f32, 380.0f32);
    let mut c = Canvas::new((pw * panels.len().max(1) as f32) as u32, ph as u32 + 40)?;
    for (i, panel) in panels.iter().enumerate() {
        let pts: Vec<(f64, f64)> = panel
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
            .collect();
        let span = |f: &dyn Fn(&(f64, f64)) -> f64| {
            let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
            let hi = pts.iter().map(f).fold(f64::NEG_INFINITY, f64::max);
            if lo.is_finite() {
                (
                    lo.log10().floor() as i32,
                    hi.log10().ceil().max(lo.log10().floor() + 1.0) as i32,
                )
            } else {
                (0, 1)
            }
        };
        let (x0, x1) = span(&|p| p.0);
        let (y0, y1) = span(&|p| p.1);
        let left = i as f32 * pw + 80.0;
        let a = Axes {
            frame: (left, 40.0, left + pw - 110.0, ph - 60.0),
            x: (f64::from(x0), f64::from(x1)),
            y: (f64::from(y0), f64::from(y1)),
        };
        let (l, t, r, b) = a.frame;
        for d in x0..=x1 {
            let (x, _) = a.px(f64::from(d), a.y.0);
            c.line((x, t), (x, b), (232, 232, 232), 1.0);
            c.line((x, b), (x, b + 5.0), INK, 1.0);
            c.text(x, b + 7.0, SMALL, &decade_label(d), INK, TextAlign::Center);
        }
        for d in y0..=y1 {
            let (_, y) = a.px(a.x.0, f64::from(d));
            c.line((l, y), (r, y), (232, 232, 232), 1.0);
            c.line((l - 5.0, y), (l, y), INK, 1.0);
            c.text(
                l - 8.0,
                y - SMALL * 0.6,
                SMALL,
                &decade_label(d),
                INK,
                TextAlign::Right,
            );
        }
        c.rect((l, t), (r, b), INK, 1.0);
        c.text(
            (l + r) / 2.0,
            b + 26.0,
            LABEL,
            &panel.x_label,
            INK,
            TextAlign::Center,
        );
        c.vertical_text(l - 60.0, (t + b) / 2.0, LABEL, &panel.y_label, INK);
        c.text(
            (l + r) / 2.0,
            t - 26.0,
            LABEL,
            &panel.title,
            INK,
            TextAlign::Center,
        );
        for s in &panel.series {
            let p: Vec<(f64, f64)> = s
                .points
                .iter()
                .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
                .map(|(x, y)| (x.log10(), y.log10()))
                .collect();
            a.curve(&mut c, &p, s.rgb, 2.0);
            for q in &p {
                c.dot(a.px(q.0, q.1), 4.0, s.rgb);
            }
        }
        let entries: Vec<(&str, Rgb)> = panel
            .series
            .iter()
            .map(|s| (s.label.as_str(), s.rgb))
            .collect();
        a.legend(&mut c, &entries, false);
    }
    c.text(
        c.width() / 2.0,
        ph + 14.0,
        SMALL,
        footer,
        GRAY,
        TextAlign::Center,
    );
    Ok(c)
}
