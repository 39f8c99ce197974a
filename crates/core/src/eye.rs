//! Which eye: the one name the rig, the passes, the effects and the frame buffers use.
//!
//! [`Eye`] is the exercise API's own type (`exercise_api::Eye`), so the renderer, the grader and
//! the students' stubs share one enum, and its JSON form (0 = left, 1 = right) is the grader's.

pub use exercise_api::Eye;
