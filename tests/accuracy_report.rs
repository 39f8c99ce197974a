//! The accuracy-against-time report (`stereolab bench --report DIR`): its structure, in quick
//! mode into a fresh folder (timings vary run to run, so nothing here compares numbers or the
//! committed report byte for byte), and the committed copy in `docs/accuracy/` (every plot it
//! shows exists and decodes; the slides' copies are the report's plots).

use stereolab_bench::BenchOptions;
use stereolab_bench::report::{ReportOptions, SLIDE_KNOBS, write_report};
use stereolab_figures::plot::pareto_front;

use crate::common::{asset, out_dir, root};

/// The PNG decodes and is a plot: white page, some dark ink (axes, labels: the canvas draws
/// them antialiased in near-black), the front's color somewhere.
fn check_plot(path: &std::path::Path) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: does not decode: {e}", path.display()))
        .to_rgb8();
    assert_eq!(img.dimensions(), (960, 460), "{}", path.display());
    let ink = img.pixels().filter(|p| p.0.iter().all(|&c| c < 80)).count();
    assert!(ink > 500, "{}: {ink} dark pixels, no axes?", path.display());
    let front = img.pixels().filter(|p| p.0 == [205, 70, 20]).count();
    assert!(front > 20, "{}: no Pareto front drawn", path.display());
}

#[test]
fn quick_report_has_a_plot_per_knob_with_axes_and_a_reading() {
    let dir = out_dir("accuracy_report");
    let slides = dir.join("slides");
    std::fs::create_dir_all(&slides).expect("slides folder");
    let bench = BenchOptions {
        scene: asset("scenes/wuson.toml"),
        ..BenchOptions::default()
    };
    let opts = ReportOptions {
        dir: dir.clone(),
        quick: true,
        slides: Some(slides.clone()),
    };
    let written = write_report(&bench, &opts).expect("report");
    assert!(
        written.knobs.len() >= 12,
        "{} knobs, want at least 12",
        written.knobs.len()
    );
    let md = std::fs::read_to_string(dir.join("report.md")).expect("report.md");
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    let mut ids: Vec<&str> = Vec::new();
    for k in &written.knobs {
        assert!(!ids.contains(&k.id.as_str()), "two knobs named {}", k.id);
        ids.push(&k.id);
        let measured = k
            .points
            .iter()
            .filter(|p| p.error.is_finite() && p.seconds.is_finite() && p.seconds > 0.0)
            .count();
        assert!(measured >= 2, "{}: {measured} settings measured", k.id);
        assert!(
            k.points.iter().all(|p| p.error >= 0.0),
            "{}: negative error",
            k.id
        );
        check_plot(&dir.join(format!("{}.png", k.id)));
        // The plot, its axes (with units) and its reading are in both pages.
        assert!(
            md.contains(&format!("]({}.png)", k.id)),
            "{}: no plot in md",
            k.id
        );
        assert!(
            md.contains(&format!(
                "*x: median time ({}); y: {}.*",
                k.time_unit, k.error_unit
            )),
            "{}: axes not labelled in md",
            k.id
        );
        assert!(html.contains(&format!("src=\"{}.png\"", k.id)), "{}", k.id);
        let reading = stereolab_bench::report::reading(k);
        assert!(reading.starts_with("**Use "), "{}: {reading}", k.id);
        assert!(md.contains(&reading), "{}: reading missing", k.id);
        // The front in the table is the front of the numbers.
        let front = pareto_front(&k.pairs());
        assert!(front.iter().any(|f| *f), "{}: empty front", k.id);
        let section = &md[md.find(&format!("<a id=\"{}\">", k.id)).expect("anchor")..];
        let section = &section[..section[1..].find("<a id=").map_or(section.len(), |e| e + 1)];
        let yes = section.lines().filter(|l| l.ends_with("| yes |")).count();
        assert_eq!(yes, front.iter().filter(|f| **f).count(), "{}", k.id);
    }
    // The determinism knob: every thread count gives the same bytes.
    let threads = written
        .knobs
        .iter()
        .find(|k| k.id == "threads")
        .expect("threads knob");
    assert!(threads.points.iter().all(|p| p.error == 0.0), "{threads:?}");
    for id in SLIDE_KNOBS {
        let copy = std::fs::read(slides.join(format!("accuracy_{id}.png"))).expect("slide copy");
        assert_eq!(
            copy,
            std::fs::read(dir.join(format!("{id}.png"))).expect("plot"),
            "{id}"
        );
    }
}

/// The committed report: at least 12 plots, each file there and a PNG; the slides show
/// copies of its plots, byte for byte; the README links it.
#[test]
fn committed_report_plots_exist_and_slides_copy_them() {
    let dir = root().join("docs/accuracy");
    let md = std::fs::read_to_string(dir.join("report.md")).expect(
        "docs/accuracy/report.md: run `cargo run --release -- bench --report docs/accuracy \
         --slides slides/figures`",
    );
    let html = std::fs::read_to_string(dir.join("report.html")).expect("report.html");
    let plots: Vec<&str> = md
        .match_indices("](")
        .filter_map(|(i, _)| {
            let rest = &md[i + 2..];
            // The link target runs to the first `)`; only image targets count (the summary
            // table's `](#id)` links are anchors).
            rest.find(')')
                .map(|e| &rest[..e])
                .filter(|t| t.ends_with(".png"))
        })
        .collect();
    assert!(plots.len() >= 12, "{} plots in report.md", plots.len());
    for p in &plots {
        check_plot(&dir.join(p));
        assert!(
            html.contains(&format!("src=\"{p}\"")),
            "{p} not in report.html"
        );
    }
    for id in SLIDE_KNOBS {
        let name = format!("accuracy_{id}.png");
        let copy = std::fs::read(root().join("slides/figures").join(&name)).expect(&name);
        assert_eq!(
            copy,
            std::fs::read(dir.join(format!("{id}.png"))).expect("plot"),
            "slides/figures/{name} is not docs/accuracy/{id}.png: regenerate both with the \
             command in docs/accuracy/report.md"
        );
    }
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README");
    assert!(
        readme.contains("docs/accuracy/report.md"),
        "README does not link the report"
    );
}
