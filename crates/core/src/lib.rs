//! stereolab's teaching core: the stereo rig's matrices, the fixed-point rasterizer that covers
//! the pixels lavapipe covers, the f64 reference the hard cases are measured against, and the
//! effects (anaglyphs, remapping and the visibility check, parallax, layouts, ChromaDepth,
//! SIRDS), each a function of framebuffers, matrices and its own settings.
//!
//! A pass is [`rasterize`] with a [`Shader`] into a [`Framebuffer`], with the
//! matrices of [`StereoRig::eyes`]; an effect reads the framebuffers, e.g.
//! [`anaglyph`]. Scene files, the plan and the outputs are the `stereolab`
//! crate's; `examples/` in the repository has small complete programs.
//!
//! Its modules import lower ones only, in the order `tests/architecture.rs` holds.
//!
#![doc = include_str!("../../../docs/formulas.md")]
#![warn(missing_docs)]

mod effects;
mod error;
mod eye;
mod files;
mod framebuffer;
mod math;
mod raster;
mod reference;
mod shade;
mod simd;
mod text;

// The names, in the order a course meets them. Each module is private: these are the crate.

// Errors, eyes, framebuffers.
pub use error::{Error, Result};
pub use eye::Eye;
pub use framebuffer::{
    BACK_LEFT, BACK_RIGHT, DrawBuffer, EyePair, Framebuffer, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE,
    MAX_OUTPUT_PIXELS, MAX_OUTPUT_SIDE, check_output_size, check_size, open_image,
    open_output_image,
};

// The camera and the stereo rig: each formula a short function (`math::stereo`), the rig that
// checks its inputs and calls them.
pub use math::stereo::{
    auto_eye_separation, camera_frustum_asymmetry, camera_translation, cyclopic_projection,
    eye_translation, frustum_asymmetry, image_shift_translation, off_axis_frustum,
    toe_in_camera_view, toe_in_view, view_offset, view_width_at, zero_parallax_at_fraction,
};
pub use math::{
    Camera, CameraMode, EyeMatrices, ImageShift, Lighting, MAX_VIEWS, ResolvedRig, Separation,
    StereoRig, Viewer, ZeroParallax, fit_zero_parallax, frustum, look_at, perspective, project_ndc,
};

// Shading and the fixed-point rasterizer (knows nothing of stereo).
pub use raster::{
    Band as RasterBand, ClipRange, DepthMode, DepthPlane, Plane, RasterOptions, RasterStats,
    Setup as TriangleSetup, SetupTriangle, Setups, SmallBox, WindowVertex, rasterize,
    rasterize_blinn_phong, setup_triangle, setup_triangles, traverse,
};
pub use shade::{BlinnPhong, DepthOnly, Fragment, Light, MAX_VARYINGS, Shader, Varyings, to_rgba8};

// The f64 reference the hard cases are measured against.
pub use reference::{
    IdShader, Mismatch, Visible, compare as compare_with_reference, drawn_id,
    eye as eye_matrices_f64, frustum as frustum_f64, look_at as look_at_f64, soup as triangle_soup,
    visible as visible_f64, zero_parallax as zero_parallax_f64,
};

// Anaglyphs and layouts.
pub use effects::anaglyph::{
    ANTI_RIVALRY_GAMMA, AnaglyphGlasses, AnaglyphKind, AnaglyphMatrices, AnaglyphMethod,
    AnaglyphOptions, ColorMatrix, anaglyph, anaglyph_pixel, anaglyph_pixel_with,
    anaglyph_reference, anti_rivalry, linear_to_srgb, mix as anaglyph_mix, srgb_to_linear,
    threejs_anaglyph,
};
pub use effects::calibration::{
    ARROW_COLOR as CALIBRATION_ARROW_COLOR, BLANK_COLOR as CALIBRATION_BLANK_COLOR,
    CalibrationLayout, VIEW_COLOR as CALIBRATION_VIEW_COLOR, calibration_screen,
};
pub use effects::eye_input::check_same_size;
pub use effects::frame_sequential::{
    DEFAULT_WIGGLE_FRAME_MS, Field as FrameField, FrameSequentialSettings, MAX_CYCLES,
    MAX_EYE_RATE_HZ, MAX_WIGGLE_FRAME_MS, MIN_WIGGLE_FRAME_MS, WiggleSettings, WiggleStart,
};
pub use effects::ghosting::{
    BRIGHT as GHOST_BRIGHT, DARK as GHOST_DARK, DEFAULT_LEAK as DEFAULT_GHOSTING_LEAK, GhostRisk,
    GhostingSettings, cancel_pixel, cancel_value, cancelled, contrast_warning, ghost_pixel,
    ghost_risk, ghosted,
};
pub use effects::layout::{
    above_below, above_below_squashed, frame_packing, frame_packing_active_space, half_above_below,
    half_side_by_side, interleave, lenticular_interleave, lenticular_view, side_by_side, view_grid,
    view_tiles,
};

