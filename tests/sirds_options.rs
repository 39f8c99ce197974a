//! pamstereogram's options in `[sirds]`: mapped textures, tileable rows, depth planes and guide
//! boxes, each encoded from a known depth and decoded back, and checked against netpbm's
//! `pamstereogram` itself where it makes the same kind.

use std::path::Path;

use stereolab::fixtures::sphere_over_ramp;
use stereolab::output::sirds::from_frame;
use stereolab::plan::Plan;
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{
    DepthMap, Disparity, GuideBoxes, GuidePlace, PerPixelOptions, SirdsDecodeOptions,
    SirdsGeometry, SirdsPattern, SirdsSettings, SirdsSpec, SirdsTexture, decode_sirds,
    decode_sirds_auto, draw_guide_boxes, left_of_pair, per_pixel, plane_nearness, plane_separation,
    sirds_round_trip,
};

use crate::common::{self, asset};

/// TIW's whole-pixel separation of nearness `z` (`(int)(s + 0.5)`).
fn whole(d: &Disparity, z: f32) -> usize {
    (d.separation(z) + 0.5) as usize
}

/// A fixed LCG, so the textures are the same every run.
fn lcg(state: &mut u64) -> u32 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 33) as u32
}

/// A `w × h` texture of random colors, black (the background, also the top-left texel) where
/// `background(x, y)`.
fn noise_texture(w: u32, h: u32, background: impl Fn(u32, u32) -> bool) -> image::RgbaImage {
    let mut state = 7;
    image::RgbaImage::from_fn(w, h, |x, y| {
        let v = lcg(&mut state);
        if background(x, y) || (x, y) == (0, 0) {
            image::Rgba([0, 0, 0, 255])
        } else {
            image::Rgba([(v >> 16) as u8 | 1, (v >> 8) as u8, v as u8, 255])
        }
    })
}

fn textured(texture: image::RgbaImage, base: SirdsPattern) -> SirdsPattern {
    let background = texture.get_pixel(0, 0).0;
    SirdsPattern::Textured(std::sync::Arc::new(SirdsTexture {
        texture,
        background,
        base,
    }))
}

fn no_hsr() -> PerPixelOptions {
    PerPixelOptions {
        hidden_surface: false,
        ..PerPixelOptions::default()
    }
}

/// On a flat background every pixel `l` with `l + s` inside the row is linked to `l + s`, so
/// the sets are the residues mod `s`; each must hold the rounded mean of its non-black texels
/// (computed here from the texture directly), or one color throughout where all are black.
/// Black is the background as the texture's top-left pixel, and as `texture_background` of a
/// texture whose top-left pixel is red (that red then counts in its set's mean).
#[test]
fn mapped_texture_sets_take_the_mean_of_their_non_background_texels() {
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (w, h) = (400u32, 6u32);
    let map = DepthMap::new(w, h, vec![0.0; (w * h) as usize]).expect("map");
    // A quarter of the texels black; whole residue classes black in row 3.
    let s = whole(&d, 0.0);
    let texture = noise_texture(w, h, |x, y| {
        (x * 7 + y * 5) % 4 == 0 || (y == 3 && x % s as u32 == 5)
    });
    let mut red_corner = texture.clone();
    red_corner.put_pixel(0, 0, image::Rgba([255, 0, 0, 255]));
    let dir = common::out_dir("sirds_options_means");
    red_corner.save(dir.join("red_corner.png")).expect("png");
    let spec =
        spec("texture = \"red_corner.png\"\ntexture_background = [0, 0, 0]\ndots = \"gray\"");
    let root = stereolab_core::InputRoot::anywhere(&dir);
    let from_file = SirdsSettings::from_spec(&spec, &root)
        .expect("valid")
        .pattern;
    for (texture, pattern) in [
        (
            texture.clone(),
            textured(texture, SirdsPattern::Gray { seed: 4 }),
        ),
        (red_corner, from_file),
    ] {
        let px = per_pixel(&map, &d, &pattern, &no_hsr()).expect("mts");
        let (mut checked, mut background_sets) = (0, 0);
        for y in 0..h {
            for c in 0..s {
                let members: Vec<u32> = (c as u32..w).step_by(s).collect();
                let texels: Vec<[u8; 4]> = members
                    .iter()
                    .map(|&x| texture.get_pixel(x, y).0)
                    .filter(|t| *t != [0, 0, 0, 255])
                    .collect();
                let got: Vec<[u8; 4]> = members.iter().map(|&x| px[(y * w + x) as usize]).collect();
                assert!(
                    got.iter().all(|&g| g == got[0]),
                    "row {y} class {c}: one color"
                );
                if texels.is_empty() {
                    background_sets += 1;
                    continue;
                }
                let n = texels.len() as u32;
                let mean = |k: usize| {
                    ((texels.iter().map(|t| u32::from(t[k])).sum::<u32>() + n / 2) / n) as u8
                };
                assert_eq!(
                    got[0],
                    [mean(0), mean(1), mean(2), 255],
                    "row {y} class {c}"
                );
                checked += 1;
            }
        }
        assert!(
            checked > 400 && background_sets >= 1,
            "{checked} sets, {background_sets} black"
        );
    }
}

