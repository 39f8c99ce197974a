//! Exercise 1's `remap` task: a left pixel's texture coordinate and depth in the right eye.

use glam::{DMat4, DVec4, Mat4};
use serde_json::json;

use super::left_samples;
use crate::effects::remap::{Precision, Remapped, Remapper};
use crate::grade::fixture::Fixture;
use crate::grade::spec::{Case, ImageCheck, Mistake, Picture, TaskSpec, Tolerance};

/// The known remapping mistakes as switches.
#[derive(Clone, Copy, Default)]
struct RemapVariant {
    depth_as_ndc: bool,
    /// Only the incoming depth left as it is (`z_ndc = depth`), the outgoing one converted.
    depth_in_raw: bool,
    /// Only the outgoing depth left in NDC, the incoming one converted.
    depth_out_raw: bool,
    /// No `None` when `w ≤ 0`.
    never_none: bool,
    order_swapped: bool,
    no_divide: bool,
    ndc_out: bool,
}

/// The known mistakes' answers (and, with no switch set, the same numbers as
/// [`stereolab_remap`]): the exercise slides' chain in f64 from a texture coordinate.
fn remap_reference(l: &Mat4, r: &Mat4, uv: [f32; 2], depth: f32, v: RemapVariant) -> Vec<f64> {
    let (l, r) = (l.as_dmat4(), r.as_dmat4());
    let m: DMat4 = if v.order_swapped {
        l * r.inverse()
    } else {
        r * l.inverse()
    };
    let z = if v.depth_as_ndc || v.depth_in_raw {
        depth as f64
    } else {
        2.0 * depth as f64 - 1.0
    };
    let clip = m * DVec4::new(2.0 * uv[0] as f64 - 1.0, 2.0 * uv[1] as f64 - 1.0, z, 1.0);
    if clip.w <= 0.0 && !v.never_none {
        return Vec::new();
    }
    let ndc = if v.no_divide {
        clip.truncate()
    } else {
        clip.truncate() / clip.w
    };
    if v.ndc_out {
        return ndc.to_array().to_vec();
    }
    let depth = if v.depth_as_ndc || v.depth_out_raw {
        ndc.z
    } else {
        0.5 * (ndc.z + 1.0)
    };
    vec![0.5 * (ndc.x + 1.0), 0.5 * (ndc.y + 1.0), depth]
}

/// stereolab's remapping (`effects::remap`, f64) of left pixel (x, y) at depth `d`:
/// `[u, v, depth]` in the right eye, empty when behind it.
pub(super) fn stereolab_remap(
    l: &Mat4,
    r: &Mat4,
    (w, h): (u32, u32),
    (x, y): (u32, u32),
    d: f32,
) -> Vec<f64> {
    Remapper::new(l, r, w, h, Precision::F64)
        .ok()
        .and_then(|m| m.remap(x, y, d))
        .map_or_else(Vec::new, |m| vec![m.tex[0], m.tex[1], m.depth])
}

/// A remap check: label, MVP_l, MVP_r, the left pixel, its stored depth.
type RemapCase = (String, Mat4, Mat4, (u32, u32), f32);

