//! The Blinn-Phong fragment stage eight pixels at a time: [`BlinnPhong::fragment`]'s
//! arithmetic on AVX2 lanes, with the depth test LESS and the color and depth writes of
//! [`traverse`](super::traverse) around it.
//!
//! Every lane performs the scalar code's IEEE operations in the same order: the plane
//! evaluations `(a0 + dadx·fx) + dady·fy`, one division `1 / (1/w)` for perspective, the three
//! `normalize_or_zero` of glam (`(x·x + y·y) + z·z`, `sqrt`, `1 / length`, kept only where
//! that reciprocal is finite and positive), the dot products in the same order, the specular
//! power by the same repeated squaring as [`powi`](crate::shade::powi), and the rounding of
//! [`to_rgba8`](crate::shade::to_rgba8). No fused multiply-add: `sqrt`, `+`, `−`, `×` and `÷`
//! are correctly rounded in both, so the bytes are the scalar stage's
//! (`avx2_blinn_phong_matches_traverse`, the golden images and the scene hashes hold them).
//! The scalar path stays the reference: it is what runs without AVX2 or with
//! `STEREOLAB_SCALAR=1`.
//!
//! A vector costs the same to shade for one covered pixel as for eight, and a triangle smaller
//! than a pixel covers one. Vectors where at most [`PENDING_LANES`] pixels passed the depth
//! test therefore wait in [`Pending`], and are shaded eight fragments at a time, each lane with
//! its own triangle's planes: the same operations per lane, so the same bytes.

use std::arch::x86_64::*;

use super::avx2::{clamp01, columns, covered_vectors, depth_at, load, store};
use super::{Band, Plane, SetupTriangle};
use crate::shade::BlinnPhong;

/// The uniforms of one Blinn-Phong program, splatted once per band.
#[derive(Clone, Copy)]
pub(crate) struct Uniforms {
    /// The light position in the lighting eye's space.
    light: [f32; 3],
    /// The material color.
    color: [f32; 3],
    ambient: f32,
    specular: f32,
    /// The whole-number exponent (`None`: `powf` needed, no vector form here).
    power: u32,
}

impl Uniforms {
    /// The uniforms of `s`, when its specular power is the repeated-squaring case of
    /// [`specular_power`](crate::shade::specular_power) (a whole exponent up to 1024); `None`
    /// otherwise (the scalar stage then runs, with its `powf`).
    pub(crate) fn of(s: &BlinnPhong) -> Option<Uniforms> {
        let light = s.light();
        let n = light.shininess;
        let whole = (0.0..=1024.0).contains(&n) && (n as u32) as f32 == n;
        whole.then(|| Uniforms {
            light: s.light_eye().to_array(),
            color: s.color().to_array(),
            ambient: light.ambient,
            specular: light.specular,
            power: n as u32,
        })
    }
}

/// [`traverse`](super::traverse) of one triangle over `band` with the Blinn-Phong program `u`,
/// depth test LESS with depth writes: the same color and depth bits, the same fragment count.
///
/// # Safety
/// The CPU must support AVX2, FMA and POPCNT ([`super::avx2::available`]).
#[target_feature(enable = "avx2,fma,popcnt")]
pub(crate) unsafe fn shade_triangle(
    t: &SetupTriangle,
    u: &Uniforms,
    band: &mut Band,
    pending: &mut Pending,
    perspective_correct: bool,
) -> usize {
    let rows = (band.depth.len() / band.width.max(1) as usize) as u32;
    let (x0, y0, w) = (band.x0, band.y0, band.width as usize);
    let mut passed = 0;
    covered_vectors(t, (x0, y0, band.width, rows), |y, x, mask| {
        let i = (y - y0) as usize * w + (x - x0) as usize;
        // SAFETY: this function runs only where AVX2 is available; `i` is the vector's first
        // pixel in the tile, and `mask` covers only pixels inside it.
        passed +=
            unsafe { shade_vector(t, u, (x, y), mask, i, band, pending, perspective_correct) };
    });
    passed
}

/// Lanes of a vector that passed the depth test up to which they wait in [`Pending`] instead
/// of being shaded at once. A vector costs the same to shade for one lane as for eight; a
/// triangle smaller than a pixel passes one lane per vector. Measured on a 1 M-triangle grid
/// (sub-pixel triangles) and on the real model at 1024×768 (its triangles' spans end in
/// vectors of a few lanes): one lane takes the grid's gain (11% less CPU time per frame) and
/// leaves the real model's frame as it was; three lanes slowed the real model by 4%.
const PENDING_LANES: u32 = 1;

