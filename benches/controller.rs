//! One sample of the two-axis cross-coupled controller (axis loops + contour estimate +
//! CCC law), per CCC mode, on the paper's circle (DESIGN 4.2).
//!
//! The estimator here is the exact circle error, defined below, so the bench measures the
//! controller itself; swap `make_estimator` for the free-curve estimator to include it.

use std::hint::black_box;

use contour_fmu::contour::{ContourEstimate, ContourEstimator};
use contour_fmu::control::{CccConfig, CccMode, ControllerConfig, CrossCoupledController};
use criterion::{criterion_group, criterion_main, Criterion};

/// Exact contour error of the circle centre (−10, 0), radius 10, counter-clockwise.
struct CircleEstimator;

impl ContourEstimator for CircleEstimator {
    fn estimate(&mut self, _reference: [f64; 2], p: [f64; 2]) -> ContourEstimate {
        let d = [p[0] + 10.0, p[1]];
        let rho = d[0].hypot(d[1]);
        ContourEstimate {
            error: rho - 10.0,
            normal: [-d[0] / rho, -d[1] / rho],
        }
    }
    fn reset(&mut self) {}
}

fn make_estimator() -> CircleEstimator {
    CircleEstimator
}

fn circle(t: f64) -> [f64; 2] {
    let a = std::f64::consts::PI * t;
    [10.0 * a.cos() - 10.0, 10.0 * a.sin()]
}

fn bench_controller(c: &mut Criterion) {
    // Precomputed reference, so only the controller is timed; the "plant" is an ideal
    // velocity follower (p ← p + u·Ts), which keeps the errors realistic and non-zero.
    let refs: Vec<[f64; 2]> = (0..2000).map(|k| circle(k as f64 * 1e-3)).collect();
    for (name, mode) in [
        ("controller/sample_off", CccMode::Off),
        ("controller/sample_fixed", CccMode::Fixed),
        ("controller/sample_fuzzy", CccMode::Fuzzy),
    ] {
        let config = ControllerConfig {
            ccc: CccConfig {
                mode,
                ..CccConfig::default()
            },
            ..ControllerConfig::default()
        };
        let ts = config.ts;
        let mut ctl = CrossCoupledController::new(config, make_estimator()).unwrap();
        let mut p = refs[0];
        let mut k = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                if k == refs.len() {
                    k = 0;
                    p = refs[0];
                    ctl.reset();
                }
                let out = ctl.sample(black_box(refs[k]), black_box(p));
                p = [p[0] + out.u[0] * ts, p[1] + out.u[1] * ts];
                k += 1;
                out.u
            })
        });
    }
}

criterion_group!(benches, bench_controller);
criterion_main!(benches);
