//! SIRDS benchmark rows: the SIRDS paper's Table 1 (with and without the depth pass) beside the paper's
//! frame rates, every accuracy knob with its decode error, and TIW on a 4096×3072 depth map.

use std::path::Path;

use super::{Row, interleaved_medians, median, median_ms, ns, round_trip_ns};
use stereolab::fixtures::{TABLE_1, scene_from_text, sphere_over_ramp, table_scene};
use stereolab::output::sirds::{from_frame, scene_depth};
use stereolab::plan::{Output, Plan, Shading};
use stereolab::render::{render, render_view};
use stereolab::scene::Scene;
use stereolab_core::{
    DepthRange, Disparity, EyeMatrices, PerPixelOptions, PerVertexOptions, Result, SirdsAlgorithm,
    SirdsDecodeOptions, SirdsPattern, SirdsRoundTrip, StereoRig, StripFilter, StripStart,
    decode_sirds, depth_range, per_pixel, sirds_round_trip,
};
use stereolab_core::{StripGeometry, per_vertex, per_vertex_reference};

/// What precedes the round trip timed in Table 1's turns in each of its rows' notes (the
/// doc's Table 1 paragraph reads it back).
pub(crate) const ROUND_TRIP: &str =
    "a cache line's round trip between two threads in the rows' turns: ";

/// The SIRDS paper's Table 1, two rows per line of the table, each rate also as a multiple of
/// the paper's:
/// - **depth pass + strips**: stereolab's frame with the scene's automatic depth range (a depth
///   pass finds the nearest and farthest drawn depth, then the strip geometry and the strips;
///   left start, bilinear, k as in the paper).
/// - **strips, range fixed**: the work the paper's frame does. Its vertex program maps each
///   vertex's eye-space z to a disparity with constants (§4, Fig. 4: `c[2] = (0.5a, f, 0, 0)`),
///   so the paper renders no depth pass: its frame is the random initialization and the k
///   textured passes. Here the depth range is found once before timing and the frame is the
///   strip geometry (the vertex program) and the strips: the second half of the full frame,
///   so the same image. Row 1 once more on the strips' scalar loops
///   ([`per_vertex_reference`]): what the AVX2 loops bring (same bytes).
///
/// The rows are timed in turns ([`interleaved_medians`]), blocks of 20 frames, every row once
/// per round, until each has at least 300 frames: a slow spell of this shared VM (they last
/// seconds and move a frame's time by up to 40%) then falls on every row alike instead of on
/// whichever was being timed.
fn table_1(iters: usize) -> Result<Vec<Row>> {
    let mut scenes = Vec::new();
    for (w, h, tris, k, _) in TABLE_1 {
        let s = table_scene(w, h, tris, k)?;
        let center = StereoRig::center(&s.camera, s.aspect())?;
        let d = s.sirds.geometry.to_pixels()?;
        scenes.push((s, center, d));
    }
    let strips =
        |(s, center, d): &(Scene, EyeMatrices, Disparity), range: &DepthRange, simd: bool| {
            let g = StripGeometry::new(&s.strip_objects(), center, range, d, false);
            let (p, opts) = (&s.sirds.pattern, &s.sirds.per_vertex);
            if simd {
                per_vertex(&g, s.width, s.height, d, p, opts, false).map(drop)
            } else {
                per_vertex_reference(&g, s.width, s.height, d, p, opts, false).map(drop)
            }
        };
    let range_of = |(s, center, _): &(Scene, EyeMatrices, Disparity)| {
        let (fb, _) = render_view(s, center, Shading::DepthOnly)?;
        depth_range(&s.sirds, &fb, s.camera.near, s.camera.far)
    };
    // What is timed: each line's full frame, then each line's strips with the range fixed,
    // then row 1's strips with the range fixed on the scalar loops: (line, range, AVX2 loops).
    let mut timed: Vec<(usize, Option<DepthRange>, bool)> =
        (0..scenes.len()).map(|i| (i, None, true)).collect();
    for (i, scene) in scenes.iter().enumerate() {
        timed.push((i, Some(range_of(scene)?), true));
    }
    timed.push((0, Some(range_of(&scenes[0])?), false));
    let mut frames: Vec<Box<dyn FnMut() -> Result<()> + '_>> = timed
        .iter()
        .map(|&(i, range, simd)| -> Box<dyn FnMut() -> Result<()> + '_> {
            let scene = &scenes[i];
            match range {
                Some(r) => Box::new(move || strips(scene, &r, simd)),
                None => Box::new(move || strips(scene, &range_of(scene)?, simd)),
            }
        })
        .collect();
    // The machine's phase in the same turns: how far apart its cores are.
    let mut trips = Vec::new();
    let mut trip = || {
        trips.push(round_trip_ns());
        Ok(())
    };
    let mut fs: Vec<&mut dyn FnMut() -> Result<()>> =
        frames.iter_mut().map(|f| &mut **f as _).collect();
    fs.push(&mut trip);
    const BLOCK: usize = 20;
    let mut ms = interleaved_medians(iters.max(300).div_ceil(BLOCK), BLOCK, &mut fs)?;
    ms.pop();
    drop(fs);
    let phase = format!("; {ROUND_TRIP}{}", ns(median(trips)));
    let loops = |simd: bool| {
        if !simd {
            ", scalar loops"
        } else if stereolab_core::uses_avx2() {
            ", AVX2 loops"
        } else {
            ", scalar loops (no AVX2 here, or STEREOLAB_SCALAR set)"
        }
    };
    Ok(timed
        .iter()
        .zip(ms)
        .map(|(&(i, range, simd), ms)| {
            let (w, h, tris, k, paper_hz) = TABLE_1[i];
            let (setting, what) = if range.is_some() {
                (
                    format!("{w}x{h} {tris} tris k={k}, range fixed"),
                    "strips only (the paper's frame: no depth pass)",
                )
            } else {
                (format!("{w}x{h} {tris} tris k={k}"), "depth pass + strips")
            };
            let hz = 1e3 / ms;
            Row {
                area: "sirds".into(),
                knob: "the SIRDS paper's Table 1".into(),
                setting,
                error: None,
                error_unit: String::new(),
                ms,
                note: format!(
                    "{hz:.0} Hz vs paper {paper_hz} Hz (GeForce4): {:.1}x, {what}{}{phase}",
                    hz / paper_hz,
                    loops(simd)
                ),
            }
        })
        .collect())
}

