//! Three-axis G-code on the five-axis machine, its tool axis vertical: programs written
//! here as CAM posts write them (a thread-milling helix as Fusion 360's post writes it,
//! ramps, G18 and G19 arcs, a drilling cycle, G28 and G43, a profile under G41), each
//! planned as PathInterpolator5X plans it and judged against the test's own geometry:
//! every sample within the plan's tolerance of the programmed path (plus the chords' sag
//! an arc becomes), no faster than the feed of the move it is on, the joints within
//! their limits, and the duration no shorter than every move at its feed.

mod support;

use std::f64::consts::TAU;

use contour_core::geometry::Vector;
use contour_core::kinematics::Pose;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::math;
use contour_core::part_program::cutter_compensation::ToolTable;
use contour_core::part_program::gcode::{parse_gcode, GcodeOptions};
use contour_core::path::five_axis::{machine_moves, GCODE_ARC_SAG};
use support::*;

type V3 = Vector<3>;

/// The sag of the chords the test's own arcs become, mm.
const TEST_SAG: f64 = 1e-7;

/// A program written block by block with the pieces of its path, as the test reads it.
struct Writer {
    text: String,
    at: Option<V3>,
    pieces: Vec<Piece>,
}

/// The indices (X 0, Y 1, Z 2) of an arc's first and second axes and the axis it climbs
/// along: G17 X, Y (Z), G18 Z, X (Y), G19 Y, Z (X).
fn plane_axes(code: &str) -> [usize; 3] {
    match code {
        "G17" => [0, 1, 2],
        "G18" => [2, 0, 1],
        "G19" => [1, 2, 0],
        _ => unreachable!(),
    }
}

fn vertical(tip: V3) -> Pose {
    Pose { tip, axis: V3::z() }
}

impl Writer {
    fn new(header: &str) -> Self {
        Writer {
            text: header.to_string(),
            at: None,
            pieces: Vec::new(),
        }
    }

    fn block(&mut self, text: &str) {
        self.text += text;
        self.text.push('\n');
    }

    /// A straight piece to `to` at `speed` mm/s (the first one only places the tool).
    fn piece(&mut self, to: V3, speed: f64) {
        if let Some(from) = self.at {
            if from != to {
                self.pieces.push(Piece {
                    from: vertical(from),
                    to: vertical(to),
                    feed: speed,
                });
            }
        }
        self.at = Some(to);
    }

    /// `code` (G0 or G1 with its feed words) to `to`, all three axes written.
    fn straight(&mut self, code: &str, to: V3, speed: f64) {
        self.block(&format!("{code} X{:.4} Y{:.4} Z{:.4}", to[0], to[1], to[2]));
        self.piece(to, speed);
    }

    /// An arc (G2 when `clockwise`) in `plane` about `centre` (its climbing coordinate
    /// unused) to `to` at `speed`, turning `turns` extra full turns first: the test's
    /// own helix as chords of sag `TEST_SAG`.
    fn arc(&mut self, plane: &str, clockwise: bool, centre: V3, to: V3, speed: f64) {
        let [u, v, w] = plane_axes(plane);
        let from = self.at.unwrap();
        let letters = ['X', 'Y', 'Z'];
        let offsets = ['I', 'J', 'K'];
        self.block(&format!(
            "{plane} {} {}{:.4} {}{:.4} {}{:.4} {}{:.4} {}{:.4}",
            if clockwise { "G2" } else { "G3" },
            letters[u],
            to[u],
            letters[v],
            to[v],
            letters[w],
            to[w],
            offsets[u],
            centre[u] - from[u],
            offsets[v],
            centre[v] - from[v],
        ));
        let angle = |p: V3| math::atan2(p[v] - centre[v], p[u] - centre[u]);
        let r = math::hypot(from[u] - centre[u], from[v] - centre[v]);
        let mut sweep = (angle(to) - angle(from)).rem_euclid(TAU);
        if clockwise {
            sweep = (TAU - sweep).rem_euclid(TAU);
        }
        if sweep < 1e-12 {
            sweep = TAU;
        }
        let chords = (sweep / (2.0 * math::acos(1.0 - TEST_SAG / r))).ceil() as usize;
        let sign = if clockwise { -1.0 } else { 1.0 };
        for k in 1..=chords {
            let t = k as f64 / chords as f64;
            let a = angle(from) + sign * sweep * t;
            let mut p = V3::zeros();
            p[u] = centre[u] + r * math::cos(a);
            p[v] = centre[v] + r * math::sin(a);
            p[w] = from[w] + (to[w] - from[w]) * t;
            self.piece(if k == chords { to } else { p }, speed);
        }
    }
}

