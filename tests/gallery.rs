//! The ChromaDepth article's gallery from real data: the USGS fault-valley elevation model and
//! the Pacific North-West topobathy grid (`kind = "dem"`), the 1HPV protein (`kind = "pdb"`),
//! a CAD part; and the loader's errors for bad files.

use std::path::Path;

use stereolab::output::{Image, produce};
use stereolab::plan::{Output, Plan};
use stereolab::render::render;
use stereolab::scene::{Scene, dem, pdb};

use crate::common::{asset, out_dir};

fn load(name: &str) -> Scene {
    Scene::load(&asset(&format!("scenes/{name}.toml")), &[]).unwrap()
}

fn world_bounds(s: &Scene) -> (glam::Vec3, glam::Vec3) {
    s.world_points().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(p), hi.max(p)),
    )
}

#[test]
fn the_shipped_dems_hold_the_source_grids() {
    // 16-bit gray, one step per metre above the lowest point: the Jacksboro grid spans
    // 236..1076 m (840 steps), the topobathy grid −1437..2205 m (3642 steps).
    for (file, (w, h), relief) in [
        ("jacksboro_fault_dem.png", (403, 344), 840.0),
        ("topobathy.png", (120, 91), 3642.0),
    ] {
        let g = dem::load_grid(&asset(&format!("scenes/terrain/{file}"))).unwrap();
        assert_eq!((g.width, g.height), (w, h), "{file}");
        let lo = g.samples.iter().copied().fold(f32::MAX, f32::min);
        let hi = g.samples.iter().copied().fold(f32::MIN, f32::max);
        assert_eq!(lo, 0.0, "{file}");
        assert!(
            (hi * 65535.0 - relief).abs() < 0.01,
            "{file}: {}",
            hi * 65535.0
        );
    }
}

#[test]
fn a_dem_scene_is_scattered_points_over_the_extent_at_the_mapped_heights() {
    let s = load("chromadepth_jacksboro");
    let mesh = &s.objects[0].mesh;
    // 20 000 scattered points and 4·⌈√20000⌉ = 4·142 border points, all distinct.
    assert_eq!(mesh.positions.len(), 20_000 + 4 * 142);
    // Delaunay: a triangulation of n points with h on the hull has 2n − 2 − h triangles.
    let hull = 4 * 142;
    assert_eq!(mesh.triangles.len(), 2 * mesh.positions.len() - 2 - hull);
    let (lo, hi) = world_bounds(&s);
    // The extent, centred: 30.02 km east (x), 31.91 km north (−z).
    assert!(
        (lo.x + 15.01).abs() < 1e-4 && (hi.x - 15.01).abs() < 1e-4,
        "{lo} {hi}"
    );
    assert!(
        (lo.z + 15.955).abs() < 1e-4 && (hi.z - 15.955).abs() < 1e-4,
        "{lo} {hi}"
    );
    // Heights: (236 .. 1076 m) × 4 / 1000 km; the scatter reaches close to both ends.
    assert!(lo.y >= 0.944 - 1e-4 && hi.y <= 4.304 + 1e-4, "{lo} {hi}");
    assert!(lo.y < 0.944 + 0.1 && hi.y > 4.304 - 0.3, "{lo} {hi}");
}

/// Mean red and blue of the covered pixels of rows `rows`.
fn mean_red_blue(img: &image::RgbaImage, rows: std::ops::Range<u32>) -> (f64, f64) {
    let (mut r, mut b, mut n) = (0.0, 0.0, 0.0);
    for y in rows {
        for x in 0..img.width() {
            let p = img.get_pixel(x, y).0;
            if p[0] as u32 + p[1] as u32 + p[2] as u32 > 0 {
                r += f64::from(p[0]);
                b += f64::from(p[2]);
                n += 1.0;
            }
        }
    }
    assert!(n > 0.0, "no covered pixels in rows");
    (r / n, b / n)
}

