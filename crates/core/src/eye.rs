//! Which eye: the one name the rig, the passes, the effects and the frame buffers use.

/// The left or the right eye of a stereo pair. The exercise slides number them 0 (left) and 1
/// (right), and put the left eye at `x = −d/2`, the right one at `x = +d/2` along the camera's
/// x axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
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
}
