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

use stereolab_core::{AnaglyphKind as ReferenceKind, AnaglyphMatrices as ReferenceMatrices};

/// The same anaglyph kind in stereolab's anaglyph module (the reference).
pub(crate) fn reference_kind(kind: AnaglyphKind) -> ReferenceKind {
    match kind {
        AnaglyphKind::True => ReferenceKind::True,
        AnaglyphKind::Gray => ReferenceKind::Gray,
        AnaglyphKind::Color => ReferenceKind::Color,
        AnaglyphKind::HalfColor => ReferenceKind::HalfColor,
    }
}

/// stereolab's matrices as the exercise's type (the same numbers, row-major).
pub(crate) fn exercise_matrices(m: ReferenceMatrices) -> AnaglyphMatrices {
    AnaglyphMatrices {
        left: m.left,
        right: m.right,
    }
}

/// The exercise's matrices as stereolab's type.
pub(crate) fn reference_matrices(m: AnaglyphMatrices) -> ReferenceMatrices {
    ReferenceMatrices {
        left: m.left,
        right: m.right,
    }
}
