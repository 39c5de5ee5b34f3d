//! Programs written in the styles of CAM posts (FreeCAD's LinuxCNC post, Inventor HSM's
//! Fanuc post, CamBam), from the test's own profile: arcs rounded to the post's decimals
//! at radii down to 0.14 mm, the words each post writes (K0, G4, M0/M1, O numbers, G43 H,
//! G28 G91 Z0, drilling cycles with G98/G99), planned on the XY table. Checked against
//! the test's own geometry and arithmetic: every sample within the blend tolerance (plus
//! the post's rounding) of the exact profile, no sample faster than the F in force, and
//! the table standing at every dwell and hole for the time the test computes. Then the
//! public CAM programs of `tests/data/cam` (sources in its README) are read and planned.

use std::f64::consts::PI;

use contour_core::geometry::Vector2;
use contour_core::math;
use contour_core::part_program::gcode::{Dialect, GcodeOptions};
use contour_core::part_program::Speed;
use contour_core::path::planar::{Path, Program, XyLimits, XyReference};
use contour_core::path::Curve;

const LIMITS: XyLimits = XyLimits {
    feed: 20.0,
    rapid: 100.0,
    accel: 2000.0,
    jerk: 5e4,
    tolerance: 0.01,
    ts: 1e-3,
};

/// |v|, the test's own.
fn size(v: Vector2) -> f64 {
    math::hypot(v[0], v[1])
}

/// A piece of the exact profile: a line, or an arc (centre, radius, start angle, sweep).
#[derive(Clone, Copy, Debug)]
enum Piece {
    Line(Vector2, Vector2),
    Arc(Vector2, f64, f64, f64),
}

impl Piece {
    fn end(&self) -> Vector2 {
        match *self {
            Piece::Line(_, b) => b,
            Piece::Arc(c, r, a0, sweep) => {
                c + Vector2::new(math::cos(a0 + sweep), math::sin(a0 + sweep)) * r
            }
        }
    }

    fn distance(&self, p: Vector2) -> f64 {
        match *self {
            Piece::Line(a, b) => {
                let d = b - a;
                let t = ((p - a).dot(&d) / d.dot(&d)).clamp(0.0, 1.0);
                size(p - (a + d * t))
            }
            Piece::Arc(c, r, a0, sweep) => {
                let q = p - c;
                let turned = (sweep.signum() * (math::atan2(q[1], q[0]) - a0)).rem_euclid(2.0 * PI);
                if turned <= sweep.abs() {
                    (size(q) - r).abs()
                } else {
                    let start = c + Vector2::new(math::cos(a0), math::sin(a0)) * r;
                    size(p - start).min(size(p - self.end()))
                }
            }
        }
    }
}

/// A closed profile from (0, 0): a rectangle 40 × 25 mm with fillets of 3, 0.5 and 0.14
/// mm, a 0.3 mm notch arc and one sharp corner, counter-clockwise.
fn profile() -> Vec<Piece> {
    let v = Vector2::new;
    let h = PI / 2.0;
    let mut pieces = Vec::new();
    let mut at = v(0.0, 0.0);
    let line = |pieces: &mut Vec<Piece>, at: &mut Vector2, to: Vector2| {
        pieces.push(Piece::Line(*at, to));
        *at = to;
    };
    line(&mut pieces, &mut at, v(37.0, 0.0));
    pieces.push(Piece::Arc(v(37.0, 3.0), 3.0, -h, h));
    at = v(40.0, 3.0);
    line(&mut pieces, &mut at, v(40.0, 24.5));
    pieces.push(Piece::Arc(v(39.5, 24.5), 0.5, 0.0, h));
    at = v(39.5, 25.0);
    line(&mut pieces, &mut at, v(20.3, 25.0));
    // A notch: half a circle of 0.3 mm into the part (clockwise).
    pieces.push(Piece::Arc(v(20.0, 25.0), 0.3, 0.0, -PI));
    at = v(19.7, 25.0);
    line(&mut pieces, &mut at, v(0.14, 25.0));
    pieces.push(Piece::Arc(v(0.14, 24.86), 0.14, h, h));
    at = v(0.0, 24.86);
    line(&mut pieces, &mut at, v(0.0, 0.0));
    pieces
}