/// The sphere over a ramp as an MTS (a noise texture, black in every 5th column), decoded with the decoder told the set-up: within ±1 px of the
/// intended separation for at least 80% of the pixels (measured 83.4%), within 5 points of the
/// same map with plain color dots (84.1%).
#[test]
fn mapped_texture_decodes_to_its_depth() {
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (w, h) = (480u32, 160u32);
    let map = sphere_over_ramp(w, h);
    let intended: Vec<f32> = map.z.iter().map(|&z| d.separation(z)).collect();
    // Black (background, left out of the means) in every 5th column.
    let texture = noise_texture(w, h, |x, _| x % 5 == 0);
    let opts = SirdsDecodeOptions::for_disparity(&d);
    let mut report = String::new();
    let mut shares = Vec::new();
    for (name, pattern) in [
        (
            "texture",
            textured(texture, SirdsPattern::Color { seed: 2 }),
        ),
        ("color dots", SirdsPattern::Color { seed: 2 }),
    ] {
        let px = per_pixel(&map, &d, &pattern, &PerPixelOptions::default()).expect("sirds");
        let decoded = decode_sirds(&px, w, h, &opts).expect("decodes");
        let rt = sirds_round_trip(&decoded, &intended, &opts);
        report += &format!(
            "{name}: within ±1 px {:.1}%, rms {:.2} px, matched {:.1}%\n",
            rt.within_one * 100.0,
            rt.rms,
            rt.matched * 100.0
        );
        shares.push(rt.within_one);
    }
    eprintln!("{report}");
    assert!(shares[0] >= 0.80, "{report}");
    assert!(shares[0] >= shares[1] - 0.05, "{report}");
}

fn rgba_of(path: &Path) -> (Vec<[u8; 4]>, u32, u32) {
    let img = image::open(path)
        .expect("the image crate reads PAM")
        .to_rgba8();
    let (w, h) = img.dimensions();
    (img.pixels().map(|p| p.0).collect(), w, h)
}

