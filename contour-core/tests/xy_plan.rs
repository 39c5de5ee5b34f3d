//! The planned XY reference on test programs, checked on its samples by finite
//! differences (docs/design/two-axis.md §4.9): the speed within F, the acceleration and
//! jerk within the limits (within the derived allowance at junctions), zero speed at
//! exact stops, the planned path within the tolerance of the programmed one, start and
//! end at rest; and on single lines the trapezoid's and the S-curve's closed forms.

use contour_core::contour::planar::{true_error, TrueErrorIndex};
use contour_core::geometry::Vector2;
use contour_core::math;
use contour_core::path::planar::{Path, Program, XyLimits, XyReference};

const LIMITS: XyLimits = XyLimits {
    feed: 50.0,
    rapid: 200.0,
    accel: 2000.0,
    jerk: 1e5,
    tolerance: 0.01,
    ts: 1e-3,
};

fn program(text: &str) -> Path {
    Path::Program(Program::parse_gcode(text, "test.ngc").unwrap())
}

/// All samples of a planned reference, from the start to the end.
fn samples(path: &Path, limits: XyLimits) -> (Vec<Vector2>, XyReference) {
    let mut r = XyReference::new(path.clone(), limits).unwrap();
    let mut points = vec![r.current().point];
    while !r.done() {
        points.push(r.step().point);
    }
    // Two samples at rest at the end, for the differences.
    points.push(r.step().point);
    points.push(r.step().point);
    (points, r)
}

fn norm(v: Vector2) -> f64 {
    math::hypot(v[0], v[1])
}

struct Case {
    name: &'static str,
    text: &'static str,
    /// Programmed speeds, mm/s (F words; the feed 50 otherwise).
    fastest: f64,
    /// Path positions (mm, along the programmed path) of the exact stops.
    stops: &'static [[f64; 2]],
}

const CASES: &[Case] = &[
    Case {
        name: "square, exact stops",
        text: "G61\nG1 X20 F3000\nY20\nX0\nY0\n",
        fastest: 50.0,
        stops: &[[20.0, 0.0], [20.0, 20.0], [0.0, 20.0]],
    },
    Case {
        name: "square, blended within 0.05 mm",
        text: "G64 P0.05\nG1 X20 F3000\nY20\nX0\nY0\n",
        fastest: 50.0,
        stops: &[],
    },
    Case {
        name: "part with arcs, a small radius, G61 and G64",
        text: "G21 G90 G64 P0.01\nG1 X30 F2400\nG3 X35 Y5 I0 J5\nG1 Y20\nG2 X30 Y25 R5\n\
               G1 X10 F600\nG3 X9.5 Y24.5 R0.5\nG61\nG1 Y15\nG2 X4.5 Y10 I-5 J0\n\
               G64 G1 X0\nY0\n",
        fastest: 40.0,
        stops: &[[9.5, 15.0], [4.5, 10.0]],
    },
    Case {
        name: "a rapid, then a feed of 10 mm/s",
        text: "G0 X0 Y0\nG1 X5 F600\nG0 X30\nG1 Y10 F600\n",
        fastest: 200.0,
        stops: &[],
    },
];

/// What a planned run is checked against.
struct Expect<'a> {
    name: String,
    /// The programmed speeds, at most.
    fastest: f64,
    /// Points where the geometry may jump in curvature or kink (the jerk allowance).
    junctions: Vec<Vector2>,
    /// Where the motion stops.
    stops: &'a [[f64; 2]],
    /// How far the planned geometry may lie from the programmed path, mm.
    tolerance: f64,
}

