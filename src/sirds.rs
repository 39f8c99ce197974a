//! `stereolab sirds`: autostereograms from a scene or a depth-map image, animations, decoding.

use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use stereolab::output::animate::{AnimationOptions, animate};
use stereolab::output::sirds::{from_frame, save, stream_depth_map};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab_core::{
    DepthMap, Error, Near, Result, SirdsSettings, depth_from_separation, from_depth_map,
};

/// Arguments of `stereolab sirds`.
#[derive(clap::Args, Debug)]
pub struct SirdsArgs {
    /// Scene file (TOML): its geometry and `[sirds]` table.
    pub scene: Option<PathBuf>,
    /// Make a SIRDS of this depth-map image instead with the per-pixel algorithm: 8- or 16-bit
    /// PNG, netpbm PGM/PPM/PAM (full scale: v / max), or float PFM (its own min..max).
    #[arg(long, conflicts_with = "scene")]
    pub depth: Option<PathBuf>,
    /// With --depth only: which values are near, `white` (larger; netpbm, stereolab's
    /// sirds_depth; the default unless the file says otherwise, as stereolab's left_depth.png
    /// and right_depth.png do) or `black` (smaller; distance maps, Z-buffers).
    // No clap default, so that `report` sees whether it was given: clap drops `requires`
    // when the required argument conflicts with one present (a scene, --decode).
    #[arg(long, value_parser = ["white", "black"], requires = "depth")]
    pub near: Option<String>,
    /// With --depth only: a mapped-texture stereogram colored by this image (the scene
    /// field `sirds.texture`; best the depth map's size, at least the largest separation
    /// wide).
    #[arg(long, requires = "depth", value_name = "FILE")]
    pub texture: Option<PathBuf>,
    /// Decode this autostereogram: write the depth it encodes to --out and say whether it is
    /// one at all. With a scene (its `[sirds]` table) or `--set sirds.*` flags the decoder is
    /// told the viewing set-up: it decodes over that model's separations (eq. 1 or eq. 3,
    /// wall- or cross-eyed) instead of searching for them.
    #[arg(long, conflicts_with_all = ["depth", "frames"])]
    pub decode: Option<PathBuf>,
    /// Output file, written in the format its extension names (case ignored): .png, .jpg /
    /// .jpeg, .gif (one frame), or .ppm / .pnm / .pgm (uncompressed; .pgm for gray patterns,
    /// one byte a pixel); with --frames a .gif; with --decode a .png or .pgm (16-bit), .pam
    /// (16-bit), .ppm / .pnm or .jpg / .jpeg (8-bit). Any other name is refused before any
    /// work. Default sirds.png, or sirds.gif with --frames.
    #[arg(long, short)]
    pub out: Option<PathBuf>,
    /// Override a `[sirds]` field, e.g. --set sirds.dpi=100 (repeatable; with a scene any
    /// scene field).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Animate: this many frames of the model turning once, written as a GIF.
    #[arg(long, requires = "scene")]
    pub frames: Option<u32>,
    /// Animation: keep one random-dot seed in every frame (default: a new pattern per frame).
    #[arg(long, requires = "frames")]
    pub fixed_seed: bool,
    /// With --decode: also write the views the viewer's eyes see (left.png, right.png) and a
    /// red–cyan anaglyph of them (anaglyph.png) into this folder.
    #[arg(long, requires = "decode", value_name = "DIR")]
    pub pair: Option<PathBuf>,
}

/// Whether `path` ends in one of `extensions` (ASCII case ignored).
fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The extensions a decoded depth map may be named with ([`encode_depth`]).
const DEPTH_EXTENSIONS: [&str; 7] = ["png", "pgm", "ppm", "pnm", "pam", "jpg", "jpeg"];

