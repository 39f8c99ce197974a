//! The instructor's solution (feature `solution`). Never part of the student handout.
//!
//! `STEREOLAB_MUTANT=name[,name]` plants a known mistake for the grader's mutation tests
//! (tests/grading.rs): `swapped-eyes`, `toe-in`, `full-separation`, `transposed-anaglyph`,
//! `opengl-depth`, `hang-parallax`, `nan-parallax`, `transposed-frustum`, `fov-degrees`,
//! `mv-t-order`, `one-sided-depth`, `no-w-divide`, `never-none`, `sheet-unscaled-shift`,
//! `sheet-d-not-dw`, `remap-back-same-order`, `finalize-transposed`, `finalize-no-clamp`,
//! `finalize-swapped-eyes`, `rds-no-visibility`, `rds-v-not-flipped`, `rds-pixel-corner`,
//! `rds-left-fallback`.

use exercise_api::{
    AnaglyphKind, AnaglyphMatrices, ColorMatrix, Eye, EyeView, ScreenSetup, StereoSetup, Texture,
};
use exercise_api::{Lighting, look_at};
use glam::{Mat4, Vec2, Vec3, Vec4};

fn planted(mistake: &str) -> bool {
    std::env::var("STEREOLAB_MUTANT").is_ok_and(|v| v.split(',').any(|m| m == mistake))
}

/// `P_frustum(l, r, b, t, n, f)` (the exercise slides).
pub fn frustum(l: f32, r: f32, b: f32, t: f32, n: f32, f: f32) -> Mat4 {
    let m = Mat4::from_cols(
        Vec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
        Vec4::new(
            (r + l) / (r - l),
            (t + b) / (t - b),
            (n + f) / (n - f),
            -1.0,
        ),
        Vec4::new(0.0, 0.0, 2.0 * n * f / (n - f), 0.0),
    );
    if planted("transposed-frustum") {
        m.transpose()
    } else {
        m
    }
}

/// −1 for the left eye, +1 for the right eye.
fn side(eye: Eye) -> f32 {
    let eye = if planted("swapped-eyes") {
        eye.other()
    } else {
        eye
    };
    match eye {
        Eye::Left => -1.0,
        Eye::Right => 1.0,
    }
}

/// Half the eye separation (the whole of it with the `full-separation` mistake).
fn half_separation(s: &StereoSetup) -> f32 {
    if planted("full-separation") {
        s.eye_separation
    } else {
        0.5 * s.eye_separation
    }
}

/// `[l, r, b, t, n, f]` of `P_frustum±` (the exercise slides).
pub fn stereo_frustum(setup: &StereoSetup, eye: Eye) -> [f32; 6] {
    let fov = if planted("fov-degrees") {
        setup.fov_y_degrees
    } else {
        setup.fov_y_degrees.to_radians()
    };
    let t = setup.near * (fov * 0.5).tan();
    let w = t * setup.aspect;
    let shift = if planted("toe-in") {
        0.0
    } else {
        -side(eye) * half_separation(setup) * setup.near / setup.zero_parallax
    };
    [-w + shift, w + shift, -t, t, setup.near, setup.far]
}

/// `[l, r, b, t, n, f]` of `P_frustum±` in the exercise slides' screen-relative terms.
pub fn sheet_frustum(screen: &ScreenSetup, eye: Eye) -> [f32; 6] {
    let scale = screen.near / screen.zero_parallax;
    let t = 0.5 * screen.height * scale;
    let r = 0.5 * screen.width * scale;
    // The eye's offset from the center: ½·d·w (½·d with the `sheet-d-not-dw` mistake).
    let offset = if planted("sheet-d-not-dw") {
        0.5 * screen.eye_separation_fraction
    } else {
        0.5 * screen.eye_separation_fraction * screen.width
    };
    let shift = if planted("sheet-unscaled-shift") {
        offset
    } else {
        offset * scale
    };
    let shift = match eye {
        Eye::Left => shift,
        Eye::Right => -shift,
    };
    [-r + shift, r + shift, -t, t, screen.near, screen.far]
}

