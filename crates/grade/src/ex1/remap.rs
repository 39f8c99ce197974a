//! Exercise 1's remapping tasks: a left pixel's texture coordinate and depth in the right eye
//! (`remap`) and the other direction, a right pixel's in the left eye (`remap_right_to_left`).

use glam::{DMat4, DVec4, Mat4};
use serde_json::json;

use super::view_samples;
use super::{HIDDEN_SETUPS, eyes, random_setup};
use crate::fixture::Fixture;
use crate::spec::{Case, Mistake, Picture, SplitMix64, TaskSpec, Tolerance, hidden_cases};
use stereolab_core::{CameraMode, Lighting, Precision, Remapped, Remapper};

/// The known remapping mistakes as switches.
#[derive(Clone, Copy, Default)]
pub(super) struct RemapVariant {
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
pub(super) fn remap_reference(
    l: &Mat4,
    r: &Mat4,
    uv: [f32; 2],
    depth: f32,
    v: RemapVariant,
) -> Vec<f64> {
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

/// A remap check: label, MVP of the eye remapped from, MVP of the eye remapped to, the pixel,
/// its stored depth.
type RemapCase = (String, Mat4, Mat4, (u32, u32), f32);

pub(super) fn remap_task(fx: &Fixture) -> TaskSpec {
    remap_direction_task(fx, 0)
}

pub(super) fn remap_right_to_left_task(fx: &Fixture) -> TaskSpec {
    remap_direction_task(fx, 1)
}

/// The remapping task from eye `from` (0: left, the `remap` task) to the other eye (1: right
/// to left, `remap_right_to_left`): the same checks with the eyes' roles exchanged. The inputs
/// always read `[MVP_l, MVP_r, uv, depth]` (the stubs take `mvp_left` first either way).
fn remap_direction_task(fx: &Fixture, from: usize) -> TaskSpec {
    let to = 1 - from;
    let names = ["left", "right"];
    let (src_name, dst_name) = (names[from], names[to]);
    let (src, dst) = (fx.eyes[from].mvp, fx.eyes[to].mvp);
    let size = fx.size();
    let mut inputs: Vec<RemapCase> = view_samples(fx, from)
        .into_iter()
        .enumerate()
        .filter(|(i, _)| i % 41 == 0)
        .map(|(_, (x, y, _, d))| (format!("{src_name} pixel ({x}, {y})"), src, dst, (x, y), d))
        .collect();
    // The other eye turned 8.6° about its own Y axis (converged eyes): MVP_to · MVP_from⁻¹ then
    // has a non-trivial bottom row, so clip.w ≠ 1 and a forgotten divide shows. With the
    // parallel eyes of the rig w is exactly 1 and the divide cannot be checked.
    let turned = fx.eyes[to].projection * Mat4::from_rotation_y(0.15) * fx.eyes[to].view;
    inputs.extend(
        view_samples(fx, from)
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % 41 == 20)
            .map(|(_, (x, y, _, d))| {
                (
                    format!(
                        "{src_name} pixel ({x}, {y}), {dst_name} eye turned 8.6° about Y (w ≠ 1)"
                    ),
                    src,
                    turned,
                    (x, y),
                    d,
                )
            }),
    );
    // The other eye turned round (180° about its own Y axis): every point this eye sees is
    // behind it, clip.w < 0 → None.
    let around =
        fx.eyes[to].projection * Mat4::from_rotation_y(std::f32::consts::PI) * fx.eyes[to].view;
    inputs.extend(
        view_samples(fx, from)
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % 97 == 5)
            .take(4)
            .map(|(_, (x, y, _, d))| {
                (
                    format!(
                        "{src_name} pixel ({x}, {y}), {dst_name} eye turned round (behind it: None)"
                    ),
                    src,
                    around,
                    (x, y),
                    d,
                )
            }),
    );
    // The model turned 180° about its own Y axis for the other eye only (a point still in
    // front of that eye, elsewhere in the image).
    let model_turned = dst * Mat4::from_rotation_y(std::f32::consts::PI);
    let center = (size.0 / 2, size.1 / 2);
    inputs.push((
        format!("center pixel, the model turned 180° about Y for the {dst_name} eye"),
        src,
        model_turned,
        center,
        0.9,
    ));
    let json_of = |src: &Mat4, dst: &Mat4, uv: [f32; 2], d: f32| {
        let (l, r) = if from == 0 { (src, dst) } else { (dst, src) };
        json!([l.to_cols_array(), r.to_cols_array(), uv, d])
    };
    let cases = inputs
        .iter()
        .map(|(label, src, dst, (x, y), d)| Case {
            label: label.clone(),
            input: json_of(src, dst, fx.uv(*x, *y), *d),
            expected: stereolab_remap(src, dst, size, (*x, *y), *d),
        })
        .collect();
    let each = |v: RemapVariant| {
        inputs
            .iter()
            .map(|(_, src, dst, (x, y), d)| remap_reference(src, dst, fx.uv(*x, *y), *d, v))
            .collect()
    };
    let samples = view_samples(fx, from);
    let image_inputs = samples
        .iter()
        .map(|(_, _, uv, d)| json_of(&src, &dst, *uv, *d))
        .collect();
    let picture = {
        let samples = samples.clone();
        let other = fx.views[to].clone();
        let canvas = fx.canvas_over(&fx.views[from], fx.scene.background);
        let (w, h) = fx.size();
        move |answers: &[Option<Vec<f64>>]| {
            let mut fb = canvas.clone();
            for ((x, y, _, _), a) in samples.iter().zip(answers) {
                let texel = a
                    .as_ref()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| texel_of(a[0], a[1], w, h));
                let i = fb.index(*x, *y);
                fb.color_mut()[i] = match texel {
                    Some((tx, ty)) => other.color()[other.index(tx, ty)],
                    None => [0, 0, 0, 255],
                };
            }
            fb
        }
    };
    let expected = picture(
        &samples
            .iter()
            .map(|(x, y, _, d)| Some(stereolab_remap(&src, &dst, size, (*x, *y), *d)))
            .collect::<Vec<_>>(),
    );
    let picture_name = format!("remap_{dst_name}_colors_on_{src_name}");
    let build = move |answers: &[Option<Vec<f64>>]| {
        vec![Picture {
            name: picture_name.clone(),
            expected: expected.clone(),
            actual: picture(answers),
        }]
    };
    let forward = from == 0;
    TaskSpec {
        name: if forward {
            "remap"
        } else {
            "remap_right_to_left"
        },
        points: if forward { 2.0 } else { 1.0 },
        bonus: false,
        // The solution's right-to-left remap is `remap` with the eyes exchanged.
        depends_on: if forward { &[] } else { &["remap"] },
        hidden: hidden_remaps(
            if forward {
                "remap"
            } else {
                "remap_right_to_left"
            },
            from,
        ),
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
                hint: if forward {
                    "depth converted one way only: depth_left in [0, 1] becomes \
                     z_ndc = 2·depth − 1, AND the result goes back: depth = (z_ndc + 1)/2"
                } else {
                    "depth converted one way only: depth_right in [0, 1] becomes \
                     z_ndc = 2·depth − 1, AND the result goes back: depth = (z_ndc + 1)/2"
                },
                answers: each(RemapVariant {
                    depth_out_raw: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "one-sided-depth",
                hint: if forward {
                    "depth converted one way only: the result is converted back with \
                     (z_ndc + 1)/2, so depth_left must go in as z_ndc = 2·depth − 1"
                } else {
                    "depth converted one way only: the result is converted back with \
                     (z_ndc + 1)/2, so depth_right must go in as z_ndc = 2·depth − 1"
                },
                answers: each(RemapVariant {
                    depth_in_raw: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "never-none",
                hint: if forward {
                    "return None when clip_r.w ≤ 0: the point is behind the right eye and \
                     dividing by w flips it into the image"
                } else {
                    "return None when clip_l.w ≤ 0: the point is behind the left eye and \
                     dividing by w flips it into the image"
                },
                answers: each(RemapVariant {
                    never_none: true,
                    ..Default::default()
                }),
            },
            Mistake {
                id: "matrix-order",
                hint: if forward {
                    "MVP_l · MVP_r⁻¹ is the wrong way round: undo the LEFT eye's transform \
                     first, then apply the right eye's: MVP_r · MVP_l⁻¹"
                } else {
                    "MVP_r · MVP_l⁻¹ is the wrong way round here (it maps the LEFT image to \
                     the right: that is `remap`): undo the RIGHT eye's transform first, then \
                     apply the left eye's: MVP_l · MVP_r⁻¹"
                },
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
        image: Some(crate::pictures::check(image_inputs, Box::new(build))),
    }
}

/// Hidden cases of a remapping task from eye `from`.
fn hidden_remaps(task: &str, from: usize) -> Vec<Case> {
    hidden_cases(task, 2 * HIDDEN_SETUPS, |rng, _| hidden_remap(rng, from).0)
}

/// One hidden remapping case from eye `from`: a random setup and camera, a random texture
/// coordinate and a stored depth between the clip planes (f64 reference from the texture
/// coordinate: [`remap_reference`]); with the two MVPs as `(MVP_from, MVP_to)`.
fn hidden_remap(rng: &mut SplitMix64, from: usize) -> (Case, Mat4, Mat4, [f32; 2], f32) {
    let (s, cam) = random_setup(rng);
    let e = eyes(
        &s,
        &cam,
        s.eye_separation,
        CameraMode::OffAxis,
        Lighting::PerEye,
    );
    let (src, dst) = (e[from].mvp, e[1 - from].mvp);
    let uv = [rng.range(0.05, 0.95), rng.range(0.05, 0.95)];
    let depth = rng.range(0.1, 0.99);
    let (l, r) = if from == 0 { (src, dst) } else { (dst, src) };
    let case = Case {
        label: format!("hidden: uv {uv:?}, depth {depth}, {s:?}"),
        input: json!([l.to_cols_array(), r.to_cols_array(), uv, depth]),
        expected: remap_reference(&src, &dst, uv, depth, RemapVariant::default()),
    };
    (case, src, dst, uv, depth)
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec2, Vec4};

    /// The exercise slides' chain in f32, as a student (and the instructor's solution) writes it.
    fn f32_chain(src: Mat4, dst: Mat4, uv: [f32; 2], depth: f32) -> Vec<f64> {
        let ndc = (2.0 * Vec2::from(uv) - Vec2::ONE).extend(2.0 * depth - 1.0);
        let clip = dst * src.inverse() * Vec4::from((ndc, 1.0));
        if clip.w <= 0.0 {
            return Vec::new();
        }
        let n = clip.truncate() / clip.w;
        [0.5 * (n.x + 1.0), 0.5 * (n.y + 1.0), 0.5 * (n.z + 1.0)]
            .map(f64::from)
            .to_vec()
    }

    #[test]
    fn the_f32_chain_passes_the_hidden_remaps_of_many_seeds_with_room_to_spare() {
        let mut worst = 0.0f64;
        for seed in 0..500u64 {
            for (task, from) in [("remap", 0), ("remap_right_to_left", 1)] {
                let mut rng = SplitMix64::for_task(seed, task);
                for _ in 0..2 * HIDDEN_SETUPS {
                    let (case, src, dst, uv, depth) = hidden_remap(&mut rng, from);
                    let got = f32_chain(src, dst, uv, depth);
                    assert_eq!(got.len(), 3, "{}", case.label);
                    for (a, e) in got.iter().zip(&case.expected) {
                        worst = worst.max((a - e).abs());
                    }
                }
            }
        }
        // Measured: 3.4e-5 at worst over these 8000 cases (far/near up to 200, depth up to
        // 0.99); the tolerance is 2e-4.
        assert!(worst < 5e-5, "worst f32 error {worst:e}");
    }
}
