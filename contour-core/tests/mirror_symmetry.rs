//! The controller does not care about the direction of travel: a path and its mirror
//! image about the x axis give mirrored runs. Sample by sample, the mirrored run's signed
//! contour errors (true and estimated) are the negatives of the original's, its actual
//! points are the mirror images, its CCC gains are the same; to 1e-12 mm, on every
//! built-in path, on the paper's and the mismatched plant, with the CCC off, fixed, fuzzy
//! with the paper's factors and fuzzy with a large-kp factor set.
//!
//! The mirror images are built here from the definition (NURBS control points (x, −y);
//! arc centre (cx, −cy), start −a0, sweep −s; line end points (x, −y)), independently of
//! `Path::mirrored`, which is checked against them.

use contour_core::control::{CccMode, FuzzyFactors};
use contour_core::path::planar::{builtin, Move, Path, Program, Shape};
use contour_core::path::{CircularArc, Line, Nurbs};
use contour_core::plant::XyTableParams;
use contour_core::sim::{simulate, SimConfig};

const TOLERANCE_MM: f64 = 1e-12;

fn mirror_by_definition(path: &Path) -> Path {
    match path {
        Path::Line(l) => {
            let (a, b) = (l.start(), l.end());
            Path::Line(Line::new([a[0], -a[1]], [b[0], -b[1]]).unwrap())
        }
        Path::Arc(a) => {
            let c = a.center();
            Path::Arc(
                CircularArc::new([c[0], -c[1]], a.radius(), -a.start_angle(), -a.sweep()).unwrap(),
            )
        }
        Path::Nurbs(n) => {
            let points = n.control_points().iter().map(|p| [p[0], -p[1]]).collect();
            Path::Nurbs(
                Nurbs::new(
                    n.degree(),
                    n.knots().to_vec(),
                    points,
                    Some(n.weights().to_vec()),
                )
                .unwrap(),
            )
        }
        Path::Program(p) => {
            let moves = p.moves().iter().map(|m| {
                let shape = match &m.shape {
                    Shape::Line(l) => match mirror_by_definition(&Path::Line(l.clone())) {
                        Path::Line(l) => Shape::Line(l),
                        _ => unreachable!(),
                    },
                    Shape::Arc(a) => match mirror_by_definition(&Path::Arc(a.clone())) {
                        Path::Arc(a) => Shape::Arc(a),
                        _ => unreachable!(),
                    },
                    Shape::Blend(_) => unreachable!("a program read from G-code has no blends"),
                };
                Move { shape, ..m.clone() }
            });
            Path::Program(Program::new(moves.collect()).unwrap())
        }
    }
}

/// A part with corners, a tangent arc, a 1 mm radius and a clockwise arc.
const PART: &str =
    "G1 X10 F600\nG3 X15 Y5 R5\nG1 Y8\nG2 X17 Y10 I2 J0\nG1 X18\nG3 X18 Y12 R1\nG1 X0 Y12\nG1 Y0\n";

/// A tuned-looking set that leans hard on the fuzzy Kp increment, where an asymmetric
/// schedule shows most (the defect this test guards against was worst there).
const LARGE_KP: FuzzyFactors = FuzzyFactors {
    ke: 3.0,
    kde: 0.5,
    kpf: 900.0,
    kif: 0.0,
    kdf: 5.0,
};

#[test]
fn path_mirrored_matches_the_definition() {
    for name in builtin::NAMES {
        let path = builtin::by_name(name).unwrap();
        assert_eq!(path.mirrored(), mirror_by_definition(&path), "{name}");
        assert_eq!(path.mirrored().mirrored(), path, "{name}");
    }
}

#[test]
fn mirrored_paths_give_mirrored_runs() {
    let modes: [(&str, CccMode, FuzzyFactors); 4] = [
        ("off", CccMode::Off, FuzzyFactors::PAPER),
        ("fixed", CccMode::Fixed, FuzzyFactors::PAPER),
        ("fuzzy paper", CccMode::Fuzzy, FuzzyFactors::PAPER),
        ("fuzzy large kp", CccMode::Fuzzy, LARGE_KP),
    ];
    let plants = [
        ("paper", XyTableParams::PAPER),
        ("mismatched", XyTableParams::mismatched()),
    ];
    let mut compared = 0usize;
    for name in builtin::NAMES {
        for (plant_name, plant) in plants {
            for (mode_name, mode, factors) in modes {
                let config = |path: Path| {
                    let mut c = SimConfig::builtin(name).unwrap().with_plant(plant);
                    c.path = path;
                    c.controller.ccc.mode = mode;
                    c.controller.ccc.fuzzy = factors;
                    c
                };
                let path = builtin::by_name(name).unwrap();
                let mirror = mirror_by_definition(&path);
                let case = format!("{name}, {plant_name} plant, CCC {mode_name}");
                assert_mirrored_runs(&case, config(path), config(mirror));
                compared += 1;
            }
        }
    }
    assert_eq!(compared, builtin::NAMES.len() * 2 * 4);
}

#[test]
fn a_part_program_and_its_mirror_give_mirrored_runs() {
    let part = Path::Program(Program::parse_gcode(PART, "part.ngc").unwrap());
    assert_eq!(part.mirrored(), mirror_by_definition(&part));
    assert_eq!(part.mirrored().mirrored(), part);
    for (mode_name, mode) in [("off", CccMode::Off), ("fuzzy", CccMode::Fuzzy)] {
        let config = |path: Path| {
            let mut c = SimConfig::builtin("circle").unwrap();
            c.path = path;
            c.controller.ccc.mode = mode;
            c
        };
        let mirror = mirror_by_definition(&part);
        assert_mirrored_runs(
            &format!("part, CCC {mode_name}"),
            config(part.clone()),
            config(mirror),
        );
    }
}

/// Runs both configurations and checks the second is the mirror image of the first.
fn assert_mirrored_runs(case: &str, original: SimConfig, mirrored: SimConfig) {
    let a = simulate(original).unwrap();
    let b = simulate(mirrored).unwrap();
    assert!(a.metrics.is_stable(), "{case}: {:?}", a.metrics);
    assert_eq!(a.trace.len(), b.trace.len(), "{case}");
    let (ta, tb) = (&a.trace, &b.trace);
    for k in 0..ta.len() {
        let deviations = [
            ta.true_error[k] + tb.true_error[k],
            ta.estimated_error[k] + tb.estimated_error[k],
            ta.actual[k][0] - tb.actual[k][0],
            ta.actual[k][1] + tb.actual[k][1],
            ta.reference[k][0] - tb.reference[k][0],
            ta.reference[k][1] + tb.reference[k][1],
        ];
        for d in deviations {
            assert!(
                d.abs() <= TOLERANCE_MM,
                "{case}: sample {k} deviates by {d:e} mm: {:?} vs {:?}",
                (ta.true_error[k], ta.estimated_error[k], ta.actual[k]),
                (tb.true_error[k], tb.estimated_error[k], tb.actual[k]),
            );
        }
        for j in 0..3 {
            let (ga, gb) = (ta.gains[k][j], tb.gains[k][j]);
            assert!(
                (ga - gb).abs() <= 1e-9 * ga.abs().max(1.0),
                "{case}: sample {k} gain {j}: {ga} vs {gb}"
            );
        }
    }
    let peak = ta.true_error.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    eprintln!("{case}: peak |true contour error| {:.4} um", peak * 1e3);
}
