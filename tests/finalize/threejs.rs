//! three.js's method × glasses anaglyph table, transcribed here a second time from three.js's
//! own notation (`ANAGLYPH_MATRICES`: per eye, one input-weight triple per output channel,
//! column-major once built), and Rendepth's anti-rivalry stage against a transcription of its
//! shader.

use stereolab_core::{
    ANTI_RIVALRY_GAMMA, AnaglyphGlasses, AnaglyphKind, AnaglyphMatrices, AnaglyphMethod,
    AnaglyphOptions, ColorMatrix, Framebuffer, anaglyph, anaglyph_pixel, anaglyph_pixel_with,
    threejs_anaglyph,
};

type M = AnaglyphMethod;
type G = AnaglyphGlasses;

/// One eye as three.js writes it: `{ r: [...], g: [...], b: [...] }`, a missing channel zero.
#[derive(Clone, Copy, Default)]
struct Spec {
    r: Option<[f32; 3]>,
    g: Option<[f32; 3]>,
    b: Option<[f32; 3]>,
}

/// three.js's `specToColumnMajor`: column j holds input channel j's weight in R, G, B out.
fn column_major(s: Spec) -> [f32; 9] {
    let (r, g, b) = (
        s.r.unwrap_or_default(),
        s.g.unwrap_or_default(),
        s.b.unwrap_or_default(),
    );
    [r[0], g[0], b[0], r[1], g[1], b[1], r[2], g[2], b[2]]
}

/// Back from `Matrix3.fromArray`'s column-major array to rows of output channels.
fn rows(a: [f32; 9]) -> ColorMatrix {
    [[a[0], a[3], a[6]], [a[1], a[4], a[7]], [a[2], a[5], a[8]]]
}

const LUM: [f32; 3] = [0.299, 0.587, 0.114];

fn r(v: [f32; 3]) -> Spec {
    Spec {
        r: Some(v),
        ..Spec::default()
    }
}
fn g(v: [f32; 3]) -> Spec {
    Spec {
        g: Some(v),
        ..Spec::default()
    }
}
fn with_b(s: Spec, v: [f32; 3]) -> Spec {
    Spec { b: Some(v), ..s }
}
fn with_g(s: Spec, v: [f32; 3]) -> Spec {
    Spec { g: Some(v), ..s }
}

