//! A G-code part read as the test describes it: the program text is written from the
//! test's own list of pieces (lines and arcs given by centre, radius and angles), and
//! the reader's geometry, the exact distance to it (`TrueErrorIndex`, any hint) and the
//! constant-feed interpolator on it are checked against the test's own closed forms.

use contour_core::math;
use std::f64::consts::{FRAC_PI_2, PI};

use contour_core::contour::planar::TrueErrorIndex;
use contour_core::geometry::Vector2;
use contour_core::part_program::{Corner, Speed};
use contour_core::path::planar::{Path, Program};
use contour_core::path::{Curve, Interpolator};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

/// |v|, the test's own.
fn size(v: Vector2) -> f64 {
    math::hypot(v[0], v[1])
}

/// A piece of the part as the test knows it.
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line([f64; 2], [f64; 2]),
    /// Centre, radius, start angle, signed sweep (rad).
    Arc([f64; 2], f64, f64, f64),
}

impl Piece {
    fn at(&self, t: f64) -> Vector2 {
        match *self {
            Piece::Line(a, b) => Vector2::new(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])),
            Piece::Arc(c, r, a0, sweep) => {
                let phi = a0 + t * sweep;
                Vector2::new(c[0] + r * math::cos(phi), c[1] + r * math::sin(phi))
            }
        }
    }

    fn length(&self) -> f64 {
        match *self {
            Piece::Line(a, b) => math::hypot(b[0] - a[0], b[1] - a[1]),
            Piece::Arc(_, r, _, sweep) => r * sweep.abs(),
        }
    }

    /// Distance from `p`, with the foot's parameter and the unit tangent there.
    fn nearest(&self, p: Vector2) -> (f64, f64, Vector2) {
        match *self {
            Piece::Line(a, b) => {
                let (a, b) = (Vector2::from(a), Vector2::from(b));
                let d = b - a;
                let t = ((p - a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
                (size(p - (a + d * t)), t, d / size(d))
            }
            Piece::Arc(c, _, a0, sweep) => {
                let q = p - Vector2::from(c);
                // How far round from the start, in the direction of travel.
                let turned = (sweep.signum() * (math::atan2(q[1], q[0]) - a0)).rem_euclid(2.0 * PI);
                let t = if turned <= sweep.abs() {
                    turned / sweep.abs()
                } else if size(p - self.at(0.0)) <= size(p - self.at(1.0)) {
                    0.0
                } else {
                    1.0
                };
                let phi = a0 + t * sweep;
                let tangent = Vector2::new(-math::sin(phi), math::cos(phi)) * sweep.signum();
                (size(p - self.at(t)), t, tangent)
            }
        }
    }
}

/// The part: a closed counter-clockwise contour from (0, 0) with a tangent arc, a
/// corner into a concave arc given by R, a 0.5 mm radius, a quarter given by I and J,
/// and three sharp corners; one exact stop (G61) and one blended corner (G64 P0.01).
fn part() -> (String, Vec<Piece>) {
    let h = FRAC_PI_2;
    let pieces = vec![
        Piece::Line([0.0, 0.0], [30.0, 0.0]),
        Piece::Arc([30.0, 5.0], 5.0, -h, h),
        Piece::Line([35.0, 5.0], [35.0, 20.0]),
        Piece::Arc([35.0, 25.0], 5.0, -h, -h),
        Piece::Line([30.0, 25.0], [10.0, 25.0]),
        Piece::Arc([10.0, 24.5], 0.5, h, h),
        Piece::Line([9.5, 24.5], [9.5, 15.0]),
        Piece::Arc([4.5, 15.0], 5.0, 0.0, -h),
        Piece::Line([4.5, 10.0], [0.0, 10.0]),
        Piece::Line([0.0, 10.0], [0.0, 0.0]),
    ];
    let text = "%\n(part: test)\nG21 G17 G90 G94 G64 P0.01\nG0 X0 Y0\n\
                G1 X30 F1200\nG3 X35 Y5 I0 J5\nG1 Y20\nG2 X30 Y25 R5\n\
                G1 X10 F600\nG3 X9.5 Y24.5 R0.5\nG61\nG1 Y15\nN100 G2 X4.5 Y10 I-5 J0\n\
                G64 G1 X0\nY0\nM30\n%\n"
        .to_string();
    (text, pieces)
}

#[test]
fn the_reader_gives_the_parts_pieces_and_their_modes() {
    let (text, pieces) = part();
    let program = Program::parse_gcode(&text, "part.ngc").unwrap();
    assert!(
        program.warnings.iter().any(|w| w.contains("G94")),
        "{:?}",
        program.warnings
    );
    let moves = program.moves();
    assert_eq!(moves.len(), pieces.len());
    for (m, piece) in moves.iter().zip(&pieces) {
        let curve = m.shape.curve();
        for t in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let off = (curve.point(t) - piece.at(t)).amax();
            assert!(off < 1e-12, "line {}: {off} mm off at {t}", m.line);
        }
        assert!((curve.length() - piece.length()).abs() < 1e-12);
    }
    let total: f64 = pieces.iter().map(Piece::length).sum();
    assert!((program.length() - total).abs() < 1e-11);
    // F1200 and F600 mm/min; the corner modes as programmed.
    assert_eq!(moves[0].speed, Speed::Feed(20.0));
    assert_eq!(moves[4].speed, Speed::Feed(10.0));
    assert_eq!(moves[0].corner, Corner::Blend(0.01));
    assert_eq!(moves[6].corner, Corner::ExactStop);
    assert_eq!(moves[7].line, 13);
    assert_eq!(moves[8].corner, Corner::BlendDefault);
    assert_eq!(moves[9].line, 15);
}