/// The output's name (`--out`, or sirds.png / sirds.gif with `--frames`), refused before any
/// work when its extension names a container this mode does not write: an animation is a GIF,
/// a decoded depth map one of [`DEPTH_EXTENSIONS`], a still SIRDS one of
/// [`STILL_EXTENSIONS`](stereolab::output::sirds::STILL_EXTENSIONS).
fn output_name(args: &SirdsArgs) -> Result<PathBuf> {
    let out = match (&args.out, args.frames) {
        (Some(out), _) => out.clone(),
        (None, Some(_)) => PathBuf::from("sirds.gif"),
        (None, None) => PathBuf::from("sirds.png"),
    };
    if args.frames.is_some() {
        if !has_extension(&out, &["gif"]) {
            return Err(Error::invalid(
                "--out",
                out.display(),
                "an animation (--frames) is written as GIF: name the file .gif",
            ));
        }
    } else if args.decode.is_some() {
        if !has_extension(&out, &DEPTH_EXTENSIONS) {
            return Err(stereolab::output::sirds::unsupported_extension(
                &out,
                &DEPTH_EXTENSIONS,
            ));
        }
    } else {
        stereolab::output::sirds::StillFormat::of(&out)?;
    }
    Ok(out)
}

/// Runs `stereolab sirds`.
///
/// # Errors
/// Any input, render or write error.
pub fn run(args: &SirdsArgs) -> Result<()> {
    out!("{}", report(args)?);
    Ok(())
}

