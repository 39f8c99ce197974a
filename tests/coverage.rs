//! The fast walks over a triangle's pixels ([`SetupTriangle::spans`], [`SetupTriangle::small_box`])
//! visit exactly the pixels of [`SetupTriangle::covers`], the readable definition of coverage;
//! and that definition's tie-break gives a pixel on a shared edge to exactly one triangle.

use std::collections::BTreeSet;

use proptest::prelude::*;
use stereolab::compare::ascii_map;
use stereolab_core::{
    MAX_VARYINGS, RasterOptions, SetupTriangle, TriangleSetup, Varyings, WindowVertex,
    setup_triangle,
};

/// The target: small, so that every pixel is tested, and not a multiple of 8 wide.
const W: u32 = 37;
const H: u32 = 29;

/// A triangle's vertices in window coordinates (pixels, y down).
type Tri = [(f32, f32); 3];

/// Sets up a triangle given in window coordinates (pixels, y down; pixel `p`'s center at
/// `p + 0.5`) for a `W`×`H` target; `None` when it covers no sample point there.
fn setup(v: Tri, bits: u32) -> Option<SetupTriangle> {
    let var: Varyings = [0.0; MAX_VARYINGS];
    let wv = v.map(|(x, y)| WindowVertex {
        x,
        y,
        z: 0.5,
        inv_w: 1.0,
        depth_x: x,
        depth_y: y,
    });
    let opts = RasterOptions {
        subpixel_bits: bits,
        ..RasterOptions::default()
    };
    match setup_triangle(wv, [&var; 3], 0, W, H, &opts) {
        TriangleSetup::Triangle(t) => Some(t),
        TriangleSetup::Empty => None,
        TriangleSetup::Culled => unreachable!("culling is off"),
    }
}

/// A tile of the target: first column, first row, width, rows.
type Tile = (u32, u32, u32, u32);

/// The pixels of `tile` that [`SetupTriangle::covers`] says are covered.
fn covered(t: &SetupTriangle, (x0, y0, width, rows): Tile) -> BTreeSet<(u32, u32)> {
    let mut set = BTreeSet::new();
    for py in y0..y0 + rows {
        for px in x0..x0 + width {
            if t.covers(px, py) {
                set.insert((px, py));
            }
        }
    }
    set
}

/// The pixels [`SetupTriangle::spans`] visits in `tile`, checking that each row comes once,
/// top row first, with a non-empty span.
fn spans(t: &SetupTriangle, (x0, y0, width, rows): Tile) -> Result<BTreeSet<(u32, u32)>, String> {
    let mut set = BTreeSet::new();
    let mut last_row = None;
    let mut err = None;
    t.spans(x0, y0, width, rows, |py, x_lo, x_hi| {
        if x_lo > x_hi || last_row.is_some_and(|r| r >= py) {
            err.get_or_insert(format!(
                "row {py}: span {x_lo}..={x_hi} after row {last_row:?}"
            ));
        }
        last_row = Some(py);
        set.extend((x_lo..=x_hi).map(|px| (px, py)));
    });
    err.map_or(Ok(set), Err)
}

/// The pixels a vector of `lanes` lanes finds covered in [`SetupTriangle::small_box`]'s box,
/// computed as the AVX2 loop does: `i32` lanes (wrapping, so an overflow the box promised
/// away would show), lanes past the box's columns masked off. `None` when the triangle does not
/// take the small-box path.
fn small_box(
    t: &SetupTriangle,
    (x0, y0, width, rows): Tile,
    lanes: u32,
) -> Option<BTreeSet<(u32, u32)>> {
    let b = t.small_box(x0, y0, width, rows, lanes)?;
    assert!(
        b.columns >= 1 && b.columns <= lanes,
        "box of {} columns",
        b.columns
    );
    let mut set = BTreeSet::new();
    for y in b.y0..=b.y1 {
        let row = (y - b.y0) as i32;
        for j in 0..lanes {
            let inside = (0..3).all(|i| {
                let e = b.e[i]
                    .wrapping_add(b.dx[i].wrapping_mul(j as i32))
                    .wrapping_add(b.dy[i].wrapping_mul(row));
                e >= 0
            });
            if inside && j < b.columns {
                set.insert((b.x + j, y));
            }
        }
    }
    Some(set)
}