#[test]
fn the_exact_distance_is_the_nearest_piece_whatever_the_hint() {
    let (text, pieces) = part();
    let program = Program::parse_gcode(&text, "part.ngc").unwrap();
    for (path, mirrored) in [
        (Path::Program(program.clone()), false),
        (Path::Program(program.mirrored()), true),
    ] {
        let index = TrueErrorIndex::new(&path);
        let mut rng = StdRng::seed_from_u64(23);
        let flip = |p: Vector2| {
            if mirrored {
                Vector2::new(p[0], -p[1])
            } else {
                p
            }
        };
        let mut signs = 0;
        for k in 0..4000 {
            // Near the contour mostly, some far away.
            let spread = if k % 5 == 0 { 8.0 } else { 0.8 };
            let near = pieces[k % pieces.len()].at(rng.random_range(0.0..1.0));
            let p = near
                + Vector2::new(
                    rng.random_range(-spread..spread),
                    rng.random_range(-spread..spread),
                );
            let (piece, (want, t, tangent)) = pieces
                .iter()
                .map(|q| (q, q.nearest(p)))
                .reduce(|b, c| if c.1 .0 < b.1 .0 { c } else { b })
                .unwrap();
            let q = flip(p);
            for hint in [
                0.0,
                path.length() * rng.random_range(0.0..1.0),
                path.length(),
            ] {
                let got = index.error(q, hint);
                assert!(
                    (got.error.abs() - want).abs() < 1e-9,
                    "{p:?}: {} vs {want}",
                    got.error
                );
                assert!((size(got.foot - q) - want).abs() < 1e-9);
            }
            let brute = contour_core::contour::planar::true_error(&path, q);
            assert!((brute.error.abs() - want).abs() < 1e-9);
            // The sign, where the foot is inside a piece: positive right of travel; the
            // mirror image travels the other way round, so the sign flips.
            if want > 1e-6 && t > 1e-6 && t < 1.0 - 1e-6 {
                let r = p - piece.at(t);
                let right = -(tangent[0] * r[1] - tangent[1] * r[0]);
                let got = index.error(q, 0.0).error;
                let want_sign = if mirrored {
                    -right.signum()
                } else {
                    right.signum()
                };
                assert_eq!(got.signum(), want_sign, "{p:?}");
                signs += 1;
            }
        }
        assert!(signs > 3000, "{signs}");
    }
}

