//! `contour-eval`: the offline contour-error evaluation of a measured run.
//!
//! The run's columns say what it is ([`measured`]). A five-axis run (docs/design/five-axis.md
//! §5.3a): a reference (CL file, two-curve JSON or built-in) and a CSV of joints; every
//! sample is mapped to a reference segment with the windowed Viterbi decoder, and the
//! per-sample foot-point errors and, on request, the per-reference-point
//! evaluation-function estimates and a PNG plot are written. A run of the XY table
//! ([`planar`], [`planar_run`]): a path (G-code, NURBS JSON or built-in) and a CSV of X, Y;
//! every sample's signed distance to the programmed and to the planned contour.
//!
//! Outputs are written beside their targets under a temporary name and renamed into
//! place only when everything succeeded ([`staged`]): a failed run leaves existing files
//! as they were.

use std::fmt;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use contour_core::contour::five_axis::reference_shape::ReferenceShape;
use contour_core::contour::five_axis::run_evaluation::{
    evaluate_run, suggested_max_skip, RunEvaluation, RunSettings,
};
use contour_core::geometry::{self, Vector};
use contour_core::kinematics::{Joints, Pose, TableTiltingAc};
use contour_core::part_program::cutter_compensation::ToolTable;
use contour_core::part_program::gcode::GcodeOptions;

use measured::{Kind, Samples};
use planar_run::PlanarOptions;
use reference::Reference;
use staged::{commit, Staged};

mod circular_run;
mod circular_test;
mod csv_lines;
mod measured;
mod planar;
mod planar_run;
mod plot;
mod reference;
mod staged;

const USAGE: &str = "\
usage: contour-eval --path PART.cl|PART.apt|PART.ngc|PART.json|tilted_helix|figure_eight
                    --measured RUN.csv --out ERR.csv [--out-reference REF.csv]
                    [--plot ERR.png] [--tool-length 100] [--pivot-a Y,Z] [--pivot-c X,Y]
                    [--max-skip K] [--angle-weight 0.1] [--window W]
                    [--reference straight|smooth] [--tool-radii D:R,...] [--threads N]
       contour-eval --path PART.ngc|NURBS.json|line|arc|circle|infinity|trident
                    --measured RUN.csv --out ERR.csv [--tolerance P] [--home X,Y,Z]
                    [--tool-radii D:R,...] [--against compensated|programmed]
                    [--plot ERR.png] [--threads N]
       contour-eval --circle CX,CY,R --measured RUN.csv [--reverse RUN.csv]
                    [--from T0] [--to T1] [--out DEV.csv] [--plot BALLBAR.png]
                    [--magnification M] [--figures FIG.json]

The run's columns say what it is: time,X,Y,Z,A,C a five-axis run, time,X,Y and none of
Z, A, C a run of the XY table. A --path of the other kind is refused. --threads N: the
threads to use (default: as many as the machine runs at once; 1 runs on one); the
outputs are the same with any number.

Five axes: maps every measured sample to a segment of the reference (HMM, Viterbi) and
reports the tool-tip and orientation contour errors of a table-tilting A-C machine.
  RUN.csv   header row with columns time,X,Y,Z,A,C (s, mm, rad) in any order; other
            columns are ignored
  ERR.csv   time,segment,tip,orientation per sample (foot-point errors, mm and rad)
  REF.csv   index,x,y,z,i,j,k,tip,orientation,t per reference point (evaluation-function
            estimate; empty where no sample is mapped next to the point)
  --pivot-a Y,Z  a point of the A axis (machine frame, mm; default 0,0)
  --pivot-c X,Y  a point of the C axis at A = 0 (machine frame, mm; default 0,0)
  --tool-length  L of the second point along the tool axis used by the mapping, mm
  --max-skip     most segments the mapping may advance per sample (<= 255); default:
                 1.5 x the largest measured tip step over the median reference segment
  --angle-weight weight of the motion-direction term of the mapping, mm/rad
  --window       candidate segments per sample of the mapping; default max(64, 8 K)
  --reference    what the errors are measured against: 'straight' (default) the
                 straight moves between the reference points, the axis slerped along
                 each, as CL data means; 'smooth' a G1 cubic through the points, the
                 axis slerped by its parameter. Either way the tip error is the distance
                 to the nearest point and the orientation error is taken there.
