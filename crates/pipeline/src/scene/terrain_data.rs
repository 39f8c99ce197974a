//! The terrain data sets shipped under `assets/scenes/terrain/`, in the spirit of the ChromaDepth article's gallery:
//! an earthquake fault valley and a map-like island. Generated deterministically from fixed
//! seeds with integer hashing and `+ − × ÷` only (no `sin`/`exp`, whose last bits vary between
//! math libraries), so the same CSV bytes come out on every machine.

/// splitmix64 (Steele, Lea, Flood 2014): the whole random state is one `u64`.
pub(crate) struct SplitMix64(pub(crate) u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix(self.0)
    }
    /// Uniform in [0, 1) with 53 random bits.
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// splitmix64's finalizer.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A lattice value in [0, 1) for integer cell `(i, j)`.
fn lattice(i: i64, j: i64, seed: u64) -> f64 {
    let h = mix(seed ^ mix((i as u64).wrapping_mul(0x100_0000_01B3) ^ (j as u64)));
    (h >> 11) as f64 / (1u64 << 53) as f64
}

fn smoothstep(edge0: f64, edge1: f64, x: f64) -> f64 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Value noise in [−1, 1]: lattice values blended with smoothstep weights.
fn value_noise(x: f64, y: f64, seed: u64) -> f64 {
    let (i, j) = (x.floor(), y.floor());
    let (u, v) = (smoothstep(0.0, 1.0, x - i), smoothstep(0.0, 1.0, y - j));
    let (i, j) = (i as i64, j as i64);
    let a = lattice(i, j, seed) + (lattice(i + 1, j, seed) - lattice(i, j, seed)) * u;
    let b = lattice(i, j + 1, seed) + (lattice(i + 1, j + 1, seed) - lattice(i, j + 1, seed)) * u;
    2.0 * (a + (b - a) * v) - 1.0
}

/// Fractal noise: `octaves` of value noise, each twice the frequency and half the amplitude,
/// normalized to [−1, 1].
fn fbm(x: f64, y: f64, seed: u64, octaves: u32) -> f64 {
    let (mut sum, mut amp, mut freq, mut norm) = (0.0, 1.0, 1.0, 0.0);
    for k in 0..octaves {
        sum += amp * value_noise(x * freq, y * freq, seed.wrapping_add(k as u64));
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    sum / norm
}

/// `count` uniform points over `[lo, hi]²` plus the four corners (so the triangulation covers
/// the whole square), each with `height(x, y)`.
fn scatter(
    seed: u64,
    count: usize,
    lo: f64,
    hi: f64,
    height: impl Fn(f64, f64) -> f64,
) -> Vec<[f64; 3]> {
    let mut rng = SplitMix64(seed);
    let corners = [[lo, lo], [hi, lo], [hi, hi], [lo, hi]];
    corners
        .into_iter()
        .chain((0..count).map(|_| {
            let x = lo + (hi - lo) * rng.next_f64();
            [x, lo + (hi - lo) * rng.next_f64()]
        }))
        .map(|[x, y]| [x, y, height(x, y)])
        .collect()
}

/// An earthquake fault valley on `[0, 100]²`: a stream valley running north–south, cut by a
/// strike-slip fault trace `y = 50 + 0.25 (x − 50)`. The north block is displaced 15 units east
/// (the stream's valley jogs at the fault, like offset streams on the San Andreas) and lifted
/// 5 units (a scarp). Valley walls rise about 15 units; fractal noise adds hills; 4004 points.
pub fn fault_valley_points() -> Vec<[f64; 3]> {
    scatter(0x000F_A017, 4000, 0.0, 100.0, |x, y| {
        let north = smoothstep(-1.5, 1.5, y - (50.0 + 0.25 * (x - 50.0)));
        let center = 50.0 + 15.0 * north;
        let d = (x - center) / 30.0;
        let walls = 20.0 * d * d / (0.35 + d * d);
        let dc = (x - center) / 2.5;
        let channel = -2.5 / (1.0 + dc * dc);
        let slope = 0.06 * y;
        walls + channel + slope + 5.0 * north + 2.0 * fbm(x / 12.0, y / 12.0, 7, 4) + 3.0
    })
}

/// A map-like volcanic island on `[−50, 50]²`, after the ChromaDepth article's Oahu map: two ridges (like the
/// Waianae and Ko'olau ranges) on a low dome, roughened by fractal noise; everything below sea
/// level is flat sea at height 0. 6004 points.
pub fn island_points() -> Vec<[f64; 3]> {
    let ridge = |x: f64, y: f64, a: [f64; 2], b: [f64; 2], half_width: f64, height: f64| {
        let (abx, aby) = (b[0] - a[0], b[1] - a[1]);
        let t = (((x - a[0]) * abx + (y - a[1]) * aby) / (abx * abx + aby * aby)).clamp(0.0, 1.0);
        let (dx, dy) = (x - a[0] - t * abx, y - a[1] - t * aby);
        let q = (1.0 - (dx * dx + dy * dy) / (half_width * half_width)).max(0.0);
        height * q * q
    };
    scatter(0x0000_0A40, 6000, -50.0, 50.0, move |x, y| {
        let (ex, ey) = (x / 40.0, y / 33.0);
        let dome = 1.0 - (ex * ex + ey * ey);
        let relief = ridge(x, y, [-32.0, -8.0], [-16.0, 22.0], 11.0, 16.0)
            + ridge(x, y, [4.0, -24.0], [28.0, 18.0], 12.0, 20.0);
        let h = 8.0 * dome + relief * dome.max(0.0) + 3.5 * fbm(x / 9.0, y / 9.0, 11, 5) - 1.0;
        h.max(0.0)
    })
}

/// The points as terrain CSV: `# title` comment lines, the `x,y,height` header, 3 decimals.
pub fn to_csv(title: &str, points: &[[f64; 3]]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    for line in title.lines() {
        let _ = writeln!(s, "# {line}");
    }
    s.push_str("x,y,height\n");
    for [x, y, h] in points {
        let _ = writeln!(s, "{x:.3},{y:.3},{h:.3}");
    }
    s
}

/// The shipped data sets: file name under `assets/scenes/terrain/`, its header comment, its points.
pub fn shipped() -> [(&'static str, &'static str, Vec<[f64; 3]>); 2] {
    [
        (
            "fault_valley.csv",
            "Earthquake fault valley (generated by stereolab::scene::terrain_data, seed 0xFA017).\n\
             A valley offset 15 units east and lifted 5 north of the fault y = 50 + 0.25 (x - 50).",
            fault_valley_points(),
        ),
        (
            "island.csv",
            "Map-like volcanic island with two ridges (generated by stereolab::scene::terrain_data, seed 0xA40).\n\
             Heights below sea level are clamped to 0.",
            island_points(),
        ),
    ]
}
