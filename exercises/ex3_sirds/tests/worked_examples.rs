//! Checks you can run yourself (`cargo test -p ex3_sirds`).

use exercise_api::{SirdsGeometry, SirdsSetup};

#[test]
fn flat_row_links_every_pixel_to_the_one_s_to_its_right() {
    // a = 60, f = 240, z = 60 → d = 60·60/300 = 12 pixels.
    let g = SirdsGeometry {
        eye_distance: 60.0,
        focal_length: 240.0,
    };
    assert!((ex3_sirds::disparity_constant_eyes(60.0, &g) - 12.0).abs() < 1e-5);
    // Nearness 0.5 between 40 and 80 px behind the image: t = 60 px, s = 12.
    let setup = SirdsSetup {
        eye_distance: 60.0,
        focal_length: 240.0,
        depth_near: 40.0,
        depth_far: 80.0,
    };
    let same = ex3_sirds::link_row(&[0.5; 40], 0, &setup);
    for (x, partner) in same.iter().enumerate().take(28) {
        assert_eq!(*partner, x + 12, "pixel {x}");
    }
}

#[test]
fn constant_direction_at_45_degrees_is_twice_the_depth() {
    let d = ex3_sirds::disparity_constant_direction(10.0, std::f32::consts::FRAC_PI_4);
    assert!((d - 20.0).abs() < 1e-4, "{d}");
}
