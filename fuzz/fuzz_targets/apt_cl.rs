//! The APT CL reader (`parse_cl`, as PathInterpolator5X reads a CL file) on
//! arbitrary text (lossily UTF-8: a file that is not is refused before parsing). What
//! parses becomes a tool path (`ToolPath::from_poses`), is evaluated at awkward
//! parameters and followed for a few samples through the inverse kinematics, as the
//! model does; a short one is also planned with its FEDRATs and RAPIDs within a small
//! sample budget. Nothing may panic; every loop in there is bounded.
#![no_main]

use contour_core::kinematics::TableTiltingAc;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::part_program::cl_data::parse_cl;
use contour_core::path::five_axis::{
    check_feeds, program_feeds, FiveAxisPlan, JointReference, ToolPath,
};
use contour_fmu_fuzz::install_panic_hook;
use libfuzzer_sys::fuzz_target;

const SAMPLES: usize = 32;
/// The programs planned: at most this many poses and mm of tip path (a plan costs about
/// 10 µs a node, and nodes are 5 µm apart at the feed below: a longer path would slow
/// the reading this target is for to a few executions a second), within this many
/// samples.
const PLANNED_POSES: usize = 16;
const PLANNED_LENGTH: f64 = 2.0;
const PLAN_SAMPLES: u64 = 4_000;

fuzz_target!(init: install_panic_hook(), |data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(cl) = parse_cl(&text, "fuzz.cl") else {
        return;
    };
    assert!(cl.poses().len() >= 2, "parse_cl accepted fewer than two poses");
    // CIRCLE records become up to 10 000 chords each: the reading is what this target
    // checks there, not the following of a million poses.
    if cl.poses().len() > 100_000 {
        return;
    }
    let poses = cl.poses();
    let feeds = program_feeds(&cl, 10.0, 100.0);
    if let Err(e) = check_feeds(&feeds, poses.len()) {
        // Only a speed that overflowed (a feed per turn times a huge spindle speed).
        assert!(
            feeds.iter().any(|f| !f.feed.is_finite()),
            "the reader's speeds fail their check: {e}"
        );
        return;
    }
    let length: f64 = poses
        .windows(2)
        .map(|w| (w[1].tip - w[0].tip).norm())
        .sum();
    if poses.len() <= PLANNED_POSES && length <= PLANNED_LENGTH {
        let _ = FiveAxisPlan::within_budget(
            (&poses, &feeds),
            TableTiltingAc::default(),
            &JointLimits::default(),
            &PathLimits::at_feed(10.0),
            1e-3,
            &|i| format!("pose {i}"),
            PLAN_SAMPLES,
        );
    }
    let Ok(path) = ToolPath::from_poses(&poses) else {
        return;
    };
    let ToolPath::Poses { tips, .. } = &path else {
        panic!("poses make a pose path");
    };
    let (a, b) = (0.0, (tips.len() - 1) as f64);
    for u in [a, b, 0.5 * (a + b), a - 1.0, b + 1.0, f64::NAN, f64::INFINITY] {
        let _ = path.pose_at(u);
    }
    // The vertices themselves: no sampling for a pose path.
    assert_eq!(path.poses(0.01).map(|p| p.len()), Ok(cl.poses().len()));
    let feed = (length / (SAMPLES as f64 * 1e-3)).clamp(1e-3, 1e6);
    if let Ok(mut reference) = JointReference::new(path, TableTiltingAc::default(), feed, 1e-3) {
        for _ in 0..SAMPLES {
            match reference.step() {
                Ok(sample) if !sample.done => {}
                _ => break,
            }
        }
    }
});