/// pamstereogram's own MTS (`-texfile`, a noise disc on black, the depth map's size) decoded by
/// stereolab untold: the median separation off the disc is the far plane's 128 px, on the disc
/// a nearer one (measured: 128.0 px and 102.0 px; 65.9% of the pixels matched, found
/// 62..=128 px).
#[test]
fn pamstereograms_mapped_texture_decodes_with_stereolab() {
    let dir = common::out_dir("sirds_options_mts");
    let (w, h) = (600u32, 240u32);
    let inside = |x: u32, y: u32| {
        let (dx, dy) = (x as f32 + 0.5 - 300.0, y as f32 + 0.5 - 120.0);
        dx * dx + dy * dy < 90.0 * 90.0
    };
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend((0..h).flat_map(|y| (0..w).map(move |x| if inside(x, y) { 255u8 } else { 0 })));
    let texture = noise_texture(w, h, |x, y| !inside(x, y));
    let mut ppm = format!("P6\n{w} {h}\n255\n").into_bytes();
    ppm.extend(texture.pixels().flat_map(|p| [p[0], p[1], p[2]]));
    let (map, tex, out) = (
        dir.join("disc.pgm"),
        dir.join("tex.ppm"),
        dir.join("mts.pam"),
    );
    std::fs::write(&map, pgm).expect("map");
    std::fs::write(&tex, ppm).expect("texture");
    let tex_arg = format!("-texfile={}", tex.display());
    common::pamstereogram(
        &["-randomseed=1", &tex_arg, map.to_str().expect("utf-8")],
        &out,
    );
    let (px, iw, ih) = rgba_of(&out);
    assert_eq!((iw, ih), (w, h));
    let auto = decode_sirds_auto(&px, w, h, &Default::default()).expect("decodes");
    let (lo, hi) = auto.search.found.expect("a range found");
    let decoded = auto.decoded.as_ref().expect("decoded");
    let median = |want: bool| {
        let mut v: Vec<f32> = decoded
            .separation
            .iter()
            .enumerate()
            .filter(|&(i, s)| s.is_finite() && inside(i as u32 % w, i as u32 / w) == want)
            .map(|(_, &s)| s)
            .collect();
        v.sort_by(f32::total_cmp);
        (v[v.len() / 2], v.len())
    };
    let (disc, n_disc) = median(true);
    let (back, n_back) = median(false);
    let report = format!(
        "found {lo}..={hi} px, matched {:.1}%, disc {disc:.1} px over {n_disc}, background {back:.1} px over {n_back}",
        auto.matched_share() * 100.0
    );
    eprintln!("{report}");
    assert!(auto.is_autostereogram(), "{report}");
    assert!(
        (125.0..=131.0).contains(&back) && n_back > 40_000,
        "{report}"
    );
    assert!(
        disc < 112.0 && n_disc > 3_000,
        "the disc is nearer: {report}"
    );
}

/// Tileable rows: for every pixel's point the two linked pixels, taken around the row, have
/// one color (hidden-surface removal off, so every point links), computed here from the depth
/// and [`left_of_pair`]; pairs that wrap exist, and the same map without `tileable` breaks them.
#[test]
fn tileable_links_hold_across_the_wrap() {
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (w, h) = (333u32, 40u32);
    let map = sphere_over_ramp(w, h);
    let check = |px: &[[u8; 4]]| {
        let (mut wrapped, mut broken) = (0, 0);
        for y in 0..h {
            for x in 0..w as usize {
                let s = whole(&d, map.at(x as u32, y));
                let l = left_of_pair(x, s, y).rem_euclid(w as isize) as usize;
                let r = (l + s) % w as usize;
                if r < l {
                    wrapped += 1;
                    let row = &px[(y * w) as usize..((y + 1) * w) as usize];
                    if row[l] != row[r] {
                        broken += 1;
                    }
                } else {
                    let row = &px[(y * w) as usize..((y + 1) * w) as usize];
                    assert_eq!(row[l], row[r], "row {y} x {x}");
                }
            }
        }
        (wrapped, broken)
    };
    let opts = PerPixelOptions {
        tileable: true,
        ..no_hsr()
    };
    let pattern = SirdsPattern::Gray { seed: 3 };
    let tiled = per_pixel(&map, &d, &pattern, &opts).expect("tileable");
    let (wrapped, broken) = check(&tiled);
    assert!(
        wrapped > 20 * h as usize && broken == 0,
        "{wrapped} wrapping pairs, {broken} broken"
    );
    let plain = per_pixel(
        &map,
        &d,
        &pattern,
        &PerPixelOptions {
            tileable: false,
            ..opts
        },
    )
    .expect("plain");
    let wrap_pairs = |px: &[[u8; 4]]| {
        let mut broken = 0;
        for y in 0..h {
            for x in 0..w as usize {
                let s = whole(&d, map.at(x as u32, y));
                let l = left_of_pair(x, s, y).rem_euclid(w as isize) as usize;
                let r = (l + s) % w as usize;
                if r < l && px[(y * w) as usize + l] != px[(y * w) as usize + r] {
                    broken += 1;
                }
            }
        }
        broken
    };
    assert!(
        wrap_pairs(&plain) > wrapped / 4,
        "without tileable the wrap is a seam"
    );
}

