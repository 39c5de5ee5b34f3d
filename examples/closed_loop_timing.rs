//! Wall-clock cost of one metrics-only closed-loop run, the unit of work of the PSO tuner
//! (docs/design/two-axis.md §4.4: 50 particles × 100 iterations ≈ 5000 runs):
//! `cargo run --release --example closed_loop_timing [RUNS]`.
//!
//! The paper's circle (2 s at Ts = 1 ms, 2001 samples) per CCC mode, plus the trident at
//! 50 mm/s. The `Simulator` is prepared once (reference samples, true-error index) and
//! each run builds a fresh controller, as the tuner does through `metrics_with`.

use std::hint::black_box;
use std::time::Instant;

use contour_core::control::CccMode;
use contour_core::sim::{SimConfig, Simulator};

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(500);
    let prepare = Instant::now();
    let circle = Simulator::new(SimConfig::paper_circle()).expect("preset");
    let circle_prep = prepare.elapsed();
    let prepare = Instant::now();
    let trident = Simulator::new(SimConfig::builtin("trident").expect("preset")).expect("preset");
    let trident_prep = prepare.elapsed();
    println!(
        "prepare: circle {:.3} ms, trident {:.3} ms",
        circle_prep.as_secs_f64() * 1e3,
        trident_prep.as_secs_f64() * 1e3
    );
    for (name, sim) in [("circle", &circle), ("trident", &trident)] {
        for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
            let mut c = sim.config().controller;
            c.ccc.mode = mode;
            // Warm-up (page faults, caches).
            black_box(sim.metrics_with(&c).expect("valid"));
            let start = Instant::now();
            for _ in 0..runs {
                black_box(sim.metrics_with(black_box(&c)).expect("valid"));
            }
            let per_run = start.elapsed().as_secs_f64() / runs as f64;
            println!(
                "{name:<8} {mode:<6?} {:>8.1} µs per run, {:>6.0} ns per sample ({} samples)",
                per_run * 1e6,
                per_run * 1e9 / sim.samples() as f64,
                sim.samples()
            );
        }
    }
}
