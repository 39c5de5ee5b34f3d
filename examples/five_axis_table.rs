//! Five-axis closed loop on the built-in paths, without and with the CCC: true tip and
//! orientation contour errors, how far the controller's estimates are from them, and the
//! planned reference's own deviation from the path (docs/design/five-axis.md §5.3b).
//!
//! `cargo run --release --example five_axis_table [--unplanned] [PATH …]`
//! (`--unplanned`: the reference at constant feed and a controller without limits, as
//! before machine limits).

use contour_core::control::CccMode;
use contour_core::limits::JointLimits;
use contour_core::path::five_axis::BUILTIN_TOOL_PATHS;
use contour_core::sim::{simulate_five_axis, FiveAxisSimConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut names: Vec<String> = std::env::args().skip(1).collect();
    let unplanned = names.first().is_some_and(|a| a == "--unplanned");
    if unplanned {
        names.remove(0);
    }
    let names: Vec<&str> = if names.is_empty() {
        BUILTIN_TOOL_PATHS.to_vec()
    } else {
        names.iter().map(String::as_str).collect()
    };
    println!(
        "{:<14} {:<6} {:>10} {:>10} {:>12} {:>12} {:>10} {:>10} {:>9} {:>9} {:>8}",
        "path",
        "CCC",
        "tip max",
        "tip mean",
        "orient max",
        "orient mean",
        "est. tip",
        "est. or.",
        "ref. tip",
        "ref. or.",
        "duration"
    );
    println!(
        "{:<14} {:<6} {:>10} {:>10} {:>12} {:>12} {:>10} {:>10} {:>9} {:>9} {:>8}",
        "", "", "µm", "µm", "µrad", "µrad", "µm", "µrad", "µm", "µrad", "s"
    );
    for name in names {
        for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
            let mut config = FiveAxisSimConfig::builtin(name)?.with_mode(mode);
            if unplanned {
                // The loop before limits: the reference at constant feed, a controller
                // that knows no limit.
                config = config.unplanned();
                config.controller.limits = JointLimits::UNLIMITED;
            }
            let (m, _) = simulate_five_axis(&config, false)?;
            println!(
                "{:<14} {:<6} {:>10.3} {:>10.3} {:>12.3} {:>12.3} {:>10.4} {:>10.4} {:>9.3} {:>9.3} {:>8.3}{}",
                name,
                format!("{mode:?}"),
                m.max_tip * 1e3,
                m.mean_tip * 1e3,
                m.max_orientation * 1e6,
                m.mean_orientation * 1e6,
                m.max_tip_estimate_deviation * 1e3,
                m.max_orientation_estimate_deviation * 1e6,
                m.max_reference_tip_deviation * 1e3,
                m.max_reference_orientation_deviation * 1e6,
                m.samples as f64 * config.controller.ts,
                m.divergence
                    .map_or(String::new(), |d| format!("  diverged: {d:?}")),
            );
        }
    }
    Ok(())
}