/// `text` read, planned at the interpolator's defaults and followed against `pieces`:
/// within the tolerances, the speeds, the limits and the time bound; the table's row.
fn judge(name: &str, text: &str, pieces: &[Piece], options: &GcodeOptions) -> String {
    let start = std::time::Instant::now();
    let programmed = parse_gcode(text, name, options).unwrap_or_else(|e| panic!("{e}"));
    let program = machine_moves(&programmed).unwrap_or_else(|e| panic!("{e}"));
    let limits = PathLimits::at_feed(FEED);
    let mut reference = planned(&program, name, limits).unwrap_or_else(|e| panic!("{e}"));
    let seconds = start.elapsed().as_secs_f64();
    let followed = follow(pieces, &mut reference);
    let allowed = limits.tolerance + GCODE_ARC_SAG + TEST_SAG;
    assert!(followed.tip <= allowed, "{name}: tip {} mm", followed.tip);
    assert!(followed.axis < 1e-9, "{name}: axis {} rad", followed.axis);
    let peaks = joints_within(&followed.samples, &JointLimits::default());
    let fastest = speeds_within(&followed.samples, pieces);
    let (duration, lower) = duration_within(&reference, pieces, name);
    // The program's feeds, not the `feed` parameter: every feed of a long enough
    // stretch is reached.
    let top = fastest.values().copied().fold(0.0, f64::max);
    assert!(top > 0.0, "{name}: {fastest:?}");
    format!(
        "| {name} | {} poses | {seconds:.2} s | {duration:.1} s (≥ {lower:.1} s) | {:.2e} mm | \
         {peaks:?} |",
        program.poses().len(),
        followed.tip,
    )
}

/// A Fusion 360-style thread-milling operation (its post's header and preamble, G28 G91
/// Z0, G43 H, a lead-in half circle, four helical turns of pitch 1.75 mm, a lead-out).
fn thread_milling() -> Writer {
    let mut w = Writer::new(
        "%\nO1001 (THREAD M12X1.75)\n(T1 D=6. CR=0. - ZMIN=-10. - THREAD MILL)\nN10 G90 G94 G17\n\
         N15 G21\nN20 G28 G91 Z0.\nN25 G90\nN30 T1 M6\nN35 S5000 M3\nN40 G54\n",
    );
    // The rapids before the first cut only position the tool: the path starts at Z5.
    let feed = 300.0 / 60.0;
    w.block("G0 X20. Y20.\nG43 Z15. H1\nG0 Z5.");
    w.at = Some(V3::new(20.0, 20.0, 5.0));
    w.straight("G1 F300.", V3::new(20.0, 20.0, -10.0), feed);
    w.straight("G1", V3::new(21.5, 20.0, -10.0), feed);
    w.arc(
        "G17",
        false,
        V3::new(22.25, 20.0, 0.0),
        V3::new(23.0, 20.0, -10.0),
        feed,
    );
    for turn in 1..=4 {
        let z = -10.0 + 1.75 * turn as f64;
        w.arc(
            "G17",
            false,
            V3::new(20.0, 20.0, 0.0),
            V3::new(23.0, 20.0, z),
            feed,
        );
    }
    w.arc(
        "G17",
        false,
        V3::new(22.25, 20.0, 0.0),
        V3::new(21.5, 20.0, -3.0),
        feed,
    );
    w.straight("G1", V3::new(20.0, 20.0, -3.0), feed);
    w.straight("G0", V3::new(20.0, 20.0, 15.0), RAPID);
    w
}