/// Two copies of a tileable SIRDS side by side decode across the seam: within ±1 px of the
/// tiled depth's separations in the columns around the seam, as well as elsewhere; the same
/// map without `tileable` does not (measured: 80.4% at the seam, 75.9% over the whole image;
/// 25.8% at the seam without `tileable`).
#[test]
fn tileable_sirds_decodes_across_the_seam() {
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (w, h) = (360u32, 120u32);
    let map = sphere_over_ramp(w, h);
    let opts = SirdsDecodeOptions::for_disparity(&d);
    let seam_share = |tileable: bool| {
        let px = per_pixel(
            &map,
            &d,
            &SirdsPattern::Color { seed: 6 },
            &PerPixelOptions {
                tileable,
                ..PerPixelOptions::default()
            },
        )
        .expect("sirds");
        let (tw, mut twice, mut intended) = (2 * w, Vec::new(), Vec::new());
        for y in 0..h as usize {
            let row = &px[y * w as usize..(y + 1) * w as usize];
            twice.extend_from_slice(row);
            twice.extend_from_slice(row);
            for x in 0..tw {
                intended.push(d.separation(map.at(x % w, y as u32)));
            }
        }
        let decoded = decode_sirds(&twice, tw, h, &opts).expect("decodes");
        // Only the columns whose windows straddle the seam: w ± 60.
        let near_seam: Vec<f32> = intended
            .iter()
            .enumerate()
            .map(|(i, &s)| {
                let x = i as u32 % tw;
                if x + 60 >= w && x < w + 60 {
                    s
                } else {
                    f32::NAN
                }
            })
            .collect();
        let (mut n, mut ok) = (0, 0);
        for (got, want) in decoded.separation.iter().zip(&near_seam) {
            if want.is_finite() {
                n += 1;
                if (got - want).abs() <= 1.0 {
                    ok += 1;
                }
            }
        }
        let all = sirds_round_trip(&decoded, &intended, &opts).within_one;
        (ok as f64 / n as f64, all)
    };
    let (tiled, tiled_all) = seam_share(true);
    let (plain, _) = seam_share(false);
    let report = format!(
        "seam ±60 columns within ±1 px: tileable {:.1}% (whole image {:.1}%), plain {:.1}%",
        tiled * 100.0,
        tiled_all * 100.0,
        plain * 100.0
    );
    eprintln!("{report}");
    assert!(tiled >= 0.75 && tiled >= tiled_all - 0.05, "{report}");
    assert!(plain < tiled - 0.3, "{report}");
}

/// pamstereogram's planes are the whole separations near..=far; with as many planes as that,
/// [`plane_separation`] rounds to them (ties excepted). With fewer, the planes are equally
/// spaced and each separation moves by at most half a step; [`plane_nearness`] lands on them.
#[test]
fn planes_are_equally_spaced_separations() {
    for i in 0..=1000 {
        let s = 40.0 + i as f32 * 0.01;
        if (s.fract() - 0.5).abs() < 1e-3 {
            continue;
        }
        assert_eq!(plane_separation(s, 40.0, 50.0, 11), s.round(), "s = {s}");
    }
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (s_near, s_far) = (d.separation(1.0), d.separation(0.0));
    for n in [2u32, 6, 17, 255] {
        let step = (s_far - s_near) / (n - 1) as f32;
        let mut seen = std::collections::BTreeSet::new();
        for i in 0..=2000 {
            let z = i as f32 / 2000.0;
            let q = d.separation(plane_nearness(z, &d, n));
            let k = ((s_far - q) / step).round();
            assert!(
                (q - (s_far - k * step)).abs() < 2e-3,
                "n {n} z {z}: {q} is no plane"
            );
            assert!(
                (q - d.separation(z)).abs() <= step / 2.0 + 2e-3,
                "n {n} z {z}"
            );
            seen.insert(k as u32);
        }
        assert_eq!(seen.len() as u32, n, "every plane used");
    }
}

/// The set-up under which stereolab's eq. 3 is pamstereogram's (and TIW's) separation
/// `round((1 − μz) E / (2 − μz))`: eyes `E` = 100 px (1 in at 100 DPI), viewing distance =
/// background depth, `μ = 1/3` (`-planes=40,50`: eyesep 2·50, depth 2·10/(100 − 40)).
fn pamstereogram_planes_setup() -> Disparity {
    SirdsGeometry {
        eye_separation_in: 1.0,
        dpi: 100.0,
        viewing_distance_in: 12.0,
        depth_far_in: 12.0,
        depth_near_in: 8.0,
        ..SirdsGeometry::default()
    }
    .to_pixels()
    .expect("valid")
}