#[test]
fn at_constant_feed_every_sample_is_on_the_part_one_feed_step_apart() {
    let (text, pieces) = part();
    let program = Program::parse_gcode(&text, "part.ngc").unwrap();
    let path = Path::Program(program);
    let index = TrueErrorIndex::new(&path);
    let (feed, ts) = (20.0, 1e-3);
    let mut it = Interpolator::new(path.clone(), feed, ts).unwrap();
    let mut previous = it.current().point;
    let mut samples = 0;
    while !it.step().done {
        let s = it.current();
        let off = index.error(s.point, s.u).error.abs();
        assert!(off < 1e-9, "sample {samples} is {off} mm off the part");
        let chord = size(s.point - previous);
        // A chord across a corner is shorter than the feed step, never longer.
        assert!(
            chord <= feed * ts * (1.0 + 1e-3),
            "sample {samples}: chord {chord}"
        );
        previous = s.point;
        samples += 1;
    }
    let total: f64 = pieces.iter().map(Piece::length).sum();
    // A chord of one feed step across a corner covers more of the path than a step (at
    // most √2 steps at a right angle): the part's 4 sharp corners save up to 2 samples.
    let steps = (total / (feed * ts)).ceil() as i64;
    assert!(
        (steps - 3..=steps).contains(&(samples as i64)),
        "{samples} samples for {steps}"
    );
    assert_eq!(it.current().point, Vector2::zeros());
}

#[test]
fn beyond_a_sharp_corner_the_sign_says_outside() {
    // A counter-clockwise triangle with 120° turns (and the closing vertex at the start):
    // points all round each vertex are positive outside and negative inside, by the
    // test's own half-plane test, whichever move's end is the foot.
    let h = 5.0 * 3f64.sqrt();
    let program =
        Program::parse_gcode("G1 X10 F600\nG1 X5 Y8.660254037844386\nG1 X0 Y0\n", "t.ngc");
    let path = Path::Program(program.unwrap());
    let index = TrueErrorIndex::new(&path);
    let corners = [
        Vector2::new(0.0, 0.0),
        Vector2::new(10.0, 0.0),
        Vector2::new(5.0, h),
    ];
    let inside = |p: Vector2| {
        (0..3).all(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % 3]);
            (b - a)[0] * (p - a)[1] - (b - a)[1] * (p - a)[0] > 0.0
        })
    };
    for corner in corners {
        for k in 0..360 {
            let phi = (k as f64 + 0.5).to_radians();
            let p = corner + Vector2::new(math::cos(phi), math::sin(phi));
            for hint in [0.0, 15.0, 30.0] {
                let e = index.error(p, hint).error;
                let want = if inside(p) { -1.0 } else { 1.0 };
                assert_eq!(e.signum(), want, "{p:?}, hint {hint}: {e}");
            }
            let brute = contour_core::contour::planar::true_error(&path, p).error;
            assert_eq!(brute, index.error(p, 7.0).error, "{p:?}");
        }
    }
}

/// The test's own signed distance from `p` to the nearest of `pieces` (positive right of
/// travel; the sign `None` where the foot is a vertex), its piece, foot and unit tangent.
fn nearest_piece(pieces: &[Piece], p: Vector2) -> (f64, Option<f64>, usize, Vector2, Vector2) {
    let (i, (distance, t, tangent)) = pieces
        .iter()
        .map(|q| q.nearest(p))
        .enumerate()
        .reduce(|b, c| if c.1 .0 < b.1 .0 { c } else { b })
        .unwrap();
    let foot = pieces[i].at(t);
    let r = p - foot;
    let right = -(tangent[0] * r[1] - tangent[1] * r[0]);
    let sign = (t > 1e-9 && t < 1.0 - 1e-9 && distance > 1e-9).then_some(right.signum());
    (distance, sign, i, foot, tangent)
}