/// Fragments of small triangles that passed the depth test (their depth written), waiting to
/// be shaded eight at a time, each lane with its own triangle's planes.
///
/// A waiting fragment's color is written when the batch is shaded, if the pixel still holds
/// its depth: the depth test is LESS, so any later fragment that passed there left a smaller
/// depth, and its color (written at once, or waiting after this one) is the pixel's. The
/// bytes are those of shading each fragment when it passed.
pub(crate) struct Pending {
    n: usize,
    /// Per waiting fragment: its pixel in the band, its depth's bits, its `fx`.
    pixel: [usize; 8],
    depth: [u32; 8],
    fx: [f32; 8],
    /// Per plane (1/w, then the six varyings) and lane: `a0`, `dadx` and `dady·fy`, the three
    /// terms of [`plane_at`](super::avx2::plane_at).
    planes: [[[f32; 8]; 3]; PLANES],
    /// −0.0 for a back face (its normal is negated), +0.0 for a front face.
    back: [f32; 8],
}

/// The planes the lighting reads: 1/w and the six varyings of [`BlinnPhong`] (position and
/// normal in eye space).
const PLANES: usize = 7;

/// `t`'s plane `k` in the order [`lighting`] reads them: 1/w, then the six varyings.
#[inline(always)]
fn lighting_plane(t: &SetupTriangle, k: usize) -> Plane {
    if k == 0 {
        t.inv_w_plane()
    } else {
        t.varying_plane(k - 1)
    }
}

impl Pending {
    /// No fragment waiting.
    pub(crate) fn new() -> Pending {
        Pending {
            n: 0,
            pixel: [0; 8],
            depth: [0; 8],
            fx: [0.0; 8],
            planes: [[[0.0; 8]; 3]; PLANES],
            back: [0.0; 8],
        }
    }

    /// Shades the waiting fragments (eight lanes, the unused ones ignored) and writes the
    /// color of each whose pixel still holds its depth.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA; `band` is the band the fragments were added from.
    #[target_feature(enable = "avx2,fma")]
    pub(crate) unsafe fn flush(
        &mut self,
        u: &Uniforms,
        band: &mut Band,
        perspective_correct: bool,
    ) {
        if self.n == 0 {
            return;
        }
        // SAFETY: each array holds eight f32, the unaligned load's width.
        let load = |a: &[f32; 8]| unsafe { _mm256_loadu_ps(a.as_ptr()) };
        let planes = self.planes.each_ref().map(|p| p.each_ref().map(load));
        let rgba = lighting(
            u,
            load(&self.fx),
            &planes,
            load(&self.back),
            perspective_correct,
        );
        let mut out = [0u32; 8];
        // SAFETY: `out` holds eight u32, one 256-bit store.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), rgba) };
        let waiting = self.pixel.iter().zip(&self.depth).zip(&out).take(self.n);
        for ((&i, &depth), rgba) in waiting {
            if band.depth[i].to_bits() == depth {
                band.color[i] = rgba.to_le_bytes();
            }
        }
        self.n = 0;
    }

    /// Adds the `pass` lanes of a vector of `t` at pixel `i` of the band (depths `z`, columns
    /// `fx`, row `fy`), shading the waiting ones first when they would not fit.
    ///
    /// # Safety
    /// As [`Pending::flush`].
    #[target_feature(enable = "avx2,fma")]
    unsafe fn add(
        &mut self,
        t: &SetupTriangle,
        (i, pass): (usize, i32),
        (z, fx, fy): (__m256, __m256, f32),
        (u, band, perspective_correct): (&Uniforms, &mut Band, bool),
    ) {
        if self.n + pass.count_ones() as usize > 8 {
            // SAFETY: as this function's own conditions.
            unsafe { self.flush(u, band, perspective_correct) };
        }
        let (mut zs, mut fxs) = ([0f32; 8], [0f32; 8]);
        // SAFETY: eight f32 each, one 256-bit store.
        unsafe {
            _mm256_storeu_ps(zs.as_mut_ptr(), z);
            _mm256_storeu_ps(fxs.as_mut_ptr(), fx);
        }
        let back = if t.front_facing { 0.0 } else { -0.0 };
        for lane in 0..8 {
            if pass & (1 << lane) == 0 {
                continue;
            }
            let n = self.n;
            self.pixel[n] = i + lane;
            self.depth[n] = zs[lane].to_bits();
            self.fx[n] = fxs[lane];
            for (k, p) in self.planes.iter_mut().enumerate() {
                let q = lighting_plane(t, k);
                (p[0][n], p[1][n], p[2][n]) = (q.a0, q.dadx, q.dady * fy);
            }
            self.back[n] = back;
            self.n += 1;
        }
    }
}