/// A depth ramp down the rows (`v = 255 · y / (h − 1)` in row y), encoded with 6 planes and
/// decoded: each row's median separation is its plane's, within ±1 px, and 6 separations
/// occur.
#[test]
fn planes_decode_to_n_levels() {
    let d = SirdsGeometry::default().to_pixels().expect("valid");
    let (w, h) = (400u32, 180u32);
    let z: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |_| y as f32 / (h - 1) as f32))
        .collect();
    let map = DepthMap::new(w, h, z).expect("map");
    let n = 6;
    let opts = PerPixelOptions {
        planes: Some(n),
        ..PerPixelOptions::default()
    };
    let px = per_pixel(&map, &d, &SirdsPattern::Gray { seed: 8 }, &opts).expect("planes");
    let decoded = decode_sirds(&px, w, h, &SirdsDecodeOptions::for_disparity(&d)).expect("decodes");
    let (s_near, s_far) = (d.separation(1.0), d.separation(0.0));
    let want = |y: u32| plane_separation(d.separation(y as f32 / (h - 1) as f32), s_near, s_far, n);
    let hh = SirdsDecodeOptions::for_disparity(&d).half_height;
    let mut levels = std::collections::BTreeSet::new();
    let (mut off, mut compared) = (0, 0);
    for y in hh..h - hh {
        // Rows whose decoding window spans two planes are left out.
        if (y - hh..=y + hh).any(|v| want(v) != want(y)) {
            continue;
        }
        let mut row: Vec<f32> = decoded.separation[(y * w) as usize..((y + 1) * w) as usize]
            .iter()
            .copied()
            .filter(|s| s.is_finite())
            .collect();
        row.sort_by(f32::total_cmp);
        let median = row[row.len() / 2];
        compared += 1;
        if (median - want(y)).abs() > 1.0 {
            off += 1;
        }
        levels.insert(median.round() as i32);
    }
    eprintln!("rows off their plane: {off} of {compared}; decoded levels {levels:?}");
    assert!(
        compared > h / 2 && off == 0,
        "{off} of {compared} rows off their plane"
    );
    assert_eq!(levels.len(), n as usize, "{levels:?}");
}

/// pamstereogram `-planes=40,50` on a row ramp, decoded by stereolab: per row the whole
/// separation pamstereogram used; stereolab's planes (11 = 50 − 40 + 1) on the same 8-bit
/// ramp under the same set-up give the same separation row for row (left out: rows where the
/// exact separation is within 0.01 px of a half, which the two may round apart, and rows whose
/// decoding window spans two planes).
#[test]
fn pamstereograms_planes_decode_to_far_minus_near_plus_one_levels() {
    let dir = common::out_dir("sirds_options_planes");
    let (w, h) = (400u32, 256u32);
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend((0..h).flat_map(|y| (0..w).map(move |_| y as u8)));
    let (map, out) = (dir.join("ramp.pgm"), dir.join("planes.pam"));
    std::fs::write(&map, pgm).expect("map");
    common::pamstereogram(
        &[
            "-randomseed=1",
            "-planes=40,50",
            map.to_str().expect("utf-8"),
        ],
        &out,
    );
    let (px, iw, ih) = rgba_of(&out);
    assert_eq!((iw, ih), (w, h));
    let d = pamstereogram_planes_setup();
    assert!((d.separation(0.0) - 50.0).abs() < 1e-3 && (d.separation(1.0) - 40.0).abs() < 1e-3);
    let decoded = decode_sirds(&px, w, h, &SirdsDecodeOptions::for_disparity(&d)).expect("decodes");
    let (mut compared, mut agree, mut levels) = (0, 0, std::collections::BTreeSet::new());
    let ours = |y: u32| d.separation(plane_nearness(y as f32 / 255.0, &d, 11));
    let hh = SirdsDecodeOptions::for_disparity(&d).half_height;
    for y in hh..h - hh {
        let mut row: Vec<f32> = decoded.separation[(y * w) as usize..((y + 1) * w) as usize]
            .iter()
            .copied()
            .filter(|s| s.is_finite())
            .collect();
        row.sort_by(f32::total_cmp);
        let theirs = row[row.len() / 2].round();
        levels.insert(theirs as i32);
        let z = y as f32 / 255.0;
        // Rows at a half, or whose decoding window spans two planes, are left out.
        let spans = (y - hh..=y + hh).any(|v| (ours(v) - ours(y)).abs() > 0.01);
        if (d.separation(z).fract() - 0.5).abs() < 0.01 || spans {
            continue;
        }
        compared += 1;
        if (ours(y) - theirs).abs() < 0.01 {
            agree += 1;
        }
    }
    eprintln!(
        "pamstereogram -planes=40,50: levels {levels:?}; stereolab's 11 planes agree on {agree} of {compared} rows"
    );
    assert_eq!(levels, (40..=50).collect(), "far − near + 1 levels");
    assert!(compared > 150 && agree == compared, "{agree} of {compared}");
}