#[test]
fn chromadepth_of_the_real_terrains_is_red_near_and_blue_far() {
    // Fault valley, seen from the south: the near (bottom) rows red, the far (top) rows not.
    // The topobathy map from above: the mountain peaks (north-east) redder than the open
    // ocean (south-west corner), which is blue.
    for (name, near, far) in [
        ("chromadepth_jacksboro", 90..100, 30..40),
        ("chromadepth_jacksboro_view2", 90..100, 30..40),
    ] {
        let mut s = load(name);
        s.set_size(160, 120).unwrap();
        let frame = render(&s, &Plan::new(&[Output::ChromaDepth])).unwrap();
        let Image::Rgba(img) = produce(Output::ChromaDepth, &frame, &s).unwrap() else {
            panic!("chromadepth is RGBA")
        };
        let (nr, nb) = mean_red_blue(&img, near);
        let (fr, fb) = mean_red_blue(&img, far);
        assert!(
            nr > 150.0 && nb < 40.0,
            "{name}: near rows red {nr} blue {nb}"
        );
        assert!(
            fr < nr - 80.0 && fb > nb,
            "{name}: far rows red {fr} blue {fb}"
        );
    }
    let mut s = load("chromadepth_topobathy");
    s.set_size(160, 120).unwrap();
    let frame = render(&s, &Plan::new(&[Output::ChromaDepth])).unwrap();
    let Image::Rgba(img) = produce(Output::ChromaDepth, &frame, &s).unwrap() else {
        panic!("chromadepth is RGBA")
    };
    // The deep Pacific in the south-west corner of the map is the farthest: blue.
    let sw = img.get_pixel(27, 96).0;
    assert!(sw[2] > 150 && sw[0] < 60, "south-west ocean {sw:?}");
    // The reddest pixel is a mountain in the north-east quarter (the Coast Mountains).
    let (mut best, mut at) = (0u8, (0, 0));
    for y in 0..120 {
        for x in 0..160 {
            let p = img.get_pixel(x, y).0;
            if p[0] > best && p[2] < 30 {
                (best, at) = (p[0], (x, y));
            }
        }
    }
    assert!(
        at.0 > 80 && at.1 < 60 && best > 200,
        "reddest {best} at {at:?}"
    );
}

#[test]
fn the_protein_is_every_non_water_atom_of_1hpv_as_a_cpk_sphere() {
    let atoms = pdb::load_pdb(&asset("scenes/molecules/1hpv.pdb")).unwrap();
    // 1516 ATOM records (the two chains of HIV-1 protease) and 35 HETATM (the VX-478
    // inhibitor); the file's 80 waters are not in the shipped copy, and would be left out.
    assert_eq!(atoms.len(), 1516 + 35);
    let count = |e: &str| atoms.iter().filter(|a| a.element == e).count();
    assert!(
        count("C") > 900 && count("N") > 200 && count("O") > 200,
        "C N O"
    );
    assert!(
        count("S") >= 2,
        "methionine/cysteine and the sulfonamide have sulfur"
    );
    assert_eq!(
        count("H"),
        0,
        "an X-ray structure at 1.9 Å has no hydrogens"
    );
    let s = load("chromadepth_protein");
    let mesh = &s.objects[0].mesh;
    assert_eq!(
        mesh.triangles.len() as u64,
        pdb::planned_triangles(atoms.len(), 10)
    );
    // Centred on the centroid: the molecule's bounds straddle the origin, ~50 Å across.
    let (lo, hi) = mesh.bounds();
    let size = hi - lo;
    assert!(
        lo.max_element() < 0.0 && hi.min_element() > 0.0,
        "{lo} {hi}"
    );
    assert!(
        size.max_element() > 40.0 && size.max_element() < 80.0,
        "{size}"
    );
}

