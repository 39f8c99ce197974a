//! The reference rasterizer: fixed-point coverage and the top-left rule on a pixel grid, each
//! pixel decided by [`SetupTriangle::covers`], the rasterizer's own coverage test.

use super::Context;
use super::canvas::{Canvas, GRAY, INK, LABEL, LEFT, RIGHT, SMALL};
use stereolab_core::{
    Error, MAX_VARYINGS, RasterOptions, Result, SetupTriangle, TextAlign, TriangleSetup, Varyings,
    WindowVertex, setup_triangle,
};

/// The grid the figure draws: `W`×`H` pixels.
pub const GRID: (u32, u32) = (10, 8);

/// The two triangles of the figure in window coordinates (pixel centers at +0.5): they share
/// the diagonal from (1.5, 0.5) to (8.5, 7.5), which runs through pixel centers, and A's left
/// edge, B's top edge, B's right edge and A's bottom edge all run through pixel centers too.
pub const TRIANGLES: [[(f32, f32); 3]; 2] = [
    [(1.5, 0.5), (8.5, 7.5), (1.5, 7.5)],
    [(1.5, 0.5), (8.5, 0.5), (8.5, 7.5)],
];

/// The rasterizer's setup of one of [`TRIANGLES`].
///
/// # Errors
/// The triangle sets up empty (a bug).
pub fn setup(tri: [(f32, f32); 3]) -> Result<SetupTriangle> {
    let v = tri.map(|(x, y)| WindowVertex {
        x,
        y,
        z: 0.5,
        inv_w: 1.0,
        depth_x: x,
        depth_y: y,
    });
    let var: Varyings = [0.0; MAX_VARYINGS];
    match setup_triangle(
        v,
        [&var, &var, &var],
        0,
        GRID.0,
        GRID.1,
        &RasterOptions::default(),
    ) {
        TriangleSetup::Triangle(t) => Ok(t),
        _ => Err(Error::internal(
            "figures",
            "the figure's triangle set up empty",
        )),
    }
}

/// Two triangles sharing an edge on a 10×8 pixel grid: every pixel center on the shared edge
/// goes to exactly one of them (the top-left rule), none to both, none lost.
///
/// # Errors
/// As [`setup`].
pub fn top_left(_: &Context) -> Result<Canvas> {
    let tris = [setup(TRIANGLES[0])?, setup(TRIANGLES[1])?];
    let cell = 44.0;
    let (ox, oy) = (30.0, 40.0);
    let mut c = Canvas::new(720, 430)?;
    let px = |x: f32, y: f32| (ox + x * cell, oy + y * cell);
    let mut counts = [0usize; 3];
    for py in 0..GRID.1 {
        for pxl in 0..GRID.0 {
            let (a, b) = (tris[0].covers(pxl, py), tris[1].covers(pxl, py));
            let fill = match (a, b) {
                (true, false) => Some(((250, 200, 200), LEFT)),
                (false, true) => Some(((200, 225, 250), RIGHT)),
                (true, true) => Some(((255, 230, 0), INK)),
                (false, false) => None,
            };
            let (x0, y0) = px(pxl as f32, py as f32);
            if let Some((bg, _)) = fill {
                c.fill_rect((x0, y0), (x0 + cell, y0 + cell), bg, 255);
            }
            c.rect((x0, y0), (x0 + cell, y0 + cell), (200, 200, 200), 1.0);
            let center = px(pxl as f32 + 0.5, py as f32 + 0.5);
            match fill {
                Some((_, ink)) => c.dot(center, 4.0, ink),
                None => c.circle(center, 3.0, GRAY, 1.0),
            }
            if a && b {
                counts[2] += 1;
            } else if a {
                counts[0] += 1;
            } else if b {
                counts[1] += 1;
            }
        }
    }
    for (tri, rgb) in TRIANGLES.iter().zip([LEFT, RIGHT]) {
        let pts: Vec<(f32, f32)> = tri
            .iter()
            .chain(tri.iter().take(1))
            .map(|&(x, y)| px(x, y))
            .collect();
        c.polyline(&pts, rgb, 2.0);
    }
    c.text(
        px(1.7, 5.65).0,
        px(1.7, 5.65).1,
        LABEL,
        "A",
        LEFT,
        TextAlign::Left,
    );
    c.text(
        px(6.7, 2.65).0,
        px(6.7, 2.65).1,
        LABEL,
        "B",
        RIGHT,
        TextAlign::Left,
    );
    c.text(
        ox,
        10.0,
        LABEL,
        "pixel centers at +0.5; window y down",
        INK,
        TextAlign::Left,
    );
    let x = ox + GRID.0 as f32 * cell + 20.0;
    // Who gets the pixel centers on each edge, read back from the coverage test.
    let who = |pixels: &[(u32, u32)]| -> String {
        let a = pixels
            .iter()
            .filter(|&&(x, y)| tris[0].covers(x, y))
            .count();
        let b = pixels
            .iter()
            .filter(|&&(x, y)| tris[1].covers(x, y))
            .count();
        format!("{} centers: A {a}, B {b}", pixels.len())
    };
    let diagonal: Vec<(u32, u32)> = (1..7).map(|k| (k + 1, k)).collect();
    let a_left: Vec<(u32, u32)> = (1..7).map(|y| (1, y)).collect();
    let b_top: Vec<(u32, u32)> = (2..8).map(|x| (x, 0)).collect();
    let b_right: Vec<(u32, u32)> = (1..7).map(|y| (8, y)).collect();
    let a_bottom: Vec<(u32, u32)> = (2..8).map(|x| (x, 7)).collect();
    let lines = [
        (format!("A covers {} pixels", counts[0]), LEFT),
        (format!("B covers {} pixels", counts[1]), RIGHT),
        (format!("covered by both: {}", counts[2]), INK),
        ("shared diagonal (B's left edge):".to_string(), INK),
        (format!("  {}", who(&diagonal)), INK),
        ("A's left edge x = 1.5:".to_string(), INK),
        (format!("  {}", who(&a_left)), INK),
        ("B's top edge y = 0.5:".to_string(), INK),
        (format!("  {}", who(&b_top)), INK),
        ("B's right edge x = 8.5:".to_string(), INK),
        (format!("  {}", who(&b_right)), INK),
        ("A's bottom edge y = 7.5:".to_string(), INK),
        (format!("  {}", who(&a_bottom)), INK),
        ("8 subpixel bits (1/256 px),".to_string(), GRAY),
        ("64-bit integer edge tests".to_string(), GRAY),
    ];
    for (i, (s, rgb)) in lines.iter().enumerate() {
        c.text(x, 44.0 + 21.0 * i as f32, SMALL, s, *rgb, TextAlign::Left);
    }
    Ok(c)
}