/// The profile's moves as a post writes them: `digits` decimals, I J incremental (with
/// K0 when `k0`), `arc_z` repeating the cutting height on arcs (FreeCAD).
fn profile_moves(digits: usize, k0: bool, arc_z: Option<&str>) -> String {
    let f = |x: f64| format!("{x:.digits$}");
    let mut text = String::new();
    let mut at = Vector2::zeros();
    for piece in profile() {
        let end = piece.end();
        match piece {
            Piece::Line(..) => text += &format!("G1 X{} Y{}\n", f(end[0]), f(end[1])),
            Piece::Arc(c, _, _, sweep) => {
                let g = if sweep > 0.0 { "G3" } else { "G2" };
                text += &format!("{g} X{} Y{}", f(end[0]), f(end[1]));
                if let Some(z) = arc_z {
                    text += &format!(" Z{z}");
                }
                text += &format!(" I{} J{}", f(c[0] - at[0]), f(c[1] - at[1]));
                if k0 {
                    text += &format!(" K{}", f(0.0));
                }
                text += "\n";
            }
        }
        at = end;
    }
    text
}

/// What the test expects the table to do somewhere: stand at `point` for `seconds`.
struct Stand {
    point: Vector2,
    seconds: f64,
}

/// Samples the plan of `program`: every sample within `within` mm of the profile (or of
/// the straight moves in `extra`), no faster than the F in force; returns the time the
/// reference stood at each of `stands` (speed 0 there).
fn run(program: &Program, extra: &[Piece], within: f64, stands: &[Stand]) -> Vec<f64> {
    let mut reference = XyReference::new(Path::Program(program.clone()), LIMITS).unwrap();
    let pieces: Vec<Piece> = profile().into_iter().chain(extra.iter().copied()).collect();
    let geometry = match reference.geometry() {
        Path::Program(p) => p,
        other => panic!("{other:?}"),
    };
    let speed_of = |speed: Speed| match speed {
        Speed::Feed(f) => f,
        Speed::Default => LIMITS.feed,
        Speed::Rapid => LIMITS.rapid,
    };
    let mut stood = vec![0.0; stands.len()];
    let mut worst = 0.0f64;
    loop {
        let sample = reference.current();
        let off = pieces
            .iter()
            .map(|p| p.distance(sample.point))
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(off);
        let allowed = speed_of(geometry.moves()[geometry.move_at(sample.s)].speed);
        assert!(
            sample.speed <= allowed * (1.0 + 1e-9),
            "{} > {allowed}",
            sample.speed
        );
        if sample.speed == 0.0 {
            for (k, stand) in stands.iter().enumerate() {
                if size(sample.point - stand.point) < 1e-6 {
                    stood[k] += LIMITS.ts;
                }
            }
        }
        if reference.done() {
            break;
        }
        reference.step();
    }
    assert!(worst <= within, "a sample {worst} mm from the program");
    stood
}

#[test]
fn freecad_linuxcnc_post_with_k0_z_on_arcs_and_a_dwell() {
    // FreeCAD's LinuxCNC post: 3 decimals, I J K on every arc, Z repeated on arcs.
    let text = format!(
        "(Exported by FreeCAD)\n(Post Processor: linuxcnc_post)\n(Output Time:2026-12-05)\n\
         (begin preamble)\nG17 G54 G40 G49 G80 G90\nG21\n(begin operation: Profile)\n\
         (machine units: mm/min)\nM3 S10000\nG0 Z5.000\nG0 X0.000 Y0.000\n\
         G1 X0.000 Y0.000 Z-1.000 F300.000\nG4 P2.5\nG1 F1200.000\n{}\
         (finish operation: Profile)\nG0 Z5.000\nM05\nG17 G54 G90 G80 G40\nM2\n",
        profile_moves(3, true, Some("-1.000"))
    );
    let program = Program::parse_gcode(&text, "freecad.ngc").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(program.moves()[0].speed, Speed::Feed(20.0));
    // The plunge before the first XY move positions the tool; the dwell after it is
    // where the path starts, before which the reference is at rest anyway; the retract
    // at the end: 6 mm at rapid.
    let stood = run(
        &program,
        &[],
        LIMITS.tolerance + 1e-3,
        &[Stand {
            point: Vector2::zeros(),
            seconds: 0.06,
        }],
    );
    assert!((stood[0] - 0.06).abs() < 2.5 * LIMITS.ts, "{stood:?}");
}