// Remapping, the visibility check, random-dot pairs.
pub use effects::occlusion::{
    BACKGROUND_COLOR as OCCLUSION_BACKGROUND_COLOR, FARTHER_COLOR as OCCLUSION_FARTHER_COLOR,
    OCCLUDED_COLOR as OCCLUSION_OCCLUDED_COLOR, OUT_OF_VIEW_COLOR as OCCLUSION_OUT_OF_VIEW_COLOR,
    occlusion_image,
};
pub use effects::rds::{
    MAX_DOT_SIZE, RdsSettings, as_framebuffer as rds_framebuffer, dot as rds_dot, rds_left,
    rds_right, right_only_seed, source_texel,
};
pub use effects::remap::{
    DEPTH_PRECISION, Precision, Remapped, Remapper, Visibility, classify as classify_visibility,
    depth_slope, remap_color, remap_color_pixel, remap_color_reference, remap_coordinates,
    tolerance as remap_tolerance, visibility_map,
};

// Parallax, its budget, and shear against rotate.
pub use effects::legend::{LEGEND_HEIGHT, draw_legend, draw_legend_reference};
pub use effects::parallax::{
    PARALLAX_BACKGROUND, PARALLAX_BUDGET_PERCENT, ParallaxBudget, ParallaxRig,
    VIOLATION_COLOR as PARALLAX_VIOLATION_COLOR, budget as parallax_budget,
    budget_of as parallax_budget_of, color_scale as parallax_color_scale, parallax_color,
    parallax_image, parallax_image_reference, parallax_map, violation_band, window_violation_marks,
};
pub use effects::shear_rotate::{
    Difference as ShearRotateDifference, difference as shear_rotate_difference,
    max_abs as max_abs_vertical_parallax, vertical_parallax_image, vertical_parallax_map,
};

// ChromaDepth: texgen, the ramp, the glasses.
pub use effects::chromadepth::glasses::{
    channel_weights, glasses_pair, glasses_view, pixel_shift, shift_map,
};
pub use effects::chromadepth::ramp::{
    DEFAULT_TEXELS, FAR_HUE_DEGREES, Ramp, RampKind, Sampling as RampSampling, exact as ramp_exact,
    hsv_to_rgb, hue_degrees,
};
pub use effects::chromadepth::texgen::{
    Texgen, auto_range, bounding_sphere, eye_plane, eye_plane_specified_under,
};
pub use effects::chromadepth::{
    ChromaDepthSettings, ChromaDepthView, TexgenMode, chromadepth_view,
};

// SIRDS: disparity, depth maps, TIW's per-pixel linking, the paper's per-vertex strips, and
// decoding.
pub use effects::sirds::decode::{
    AUTOSTEREOGRAM_SHARE, AutoDecoded as AutoDecodedSirds, DecodeOptions as SirdsDecodeOptions,
    Decoded as DecodedSirds, RoundTrip as SirdsRoundTrip, decode as decode_sirds,
    decode_auto as decode_sirds_auto, decode_auto_reporting as decode_sirds_auto_reporting,
    decode_reporting as decode_sirds_reporting, depth_from_separation, matched_share_where_all_fit,
    nearness_linear, round_trip as sirds_round_trip,
};
pub use effects::sirds::depthfile::{
    DepthSamples, Near, PgmRows, WINDOW_DEPTH_KEYWORD, WINDOW_DEPTH_TEXT, near_of_file,
};
pub use effects::sirds::depthmap::DepthMapping;
pub use effects::sirds::disparity::{
    separation_eye_distance, separation_view_angle, tan_phi_eye_distance,
};
pub use effects::sirds::pair::{Views as SirdsViews, views as sirds_views};
pub use effects::sirds::pattern::{
    GuideBoxes, GuidePlace, MAX_GUIDE_SIZE, MAX_TEXTURE_SIDE, Textured as SirdsTexture,
    draw_guide_boxes, draw_guide_dots, guide_box_columns,
};
pub use effects::sirds::per_pixel::{
    MAX_OVERSAMPLE, PLANES as SIRDS_PLANES, PerPixelOptions, RowLinker, SampleTable,
    check_inputs as check_sirds_inputs, left_of_pair, per_pixel, per_pixel_samples,
    per_pixel_streamed, plane_nearness, plane_separation,
};
pub use effects::sirds::search::{
    Region as SearchRegion, Search as SeparationSearch, SearchOptions as SeparationSearchOptions,
    search as search_separation,
};
pub use effects::sirds::settings::DotKind;
pub use effects::sirds::strips::reference::k_passes as per_vertex_k_passes;
pub use effects::sirds::strips::{
    Strip, StripGeometry, StripObject, StripResult, per_vertex, per_vertex_reference, plan_strips,
};
pub use effects::sirds::{
    Algorithm as SirdsAlgorithm, DepthMap, DepthRange, Disparity, DisparityModel,
    Filter as StripFilter, Geometry as SirdsGeometry, Pattern as SirdsPattern, PerVertexOptions,
    Settings as SirdsSettings, Sirds, SirdsSpec, Start as StripStart, depth_range, from_depth_map,
};

// Reading and writing files within bounds, text in pictures, the CPU's vector loops.
pub use files::{
    EXCERPT_CHARS, InputRoot, OutputSet, STALE_AFTER, StagingDir, UTF16_WITHOUT_BOM, check_input,
    check_output_path, excerpt, image_error, looks_like_utf16, open_image as open_image_within,
    read_input, read_text, remove_stale_temporaries, remove_temporaries, without_bom, write_atomic,
    write_bytes, write_png,
};
pub use simd::{avx2_available, uses_avx2};
pub use text::{Align as TextAlign, caption, draw_rgba as draw_text_rgba, width as text_width};