A JSON reference is sampled into poses with tip chords of at most 0.01 mm.

XY table: the signed distance (mm, > 0 right of travel, as ContourCCC2D's contourError)
of every sample to the programmed contour and to the planned one, the sample tracked
along the path so that a pass that comes back near itself is not confused.
  RUN.csv   header row with columns time,X,Y (s, mm) in any order, none of Z, A, C;
            other columns are ignored
  ERR.csv   time,segment,contour,contour_planned per sample (segment: the program's
            move, from 0; 0 on a line, an arc or a NURBS)
  --tolerance  P, mm: the corners of bare G64 (and of the start) blended within P as
               PathInterpolator2D plans them (its 'tolerance'); default 0: only the
               program's own G64 P corners are blended
  --home       X,Y,Z, mm: the machine's home in the program's coordinates, where its
               G28/G30 go and what G53 counts from (PathInterpolator2D's 'home.*');
               default 0,0,0; also for a G-code program on five axes
  --tool-radii D:R pairs, mm: the tools' radii for a program's cutter radius
               compensation (G41/G42 D), as the FMUs' 'toolRadii'; also for five axes
  --against    compensated (default): the errors against the tool centre's path, the
               compensation applied, as the interpolator follows it; programmed: the
               part's edge against the programmed contour (the signed distance less each
               move's offset: 0 where the tool centre runs its radius off the contour)

Circular test (ISO 230-4) of XY runs around the nominal circle CX,CY,R (mm): the
least-squares circle, the circular deviation G, the radial deviation F (min, max) of each
run and, with a --reverse run (the other direction), the bidirectional circular
deviation G(b).
  --from, --to   the samples of the circle itself (s), without lead-in and lead-out
  DEV.csv        run,time,angle,deviation per sample (rad from the nominal centre, mm
                 from the nominal circle, > 0 outside)
  BALLBAR.png    the polar plot of the deviation, magnified M times (default: the
                 largest deviation drawn as a quarter of the radius)
  FIG.json       the figures for scripts, in mm: per run its file, samples, LSC centre
                 and radius, G and F [min, max]; with --reverse, Gb and its LSC centre";

/// The options that apply to five-axis runs only.
const FIVE_AXIS_ONLY: [&str; 8] = [
    "--out-reference",
    "--tool-length",
    "--pivot-a",
    "--pivot-c",
    "--max-skip",
    "--angle-weight",
    "--window",
    "--reference",
];

struct Options {
    path: String,
    measured: PathBuf,
    out: PathBuf,
    out_reference: Option<PathBuf>,
    plot: Option<PathBuf>,
    machine: TableTiltingAc,
    settings: RunSettings,
    /// --max-skip and --window as given (else chosen from the data).
    max_skip: Option<usize>,
    window: Option<usize>,
    /// --tolerance as given (XY runs only).
    tolerance: Option<f64>,
    /// --home as given (XY runs only).
    home: Option<Vector<3>>,
    /// --tool-radii: a G-code program's tools for cutter radius compensation.
    tools: ToolTable,
    /// --against programmed: the part's edge against the programmed contour.
    against_programmed: bool,
    /// The five-axis-only options given, in order.
    five_axis_only: Vec<String>,
    /// --threads: threads to read, evaluate and write with.
    threads: usize,
}

/// Exit 2: the command line or an input is wrong; exit 1: the run or a write failed.
enum Failure {
    Input(String),
    Run(String),
}

pub(crate) fn pair(text: &str, what: &str) -> Result<(f64, f64), String> {
    let values: Vec<&str> = text.split(',').collect();
    let parse = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{what} '{text}': '{v}' is not a finite number"))
    };
    match values.as_slice() {
        [a, b] => Ok((parse(a)?, parse(b)?)),
        _ => Err(format!(
            "{what} needs two comma-separated numbers, got '{text}'"
        )),
    }
}

/// "X,Y,Z" as three finite numbers.
fn triple(text: &str, what: &str) -> Result<Vector<3>, String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{what} '{text}': not three finite numbers"))?;
    match values.as_slice() {
        [x, y, z] => Ok(Vector::<3>::new(*x, *y, *z)),
        _ => Err(format!(
            "{what} needs three comma-separated numbers, got '{text}'"
        )),
    }
}

