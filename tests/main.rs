//! One integration-test binary (tiny-skia's layout): `mod` per area.

mod common;
mod sirds;
