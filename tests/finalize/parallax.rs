//! Parallax p(z) = d (1 − z0/z) measured in rendered pairs, the budget report, the color image,
//! the plan, the scene table, and the real-model scene.

use stereolab::plan::{Output, Pass, Plan, Shading, View};
use stereolab::scene::Scene;
use stereolab::{info, output};
use stereolab_core::{
    LEGEND_HEIGHT, parallax_budget_of, parallax_color, parallax_image, parallax_map, project_ndc,
};

use super::{Rig, drawn_centroid, eyes, plane, render_outputs, scene};

/// A small quad (about 30 px) rotated 8.3° about the view axis, so that its edges cross pixel
/// centers at every sub-pixel phase and the coverage centroid measures position to a small
/// fraction of a pixel.
fn small_quad(x: f32, y: f32, z: f32) -> String {
    plane(quad_size(z), [x, y, -z], [0.0, 0.0, 8.3])
}

/// Edge of the small quad at distance z: about 31 px at 240 px width.
fn quad_size(z: f32) -> f32 {
    z / 8.0
}

/// Area centroid of a simple polygon (shoelace formula).
fn polygon_centroid(p: &[[f64; 2]]) -> [f64; 2] {
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for i in 0..p.len() {
        let (q, r) = (p[i], p[(i + 1) % p.len()]);
        let cross = q[0] * r[1] - r[0] * q[1];
        a += cross;
        cx += (q[0] + r[0]) * cross;
        cy += (q[1] + r[1]) * cross;
    }
    [cx / (3.0 * a), cy / (3.0 * a)]
}

#[test]
fn measured_parallax_of_a_small_quad_is_p_of_z_off_axis() {
    let rig = Rig {
        width: 240,
        height: 180,
        ..Rig::default()
    };
    for (x, y, z) in [
        (0.6f32, 0.3f32, 4.0f32),
        (-0.9, -0.4, 6.0),
        (1.1, 0.5, 9.0),
        (-2.0, 1.0, 15.0),
    ] {
        let s = scene(&rig, &small_quad(x, y, z), &["left", "right"]);
        let frame = render_outputs(&s, &[Output::Left, Output::Right]);
        let (left, right) = eyes(&frame);
        let (cl, cr) = (drawn_centroid(left), drawn_centroid(right));
        let measured = cr[0] - cl[0];
        let predicted = rig.parallax_px(z as f64);
        println!(
            "quad at z = {z}: measured parallax {measured:+.3} px, p(z) = {predicted:+.3} px, vertical {:+.3} px",
            cr[1] - cl[1]
        );
        assert!(
            (measured - predicted).abs() <= 0.5,
            "z {z}: measured {measured}, p(z) {predicted}"
        );
        // Off-axis has no vertical parallax: what remains is the centroid's sampling noise.
        assert!((cr[1] - cl[1]).abs() < 0.1, "vertical {}", cr[1] - cl[1]);
        // The per-pixel map reads the same p(z) back from the depth buffer.
        let map = parallax_map(left, &s.parallax_rig().expect("rig")).expect("map");
        for p in map.iter().flatten() {
            assert!((p - predicted).abs() < 1e-3, "map {p} vs {predicted}");
        }
    }
}

