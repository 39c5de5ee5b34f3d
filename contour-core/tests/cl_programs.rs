//! A fifteen-operation CL file as NX writes it (an information listing's header, `TOOL
//! PATH`, `TLDATA`, `MSYS`, `PAINT`, `SPINDL` records, `FEDRAT`s, `RAPID`s between the
//! operations, `CIRCLE` corners, tilts from 0° to 90°, a raster over a dome's apex and a
//! pass beside vertical; `cam_examples::nx_multi_operation_cls`), planned as the
//! five-axis interpolator plans it with the file's own speeds. The reference is judged
//! against the test's own reading of the file: every sample within the tolerances of the
//! CL path, within the joints' limits, no faster than the move it is on, and its duration
//! between bounds the test derives from the file.
//!
//! Public CL files (`tests/data/cl`, their sources and licences in its README; or any
//! folder through `CL_FILES=dir`) are read and planned the same way and judged against
//! the reader's poses: the table of the note (`--nocapture`).

use std::time::Instant;

use contour_core::geometry::{self, Vector};
use contour_core::kinematics::{Pose, TableTiltingAc};
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::math;
use contour_core::part_program::cl_data::{load_cl, parse_cl};
use contour_core::part_program::PartProgram;
use contour_core::path::five_axis::{
    cam_examples, feed_of_move, program_feeds, FiveAxisInputs, FiveAxisReference, Planner, ToolPath,
};

const TS: f64 = 1e-3;
/// The interpolator's `feed` and `rapid` parameters, mm/s: the file's FEDRATs win.
const FEED: f64 = 50.0;
const RAPID: f64 = 100.0;

/// One straight piece of the CL path as this test reads the file.
#[derive(Clone, Copy)]
struct Piece {
    from: Pose,
    to: Pose,
    /// mm/s.
    feed: f64,
}

/// A record's numbers (its words, `MMPM`, left out).
fn numbers(record: &str) -> Vec<f64> {
    let (_, args) = record.split_once('/').unwrap();
    args.split(',')
        .filter_map(|x| x.trim().parse::<f64>().ok())
        .collect()
}

/// The file's moves as straight pieces, each `CIRCLE` as chords of at most 0.1 µm sag,
/// counter-clockwise about its axis; the speed of each (FEDRAT in mm/min, `RAPID` for
/// the next GOTO only, `FEED` before the first FEDRAT).
fn read(text: &str) -> Vec<Piece> {
    let mut pieces = Vec::new();
    let (mut feed, mut rapid) = (FEED, false);
    let mut at: Option<Pose> = None;
    let mut circle: Option<(Vector<3>, Vector<3>, f64)> = None;
    for line in text.lines() {
        if line.starts_with("FEDRAT/MMPM,") {
            feed = numbers(line)[0] / 60.0;
        } else if line == "RAPID" {
            rapid = true;
        } else if line.starts_with("CIRCLE/") {
            let n = numbers(line);
            circle = Some((
                Vector::<3>::new(n[0], n[1], n[2]),
                geometry::unit(&Vector::<3>::new(n[3], n[4], n[5])).unwrap(),
                n[6],
            ));
        } else if line.starts_with("GOTO/") {
            let n = numbers(line);
            let to = Pose {
                tip: Vector::<3>::new(n[0], n[1], n[2]),
                axis: geometry::unit(&Vector::<3>::new(n[3], n[4], n[5])).unwrap(),
            };
            let speed = if std::mem::take(&mut rapid) {
                RAPID
            } else {
                feed
            };
            if let Some(from) = at {
                match circle.take() {
                    Some((centre, axis, r)) => {
                        // Angles about the axis from the start to the end, counter-clockwise.
                        let u = geometry::unit(&(from.tip - centre)).unwrap();
                        let v = axis.cross(&u);
                        let e = to.tip - centre;
                        let mut sweep = math::atan2(e.dot(&v), e.dot(&u));
                        if sweep <= 1e-9 {
                            sweep += 2.0 * std::f64::consts::PI;
                        }
                        let chords = (sweep / (2.0 * math::acos(1.0 - 1e-7 / r))).ceil() as usize;
                        let mut last = from;
                        for k in 1..=chords {
                            let angle = sweep * k as f64 / chords as f64;
                            let tip = if k == chords {
                                to.tip
                            } else {
                                centre + (u * math::cos(angle) + v * math::sin(angle)) * r
                            };
                            let next = Pose { tip, axis: to.axis };
                            pieces.push(Piece {
                                from: last,
                                to: next,
                                feed: speed,
                            });
                            last = next;
                        }
                    }
                    None => pieces.push(Piece {
                        from,
                        to,
                        feed: speed,
                    }),
                }
            }
            at = Some(to);
        }
    }
    pieces
}