fn parse(args: &[String]) -> Result<Option<Options>, String> {
    let defaults = RunSettings::default();
    let (mut path, mut measured, mut out) = (None, None, None);
    let mut o = Options {
        path: String::new(),
        measured: PathBuf::new(),
        out: PathBuf::new(),
        out_reference: None,
        plot: None,
        machine: TableTiltingAc::default(),
        settings: defaults,
        max_skip: None,
        window: None,
        tolerance: None,
        home: None,
        tools: ToolTable::default(),
        against_programmed: false,
        five_axis_only: Vec::new(),
        threads: defaults.threads,
    };
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        if flag == "-h" || flag == "--help" {
            return Ok(None);
        }
        let value = it.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| -> Result<f64, String> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| format!("{what} '{value}' must be a finite number >= 0"))
        };
        let count = |what: &str| -> Result<usize, String> {
            value
                .parse::<usize>()
                .map_err(|e| format!("{what} '{value}': {e}"))
        };
        if FIVE_AXIS_ONLY.contains(&flag.as_str()) {
            o.five_axis_only.push(flag.clone());
        }
        match flag.as_str() {
            "--path" => path = Some(value.clone()),
            "--tolerance" => o.tolerance = Some(number("--tolerance")?),
            "--home" => o.home = Some(triple(value, "--home")?),
            "--tool-radii" => {
                o.tools = ToolTable::parse(value).map_err(|e| format!("--tool-radii: {e}"))?
            }
            "--against" => {
                o.against_programmed = match value.as_str() {
                    "compensated" => false,
                    "programmed" => true,
                    other => {
                        return Err(format!(
                            "--against must be compensated or programmed, got '{other}'"
                        ))
                    }
                }
            }
            "--measured" => measured = Some(PathBuf::from(value)),
            "--out" => out = Some(PathBuf::from(value)),
            "--out-reference" => o.out_reference = Some(PathBuf::from(value)),
            "--plot" => o.plot = Some(PathBuf::from(value)),
            "--tool-length" => o.settings.tool_length = number("--tool-length")?,
            "--pivot-a" => {
                let (y, z) = pair(value, "--pivot-a")?;
                o.machine.a_pivot = Vector::<3>::new(0.0, y, z);
            }
            "--pivot-c" => {
                let (x, y) = pair(value, "--pivot-c")?;
                o.machine.c_pivot = Vector::<3>::new(x, y, 0.0);
            }
            "--max-skip" => {
                let k = count("--max-skip")?;
                if !(1..=255).contains(&k) {
                    return Err(format!("--max-skip must be 1 ... 255, got {k}"));
                }
                o.max_skip = Some(k);
            }
            "--angle-weight" => o.settings.params.angle_weight = number("--angle-weight")?,
            "--window" => o.window = Some(count("--window")?),
            "--threads" => {
                o.threads = count("--threads")?;
                if o.threads == 0 {
                    return Err("--threads must be at least 1, got 0".to_string());
                }
                o.settings.threads = o.threads;
            }
            "--reference" => {
                o.settings.reference = value
                    .parse::<ReferenceShape>()
                    .map_err(|e| format!("--reference: {e}"))?;
            }
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    o.path = path.ok_or("--path is required")?;
    o.measured = measured.ok_or("--measured is required")?;
    o.out = out.ok_or("--out is required")?;
    if let (Some(window), Some(max_skip)) = (o.window, o.max_skip) {
        if window <= max_skip {
            return Err(format!(
                "--window must exceed --max-skip ({max_skip}), got {window}"
            ));
        }
    }
    Ok(Some(o))
}