/// Every sample of `path` planned within `limits` against `expect` (module docs).
fn check_samples(path: &Path, limits: XyLimits, expect: &Expect) {
    let (p, reference) = samples(path, limits);
    let ts = limits.ts;
    let name = &expect.name;
    // Start and end at rest, at the path's ends.
    assert!(norm(p[0] - path.start_point()) < 1e-12, "{name}");
    // From rest: the first step is at most what the jerk (or the acceleration) covers in
    // one sample.
    let first = if limits.jerk > 0.0 {
        limits.jerk * ts.powi(3) / 6.0
    } else {
        limits.accel * ts * ts / 2.0
    };
    assert!(
        norm(p[1] - p[0]) <= first * (1.0 + 1e-9),
        "{name}: starts moving at once"
    );
    let n = p.len();
    assert!(norm(p[n - 1] - path.end_point()) < 1e-9, "{name}");
    assert!(norm(p[n - 1] - p[n - 3]) < 1e-12, "{name}");
    let geometry = reference.geometry();
    let near_junction =
        |q: Vector2, reach: f64| expect.junctions.iter().any(|&j| norm(q - j) <= reach);
    let index = TrueErrorIndex::new(path);
    let mut max_a = 0.0f64;
    for k in 1..n - 2 {
        let v = norm(p[k + 1] - p[k]) / ts;
        assert!(
            v <= expect.fastest * (1.0 + 1e-9),
            "{name}: {v} mm/s at sample {k}"
        );
        let a = norm(p[k + 1] - p[k] * 2.0 + p[k - 1]) / (ts * ts);
        let j = norm(p[k + 2] - p[k + 1] * 3.0 + p[k] * 3.0 - p[k - 1]) / (ts * ts * ts);
        // The samples' acceleration averages the reference's over ±Ts, so it keeps the
        // limit; their jerk averages the jerk over three samples, where a curvature
        // jump's step v²Δκ ≤ jerk·Ts weighs at most 3/4 (the kernel's peak): up to
        // 1.75·jerk within three samples of a junction.
        let reach = 3.0 * v * ts + 1e-9;
        let j_allowed = if near_junction(p[k], reach) {
            1.75
        } else {
            1.0 + 1e-6
        } * limits.jerk;
        assert!(
            a <= limits.accel * (1.0 + 1e-6),
            "{name}: {a} mm/s² at sample {k} ({:?})",
            p[k]
        );
        if limits.jerk > 0.0 {
            assert!(
                j <= j_allowed,
                "{name}: {j} mm/s³ at sample {k} ({:?})",
                p[k]
            );
        }
        max_a = max_a.max(a);
        // On the planned geometry, within the tolerance of the programmed path.
        assert!(
            true_error(&geometry, p[k]).error.abs() < 1e-9,
            "{name}: off at {k}"
        );
        let off = index.error(p[k], 0.0).error.abs();
        assert!(
            off <= expect.tolerance + 1e-9,
            "{name}: {off} mm from the program at {k}"
        );
    }
    // The limits are used, not just kept.
    assert!(max_a > 0.5 * limits.accel, "{name}: {max_a}");
    // Exact stops: the motion comes to rest there between two samples, so the samples
    // either side are within one sample's motion from rest of it (one passing at v would
    // be v·Ts/2 away).
    for stop in expect.stops {
        let stop = Vector2::from(*stop);
        let at_rest = (1..n - 1).any(|k| {
            norm(p[k] - stop) <= first * (1.0 + 1e-6)
                && norm(p[k + 1] - stop) <= first * (1.0 + 1e-6)
        });
        assert!(at_rest, "{name}: no stop at {stop:?}");
    }
}

/// With and without a jerk limit.
fn both_jerks() -> [XyLimits; 2] {
    [
        LIMITS,
        XyLimits {
            jerk: 0.0,
            ..LIMITS
        },
    ]
}

