//! Runs the in-process five-axis closed loop (docs/design/five-axis.md §5.4) on a reference and
//! writes the measured joints as contour-eval reads them (`time,X,Y,Z,A,C`), with the
//! true errors of the run on stderr.
//!
//! `cargo run --release --example five_axis_run -- PATH MODE OUT.csv [FEED]`
//! PATH: a CL file, a two-curve JSON file or a built-in name; MODE: off, fixed, fuzzy;
//! FEED: tool-tip mm/s (default 50).

use std::io::Write;

use contour_core::control::CccMode;
use contour_core::path::five_axis::ToolPath;
use contour_core::sim::{simulate_five_axis, FiveAxisSimConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [spec, mode, out, rest @ ..] = args.as_slice() else {
        return Err("usage: five_axis_run PATH off|fixed|fuzzy OUT.csv [FEED]".into());
    };
    let mode = match mode.as_str() {
        "off" => CccMode::Off,
        "fixed" => CccMode::Fixed,
        "fuzzy" => CccMode::Fuzzy,
        other => return Err(format!("unknown mode {other:?}: off, fixed or fuzzy").into()),
    };
    let feed = rest.first().map_or(Ok(50.0), |f| f.parse::<f64>())?;
    let (path, warnings) = ToolPath::load(spec)?;
    for w in warnings {
        eprintln!("warning: {w}");
    }
    let config = FiveAxisSimConfig::new(path, feed).with_mode(mode);
    let (metrics, records) = simulate_five_axis(&config, true)?;
    let mut file = std::io::BufWriter::new(std::fs::File::create(out)?);
    writeln!(file, "time,X,Y,Z,A,C")?;
    for r in &records {
        let q = r.actual;
        writeln!(file, "{},{},{},{},{},{}", r.t, q[0], q[1], q[2], q[3], q[4])?;
    }
    file.flush()?;
    eprintln!(
        "{} samples; true tip error max {:.3} µm, mean {:.3} µm; orientation max {:.3} µrad, mean {:.3} µrad",
        metrics.samples,
        metrics.max_tip * 1e3,
        metrics.mean_tip * 1e3,
        metrics.max_orientation * 1e6,
        metrics.mean_orientation * 1e6
    );
    Ok(())
}