/// Panics with a map of the tile (`#` both, `?` only `covers`, `!` only the walk) when the
/// sets differ.
fn same(
    name: &str,
    v: Tri,
    bits: u32,
    tile: Tile,
    want: &BTreeSet<(u32, u32)>,
    got: &BTreeSet<(u32, u32)>,
) -> Result<(), TestCaseError> {
    if want == got {
        return Ok(());
    }
    let (x0, y0, width, rows) = tile;
    let at = |set: &BTreeSet<(u32, u32)>| {
        (0..rows * width)
            .map(|i| set.contains(&(x0 + i % width, y0 + i / width)))
            .collect::<Vec<_>>()
    };
    Err(TestCaseError::fail(format!(
        "{name} differs from covers() for {v:?} at {bits} subpixel bits, tile {tile:?}:\n{}",
        ascii_map(&at(want), &at(got), width as usize, 80)
    )))
}

/// A window coordinate in `lo .. hi`: on the grid of 1, 1/2, 1/4 or 1/256 pixel (edges then
/// run through pixel centers, where the tie-break decides) or anywhere.
fn coord(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        (0u32..5, lo..hi).prop_map(|(k, c)| {
            let d = [1.0, 2.0, 4.0, 256.0, 256.0][k as usize];
            (c * d).round() / d + if k == 0 { 0.5 } else { 0.0 }
        }),
        lo..hi,
    ]
}

/// A point anywhere around the target (up to 20 pixels outside it).
fn point() -> impl Strategy<Value = (f32, f32)> {
    (coord(-20.0, W as f32 + 20.0), coord(-20.0, H as f32 + 20.0))
}

/// Triangles of every kind: any three points (large, partly outside, either orientation);
/// tiny ones, at most a few pixels across (the small-box path); slivers, the third vertex
/// near the line through the other two.
fn triangle() -> impl Strategy<Value = Tri> {
    let any = [point(), point(), point()];
    let tiny = (
        point(),
        [
            coord(-4.0, 4.0),
            coord(-4.0, 4.0),
            coord(-4.0, 4.0),
            coord(-4.0, 4.0),
        ],
    )
        .prop_map(|((x, y), d)| [(x, y), (x + d[0], y + d[1]), (x + d[2], y + d[3])]);
    let sliver = (point(), point(), 0.0f32..1.0, -0.3f32..0.3).prop_map(|(a, b, s, off)| {
        let c = (a.0 + s * (b.0 - a.0) + off, a.1 + s * (b.1 - a.1) - off);
        [a, b, c]
    });
    prop_oneof![any, tiny, sliver]
}

