//! One integration-test binary (tiny-skia's layout): `mod` per area.

mod accuracy_report;
mod architecture;
mod chromadepth;
mod cli;
mod clipping;
mod common;
mod compare_flip;
mod conformance;
mod coverage;
mod determinism;
mod display;
mod figures;
mod finalize;
mod formulas_doc;
mod fuzz;
mod gallery;
mod golden;
#[cfg(feature = "gpu")]
mod gpu_finalize;
#[cfg(feature = "gpu")]
mod gpu_parity;
#[cfg(feature = "gpu")]
mod gpu_sirds;
mod grading;
mod grading_batch;
mod grading_sandbox;
mod grading_trust;
mod hard_cases;
mod image_shift;
mod inspect;
mod interruptions;
mod layout;
mod memory;
mod obj_corpus;
mod readme;
mod reliability;
mod rig;
mod scene_hashes;
mod shear_rotate;
mod sirds;
mod sirds_experiments;
mod sirds_interop;
mod sirds_options;
mod sirds_told;
mod stability;
mod stereo_photo;
#[cfg(feature = "viewer")]
mod viewer;
#[cfg(feature = "viewer")]
mod viewer_pair;
mod views;
mod zero_parallax;