pub(super) fn remap_task(fx: &Fixture) -> TaskSpec {
    let (l, r) = (fx.eyes[0].mvp, fx.eyes[1].mvp);
    let size = fx.size();
    let mut inputs: Vec<RemapCase> = left_samples(fx)
        .into_iter()
        .enumerate()
        .filter(|(i, _)| i % 41 == 0)
        .map(|(_, (x, y, _, d))| (format!("left pixel ({x}, {y})"), l, r, (x, y), d))
        .collect();
    // A right eye turned 8.6° about its own Y axis (converged eyes): MVP_r · MVP_l⁻¹ then has a
    // non-trivial bottom row, so clip_r.w ≠ 1 and a forgotten divide shows. With the parallel
    // eyes of the rig w is exactly 1 and the divide cannot be checked.
    let turned = fx.eyes[1].projection * Mat4::from_rotation_y(0.15) * fx.eyes[1].view;
    inputs.extend(
        left_samples(fx)
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % 41 == 20)
            .map(|(_, (x, y, _, d))| {
                (
                    format!("left pixel ({x}, {y}), right eye turned 8.6° about Y (w ≠ 1)"),
                    l,
                    turned,
                    (x, y),
                    d,
                )
            }),
    );
    // A right eye turned round (180° about its own Y axis): every point the left eye sees is
    // behind it, clip_r.w < 0 → None.
    let around =
        fx.eyes[1].projection * Mat4::from_rotation_y(std::f32::consts::PI) * fx.eyes[1].view;
    inputs.extend(
        left_samples(fx)
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % 97 == 5)
            .take(4)
            .map(|(_, (x, y, _, d))| {
                (
                    format!("left pixel ({x}, {y}), right eye turned round (behind it: None)"),
                    l,
                    around,
                    (x, y),
                    d,
                )
            }),
    );
    // The model turned 180° about its own Y axis for the right eye only (a point still in
    // front of the right eye, elsewhere in the image).
    let model_turned = r * Mat4::from_rotation_y(std::f32::consts::PI);
    let center = (size.0 / 2, size.1 / 2);
    inputs.push((
        "center pixel, the model turned 180° about Y for the right eye".into(),
        l,
        model_turned,
        center,
        0.9,
    ));
    let json_of = |l: &Mat4, r: &Mat4, uv: [f32; 2], d: f32| {
        json!([l.to_cols_array(), r.to_cols_array(), uv, d])
    };
    let cases = inputs
        .iter()
        .map(|(label, l, r, (x, y), d)| Case {
            label: label.clone(),
            input: json_of(l, r, fx.uv(*x, *y), *d),
            expected: stereolab_remap(l, r, size, (*x, *y), *d),
        })
        .collect();
    let each = |v: RemapVariant| {
        inputs
            .iter()
            .map(|(_, l, r, (x, y), d)| remap_reference(l, r, fx.uv(*x, *y), *d, v))
            .collect()
    };
    let samples = left_samples(fx);
    let image_inputs = samples
        .iter()
        .map(|(_, _, uv, d)| json_of(&l, &r, *uv, *d))
        .collect();
    let picture = {
        let samples = samples.clone();
        let right = fx.views[1].clone();
        let mut canvas = fx.canvas(fx.scene.background);
        canvas.depth = fx.views[0].depth.clone();
        let (w, h) = fx.size();
        move |answers: &[Option<Vec<f64>>]| {
            let mut fb = canvas.clone();
            for ((x, y, _, _), a) in samples.iter().zip(answers) {
                let texel = a
                    .as_ref()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| texel_of(a[0], a[1], w, h));
                let i = fb.index(*x, *y);
                fb.color[i] = match texel {
                    Some((tx, ty)) => right.color[right.index(tx, ty)],
                    None => [0, 0, 0, 255],
                };
            }
            fb
        }
    };
    let expected = picture(
        &samples
            .iter()
            .map(|(x, y, _, d)| Some(stereolab_remap(&l, &r, size, (*x, *y), *d)))
            .collect::<Vec<_>>(),
    );
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: "remap_right_colors_on_left".into(),
            expected: expected.clone(),
            actual: picture(answers),
        }]
    };
    TaskSpec {
        name: "remap",
        points: 2.0,
        bonus: false,
        depends_on: &[],
        hidden: Vec::new(),
        tolerance: Tolerance {
            abs: 2e-4,
            rel: 0.0,
            why: "the exercise slides' f32 chain (inverse in f32, two products) is off by 4.4e-7 at most \
                  on these inputs against this f64 reference (measured); 2e-4 is a hundredth of \
                  a pixel at 64 pixels and leaves room for any evaluation order",
        },
        cases,
        mistakes: vec![
            Mistake {
                id: "opengl-depth",
                hint: "depth range: the depth texture holds window depth in [0, 1], NDC z is in \
                       [−1, 1]: z_ndc = 2·depth − 1 going in, depth = (z_ndc + 1)/2 coming out",
                answers: each(RemapVariant {
                    depth_as_ndc: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "one-sided-depth",
                hint: "depth converted one way only: depth_left in [0, 1] becomes \
                       z_ndc = 2·depth − 1, AND the result goes back: depth = (z_ndc + 1)/2",
                answers: each(RemapVariant {
                    depth_out_raw: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "one-sided-depth",
                hint: "depth converted one way only: the result is converted back with \
                       (z_ndc + 1)/2, so depth_left must go in as z_ndc = 2·depth − 1",
                answers: each(RemapVariant {
                    depth_in_raw: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "never-none",
                hint: "return None when clip_r.w ≤ 0: the point is behind the right eye and \
                       dividing by w flips it into the image",
                answers: each(RemapVariant {
                    never_none: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "matrix-order",
                hint: "MVP_l · MVP_r⁻¹ is the wrong way round: undo the LEFT eye's transform \
                       first, then apply the right eye's: MVP_r · MVP_l⁻¹",
                answers: each(RemapVariant {
                    order_swapped: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "no-w-divide",
                hint: "missing w-clip: divide x, y, z by w before leaving clip space",
                answers: each(RemapVariant {
                    no_divide: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "ndc-not-texture",
                hint: "wrong range: these are NDC in [−1, 1]; texture coordinates are \
                       (ndc + 1)/2 in [0, 1]",
                answers: each(RemapVariant {
                    ndc_out: true,
                    ..Default::default()
                }),
            },
        ],
        image: Some(ImageCheck {
            inputs: image_inputs,
            build: Box::new(build),
        }),
    }
}

/// The texel nearest filtering fetches at texture coordinate (u, v) (v = 0 bottom) in a w × h
/// image, if inside (stereolab's `Remapped::texel`).
pub(super) fn texel_of(u: f64, v: f64, w: u32, h: u32) -> Option<(u32, u32)> {
    Remapped {
        tex: [u, v],
        depth: 0.0,
    }
    .texel(w, h)
}