#[test]
fn every_sample_keeps_the_limits_and_the_tolerance() {
    for limits in both_jerks() {
        for case in CASES {
            let path = program(case.text);
            // The geometry's junctions, where it may jump in curvature or kink.
            let Path::Program(planned) = XyReference::new(path.clone(), limits).unwrap().geometry()
            else {
                panic!("a program is planned as a program")
            };
            let junctions = planned
                .moves()
                .iter()
                .map(|m| m.shape.curve().point(1.0))
                .collect();
            let expect = Expect {
                name: format!("{} (jerk {})", case.name, limits.jerk),
                fastest: case.fastest,
                junctions,
                stops: case.stops,
                tolerance: 0.05,
            };
            check_samples(&path, limits, &expect);
        }
    }
}

#[test]
fn a_line_takes_the_closed_form_time_of_its_limits() {
    for length in [0.001, 0.01, 0.1, 0.5, 1.0, 2.0, 10.0, 100.0] {
        let path = program(&format!("G1 X{length} F3000\n"));
        // Trapezoid (no jerk limit): triangle below 2·v²/2a = 1.25 mm.
        let (v, a, j) = (50.0f64, 2000.0f64, 1e5f64);
        let r = XyReference::new(
            path.clone(),
            XyLimits {
                jerk: 0.0,
                ..LIMITS
            },
        )
        .unwrap();
        let want = if length >= v * v / a {
            length / v + v / a
        } else {
            2.0 * (length / a).sqrt()
        };
        assert!(
            (r.duration() - want).abs() < 1e-9 * want,
            "{length}: {} vs {want}",
            r.duration()
        );
        // S-curve, where both limits are reached: L/v + v/a + a/j.
        let r = XyReference::new(path, LIMITS).unwrap();
        if length >= v * (v / a + a / j) {
            let want = length / v + v / a + a / j;
            assert!(
                (r.duration() - want).abs() < 1e-9 * want,
                "{length}: {}",
                r.duration()
            );
        }
        assert!(r.duration() > 0.0);
    }
}