/// pamstereogram's guide band (`-guidetop -guidesize=10`, `-guidebottom -guidesize=7`,
/// default set-up: far separation 128 px) against [`draw_guide_boxes`] with the same size and
/// separation: the same black and white pixels, row for row.
#[test]
fn guide_boxes_match_pamstereograms_band() {
    let dir = common::out_dir("sirds_options_guides");
    let (w, h) = (300u32, 120u32);
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend(std::iter::repeat_n(0u8, (w * h) as usize));
    let map = dir.join("flat.pgm");
    std::fs::write(&map, pgm).expect("map");
    for (place, size, flag) in [
        (GuidePlace::Top, 10u32, "-guidetop"),
        (GuidePlace::Bottom, 7, "-guidebottom"),
    ] {
        let out = dir.join(format!("{flag}.pam"));
        let size_arg = format!("-guidesize={size}");
        common::pamstereogram(
            &[
                "-randomseed=1",
                flag,
                &size_arg,
                map.to_str().expect("utf-8"),
            ],
            &out,
        );
        let (theirs, iw, ih) = rgba_of(&out);
        let band = 3 * size;
        assert_eq!((iw, ih), (w, h + band), "pamstereogram adds the band");
        let mut ours = vec![[128, 128, 128, 255]; (w * h) as usize];
        draw_guide_boxes(&mut ours, w, h, 128.0, GuideBoxes { place, size }).expect("fits");
        let (their_rows, our_rows) = match place {
            GuidePlace::Top => (0..band, 0..band),
            _ => (h..h + band, h - band..h),
        };
        for (ty, oy) in their_rows.zip(our_rows) {
            let t = &theirs[(ty * w) as usize..((ty + 1) * w) as usize];
            let o = &ours[(oy * w) as usize..((oy + 1) * w) as usize];
            let dark = |p: &[u8; 4]| p[0] < 128;
            assert!(
                t.iter().map(dark).eq(o.iter().map(dark)),
                "{flag}: band row {ty} differs"
            );
        }
        let black = ours.iter().filter(|p| p[0] == 0).count() as u32;
        assert_eq!(black, 2 * size * size, "{flag}: two squares");
    }
}

fn spec(text: &str) -> SirdsSpec {
    toml::from_str(text).expect("parses")
}

fn settings(text: &str) -> stereolab_core::Result<SirdsSettings> {
    SirdsSettings::from_spec(
        &spec(text),
        &stereolab_core::InputRoot::anywhere(&asset("scenes")),
    )
}

fn field_of(r: stereolab_core::Result<impl std::fmt::Debug>) -> String {
    format!("{}", r.expect_err("must be refused"))
}