/// glam's `normalize_or_zero` per lane: `v · (1 / √((x·x + y·y) + z·z))` where that
/// reciprocal is finite and positive, else zero.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn normalize_or_zero(v: [__m256; 3]) -> [__m256; 3] {
    let len2 = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(v[0], v[0]), _mm256_mul_ps(v[1], v[1])),
        _mm256_mul_ps(v[2], v[2]),
    );
    let rcp = _mm256_div_ps(_mm256_set1_ps(1.0), _mm256_sqrt_ps(len2));
    let ok = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_GT_OQ>(rcp, _mm256_setzero_ps()),
        _mm256_cmp_ps::<_CMP_LT_OQ>(rcp, _mm256_set1_ps(f32::INFINITY)),
    );
    v.map(|c| _mm256_and_ps(_mm256_mul_ps(c, rcp), ok))
}

/// `a · b` in glam's order: `(ax·bx + ay·by) + az·bz`.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn dot(a: [__m256; 3], b: [__m256; 3]) -> __m256 {
    _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])),
        _mm256_mul_ps(a[2], b[2]),
    )
}

/// [`powi`](crate::shade::powi) per lane: the same multiplications in the same order.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn powi(mut x: __m256, mut n: u32) -> __m256 {
    let mut r = _mm256_set1_ps(1.0);
    loop {
        if n & 1 != 0 {
            r = _mm256_mul_ps(r, x);
        }
        n >>= 1;
        if n == 0 {
            return r;
        }
        x = _mm256_mul_ps(x, x);
    }
}

/// [`to_rgba8`](crate::shade::to_rgba8)'s rounding of one channel per lane:
/// `(clamp(c, 0, 1)·255 + ½)` truncated; NaN gives 0, as Rust's saturating `as u8`.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn channel(c: __m256) -> __m256i {
    let q = _mm256_add_ps(
        _mm256_mul_ps(clamp01(c), _mm256_set1_ps(255.0)),
        _mm256_set1_ps(0.5),
    );
    // In 0.5 ..= 255.5, so the truncation lies in 0 ..= 255; NaN truncates to i32::MIN,
    // whose low byte is 0.
    _mm256_and_si256(_mm256_cvttps_epi32(q), _mm256_set1_epi32(0xff))
}

/// One vector of the stage: pixels `x .. x + 8` of row `y` (the first at pixel `i` of the
/// band) where `mask` is set. Depth test LESS; where it passes, the depth write and
/// [`BlinnPhong::fragment`] per lane, then the color write: at once, or for a vector with at
/// most [`PENDING_LANES`] lanes passed, when `pending` is shaded. Returns how many passed.
///
/// # Safety
/// The CPU must support AVX2; `mask` covers only pixels of `band` from pixel `i` on.
#[target_feature(enable = "avx2,fma,popcnt")]
#[inline]
#[allow(clippy::too_many_arguments)]
unsafe fn shade_vector(
    t: &SetupTriangle,
    u: &Uniforms,
    (x, y): (u32, u32),
    mask: __m256i,
    i: usize,
    band: &mut Band,
    pending: &mut Pending,
    perspective_correct: bool,
) -> usize {
    let full = band.depth.len() - i >= 8;
    let (xf, fx) = columns(t, x);
    let z = depth_at(t, xf, y);
    let dp = band.depth[i..].as_mut_ptr();
    // SAFETY: eight lanes fit when `full`; otherwise `mask` covers only pixels inside.
    let d = unsafe { load(dp, mask, full) };
    let pass = _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(z, d), _mm256_castsi256_ps(mask));
    let bits = _mm256_movemask_ps(pass);
    if bits == 0 {
        return 0;
    }
    // SAFETY: as for the load.
    unsafe { store(dp, mask, full, _mm256_blendv_ps(d, z, pass)) };
    let fy = t.fy(y);
    if bits.count_ones() <= PENDING_LANES {
        // SAFETY: as this function's own conditions.
        unsafe { pending.add(t, (i, bits), (z, fx, fy), (u, band, perspective_correct)) };
        return bits.count_ones() as usize;
    }
    let splat = |p: Plane| {
        [
            _mm256_set1_ps(p.a0),
            _mm256_set1_ps(p.dadx),
            _mm256_set1_ps(p.dady * fy),
        ]
    };
    let planes: [[__m256; 3]; PLANES] = std::array::from_fn(|k| splat(lighting_plane(t, k)));
    let back = _mm256_set1_ps(if t.front_facing { 0.0 } else { -0.0 });
    let rgba = lighting(u, fx, &planes, back, perspective_correct);
    let cp = band.color[i..].as_mut_ptr().cast::<f32>();
    // SAFETY: as for the depth above; a color is four bytes, one f32 lane, moved as bits.
    unsafe {
        let old = load(cp, mask, full);
        store(
            cp,
            mask,
            full,
            _mm256_blendv_ps(old, _mm256_castsi256_ps(rgba), pass),
        );
    }
    bits.count_ones() as usize
}

