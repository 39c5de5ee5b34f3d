//! `--circle`: the ISO 230-4 circular test of one XY run, or of a clockwise and a
//! counter-clockwise run ([`crate::circular_test`]), from the command line to its
//! figures: the summary on stdout, per sample deviations and the ballbar plot written all
//! or nothing.

use std::io::Write;
use std::path::PathBuf;

use contour_core::geometry::Vector2;

use crate::circular_test::{figures, Circle, CircularFigures};
use crate::measured::{self, Samples};
use crate::staged::{commit, Staged};
use crate::{pair, plot, Failure};

/// What a circular test is asked for.
pub struct CircularOptions {
    pub nominal: Circle,
    /// The run, and the run in the other direction for G(b).
    pub runs: Vec<PathBuf>,
    /// Samples from this time on, up to `to` (s): the circle without lead-in and lead-out.
    pub from: f64,
    pub to: f64,
    pub out: Option<PathBuf>,
    pub plot: Option<PathBuf>,
    /// The figures as JSON (mm), for scripts.
    pub figures: Option<PathBuf>,
    /// Deviation magnification of the plot (0: chosen from the data).
    pub magnification: f64,
}

/// Parses the options of `--circle` (`args` holds it).
pub fn parse(args: &[String]) -> Result<CircularOptions, String> {
    let mut o = CircularOptions {
        nominal: Circle {
            centre: Vector2::zeros(),
            radius: 0.0,
        },
        runs: Vec::new(),
        from: f64::NEG_INFINITY,
        to: f64::INFINITY,
        out: None,
        plot: None,
        figures: None,
        magnification: 0.0,
    };
    let mut circle = None;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| -> Result<f64, String> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{what} '{value}' must be a finite number"))
        };
        match flag.as_str() {
            "--circle" => {
                let fields: Vec<&str> = value.split(',').collect();
                let [x, y, r] = fields.as_slice() else {
                    return Err(format!("--circle needs CX,CY,R (mm), got '{value}'"));
                };
                let (cx, cy) = pair(&format!("{x},{y}"), "--circle")?;
                let radius: f64 = r
                    .trim()
                    .parse()
                    .ok()
                    .filter(|r: &f64| r.is_finite() && *r > 0.0)
                    .ok_or_else(|| {
                        format!("--circle: the radius '{r}' must be a finite number > 0")
                    })?;
                circle = Some(Circle {
                    centre: Vector2::new(cx, cy),
                    radius,
                });
            }
            "--measured" | "--reverse" => o.runs.push(PathBuf::from(value)),
            "--from" => o.from = number("--from")?,
            "--to" => o.to = number("--to")?,
            "--out" => o.out = Some(PathBuf::from(value)),
            "--plot" => o.plot = Some(PathBuf::from(value)),
            "--figures" => o.figures = Some(PathBuf::from(value)),
            "--magnification" => {
                o.magnification = number("--magnification")?;
                if o.magnification <= 0.0 {
                    return Err(format!("--magnification must be > 0, got {value}"));
                }
            }
            other => return Err(format!("unknown option '{other}' of the circular test")),
        }
    }
    o.nominal = circle.ok_or("--circle is required")?;
    if !(1..=2).contains(&o.runs.len()) {
        return Err(
            "the circular test needs --measured RUN.csv and at most one --reverse RUN.csv".into(),
        );
    }
    if o.from >= o.to {
        return Err(format!(
            "--from ({}) must be before --to ({})",
            o.from, o.to
        ));
    }
    Ok(o)
}

/// One run's samples within the window: (time, point).
fn read_run(file: &std::path::Path, from: f64, to: f64) -> Result<Vec<(f64, Vector2)>, String> {
    let run = measured::read(file, measured::default_threads())?;
    let Samples::Planar(points) = run.samples else {
        return Err(format!(
            "{}: a five-axis run: the circular test takes a run of the XY table (time,X,Y)",
            file.display()
        ));
    };
    let kept: Vec<(f64, Vector2)> = run
        .times
        .into_iter()
        .zip(points)
        .filter(|(t, _)| (from..=to).contains(t))
        .collect();
    if kept.len() < 3 {
        return Err(format!(
            "{}: {} samples between --from and --to; the circle needs at least 3",
            file.display(),
            kept.len()
        ));
    }
    Ok(kept)
}

