//! `contour-cosim`: runs a loop described by an SSP file through its FMUs and writes the
//! recorded trajectory as CSV. `contour-cosim --help` says how.

use std::io::{BufRead, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use contour_cosim::fmi2::{self, Activity};
use contour_cosim::metrics::Metrics;
use contour_cosim::ssp::StartValues;
use contour_cosim::watchdog::Watchdog;
use contour_cosim::{
    End, Error, Experiment, Recording, Scheme, Simulation, System, SystemStructure, Trace,
};

const USAGE: &str = r#"usage: contour-cosim run LOOP.ssd|LOOP.ssp [options]
       contour-cosim batch LOOP.ssd|LOOP.ssp [options] [--runs FILE]
       contour-cosim check LOOP.ssd|LOOP.ssp

run: steps the loop's FMUs from t = 0 with a fixed communication step and writes, as CSV,
the recorded variables at every t_k (row k: before the step from t_k; the last row after
the last step). check: loads the FMUs and checks the wiring, then lists the units.
batch: many runs through one set of instances (reset between runs), one per line of
--runs (default: standard input), each a JSON object {"run": ID, "start": [[UNIT,
VARIABLE, TEXT], ...]} (TEXT as --start takes it; the options' start values come first).
For each run it writes a JSON line {"run", "status" ("ok" or "error"), "message",
"steps"} and, when ok, the trajectory: (steps + 1) rows of the recorded columns as
little-endian f64. Its first line lists the columns: {"columns": [...]}. With --metrics
each ok run's line carries its "metrics" ({NAME: value}; NaN and infinities as the
strings "NaN", "inf", "-inf") and no trajectory unless --trajectory asks for it; the first
line then also says {"metrics": [...], "trajectory": true|false}.

options:
  --parameter-set NAME     the start values of the SSP file's parameter set NAME
  --start UNIT.VAR=VALUE   a further start value (repeatable; after the parameter set)
  --step SECONDS           the communication step (default: the file's default experiment)
  --stop SECONDS           the end time (default: the file's default experiment)
  --until UNIT.VAR         instead of --stop: end --settle seconds after this Boolean
                           output turns true (e.g. interpolator.done)
  --settle SECONDS         with --until (default 0)
  --max-stop SECONDS       with --until: the run fails if the signal has not come (default 600)
  --scheme gauss-seidel|jacobi   the coupling (default gauss-seidel, in the file's order)
  --record UNIT.VAR,...    the variables to record (default: every output of every unit)
  --output FILE            where the results go (default: standard output)
  --runs FILE              batch: the run lines (default: standard input)
  --metrics NAME,...       batch: measure each run where it ran (the campaigns' metrics:
                           contour_error, estimated_contour_error of the two-axis loop;
                           tip_error, orientation_error, estimated_tip_error,
                           estimated_orientation_error of the five-axis loop; each .max
                           or .mean) and answer them instead of the trajectory
  --trajectory             batch with --metrics: the trajectory too
  --timeout SECONDS        a single FMU call that takes longer ends the run as a timeout
                           (default 60)
  --log                    print the FMUs' log messages on standard error

exit status: 0 done; 1 the run failed (an FMU call returned an error; batch: never, each
run says); 2 refused before any run (a file, the wiring or an option; batch: also a run
line without a run id); 3 timeout (batch: of the first run without its result line);
4 (batch) an FMU returned fmi2Fatal in the last run answered: it may not be called again
in this process, so the next runs need a new one."#;

/// Exit status of a batch that stopped after a run in which an FMU returned fmi2Fatal.
const FATAL_STATUS: i32 = 4;

struct Options {
    command: String,
    file: PathBuf,
    parameter_set: Option<String>,
    starts: Vec<String>,
    step: Option<f64>,
    stop: Option<f64>,
    until: Option<String>,
    settle: f64,
    max_stop: f64,
    scheme: Scheme,
    record: Option<Vec<String>>,
    output: Option<PathBuf>,
    runs: Option<PathBuf>,
    metrics: Option<Vec<String>>,
    trajectory: bool,
    timeout: f64,
    log: bool,
}

/// The most seconds an option takes (about 30 years).
const MAX_SECONDS: f64 = 1e9;

fn seconds(option: &str, text: &str) -> Result<f64, Error> {
    text.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && (0.0..=MAX_SECONDS).contains(v))
        .ok_or_else(|| {
            Error::Refused(format!(
                "{option} wants a number of seconds from 0 to {MAX_SECONDS:e}, not {text:?}"
            ))
        })
}

fn parse(args: &[String]) -> Result<Options, Error> {
    let usage = |why: &str| Error::Refused(format!("{why}\n{USAGE}"));
    let (Some(command), Some(file)) = (args.first(), args.get(1)) else {
        return Err(usage("a command and a loop file are needed"));
    };
    if !["run", "batch", "check"].contains(&command.as_str()) {
        return Err(usage(&format!("unknown command {command:?}")));
    }
    let mut options = Options {
        command: command.clone(),
        file: PathBuf::from(file),
        parameter_set: None,
        starts: Vec::new(),
        step: None,
        stop: None,
        until: None,
        settle: 0.0,
        max_stop: 600.0,
        scheme: Scheme::GaussSeidel,
        record: None,
        output: None,
        runs: None,
        metrics: None,
        trajectory: false,
        timeout: 60.0,
        log: false,
    };
    let mut rest = args[2..].iter();
    while let Some(option) = rest.next() {
        if option == "--log" || option == "--trajectory" {
            *(if option == "--log" {
                &mut options.log
            } else {
                &mut options.trajectory
            }) = true;
            continue;
        }
        let value = rest
            .next()
            .ok_or_else(|| usage(&format!("{option} wants a value")))?;
        match option.as_str() {
            "--parameter-set" => options.parameter_set = Some(value.clone()),
            "--start" => options.starts.push(value.clone()),
            "--step" => options.step = Some(seconds(option, value)?),
            "--stop" => options.stop = Some(seconds(option, value)?),
            "--until" => options.until = Some(value.clone()),
            "--settle" => options.settle = seconds(option, value)?,
            "--max-stop" => options.max_stop = seconds(option, value)?,
            "--scheme" => options.scheme = value.parse()?,
            "--record" => options.record = Some(value.split(',').map(str::to_string).collect()),
            "--output" => options.output = Some(PathBuf::from(value)),
            "--runs" => options.runs = Some(PathBuf::from(value)),
            "--metrics" => {
                options.metrics = Some(value.split(',').map(|m| m.trim().to_string()).collect())
            }
            "--timeout" => options.timeout = seconds(option, value)?,
            other => return Err(usage(&format!("unknown option {other:?}"))),
        }
    }
    if options.until.is_some() && options.stop.is_some() {
        return Err(usage("--stop and --until exclude each other"));
    }
    if options.command != "batch" && options.metrics.is_some() {
        return Err(usage("--metrics is an option of batch"));
    }
    if options.trajectory && options.metrics.is_none() {
        return Err(usage(
            "--trajectory goes with --metrics (a batch without metrics answers trajectories)",
        ));
    }
    Ok(options)
}

/// "unit.variable" split at its first dot.
fn port(text: &str) -> Result<(String, String), Error> {
    text.split_once('.')
        .map(|(u, v)| (u.to_string(), v.to_string()))
        .ok_or_else(|| Error::Refused(format!("{text:?} is not UNIT.VARIABLE")))
}

/// What every run of a command shares: the start values of the options, the experiment,
/// the recorded columns.
struct Setup {
    starts: StartValues,
    experiment: Experiment,
    recording: Recording,
    metrics: Option<Metrics>,
}

fn setup(options: &Options, system: &System) -> Result<Setup, Error> {
    let mut starts = match &options.parameter_set {
        Some(name) => system.structure.parameter_set(name)?.clone(),
        None => Vec::new(),
    };
    for assignment in &options.starts {
        starts.push(
            system
                .parse_assignment(assignment)
                .map_err(|e| Error::Refused(format!("--start {e}")))?,
        );
    }
    system.start_values(&starts)?;
    let file = system.structure.file.display().to_string();
    let step = options.step.or(system.structure.step).ok_or_else(|| {
        Error::Refused(format!(
            "{file} gives no communication step (an OSP FixedStepAlgorithm); pass --step"
        ))
    })?;
    let end = match &options.until {
        Some(signal) => {
            let (unit, name) = port(signal)?;
            End::Signal {
                signal: system.resolve(&unit, &name)?,
                settle: options.settle,
                max_stop: options.max_stop,
            }
        }
        None => End::Time(options.stop.or(system.structure.stop).ok_or_else(|| {
            Error::Refused(format!("{file} gives no stop time; pass --stop or --until"))
        })?),
    };
    let experiment = Experiment { step, end }.checked()?;
    let metrics = match &options.metrics {
        Some(names) => Some(Metrics::new(system, names)?),
        None => None,
    };
    let mut columns = match (&options.record, &metrics) {
        (Some(names), _) => names
            .iter()
            .map(|n| port(n))
            .collect::<Result<Vec<_>, _>>()?,
        // Metrics alone record what they read.
        (None, Some(_)) => Vec::new(),
        (None, None) => system.outputs(),
    };
    for column in metrics.iter().flat_map(Metrics::columns) {
        if !columns.contains(column) {
            columns.push(column.clone());
        }
    }
    let recording = Recording::new(system, &columns)?;
    Ok(Setup {
        starts,
        experiment,
        recording,
        metrics,
    })
}

fn run(options: &Options) -> Result<Outcome, Error> {
    // Watched from the start: loading runs the FMU libraries' initialisers, and the first
    // instantiation comes before any result; the watchdog is dropped last.
    let activity = Arc::new(Activity::default());
    let timeout = Duration::from_secs_f64(options.timeout.max(1e-3));
    let _watchdog = Watchdog::ending_process(activity.clone(), timeout, "contour-cosim");
    // Results go to a descriptor of their own: what an FMU prints goes to stderr.
    let mut output: Box<dyn Write> = match &options.output {
        Some(path) => Box::new(
            std::fs::File::create(path)
                .map_err(|e| Error::Refused(format!("{}: {e}", path.display())))?,
        ),
        None => Box::new(std::io::BufWriter::new(fmi2::private_stdout().map_err(
            |e| Error::Failed(format!("cannot set the standard output aside: {e}")),
        )?)),
    };
    let system = System::from_structure(SystemStructure::read(&options.file)?, &activity)?;
    if options.command == "check" {
        let mut text = String::new();
        for unit in &system.units {
            text += &format!(
                "{}: {} ({})\n",
                unit.name,
                unit.fmu.description.model_name,
                unit.fmu.file.display()
            );
        }
        text += &format!(
            "{} connections, {} initial copies\n",
            system.connections.len(),
            system.initial_copies.len()
        );
        return write_out(&mut output, text.as_bytes()).map(|()| Outcome::Done);
    }
    let mut setup = setup(options, &system)?;
    let mut simulation = Simulation::watched(&system, options.scheme, options.log, activity)?;
    if options.command == "batch" {
        return batch(options, &system, &mut setup, &mut simulation, &mut output);
    }
    let start_values = system.start_values(&setup.starts)?;
    let trace = simulation.run(&setup.experiment, &start_values, &setup.recording)?;
    write_out(&mut output, csv(&trace).as_bytes()).map(|()| Outcome::Done)
}

/// How a command ended, when it did not fail.
enum Outcome {
    Done,
    /// A batch stopped after a run in which an FMU returned fmi2Fatal: the process may
    /// not call that FMU again, a new one takes the next runs.
    Fatal,
}

fn write_out(output: &mut dyn Write, bytes: &[u8]) -> Result<(), Error> {
    output
        .write_all(bytes)
        .and_then(|()| output.flush())
        .map_err(|e| Error::Failed(format!("cannot write the results: {e}")))
}

/// The trajectory as CSV: a "time" column, then the recorded ones.
fn csv(trace: &Trace) -> String {
    let mut text = String::with_capacity(trace.values.len() * 20);
    text.push_str("time");
    for column in &trace.columns {
        text.push(',');
        text.push_str(column);
    }
    text.push('\n');
    for k in 0..=trace.steps {
        text.push_str(&(k as f64 * trace.step).to_string());
        for value in trace.row(k) {
            text.push(',');
            text.push_str(&value.to_string());
        }
        text.push('\n');
    }
    text
}

/// The id of a batch's run line.
fn run_id(line: &str) -> Result<serde_json::Value, Error> {
    serde_json::from_str::<serde_json::Value>(line)
        .ok()
        .and_then(|parsed| parsed.get("run").cloned())
        .ok_or_else(|| {
            Error::Refused(format!(
                "run line {line:?}: not a JSON object with a \"run\""
            ))
        })
}

/// The start values of a batch's run line.
fn run_line(line: &str, system: &System) -> Result<StartValues, Error> {
    let bad = |why: &str| Error::Refused(format!("run line {line:?}: {why}"));
    let parsed: serde_json::Value = serde_json::from_str(line).map_err(|e| bad(&e.to_string()))?;
    let mut starts = Vec::new();
    let listed = match parsed.get("start") {
        None => &[][..],
        Some(list) => list
            .as_array()
            .map(Vec::as_slice)
            .ok_or_else(|| bad("\"start\" is not a list"))?,
    };
    for triple in listed {
        let texts: Option<Vec<&str>> = triple
            .as_array()
            .filter(|t| t.len() == 3)
            .and_then(|t| t.iter().map(|v| v.as_str()).collect());
        let Some([unit, name, text]) = texts.as_deref() else {
            return Err(bad(
                "a start value is not [UNIT, VARIABLE, TEXT] of strings",
            ));
        };
        starts.push(system.parse_start_value(unit, name, text)?);
    }
    Ok(starts)
}

/// A metric's value in a result line: a number, or the name of a non-finite one.
fn metric_value(value: f64) -> serde_json::Value {
    if value.is_finite() {
        serde_json::json!(value)
    } else if value.is_nan() {
        serde_json::json!("NaN")
    } else if value > 0.0 {
        serde_json::json!("inf")
    } else {
        serde_json::json!("-inf")
    }
}

fn batch(
    options: &Options,
    system: &System,
    setup: &mut Setup,
    simulation: &mut Simulation,
    output: &mut dyn Write,
) -> Result<Outcome, Error> {
    let input: Box<dyn BufRead> = match &options.runs {
        Some(path) => Box::new(std::io::BufReader::new(
            std::fs::File::open(path)
                .map_err(|e| Error::Refused(format!("{}: {e}", path.display())))?,
        )),
        None => Box::new(std::io::stdin().lock()),
    };
    let mut header = serde_json::json!({ "columns": setup.recording.columns() });
    let trajectory = setup.metrics.is_none() || options.trajectory;
    if let Some(metrics) = &setup.metrics {
        header["metrics"] = serde_json::json!(metrics.names());
        header["trajectory"] = serde_json::json!(trajectory);
    }
    write_out(output, format!("{header}\n").as_bytes())?;
    let mut bytes = Vec::new();
    for line in input.lines() {
        let line = line.map_err(|e| Error::Failed(format!("cannot read the run lines: {e}")))?;
        if line.trim().is_empty() {
            continue;
        }
        // A line without a run id cannot be answered; one with an id gets an error row.
        let id = run_id(&line)?;
        let result = run_line(&line, system).and_then(|mut starts| {
            starts.splice(0..0, setup.starts.iter().cloned());
            let values = system.start_values(&starts)?;
            let trace = simulation.run(&setup.experiment, &values, &setup.recording)?;
            let measured = match &mut setup.metrics {
                Some(metrics) => Some(metrics.compute(&trace, simulation)?),
                None => None,
            };
            Ok((trace, measured))
        });
        let (status, message, steps) = match &result {
            Ok((trace, _)) => ("ok", String::new(), trace.steps),
            Err(e) => ("error", e.to_string(), 0),
        };
        bytes.clear();
        let mut head =
            serde_json::json!({ "run": id, "status": status, "message": message, "steps": steps });
        if let (Ok((_, Some(values))), Some(metrics)) = (&result, &setup.metrics) {
            head["metrics"] = metrics
                .names()
                .iter()
                .zip(values)
                .map(|(name, &v)| (name.clone(), metric_value(v)))
                .collect::<serde_json::Map<_, _>>()
                .into();
        }
        bytes.extend_from_slice(format!("{head}\n").as_bytes());
        if let (Ok((trace, _)), true) = (&result, trajectory) {
            bytes.extend(trace.values.iter().flat_map(|v| v.to_le_bytes()));
        }
        // The caller reads as runs finish, and knows which run a crash took.
        write_out(output, &bytes)?;
        if simulation.fatal() {
            return Ok(Outcome::Fatal);
        }
    }
    Ok(Outcome::Done)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}");
        return ExitCode::SUCCESS;
    }
    match parse(&args).and_then(|options| run(&options)) {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Fatal) => {
            eprintln!("contour-cosim: an FMU returned fmi2Fatal; its functions may not be called again in this process");
            ExitCode::from(FATAL_STATUS as u8)
        }
        Err(e) => {
            eprintln!("contour-cosim: {e}");
            ExitCode::from(match e {
                Error::Refused(_) => 2,
                Error::Failed(_) => 1,
            })
        }
    }
}
