//! The NURBS JSON readers on arbitrary text: the planar path file (`parse_nurbs::<2>`, as
//! PathInterpolator2D reads it), the same in 3-D, and the two-curve five-axis file
//! (`ToolPath::parse_json`, as PathInterpolator5X reads it). The first byte picks the
//! reader; the rest is the file's text (lossily UTF-8, as a file would be refused
//! otherwise before parsing).
//!
//! What parses is then used as the models use it: evaluated at awkward parameters,
//! measured, and followed by the feed-rate interpolator (a few samples at a feed that
//! makes each one a sizable part of the path), the five-axis one through the inverse
//! kinematics. Nothing may panic; every loop in there is bounded.
#![no_main]

use contour_core::kinematics::TableTiltingAc;
use contour_core::path::five_axis::{JointReference, ToolPath};
use contour_core::path::planar::Path;
use contour_core::path::{nurbs_file, Curve, Interpolator, Nurbs};
use contour_fmu_fuzz::install_panic_hook;
use libfuzzer_sys::fuzz_target;

const SAMPLES: usize = 32;
/// The longest sampled path `ToolPath::poses` is asked for here, in chords: longer ones
/// allocate proportionally (see the report in fuzz/README.md).
const MAX_CHORDS: f64 = 1e5;

/// Parameters inside, at and outside the range, and the ones no caller should pass.
fn probes(range: (f64, f64)) -> [f64; 8] {
    let (a, b) = range;
    [
        a,
        b,
        0.5 * (a + b),
        a - 1.0,
        b + 1.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ]
}

fn exercise<const D: usize>(curve: &Nurbs<D>) {
    for u in probes(curve.param_range()) {
        let _ = curve.eval(u);
    }
    let _ = curve.breakpoints();
    let length = curve.length();
    // A feed that crosses the path in about SAMPLES samples of 1 ms (finite, > 0).
    let feed = (length / (SAMPLES as f64 * 1e-3)).clamp(1e-3, 1e6);
    if let Ok(mut interpolator) = Interpolator::new(curve.clone(), feed, 1e-3) {
        for _ in 0..SAMPLES {
            if interpolator.step().done {
                break;
            }
        }
    }
}

fuzz_target!(init: install_panic_hook(), |data: &[u8]| {
    let Some((&selector, body)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(body);
    match selector % 3 {
        0 => {
            if let Ok(curve) = nurbs_file::parse_nurbs::<2>(&text, "fuzz.json") {
                exercise(&curve);
                // As PathInterpolator2D holds it.
                let path = Path::Nurbs(curve);
                let _ = (path.start_point(), path.end_point(), path.mirrored());
            }
        }
        1 => {
            if let Ok(curve) = nurbs_file::parse_nurbs::<3>(&text, "fuzz.json") {
                exercise(&curve);
            }
        }
        _ => {
            let Ok(path) = ToolPath::parse_json(&text, "fuzz.json") else {
                return;
            };
            let ToolPath::Curves { tip, second, .. } = &path else {
                panic!("a JSON tool path is a curve pair");
            };
            exercise(tip);
            exercise(second);
            for u in probes(tip.param_range()) {
                let _ = path.pose_at(u);
            }
            let chord = 0.01;
            if tip.length() / chord <= MAX_CHORDS {
                let _ = path.poses(chord);
            }
            let feed = (tip.length() / (SAMPLES as f64 * 1e-3)).clamp(1e-3, 1e6);
            if let Ok(mut reference) =
                JointReference::new(path.clone(), TableTiltingAc::default(), feed, 1e-3)
            {
                for _ in 0..SAMPLES {
                    match reference.step() {
                        Ok(sample) if !sample.done => {}
                        _ => break,
                    }
                }
            }
        }
    }
});