#[test]
fn fanuc_post_with_o_number_g43_home_returns_a_dwell_in_ms_holes_and_an_optional_stop() {
    // Inventor HSM's Fanuc post: O number, N numbers, G28 G91 Z0., G43 H, 3 decimals
    // with trailing zeros stripped, a dwell of 1500 ms, a G82 cycle with P250 (ms), M1.
    let mut text = String::from(
        "%\nO1001 (BRACKET)\n(T1  D=6. CR=0. - ZMIN=-1. - FLAT END MILL)\n\
         N10 G90 G94 G17 G49 G40 G80\nN15 G21\nN20 G28 G91 Z0.\nN25 G90\nN30 T1 M6\n\
         N35 S5000 M3\nN40 G54\nN45 M8\nN50 G0 X0. Y0.\nN55 G43 Z15. H1\nN60 G0 Z5.\n\
         N65 G1 Z-1. F300.\nN70 G1 X0. Y0. F1200.\n",
    );
    text += &profile_moves(3, false, None).replace(".000", ".");
    text += "G4 P1500\nM1\nG0 Z15.\nG98 G82 X10. Y10. Z-3. R5. P250 F200.\nX30.\nG80\n\
             M9\nG28 G91 Z0.\nG90\nG28 G91 X0. Y0.\nG90\nM30\n%\n";
    let options = GcodeOptions {
        dialect: Dialect::Fanuc,
        optional_stop: true,
        home: contour_core::geometry::Vector::<3>::new(-50.0, -40.0, 100.0),
        ..GcodeOptions::default()
    };
    let program =
        Program::parse_gcode_with(&text, "hsm.nc", &options).unwrap_or_else(|e| panic!("{e}"));
    // Back at (0, 0): the dwell (1.5 s), the optional stop, the retract to 15 at rapid.
    let at_end = 1.5 + 16.0 / LIMITS.rapid;
    // Each hole: rapid 10 to R, 8 mm at F200 (3.33 mm/s), 0.25 s, rapid 18 back to 15;
    // the last also home in Z at rapid (85 mm).
    let hole = 10.0 / LIMITS.rapid + 8.0 / (200.0 / 60.0) + 0.25 + 18.0 / LIMITS.rapid;
    let v = Vector2::new;
    let stands = [
        Stand {
            point: v(0.0, 0.0),
            seconds: at_end,
        },
        Stand {
            point: v(10.0, 10.0),
            seconds: hole,
        },
        Stand {
            point: v(30.0, 10.0),
            seconds: hole + 85.0 / LIMITS.rapid,
        },
    ];
    let rapids = [
        Piece::Line(v(0.0, 0.0), v(10.0, 10.0)),
        Piece::Line(v(10.0, 10.0), v(30.0, 10.0)),
        Piece::Line(v(30.0, 10.0), v(-50.0, -40.0)),
    ];
    let stood = run(&program, &rapids, LIMITS.tolerance + 1e-3, &stands);
    for (stand, time) in stands.iter().zip(&stood) {
        assert!(
            (time - stand.seconds).abs() < 2.5 * LIMITS.ts,
            "{time} s, want {}",
            stand.seconds
        );
    }
    // Read as LinuxCNC, the same P1500 is 25 minutes.
    let linuxcnc = Program::parse_gcode(&text, "hsm.nc").unwrap();
    let standstill = linuxcnc
        .moves()
        .iter()
        .map(|m| m.standstill.seconds)
        .fold(0.0, f64::max);
    assert!(standstill >= 1500.0, "{standstill}");
}