#[test]
fn toe_in_reports_vertical_parallax() {
    let rig = Rig {
        width: 240,
        height: 180,
        mode: "toe-in",
        ..Rig::default()
    };
    let (x, y, z) = (1.5f32, 1.0f32, 4.0f32);
    let s = scene(&rig, &small_quad(x, y, z), &["left", "right"]);
    let frame = render_outputs(&s, &[Output::Left, Output::Right]);
    let (left, right) = eyes(&frame);
    let (cl, cr) = (drawn_centroid(left), drawn_centroid(right));
    let vertical = cr[1] - cl[1];
    // The prediction: the area centroid of the quad's four corners projected by each eye's
    // MVP (toe-in's keystone makes the two images different trapezoids, so the projected
    // center would be off by ~0.3 px per eye).
    let centroid = |k: usize| -> [f64; 2] {
        let size = quad_size(z) as f64 / 2.0;
        let (sn, cs) = (8.3f64.to_radians().sin(), 8.3f64.to_radians().cos());
        let corners: Vec<[f64; 2]> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|(u, v)| {
                let (px, py) = (u * size, v * size);
                let world = glam::Vec3::new(
                    (x as f64 + px * cs - py * sn) as f32,
                    (y as f64 + px * sn + py * cs) as f32,
                    -z,
                );
                let n = project_ndc(&frame.views.eyes[k].mvp, world).expect("in front");
                [
                    (n.x as f64 + 1.0) * 0.5 * rig.width as f64,
                    (1.0 - n.y as f64) * 0.5 * rig.height as f64,
                ]
            })
            .collect();
        polygon_centroid(&corners)
    };
    let (pl, pr) = (centroid(0), centroid(1));
    let predicted = pr[1] - pl[1];
    println!("centroids measured {cl:?} {cr:?}, predicted {pl:?} {pr:?}");
    println!(
        "toe-in quad at ({x}, {y}, {z}): vertical parallax {vertical:+.3} px (predicted {predicted:+.3}), horizontal {:+.3} px (predicted {:+.3}; off-axis p(z) would be {:+.3})",
        cr[0] - cl[0],
        pr[0] - pl[0],
        rig.parallax_px(z as f64)
    );
    assert!(
        predicted.abs() > 1.0,
        "toe-in must show vertical parallax here"
    );
    assert!(
        (vertical - predicted).abs() <= 0.5,
        "{vertical} vs {predicted}"
    );
    assert!(
        (cr[0] - cl[0] - (pr[0] - pl[0])).abs() <= 0.5,
        "horizontal {} vs {}",
        cr[0] - cl[0],
        pr[0] - pl[0]
    );
}

#[test]
fn budget_reports_share_beyond_three_percent_and_window_violations() {
    let rig = Rig::default();
    // A far wall (p = 0.5·(1 − 6/30)·27.5 = 11 px = 6.9% of 160 px, beyond the budget) and a
    // near quad (negative parallax) cut by the left border.
    let meshes =
        plane(200.0, [0.0, 0.0, -30.0], [0.0; 3]) + &plane(1.0, [-1.6, 0.2, -3.0], [0.0; 3]);
    let s = scene(&rig, &meshes, &["parallax"]);
    let frame = render_outputs(&s, &[Output::Parallax]);
    let left = frame.view(View::Left).expect("left");
    let b = parallax_budget_of(left, &s.parallax_rig().expect("rig")).expect("budget");
    print!("{}", b.report());
    let (wall, near) = (rig.parallax_px(30.0), rig.parallax_px(3.0));
    assert!(
        (b.max_pixels - wall).abs() < 1e-3,
        "{} vs {wall}",
        b.max_pixels
    );
    assert!(
        (b.min_pixels - near).abs() < 1e-3,
        "{} vs {near}",
        b.min_pixels
    );
    assert_eq!(b.drawn, (rig.width * rig.height) as usize);
    // Every pixel is beyond ±3% (4.8 px): the wall at +11 px, the quad at −13.7 px.
    assert!(wall > 4.8 && near < -4.8);
    assert_eq!(b.beyond_budget, b.drawn);
    // The quad touches the left border only: rows it covers at x = 0.
    let quad_rows = (0..rig.height)
        .filter(|&y| left.depth()[left.index(0, y)] < left.depth()[left.index(rig.width - 1, y)])
        .count();
    assert!(quad_rows > 0);
    assert_eq!(b.window_violations, [quad_rows, 0, 0, 0]);
    assert!(
        b.report()
            .contains("window violations (negative parallax at the border): left")
    );
}

#[test]
fn parallax_image_is_blue_in_front_red_behind_with_a_legend() {
    let rig = Rig::default();
    let meshes =
        plane(200.0, [0.0, 0.0, -12.0], [0.0; 3]) + &plane(1.0, [0.3, 0.2, -4.0], [0.0; 3]);
    let s = scene(&rig, &meshes, &["parallax"]);
    let frame = render_outputs(&s, &[Output::Parallax]);
    let left = frame.view(View::Left).expect("left");
    let img = parallax_image(left, &s.parallax_rig().expect("rig")).expect("image");
    assert_eq!(img.height(), rig.height + LEGEND_HEIGHT);
    let corner = img.get_pixel(2, 2).0; // wall, behind the screen
    let center = img.get_pixel(rig.width / 2 + 5, rig.height / 2).0; // quad, in front
    assert!(corner[0] > corner[2], "behind is red: {corner:?}");
    assert!(center[2] > center[0], "in front is blue: {center:?}");
    // Scale = largest |p|: the quad saturates to full blue.
    assert_eq!(center, parallax_color(-1.0, 1.0));
    // The legend bar runs from blue through white to red.
    let bar_y = rig.height + 8;
    let (a, m, z) = (
        img.get_pixel(7, bar_y).0,
        img.get_pixel(rig.width / 2, bar_y).0,
        img.get_pixel(rig.width - 8, bar_y).0,
    );
    assert!(a[2] > 200 && a[0] < 40, "{a:?}");
    assert!(m.iter().all(|c| *c > 240), "{m:?}");
    assert!(z[0] > 200 && z[2] < 40, "{z:?}");
    let _ = std::fs::create_dir_all("target/test-out/finalize");
    img.save("target/test-out/finalize/parallax.png")
        .expect("save");
}