/// View and projection of one eye (the exercise slides, per-eye or cyclopic lighting).
pub fn stereo_matrices(
    setup: &StereoSetup,
    modelview: Mat4,
    eye: Eye,
    lighting: Lighting,
) -> EyeView {
    let [l, r, b, t, n, f] = stereo_frustum(setup, eye);
    let p = frustum(l, r, b, t, n, f);
    let half = half_separation(setup);
    let translation = Mat4::from_translation(Vec3::new(-side(eye) * half, 0.0, 0.0));
    let eye_view = if planted("toe-in") {
        // The SGI course notes' rotated eyes: each looks at the fusion point on the center line.
        let inv = modelview.inverse();
        let at = inv.transform_point3(Vec3::new(side(eye) * half, 0.0, 0.0));
        let fusion = inv.transform_point3(Vec3::new(0.0, 0.0, -setup.zero_parallax));
        look_at(at, fusion, inv.transform_vector3(Vec3::Y))
    } else {
        translation * modelview
    };
    match lighting {
        Lighting::PerEye if planted("mv-t-order") => EyeView {
            view: modelview * translation,
            projection: p,
        },
        Lighting::PerEye => EyeView {
            view: eye_view,
            projection: p,
        },
        Lighting::Cyclopic => EyeView {
            view: modelview,
            projection: p * eye_view * modelview.inverse(),
        },
    }
}

const LUMA: [f32; 3] = [0.299, 0.587, 0.114];
const ZERO: [f32; 3] = [0.0; 3];

fn transposed(m: ColorMatrix) -> ColorMatrix {
    std::array::from_fn(|i| std::array::from_fn(|j| m[j][i]))
}

