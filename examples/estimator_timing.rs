//! Times the contour-error functions per sample along a closed-loop-like run: the actual
//! point lags 35 samples (P position loop, Kpp = 28.5 s⁻¹, Ts = 1 ms) and sits 50 µm off
//! the path. Usage: `estimator_timing [PATH]` (default trident).

use contour_core::math;
use std::time::Instant;

use contour_core::contour::planar::{true_error, FreeCurveEstimator, TrueErrorIndex};
use contour_core::contour::ContourEstimator;
use contour_core::path::planar::builtin;
use contour_core::path::{Curve, Interpolator};

fn main() {
    let name = std::env::args().nth(1).unwrap_or_else(|| "trident".into());
    let path = builtin::by_name(&name).expect("built-in path name");
    let mut it = Interpolator::new(path.clone(), 10.0 * std::f64::consts::PI, 1e-3).unwrap();
    let mut samples = vec![it.current()];
    while !it.step().done {
        samples.push(it.current());
    }
    let actual: Vec<[f64; 2]> = (0..samples.len())
        .map(|k| {
            let e = path.eval(samples[k.saturating_sub(35)].u);
            let s = math::hypot(e.d1[0], e.d1[1]);
            [e.p[0] + 0.05 * e.d1[1] / s, e.p[1] - 0.05 * e.d1[0] / s]
        })
        .collect();
    let n = samples.len() as f64;

    let t = Instant::now();
    let idx = TrueErrorIndex::new(&path);
    println!(
        "index build: {:.2} ms ({} chunks)",
        t.elapsed().as_secs_f64() * 1e3,
        idx.chunk_count()
    );

    let mut sum = 0.0;
    let t = Instant::now();
    for (s, p) in samples.iter().zip(&actual) {
        sum += idx.error((*p).into(), s.u).error;
    }
    println!(
        "index, hint = reference u: {:.3} µs/sample",
        t.elapsed().as_secs_f64() * 1e6 / n
    );

    let t = Instant::now();
    let mut hint = 0.0;
    for p in &actual {
        let r = idx.error((*p).into(), hint);
        hint = r.u;
        sum += r.error;
    }
    println!(
        "index, hint = previous foot: {:.3} µs/sample",
        t.elapsed().as_secs_f64() * 1e6 / n
    );

    let t = Instant::now();
    let mut est = FreeCurveEstimator::default();
    for (s, p) in samples.iter().zip(&actual) {
        sum += est.estimate(s.point, (*p).into()).error;
    }
    println!(
        "free-curve estimator: {:.3} µs/sample",
        t.elapsed().as_secs_f64() * 1e6 / n
    );

    let t = Instant::now();
    let m = 200;
    for p in actual.iter().step_by(actual.len() / m) {
        sum += true_error(&path, (*p).into()).error;
    }
    println!(
        "global brute force: {:.1} µs/query",
        t.elapsed().as_secs_f64() * 1e6 / m as f64
    );
    println!("(checksum {sum:.6})");
}
