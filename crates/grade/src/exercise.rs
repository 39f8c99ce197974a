//! What exercise crates and the grader share, seen from stereolab: the `exercise-api` crate
//! (`exercises/exercise-api`: the wire protocol and the types the stubs take and return), plus
//! the conversions between its types and stereolab's.
//!
//! A student's crate depends on `exercise-api` and `glam` only, never on stereolab: the reference
//! answers live here, in the grader.

pub use exercise_api::{
    AnaglyphKind, AnaglyphMatrices, Answer, ColorMatrix, Eye, EyeView, ScreenSetup, SirdsGeometry,
    SirdsSetup, StereoSetup, decode_reply, protocol,
};

use stereolab_core::effects::anaglyph;

/// The same anaglyph kind in stereolab's anaglyph module (the reference).
pub(crate) fn reference_kind(kind: AnaglyphKind) -> anaglyph::AnaglyphKind {
    match kind {
        AnaglyphKind::True => anaglyph::AnaglyphKind::True,
        AnaglyphKind::Gray => anaglyph::AnaglyphKind::Gray,
        AnaglyphKind::Color => anaglyph::AnaglyphKind::Color,
        AnaglyphKind::HalfColor => anaglyph::AnaglyphKind::HalfColor,
    }
}

/// stereolab's matrices as the exercise's type (the same numbers, row-major).
pub(crate) fn exercise_matrices(m: anaglyph::AnaglyphMatrices) -> AnaglyphMatrices {
    AnaglyphMatrices {
        left: m.left,
        right: m.right,
    }
}

/// The exercise's matrices as stereolab's type.
pub(crate) fn reference_matrices(m: AnaglyphMatrices) -> anaglyph::AnaglyphMatrices {
    anaglyph::AnaglyphMatrices {
        left: m.left,
        right: m.right,
    }
}
