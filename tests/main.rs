//! One integration-test binary (tiny-skia's layout): `mod` per area.

mod common;
#[cfg(feature = "gpu")]
mod gpu_parity;
