//! Prints a NURBS path and its point, first and second derivatives at evenly spaced
//! parameters (plus every knot) as JSON, for comparison with geomdl.
//!
//! Usage: `nurbs_dump <infinity|trident|unit_circle|FILE.json> [COUNT]` (COUNT = 1000).

use contour_core::path::planar::builtin;
use contour_core::path::{nurbs_file, Curve, Nurbs};
use serde_json::json;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("infinity");
    let count: usize = match args.get(2).map(|s| s.parse()) {
        None => 1000,
        Some(Ok(n)) if n >= 2 => n,
        _ => {
            eprintln!("COUNT must be an integer >= 2");
            std::process::exit(2);
        }
    };
    let curve: Nurbs = match name {
        "infinity" => builtin::infinity(),
        "trident" => builtin::trident(),
        "unit_circle" => builtin::rational_unit_circle(),
        f => match nurbs_file::load_nurbs(f) {
            Ok(n) => n,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        },
    };
    let (a, b) = curve.param_range();
    let mut us: Vec<f64> = (0..count)
        .map(|k| a + (b - a) * k as f64 / (count - 1) as f64)
        .collect();
    us.extend(curve.breakpoints());
    let samples: Vec<_> = us
        .iter()
        .map(|&u| {
            let e = curve.eval(u);
            json!({"u": u, "p": e.p, "d1": e.d1, "d2": e.d2})
        })
        .collect();
    let out = json!({
        "degree": curve.degree(),
        "knots": curve.knots(),
        "control_points": curve.control_points(),
        "weights": curve.weights(),
        "length": curve.length(),
        "samples": samples,
    });
    println!("{out}");
}