/// [`BlinnPhong::fragment`] per lane at columns `fx`, each lane with its own planes (1/w, then
/// the six varyings; per plane `a0`, `dadx` and `dady·fy`, evaluated as [`plane_at`](super::avx2::plane_at) does) and
/// its face (`back`: −0.0 negates the normal): the colors as RGBA8 words.
#[target_feature(enable = "avx2,fma")]
#[inline]
fn lighting(
    u: &Uniforms,
    fx: __m256,
    planes: &[[__m256; 3]; PLANES],
    back: __m256,
    perspective_correct: bool,
) -> __m256i {
    let at = |p: &[__m256; 3]| _mm256_add_ps(_mm256_add_ps(p[0], _mm256_mul_ps(p[1], fx)), p[2]);
    // Perspective correction: `a = (a/w) · w`, `w = 1 / (1/w)`; affine: `· 1`, which changes
    // no bit.
    let wv = if perspective_correct {
        _mm256_div_ps(_mm256_set1_ps(1.0), at(&planes[0]))
    } else {
        _mm256_set1_ps(1.0)
    };
    let var = |k: usize| _mm256_mul_ps(at(&planes[1 + k]), wv);
    let p = [var(0), var(1), var(2)];
    // Two-sided lighting: a back face's normal is `-n`, every sign bit flipped, zeros
    // included (a front face's is XORed with +0.0, which changes no bit).
    let n = normalize_or_zero([var(3), var(4), var(5)]).map(|c| _mm256_xor_ps(c, back));
    let sign = _mm256_set1_ps(-0.0);
    let l = normalize_or_zero(std::array::from_fn(|k| {
        _mm256_sub_ps(_mm256_set1_ps(u.light[k]), p[k])
    }));
    let v = normalize_or_zero(p.map(|c| _mm256_xor_ps(c, sign)));
    let h = normalize_or_zero(std::array::from_fn(|k| _mm256_add_ps(l[k], v[k])));
    let zero = _mm256_setzero_ps();
    // `f32::max(x, 0)`: 0 for NaN, as `maxps` returns its second operand then.
    let diffuse = _mm256_max_ps(dot(n, l), zero);
    let lit = _mm256_cmp_ps::<_CMP_GT_OQ>(diffuse, zero);
    let spec = if _mm256_movemask_ps(lit) != 0 {
        let s = _mm256_mul_ps(
            powi(_mm256_max_ps(dot(n, h), zero), u.power),
            _mm256_set1_ps(u.specular),
        );
        _mm256_and_ps(s, lit)
    } else {
        zero
    };
    // `color · (ambient + (1 − ambient)·diffuse) + spec`, per channel.
    let k = _mm256_add_ps(
        _mm256_set1_ps(u.ambient),
        _mm256_mul_ps(_mm256_set1_ps(1.0 - u.ambient), diffuse),
    );
    let c: [__m256i; 3] = std::array::from_fn(|i| {
        channel(_mm256_add_ps(
            _mm256_mul_ps(_mm256_set1_ps(u.color[i]), k),
            spec,
        ))
    });
    // RGBA8 in memory order: r | g << 8 | b << 16 | 255 << 24 in a little-endian word.
    _mm256_or_si256(
        _mm256_or_si256(c[0], _mm256_slli_epi32::<8>(c[1])),
        _mm256_or_si256(
            _mm256_slli_epi32::<16>(c[2]),
            _mm256_set1_epi32(0xff00_0000_u32 as i32),
        ),
    )
}
