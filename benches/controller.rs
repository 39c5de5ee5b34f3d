//! One sample of the two-axis cross-coupled controller (axis loops + free-curve contour
//! estimate + CCC law), per CCC mode, on the paper's circle (docs/design/two-axis.md §4.2), and one whole
//! metrics-only closed-loop run (the PSO's unit of work).
//!
//! The controller is fed realistic samples: the reference and actual points of a recorded
//! closed-loop run of the real plant (`sim`), so the free-curve estimator walks back as far
//! as it does in practice (≈ 35 samples of lag at Kpp = 28.5 s⁻¹, Ts = 1 ms). Replaying a
//! recording keeps the plant out of the timing; criterion reports ns per sample.

use std::hint::black_box;

use contour_core::contour::planar::FreeCurveEstimator;
use contour_core::control::{CccConfig, CccMode, ControllerConfig, CrossCoupledController};
use contour_core::geometry::Vector2;
use contour_core::sim::{SimConfig, Simulator};
use criterion::{criterion_group, criterion_main, Criterion};

/// The estimator the controller FMU runs by default.
fn make_estimator() -> FreeCurveEstimator {
    FreeCurveEstimator::default()
}

fn bench_controller(c: &mut Criterion) {
    for (name, mode) in [
        ("controller/sample_off", CccMode::Off),
        ("controller/sample_fixed", CccMode::Fixed),
        ("controller/sample_fuzzy", CccMode::Fuzzy),
    ] {
        // (reference, actual) pairs of the closed loop in this mode, 2 s on the circle.
        let sim = Simulator::new(SimConfig::paper_circle().with_mode(mode)).unwrap();
        let trace = sim.run().trace;
        let samples: Vec<(Vector2, Vector2)> = trace
            .reference
            .iter()
            .copied()
            .zip(trace.actual.iter().copied())
            .collect();
        let config = ControllerConfig {
            ccc: CccConfig {
                mode,
                ..CccConfig::default()
            },
            ..ControllerConfig::default()
        };
        let mut ctl = CrossCoupledController::new(config, make_estimator()).unwrap();
        let mut k = 0;
        c.bench_function(name, |b| {
            b.iter(|| {
                if k == samples.len() {
                    k = 0;
                    ctl.reset();
                }
                let (r, p) = samples[k];
                k += 1;
                ctl.sample(black_box(r), black_box(p)).u
            })
        });
    }

    let sim = Simulator::new(SimConfig::paper_circle()).unwrap();
    let controller = sim.config().controller;
    c.bench_function("sim/paper_circle_2s_metrics_fuzzy", |b| {
        b.iter(|| sim.metrics_with(black_box(&controller)).unwrap())
    });
}

criterion_group!(benches, bench_controller);
criterion_main!(benches);