/// The Fig. 5 ramp: a 20×20 plane (16×16 quads) turned 35° about y, 512×256, black-white
/// dots with seed 5; the scene of every SIRDS accuracy knob.
///
/// # Errors
/// None in practice (the scene text is fixed).
pub(super) fn ramp_scene() -> Result<Scene> {
    let mut base = scene_from_text(
        r#"outputs = ["sirds"]
[image]
width = 512
height = 256
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
fov_y = 40.0
near = 1.0
far = 20.0
[[mesh]]
kind = "plane"
size = 20.0
detail = 16
rotate = [0.0, 35.0, 0.0]
"#,
    )?;
    base.sirds.pattern = SirdsPattern::BlackWhite { seed: 5 };
    Ok(base)
}

/// Every accuracy knob on the Fig. 5 ramp at 512×256: time to make the SIRDS from the depth
/// pass, and the decoded separation's RMS error (share within ±1 px in the note).
fn knobs(iters: usize) -> Result<Vec<Row>> {
    let base = ramp_scene()?;
    let frame = render(&base, &Plan::new(&[Output::Sirds]))?;
    let (depth, _) = scene_depth(&frame, &base)?;
    let mut variants: Vec<(&str, String, Scene)> = Vec::new();
    for (start, filter) in [
        (StripStart::Left, StripFilter::Nearest),
        (StripStart::Left, StripFilter::Bilinear),
        (StripStart::Center, StripFilter::Nearest),
        (StripStart::Center, StripFilter::Bilinear),
    ] {
        let mut s = base.clone();
        s.sirds.per_vertex = PerVertexOptions {
            start,
            filter,
            iterations: None,
        };
        variants.push(("strip start/filter", format!("{start:?} {filter:?}"), s));
    }
    for (hidden_surface, oversample) in [(false, 1), (true, 1), (true, 2), (true, 4)] {
        let mut s = base.clone();
        s.sirds.algorithm = SirdsAlgorithm::PerPixel;
        s.sirds.per_pixel = PerPixelOptions {
            hidden_surface,
            oversample,
            ..PerPixelOptions::default()
        };
        variants.push((
            "TIW hsr/oversample",
            format!("hsr={hidden_surface} x{oversample}"),
            s,
        ));
    }
    let mut rows = Vec::new();
    for (knob, setting, s) in variants {
        let sirds = from_frame(&frame, &s)?;
        let d = sirds.disparity;
        let opts = SirdsDecodeOptions::for_disparity(&d);
        let decoded = decode_sirds(&sirds.pixels, sirds.width, sirds.height, &opts)?;
        let intended: Vec<f32> = depth.z.iter().map(|&z| d.separation(z)).collect();
        let rt = sirds_round_trip(&decoded, &intended, &opts);
        let ms = median_ms(iters, || from_frame(&frame, &s).is_ok());
        rows.push(Row {
            area: "sirds".into(),
            knob: knob.into(),
            setting,
            error: Some(rt.rms),
            error_unit: "rms decoded sep, px".into(),
            ms,
            note: format!(
                "ramp 512x256: {:.1}% within ±1 px, {:.1}% matched",
                rt.within_one * 100.0,
                rt.matched * 100.0
            ),
        });
    }
    Ok(rows)
}

