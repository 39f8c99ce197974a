//! A render's peak memory, estimated before it starts, and the budget it must fit
//! (`stereolab render --max-memory`, shown by `--explain`).
//!
//! The model counts what a render holds at once: one framebuffer a pass (8-bit RGBA and an f32
//! depth: 8 bytes a pixel), every output image (they are all made before any is written), one
//! output's working copy, and the geometry (the mesh, and each pass's transformed vertices and
//! triangle set-ups). Its per-vertex and per-triangle bytes come from measuring peak resident
//! memory with one and two passes on three meshes: a 2 M-triangle sphere (half a vertex a
//! triangle) at 4096×3072, where most triangles keep a set-up, a 1 M-triangle OBJ of separate
//! triangles (three vertices each), and 4 M slivers ear-clipped from 1024-corner stars (1 024
//! vertices in all). A pass took about 83 bytes a vertex, and from 175 to 285 bytes a
//! triangle; the estimate takes the most, rounded up, for every triangle (at 64×48 most cover
//! no pixel center and keep no set-up, so small images are overestimated, up to about 3× for
//! a 4 M-triangle sphere at 1024×768).
//! Two terms look at the geometry through each pass's matrices first: the bands' lists (a
//! triangle is listed in every 32-row band its projected rows cross, 8 bytes each) and a
//! second set-up for every triangle that reaches past the frustum's sides (clipping turns it
//! into a fan). `tests/memory.rs` holds the estimate above the measured peak of real renders.

use std::fmt;

use crate::plan::{Output, Plan};
use crate::scene::Scene;
use stereolab_core::{Error, Result};

/// Bytes of one framebuffer pixel: RGBA8 color and f32 depth.
pub const FRAMEBUFFER_BYTES_PER_PIXEL: u64 = 8;
/// Bytes a vertex of a mesh takes (position and normal).
pub const MESH_BYTES_PER_VERTEX: u64 = 24;
/// Bytes a triangle of a mesh takes (three indices).
pub const MESH_BYTES_PER_TRIANGLE: u64 = 12;
/// Bytes a vertex takes in each pass (its clip-space and window positions, its varyings),
/// measured, rounded up.
pub const PASS_BYTES_PER_VERTEX: u64 = 96;
/// Bytes a triangle takes in each pass (its set-up and its places in the bands' lists), the
/// most measured, rounded up.
pub const PASS_BYTES_PER_TRIANGLE: u64 = 288;
/// Bytes of one entry in a band's list of triangles (a reference to the triangle's set-up).
pub const BAND_ENTRY_BYTES: u64 = 8;
/// Rows in a band of the rasterizer (each band lists the triangles that cross its rows).
pub const BAND_ROWS: u32 = 32;

/// The process itself: code, the thread pool's stacks, the scene's text.
pub const BASE_BYTES: u64 = 32 << 20;

/// A render's estimated peak memory, by what holds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryEstimate {
    /// The passes' framebuffers.
    pub framebuffers: u64,
    /// The output images, and one output's working copy.
    pub outputs: u64,
    /// The mesh and each pass's transformed geometry.
    pub geometry: u64,
    /// All of it, the process included.
    pub total: u64,
}

/// How many eye-sized RGBA images `output` holds when made (side-by-side formats two, a
/// 16-bit depth map half of one, the SIRDS figure six panels).
pub fn images_held(output: Output) -> f64 {
    match output {
        Output::LeftDepth | Output::RightDepth => 0.5,
        Output::SideBySide
        | Output::CrossEyed
        | Output::AboveBelow
        | Output::FrameSequential
        | Output::AboveBelowCalibration
        | Output::Mpo
        | Output::Jps
        | Output::Pns => 2.0,
        // Both views and the active space between them (H/24 rows).
        Output::FramePacking => 2.0 + 1.0 / 24.0,
        Output::ShearVsRotate => 3.0,
        // Both eyes; the GIF also its palette indices (a byte a pixel, each eye) and the
        // quantiser's copy of both eyes.
        Output::WiggleApng => 2.0,
        Output::WiggleGif => 4.5,
        // The tiles' whole grid, empty tiles included.
        Output::ViewTiles(n) => {
            let (columns, rows) = stereolab_core::view_grid(u32::from(n));
            f64::from(columns * rows)
        }
        Output::SirdsFig5 => 6.0,
        _ => 1.0,
    }
}

