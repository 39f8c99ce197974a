//! One integration-test binary (tiny-skia's layout): `mod` per area.

mod common;
mod rig;
mod conformance;
mod determinism;
mod layout;
mod cli;