fn write_errors(
    staged: &Staged,
    times: &[f64],
    result: &RunEvaluation,
    threads: usize,
) -> Result<(), std::io::Error> {
    let mut w = staged.create().map_err(std::io::Error::other)?;
    writeln!(w, "time,segment,tip,orientation")?;
    let line = |text: &mut String, k: usize| {
        let s = &result.samples[k];
        let line = format_args!("{},{},{},{}\n", times[k], s.segment, s.tip, s.orientation);
        fmt::Write::write_fmt(text, line).expect("a String takes every write");
    };
    csv_lines::write(&mut w, result.samples.len(), threads, line)?;
    w.into_inner().map_err(|e| e.into_error())?.sync_all()
}

fn write_reference(
    staged: &Staged,
    reference: &[Pose],
    result: &RunEvaluation,
) -> Result<(), std::io::Error> {
    let mut w = staged.create().map_err(std::io::Error::other)?;
    writeln!(w, "index,x,y,z,i,j,k,tip,orientation,t")?;
    for (index, (pose, e)) in reference.iter().zip(&result.references).enumerate() {
        let (p, o) = (pose.tip, geometry::unit(&pose.axis).unwrap_or(pose.axis));
        write!(
            w,
            "{index},{},{},{},{},{},{},",
            p[0], p[1], p[2], o[0], o[1], o[2]
        )?;
        match e {
            Some(e) => writeln!(w, "{},{},{}", e.tip, e.orientation, e.t)?,
            None => writeln!(w, ",,")?,
        }
    }
    w.into_inner().map_err(|e| e.into_error())?.sync_all()
}

/// Reads the run, then the reference of its kind, and evaluates it.
fn run(o: Options) -> Result<(), Failure> {
    let started = Instant::now();
    let measured = measured::read(&o.measured, o.threads).map_err(Failure::Input)?;
    let kind = match measured.samples {
        Samples::Planar(_) => Kind::Planar,
        Samples::FiveAxis(_) => Kind::FiveAxis,
    };
    let name = o.measured.display().to_string();
    // Options of the other kind are a mistake, not something to ignore.
    let other = match kind {
        Kind::Planar => o.five_axis_only.first().cloned(),
        Kind::FiveAxis => o.tolerance.map(|_| "--tolerance".to_string()),
    };
    if let Some(flag) = other {
        return Err(Failure::Input(format!(
            "{flag} does not apply to {name}: it has {}",
            kind.columns()
        )));
    }
    let gcode = GcodeOptions {
        home: o.home.unwrap_or_else(Vector::<3>::zeros),
        tools: o.tools.clone(),
        ..GcodeOptions::default()
    };
    let reference = reference::load(&o.path, kind, &name, &gcode, o.against_programmed)
        .map_err(Failure::Input)?;
    match (reference, measured.samples) {
        (Reference::Planar(path, offsets), Samples::Planar(points)) => {
            let options = PlanarOptions {
                spec: o.path.clone(),
                out: o.out.clone(),
                plot: o.plot.clone(),
                tolerance: o.tolerance.unwrap_or(0.0),
                offsets,
                threads: o.threads,
            };
            planar_run::run(&options, path, &measured.times, &points, started)
        }
        (Reference::FiveAxis(poses, warnings), Samples::FiveAxis(joints)) => {
            for warning in &warnings {
                eprintln!("contour-eval: warning: {warning}");
            }
            five_axis(o, &poses, &measured.times, &joints, started)
        }
        _ => unreachable!("reference::load reads the reference of the run's kind"),
    }
}