#[test]
fn the_exact_distance_to_a_blended_program_is_the_dense_samples_nearest() {
    // A blended square, a corner of 150° and two small turns (14° and 2.9°, whose blends
    // the search samples more sparsely): every blend against its own 200 000 samples
    // (chords under 40 nm), the lines by their closed form, for points around every
    // corner.
    use contour_core::path::planar::{blended, Shape};
    let program = Program::parse_gcode(
        "G64 P0.05\nG1 X20 F600\nY20\nX0\nY0\nX-3 Y0.8\nX-13 Y1\nX-23 Y1.2\nX-33 Y1.9\n",
        "b.ngc",
    )
    .unwrap();
    let geometry = blended(&program, 0.0);
    let path = Path::Program(geometry.clone());
    let index = TrueErrorIndex::new(&path);
    let blends: Vec<Vec<Vector2>> = geometry
        .moves()
        .iter()
        .filter(|m| matches!(m.shape, Shape::Blend(_)))
        .map(|m| {
            (0..=200_000)
                .map(|k| m.shape.curve().point(k as f64 / 200_000.0))
                .collect()
        })
        .collect();
    assert_eq!(blends.len(), 6);
    let lines: Vec<(Vector2, Vector2)> = geometry
        .moves()
        .iter()
        .filter_map(|m| match &m.shape {
            Shape::Line(l) => Some((l.start(), l.end())),
            _ => None,
        })
        .collect();
    let segment = |p: Vector2, (a, b): (Vector2, Vector2)| {
        let d = b - a;
        let t = ((p - a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
        norm(p - (a + d * t))
    };
    let mut compared = 0;
    for blend in &blends {
        let middle = blend[100_000];
        for k in 0..100 {
            let phi = k as f64 * 0.2;
            let radius = 0.001 + 0.0005 * (k % 37) as f64;
            let p = middle + Vector2::new(math::cos(phi), math::sin(phi)) * radius;
            let sampled = blends
                .iter()
                .flat_map(|b| b.iter().map(|&q| norm(p - q)))
                .chain(lines.iter().map(|&l| segment(p, l)))
                .fold(f64::INFINITY, f64::min);
            let got = index.error(p, 0.0).error.abs();
            // The samples' nearest is farther than the curve's by at most
            // (1 + κd)·(h/2)²/(2d) with h the chord (κd < 1 here): never nearer.
            let h = blends.iter().map(|b| norm(b[1] - b[0])).fold(0.0, f64::max);
            let slack = h * h / (4.0 * got.max(1e-9)) + 1e-12;
            assert!(
                got <= sampled + 1e-12 && sampled - got <= slack,
                "{p:?}: {got} vs {sampled}"
            );
            // A search started from a guessed place (Newton from it on a blend whose
            // distance is convex) finds the same, from any guess and hint.
            let length = geometry.start_of(geometry.moves().len());
            for (hint, guess) in [(0, length * 0.37), (k % 13, 0.0), (k % 7, length)] {
                let (_, e) = index.error_between(p, hint, guess, f64::NEG_INFINITY, f64::INFINITY);
                assert!(
                    (e.error.abs() - got).abs() < 1e-12,
                    "{p:?} from {guess}: {} vs {got}",
                    e.error
                );
            }
            compared += 1;
        }
    }
    assert_eq!(compared, 600);
}

#[test]
fn a_nurbs_is_planned_on_itself_within_the_limits() {
    use contour_core::path::planar::builtin;
    use contour_core::path::{clamped_uniform_knots, Curve, Nurbs};
    let knots_inside = |n: &Nurbs| -> Vec<Vector2> {
        let (a, b) = n.param_range();
        n.knots()
            .iter()
            .filter(|&&u| u > a && u < b)
            .map(|&u| n.point(u))
            .collect()
    };
    // A 20 mm square as a degree-1 NURBS (issue 23's square): stops at its corners.
    let square = Nurbs::new(
        1,
        clamped_uniform_knots(5, 1),
        vec![
            [0.0, 0.0],
            [20.0, 0.0],
            [20.0, 20.0],
            [0.0, 20.0],
            [0.0, 0.0],
        ],
        None,
    )
    .unwrap();
    // A quadratic B-spline: tangent-continuous, its curvature jumps at every knot.
    let wave = Nurbs::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0, 4.0],
        vec![
            [0.0, 0.0],
            [10.0, 8.0],
            [20.0, -8.0],
            [30.0, 8.0],
            [40.0, -8.0],
            [50.0, 0.0],
        ],
        None,
    )
    .unwrap();
    // The exact rational circle, 10 mm radius: curvature 0.1 everywhere.
    let unit = builtin::rational_unit_circle();
    let circle = Nurbs::new(
        2,
        unit.knots().to_vec(),
        unit.control_points().iter().map(|p| p * 10.0).collect(),
        Some(unit.weights().to_vec()),
    )
    .unwrap();
    let cases: [(&str, Nurbs, &[[f64; 2]]); 5] = [
        ("infinity", builtin::infinity(), &[]),
        ("trident", builtin::trident(), &[]),
        (
            "square NURBS",
            square,
            &[[20.0, 0.0], [20.0, 20.0], [0.0, 20.0]],
        ),
        ("quadratic wave", wave, &[]),
        ("rational circle", circle, &[]),
    ];
    for limits in both_jerks() {
        for (name, nurbs, stops) in &cases {
            let expect = Expect {
                name: format!("{name} (jerk {})", limits.jerk),
                fastest: limits.feed,
                junctions: knots_inside(nurbs),
                stops,
                tolerance: 0.0,
            };
            check_samples(&Path::Nurbs(nurbs.clone()), limits, &expect);
        }
    }
    // The mirror image runs the mirrored samples exactly.
    let path = Path::Nurbs(builtin::trident());
    let (p, _) = samples(&path, LIMITS);
    let (q, _) = samples(&path.mirrored(), LIMITS);
    assert_eq!(p.len(), q.len());
    assert!(p.iter().zip(&q).all(|(a, b)| a[0] == b[0] && a[1] == -b[1]));
}
