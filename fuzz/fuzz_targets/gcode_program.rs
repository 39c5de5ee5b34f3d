//! The G-code program reader on arbitrary text (as PathInterpolator2D reads a `.ngc`
//! file; lossily UTF-8, as a file would be refused otherwise before parsing), with the
//! reader's options (dialect, optional stop, home) taken from the first byte and a tool
//! table for cutter radius compensation. The part program is made the five-axis
//! machine's moves (compensation, arcs as chords, within a smaller budget than the
//! library's) and, when not too many, a five-axis path. What the XY table reads is then used as the models use it: evaluated at awkward path
//! positions, mirrored, measured against by the exact distance from points near and far,
//! round-tripped through the FMU state's encoding and followed by the interpolator for a
//! few samples. Nothing may panic; every loop in there is bounded.
#![no_main]

use contour_core::contour::planar::TrueErrorIndex;
use contour_core::geometry::{Vector, Vector2};
use contour_core::part_program::cutter_compensation::compensate;
use contour_core::part_program::cutter_compensation::ToolTable;
use contour_core::part_program::gcode::{parse_gcode, Dialect, GcodeOptions};
use contour_core::path::five_axis::{ToolPath, GCODE_ARC_SAG};
use contour_core::path::planar::{Path, Program, XyLimits, XyReference};
use contour_core::path::{Curve, Interpolator};
use contour_fmu_fuzz::install_panic_hook;
use libfuzzer_sys::fuzz_target;

const SAMPLES: usize = 32;

fuzz_target!(init: install_panic_hook(), |data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let options = GcodeOptions {
        dialect: if first & 1 == 0 { Dialect::LinuxCnc } else { Dialect::Fanuc },
        optional_stop: first & 2 != 0,
        home: Vector::<3>::new(-f64::from(first >> 2), 10.0, 50.0),
        tools: ToolTable::parse("0:0, 1:2, 2:0.5, 3:-1.5, 4:1e-9").expect("a tool table"),
    };
    let text = String::from_utf8_lossy(rest);
    let Ok(part) = parse_gcode(&text, "fuzz.ngc", &options) else {
        return;
    };
    // machine_moves with a budget a fuzzer's memory allows (the library's is 2^22 moves).
    let chorded = compensate(&part).and_then(|p| p.with_arcs_as_chords(GCODE_ARC_SAG, 100_000));
    if let Ok(moves) = chorded {
        if moves.moves.len() <= 4096 {
            let _ = ToolPath::from_poses(&moves.poses());
        }
    }
    let Ok(program) = Program::from_part_program(&part) else {
        return;
    };
    let length = program.length();
    for s in [0.0, length, 0.5 * length, -1.0, length + 1.0, f64::NAN, f64::INFINITY] {
        let _ = (program.eval(s), program.move_at(s));
    }
    let bytes = postcard::to_stdvec(&program).expect("a program serialises");
    let back: Program = postcard::from_bytes(&bytes).expect("a saved program reads back");
    assert_eq!(back.moves(), program.moves());
    // Planned, with its standstills: a few samples, and the end.
    let limits = XyLimits {
        feed: 10.0,
        rapid: 100.0,
        accel: 1000.0,
        jerk: 1e5,
        tolerance: 0.01,
        ts: 1e-3,
    };
    if program.moves().len() <= 64 {
        if let Ok(mut reference) = XyReference::new(Path::Program(program.clone()), limits) {
            for _ in 0..SAMPLES {
                let _ = reference.step();
            }
        }
    }
    let path = Path::Program(program);
    let _ = path.mirrored();
    let index = TrueErrorIndex::new(&path);
    let (start, end) = (path.start_point(), path.end_point());
    for p in [start, end, (start + end) * 0.5, Vector2::new(1e9, -1e9), Vector2::new(f64::NAN, 0.0)] {
        let _ = index.error(p, 0.5 * length);
    }
    let feed = (length / (SAMPLES as f64 * 1e-3)).clamp(1e-3, 1e6);
    if let Ok(mut interpolator) = Interpolator::new(path, feed, 1e-3) {
        for _ in 0..SAMPLES {
            if interpolator.step().done {
                break;
            }
        }
    }
});