/// TIW on a 4096×3072 sphere over a ramp, in memory (the whole-process comparison with netpbm's
/// `pamstereogram` is done with hyperfine, see the issue note).
fn large_depth_map(iters: usize) -> Result<Vec<Row>> {
    let depth = sphere_over_ramp(4096, 3072);
    let d = stereolab_core::SirdsGeometry::default().to_pixels()?;
    let pattern = SirdsPattern::BlackWhite { seed: 1 };
    let mut rows = Vec::new();
    for hidden_surface in [false, true] {
        let opts = PerPixelOptions {
            hidden_surface,
            oversample: 1,
            ..PerPixelOptions::default()
        };
        per_pixel(&depth, &d, &pattern, &opts)?;
        let ms = median_ms(iters.min(3), || {
            per_pixel(&depth, &d, &pattern, &opts).is_ok()
        });
        rows.push(Row {
            area: "sirds".into(),
            knob: "TIW 4096x3072".into(),
            setting: format!("hsr={hidden_surface}"),
            error: None,
            error_unit: String::new(),
            ms,
            note: format!(
                "{:.0} Mpixel/s, in memory (no I/O)",
                4096.0 * 3072.0 / ms / 1e3
            ),
        });
    }
    Ok(rows)
}

/// Decoding without being told the separations: a per-pixel SIRDS of a 600×300 sphere over a
/// ramp decoded over the range its set-up produces (the old way), the full-range search
/// alone, and search + decode; error: RMS decoded separation; note: time against the known
/// range, in this run.
fn decode_search(iters: usize) -> Result<Vec<Row>> {
    use stereolab_core::{SeparationSearchOptions, decode_sirds_auto, search_separation};
    let (w, h) = (600, 300);
    let depth = sphere_over_ramp(w, h);
    let d = stereolab_core::SirdsGeometry::default().to_pixels()?;
    let pixels = per_pixel(
        &depth,
        &d,
        &SirdsPattern::BlackWhite { seed: 1 },
        &PerPixelOptions::default(),
    )?;
    let intended: Vec<f32> = depth.z.iter().map(|&z| d.separation(z)).collect();
    let known = SirdsDecodeOptions::for_disparity(&d);
    let so = SeparationSearchOptions::default();
    let rt_known = sirds_round_trip(&decode_sirds(&pixels, w, h, &known)?, &intended, &known);
    let auto = decode_sirds_auto(&pixels, w, h, &so)?;
    let rt_auto = match (&auto.decoded, &auto.options) {
        (Some(dec), Some(o)) => Some(sirds_round_trip(dec, &intended, o)),
        _ => None,
    };
    let t_known = median_ms(iters, || decode_sirds(&pixels, w, h, &known).is_ok());
    let t_search = median_ms(iters, || search_separation(&pixels, w, h, &so).is_ok());
    let t_auto = median_ms(iters, || decode_sirds_auto(&pixels, w, h, &so).is_ok());
    let row = |setting: String, rt: Option<SirdsRoundTrip>, ms: f64| Row {
        area: "sirds".into(),
        knob: "decode 600x300".into(),
        setting,
        error: rt.map(|r| r.rms),
        error_unit: "rms decoded sep, px".into(),
        ms,
        note: format!(
            "{:.2}x the known range{}",
            ms / t_known,
            rt.map(|r| format!(", {:.1}% within ±1 px", r.within_one * 100.0))
                .unwrap_or_default()
        ),
    };
    Ok(vec![
        row(
            format!(
                "known range {}..={} px",
                known.min_separation, known.max_separation
            ),
            Some(rt_known),
            t_known,
        ),
        row(
            format!("search {}..={} px", so.min_separation, w / 3),
            None,
            t_search,
        ),
        row(
            format!(
                "search + decode_sirds (found {:?})",
                auto.search.found.unwrap_or((0, 0))
            ),
            rt_auto,
            t_auto,
        ),
    ])
}