/// The estimate for rendering `scene` with `plan`.
pub fn estimate(scene: &Scene, plan: &Plan) -> MemoryEstimate {
    let pixels = u64::from(scene.width) * u64::from(scene.height);
    let passes = plan.passes.len() as u64;
    let framebuffers = passes * pixels * FRAMEBUFFER_BYTES_PER_PIXEL;
    let eye_image = pixels as f64 * 4.0;
    let held: f64 = plan.outputs.iter().map(|&o| images_held(o)).sum();
    let working = if plan.outputs.is_empty() { 0.0 } else { 1.0 };
    let outputs = ((held + working) * eye_image).ceil() as u64;
    let (vertices, triangles) = scene.objects.iter().fold((0u64, 0u64), |(v, t), o| {
        (
            v + o.mesh.positions.len() as u64,
            t + o.mesh.triangles.len() as u64,
        )
    });
    // The bands' lists (each triangle once in every band its projected rows cross), and a
    // second set-up for each triangle the frustum clips (its polygon becomes a fan).
    let (bands, clipped) = crate::render::ViewMatrices::new(scene, plan).map_or((0, 0), |views| {
        plan.passes
            .iter()
            .filter_map(|p| views.get(p.view))
            .map(|m| pass_geometry(scene, &m.mvp))
            .fold((0, 0), |(b, c), (pb, pc)| (b + pb, c + pc))
    });
    let geometry = vertices * (MESH_BYTES_PER_VERTEX + passes * PASS_BYTES_PER_VERTEX)
        + triangles * (MESH_BYTES_PER_TRIANGLE + passes * PASS_BYTES_PER_TRIANGLE)
        + bands * BAND_ENTRY_BYTES
        + clipped * PASS_BYTES_PER_TRIANGLE;
    let held = framebuffers + outputs + geometry;
    MemoryEstimate {
        framebuffers,
        outputs,
        geometry,
        // A quarter more for the allocator: mimalloc (the `mimalloc` feature) keeps freed
        // pages a while, and its peaks came up to 15% above the sum (the anaglyph scene at
        // 2048²; the system allocator's within 1% of it at 8192²).
        total: BASE_BYTES + held + held / 4,
    }
}

/// For a pass through `view_projection`: how many entries the rasterizer's bands' lists get
/// (every triangle once for each band of [`BAND_ROWS`] rows its vertices' projected rows
/// span; all bands when a vertex is behind the eye, none when the triangle lies wholly above
/// or below the image), and how many triangles reach past the frustum's sides (clipped into
/// a fan). A triangle that culling drops still counts: an upper bound.
pub fn pass_geometry(scene: &Scene, view_projection: &glam::Mat4) -> (u64, u64) {
    let h = f64::from(scene.height);
    let all = u64::from(scene.height.div_ceil(BAND_ROWS));
    let mut rows: Vec<Option<f64>> = Vec::new();
    let mut outside: Vec<bool> = Vec::new();
    let (mut entries, mut clipped) = (0u64, 0u64);
    for o in &scene.objects {
        let mvp = *view_projection * o.model;
        rows.clear();
        outside.clear();
        for p in &o.mesh.positions {
            let c = mvp * p.extend(1.0);
            // Window row of the vertex: y = −1 is the bottom row.
            rows.push((c.w > 0.0).then(|| (1.0 - f64::from(c.y) / f64::from(c.w)) * 0.5 * h));
            outside.push(!(c.x.abs() <= c.w && c.y.abs() <= c.w));
        }
        for t in &o.mesh.triangles {
            let out = t
                .iter()
                .any(|&i| outside.get(i as usize).copied().unwrap_or(true));
            clipped += u64::from(out);
            let corners = t.map(|i| rows.get(i as usize).copied().flatten());
            let [Some(a), Some(b), Some(c)] = corners else {
                entries += all;
                continue;
            };
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            if !(lo.is_finite() && hi.is_finite()) {
                entries += all;
            } else if hi >= 0.0 && lo < h {
                let first = (lo.max(0.0) as u64) / u64::from(BAND_ROWS);
                let last = (hi.min(h - 1.0) as u64) / u64::from(BAND_ROWS);
                entries += last - first + 1;
            }
        }
    }
    (entries, clipped)
}

/// Bytes as a person reads them: `512 MiB`, `10.4 GiB`.
pub fn human_bytes(bytes: u64) -> String {
    const GIB: f64 = (1u64 << 30) as f64;
    const MIB: f64 = (1u64 << 20) as f64;
    let b = bytes as f64;
    if b >= GIB {
        format!("{:.1} GiB", b / GIB)
    } else {
        format!("{:.0} MiB", (b / MIB).ceil())
    }
}

