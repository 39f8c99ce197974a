//! Which eye: the one name the stubs, the grader and stereolab's renderer use.

use serde::{Deserialize, Serialize};

/// The left or the right eye of a stereo pair. The exercise slides number them 0 (left) and 1
/// (right), and put the left eye at `x = −d/2`, the right one at `x = +d/2` along the camera's
/// x axis.
///
/// In JSON (the grader's inputs, the handout's data files) an eye is that number: `0` or `1`;
/// any other value is refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub enum Eye {
    /// The left eye: index 0, at `−d/2`.
    Left,
    /// The right eye: index 1, at `+d/2`.
    Right,
}

impl Eye {
    /// Both eyes, left first: the order of an eye pair.
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    /// 0 for the left eye, 1 for the right: the index into an eye pair.
    pub const fn index(self) -> usize {
        match self {
            Eye::Left => 0,
            Eye::Right => 1,
        }
    }

    /// −1 for the left eye, +1 for the right: the side of the camera's x axis the eye sits on.
    pub const fn sign(self) -> f32 {
        match self {
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }

    /// The other eye.
    pub const fn other(self) -> Eye {
        match self {
            Eye::Left => Eye::Right,
            Eye::Right => Eye::Left,
        }
    }
}

/// The eye's number: 0 for the left eye, 1 for the right (its JSON form).
impl From<Eye> for u8 {
    fn from(eye: Eye) -> u8 {
        match eye {
            Eye::Left => 0,
            Eye::Right => 1,
        }
    }
}

/// 0 is the left eye, 1 the right; any other number is no eye.
impl TryFrom<u8> for Eye {
    type Error = String;

    fn try_from(n: u8) -> Result<Eye, String> {
        match n {
            0 => Ok(Eye::Left),
            1 => Ok(Eye::Right),
            n => Err(format!("{n} is not an eye: 0 is the left eye, 1 the right")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_and_sign_follow_the_exercise_slides() {
        assert_eq!(Eye::BOTH.map(Eye::index), [0, 1]);
        assert_eq!(Eye::BOTH.map(Eye::sign), [-1.0, 1.0]);
        assert_eq!(Eye::Left.other(), Eye::Right);
        assert_eq!(Eye::Right.other(), Eye::Left);
    }

    #[test]
    fn json_numbers_the_eyes_0_and_1() {
        assert_eq!(serde_json::to_string(&Eye::BOTH).unwrap(), "[0,1]");
        let back: [Eye; 2] = serde_json::from_str("[0, 1]").unwrap();
        assert_eq!(back, Eye::BOTH);
        let pair: (f32, Eye) = serde_json::from_value(serde_json::json!([2.5, 1])).unwrap();
        assert_eq!(pair, (2.5, Eye::Right));
    }

    #[test]
    fn json_refuses_any_other_eye_number() {
        for bad in ["2", "-1", "0.5", "\"left\"", "null"] {
            assert!(
                serde_json::from_str::<Eye>(bad).is_err(),
                "{bad} was read as an eye"
            );
        }
        let e = serde_json::from_str::<Eye>("2").unwrap_err().to_string();
        assert!(e.contains("2 is not an eye"), "{e}");
    }
}
