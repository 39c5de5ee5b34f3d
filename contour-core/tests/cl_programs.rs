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
use contour_core::kinematics::Pose;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::math;
use contour_core::part_program::cl_data::{load_cl, parse_cl};
use contour_core::path::five_axis::cam_examples;

mod support;

use support::*;

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
    let fastest = speeds_within(&samples, &pieces);
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

/// The public CL files of `tests/data/cl` (their sources and licences in its README),
/// each read and planned as the interpolator does, every sample within the tolerances of
/// the reader's poses and the joints within their limits; the table printed
/// (`--nocapture`). `CL_FILES=dir` surveys another folder instead: a file refused there
/// is a row of the table with its reason, not a failure.
#[test]
fn public_cl_files_are_read_and_planned() {
    // The files of tests/data/cl the reader refuses, and why (its README).
    let refused = [
        ("bohren_1.ncl", "16: CYCLE/DEEP"),
        ("PrepaFlans_Pointage.aptsource", "36: CYCLE/DRILL"),
        ("RotateThin.apt", "20: CUTCOM"),
    ];
    let not_readme = |p: &std::path::Path| p.extension().is_some_and(|x| x != "md");
    survey("CL_FILES", "cl", not_readme, &refused, read_and_plan);
}

/// One CL file read and planned at the interpolator's defaults: its row of the table, or
/// why it is refused.
fn read_and_plan(file: &std::path::Path, name: &str) -> Result<String, String> {
    let start = Instant::now();
    let program = load_cl(file).map_err(|e| e.to_string())?;
    plan_and_follow(&program, name, start)
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
