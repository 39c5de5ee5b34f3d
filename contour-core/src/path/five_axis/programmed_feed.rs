//! The programmed tip speed move by move (docs/design/five-axis.md §5.3c): a part
//! program's feed words and rapids become [`FeedChange`]s on its poses, and the plan keeps
//! every move within its own speed, as a controller keeps each block within its F.

use serde::{Deserialize, Serialize};

use crate::part_program::{Motion, PartProgram, Speed};
use crate::path::PathError;

/// From one programmed pose on, the tip's greatest speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeedChange {
    /// The first pose whose move (from the pose before it) runs at `feed`; the moves
    /// after it do too, up to the next change.
    pub from: usize,
    /// The greatest tip speed, mm/s (finite, > 0).
    pub feed: f64,
}

/// The speed changes along `program`'s poses ([`PartProgram::poses`]): a feed word's
/// speed, `rapid` for a rapid, `feed` before the first feed word; nothing where the
/// speed stays `feed` (a program without feed words gives none).
pub fn program_feeds(program: &PartProgram, feed: f64, rapid: f64) -> Vec<FeedChange> {
    let mut changes = Vec::new();
    let mut current = feed;
    let moves = program
        .moves
        .iter()
        .filter(|m| !matches!(m.motion, Motion::Dwell(_)));
    // Pose 0 is where the path starts: its move brings nothing to plan.
    for (pose, m) in moves.enumerate().skip(1) {
        let speed = match m.speed {
            Speed::Feed(f) => f,
            Speed::Default => feed,
            Speed::Rapid => rapid,
        };
        if speed != current {
            changes.push(FeedChange {
                from: pose,
                feed: speed,
            });
            current = speed;
        }
    }
    changes
}

/// Checks `changes` on a path of `poses` poses: in order, each on a move of the path, each
/// speed finite and > 0 (a restored state's changes are checked here too).
pub fn check_feeds(changes: &[FeedChange], poses: usize) -> Result<(), PathError> {
    let mut after = 0;
    for (k, change) in changes.iter().enumerate() {
        if change.from <= after || change.from >= poses {
            return Err(PathError::invalid(format!(
                "feed change {k} is at pose {}: changes must be in order, on poses 1 to {}",
                change.from,
                poses.saturating_sub(1)
            )));
        }
        if !(change.feed.is_finite() && change.feed > 0.0) {
            return Err(PathError::invalid(format!(
                "feed change {k} (pose {}) is {} mm/s: it must be finite and > 0",
                change.from, change.feed
            )));
        }
        after = change.from;
    }
    Ok(())
}

/// The speed of the move ending at `pose` (`default` before the first change).
pub fn feed_of_move(changes: &[FeedChange], default: f64, pose: usize) -> f64 {
    match changes.partition_point(|c| c.from <= pose) {
        0 => default,
        k => changes[k - 1].feed,
    }
}

/// The greatest speed anywhere on the path.
pub fn greatest_feed(changes: &[FeedChange], default: f64) -> f64 {
    changes.iter().map(|c| c.feed).fold(default, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::part_program::cl_data::parse_cl;

    #[test]
    fn feeds_follow_the_program_with_rapids_and_the_default_before_the_first_word() {
        let program = parse_cl(
            "GOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,1\nFEDRAT/MMPM,600\nGOTO/2,0,0,0,0,1\n\
             GOTO/3,0,0,0,0,1\nRAPID\nGOTO/3,0,50,0,0,1\nGOTO/4,0,50,0,0,1\n\
             FEDRAT/MMPM,3000\nGOTO/5,0,50,0,0,1\n",
            "t.cls",
        )
        .unwrap();
        let changes = program_feeds(&program, 40.0, 250.0);
        let expected = [(2, 10.0), (4, 250.0), (5, 10.0), (6, 50.0)];
        assert_eq!(changes.len(), expected.len(), "{changes:?}");
        for (c, (from, feed)) in changes.iter().zip(expected) {
            assert_eq!(c.from, from);
            assert!((c.feed - feed).abs() < 1e-12, "{c:?}");
        }
        check_feeds(&changes, 7).unwrap();
        let speeds: Vec<f64> = (1..7).map(|i| feed_of_move(&changes, 40.0, i)).collect();
        assert_eq!(speeds, [40.0, 10.0, 10.0, 250.0, 10.0, 50.0]);
        assert_eq!(greatest_feed(&changes, 40.0), 250.0);
    }

    #[test]
    fn bad_changes_are_refused() {
        let at = |from, feed| FeedChange { from, feed };
        for bad in [
            vec![at(0, 1.0)],
            vec![at(3, 1.0)],
            vec![at(2, 1.0), at(2, 2.0)],
            vec![at(1, f64::NAN)],
            vec![at(1, 0.0)],
            vec![at(1, f64::INFINITY)],
        ] {
            assert!(check_feeds(&bad, 3).is_err(), "{bad:?}");
        }
        check_feeds(&[at(1, 1.0), at(2, 3.0)], 3).unwrap();
    }
}
