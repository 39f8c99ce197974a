//! `stereolab bench`: one row per measurement — area, knob, setting, error against the most
//! accurate setting, milliseconds — printed and optionally written as CSV.

pub mod accuracy;
mod chromadepth;
pub mod cost;
pub mod depth;
pub mod doc;
mod finalize;
#[cfg(feature = "gpu")]
mod gpu;
#[cfg(feature = "gpu")]
mod gpu_oneshot;
pub mod report;
mod scaling;
mod sirds;

use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3, Vec4};

use stereolab::plan::{Output, Plan};
use stereolab::render::{render, render_view};
use stereolab::scene::{Mesh, Scene};
use stereolab_core::{
    Error, Fragment, Framebuffer, RasterOptions, Result, Shader, Varyings, perspective, rasterize,
};

/// One measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// What part of stereolab (e.g. `raster`, `stereo pair`).
    pub area: String,
    /// The accuracy or speed knob.
    pub knob: String,
    /// Its setting.
    pub setting: String,
    /// Error against the most accurate setting (unit in `error_unit`); `None` for pure timings.
    pub error: Option<f64>,
    /// What `error` measures.
    pub error_unit: String,
    /// Median wall time in milliseconds.
    pub ms: f64,
    /// Anything else worth printing (throughput, ratios).
    pub note: String,
}

/// Benchmark options.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// The real-model scene (default: `assets/scenes/wuson.toml`).
    pub scene: std::path::PathBuf,
    /// Repetitions per timing (the median is reported).
    pub iterations: usize,
    /// Image size for the frame timings.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Run only these groups (`stereo`, `raster`, `depth`, `chromadepth`, `finalize`, `sirds`,
    /// `scaling`, `gpu`, `cost`);
    /// empty: all.
    pub only: Vec<String>,
}

/// The benchmark groups, in the order they run.
pub(crate) const GROUPS: [&str; 9] = [
    "stereo",
    "raster",
    "depth",
    "chromadepth",
    "finalize",
    "sirds",
    "scaling",
    "gpu",
    "cost",
];

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            scene: Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/wuson.toml"),
            iterations: 15,
            width: 1024,
            height: 768,
            only: Vec::new(),
        }
    }
}

/// Median milliseconds of `iters` runs of `f` (after one warm-up run).
pub(crate) fn median_ms<T>(iters: usize, mut f: impl FnMut() -> T) -> f64 {
    std::hint::black_box(f());
    median(
        (0..iters.max(1))
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(f());
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect(),
    )
}

