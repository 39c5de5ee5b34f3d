//! `--plot`: a five-axis run's tip and orientation errors against time as a PNG, one
//! panel each; an XY run's contour errors to the programmed and the planned contour,
//! against time and along the path. Long runs are drawn as their per-pixel-column
//! envelope (min and max of each bucket), so a million samples cost no more to draw than
//! two thousand. `--circle`: the ballbar plot of the ISO 230-4 circular test.

use contour_core::math;
use std::path::Path;

use contour_core::contour::five_axis::run_evaluation::SampleContourError;
use plotters::prelude::*;

use contour_core::geometry::Vector2;

use crate::circular_test::Circle;
use crate::planar::PlanarSample;

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

/// The series' legend at `position`, boxed on white, in the labels' font.
fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())
}

fn register_font() -> Result<(), String> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| "the embedded font cannot be read".to_string())
}

/// Draws the errors (µm and µrad) against time into `file` (PNG by its extension).
pub fn errors_against_time(
    file: &Path,
    times: &[f64],
    samples: &[SampleContourError],
) -> Result<(), String> {
    register_font()?;
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

/// Draws an XY run's signed contour errors (µm) to the programmed and the planned
/// contour into `file` (PNG by its extension): against time above, against the position
/// along the programmed path below.
pub fn contour_errors(file: &Path, times: &[f64], samples: &[PlanarSample]) -> Result<(), String> {
    register_font()?;
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let root = BitMapBackend::new(file, (1200, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let panels = root.split_evenly((2, 1));
    let along: Vec<f64> = samples.iter().map(|s| s.along).collect();
    let programmed = |k: usize| 1e3 * samples[k].contour;
    let planned = |k: usize| 1e3 * samples[k].planned;
    let (lo, hi) = range((0..samples.len()).flat_map(|k| [programmed(k), planned(k)]));
    let pad = 0.05 * (hi - lo);
    let axes = [
        ("contour error against time", "time (s)", times, &panels[0]),
        (
            "contour error along the path",
            "position along the programmed path (mm)",
            &along[..],
            &panels[1],
        ),
    ];
    for (caption, x_label, xs, area) in axes {
        let (x0, x1) = range(xs.iter().copied());
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, lo - pad..hi + pad)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc("contour error (um), > 0 right of travel")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(|e| fail(&e))?;
        // The planned contour first: where they agree the programmed one is on top.
        for (name, colour, value) in [
            (
                "to the planned contour",
                RED,
                &planned as &dyn Fn(usize) -> f64,
            ),
            ("to the programmed contour", BLUE, &programmed),
        ] {
            chart
                .draw_series(LineSeries::new(envelope(xs, value), colour))
                .map_err(|e| fail(&e))?
                .label(name)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
        }
        draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    }
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}

/// The ballbar plot of ISO 230-4: each run's radial deviation from the `nominal` circle,
/// magnified `magnification` times (0: so that the largest deviation is a quarter of the
/// radius), drawn around the nominal circle; the first run blue, the second red.
pub fn ballbar(
    file: &Path,
    runs: &[Vec<Vector2>],
    nominal: &Circle,
    magnification: f64,
) -> Result<(), String> {
    register_font()?;
    let fail = |e: &dyn std::fmt::Display| e.to_string();
    let deviation = |p: &Vector2| nominal.deviation(p);
    let largest = runs
        .iter()
        .flatten()
        .map(|p| deviation(p).abs())
        .fold(0.0f64, f64::max);
    let m = if magnification > 0.0 {
        magnification
    } else if largest > 0.0 {
        0.25 * nominal.radius / largest
    } else {
        1.0
    };
    let drawn = |p: &Vector2| {
        let d = p - nominal.centre;
        let r = nominal.radius + m * deviation(p);
        let a = math::atan2(d.y, d.x);
        (r * math::cos(a), r * math::sin(a))
    };
    let extent = 1.4 * nominal.radius;
    let root = BitMapBackend::new(file, (900, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    let caption = format!(
        "circular test (ISO 230-4): radial deviation x{m:.0} ({:.2} um per mm of the plot)",
        1e3 / m
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(-extent..extent, -extent..extent)
        .map_err(|e| fail(&e))?;
    chart
        .configure_mesh()
        .x_desc("x - centre (mm, deviation magnified)")
        .y_desc("y - centre (mm)")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| fail(&e))?;
    let nominal_circle = (0..=720).map(|k| {
        let a = std::f64::consts::PI * k as f64 / 360.0;
        (nominal.radius * math::cos(a), nominal.radius * math::sin(a))
    });
    chart
        .draw_series(LineSeries::new(nominal_circle, BLACK.mix(0.4)))
        .map_err(|e| fail(&e))?
        .label("nominal circle")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.mix(0.4)));
    for (index, run) in runs.iter().enumerate() {
        let (colour, name) = if index == 0 {
            (BLUE, "run")
        } else {
            (RED, "reverse run")
        };
        chart
            .draw_series(LineSeries::new(run.iter().map(drawn), colour))
            .map_err(|e| fail(&e))?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour));
    }
    // In a corner: the glitches at 0°, 90°, 180° and 270° stay clear.
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    root.present().map_err(|e| fail(&e))?;
    Ok(())
}