/// Ramps, vertical arcs in G18 and G19 as lead-ins write them, and a drilling cycle.
fn ramps_vertical_arcs_and_a_cycle() -> Writer {
    let mut w = Writer::new("G21 G90 G17\n");
    let feed = 600.0 / 60.0;
    w.straight("G0", V3::new(0.0, 0.0, 5.0), RAPID);
    w.straight("G1 F600", V3::new(0.0, 0.0, 0.0), feed);
    w.straight("G1", V3::new(20.0, 0.0, -1.0), feed);
    w.straight("G1", V3::new(0.0, 0.0, -2.0), feed);
    w.straight("G1", V3::new(30.0, 0.0, -2.0), feed);
    // Down a quarter circle in XZ, along Y, up a quarter circle in YZ.
    w.arc(
        "G18",
        true,
        V3::new(30.0, 0.0, -12.0),
        V3::new(40.0, 0.0, -12.0),
        feed,
    );
    w.straight("G17 G1", V3::new(40.0, 20.0, -12.0), feed);
    w.arc(
        "G19",
        false,
        V3::new(40.0, 20.0, -2.0),
        V3::new(40.0, 30.0, -2.0),
        feed,
    );
    // A G18 helix: a half turn about Y while Y moves 5 mm.
    w.arc(
        "G18",
        false,
        V3::new(35.0, 0.0, -2.0),
        V3::new(30.0, 35.0, -2.0),
        feed,
    );
    w.straight("G17 G0", V3::new(30.0, 35.0, 5.0), RAPID);
    // G81 at two holes, R 1, Z −5, retracting to where Z was (G98).
    let drill = 200.0 / 60.0;
    w.block("G98 G81 X10 Y10 Z-5 R1 F200");
    for (k, (x, y)) in [(10.0, 10.0), (20.0, 10.0)].into_iter().enumerate() {
        if k == 1 {
            w.block("X20 Y10");
        }
        w.piece(V3::new(x, y, 5.0), RAPID);
        w.piece(V3::new(x, y, 1.0), RAPID);
        w.piece(V3::new(x, y, -5.0), drill);
        w.piece(V3::new(x, y, 5.0), RAPID);
    }
    w.block("G80");
    w.straight("G0", V3::new(0.0, 0.0, 20.0), RAPID);
    w.block("M30");
    w
}

#[test]
fn three_axis_programs_are_planned_on_their_path_within_their_feeds_and_the_limits() {
    println!("| program | poses | planning | duration | tip | peak joint speeds (X Y Z A C) |");
    for (name, writer) in [
        ("thread_milling.nc", thread_milling()),
        ("ramps_arcs_cycle.ngc", ramps_vertical_arcs_and_a_cycle()),
    ] {
        let row = judge(name, &writer.text, &writer.pieces, &GcodeOptions::default());
        println!("{row}");
    }
}

#[test]
fn a_compensated_profile_is_planned_on_the_tool_centre_path() {
    // A 30 × 20 rectangle with a rounded corner at Z −2, G41 (the tool inside it going
    // counter-clockwise, r 3): the tool centre runs the rectangle 3 mm inside, the
    // rounded corner on r 7, from the entry's end to the exit.
    let text = "G21 G90 G17\nG0 X15 Y10 Z5\nG1 Z-2 F300\nG41 D1 G1 X15 Y0\nG1 X30\nG1 Y10\n\
                G3 X20 Y20 I-10 J0\nG1 X0\nG1 Y0\nG1 X15\nG40 G1 X15 Y10\nG0 Z5\nM2\n";
    let options = GcodeOptions {
        tools: ToolTable::parse("1:3").unwrap(),
        ..GcodeOptions::default()
    };
    let mut w = Writer::new("");
    let feed = 5.0;
    w.at = Some(V3::new(15.0, 10.0, 5.0));
    w.piece(V3::new(15.0, 10.0, -2.0), feed);
    // The entry from (15, 10) toward (15, 0) would end 3 mm left of its direction, at
    // (18, 0); the corner with the bottom side is concave, so it ends where it meets
    // that side's offset y = 3: at (17.1, 3). Every corner of the rectangle is concave
    // (the offsets meet 3 mm in), the rounded one is followed on r 7, the last side ends
    // at its offset end (15, 3) and the exit goes back to (15, 10).
    w.piece(V3::new(17.1, 3.0, -2.0), feed);
    w.piece(V3::new(27.0, 3.0, -2.0), feed);
    w.piece(V3::new(27.0, 10.0, -2.0), feed);
    w.arc(
        "G17",
        false,
        V3::new(20.0, 10.0, 0.0),
        V3::new(20.0, 17.0, -2.0),
        feed,
    );
    w.piece(V3::new(3.0, 17.0, -2.0), feed);
    w.piece(V3::new(3.0, 3.0, -2.0), feed);
    w.piece(V3::new(15.0, 3.0, -2.0), feed);
    w.piece(V3::new(15.0, 10.0, -2.0), feed);
    w.piece(V3::new(15.0, 10.0, 5.0), RAPID);
    let row = judge("profile_g41.ngc", text, &w.pieces, &options);
    println!("{row}");
}