#[test]
fn cambam_post_with_four_decimals_and_small_arcs() {
    let text = format!(
        "( Made using CamBam - http://www.cambam.co.uk )\n( part 12/5/2026 )\n\
         G21 G90 G91.1 G64 G40\nG0 Z3.0\n( T1 : 3.0 )\nT1 M6\n( Profile1 )\nG17\nM3 S1000\n\
         G0 X0.0 Y0.0\nG1 F300.0 Z-0.5\nG1 F800.0 X0.0 Y0.0\n{}G0 Z3.0\nM5\nM30\n",
        profile_moves(4, false, None)
    );
    let program = Program::parse_gcode(&text, "cambam.nc").unwrap_or_else(|e| panic!("{e}"));
    run(&program, &[], LIMITS.tolerance + 1e-4, &[]);
}

/// The public programs of `tests/data/cam` (their sources and licences in its README):
/// each read and planned with its dialect, every sample within the tolerance of the
/// program as read; the table of the note printed (`--nocapture`).
/// `CAM_PROGRAMS=dir` surveys another folder instead: a program refused there is a row
/// of the table with its reason, not a failure.
#[test]
fn public_cam_programs_are_read_and_planned() {
    let survey = std::env::var_os("CAM_PROGRAMS").map(std::path::PathBuf::from);
    let dir = survey.clone().unwrap_or_else(|| {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/cam")
    });
    let mut files: Vec<_> = walk(&dir);
    files.sort();
    assert!(survey.is_some() || files.len() >= 5, "{files:?}");
    println!("| program | moves | planning | duration | largest distance |");
    for file in files {
        let name = file.strip_prefix(&dir).unwrap().display().to_string();
        match read_and_plan(&file, &name) {
            Ok(row) => println!("{row}"),
            Err(why) if survey.is_some() => println!("| {name} | refused: {why} | | | |"),
            Err(why) => panic!("{name}: {why}"),
        }
    }
}

/// One program read with its dialect ("fanuc" in its path), planned and followed: its
/// row of the table, or why it is refused.
fn read_and_plan(file: &std::path::Path, name: &str) -> Result<String, String> {
    let options = GcodeOptions {
        dialect: if name.to_lowercase().contains("fanuc") {
            Dialect::Fanuc
        } else {
            Dialect::LinuxCnc
        },
        ..GcodeOptions::default()
    };
    let started = std::time::Instant::now();
    let program = Program::load_with(file, &options).map_err(|e| e.to_string())?;
    let path = Path::Program(program.clone());
    let mut reference = XyReference::new(path, LIMITS).map_err(|e| e.to_string())?;
    let planning = started.elapsed();
    let index = contour_core::contour::planar::TrueErrorIndex::new(&Path::Program(program.clone()));
    let mut worst = 0.0f64;
    let mut k = 0usize;
    loop {
        let sample = reference.current();
        // Every 10th sample: the exact distance from the program as read.
        if k.is_multiple_of(10) {
            worst = worst.max(index.error(sample.point, sample.s).error.abs());
        }
        if reference.done() {
            break;
        }
        reference.step();
        k += 1;
    }
    assert!(worst <= LIMITS.tolerance + 1e-9, "{name}: {worst}");
    assert!(
        program.length() > 0.0 && reference.duration() > 0.0,
        "{name}"
    );
    Ok(format!(
        "| {name} | {} | {:.3} s | {:.1} s | {:.4} mm |",
        program.moves().len(),
        planning.as_secs_f64(),
        reference.duration(),
        worst
    ))
}

fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(walk(&path));
        } else if contour_core::part_program::file_kind(&path)
            == Some(contour_core::part_program::FileKind::GCode)
        {
            out.push(path);
        }
    }
    out
}

#[test]
fn a_curve_check_of_the_profile_itself() {
    // The test's profile is closed and its pieces join (its own arithmetic).
    let pieces = profile();
    let mut at = Vector2::zeros();
    for p in &pieces {
        let start = match *p {
            Piece::Line(a, _) => a,
            Piece::Arc(c, r, a0, _) => c + Vector2::new(math::cos(a0), math::sin(a0)) * r,
        };
        assert!(size(start - at) < 1e-12, "{p:?}");
        at = p.end();
    }
    assert!(size(at) < 1e-12);
    let _ = Program::parse_gcode(&profile_moves(3, false, None), "p.ngc")
        .unwrap()
        .length();
}
