//! What the five-axis part-program tests share: a program's pieces, the interpolator's
//! plan of it, the reference followed against the test's own pieces, and the joints'
//! and the tip's limits checked on every sample.
#![allow(dead_code)]

use std::time::Instant;

use contour_core::geometry;
use contour_core::kinematics::{Pose, TableTiltingAc};
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::part_program::PartProgram;
use contour_core::path::five_axis::{
    feed_of_move, program_feeds, FiveAxisInputs, FiveAxisReference, Planner, ToolPath,
};

pub const TS: f64 = 1e-3;
/// The interpolator's `feed` and `rapid` parameters, mm/s: the file's FEDRATs win.
pub const FEED: f64 = 50.0;
pub const RAPID: f64 = 100.0;

/// One straight piece of the CL path as this test reads the file.
#[derive(Clone, Copy)]
pub struct Piece {
    pub from: Pose,
    pub to: Pose,
    /// mm/s.
    pub feed: f64,
}

/// The distance of `pose`'s tip from piece `p` and the angle of its axis from the
/// piece's (slerped) axis there.
pub fn off(p: &Piece, pose: &Pose) -> (f64, f64) {
    let d = p.to.tip - p.from.tip;
    let length2 = d.norm_squared();
    let t = if length2 > 0.0 {
        ((pose.tip - p.from.tip).dot(&d) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let axis = geometry::slerp(&p.from.axis, &p.to.axis, t).unwrap();
    let distance = geometry::dist(&(p.from.tip + d * t), &pose.tip);
    if length2 == 0.0 && distance <= TURN_REACH {
        // The tool turns on the spot: every axis of the turn is programmed at this tip
        // (sampled finely enough for the tolerances, 0.16 mrad at a half turn).
        let nearest = (0..=10_000)
            .map(|k| geometry::slerp(&p.from.axis, &p.to.axis, k as f64 / 1e4).unwrap())
            .map(|axis| geometry::angle_between(&axis, &pose.axis))
            .fold(f64::INFINITY, f64::min);
        return (distance, nearest);
    }
    (distance, geometry::angle_between(&axis, &pose.axis))
}

/// How much nearer than the pieces from the last match on a piece before it must be to
/// be matched, mm (four times the plan's tolerance).
const BACK_SLACK: f64 = 0.02;

/// How near a turn on the spot's tip a planned tip counts as on it: the planner's
/// tolerance.
const TURN_REACH: f64 = 5e-3;

/// The interpolator's plan of `program` (the file's speeds, `FEED` and `RAPID`), and
/// the time it took.
pub fn planned(
    program: &PartProgram,
    name: &str,
    limits: PathLimits,
) -> Result<FiveAxisReference, String> {
    let inputs = FiveAxisInputs {
        path: ToolPath::from_poses(&program.poses()).map_err(|e| e.to_string())?,
        builtin: None,
        feeds: program_feeds(program, FEED, RAPID),
        machine: TableTiltingAc::default(),
        joints: JointLimits::default(),
        limits,
        ts: TS,
    };
    let lines = program.lines();
    let at = |i: usize| format!("{name}:{}", lines[i]);
    FiveAxisReference::new(inputs, &Planner::new(), &at).map_err(|e| e.to_string())
}

/// The samples of a reference followed to its end, each with its pose, joints and the
/// piece it was matched to.
pub struct Followed {
    pub samples: Vec<(Pose, [f64; 5], usize)>,
    /// The largest distance of a tip from its piece, mm.
    pub tip: f64,
    /// The largest angle of an axis from its piece's, rad.
    pub axis: f64,
}

/// Walks `reference` to its end, each sample matched to the nearest piece a little behind
/// or ahead of the last match (the path comes back near itself: rasters, rapids out and
/// in); asserts that it ends on the last piece.
pub fn follow(pieces: &[Piece], reference: &mut FiveAxisReference) -> Followed {
    let mut near = 0usize;
    let mut last_tip: Option<contour_core::geometry::Vector<3>> = None;
    walk(pieces, reference, |pose, _| {
        let (mut best, mut best_off) = (near, (f64::INFINITY, 0.0));
        let mut best_along = f64::NEG_INFINITY;
        // The way the tip moved since the last sample.
        let moved = last_tip.and_then(|last| geometry::unit(&(pose.tip - last)));
        last_tip = Some(pose.tip);
        // The pieces from the last match on, as far as 5 mm past it (at least two),
        // then the 20 before it.
        let mut ahead = 0.0;
        let forward = (near..pieces.len()).take_while(|&k| {
            let within = ahead < 5.0 || k <= near + 2;
            if k > near {
                // How far past the last match the pieces seen reach.
                ahead += geometry::dist(&pieces[k].from.tip, &pieces[k].to.tip)
                    + 1e-3 * geometry::angle_between(&pieces[k].from.axis, &pieces[k].to.axis);
            }
            within
        });
        for k in forward.chain(near.saturating_sub(20)..near) {
            let o = off(&pieces[k], pose);
            let along = match (
                moved,
                geometry::unit(&(pieces[k].to.tip - pieces[k].from.tip)),
            ) {
                (Some(m), Some(d)) => m.dot(&d),
                _ => 0.0,
            };
            // A piece before the last match only when clearly nearer; among pieces as
            // near (a move that retraces another, out of a hole or back up from a
            // plunge; a corner where moves meet again) the one the tip moves along.
            let better = if k < near {
                o.0 + BACK_SLACK < best_off.0
            } else if (o.0 - best_off.0).abs() <= 1e-9 {
                along > best_along
            } else {
                o.0 < best_off.0
            };
            if better {
                (best, best_off, best_along) = (k, o, along);
            }
        }
        near = best;
        (best, best_off)
    })
}

/// [`follow`] for pieces that are the planned path's own poses (piece k from pose k to
/// k + 1): each sample matched to the nearest piece among those from 10 mm of path behind
/// the raw sample's pose (the reference's `u`, a hint only: the filtered tip lags the raw
/// one) to two pieces past it. A program that comes back over itself (the same hole
/// drilled by three tools) cannot mislead the match.
pub fn follow_by_hint(pieces: &[Piece], reference: &mut FiveAxisReference) -> Followed {
    walk(pieces, reference, |pose, u| {
        let raw = (u.max(0.0) as usize).min(pieces.len() - 1);
        let mut first = raw;
        let mut behind = 0.0;
        while first > 0 && behind < 10.0 {
            first -= 1;
            behind += geometry::dist(&pieces[first].from.tip, &pieces[first].to.tip);
        }
        let (mut best, mut best_off) = (raw, (f64::INFINITY, 0.0));
        let end = (raw + 2).min(pieces.len() - 1);
        for (k, piece) in pieces.iter().enumerate().take(end + 1).skip(first) {
            let o = off(piece, pose);
            // On a tie the later piece: the one the raw sample is on or nearer it.
            if o.0 <= best_off.0 {
                (best, best_off) = (k, o);
            }
        }
        (best, best_off)
    })
}

/// Walks `reference` to its end, `matched` giving each sample's piece and its (tip, axis)
/// errors from its pose and the reference's path parameter; asserts that it ends on the
/// last piece.
fn walk(
    pieces: &[Piece],
    reference: &mut FiveAxisReference,
    mut matched: impl FnMut(&Pose, f64) -> (usize, (f64, f64)),
) -> Followed {
    let mut samples: Vec<(Pose, [f64; 5], usize)> = Vec::new();
    let (mut worst_tip, mut worst_axis) = (0.0f64, 0.0f64);
    let last = loop {
        let sample = reference.current();
        let pose = TableTiltingAc::default().forward(&sample.joints);
        let (best, (tip, axis)) = matched(&pose, sample.u);
        worst_tip = worst_tip.max(tip);
        worst_axis = worst_axis.max(axis);
        samples.push((pose, sample.joints.into(), best));
        if sample.done {
            break best;
        }
        reference.step().unwrap();
    };
    assert_eq!(
        last,
        pieces.len() - 1,
        "the reference ends on the last piece"
    );
    Followed {
        samples,
        tip: worst_tip,
        axis: worst_axis,
    }
}

/// Asserts every joint within its travel, speed and acceleration on every sample; the
/// peak speed of each joint as a share of its limit.
pub fn joints_within(samples: &[(Pose, [f64; 5], usize)], joints: &JointLimits) -> [f64; 5] {
    let mut peak_joint = [0.0f64; 5];
    for k in 2..samples.len() {
        let q = |j: usize| samples[j].1;
        for (i, peak) in peak_joint.iter_mut().enumerate() {
            let v = (q(k)[i] - q(k - 1)[i]) / TS;
            let a = (q(k)[i] - 2.0 * q(k - 1)[i] + q(k - 2)[i]) / (TS * TS);
            *peak = peak.max(v.abs() / joints.velocity[i]);
            assert!(
                v.abs() <= joints.velocity[i] * (1.0 + 1e-6) + 1e-6,
                "joint {i} at {v}/s, sample {k}"
            );
            assert!(
                a.abs() <= joints.acceleration[i] * (1.0 + 1e-5) + 1e-2,
                "joint {i} at {a}/s², sample {k}"
            );
            assert!(q(k)[i] >= joints.min[i] && q(k)[i] <= joints.max[i]);
        }
    }
    peak_joint.map(|p| (p * 1000.0).round() / 1000.0)
}

/// The reader's poses as straight pieces with their speeds.
pub fn pieces_of(program: &PartProgram) -> Vec<Piece> {
    let poses = program.poses();
    let feeds = program_feeds(program, FEED, RAPID);
    poses
        .windows(2)
        .enumerate()
        .map(|(i, w)| Piece {
            from: w[0],
            to: w[1],
            feed: feed_of_move(&feeds, FEED, i + 1),
        })
        .collect()
}

/// Asserts the tip no faster than the move it is on, where every sample within the jerk
/// filter's reach is on moves of that speed; the fastest sample at each speed (µm/s).
pub fn speeds_within(
    samples: &[(Pose, [f64; 5], usize)],
    pieces: &[Piece],
) -> std::collections::BTreeMap<u64, f64> {
    let mut fastest = std::collections::BTreeMap::<u64, f64>::new();
    let reach = 40;
    for k in 2..samples.len() {
        let speed = geometry::dist(&samples[k].0.tip, &samples[k - 1].0.tip) / TS;
        let feed = pieces[samples[k].2].feed;
        let window = k.saturating_sub(reach)..(k + reach).min(samples.len());
        if window.clone().all(|j| pieces[samples[j].2].feed == feed) {
            assert!(
                speed <= feed * (1.0 + 1e-6),
                "sample {k}: {speed} mm/s on a move at {feed}"
            );
            let top = fastest.entry((feed * 1e6) as u64).or_insert(0.0);
            *top = top.max(speed);
        }
    }
    fastest
}

/// `program` planned at the interpolator's defaults (`start`: when its reading began)
/// and followed: every sample within the tolerances of the reader's poses, the joints
/// within their limits, the duration no shorter than every move at its speed; the row of
/// the table.
pub fn plan_and_follow(
    program: &PartProgram,
    name: &str,
    start: Instant,
) -> Result<String, String> {
    let limits = PathLimits::at_feed(FEED);
    let mut reference = planned(program, name, limits)?;
    let seconds = start.elapsed().as_secs_f64();
    let pieces = pieces_of(program);
    let followed = follow_by_hint(&pieces, &mut reference);
    assert!(
        followed.tip <= limits.tolerance * (1.0 + 1e-6),
        "{name}: tip {} mm",
        followed.tip
    );
    assert!(
        followed.axis <= limits.orientation_tolerance * (1.0 + 1e-6),
        "{name}: axis {} rad",
        followed.axis
    );
    let peaks = joints_within(&followed.samples, &JointLimits::default());
    let (duration, lower) = duration_within(&reference, &pieces, name);
    let kinds: Vec<String> = program
        .warnings
        .iter()
        .map(|w| w.message.split(' ').next().unwrap_or("").to_string())
        .collect();
    Ok(format!(
        "| {name} | {} | {} | {seconds:.2} s | {duration:.1} s (≥ {lower:.1} s) | {:.2e} mm | \
         {:.2e} rad | {peaks:?} |",
        program.poses().len(),
        kinds.join(", "),
        followed.tip,
        followed.axis,
    ))
}

/// Asserts the planned duration no shorter than every piece at its feed; (duration,
/// that bound), s.
pub fn duration_within(reference: &FiveAxisReference, pieces: &[Piece], name: &str) -> (f64, f64) {
    let duration = reference.planned_duration().unwrap();
    let lower: f64 = pieces
        .iter()
        .map(|p| geometry::dist(&p.from.tip, &p.to.tip) / p.feed)
        .sum();
    assert!(duration >= lower, "{name}: {duration} s against {lower} s");
    (duration, lower)
}

/// The survey of a folder of public programs: `default` (under the repository's
/// `tests/data`), or the folder the environment variable `variable` names; every file
/// `wanted` takes, sorted, read and planned by `row`. In `default` a file must give its
/// row, or be refused for the reason `refused` lists for it; in a surveyed folder a
/// refusal is a row of the table. The table printed (`--nocapture`).
pub fn survey(
    variable: &str,
    default: &str,
    wanted: impl Fn(&std::path::Path) -> bool,
    refused: &[(&str, &str)],
    row: impl Fn(&std::path::Path, &str) -> Result<String, String>,
) {
    let survey = std::env::var_os(variable).map(std::path::PathBuf::from);
    let dir = survey.clone().unwrap_or_else(|| {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/data")
            .join(default)
    });
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| wanted(p))
        .collect();
    files.sort();
    assert!(survey.is_some() || !files.is_empty(), "{files:?}");
    println!(
        "| file | poses | warnings | planning | duration | tip | axis | peak joint speeds (X Y Z A C) |"
    );
    for file in files {
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let expected = refused
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, why)| *why);
        match (row(&file, &name), expected) {
            (Ok(row), None) => println!("{row}"),
            (Err(why), _) if survey.is_some() => {
                println!("| {name} | refused: {why} | | | | | | |")
            }
            (Err(why), Some(reason)) if why.contains(reason) => {
                println!("| {name} | refused: {why} | | | | | | |")
            }
            (Ok(_), Some(reason)) => panic!("{name}: read, expected refused for {reason}"),
            (Err(why), _) => panic!("{name}: {why}"),
        }
    }
}
