//! Five-axis closed loop on the built-in paths, without and with the CCC: true tip and
//! orientation contour errors, and how far the controller's estimates are from them.
//!
//! `cargo run --release --example five_axis_table [PATH …]`

use contour_fmu::control::CccMode;
use contour_fmu::path::tool_path::BUILTIN_TOOL_PATHS;
use contour_fmu::sim::{simulate_five_axis, FiveAxisSimConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let names: Vec<String> = std::env::args().skip(1).collect();
    let names: Vec<&str> = if names.is_empty() {
        BUILTIN_TOOL_PATHS.to_vec()
    } else {
        names.iter().map(String::as_str).collect()
    };
    println!(
        "{:<14} {:<6} {:>10} {:>10} {:>12} {:>12} {:>10} {:>10}",
        "path", "CCC", "tip max", "tip mean", "orient max", "orient mean", "est. tip", "est. or."
    );
    println!(
        "{:<14} {:<6} {:>10} {:>10} {:>12} {:>12} {:>10} {:>10}",
        "", "", "µm", "µm", "µrad", "µrad", "µm", "µrad"
    );
    for name in names {
        for mode in [CccMode::Off, CccMode::Fixed, CccMode::Fuzzy] {
            let mut config = FiveAxisSimConfig::builtin(name)?.with_mode(mode);
            let env = |k: &str| std::env::var(k).ok().map(|v| v.parse::<f64>().unwrap());
            if let Some(v) = env("TIP_KP") {
                config.controller.tip.gains0.kp = v;
            }
            if let Some(v) = env("TIP_KI") {
                config.controller.tip.gains0.ki = v;
            }
            if let Some(v) = env("OR_KP") {
                config.controller.orientation.gains0.kp = v;
            }
            if let Some(v) = env("OR_KI") {
                config.controller.orientation.gains0.ki = v;
            }
            let (m, _) = simulate_five_axis(&config, false)?;
            println!(
                "{:<14} {:<6} {:>10.3} {:>10.3} {:>12.3} {:>12.3} {:>10.4} {:>10.4}{}",
                name,
                format!("{mode:?}"),
                m.max_tip * 1e3,
                m.mean_tip * 1e3,
                m.max_orientation * 1e6,
                m.mean_orientation * 1e6,
                m.max_tip_estimate_deviation * 1e3,
                m.max_orientation_estimate_deviation * 1e6,
                m.divergence
                    .map_or(String::new(), |d| format!("  diverged: {d:?}")),
            );
        }
    }
    Ok(())
}