/// ML, MR of the exercise slides' four anaglyphs.
pub fn anaglyph_matrices(kind: AnaglyphKind) -> AnaglyphMatrices {
    let left = match kind {
        AnaglyphKind::Color => [[1.0, 0.0, 0.0], ZERO, ZERO],
        _ => [LUMA, ZERO, ZERO],
    };
    let right = match kind {
        AnaglyphKind::True => [ZERO, ZERO, LUMA],
        AnaglyphKind::Gray => [ZERO, LUMA, LUMA],
        AnaglyphKind::Color | AnaglyphKind::HalfColor => [ZERO, [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };
    if planted("transposed-anaglyph") {
        AnaglyphMatrices {
            left: transposed(left),
            right: transposed(right),
        }
    } else {
        AnaglyphMatrices { left, right }
    }
}

/// The finalize shader's pixel: `clamp(ML·left + MR·right, 0, 1)`.
pub fn finalize_pixel(left: [f32; 3], right: [f32; 3], m: &AnaglyphMatrices) -> [f32; 3] {
    let (left, right) = if planted("finalize-swapped-eyes") {
        (right, left)
    } else {
        (left, right)
    };
    let (ml, mr) = if planted("finalize-transposed") {
        (transposed(m.left), transposed(m.right))
    } else {
        (m.left, m.right)
    };
    std::array::from_fn(|i| {
        let v = (0..3)
            .map(|j| ml[i][j] * left[j] + mr[i][j] * right[j])
            .sum::<f32>();
        if planted("finalize-no-clamp") {
            v
        } else {
            v.clamp(0.0, 1.0)
        }
    })
}

/// Dubois red-cyan (three.js' CRT-derived numbers).
pub fn dubois_matrices() -> AnaglyphMatrices {
    AnaglyphMatrices {
        left: [
            [0.456100, 0.500484, 0.176381],
            [-0.0400822, -0.0378246, -0.0157589],
            [-0.0152161, -0.0205971, -0.00546856],
        ],
        right: [
            [-0.0434706, -0.0879388, -0.00155529],
            [0.378476, 0.73364, -0.0184503],
            [-0.0721527, -0.112961, 1.2264],
        ],
    }
}

/// The exercise slides' remapping through `MVP_r · MVP_l⁻¹`.
pub fn remap(mvp_left: Mat4, mvp_right: Mat4, uv_left: Vec2, depth_left: f32) -> Option<Vec3> {
    let z_ndc = if planted("opengl-depth") {
        depth_left
    } else {
        2.0 * depth_left - 1.0
    };
    let ndc_left = (2.0 * uv_left - Vec2::ONE).extend(z_ndc).extend(1.0);
    let clip = mvp_right * mvp_left.inverse() * ndc_left;
    if clip.w <= 0.0 && !planted("never-none") {
        return None;
    }
    let ndc = if planted("no-w-divide") {
        clip.truncate()
    } else {
        clip.truncate() / clip.w
    };
    let depth = if planted("opengl-depth") || planted("one-sided-depth") {
        ndc.z
    } else {
        0.5 * (ndc.z + 1.0)
    };
    Some(Vec3::new(0.5 * (ndc.x + 1.0), 0.5 * (ndc.y + 1.0), depth))
}

/// The other direction: the right eye's point in the left image, `MVP_l · MVP_r⁻¹` ([`remap`]
/// with the eyes' roles exchanged).
pub fn remap_right_to_left(
    mvp_left: Mat4,
    mvp_right: Mat4,
    uv_right: Vec2,
    depth_right: f32,
) -> Option<Vec3> {
    if planted("remap-back-same-order") {
        remap(mvp_left, mvp_right, uv_right, depth_right)
    } else {
        remap(mvp_right, mvp_left, uv_right, depth_right)
    }
}

/// The exercise slides' visibility check.
pub fn visible(
    uv_right: Option<Vec2>,
    remapped_depth: f32,
    stored_depth: f32,
    tolerance: f32,
) -> bool {
    let Some(uv) = uv_right else { return false };
    let inside = (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y);
    inside && (stored_depth - remapped_depth).abs() <= tolerance
}

/// Julesz's random-dot pair: the right image's dots through the remap and visibility check.
#[allow(clippy::too_many_arguments)]
pub fn rds_right(
    mvp_left: Mat4,
    mvp_right: Mat4,
    left_depth: &Texture<f32>,
    right_depth: &Texture<f32>,
    left_dots: &Texture<bool>,
    fresh_dots: &Texture<bool>,
    tolerance: f32,
) -> Texture<bool> {
    let (w, h) = (right_depth.width, right_depth.height);
    let mut out = Texture::new(w, h, false);
    let corner = if planted("rds-pixel-corner") {
        0.0
    } else {
        0.5
    };
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new(
                (x as f32 + corner) / w as f32,
                1.0 - (y as f32 + corner) / h as f32,
            );
            let fallback = if planted("rds-left-fallback") {
                left_dots.get(x, y)
            } else {
                fresh_dots.get(x, y)
            };
            let dot = remap_right_to_left(mvp_left, mvp_right, uv, right_depth.get(x, y))
                .and_then(|p| {
                    let row = if planted("rds-v-not-flipped") {
                        p.y
                    } else {
                        1.0 - p.y
                    };
                    let (tx, ty) = ((p.x * w as f32).floor(), (row * h as f32).floor());
                    let inside = tx >= 0.0 && ty >= 0.0 && tx < w as f32 && ty < h as f32;
                    let (tx, ty) = (tx as usize, ty as usize);
                    let seen = inside
                        && (planted("rds-no-visibility")
                            || visible(Some(p.truncate()), p.z, left_depth.get(tx, ty), tolerance));
                    seen.then(|| left_dots.get(tx, ty))
                })
                .unwrap_or(fallback);
            out.set(x, y, dot);
        }
    }
    out
}

/// `p(z) = d (1 − z0/z)` (the exercise slides).
pub fn parallax(z: f32, zero_parallax: f32, eye_separation: f32) -> f32 {
    if planted("hang-parallax") {
        #[allow(clippy::empty_loop)]
        loop {}
    }
    if planted("nan-parallax") {
        return f32::NAN;
    }
    eye_separation * (1.0 - zero_parallax / z)
}

/// Red for positive, blue for negative parallax.
pub fn parallax_color(p: f32, max_abs: f32) -> [f32; 3] {
    let t = (p / max_abs).clamp(-1.0, 1.0);
    if t >= 0.0 {
        [t, 0.0, 0.0]
    } else {
        [0.0, 0.0, -t]
    }
}