/// The distance of `pose`'s tip from piece `p` and the angle of its axis from the
/// piece's (slerped) axis there.
fn off(p: &Piece, pose: &Pose) -> (f64, f64) {
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

/// How near a turn on the spot's tip a planned tip counts as on it: the planner's
/// tolerance.
const TURN_REACH: f64 = 5e-3;

/// The interpolator's plan of `program` (the file's speeds, `FEED` and `RAPID`), and
/// the time it took.
fn planned(
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
struct Followed {
    samples: Vec<(Pose, [f64; 5], usize)>,
    /// The largest distance of a tip from its piece, mm.
    tip: f64,
    /// The largest angle of an axis from its piece's, rad.
    axis: f64,
}

/// Walks `reference` to its end, each sample matched to the nearest piece a little behind
/// or ahead of the last match (the path comes back near itself: rasters, rapids out and
/// in); asserts that it ends on the last piece.
fn follow(pieces: &[Piece], reference: &mut FiveAxisReference) -> Followed {
    let mut samples: Vec<(Pose, [f64; 5], usize)> = Vec::new();
    let mut near = 0usize;
    let (mut worst_tip, mut worst_axis) = (0.0f64, 0.0f64);
    loop {
        let sample = reference.current();
        let pose = TableTiltingAc::default().forward(&sample.joints);
        let (mut best, mut best_off) = (near, (f64::INFINITY, 0.0));
        let (mut k, mut ahead) = (near.saturating_sub(20), 0.0);
        while k < pieces.len() && (ahead < 5.0 || k <= near + 2) {
            let o = off(&pieces[k], &pose);
            // On a tie the later piece: a move that retraces the one before (out of a
            // hole) is matched to the move it is on.
            if o.0 < best_off.0 || (o.0 == best_off.0 && k > near) {
                (best, best_off) = (k, o);
            }
            // How far past the last match the pieces seen reach.
            if k > near {
                ahead += geometry::dist(&pieces[k].from.tip, &pieces[k].to.tip)
                    + 1e-3 * geometry::angle_between(&pieces[k].from.axis, &pieces[k].to.axis);
            }
            k += 1;
        }
        near = best;
        worst_tip = worst_tip.max(best_off.0);
        worst_axis = worst_axis.max(best_off.1);
        samples.push((pose, sample.joints.into(), best));
        if sample.done {
            break;
        }
        reference.step().unwrap();
    }
    assert_eq!(
        near,
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
fn joints_within(samples: &[(Pose, [f64; 5], usize)], joints: &JointLimits) -> [f64; 5] {
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

#[test]
fn the_nx_multi_operation_file_is_read_with_one_warning_per_kind() {
    let text = cam_examples::nx_multi_operation_cls();
    let gotos = text.lines().filter(|l| l.starts_with("GOTO/")).count();
    let operations = text.lines().filter(|l| l.starts_with("TOOL PATH/")).count();
    assert!(gotos > 10_000, "{gotos} GOTOs");
    assert_eq!(operations, 15);
    let program = parse_cl(&text, "multi.cls").unwrap();
    // Every GOTO a pose, and each CIRCLE's chords besides.
    assert!(program.poses().len() > gotos);
    let kinds: Vec<&str> = program
        .warnings
        .iter()
        .map(|w| w.message.split(' ').next().unwrap())
        .collect();
    assert_eq!(
        kinds,
        ["text", "TOOL", "TLDATA", "PAINT", "LOAD"],
        "{kinds:?}"
    );
    assert_eq!(program.warnings[0].place.line, 1);
}

#[test]
fn the_multi_operation_file_is_planned_within_its_speeds_the_limits_and_the_tolerances() {
    let text = cam_examples::nx_multi_operation_cls();
    let pieces = read(&text);
    let limits = PathLimits::at_feed(FEED);
    let joints = JointLimits::default();
    let start = Instant::now();
    let program = parse_cl(&text, "multi.cls").unwrap();
    let mut reference = planned(&program, "multi.cls", limits).unwrap_or_else(|e| panic!("{e}"));
    let seconds = start.elapsed().as_secs_f64();
    let duration = reference.planned_duration().unwrap();
    let Followed {
        samples,
        tip: worst_tip,
        axis: worst_axis,
    } = follow(&pieces, &mut reference);
    assert!(
        worst_tip <= limits.tolerance * (1.0 + 1e-6),
        "tip {worst_tip} mm"
    );
    assert!(
        worst_axis <= limits.orientation_tolerance * (1.0 + 1e-6),
        "axis {worst_axis} rad"
    );

    // The joints within their limits; the tip no faster than the move it is on, where
    // every sample within the jerk filter's reach is on moves of that speed.
    let peak_joint = joints_within(&samples, &joints);
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
    // Each speed of the file is reached somewhere: the file's FEDRATs, not the `feed`
    // parameter, and the rapids at `rapid`.
    let feeds: std::collections::BTreeSet<u64> =
        pieces.iter().map(|p| (p.feed * 1e6) as u64).collect();
    for f in feeds {
        let top = fastest.get(&f).copied().unwrap_or(0.0);
        assert!(
            top >= 0.95 * f as f64 * 1e-6,
            "the moves at {} mm/s reach {top}",
            f as f64 * 1e-6
        );
    }
    assert!(!fastest.contains_key(&((FEED * 1e6) as u64)));

    // No faster than every move at its speed; no slower than stopping at every pose
    // with a plain trapezoid of the tip's acceleration, the moves that turn the tool at
    // the rotary axes' speed.
    let lower: f64 = pieces
        .iter()
        .map(|p| geometry::dist(&p.from.tip, &p.to.tip) / p.feed)
        .sum();
    assert!(duration >= lower, "{duration} s against {lower} s");
    println!(
        "planned in {seconds:.2} s: {} samples ({duration:.1} s, at least {lower:.1} s), tip \
         within {:.4} mm, axis within {:.3} mrad, joints' peak speeds {:?} of their limits",
        samples.len(),
        worst_tip,
        worst_axis * 1e3,
        peak_joint
    );
}

/// The reader's poses as straight pieces with their speeds.
fn pieces_of(program: &PartProgram) -> Vec<Piece> {
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

/// The public CL files of `tests/data/cl` (their sources and licences in its README),
/// each read and planned as the interpolator does, every sample within the tolerances of
/// the reader's poses and the joints within their limits; the table printed
/// (`--nocapture`). `CL_FILES=dir` surveys another folder instead: a file refused there
/// is a row of the table with its reason, not a failure.
#[test]
fn public_cl_files_are_read_and_planned() {
    let survey = std::env::var_os("CL_FILES").map(std::path::PathBuf::from);
    let dir = survey.clone().unwrap_or_else(|| {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/cl")
    });
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x != "md"))
        .collect();
    files.sort();
    assert!(survey.is_some() || !files.is_empty(), "{files:?}");
    println!(
        "| file | poses | warnings | planning | duration | tip | axis | peak joint speeds (X Y Z A C) |"
    );
    // The files of tests/data/cl the reader refuses, and why (its README).
    let refused = [
        ("bohren_1.ncl", "16: CYCLE/DEEP"),
        ("PrepaFlans_Pointage.aptsource", "36: CYCLE/DRILL"),
        ("RotateThin.apt", "20: CUTCOM"),
    ];
    for file in files {
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let expected = refused
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, why)| *why);
        match (read_and_plan(&file, &name), expected) {
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

/// One CL file read and planned at the interpolator's defaults: its row of the table, or
/// why it is refused.
fn read_and_plan(file: &std::path::Path, name: &str) -> Result<String, String> {
    let start = Instant::now();
    let program = load_cl(file).map_err(|e| e.to_string())?;
    plan_and_follow(&program, name, start)
}

/// `program` planned at the interpolator's defaults (`start`: when its reading began)
/// and followed: every sample within the tolerances of the reader's poses, the joints
/// within their limits, the duration no shorter than every move at its speed; the row of
/// the table.
fn plan_and_follow(program: &PartProgram, name: &str, start: Instant) -> Result<String, String> {
    let limits = PathLimits::at_feed(FEED);
    let mut reference = planned(program, name, limits)?;
    let seconds = start.elapsed().as_secs_f64();
    let pieces = pieces_of(program);
    let followed = follow(&pieces, &mut reference);
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
    let duration = reference.planned_duration().unwrap();
    let lower: f64 = pieces
        .iter()
        .map(|p| geometry::dist(&p.from.tip, &p.to.tip) / p.feed)
        .sum();
    assert!(duration >= lower, "{name}: {duration} s against {lower} s");
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

/// The near-vertical pass as NX writes it (inch, `MSYS`, `FEDRAT/IPM`; the axis 0.3°–2.05°
/// from vertical, its azimuth swinging up to ±172°, across the pole cone again and again;
/// `cl_near_pole.rs` checks the reading and the joints at the nodes): planned with its
/// feed like any CL file, within the tolerances, the limits and the time bound.
#[test]
fn the_near_vertical_nx_pass_is_planned_within_its_feed_and_the_limits() {
    for (step, swing, period) in [(0.004, 2.5, 0.2), (0.02, 2.5, 0.08), (0.004, 3.0, 0.8)] {
        let text = cam_examples::nx_near_pole_pass(600, step, 2.05, swing, period);
        let start = Instant::now();
        let program = parse_cl(&text, "near_pole.cls").unwrap();
        let name = format!("near_pole step {step} in, swing {swing} rad, period {period} in");
        let row = plan_and_follow(&program, &name, start).unwrap_or_else(|e| panic!("{e}"));
        println!("{row}");
    }
}
