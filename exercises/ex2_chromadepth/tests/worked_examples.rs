//! Checks you can run yourself (`cargo test -p ex2_chromadepth`): the ChromaDepth article's own example.

#[test]
fn chromadepth_article_texgen_for_d1_5_d2_15() {
    // The ChromaDepth article's sample code: D1 = 5, D2 = 15 → { 0, 0, -1/10, -5/10 }.
    let p = ex2_chromadepth::texgen(5.0, 15.0);
    let want = [0.0, 0.0, -0.1, -0.5];
    assert!(
        p.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6),
        "{p:?}"
    );
}

#[test]
fn ramp_runs_red_green_blue() {
    assert_eq!(ex2_chromadepth::hsv_ramp(0.0), [1.0, 0.0, 0.0]);
    assert_eq!(ex2_chromadepth::hsv_ramp(0.5), [0.0, 1.0, 0.0]);
    assert_eq!(ex2_chromadepth::hsv_ramp(1.0), [0.0, 0.0, 1.0]);
}