#[test]
fn the_program_estimate_is_the_exact_distance_on_every_sample_of_closed_loop_runs() {
    use contour_core::contour::planar::EstimatorKind;
    use contour_core::sim::{SimConfig, Simulator};
    let (text, pieces) = part();
    let program = Program::parse_gcode(&text, "part.ngc").unwrap();
    let mirrored_pieces: Vec<Piece> = pieces
        .iter()
        .map(|p| match *p {
            Piece::Line(a, b) => Piece::Line([a[0], -a[1]], [b[0], -b[1]]),
            Piece::Arc(c, r, a0, sweep) => Piece::Arc([c[0], -c[1]], r, -a0, -sweep),
        })
        .collect();
    // 120° turns: past each corner the reference pulls the tool back along the side it
    // has left.
    let triangle =
        Program::parse_gcode("G1 X10 F600\nG1 X5 Y8.660254037844386\nG1 X0 Y0\n", "t.ngc");
    let h = 8.660254037844386;
    let triangle_pieces = vec![
        Piece::Line([0.0, 0.0], [10.0, 0.0]),
        Piece::Line([10.0, 0.0], [5.0, h]),
        Piece::Line([5.0, h], [0.0, 0.0]),
    ];
    // A slot's end: a half circle of 0.5 mm between two passes 1 mm apart, all joins
    // tangent; at speed the reference comes back behind the tool round it.
    let slot = Program::parse_gcode("G1 X20 F600\nG3 X20 Y1 R0.5\nG1 X0\n", "slot.ngc");
    let slot_pieces = vec![
        Piece::Line([0.0, 0.0], [20.0, 0.0]),
        Piece::Arc([20.0, 0.5], 0.5, -FRAC_PI_2, PI),
        Piece::Line([20.0, 1.0], [0.0, 1.0]),
    ];
    let cases = [
        ("slot end", Path::Program(slot.unwrap()), slot_pieces),
        ("part", Path::Program(program.clone()), pieces),
        (
            "mirrored part",
            Path::Program(program.mirrored()),
            mirrored_pieces,
        ),
        (
            "triangle",
            Path::Program(triangle.unwrap()),
            triangle_pieces,
        ),
    ];
    for (name, path, pieces) in cases {
        for (feed, ccc) in [(20.0, true), (50.0, true), (50.0, false)] {
            let mut config = SimConfig::new(path.clone(), feed);
            config.estimator = EstimatorKind::Program;
            config.settle = 0.3;
            if !ccc {
                config.controller.ccc.mode = contour_core::control::CccMode::Off;
            }
            let run = Simulator::new(config).unwrap().run();
            let trace = &run.trace;
            let (mut signs, mut own, mut peak) = (0, 0, 0.0f64);
            // The reference's piece: the first from the last one on that holds it.
            let mut reference_piece = 0;
            for k in 0..trace.len() {
                let r = trace.reference[k];
                reference_piece = (reference_piece..pieces.len())
                    .find(|&i| pieces[i].nearest(r).0 < 1e-9)
                    .expect("the reference is on the part");
                let (mut want, mut sign, piece, foot, tangent) =
                    nearest_piece(&pieces, trace.actual[k]);
                // The tool the reference pulls back along a piece it has left is
                // measured against the reference's piece.
                if piece < reference_piece && (r - foot).dot(&tangent) < 0.0 {
                    want = pieces[reference_piece].nearest(trace.actual[k]).0;
                    sign = None;
                    own += 1;
                }
                let got = trace.estimated_error[k];
                assert!(
                    (got.abs() - want).abs() < 1e-9,
                    "{name} at {feed} mm/s, sample {k}: {got} vs {want}"
                );
                if let Some(sign) = sign {
                    assert_eq!(got.signum(), sign, "{name}, sample {k}");
                    signs += 1;
                }
                peak = peak.max(want);
            }
            // Straight passes followed exactly have no side: a fifth at least.
            assert!(
                signs > trace.len() / 5,
                "{name}: {signs} of {}",
                trace.len()
            );
            // The corners make real contour error: the comparison is not of zeros.
            assert!(peak > 0.01, "{name} at {feed} mm/s: peak {peak} mm");
            // The triangle's 120° corners always; the slot's end where the lag is longer
            // than its half circle; never the part's.
            match name {
                "triangle" => assert!(own > 0, "{name}"),
                "slot end" => assert!(own > 0 || feed < 50.0, "{name} at {feed}"),
                _ => assert_eq!(own, 0, "{name}"),
            }
        }
    }
}
