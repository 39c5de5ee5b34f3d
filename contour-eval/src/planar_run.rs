//! An XY run from the command line to its outputs: the path read and planned, every
//! sample evaluated ([`crate::planar`]), `ERR.csv` and the plot written all or nothing,
//! the summary on stdout.

use std::fmt;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use contour_core::geometry::Vector2;
use contour_core::path::planar::Path;

use crate::planar::{evaluate, Geometry, PlanarSample, Statistics};
use crate::staged::{commit, Staged};
use crate::{csv_lines, plot, Failure};

/// What an XY run is asked for.
pub struct PlanarOptions {
    /// `--path` as given.
    pub spec: String,
    pub out: PathBuf,
    pub plot: Option<PathBuf>,
    /// The blend tolerance of bare G64 and of the start, mm (0: none).
    pub tolerance: f64,
    /// With `--against programmed`: each programmed move's offset, subtracted from the
    /// signed errors of the samples whose foot is on it (the part's edge).
    pub offsets: Option<Vec<f64>>,
    /// Threads to write with (`--threads`).
    pub threads: usize,
}

fn write_errors(
    staged: &Staged,
    times: &[f64],
    samples: &[PlanarSample],
    threads: usize,
) -> std::io::Result<()> {
    let mut w = staged.create().map_err(std::io::Error::other)?;
    writeln!(w, "time,segment,contour,contour_planned")?;
    let line = |text: &mut String, k: usize| {
        let s = &samples[k];
        let line = format_args!("{},{},{},{}\n", times[k], s.segment, s.contour, s.planned);
        fmt::Write::write_fmt(text, line).expect("a String takes every write");
    };
    csv_lines::write(&mut w, samples.len(), threads, line)?;
    w.into_inner().map_err(|e| e.into_error())?.sync_all()
}

/// The path in words, for the summary.
fn describe(geometry: &Geometry, tolerance: f64) -> String {
    let shape = match &geometry.programmed {
        Path::Program(p) => format!("a G-code program of {} moves", p.moves().len()),
        Path::Line(_) => "a line".into(),
        Path::Arc(_) => "an arc".into(),
        Path::Nurbs(_) => "a NURBS curve".into(),
    };
    let plan = match (&geometry.programmed, geometry.blends()) {
        (Path::Program(_), 0) => format!("no corner blended (tolerance {tolerance} mm)"),
        (Path::Program(_), n) => format!("{n} corners blended (tolerance {tolerance} mm)"),
        _ => "planned on itself (no corners)".into(),
    };
    format!("{shape}; {plan}")
}

/// Where sample `at` is, for the summary.
fn place(geometry: &Geometry, times: &[f64], samples: &[PlanarSample], at: usize) -> String {
    let segment = samples[at].segment;
    let line = match &geometry.programmed {
        Path::Program(p) => format!(" (line {})", p.moves()[segment].line),
        _ => String::new(),
    };
    format!("t = {} s, segment {segment}{line}", times[at])
}

fn summary_line(what: &str, s: &Statistics, place: &str) -> String {
    format!(
        "{what}: max {:.3} um (signed {:+.3} um at {place}), mean {:.3} um, rms {:.3} um",
        s.max.abs() * 1e3,
        s.max * 1e3,
        s.mean * 1e3,
        s.rms * 1e3
    )
}

/// Evaluates the run `times`, `points` against `path` and writes the outputs.
pub fn run(
    o: &PlanarOptions,
    path: Path,
    times: &[f64],
    points: &[Vector2],
    started: Instant,
) -> Result<(), Failure> {
    if let (Path::Nurbs(_), true) = (&path, o.tolerance > 0.0) {
        eprintln!(
            "contour-eval: warning: {} is a NURBS curve without corners: --tolerance does not \
             change it",
            o.spec
        );
    }
    let geometry = Geometry::new(path, o.tolerance).map_err(Failure::Input)?;
    let mut samples = evaluate(&geometry, points);
    if let Some(offsets) = &o.offsets {
        for s in &mut samples {
            let offset = offsets.get(s.segment).copied().unwrap_or(0.0);
            s.contour -= offset;
            s.planned -= offset;
        }
    }

    let mut staged = vec![Staged::new(&o.out)];
    let mut written = write_errors(&staged[0], times, &samples, o.threads)
        .map_err(|e| format!("cannot write {}: {e}", o.out.display()));
    if let (Ok(()), Some(target)) = (&written, &o.plot) {
        staged.push(Staged::new(target));
        written = plot::contour_errors(&staged[staged.len() - 1].temporary, times, &samples)
            .map_err(|e| format!("cannot plot {}: {e}", target.display()));
    }
    commit(&staged, written).map_err(Failure::Run)?;

    let programmed = Statistics::of(samples.iter().map(|s| s.contour));
    let planned = Statistics::of(samples.iter().map(|s| s.planned));
    println!("samples: {}", samples.len());
    println!("path: {}", describe(&geometry, o.tolerance));
    println!(
        "{}",
        summary_line(
            if o.offsets.is_some() {
                "part edge error (programmed contour, less each move's offset)"
            } else {
                "contour error (programmed)"
            },
            &programmed,
            &place(&geometry, times, &samples, programmed.at)
        )
    );
    println!(
        "{}",
        summary_line(
            "contour error (planned)",
            &planned,
            &place(&geometry, times, &samples, planned.at)
        )
    );
    println!("sign: > 0 right of the direction of travel (as ContourCCC2D's contourError)");
    println!("time: {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}
