//! Prints true contour errors of pseudo-random points near a built-in path as JSON, for
//! comparison with an independent brute force (geomdl + scipy).
//!
//! Usage: `estimator_dump true_error <circle|line|arc|infinity|trident> [COUNT] [SEED]`.
//! Points: a random parameter, displaced along the normal by up to ±2 mm (80 %) or
//! ±20 mm (20 %). Output per point: the point, the global brute-force result and the
//! hint-accelerated index result (hint = the generating parameter).

use contour_core::contour::planar::{true_error, TrueErrorIndex};
use contour_core::math;
use contour_core::path::planar::builtin;
use contour_core::path::Curve;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde_json::json;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) != Some("true_error") {
        eprintln!("usage: estimator_dump true_error PATH [COUNT] [SEED]");
        std::process::exit(2);
    }
    let name = args.get(2).map(String::as_str).unwrap_or("trident");
    let count: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(300);
    let seed: u64 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(1);
    let path = match builtin::by_name(name) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let idx = TrueErrorIndex::new(&path);
    let mut rng = StdRng::seed_from_u64(seed);
    let (a, b) = path.param_range();
    let points: Vec<_> = (0..count)
        .map(|_| {
            let u = rng.random_range(a..b);
            let e = path.eval(u);
            let s = math::hypot(e.d1[0], e.d1[1]);
            let span = if rng.random_bool(0.8) { 2.0 } else { 20.0 };
            let off = rng.random_range(-span..span);
            let p = [e.p[0] - off * e.d1[1] / s, e.p[1] + off * e.d1[0] / s];
            let g = true_error(&path, p.into());
            let h = idx.error(p.into(), u);
            json!({
                "p": p,
                "error": g.error, "u": g.u, "foot": g.foot, "normal": g.normal,
                "index_error": h.error, "index_u": h.u,
            })
        })
        .collect();
    println!("{}", json!({"path": name, "points": points}));
}
