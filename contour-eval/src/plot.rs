//! `--plot`: tip and orientation errors against time as a PNG, one panel each. Long runs
//! are drawn as their per-pixel-column envelope (min and max of each bucket), so a
//! million samples cost no more to draw than two thousand.

use std::path::Path;

use contour_core::contour::five_axis::run_evaluation::SampleContourError;
use plotters::prelude::*;

/// Buckets across the plot (about one per pixel column).
const BUCKETS: usize = 2000;

/// Points tracing the min/max envelope of `values` against `times`.
fn envelope(times: &[f64], values: impl Fn(usize) -> f64) -> Vec<(f64, f64)> {
    let n = times.len();
    let per = n.div_ceil(BUCKETS).max(1);
    let mut points = Vec::with_capacity(2 * BUCKETS);
    for start in (0..n).step_by(per) {
        let end = (start + per).min(n);
        let (lo, hi) = (start..end)
            .map(&values)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        let t = times[start];
        points.push((t, lo));
        if hi > lo {
            points.push((t, hi));
        }
    }
    points
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo.is_finite() && hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (lo - 0.5, lo + 0.5)
    } else {
        (0.0, 1.0)
    }
}

/// Draws the errors (µm and µrad) against time into `file` (PNG by its extension).
pub fn errors_against_time(
    file: &Path,
    times: &[f64],
    samples: &[SampleContourError],
) -> Result<(), String> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| "the embedded font cannot be read".to_string())?;
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::new(file, (1200, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let panels = root.split_evenly((2, 1));
    let (t0, t1) = range(times.iter().copied());
    let series = [
        (
            "tool-tip contour error",
            "tip error (um)",
            1e3,
            &BLUE,
            &panels[0],
        ),
        (
            "tool orientation contour error",
            "orientation error (urad)",
            1e6,
            &RED,
            &panels[1],
        ),
    ];
    for (index, (caption, label, scale, colour, area)) in series.into_iter().enumerate() {
        let value = |k: usize| {
            let s = &samples[k];
            scale * if index == 0 { s.tip } else { s.orientation }
        };
        let (_, top) = range((0..samples.len()).map(value));
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(t0..t1, 0.0..top * 1.05)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(label)
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(LineSeries::new(envelope(times, value), colour))
            .map_err(|e| fail(&e))?;
    }
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}