/// Bad values name their field and a remedy: planes outside 2..=255, a guide size of 0 or
/// without guides, a texture background without a texture or outside 0..=255, boxes that do not fit, a texture that is missing, not an image, too
/// narrow or too large, and the per-pixel options on a per-vertex scene.
#[test]
fn bad_option_values_name_their_field() {
    for (text, field) in [
        ("planes = 1", "sirds.planes"),
        ("planes = 256", "sirds.planes"),
        ("guides = \"top\"\nguide_size = 0", "sirds.guide_size"),
        ("guide_size = 10", "sirds.guide_size"),
        ("texture = \"textures/none.png\"", "sirds.texture"),
        ("texture = \"sirds_sphere.toml\"", "sirds.texture"),
        ("texture_background = [0, 0, 0]", "sirds.texture_background"),
    ] {
        let e = field_of(settings(text));
        assert!(e.contains(field), "{text}: {e}");
    }
    let e = format!(
        "{:?}",
        toml::from_str::<SirdsSpec>("guides = \"left\"").expect_err("unknown")
    );
    assert!(e.contains("top, bottom, both"), "{e}");
    let e = format!(
        "{:?}",
        toml::from_str::<SirdsSpec>("texture_background = [0, 0, 256]").expect_err("not a u8")
    );
    assert!(e.contains("texture_background") && e.contains("u8"), "{e}");
    let dir = common::out_dir("sirds_options_errors");
    // Narrower than the largest separation (90 px), and wider than 4096.
    for (name, w) in [("narrow.png", 60u32), ("wide.png", 4097)] {
        image::RgbaImage::from_pixel(w, 2, image::Rgba([9, 9, 9, 255]))
            .save(dir.join(name))
            .expect("png");
    }
    let root = stereolab_core::InputRoot::anywhere(&dir);
    let wide = SirdsSettings::from_spec(&spec("texture = \"wide.png\""), &root);
    assert!(field_of(wide).contains("4096"));
    let narrow = SirdsSettings::from_spec(&spec("texture = \"narrow.png\""), &root).expect("loads");
    let d = narrow.geometry.to_pixels().expect("valid");
    let map = sphere_over_ramp(200, 20);
    let e = field_of(per_pixel(&map, &d, &narrow.pattern, &narrow.per_pixel));
    assert!(e.contains("sirds.texture") && e.contains("wide"), "{e}");
    // Boxes too big for the image.
    let mut px = vec![[0u8; 4]; 160 * 120];
    let e = field_of(draw_guide_boxes(
        &mut px,
        160,
        120,
        90.0,
        GuideBoxes {
            place: GuidePlace::Both,
            size: 30,
        },
    ));
    assert!(e.contains("sirds.guide_size"), "{e}");
    // Per-pixel options on the per-vertex sphere.
    for set in [
        "sirds.tileable=true",
        "sirds.planes=4",
        "sirds.texture=\"textures/sirds_mts.png\"",
    ] {
        let scene =
            Scene::load(&asset("scenes/sirds_sphere.toml"), &[set.to_string()]).expect("loads");
        let frame = render(&scene, &Plan::new(&scene.outputs)).expect("renders");
        let e = field_of(from_frame(&frame, &scene));
        assert!(
            e.contains(set.split('=').next().unwrap()) && e.contains("per-pixel"),
            "{set}: {e}"
        );
    }
}

/// The shipped scenes render: the MTS's colors come from its texture (most pixels of the
/// sphere's columns are not random dots but texture means: few distinct colors), the tileable
/// one holds its links across the wrap where nothing hides them, the planes scene's sphere
/// has 6 separations, and the guide bands are white with two black squares.
#[test]
fn shipped_option_scenes_render() {
    let sirds_of = |name: &str| {
        let scene = Scene::load(&asset(&format!("scenes/{name}.toml")), &[]).expect("loads");
        let frame = render(&scene, &Plan::new(&scene.outputs)).expect("renders");
        (from_frame(&frame, &scene).expect("sirds"), scene)
    };
    let (mts, _) = sirds_of("sirds_texture");
    let texture = image::open(asset("scenes/textures/sirds_mts.png"))
        .expect("texture")
        .to_rgba8();
    let texel_colors: std::collections::BTreeSet<[u8; 4]> = texture.pixels().map(|p| p.0).collect();
    let from_texture = mts
        .pixels
        .iter()
        .filter(|p| texel_colors.contains(*p) && **p != [0, 0, 0, 255])
        .count();
    eprintln!(
        "sirds_texture: {from_texture} of {} pixels exactly a texel color",
        mts.pixels.len()
    );
    assert!(
        from_texture * 10 > mts.pixels.len(),
        "the texture's colors show"
    );
    let (tiled, _) = sirds_of("sirds_tileable");
    let (w, h) = (tiled.width as usize, tiled.height as usize);
    let d = tiled.disparity;
    let (mut wrapped, mut broken) = (0, 0);
    for y in 40..h {
        for x in 0..w {
            let s = whole(&d, tiled.depth.at(x as u32, y as u32));
            let l = left_of_pair(x, s, y as u32).rem_euclid(w as isize) as usize;
            let r = (l + s) % w;
            if r < l {
                wrapped += 1;
                broken += usize::from(tiled.pixels[y * w + l] != tiled.pixels[y * w + r]);
            }
        }
    }
    // The sphere is far from the edges: every wrapping pair lies on the background, unhidden.
    assert!(
        wrapped > 1000 && broken == 0,
        "{wrapped} wrapping pairs, {broken} broken"
    );
    assert!(
        tiled.pixels[..w * 10].iter().all(|p| *p == [255; 4]),
        "white band above the boxes"
    );
    let (planes, scene) = sirds_of("sirds_planes");
    assert_eq!(planes.pixels.len(), (scene.width * scene.height) as usize);
    let black = planes.pixels[..scene.width as usize * 36]
        .iter()
        .filter(|p| p[0] == 0)
        .count();
    assert_eq!(black, 2 * 12 * 12, "two black squares in the top band");
}