/// The median of `v` (the upper one of an even count; NaN sorts last), NaN when `v` is empty.
pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Medians of `rounds · block` runs of each of `fs` (after one warm-up run of each), taken in
/// turns, `block` runs of one before the next: a slow spell of the shared machine then falls on
/// every row alike and the ratios between them stay fair.
///
/// # Errors
/// The first error of any run.
pub(crate) fn interleaved_medians(
    rounds: usize,
    block: usize,
    fs: &mut [&mut dyn FnMut() -> Result<()>],
) -> Result<Vec<f64>> {
    for f in fs.iter_mut() {
        f()?;
    }
    let mut times = vec![Vec::with_capacity(rounds * block); fs.len()];
    for _ in 0..rounds.max(1) {
        for (f, t) in fs.iter_mut().zip(&mut times) {
            for _ in 0..block.max(1) {
                let start = Instant::now();
                f()?;
                t.push(start.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok(times.into_iter().map(median).collect())
}

/// Round trips of one cache line between two threads in [`round_trip_ns`].
const ROUND_TRIPS: u64 = 1000;

/// The longest one [`round_trip_ns`] may take: on a machine where the two threads share one
/// core, each turn waits for the scheduler, and the measurement gives up instead.
const ROUND_TRIP_LIMIT: Duration = Duration::from_millis(200);

/// How far apart the machine's cores are: nanoseconds for one cache line to go from one thread
/// to another and back (two threads taking turns to write one atomic counter,
/// [`ROUND_TRIPS`] times). Where a pass hands data from one thread to the next (set-up written
/// by one thread and read by the other, a buffer one thread wrote last frame and the other
/// writes now), each such line costs about this. A virtual machine's two CPUs may sit on cores
/// that share a cache or on cores far apart, and its host may move them while a program runs.
/// NaN where the machine has one core, or the turns took longer than [`ROUND_TRIP_LIMIT`].
pub(crate) fn round_trip_ns() -> f64 {
    if std::thread::available_parallelism().map_or(1, |n| n.get()) < 2 {
        return f64::NAN;
    }
    let turn = AtomicU64::new(0);
    let deadline = Instant::now() + ROUND_TRIP_LIMIT;
    std::thread::scope(|s| {
        s.spawn(|| {
            // The other side: waits for each odd turn and answers with the next even one.
            for i in 0..=ROUND_TRIPS {
                if !wait_for(&turn, 2 * i + 1, deadline) {
                    return;
                }
                turn.store(2 * i + 2, Ordering::Release);
            }
        });
        let mut start = Instant::now();
        for i in 0..=ROUND_TRIPS {
            // The first trip waits for the other thread to start; the clock starts after it.
            if i == 1 {
                start = Instant::now();
            }
            turn.store(2 * i + 1, Ordering::Release);
            if !wait_for(&turn, 2 * i + 2, deadline) {
                return f64::NAN;
            }
        }
        start.elapsed().as_secs_f64() * 1e9 / ROUND_TRIPS as f64
    })
}

/// Spins until `turn` holds `want` (true), or gives up at `deadline` (false), yielding the
/// core now and then so that a thread sharing it can take its turn.
fn wait_for(turn: &AtomicU64, want: u64, deadline: Instant) -> bool {
    let mut spins = 0u32;
    while turn.load(Ordering::Acquire) != want {
        spins = spins.wrapping_add(1);
        if spins.is_multiple_of(256) {
            if Instant::now() > deadline {
                return false;
            }
            std::thread::yield_now();
        } else {
            std::hint::spin_loop();
        }
    }
    true
}

/// A [`round_trip_ns`] figure for a note: `75 ns`, or `—` where none was measured.
pub(crate) fn ns(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.0} ns")
    } else {
        "—".into()
    }
}

/// Runs every benchmark group `opts.only` asks for (all when empty).
///
/// # Errors
/// `Invalid` naming `bench.only` for a group not in `GROUPS`. The scene cannot be loaded or
/// rendered.
pub fn run(opts: &BenchOptions) -> Result<Vec<Row>> {
    if let Some(bad) = opts.only.iter().find(|g| !GROUPS.contains(&g.as_str())) {
        return Err(Error::invalid(
            "bench.only",
            bad,
            format!("unknown group; one of {}", GROUPS.join(", ")),
        ));
    }
    let want = |g: &str| opts.only.is_empty() || opts.only.iter().any(|o| o == g);
    let iters = opts.iterations;
    let mut rows = Vec::new();
    let mut scene = Scene::load(&opts.scene, &[])?;
    scene.set_size(opts.width, opts.height)?;
    if want("stereo") {
        rows.extend(stereo_pair(&scene, iters)?);
    }
    if want("raster") {
        rows.extend(subpixel_bits(&scene, iters)?);
        rows.extend(perspective_correction(iters)?);
    }
    if want("depth") {
        rows.extend(depth::rows(iters)?);
    }
    if want("chromadepth") {
        rows.extend(chromadepth::rows(&scene, iters)?);
    }
    if want("finalize") {
        rows.extend(finalize::rows(&scene, iters)?);
    }
    if want("sirds") {
        rows.extend(sirds::rows(iters)?);
    }
    if want("scaling") {
        rows.extend(scaling::rows(&scene, iters)?);
    }
    #[cfg(feature = "gpu")]
    if want("gpu") {
        rows.extend(gpu_oneshot::rows(&scene, iters)?);
        rows.extend(gpu::rows(&scene, iters)?);
    }
    if want("cost") {
        rows.extend(cost::rows(&scene, iters)?);
    }
    Ok(rows)
}

fn row(
    area: &str,
    knob: &str,
    setting: impl Into<String>,
    error: Option<f64>,
    unit: &str,
    ms: f64,
    note: impl Into<String>,
) -> Row {
    Row {
        area: area.into(),
        knob: knob.into(),
        setting: setting.into(),
        error,
        error_unit: unit.into(),
        ms,
        note: note.into(),
    }
}

/// The stereo pair of the real model: ms per frame and triangles per second.
fn stereo_pair(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let plan = Plan::new(&[Output::Left, Output::Right]);
    let tris: usize = scene
        .objects
        .iter()
        .map(|o| o.mesh.triangles.len())
        .sum::<usize>()
        * 2;
    let mut err = None;
    let ms = median_ms(iters, || render(scene, &plan).map_err(|e| err = Some(e)));
    if let Some(e) = err {
        return Err(e);
    }
    let size = format!("{}x{}", scene.width, scene.height);
    Ok(vec![row(
        "stereo pair",
        "real model",
        size,
        None,
        "",
        ms,
        format!(
            "{:.2} M triangles/s, {} triangles/frame",
            tris as f64 / ms / 1e3,
            tris
        ),
    )])
}

/// Coverage differences of 4 and 8 subpixel bits against 16 on the real model's left eye.
fn subpixel_bits(scene: &Scene, iters: usize) -> Result<Vec<Row>> {
    let eyes = scene
        .rig
        .eyes_for_image(&scene.camera, scene.width, scene.height)?;
    let coverage = |bits: u32| -> Result<Vec<bool>> {
        let mut s = scene.clone();
        s.raster.subpixel_bits = bits;
        let (fb, _) = render_view(&s, &eyes[0], stereolab::plan::Shading::DepthOnly)?;
        Ok(fb.depth().iter().map(|d| *d < 1.0).collect())
    };
    let reference = coverage(16)?;
    let mut rows = Vec::new();
    for bits in [4, 8, 16] {
        let cov = coverage(bits)?;
        let diff = cov.iter().zip(&reference).filter(|(a, b)| a != b).count();
        let mut s = scene.clone();
        s.raster.subpixel_bits = bits;
        let ms = median_ms(iters, || {
            render_view(&s, &eyes[0], stereolab::plan::Shading::DepthOnly).is_ok()
        });
        rows.push(row(
            "raster",
            "subpixel bits",
            bits.to_string(),
            Some(diff as f64 / reference.len() as f64 * 100.0),
            "% pixels vs 16 bits",
            ms,
            "left eye, depth only",
        ));
    }
    Ok(rows)
}

/// Writes the interpolated texture coordinate as color (the timed shader of the perspective benchmark).
struct UvShader<'a> {
    mesh: &'a Mesh,
    mvp: glam::Mat4,
}

impl Shader for UvShader<'_> {
    fn varying_count(&self) -> usize {
        2
    }
    fn vertex(&self, i: u32, out: &mut Varyings) -> Vec4 {
        let uv: Vec2 = self.mesh.uvs[i as usize];
        out[0] = uv.x;
        out[1] = uv.y;
        self.mvp * self.mesh.positions[i as usize].extend(1.0)
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        // The color is only for looking at; the benchmark reads the exact floats through
        // `RecordUv`, which wraps this shader.
        Some(stereolab_core::to_rgba8(Vec3::new(
            f.varyings[0],
            f.varyings[1],
            0.0,
        )))
    }
}