impl fmt::Display for MemoryEstimate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "about {} (framebuffers {}, output images {}, geometry {})",
            human_bytes(self.total),
            human_bytes(self.framebuffers),
            human_bytes(self.outputs),
            human_bytes(self.geometry)
        )
    }
}

/// This process's peak resident memory so far (`VmHWM` of `/proc/self/status`; Linux only),
/// what `render` reports beside its estimate.
pub fn peak_resident() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// The machine's memory: the smaller of its RAM (`/proc/meminfo`'s `MemTotal`) and the
/// cgroup's limit (`memory.max`), when they can be read.
pub fn machine_memory() -> Option<u64> {
    let ram = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        let line = t.lines().find(|l| l.starts_with("MemTotal:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib * 1024)
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|t| t.trim().parse::<u64>().ok());
    match (ram, cgroup) {
        (Some(r), Some(c)) => Some(r.min(c)),
        (r, c) => r.or(c),
    }
}

/// The default budget: three quarters of [`machine_memory`] (8 GiB when it cannot be read).
pub fn default_budget() -> u64 {
    machine_memory().map_or(8 << 30, |m| m / 4 * 3)
}

/// Parses a `--max-memory` value: bytes, or a number with `K`, `M`, `G` or `T` (binary units,
/// `iB` or `B` after them allowed, case ignored): `512M`, `4G`, `1.5GiB`.
///
/// # Errors
/// `Invalid` naming `--max-memory`, the value and the accepted forms.
pub fn parse_bytes(text: &str) -> Result<u64> {
    let bad = || {
        Error::invalid(
            "--max-memory",
            stereolab_core::excerpt(text),
            "must be a size such as 512M, 4G or 1.5GiB (binary units K, M, G, T), at least 1M",
        )
    };
    let t = text.trim().to_ascii_uppercase();
    let t = t
        .strip_suffix("IB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(&t);
    let (number, shift) = match t.chars().last() {
        Some('K') => (&t[..t.len() - 1], 10),
        Some('M') => (&t[..t.len() - 1], 20),
        Some('G') => (&t[..t.len() - 1], 30),
        Some('T') => (&t[..t.len() - 1], 40),
        _ => (t, 0),
    };
    let value: f64 = number.trim().parse().map_err(|_| bad())?;
    let bytes = value * (1u64 << shift) as f64;
    if !bytes.is_finite() || !(f64::from(1u32 << 20)..=2f64.powi(60)).contains(&bytes) {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// Refuses a render whose estimate is above `budget`, saying what holds the memory and what
/// to change.
///
/// # Errors
/// `Invalid` naming `--max-memory` with the estimate and the budget.
pub fn check_budget(estimate: &MemoryEstimate, budget: u64, default: bool) -> Result<()> {
    if estimate.total <= budget {
        return Ok(());
    }
    let whose = if default {
        " (the default: three quarters of this machine's memory)"
    } else {
        ""
    };
    Err(Error::invalid(
        "--max-memory",
        human_bytes(budget),
        format!(
            "this render needs {estimate}, more than the budget{whose}: lower --size, ask \
             for fewer outputs, or raise --max-memory"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_read_in_binary_units() {
        assert_eq!(parse_bytes("512M").unwrap(), 512 << 20);
        assert_eq!(parse_bytes("4g").unwrap(), 4 << 30);
        assert_eq!(parse_bytes("1.5GiB").unwrap(), 3 << 29);
        assert_eq!(parse_bytes("2097152").unwrap(), 2 << 20);
        for bad in ["", "G", "-1G", "1K", "nan", "1e300", "12X", "4 G B"] {
            let e = parse_bytes(bad).expect_err(bad).to_string();
            assert!(
                e.contains("--max-memory") && e.contains("512M"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn the_refusal_names_the_estimate_and_the_budget() {
        let e = MemoryEstimate {
            framebuffers: 4 << 30,
            outputs: 6 << 30,
            geometry: 1 << 20,
            total: 10 << 30,
        };
        assert!(check_budget(&e, 10 << 30, true).is_ok());
        let msg = check_budget(&e, 6 << 30, true).unwrap_err().to_string();
        assert!(
            msg.contains("about 10.0 GiB")
                && msg.contains("6.0 GiB")
                && msg.contains("three quarters"),
            "{msg}"
        );
    }
}