fn depth(view: View) -> Pass {
    Pass {
        view,
        shading: Shading::DepthOnly,
    }
}
fn color(view: View) -> Pass {
    Pass {
        view,
        shading: Shading::Color,
    }
}

#[test]
fn finalize_outputs_run_only_the_passes_they_need() {
    let cases: [(&[Output], Vec<Pass>); 6] = [
        (&[Output::Parallax], vec![depth(View::Left)]),
        (
            &[Output::Occlusion],
            vec![depth(View::Left), depth(View::Right)],
        ),
        (
            &[Output::RemapLeft],
            vec![depth(View::Left), color(View::Right)],
        ),
        (
            &[Output::RemapRight],
            vec![color(View::Left), depth(View::Right)],
        ),
        (
            &[Output::Anaglyph(
                stereolab_core::AnaglyphKind::DuboisRedCyan,
            )],
            vec![color(View::Left), color(View::Right)],
        ),
        (
            &[Output::Parallax, Output::RemapRight],
            vec![depth(View::Left), depth(View::Right)]
                .into_iter()
                .map(|p| {
                    if p.view == View::Left {
                        color(View::Left)
                    } else {
                        p
                    }
                })
                .collect(),
        ),
    ];
    for (outputs, want) in cases {
        let plan = Plan::new(outputs);
        assert_eq!(plan.passes, want, "{outputs:?}\n{}", plan.explain());
    }
    for o in Output::ALL {
        assert_eq!(Output::parse(o.name()).expect("parse"), *o);
    }
}

#[test]
fn finalize_table_sets_linear_light_and_swap_eyes() {
    let base = std::fs::read_to_string(super::super::common::asset("scenes/anaglyph.toml"))
        .expect("scene");
    let dir = super::super::common::asset("scenes");
    let sets = [
        "finalize.linear_light=true".to_string(),
        "finalize.swap_eyes=true".into(),
    ];
    let s =
        Scene::from_toml(&base, std::path::Path::new("anaglyph.toml"), &dir, &sets).expect("scene");
    assert!(s.finalize.linear_light && s.finalize.swap_eyes);
    let bad = Scene::from_toml(
        &base,
        std::path::Path::new("anaglyph.toml"),
        &dir,
        &["finalize.gamma=2.2".to_string()],
    );
    let msg = bad.expect_err("unknown field").to_string();
    assert!(msg.contains("gamma"), "{msg}");
}

#[test]
fn anaglyph_scene_renders_every_output_and_reports_the_budget() {
    let path = super::super::common::asset("scenes/anaglyph.toml");
    let mut s = Scene::load(&path, &[]).expect("scene");
    s.set_size(256, 192).expect("size");
    assert!(s.outputs.contains(&Output::Parallax));
    assert!(s.outputs.iter().any(|o| matches!(o, Output::Anaglyph(_))));
    let plan = Plan::new(&s.outputs);
    let frame = stereolab::render::render(&s, &plan).expect("render");
    let dir = super::super::common::out_dir("finalize-anaglyph-scene");
    let paths = output::write_all(&frame, &s, &dir).expect("write");
    assert_eq!(paths.len(), s.outputs.len());
    for p in &paths {
        let img = image::open(p).expect("png").to_rgba8();
        assert!(img.width() >= 256, "{}", p.display());
        let first = img.get_pixel(0, 0);
        assert!(img.pixels().any(|q| q != first), "{} is blank", p.display());
    }
    let report = stereolab::info::frame_budget_report(&frame, &s)
        .expect("budget")
        .expect("an eye was rendered");
    assert!(report.contains("beyond ±3%"), "{report}");
    let text = info::describe(&s).expect("info");
    assert!(text.contains("parallax budget (per pixel"), "{text}");
}