/// Max texture-coordinate error of affine interpolation on a plane slanted 70° away.
fn perspective_correction(iters: usize) -> Result<Vec<Row>> {
    let mesh = Mesh::plane(4.0, 1);
    let model = glam::Mat4::from_translation(Vec3::new(0.0, 0.0, -4.0))
        * glam::Mat4::from_rotation_x(-70f32.to_radians());
    let mvp = perspective(60.0, 4.0 / 3.0, 0.5, 20.0) * model;
    let run = |perspective_correct: bool| -> Result<(Vec<[f32; 2]>, f64)> {
        let opts = RasterOptions {
            perspective_correct,
            ..RasterOptions::default()
        };
        let uv = std::sync::Mutex::new(vec![[f32::NAN; 2]; 1024 * 768]);
        let shader = RecordUv {
            inner: UvShader { mesh: &mesh, mvp },
            out: &uv,
        };
        let mut fb = Framebuffer::new(1024, 768, [0, 0, 0, 255])?;
        rasterize(
            &mesh.triangles,
            mesh.positions.len(),
            &shader,
            &mut fb,
            &opts,
        );
        let ms = median_ms(iters, || {
            let mut fb = Framebuffer::new(1024, 768, [0, 0, 0, 255]).map_err(|e| e.to_string());
            if let Ok(fb) = fb.as_mut() {
                rasterize(
                    &mesh.triangles,
                    mesh.positions.len(),
                    &shader.inner,
                    fb,
                    &opts,
                );
            }
        });
        let v = uv
            .into_inner()
            .map_err(|_| Error::internal("bench uv", "poisoned by a panic in another thread"))?;
        Ok((v, ms))
    };
    let (exact, ms_exact) = run(true)?;
    let (affine, ms_affine) = run(false)?;
    let max_err = exact
        .iter()
        .zip(&affine)
        .filter(|(a, _)| a[0].is_finite())
        .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) as f64)
        .fold(0.0, f64::max);
    Ok(vec![
        row(
            "raster",
            "varyings",
            "perspective-correct",
            Some(0.0),
            "max |uv| error",
            ms_exact,
            "plane slanted 70 deg, 1024x768",
        ),
        row(
            "raster",
            "varyings",
            "affine",
            Some(max_err),
            "max |uv| error",
            ms_affine,
            "plane slanted 70 deg, 1024x768",
        ),
    ])
}