/// A tile (scissor) inside the target: the whole target half of the time.
fn tile() -> impl Strategy<Value = Tile> {
    prop_oneof![
        Just((0, 0, W, H)),
        (0..W, 0..H, 1..=W, 1..=H).prop_map(|(x0, y0, w, h)| (
            x0,
            y0,
            w.min(W - x0),
            h.min(H - y0)
        )),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// `spans` visits, and `small_box` (wherever the triangle qualifies, for vectors of 4, 8
    /// and 16 lanes) marks, exactly the tile's pixels that `covers` says are covered; reversing
    /// the vertex order (the other orientation) covers the same pixels; every covered pixel
    /// lies in `rows()` (what binning relies on).
    #[test]
    fn walks_visit_exactly_the_covered_pixels(
        v in triangle(),
        bits in prop_oneof![Just(8u32), Just(8), Just(4), Just(1), Just(12), Just(16)],
        tile in tile(),
    ) {
        let Some(t) = setup(v, bits) else { return Ok(()) };
        let want = covered(&t, tile);
        let got = spans(&t, tile).map_err(TestCaseError::fail)?;
        same("spans()", v, bits, tile, &want, &got)?;
        for lanes in [4, 8, 16] {
            if let Some(got) = small_box(&t, tile, lanes) {
                same(&format!("small_box(lanes = {lanes})"), v, bits, tile, &want, &got)?;
            }
        }
        let reversed = setup([v[0], v[2], v[1]], bits).expect("the same triangle");
        prop_assert_eq!(&covered(&reversed, tile), &want, "reversed vertex order");
        let (r0, r1) = t.rows();
        prop_assert!(want.iter().all(|&(_, py)| (r0..=r1).contains(&py)), "covered outside rows() {:?}", (r0, r1));
    }
}

/// Small triangles take the small-box path (the generator above makes enough of them for it
/// to be tested): a 3-pixel triangle fits in 8 lanes.
#[test]
fn tiny_triangles_take_the_small_box_path() {
    let t = setup([(10.2, 10.1), (13.1, 10.7), (11.0, 12.9)], 8).expect("covers pixels");
    assert!(t.small_box(0, 0, W, H, 8).is_some());
    assert!(t.small_box(0, 0, W, H, 2).is_none());
}

/// The tie-break: a square with corners on pixel centers, cut into triangles whose shared
/// edges (diagonal, vertical, horizontal, through a shared vertex) run through pixel centers,
/// covers each of its pixels exactly once. Without the +1 bias of left and top edges the
/// pixels on shared edges would be covered by neither triangle; with it on every edge, by
/// both. The square's own left and top edges are in, its right and bottom edges out (a
/// top-left rule, window y down).
#[test]
fn shared_edges_cover_each_pixel_exactly_once() {
    // Corners on pixel centers: pixel p's center is at p + 0.5.
    let (lo, mid, hi) = (2.5, 6.5, 10.5);
    let fan_center = (mid, mid);
    let ring = [
        (lo, lo),
        (mid, lo),
        (hi, lo),
        (hi, mid),
        (hi, hi),
        (mid, hi),
        (lo, hi),
        (lo, mid),
    ];
    let cuts: [(&str, Vec<Tri>); 4] = [
        (
            "diagonal",
            vec![
                [(lo, lo), (hi, lo), (hi, hi)],
                [(lo, lo), (hi, hi), (lo, hi)],
            ],
        ),
        (
            "other diagonal, reversed winding",
            vec![
                [(hi, lo), (lo, lo), (lo, hi)],
                [(hi, lo), (hi, hi), (lo, hi)],
            ],
        ),
        (
            "vertical and horizontal cuts",
            vec![
                [(lo, lo), (mid, lo), (mid, hi)],
                [(lo, lo), (mid, hi), (lo, hi)],
                [(mid, lo), (hi, lo), (hi, mid)],
                [(mid, lo), (hi, mid), (mid, mid)],
                [(mid, mid), (hi, mid), (hi, hi)],
                [(mid, mid), (hi, hi), (mid, hi)],
            ],
        ),
        (
            "fan of 8 around a pixel center",
            (0..8)
                .map(|k| [fan_center, ring[k], ring[(k + 1) % 8]])
                .collect(),
        ),
    ];
    for (name, tris) in cuts {
        let setups: Vec<SetupTriangle> = tris
            .iter()
            .map(|&v| setup(v, 8).expect("covers pixels"))
            .collect();
        for py in 0..H {
            for px in 0..W {
                let count = setups.iter().filter(|t| t.covers(px, py)).count();
                let inside = (2..10).contains(&px) && (2..10).contains(&py);
                assert_eq!(
                    count, inside as usize,
                    "{name}: pixel ({px}, {py}) covered {count} times"
                );
            }
        }
    }
}
