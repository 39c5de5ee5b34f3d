//! Contour accuracy of the closed loop with and without cross-coupled control:
//! `cargo run --release --example closed_loop_table`.
//!
//! Rows: the built-in `circle`, `infinity` and `trident` paths × the paper's plant and the
//! mismatched one (Y inertia 1.5×) × CCC off, fixed-gain PI CCC (Kp0 = 100, Ki0 = 5000)
//! and fuzzy-PID CCC (the default configuration with the paper's factors). Columns: max
//! and mean |true contour error| over the run (µm), their reduction against CCC off,
//! the same max after the 0.2 s start-up transient, and the peak drive current.
//!
//! Feeds (`sim::SimConfig::builtin`): the circle at 10π mm/s, the paper's (one turn in
//! 2 s); `infinity` and `trident` at 50 mm/s (`sim::FREE_CURVE_FEED`): a 1.75 mm
//! following error, and with the paper's large viscous friction (B = 1.2 N·m·s) about
//! 65 A of drive current, against 42 A on the circle (the plant has no current limit by
//! default, docs/design/two-axis.md §4.5). Every run is from rest at the path start to the sample where the
//! interpolator reaches the path end (no settle time); Ts = 1 ms, free-curve estimator.

use contour_core::control::CccMode;
use contour_core::plant::XyTableParams;
use contour_core::sim::{Metrics, SimConfig, Simulator};

/// Metrics of a run and its peak drive current (A, at the sample instants, where the
/// held command steps and the current peaks).
fn run(config: SimConfig) -> (Metrics, f64) {
    let sim = Simulator::new(config).expect("valid preset");
    let mut run = sim.start();
    let mut peak: f64 = 0.0;
    loop {
        let before = run.plant().clone();
        let Some(r) = run.next() else { break };
        for (axis, &u) in before.axes.iter().zip(r.u.iter()) {
            peak = peak.max(axis.current(u).abs());
        }
    }
    (run.metrics(), peak)
}

fn main() {
    let plants = [
        ("paper", XyTableParams::PAPER),
        ("mismatched", XyTableParams::mismatched()),
    ];
    let modes = [
        ("off", CccMode::Off),
        ("fixed", CccMode::Fixed),
        ("fuzzy", CccMode::Fuzzy),
    ];
    println!(
        "{:<9} {:>6} {:<10} {:<6} {:>9} {:>9} {:>8} {:>8} {:>11} {:>7}",
        "path",
        "feed",
        "plant",
        "CCC",
        "max µm",
        "mean µm",
        "Δmax %",
        "Δmean %",
        "settled µm",
        "peak A"
    );
    for name in ["circle", "infinity", "trident"] {
        for (plant_name, plant) in plants {
            let mut baseline: Option<Metrics> = None;
            for (mode_name, mode) in modes {
                let config = SimConfig::builtin(name)
                    .expect("built-in path")
                    .with_plant(plant)
                    .with_mode(mode);
                let feed = config.feed;
                let (m, peak) = run(config);
                let base = *baseline.get_or_insert(m);
                let reduction = |v: f64, b: f64| {
                    if mode == CccMode::Off {
                        "—".to_string()
                    } else {
                        format!("{:.1}", 100.0 * (1.0 - v / b))
                    }
                };
                let flag = if m.is_stable() { "" } else { "  DIVERGED" };
                println!(
                    "{:<9} {:>6.2} {:<10} {:<6} {:>9.3} {:>9.3} {:>8} {:>8} {:>11.3} {:>7.1}{}",
                    name,
                    feed,
                    plant_name,
                    mode_name,
                    m.max_abs_error * 1e3,
                    m.mean_abs_error * 1e3,
                    reduction(m.max_abs_error, base.max_abs_error),
                    reduction(m.mean_abs_error, base.mean_abs_error),
                    m.settled_max_abs_error * 1e3,
                    peak,
                    flag
                );
            }
        }
    }
}
