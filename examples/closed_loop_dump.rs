//! Prints one recorded closed-loop run (`contour_core::sim`) as JSON, for comparison with
//! an independent model (tests/reference/test_closed_loop_scipy.py).
//!
//! Usage: `closed_loop_dump [PATH] [PLANT] [MODE] [FEED] [SETTLE]`
//! - PATH: a built-in name (default `circle`);
//! - PLANT: `paper` (default) or `mismatched` (Y inertia 1.5×);
//! - MODE: CCC mode `off`, `fixed` or `fuzzy` (default `off`);
//! - FEED: mm/s (default: the path's preset, 10π for the circle, 50 otherwise);
//! - SETTLE: seconds after the path end (default 0).
//!
//! Output: the run's parameters (Ts, feed, plant, axis gain), the time series (t,
//! reference, actual, true and estimated contour error, gains, u) and the metrics.

use contour_core::control::CccMode;
use contour_core::plant::XyTableParams;
use contour_core::sim::{SimConfig, Simulator};
use serde_json::json;

fn fail(msg: impl std::fmt::Display) -> ! {
    eprintln!("closed_loop_dump: {msg}");
    std::process::exit(2);
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str);
    let mut config = SimConfig::builtin(arg(0).unwrap_or("circle")).unwrap_or_else(|e| fail(e));
    config.plant = match arg(1).unwrap_or("paper") {
        "paper" => XyTableParams::PAPER,
        "mismatched" => XyTableParams::mismatched(),
        other => fail(format!(
            "unknown plant '{other}': expected paper or mismatched"
        )),
    };
    config.controller.ccc.mode = match arg(2).unwrap_or("off") {
        "off" => CccMode::Off,
        "fixed" => CccMode::Fixed,
        "fuzzy" => CccMode::Fuzzy,
        other => fail(format!(
            "unknown mode '{other}': expected off, fixed or fuzzy"
        )),
    };
    if let Some(f) = arg(3) {
        config.feed = f.parse().unwrap_or_else(|e| fail(format!("FEED: {e}")));
    }
    if let Some(s) = arg(4) {
        config.settle = s.parse().unwrap_or_else(|e| fail(format!("SETTLE: {e}")));
    }
    let sim = Simulator::new(config).unwrap_or_else(|e| fail(e));
    let result = sim.run();
    let c = sim.config();
    println!(
        "{}",
        json!({
            "ts": c.ts,
            "feed": c.feed,
            "plant": { "x": c.plant.axes[0], "y": c.plant.axes[1] },
            "axis": c.controller.axis,
            "mode": format!("{:?}", c.controller.ccc.mode),
            "trace": result.trace,
            "metrics": result.metrics,
        })
    );
}