/// The tool tables the public programs' D words name (radii in mm; LinuxCNC's sample
/// tool table for its programs: tool 1 of 0.125 in diameter).
const SURVEY_TOOLS: &str = "1:1.5875, 3:1.5, 8:1.5875";

/// The public G-code programs of `tests/data/three_axis` (their sources and licences in its
/// README), each read with its dialect ("fanuc" in its name) and `SURVEY_TOOLS`, made the
/// five-axis machine's moves and planned as PathInterpolator5X plans them, every sample
/// within the tolerances of the reader's poses, the joints within their limits; the
/// issue's table printed (`--nocapture`). `GCODE_FILES=dir` surveys another folder: a
/// file refused there is a row of the table with its reason, not a failure.
#[test]
fn public_gcode_programs_are_read_and_planned_on_five_axes() {
    use contour_core::part_program::gcode::{load_gcode, Dialect};
    use contour_core::part_program::{file_kind, FileKind};
    // The files of tests/data/three_axis the reader refuses, and why (its README).
    let refused = [("3dtest.ngc", "3dtest.ngc:6:25: G-code syntax")];
    let gcode = |p: &std::path::Path| file_kind(p) == Some(FileKind::GCode);
    survey(
        "GCODE_FILES",
        "three_axis",
        gcode,
        &refused,
        |file, name| {
            let options = GcodeOptions {
                dialect: if name.to_lowercase().contains("fanuc") {
                    Dialect::Fanuc
                } else {
                    Dialect::LinuxCnc
                },
                tools: ToolTable::parse(SURVEY_TOOLS).unwrap(),
                ..GcodeOptions::default()
            };
            let start = std::time::Instant::now();
            load_gcode(file, &options)
                .and_then(|p| machine_moves(&p))
                .map_err(|e| e.to_string())
                .and_then(|program| plan_and_follow(&program, name, start))
        },
    );
}

#[test]
fn a_drilling_cycle_reaches_the_bottom_of_every_hole() {
    // A plunge and its retract turn back on the spot: the distance to the path cannot
    // see a hole cut short, so the plan checks the reach of such corners (docs/design
    // five-axis.md §5.3d). G81 and G83 (pecks of 2 mm, each turning back) at F200.
    let text = "G21 G90 G17\nG0 X0 Y0 Z10\nG1 Z5 F600\nG98 G81 X10 Y10 Z-5 R1 F200\nX20\n\
                G83 X30 Z-6 Q2\nG80\nG0 X0 Y0 Z20\nM30\n";
    let program =
        machine_moves(&parse_gcode(text, "holes.ngc", &GcodeOptions::default()).unwrap()).unwrap();
    let limits = PathLimits::at_feed(FEED);
    let mut reference = planned(&program, "holes.ngc", limits).unwrap();
    let pieces = pieces_of(&program);
    let followed = follow(&pieces, &mut reference);
    assert!(
        followed.tip <= limits.tolerance * (1.0 + 1e-6),
        "{}",
        followed.tip
    );
    // Every bottom the test knows: each hole's depth, and each peck's.
    let mut bottoms = vec![V3::new(10.0, 10.0, -5.0), V3::new(20.0, 10.0, -5.0)];
    bottoms.extend([-1.0, -3.0, -5.0, -6.0].map(|z| V3::new(30.0, 10.0, z)));
    for bottom in bottoms {
        let nearest = followed
            .samples
            .iter()
            .map(|(pose, _, _)| contour_core::geometry::dist(&pose.tip, &bottom))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest <= limits.tolerance * (1.0 + 1e-6),
            "{bottom:?}: the nearest sample is {nearest} mm away"
        );
    }
}