/// Wraps [`UvShader`] and records each fragment's uv.
struct RecordUv<'a> {
    inner: UvShader<'a>,
    out: &'a std::sync::Mutex<Vec<[f32; 2]>>,
}

impl Shader for RecordUv<'_> {
    fn varying_count(&self) -> usize {
        self.inner.varying_count()
    }
    fn vertex(&self, i: u32, out: &mut Varyings) -> Vec4 {
        self.inner.vertex(i, out)
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        if let Ok(mut v) = self.out.lock() {
            v[f.y as usize * 1024 + f.x as usize] = [f.varyings[0], f.varyings[1]];
        }
        self.inner.fragment(f)
    }
}

/// The rows as an aligned table (column widths fitted to the content).
pub fn table(rows: &[Row]) -> String {
    let cells: Vec<[String; 7]> = rows
        .iter()
        .map(|r| {
            let e = r
                .error
                .map(|e| format!("{e:.6}"))
                .unwrap_or_else(|| "-".into());
            [
                r.area.clone(),
                r.knob.clone(),
                r.setting.clone(),
                e,
                r.error_unit.clone(),
                format!("{:.3}", r.ms),
                r.note.clone(),
            ]
        })
        .collect();
    let header = [
        "area",
        "knob",
        "setting",
        "error",
        "error unit",
        "ms",
        "note",
    ]
    .map(String::from);
    let mut width = [0usize; 7];
    for row in cells.iter().chain(std::iter::once(&header)) {
        for (w, c) in width.iter_mut().zip(row) {
            *w = (*w).max(c.chars().count());
        }
    }
    let mut s = String::new();
    for row in std::iter::once(&header).chain(&cells) {
        let line: Vec<String> = row
            .iter()
            .enumerate()
            .map(|(i, c)| {
                if i == 3 || i == 5 {
                    format!("{c:>w$}", w = width[i])
                } else if i == 6 {
                    c.clone()
                } else {
                    format!("{c:<w$}", w = width[i])
                }
            })
            .collect();
        let _ = writeln!(s, "{}", line.join("  ").trim_end());
    }
    s
}

/// Writes the rows as CSV (header `area,knob,setting,error,error_unit,ms,note`).
///
/// # Errors
/// The file cannot be written.
pub fn write_csv(rows: &[Row], path: &Path) -> Result<()> {
    let q = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    let mut s = String::from("area,knob,setting,error,error_unit,ms,note\n");
    for r in rows {
        let e = r.error.map(|e| e.to_string()).unwrap_or_default();
        let _ = writeln!(
            s,
            "{},{},{},{},{},{:.4},{}",
            q(&r.area),
            q(&r.knob),
            q(&r.setting),
            e,
            q(&r.error_unit),
            r.ms,
            q(&r.note)
        );
    }
    stereolab_core::write_bytes(path, s.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wait nobody answers gives up at its deadline instead of spinning on.
    #[test]
    fn an_unanswered_turn_gives_up_at_the_deadline() {
        let turn = AtomicU64::new(0);
        let start = Instant::now();
        let deadline = start + Duration::from_millis(20);
        assert!(!wait_for(&turn, 1, deadline));
        let waited = start.elapsed();
        assert!(waited >= Duration::from_millis(20), "{waited:?}");
        assert!(waited < Duration::from_secs(2), "{waited:?}");
    }

    /// A measured round trip is a positive time; on one core there is none (NaN), and the
    /// measurement still ends.
    #[test]
    fn a_round_trip_is_positive_or_not_measured() {
        let v = round_trip_ns();
        assert!(v.is_nan() || v > 0.0, "{v}");
        assert_eq!(ns(f64::NAN), "—");
        assert_eq!(ns(74.6), "75 ns");
    }
}