/// `ANAGLYPH_MATRICES[method][glasses]` as three.js's AnaglyphPassNode.js lists them.
fn three(method: M, glasses: G) -> (Spec, Spec) {
    let dl = r([0.4561, 0.500484, 0.176381]);
    let dl = with_g(dl, [-0.0400822, -0.0378246, -0.0157589]);
    let dr = r([-0.0434706, -0.0879388, -0.00155529]);
    let dr = with_g(dr, [0.378476, 0.73364, -0.0184503]);
    let none = Spec::default();
    match (method, glasses) {
        (M::True, G::RedCyan) => (r([1.0, 0.0, 0.0]), with_b(g(LUM), LUM)),
        (M::True, G::MagentaCyan) => (
            with_b(r([1.0, 0.0, 0.0]), [0.0, 0.0, 0.5]),
            with_b(g(LUM), [0.0, 0.0, 0.5]),
        ),
        (M::True, G::MagentaGreen) => (with_b(r([1.0, 0.0, 0.0]), LUM), g(LUM)),
        (M::Grey, G::RedCyan) => (r(LUM), with_b(g(LUM), LUM)),
        (M::Grey, G::MagentaCyan) => (
            with_b(r(LUM), [0.15, 0.29, 0.06]),
            with_b(g(LUM), [0.15, 0.29, 0.06]),
        ),
        (M::Grey, G::MagentaGreen) => (with_b(r(LUM), LUM), g(LUM)),
        (M::Colour, G::RedCyan) => (
            r([1.0, 0.0, 0.0]),
            with_b(g([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]),
        ),
        (M::Colour, G::MagentaCyan) => (
            with_b(r([1.0, 0.0, 0.0]), [0.0, 0.0, 0.5]),
            with_b(g([0.0, 1.0, 0.0]), [0.0, 0.0, 0.5]),
        ),
        (M::Colour, G::MagentaGreen) => (
            with_b(r([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0]),
            g([0.0, 1.0, 0.0]),
        ),
        (M::HalfColour, G::RedCyan) => (r(LUM), with_b(g([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0])),
        (M::HalfColour, G::MagentaCyan) => (
            with_b(r(LUM), [0.15, 0.29, 0.06]),
            with_b(g([0.0, 1.0, 0.0]), [0.15, 0.29, 0.06]),
        ),
        (M::HalfColour, G::MagentaGreen) => (with_b(r(LUM), LUM), g([0.0, 1.0, 0.0])),
        (M::Dubois, G::RedCyan) => (
            with_b(dl, [-0.0152161, -0.0205971, -0.00546856]),
            with_b(dr, [-0.0721527, -0.112961, 1.2264]),
        ),
        (M::Dubois, G::MagentaCyan) => (
            with_b(dl, [0.088, 0.088, -0.003]),
            with_b(dr, [0.088, 0.088, 0.613]),
        ),
        (M::Dubois, G::MagentaGreen) => (
            with_b(
                r([0.4561, 0.500484, 0.176381]),
                [-0.0434706, -0.0879388, -0.00155529],
            ),
            with_g(
                none,
                [0.378476 + 0.4561, 0.73364 + 0.500484, -0.0184503 + 0.176381],
            ),
        ),
        (M::Optimised, G::RedCyan) => (
            r([0.0, 0.7, 0.3]),
            with_b(g([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]),
        ),
        (M::Optimised, G::MagentaCyan) => (
            with_b(r([0.0, 0.7, 0.3]), [0.0, 0.0, 0.5]),
            with_b(g([0.0, 1.0, 0.0]), [0.0, 0.0, 0.5]),
        ),
        (M::Optimised, G::MagentaGreen) => (
            with_b(r([0.0, 0.7, 0.3]), [0.0, 0.0, 1.0]),
            g([0.0, 1.0, 0.0]),
        ),
        (M::Compromise, G::RedCyan) => (
            r([0.439, 0.447, 0.148]),
            with_b(g([0.095, 0.934, 0.005]), [0.018, 0.028, 1.057]),
        ),
        (M::Compromise, G::MagentaCyan) => (
            with_b(r([0.439, 0.447, 0.148]), [0.009, 0.014, 0.074]),
            with_b(g([0.095, 0.934, 0.005]), [0.009, 0.014, 0.528]),
        ),
        (M::Compromise, G::MagentaGreen) => (
            with_b(r([0.439, 0.447, 0.148]), [0.018, 0.028, 1.057]),
            g([0.095 + 0.439, 0.934 + 0.447, 0.005 + 0.148]),
        ),
    }
}

#[test]
fn every_cell_matches_three_js() {
    for method in M::ALL {
        for glasses in G::ALL {
            let (l, r) = three(method, glasses);
            let want = AnaglyphMatrices {
                left: rows(column_major(l)),
                right: rows(column_major(r)),
            };
            let got = threejs_anaglyph(method, glasses);
            for (a, b) in got
                .left
                .iter()
                .chain(&got.right)
                .flatten()
                .zip(want.left.iter().chain(&want.right).flatten())
            {
                // The sums of two published numbers may round differently in f32.
                assert!(
                    (a - b).abs() <= 1e-6,
                    "{method:?} {glasses:?}: {got:?} against {want:?}"
                );
            }
            assert_eq!(
                AnaglyphKind::ThreeJs(method, glasses).matrices(),
                got,
                "{method:?} {glasses:?}"
            );
        }
    }
}

#[test]
fn the_table_has_21_distinct_output_names() {
    let mut names: Vec<&str> = AnaglyphKind::THREE_JS
        .iter()
        .chain(&AnaglyphKind::ALL)
        .map(|k| k.output_name())
        .collect();
    assert_eq!(names.len(), 30);
    names.sort();
    names.dedup();
    assert_eq!(names.len(), 30, "every name is unique");
    assert_eq!(
        AnaglyphKind::ThreeJs(M::Compromise, G::MagentaCyan).output_name(),
        "anaglyph_compromise_magenta_cyan"
    );
    assert_eq!(
        AnaglyphKind::ThreeJs(M::HalfColour, G::RedCyan).output_name(),
        "anaglyph_half_colour_red_cyan"
    );
}

#[test]
fn red_cyan_cells_are_the_slides_and_dubois_matrices_except_true() {
    let same = [
        (M::Grey, AnaglyphKind::Gray),
        (M::Colour, AnaglyphKind::Color),
        (M::HalfColour, AnaglyphKind::HalfColor),
        (M::Optimised, AnaglyphKind::Optimized),
        (M::Dubois, AnaglyphKind::DuboisRedCyan),
    ];
    for (method, kind) in same {
        assert_eq!(
            threejs_anaglyph(method, G::RedCyan),
            kind.matrices(),
            "{method:?}"
        );
    }
    // three.js's true anaglyph keeps the left eye's red and gives the right eye's luma to
    // green and blue; the slides' sends both eyes' luma to red and blue.
    assert_ne!(
        threejs_anaglyph(M::True, G::RedCyan),
        AnaglyphKind::True.matrices()
    );
}

/// `round(clamp(x) · 255)`, in f64.
fn byte(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[test]
fn white_and_gray_through_every_cell() {
    for kind in AnaglyphKind::THREE_JS {
        let m = kind.matrices();
        let white = anaglyph_pixel(&m, [255; 4], [255; 4], false);
        // Row sums in f64: white gives each row's sum, clamped.
        let sums: Vec<f64> = (0..3)
            .map(|i| {
                m.left[i]
                    .iter()
                    .chain(&m.right[i])
                    .map(|&v| f64::from(v))
                    .sum()
            })
            .collect();
        for c in 0..3 {
            assert!(
                white[c].abs_diff(byte(sums[c])) <= 1,
                "{kind:?} channel {c}: {white:?}, row sums {sums:?}"
            );
        }
        let kept = white[..3].iter().all(|&c| c >= 254);
        assert_eq!(kept, kind.preserves_white(), "{kind:?}: white → {white:?}");
    }
    // The documented exceptions, by value: the magenta-cyan blue rows of Dubois and
    // Compromise sum to 0.962 and 0.648, Dubois magenta-green's to −0.133.
    let white = |method, glasses| {
        anaglyph_pixel(
            &threejs_anaglyph(method, glasses),
            [255; 4],
            [255; 4],
            false,
        )
    };
    assert_eq!(white(M::Dubois, G::MagentaCyan)[2], byte(0.173 + 0.789));
    assert_eq!(white(M::Compromise, G::MagentaCyan)[2], byte(0.097 + 0.551));
    assert_eq!(&white(M::Dubois, G::MagentaGreen)[..3], &[255, 255, 0]);
}

#[test]
fn magenta_cyan_glasses_share_blue_between_the_eyes() {
    // A pure blue left eye and a black right eye: with magenta-cyan glasses both eyes see
    // blue, so half of it reaches the output from each; with red-cyan none from the left.
    let blue = [0, 0, 255, 255];
    let black = [0, 0, 0, 255];
    for method in [M::True, M::Colour, M::Optimised] {
        let mc = anaglyph_pixel(
            &threejs_anaglyph(method, G::MagentaCyan),
            blue,
            black,
            false,
        );
        let rc = anaglyph_pixel(&threejs_anaglyph(method, G::RedCyan), blue, black, false);
        assert_eq!(mc[2], byte(0.5), "{method:?}");
        assert_eq!(rc[2], 0, "{method:?}");
    }
}

/// Rendepth's shader, transcribed: each eye's product clamped on its own, the two summed,
/// then `pow(c, 1/γ)` per channel, all in f64 from the 8-bit stored values.
fn rendepth(m: &AnaglyphMatrices, l: [u8; 4], r: [u8; 4]) -> ([u8; 4], bool) {
    let unit = |p: [u8; 4]| [p[0], p[1], p[2]].map(|v| f64::from(v) / 255.0);
    let (l, r) = (unit(l), unit(r));
    let product = |mm: &ColorMatrix, v: [f64; 3], i: usize| {
        (0..3).map(|j| f64::from(mm[i][j]) * v[j]).sum::<f64>()
    };
    let mut out = [255u8; 4];
    let mut in_range = true;
    for i in 0..3 {
        let (a, b) = (product(&m.left, l, i), product(&m.right, r, i));
        in_range &= (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a + b <= 1.0;
        let c = a.clamp(0.0, 1.0) + b.clamp(0.0, 1.0);
        out[i] = byte(
            c.clamp(0.0, 1.0)
                .powf(1.0 / f64::from(ANTI_RIVALRY_GAMMA[i])),
        );
    }
    (out, in_range)
}

#[test]
fn anti_rivalry_is_rendepths_gamma_stage() {
    // Mid gray in both eyes of the color anaglyph: each channel is 128/255, then the gamma
    // map raises red to the 1/1.6, green to the 1/0.8, keeps blue.
    let gray = [128, 128, 128, 255];
    let options = AnaglyphOptions {
        anti_rivalry: true,
        ..AnaglyphOptions::default()
    };
    let px = anaglyph_pixel_with(&AnaglyphKind::Color.matrices(), gray, gray, options);
    let v = 128.0 / 255.0f64;
    assert_eq!(
        px,
        [
            byte(v.powf(1.0 / 1.6)),
            byte(v.powf(1.0 / 0.8)),
            byte(v),
            255
        ]
    );
    assert_eq!(&px[..3], &[166, 108, 128]);

    // Against the shader, every 17th level of each channel in both eyes. With matrices of no
    // negative weight whose products stay in [0, 1], Rendepth's two clamps and the one clamp
    // of the sum agree: there the two must match within one level (f32 against f64).
    let levels: Vec<u8> = (0..=15).map(|i| i * 17).collect();
    let mut triples = Vec::new();
    for &a in &levels {
        for &b in &levels {
            for &c in &levels {
                triples.push((a, b, c));
            }
        }
    }
    let plain = [
        AnaglyphKind::Color,
        AnaglyphKind::Gray,
        AnaglyphKind::HalfColor,
        AnaglyphKind::Optimized,
        AnaglyphKind::ThreeJs(M::Compromise, G::RedCyan),
    ];
    let mut comparable = 0;
    for kind in plain {
        let m = kind.matrices();
        for &(a, b, c) in &triples {
            let (l, r) = ([a, b, c, 255], [c, a, b, 255]);
            let (theirs, in_range) = rendepth(&m, l, r);
            if in_range {
                comparable += 1;
                let ours = anaglyph_pixel_with(&m, l, r, options);
                let close = ours.iter().zip(&theirs).all(|(x, y)| x.abs_diff(*y) <= 1);
                assert!(
                    close,
                    "{kind:?} {l:?} {r:?}: {ours:?} against Rendepth's {theirs:?}"
                );
            }
        }
    }
    // With Dubois' negative weights Rendepth clamps each eye's negative product to 0 before
    // adding, so the ghost those weights cancel stays: count how often the two differ.
    let m = AnaglyphKind::DuboisRedCyan.matrices();
    let (mut differ, mut largest) = (0, 0u8);
    for &(a, b, c) in &triples {
        let (l, r) = ([a, b, c, 255], [c, a, b, 255]);
        let ours = anaglyph_pixel_with(&m, l, r, options);
        let (theirs, _) = rendepth(&m, l, r);
        let d = ours
            .iter()
            .zip(&theirs)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        differ += usize::from(d > 1);
        largest = largest.max(d);
    }
    eprintln!(
        "Rendepth's shader against anti_rivalry: {comparable} in-range pixel pairs of five \
         non-negative kinds within one level; on Dubois {differ} of {} differ by more (at most \
         {largest} levels)",
        levels.len().pow(3)
    );
    assert!(comparable > 10_000, "{comparable}");
    // The clamp order matters with negative weights: some pixels must differ, or this test
    // would not tell the two formulas apart.
    assert!(differ > 0, "no pixel tells the clamp orders apart");
}

#[test]
fn anti_rivalry_image_loop_matches_the_pixel_function() {
    let (w, h) = (7, 5);
    let mut a = Framebuffer::new(w, h, [0, 0, 0, 255]).unwrap();
    let mut b = Framebuffer::new(w, h, [0, 0, 0, 255]).unwrap();
    for (i, (p, q)) in a
        .color_mut()
        .iter_mut()
        .zip(b.color_mut().iter_mut())
        .enumerate()
    {
        *p = [(i * 37 % 256) as u8, (i * 91 % 256) as u8, 40, 255];
        *q = [9, (i * 7 % 256) as u8, (i * 111 % 256) as u8, 255];
    }
    for linear_light in [false, true] {
        let options = AnaglyphOptions {
            linear_light,
            anti_rivalry: true,
            swap_eyes: false,
        };
        let kind = AnaglyphKind::ThreeJs(M::Compromise, G::RedCyan);
        let img = anaglyph(&a, &b, kind, options).unwrap();
        let plain = anaglyph(
            &a,
            &b,
            kind,
            AnaglyphOptions {
                anti_rivalry: false,
                ..options
            },
        )
        .unwrap();
        assert_ne!(img, plain, "the gamma stage changes the image");
        for (i, px) in img.pixels().enumerate() {
            let want = anaglyph_pixel_with(&kind.matrices(), a.color()[i], b.color()[i], options);
            assert_eq!(px.0, want, "pixel {i}");
        }
    }
}

/// The shipped scene's anaglyphs against the eyes it rendered, mixed here in f64 from three.js's
/// notation (the table above), not through the library's matrices.
#[test]
fn the_shipped_scene_renders_three_js_cells_from_its_eyes() {
    use stereolab::output::{Image, produce};
    use stereolab::plan::{Output, Plan};
    use stereolab::render::render;
    use stereolab::scene::Scene;

    let mut scene =
        Scene::load(&crate::common::asset("scenes/anaglyph_threejs.toml"), &[]).unwrap();
    scene.set_size(96, 72).unwrap();
    let mut outputs = scene.outputs.clone();
    assert_eq!(outputs.len(), 3);
    outputs.extend([Output::Left, Output::Right]);
    let frame = render(&scene, &Plan::new(&outputs)).unwrap();
    let rgba = |o: Output| match produce(o, &frame, &scene).unwrap() {
        Image::Rgba(i) => i,
        _ => panic!("{o:?} is not an RGBA image"),
    };
    let (left, right) = (rgba(Output::Left), rgba(Output::Right));
    for &o in &scene.outputs {
        let Output::Anaglyph(AnaglyphKind::ThreeJs(method, glasses)) = o else {
            panic!("{o:?} is not a cell of three.js's table");
        };
        let (l, r) = three(method, glasses);
        let (ml, mr) = (rows(column_major(l)), rows(column_major(r)));
        let img = rgba(o);
        let mut colors = std::collections::HashSet::new();
        for ((px, a), b) in img.pixels().zip(left.pixels()).zip(right.pixels()) {
            let unit = |p: &image::Rgba<u8>| [0, 1, 2].map(|c| f64::from(p.0[c]) / 255.0);
            let (a, b) = (unit(a), unit(b));
            for i in 0..3 {
                let v: f64 = (0..3)
                    .map(|j| f64::from(ml[i][j]) * a[j] + f64::from(mr[i][j]) * b[j])
                    .sum();
                assert!(
                    px.0[i].abs_diff(byte(v)) <= 1,
                    "{}: {px:?} against {v}",
                    o.name()
                );
            }
            colors.insert(px.0);
        }
        assert!(
            colors.len() > 100,
            "{}: the shaded model is in view",
            o.name()
        );
    }
}
