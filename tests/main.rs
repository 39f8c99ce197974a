//! One integration-test binary (tiny-skia's layout): `mod` per area.

mod cli;
mod common;
mod conformance;
mod determinism;
mod golden;
mod grading;
mod layout;
mod rig;