/// Median wall time of `iters` runs of a whole process (stdout into `stdout`), after one
/// warm-up run; `Err` with what failed.
fn process_ms(
    iters: usize,
    program: &Path,
    args: &[&std::ffi::OsStr],
    stdout: &Path,
) -> std::result::Result<f64, String> {
    let run = || -> std::result::Result<(), String> {
        let out = std::fs::File::create(stdout).map_err(|e| e.to_string())?;
        let status = std::process::Command::new(program)
            .args(args)
            .stdout(out)
            .stderr(std::process::Stdio::null())
            .status()
            .map_err(|e| format!("{}: {e}", program.display()))?;
        if status.success() {
            Ok(())
        } else {
            Err(format!("{} exited with {status}", program.display()))
        }
    };
    run()?;
    let mut times = Vec::with_capacity(iters.max(1));
    for _ in 0..iters.max(1) {
        let t = std::time::Instant::now();
        run()?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    Ok(median(times))
}

/// TIW as a whole process against netpbm's `pamstereogram` on the same 4096×3072 16-bit PGM (a
/// sphere over a ramp), in the same run. `pamstereogram` writes a one-channel black-and-white
/// PAM (one byte a pixel); stereolab writes the same amount as a PGM (the goal's row), and,
/// for comparison, an RGB PPM (three bytes a pixel). All uncompressed, all to a file. Only
/// from the `stereolab` binary (it runs itself); a row says why when it cannot measure.
fn netpbm(iters: usize) -> Result<Vec<Row>> {
    let dir = std::env::temp_dir().join(format!("stereolab-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| stereolab_core::Error::io(&dir, e))?;
    let map = dir.join("sphere_over_ramp.pgm");
    sphere_over_ramp(4096, 3072)
        .to_image()
        .save(&map)
        .map_err(|e| stereolab_core::Error::io(&map, std::io::Error::other(e.to_string())))?;
    let ours = std::env::current_exe()
        .map_err(|e| stereolab_core::Error::io(Path::new("current_exe"), e))?;
    let row = |setting: &str, ms: f64, note: String| Row {
        area: "sirds".into(),
        knob: "TIW vs pamstereogram".into(),
        setting: setting.into(),
        error: None,
        error_unit: String::new(),
        ms,
        note,
    };
    let is_stereolab = ours
        .file_stem()
        .is_some_and(|n| n.to_string_lossy() == "stereolab");
    let run_ours = |ext: &str| {
        let out = dir.join(format!("ours.{ext}"));
        let args: Vec<&std::ffi::OsStr> = vec![
            "sirds".as_ref(),
            "--depth".as_ref(),
            map.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ];
        process_ms(iters, &ours, &args, &dir.join("ours.log"))
    };
    let result = if is_stereolab {
        // Interleaved, so that a slow spell of the machine does not fall on one program only.
        run_ours("pgm").and_then(|pgm| {
            let netpbm = process_ms(
                iters,
                Path::new("pamstereogram"),
                &[map.as_os_str()],
                &dir.join("netpbm.pam"),
            )?;
            Ok((pgm, netpbm, run_ours("ppm")?))
        })
    } else {
        Err("only measured from the stereolab binary".into())
    };
    let _ = std::fs::remove_dir_all(&dir);
    Ok(match result {
        Ok((pgm, netpbm, ppm)) => vec![
            row(
                "stereolab sirds --depth (hsr) -> PGM",
                pgm,
                format!(
                    "4096x3072 16-bit PGM -> 8-bit PGM (1 byte/pixel, as netpbm's), whole process; ours/netpbm time = {:.2} (goal <= 0.5)",
                    pgm / netpbm
                ),
            ),
            row(
                "stereolab sirds --depth (hsr) -> PPM",
                ppm,
                format!(
                    "4096x3072 16-bit PGM -> PPM (3 bytes/pixel), whole process; ours/netpbm time = {:.2}",
                    ppm / netpbm
                ),
            ),
            row(
                "pamstereogram",
                netpbm,
                "4096x3072 16-bit PGM -> black-and-white PAM (1 byte/pixel), whole process (netpbm, plain algorithm)".into(),
            ),
        ],
        Err(why) => vec![row(
            "pamstereogram",
            f64::NAN,
            format!("not measured: {why}"),
        )],
    })
}

/// All SIRDS rows.
///
/// # Errors
/// A scene or SIRDS error.
pub fn rows(iters: usize) -> Result<Vec<Row>> {
    let mut rows = table_1(iters)?;
    rows.extend(knobs(iters.min(5))?);
    rows.extend(large_depth_map(iters)?);
    rows.extend(decode_search(iters.min(5))?);
    rows.extend(netpbm(iters.min(5))?);
    Ok(rows)
}