/// The five-axis evaluation of `joints` against `reference`.
fn five_axis(
    mut o: Options,
    reference: &[Pose],
    times: &[f64],
    joints: &[Joints],
    started: Instant,
) -> Result<(), Failure> {
    let max_skip = o
        .max_skip
        .unwrap_or_else(|| suggested_max_skip(&o.machine, reference, joints, o.threads));
    o.settings.params.max_skip = max_skip;
    // Room for a few moves of K either side of the best segment.
    o.settings.window = o.window.unwrap_or(o.settings.window.max(8 * max_skip));

    let terminal = std::io::stderr().is_terminal();
    let bar = indicatif::ProgressBar::new(1);
    if terminal {
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:30} {percent:>3}%  elapsed {elapsed}  ETA {eta}",
            )
            .expect("valid template"),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = evaluate_run(&o.machine, reference, joints, &o.settings, |done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    })
    .map_err(|e| Failure::Input(e.to_string()))?;
    bar.finish_and_clear();

    let mut staged = vec![Staged::new(&o.out)];
    let mut written = write_errors(&staged[0], times, &result, o.threads)
        .map_err(|e| format!("cannot write {}: {e}", o.out.display()));
    if let (Ok(()), Some(target)) = (&written, &o.out_reference) {
        staged.push(Staged::new(target));
        written = write_reference(&staged[staged.len() - 1], reference, &result)
            .map_err(|e| format!("cannot write {}: {e}", target.display()));
    }
    if let (Ok(()), Some(target)) = (&written, &o.plot) {
        staged.push(Staged::new(target));
        written =
            plot::errors_against_time(&staged[staged.len() - 1].temporary, times, &result.samples)
                .map_err(|e| format!("cannot plot {}: {e}", target.display()));
    }
    // All or nothing: rename only when every output is complete.
    commit(&staged, written).map_err(Failure::Run)?;

    let n = result.samples.len() as f64;
    let (mut tip_max, mut tip_sum, mut rot_max, mut rot_sum) = (0.0f64, 0.0, 0.0f64, 0.0);
    for s in &result.samples {
        tip_max = tip_max.max(s.tip);
        tip_sum += s.tip;
        rot_max = rot_max.max(s.orientation);
        rot_sum += s.orientation;
    }
    let estimated = result.references.iter().filter(|e| e.is_some()).count();
    println!("samples: {}", result.samples.len());
    println!(
        "tip error: max {:.3} um, mean {:.3} um",
        tip_max * 1e3,
        tip_sum / n * 1e3
    );
    println!(
        "orientation error: max {:.3} urad, mean {:.3} urad",
        rot_max * 1e6,
        rot_sum / n * 1e6
    );
    println!(
        "reference points: {} ({estimated} with an evaluation-function estimate)",
        reference.len()
    );
    println!(
        "mapping: max skip {}, window {} segments",
        o.settings.params.max_skip, o.settings.window
    );
    println!(
        "reference read as: {}",
        match o.settings.reference {
            ReferenceShape::Straight => "straight moves between the points",
            ReferenceShape::Smooth => "a smooth curve through the points",
        }
    );
    println!("time: {:.2} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// The exit code of a finished run: 2 for a wrong input, 1 for a failed run or write.
fn finish(result: Result<(), Failure>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Input(message)) => {
            eprintln!("contour-eval: {message}");
            ExitCode::from(2)
        }
        Err(Failure::Run(message)) => {
            eprintln!("contour-eval: {message}");
            ExitCode::FAILURE
        }
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let help = args.iter().any(|a| a == "-h" || a == "--help");
    let parsed = if args.iter().any(|a| a == "--circle") && !help {
        circular_run::parse(&args).map(|o| Some(Mode::Circular(o)))
    } else {
        parse(&args).map(|o| o.map(|o| Mode::Contour(Box::new(o))))
    };
    match parsed {
        Ok(None) => {
            println!("{USAGE}");
            ExitCode::SUCCESS
        }
        Ok(Some(Mode::Circular(options))) => finish(circular_run::run(options)),
        Ok(Some(Mode::Contour(options))) => finish(run(*options)),
        Err(message) => {
            eprintln!("contour-eval: {message}\n{USAGE}");
            ExitCode::from(2)
        }
    }
}

/// What the command line asks for.
enum Mode {
    /// A run's contour errors against its path.
    Contour(Box<Options>),
    /// The circular test of ISO 230-4.
    Circular(circular_run::CircularOptions),
}