/// `stereolab sirds --depth MAP --texture FILE` with `--set` for the other options: an RGB
/// MTS whose colors are texel means (a texture of 3 colors and black gives few distinct
/// colors, random dots would give hundreds), the guide band drawn; a texture narrower than
/// the separations is refused naming `sirds.texture`, and nothing is written.
#[test]
fn cli_makes_a_mapped_texture_stereogram_of_a_depth_map() {
    let dir = common::out_dir("sirds_options_cli");
    let (w, h) = (300u32, 120u32);
    let mut pgm = format!("P5\n{w} {h}\n255\n").into_bytes();
    pgm.extend((0..h).flat_map(|y| (0..w).map(move |x| ((x / 3 + y / 5) % 2 * 200) as u8)));
    std::fs::write(dir.join("map.pgm"), pgm).expect("map");
    let colors = [
        [0, 0, 0, 255],
        [200, 30, 30, 255],
        [30, 200, 30, 255],
        [30, 30, 200, 255],
    ];
    image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba(colors[((x / 7 + y / 3) % 4) as usize])
    })
    .save(dir.join("tex.png"))
    .expect("texture");
    image::RgbaImage::from_pixel(40, 40, image::Rgba([1, 2, 3, 255]))
        .save(dir.join("narrow.png"))
        .expect("narrow");
    let run = |texture: &str, out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .current_dir(&dir)
            .args([
                "sirds",
                "--depth",
                "map.pgm",
                "--texture",
                texture,
                "-o",
                out,
            ])
            .args([
                "--set",
                "sirds.tileable=true",
                "--set",
                "sirds.guides=\"bottom\"",
            ])
            .output()
            .expect("runs")
    };
    let ok = run("tex.png", "mts.png");
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let img = image::open(dir.join("mts.png"))
        .expect("written")
        .to_rgba8();
    assert_eq!(img.dimensions(), (w, h));
    let body: std::collections::BTreeSet<[u8; 4]> =
        img.rows().take(60).flatten().map(|p| p.0).collect();
    assert!(
        body.len() > 3 && body.len() < 60,
        "{} colors: texel means",
        body.len()
    );
    assert!(
        img.rows()
            .next_back()
            .expect("row")
            .all(|p| p.0 == [255; 4]),
        "the guide band"
    );
    let bad = run("narrow.png", "bad.png");
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains("sirds.texture"),
        "{err}"
    );
    assert!(!dir.join("bad.png").exists());
}

/// `stereolab render SCENE --explain` names the options in use and runs the one depth pass
/// only: each shipped scene's line, and none for a scene without SIRDS outputs.
#[test]
fn explain_names_the_sirds_options_and_one_depth_pass() {
    for (scene, want) in [
        (
            "sirds_texture",
            "sirds: per-pixel (TIW), mapped texture 256×128\n",
        ),
        (
            "sirds_tileable",
            "sirds: per-pixel (TIW), tileable, guide boxes top, 10 px\n",
        ),
        (
            "sirds_planes",
            "sirds: per-pixel (TIW), 6 depth planes, guide boxes top and bottom, 12 px\n",
        ),
        ("anaglyph", ""),
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_stereolab"))
            .args(["render", "--explain"])
            .arg(asset(&format!("scenes/{scene}.toml")))
            .output()
            .expect("runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{scene}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        if want.is_empty() {
            assert!(!text.contains("sirds:"), "{scene}: {text}");
        } else {
            assert!(text.contains(want), "{scene}: {text}");
            assert!(
                text.contains("passes run: 1") && text.contains("depth only"),
                "{text}"
            );
        }
    }
}
