//! Hard cases stay numerically stable: extreme magnitudes, w near zero, far/near ratios.

use glam::Vec4;
use proptest::prelude::*;
use stereolab::plan::{Output, Plan, View};
use stereolab::render::render;
use stereolab::scene::Scene;
use stereolab_core::{Fragment, Framebuffer, RasterOptions, Shader, Varyings, rasterize};

struct Clip(Vec<Vec4>);

impl Shader for Clip {
    fn varying_count(&self) -> usize {
        1
    }
    fn vertex(&self, i: u32, v: &mut Varyings) -> Vec4 {
        v[0] = i as f32;
        self.0[i as usize]
    }
    fn fragment(&self, f: &Fragment) -> Option<[u8; 4]> {
        assert!(
            f.varyings[0].is_finite(),
            "varying not finite at ({}, {})",
            f.x,
            f.y
        );
        Some([255; 4])
    }
}

/// A float spanning many orders of magnitude, either sign.
fn wide() -> impl Strategy<Value = f32> {
    (any::<bool>(), -30i32..30, 1.0f32..10.0).prop_map(|(neg, e, m)| {
        if neg {
            -m * 10f32.powi(e)
        } else {
            m * 10f32.powi(e)
        }
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn extreme_clip_coordinates_never_panic_and_keep_depth_in_range(
        c in proptest::collection::vec((wide(), wide(), wide(), wide()), 3)
    ) {
        let clip: Vec<Vec4> = c.iter().map(|(x, y, z, w)| Vec4::new(*x, *y, *z, *w)).collect();
        let mut fb = Framebuffer::new(32, 24, [0, 0, 0, 255]).unwrap();
        rasterize(&[[0, 1, 2]], 3, &Clip(clip), &mut fb, &RasterOptions::default());
        prop_assert!(fb.depth().iter().all(|d| (0.0..=1.0).contains(d)));
    }
}

#[test]
fn far_near_ratios_up_to_1e6_keep_a_plane_in_front_of_a_plane_behind() {
    // Two parallel quads 1% apart in depth, at the middle of the range: the nearer must win
    // everywhere for far/near from 10 to 1e6 (f32 depth after an OpenGL projection).
    for ratio in [1e1f32, 1e2, 1e3, 1e4, 1e5, 1e6] {
        let near = 0.1f32;
        let far = near * ratio;
        let z = (near * far).sqrt(); // geometric middle: where depth precision is spent
        let text = format!(
            "outputs = [\"left\"]\n[image]\nwidth = 48\nheight = 32\n[camera]\neye = [0, 0, 0]\ntarget = [0, 0, -1]\nnear = {near}\nfar = {far}\n[stereo]\neye_separation = 0\nzero_parallax = {z}\n\
             [[mesh]]\nkind = \"plane\"\nsize = {s}\ntranslate = [0, 0, {zf}]\ncolor = [1, 0, 0]\n\
             [[mesh]]\nkind = \"plane\"\nsize = {s}\ntranslate = [0, 0, {zn}]\ncolor = [0, 0, 1]\n",
            s = z * 4.0,
            zf = -z * 1.01,
            zn = -z,
        );
        let scene = Scene::from_toml(
            &text,
            std::path::Path::new("inline.toml"),
            std::path::Path::new("."),
            &[],
        )
        .unwrap();
        let frame = render(&scene, &Plan::new(&[Output::Left])).unwrap();
        let fb = frame.view(View::Left).unwrap();
        let red = fb.color().iter().filter(|c| c[0] > c[2]).count();
        assert_eq!(
            red, 0,
            "far/near = {ratio}: the farther plane shows through on {red} pixels"
        );
        assert!(
            fb.depth().iter().all(|d| *d < 1.0 && d.is_finite()),
            "far/near = {ratio}: plane must cover the view"
        );
    }
}