#[test]
fn the_cad_part_is_a_closed_flanged_hub() {
    let s = load("chromadepth_cad");
    let mesh = &s.objects[0].mesh;
    let (lo, hi) = mesh.bounds();
    // Flange radius 4, from the flange's underside (−1.5) to the hub's top (1.5).
    assert!((hi.x - 4.0).abs() < 1e-3 && (lo.y + 1.5).abs() < 1e-4 && (hi.y - 1.5).abs() < 1e-4);
    // The lathe profile revolved: 7 edges × 48 segments × 2, and 6 bolts of 12 + 4 triangles.
    assert_eq!(mesh.triangles.len(), 7 * 48 * 2 + 6 * 16);
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const DEM_MESH: &str = "[[mesh]]\nkind = \"dem\"\npath = \"g.png\"\n";

fn scene_error(dir: &Path, mesh: &str) -> String {
    let text = format!(
        "outputs = [\"chromadepth\"]\n[image]\nwidth = 64\nheight = 48\n\
         [camera]\neye = [0.0, 5.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nnear = 1.0\nfar = 50.0\n{mesh}"
    );
    let p = write(dir, "s.toml", &text);
    Scene::load(&p, &[]).unwrap_err().to_string()
}

#[test]
fn bad_gallery_files_get_errors_that_name_the_field_or_line() {
    let dir = out_dir("gallery_errors");
    // A color image is not an elevation model.
    image::RgbImage::from_pixel(4, 4, image::Rgb([10, 200, 30]))
        .save(dir.join("g.png"))
        .unwrap();
    let e = scene_error(
        &dir,
        &format!("{DEM_MESH}extent = [1.0, 1.0]\nheights = [0.0, 1.0]\n"),
    );
    assert!(e.contains("grayscale"), "{e}");
    image::GrayImage::from_pixel(4, 4, image::Luma([7]))
        .save(dir.join("g.png"))
        .unwrap();
    let e = scene_error(&dir, &format!("{DEM_MESH}heights = [0.0, 1.0]\n"));
    assert!(e.contains("mesh[0].extent") && e.contains("missing"), "{e}");
    let e = scene_error(&dir, &format!("{DEM_MESH}extent = [1.0, 1.0]\n"));
    assert!(e.contains("mesh[0].heights"), "{e}");
    let e = scene_error(
        &dir,
        &format!("{DEM_MESH}extent = [0.0, 1.0]\nheights = [0.0, 1.0]\n"),
    );
    assert!(e.contains("mesh[0].extent") && e.contains("> 0"), "{e}");
    let e = scene_error(
        &dir,
        &format!("{DEM_MESH}extent = [1.0, 1.0]\nheights = [0.0, 1.0]\ncount = 3000000\n"),
    );
    assert!(e.contains("mesh[0].count"), "{e}");
    // A budget the points would exceed is refused before the triangulation.
    let p = write(
        &dir,
        "b.toml",
        &format!(
            "outputs = [\"chromadepth\"]\n[image]\nwidth = 64\nheight = 48\n\
             [camera]\neye = [0.0, 5.0, 5.0]\n\
             target = [0.0, 0.0, 0.0]\nnear = 1.0\nfar = 50.0\n{DEM_MESH}extent = [1.0, 1.0]\nheights = [0.0, 1.0]\n\
             count = 5000\n"
        ),
    );
    let opts = stereolab::scene::LoadOptions {
        max_triangles: 1000,
        ..Default::default()
    };
    let e = Scene::load_with(&p, &[], &opts).unwrap_err().to_string();
    assert!(e.contains("--max-triangles"), "{e}");
    // PDB: a bad coordinate names the line; a file without atoms says so.
    write(
        &dir,
        "m.pdb",
        "HEADER\nATOM      1  N   PRO A   1      -3.022   4.020  30.100\n\
         ATOM      2  CA  PRO A   1      -3.889   nan    30.881\n",
    );
    let e = scene_error(&dir, "[[mesh]]\nkind = \"pdb\"\npath = \"m.pdb\"\n");
    assert!(
        e.contains("m.pdb") && e.contains(":3") && e.contains("coordinate y"),
        "{e}"
    );
    write(&dir, "m.pdb", "HEADER nothing here\n");
    let e = scene_error(&dir, "[[mesh]]\nkind = \"pdb\"\npath = \"m.pdb\"\n");
    assert!(e.contains("no ATOM or HETATM"), "{e}");
    // A tessellation the budget cannot hold is refused before a sphere is built.
    write(
        &dir,
        "m.pdb",
        "ATOM      1  N   PRO A   1      -3.022   4.020  30.100\n",
    );
    let e = scene_error(
        &dir,
        "[[mesh]]\nkind = \"pdb\"\npath = \"m.pdb\"\ndetail = 4096\n",
    );
    assert!(e.contains("mesh[0].detail") && e.contains("budget"), "{e}");
}