/// What `stereolab sirds` prints, after doing the work.
fn report(args: &SirdsArgs) -> Result<String> {
    if let (Some(near), None) = (&args.near, &args.depth) {
        return Err(Error::invalid(
            "--near",
            near,
            "--near applies to --depth only (which values of a depth map are near); a scene or \
             --decode has no depth map to read it for",
        ));
    }
    let out = output_name(args)?;
    if let Some(path) = &args.decode {
        return decode_report(args, path, &out);
    }
    if let Some(path) = &args.depth {
        // `--texture FILE` is `--set sirds.texture="FILE"`.
        let mut sets = args.sets.clone();
        if let Some(texture) = &args.texture {
            let path = toml::Value::String(texture.display().to_string());
            sets.push(format!("sirds.texture={path}"));
        }
        let settings = stereolab::scene::sirds_settings_from_sets(&sets)?;
        // `--near` when given; else what the file says (stereolab's own window depth: black
        // is near); else white, netpbm's convention.
        let told = stereolab_core::near_of_file(path).filter(|_| args.near.is_none());
        let near = match &args.near {
            Some(word) => Near::parse(word)?,
            None => told.unwrap_or(Near::White),
        };
        let d = settings.geometry.to_pixels()?;
        let netpbm = stereolab::output::sirds::Netpbm::of(&out).is_some();
        let (w, h, mapping) = super::with_spinner("making the autostereogram", || {
            if netpbm && !settings.guide_dots && settings.guide_boxes.is_none() {
                stream_depth_map(path, near, &settings, &out)
            } else {
                let (map, mapping) = DepthMap::load_with(path, near)?;
                let sirds = from_depth_map(map, &settings)?;
                save(&sirds.pixels, sirds.width, sirds.height, &out)?;
                Ok((sirds.width, sirds.height, mapping))
            }
        })?;
        let note = if told.is_some() {
            "  the file is stereolab's window depth (black near): read as with --near black\n"
        } else {
            ""
        };
        return Ok(format!(
            "per-pixel SIRDS of {} ({w}x{h}), separations {:.1}..{:.1} px\n{note}  depth map {mapping}\n  wrote {}\n",
            path.display(),
            d.min_separation(),
            d.max_separation(),
            out.display()
        ));
    }
    let scene_path = args
        .scene
        .as_ref()
        .ok_or_else(|| Error::invalid("sirds", "no input", "give a scene, --depth or --decode"))?;
    let scene = super::load_scene(scene_path, &args.sets, None)?;
    if let Some(frames) = args.frames {
        let opts = AnimationOptions {
            frames,
            fixed_seed: args.fixed_seed,
            ..AnimationOptions::default()
        };
        let bar = ProgressBar::new(u64::from(frames));
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {elapsed} (eta {eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        animate(&scene, &opts, &out, |done, _| {
            bar.set_position(u64::from(done))
        })?;
        bar.finish_and_clear();
        return Ok(format!(
            "animated {frames} frames of {}\n  wrote {}\n",
            scene_path.display(),
            out.display()
        ));
    }
    let frame = render(&scene, &Plan::new(&[Output::Sirds]))?;
    let sirds = from_frame(&frame, &scene)?;
    save(&sirds.pixels, sirds.width, sirds.height, &out)?;
    Ok(format!(
        "{:?} SIRDS of {} ({}x{}){}\n  wrote {}\n",
        scene.sirds.algorithm,
        scene_path.display(),
        sirds.width,
        sirds.height,
        sirds
            .iterations
            .map(|k| format!(", k = {k} strip iterations"))
            .unwrap_or_default(),
        out.display()
    ))
}

/// Runs `work`, which reports `(bands done, bands)`, with a progress bar on a terminal's
/// stderr once it has run a second: the share of the rows decoded, the time elapsed and an
/// estimate of the rest (never into a pipe or a file).
fn with_rows_bar<T>(what: &str, work: impl FnOnce(&(dyn Fn(usize, usize) + Sync)) -> T) -> T {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::hidden())
        .with_message(what.to_string());
    if let Ok(style) = ProgressStyle::with_template(
        "{msg} {bar:30} {percent}% of the rows, {elapsed} (about {eta} left)",
    ) {
        bar.set_style(style);
    }
    let shown = std::sync::Once::new();
    // Bands finish in any order: each call adds one.
    let result = work(&|_, of| {
        bar.set_length(of as u64);
        bar.inc(1);
        if bar.elapsed() > std::time::Duration::from_secs(1) {
            shown.call_once(|| bar.set_draw_target(ProgressDrawTarget::stderr()));
        }
    });
    bar.finish_and_clear();
    result
}

/// `stereolab sirds --decode`: searches the full plausible separation range, decodes, writes
/// the depth (and with `--pair` the two views and their anaglyph); returns the report.
fn decode_report(args: &SirdsArgs, path: &Path, out: &Path) -> Result<String> {
    use stereolab_core::{SeparationSearchOptions, decode_sirds_auto_reporting, nearness_linear};

    // Told the set-up: by the scene's [sirds] table (with --set applied), or by --set alone.
    let told = args.scene.is_some() || !args.sets.is_empty();
    let settings = match &args.scene {
        Some(scene) => super::load_scene(scene, &args.sets, None)?.sirds,
        None => stereolab::scene::sirds_settings_from_sets(&args.sets)?,
    };
    let img = stereolab_core::open_image(path, "image")?.to_rgba8();
    let (w, h) = img.dimensions();
    let pixels: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    if told {
        return decode_told(args, path, out, &settings, &pixels, w, h);
    }
    let auto = with_rows_bar(&format!("decoding {}", path.display()), |progress| {
        decode_sirds_auto_reporting(&pixels, w, h, &SeparationSearchOptions::default(), progress)
    })
    .map_err(|e| e.in_file(path))?;
    let search = &auto.search;
    let mut report = format!(
        "{}: searched separations {}..={} px",
        path.display(),
        search.searched.0,
        search.searched.1
    );
    if search.strips.0 < search.strips.1 {
        report += &format!(
            " in {} of its {} strips of 7 rows (the work budget)",
            search.strips.0, search.strips.1
        );
    }
    let (Some(decoded), Some((lo, hi))) = (&auto.decoded, search.found) else {
        return Err(Error::invalid(
            "--decode",
            path.display(),
            format!(
                "{report}: only {:.1}% of the image repeats, in no region consistently: not an autostereogram (no consistent repetition), nothing written",
                search.matched_share * 100.0
            ),
        ));
    };
    // The regions that made the range (not those left out as harmonics).
    let dominant: Vec<u32> = search
        .regions
        .iter()
        .map(|r| r.dominant)
        .filter(|d| (lo..=hi).contains(d))
        .collect();
    report += &format!(
        "\n  found {lo}..={hi} px (dominant repeat per region: {}..={} px in {} regions)\n",
        dominant.iter().min().copied().unwrap_or(lo),
        dominant.iter().max().copied().unwrap_or(hi),
        dominant.len()
    );
    // Depth: through the viewing model when the user named the set-up (--set), else linear
    // in the range found (near repeats sooner when wall-eyed, later when cross-eyed).
    // Not told the set-up: depth linear in the range found (near repeats sooner when
    // wall-eyed, later when cross-eyed).
    let (near, far) = if settings.cross_eyed {
        (hi as f32, lo as f32)
    } else {
        (lo as f32, hi as f32)
    };
    report += &format!(
        "  depth: linear in separation, {near} px = white (near) .. {far} px = black (far)\n"
    );
    let z = nearness_linear(decoded, near, far);
    let range = auto
        .options
        .map_or((lo, hi), |o| (o.min_separation, o.max_separation));
    report += &finish_decode(args, out, &pixels, (w, h), decoded, z, range, &settings)?;
    Ok(report)
}

/// `--decode` told the viewing set-up (a scene or `--set sirds.*`): decodes over the
/// separations the model can produce ([`SirdsDecodeOptions::for_disparity`]), no search, and maps
/// separation to depth through the model (eq. 1 or eq. 3; cross-eyed inverts depth).
#[allow(clippy::too_many_arguments)]
fn decode_told(
    args: &SirdsArgs,
    path: &Path,
    out: &Path,
    settings: &SirdsSettings,
    pixels: &[[u8; 4]],
    w: u32,
    h: u32,
) -> Result<String> {
    use stereolab_core::{
        DecodedSirds, SirdsDecodeOptions, decode_sirds_reporting, matched_share_where_all_fit,
    };
    let d = settings.geometry.to_pixels()?;
    let opts = SirdsDecodeOptions::for_disparity(&d);
    let decoded = with_rows_bar(&format!("decoding {}", path.display()), |progress| {
        decode_sirds_reporting(pixels, w, h, &opts, progress)
    })
    .map_err(|e| e.in_file(path))?;
    let mut report = format!(
        "{}: told the viewing set-up ({}): the {} model, {}, separations {:.1}..{:.1} px\n  \
         depth: through that model\n",
        path.display(),
        if args.scene.is_some() {
            "the scene's [sirds]"
        } else {
            "--set"
        },
        match d.model {
            stereolab_core::DisparityModel::ViewAngle => "eq. 1 (constant view angle)",
            stereolab_core::DisparityModel::EyeDistance => "eq. 3 (constant eye distance)",
        },
        if settings.cross_eyed {
            "cross-eyed"
        } else {
            "wall-eyed"
        },
        d.min_separation(),
        d.max_separation(),
    );
    let z = depth_from_separation(&decoded, &d)
        .into_iter()
        .map(|z| if settings.cross_eyed { 1.0 - z } else { z })
        .collect();
    let range = (opts.min_separation, opts.max_separation);
    // Judged where every separation of the model fits (see matched_share_where_all_fit).
    let share = matched_share_where_all_fit(&decoded, &opts);
    report += &format!(
        "  {:.1}% of the pixels where every separation of the model fits matched\n",
        share * 100.0
    );
    let judged = DecodedSirds {
        matched_share: share,
        ..decoded
    };
    report += &finish_decode(args, out, pixels, (w, h), &judged, z, range, settings)?;
    Ok(report)
}

/// Writes the decoded depth (and with `--pair` the views and their anaglyph); returns the
/// verdict and what was written. An image that is no autostereogram (less than
/// [`AUTOSTEREOGRAM_SHARE`](stereolab_core::AUTOSTEREOGRAM_SHARE) of its pixels matched) is
/// refused with the share measured, and nothing is written.
#[allow(clippy::too_many_arguments)]
fn finish_decode(
    args: &SirdsArgs,
    out: &Path,
    pixels: &[[u8; 4]],
    (w, h): (u32, u32),
    decoded: &stereolab_core::DecodedSirds,
    z: Vec<f32>,
    (lo, hi): (u32, u32),
    settings: &SirdsSettings,
) -> Result<String> {
    use stereolab_core::{
        AUTOSTEREOGRAM_SHARE, AnaglyphKind, AnaglyphOptions, anaglyph, sirds_views,
    };
    if !decoded.is_autostereogram() {
        return Err(Error::invalid(
            "--decode",
            args.decode.as_deref().unwrap_or(out).display(),
            format!(
                "only {:.1}% of the pixels matched a separation in {lo}..={hi} px, and an \
                 autostereogram matches at least {:.0}%: not an autostereogram (no consistent \
                 repetition), nothing written",
                decoded.matched_share * 100.0,
                AUTOSTEREOGRAM_SHARE * 100.0
            ),
        ));
    }
    let z = z
        .into_iter()
        .map(|z| {
            if z.is_finite() {
                z.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
        .collect();
    let depth = encode_depth(
        &DepthMap {
            width: w,
            height: h,
            z,
        },
        out,
    )?;
    // The depth map and, with --pair, the views: all written, or none.
    let mut set = stereolab_core::OutputSet::new();
    let mut report = format!(
        "  {:.1}% of pixels matched a separation in {lo}..={hi} px: an autostereogram\n  wrote {}\n",
        decoded.matched_share * 100.0,
        out.display()
    );
    if let Some(dir) = &args.pair {
        let v = sirds_views(pixels, decoded, settings.cross_eyed)?;
        let fb = |color: Vec<[u8; 4]>| -> Result<stereolab_core::Framebuffer> {
            let depth = vec![1.0; color.len()];
            stereolab_core::Framebuffer::from_buffers(w, h, color, depth)
        };
        let (left, right) = (fb(v.left)?, fb(v.right)?);
        let ana = anaglyph(
            &left,
            &right,
            AnaglyphKind::DuboisRedCyan,
            AnaglyphOptions::default(),
        )?;
        let names = [
            dir.join("left.png"),
            dir.join("right.png"),
            dir.join("anaglyph.png"),
        ];
        for p in names.iter().chain([&out.to_path_buf()]) {
            stereolab_core::check_output_path(p)?;
        }
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        set.stage_bytes(out, &depth)?;
        set.stage_png(&names[0], &left.to_rgba_image())?;
        set.stage_png(&names[1], &right.to_rgba_image())?;
        set.stage_png(&names[2], &ana)?;
        report += &format!(
            "  stereo pair ({} viewing, background at zero parallax: {:.1} px)\n",
            if settings.cross_eyed {
                "cross-eyed"
            } else {
                "wall-eyed"
            },
            v.zero_parallax_separation
        );
        for p in names {
            report += &format!("  wrote {}\n", p.display());
        }
    } else {
        set.stage_bytes(out, &depth)?;
    }
    set.commit()?;
    Ok(report)
}

/// Encodes a decoded depth map (white = near) as `out`'s extension asks ([`DEPTH_EXTENSIONS`]):
/// PNG (16-bit), a .pgm as netpbm's binary P5 at 16 bits, a .ppm or .pnm as binary P6 (8-bit
/// gray in RGB), a .pam as PAM (16-bit `GRAYSCALE`), a .jpg or .jpeg as 8-bit gray JPEG.
fn encode_depth(map: &DepthMap, out: &Path) -> Result<Vec<u8>> {
    use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
    let depth = map.to_image();
    let ext = out
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut bytes = std::io::Cursor::new(Vec::new());
    let encoded = match ext.as_str() {
        "png" => {
            image::DynamicImage::ImageLuma16(depth).write_to(&mut bytes, image::ImageFormat::Png)
        }
        "pgm" => {
            // P5 with maxval 65535: two bytes a sample, most significant first (netpbm).
            let (w, h) = depth.dimensions();
            let b = bytes.get_mut();
            b.extend_from_slice(format!("P5\n{w} {h}\n65535\n").as_bytes());
            b.extend(depth.as_raw().iter().flat_map(|v| v.to_be_bytes()));
            Ok(())
        }
        "ppm" | "pnm" => {
            let sub = PnmSubtype::Pixmap(SampleEncoding::Binary);
            image::DynamicImage::ImageLuma16(depth)
                .into_rgb8()
                .write_with_encoder(PnmEncoder::new(&mut bytes).with_subtype(sub))
        }
        // The image crate's netpbm encoder writes 16-bit gray as PAM when not told a subtype.
        "pam" => depth.write_with_encoder(PnmEncoder::new(&mut bytes)),
        "jpg" | "jpeg" => image::DynamicImage::ImageLuma16(depth)
            .into_luma8()
            .write_with_encoder(image::codecs::jpeg::JpegEncoder::new_with_quality(
                &mut bytes,
                stereolab::output::sirds::JPEG_QUALITY,
            )),
        _ => {
            return Err(stereolab::output::sirds::unsupported_extension(
                out,
                &DEPTH_EXTENSIONS,
            ));
        }
    };
    encoded.map_err(|e| Error::invalid("--out", out.display(), e.to_string()))?;
    Ok(bytes.into_inner())
}