fn write_deviations(
    staged: &Staged,
    runs: &[Vec<(f64, Vector2)>],
    nominal: &Circle,
) -> std::io::Result<()> {
    let mut w = staged.create().map_err(std::io::Error::other)?;
    writeln!(w, "run,time,angle,deviation")?;
    for (index, run) in runs.iter().enumerate() {
        for (t, p) in run {
            let (angle, deviation) = (nominal.angle(p), nominal.deviation(p));
            writeln!(w, "{index},{t},{angle},{deviation}")?;
        }
    }
    w.into_inner().map_err(|e| e.into_error())?.sync_all()
}

fn summary(label: &str, f: &CircularFigures) {
    println!("{label}:");
    println!(
        "  least-squares circle: centre ({:.6}, {:.6}) mm, radius {:.6} mm",
        f.lsc.centre.x, f.lsc.centre.y, f.lsc.radius
    );
    println!(
        "  circular deviation G: {:.3} um",
        f.circular_deviation * 1e3
    );
    println!(
        "  radial deviation F: min {:.3} um, max {:.3} um",
        f.radial_deviation.0 * 1e3,
        f.radial_deviation.1 * 1e3
    );
}

/// Reads the runs, prints the figures, writes the outputs.
pub fn run(o: CircularOptions) -> Result<(), Failure> {
    let runs = o
        .runs
        .iter()
        .map(|file| read_run(file, o.from, o.to))
        .collect::<Result<Vec<_>, _>>()
        .map_err(Failure::Input)?;
    let points = |run: &Vec<(f64, Vector2)>| run.iter().map(|(_, p)| *p).collect::<Vec<_>>();
    let mut all = Vec::new();
    let mut json = serde_json::json!({ "unit": "mm", "runs": [] });
    for (index, run) in runs.iter().enumerate() {
        let f = figures(&points(run), &o.nominal)
            .map_err(|e| Failure::Input(format!("{}: {e}", o.runs[index].display())))?;
        summary(
            &format!(
                "run {} ({}, {} samples)",
                index,
                o.runs[index].display(),
                run.len()
            ),
            &f,
        );
        json["runs"]
            .as_array_mut()
            .expect("an array")
            .push(serde_json::json!({
                "file": o.runs[index].display().to_string(),
                "samples": run.len(),
                "centre": [f.lsc.centre.x, f.lsc.centre.y],
                "radius": f.lsc.radius,
                "G": f.circular_deviation,
                "F": [f.radial_deviation.0, f.radial_deviation.1],
            }));
        all.extend(points(run));
    }
    if runs.len() == 2 {
        let both = figures(&all, &o.nominal).map_err(Failure::Input)?;
        println!(
            "bidirectional circular deviation G(b): {:.3} um (about the LSC of both runs, centre ({:.6}, {:.6}) mm)",
            both.circular_deviation * 1e3,
            both.lsc.centre.x,
            both.lsc.centre.y
        );
        json["Gb"] = serde_json::json!(both.circular_deviation);
        json["Gb_centre"] = serde_json::json!([both.lsc.centre.x, both.lsc.centre.y]);
    }
    let mut staged = Vec::new();
    let mut written = Ok(());
    if let Some(target) = &o.out {
        staged.push(Staged::new(target));
        written = write_deviations(&staged[0], &runs, &o.nominal)
            .map_err(|e| format!("cannot write {}: {e}", target.display()));
    }
    if let (Ok(()), Some(target)) = (&written, &o.plot) {
        staged.push(Staged::new(target));
        let traces: Vec<Vec<Vector2>> = runs.iter().map(points).collect();
        written = plot::ballbar(
            &staged[staged.len() - 1].temporary,
            &traces,
            &o.nominal,
            o.magnification,
        )
        .map_err(|e| format!("cannot plot {}: {e}", target.display()));
    }
    if let (Ok(()), Some(target)) = (&written, &o.figures) {
        staged.push(Staged::new(target));
        written = std::fs::write(
            &staged[staged.len() - 1].temporary,
            serde_json::to_string_pretty(&json).expect("plain numbers and strings"),
        )
        .map_err(|e| format!("cannot write {}: {e}", target.display()));
    }
    commit(&staged, written).map_err(Failure::Run)
}
