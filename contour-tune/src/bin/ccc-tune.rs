//! `ccc-tune`: tunes the fuzzy CCC's five scaling factors (kε, kΔε, kpf, kif, kdf) with
//! the standard or improved PSO on an in-process closed loop (docs/design/two-axis.md §4.4), and writes
//! the result as JSON that the ContourCCC2D FMU takes as start values. The JSON holds
//! only what the run determines (no timing), so the same seed gives the same file on any
//! number of threads.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use contour_core::path::planar::Path;
use contour_core::sim::preset_feed;
use contour_cosim::fmi2::{self, Activity};
use contour_cosim::watchdog::Watchdog;
use contour_cosim::{System, SystemStructure};
use contour_tune::candidate_process::{serve, Workers, WORKER_FLAG};
use contour_tune::fmu_objective::{FmuObjective, LoopSettings};
use contour_tune::objective::{ContourObjective, Fitness, FACTOR_NAMES, LOWER, UPPER};
use contour_tune::{minimize, Algorithm, PsoSettings};
use serde_json::json;

const USAGE: &str = "\
usage: ccc-tune [--path circle|infinity|trident|FILE] [--feed MM_PER_S] [--swarm 50]
                [--iters 100] [--algorithm improved|standard] [--seed 1] [--out tuned.json]
                [--lower a,b,c,d,e] [--upper a,b,c,d,e] [--plant paper|mismatched|PLANT.fmu]
                [--loop LOOP.ssd|LOOP.ssp] [--parameter-set NAME] [--start UNIT.VAR=VALUE]...
                [--settle 0.25] [--timeout 60] [--fitness mean|max] [--threads N]

Minimises the mean (or max) |true contour error| of the closed loop interpolator -> fuzzy-PID CCC
-> XYServoPlant over the factors (ke, kde, kp, ki, kd) of ContourCCC2D. The feed defaults
to 10*pi mm/s on the circle (the paper's) and 50 mm/s elsewhere.

By default the loop runs in process, with the test plant's paper or mismatched data.
--loop runs every candidate through the FMUs of an SSP file instead (units interpolator,
controller, plant; contour-cosim, instances reused per thread); --plant PLANT.fmu runs them
through the shipped two-axis loop with that plant (the loop of --loop, by default
two_axis.ssd in the fmu folder beside this program's: target/fmu). Through FMUs,
--parameter-set applies one of the loop's parameter sets first (the shipped loops' sets
carry feed-forward and, on two axes, a planned reference), --start sets any variable last
(repeatable); the interpolator and the controller get --path. With a planned reference
(interpolator.accel > 0) a run lasts until the reference ends plus --settle seconds, and
the true error is taken against the path as followed (blended with interpolator.tolerance):
the way to tune the CCC on top of feed-forward, on a part program with corners.
Through FMUs the candidates run in worker processes (this program again, one per thread):
an FMU call longer than --timeout seconds ends its worker, and a candidate whose worker
ended (a hang, a crash) scores as a run that cannot start and is listed in the JSON's
failed_candidates; the tuning goes on with a new worker.";

struct Options {
    path: String,
    feed: Option<f64>,
    swarm: usize,
    iterations: usize,
    algorithm: Algorithm,
    seed: u64,
    out: PathBuf,
    lower: Vec<f64>,
    upper: Vec<f64>,
    plant: String,
    loop_file: Option<PathBuf>,
    parameter_set: Option<String>,
    starts: Vec<String>,
    settle: f64,
    timeout: f64,
    worker: bool,
    fitness: Fitness,
    threads: Option<usize>,
}

fn parse_list(text: &str, what: &str) -> Result<Vec<f64>, String> {
    let values: Result<Vec<f64>, _> = text.split(',').map(|v| v.trim().parse::<f64>()).collect();
    let values = values.map_err(|e| format!("{what}: {e} in '{text}'"))?;
    if values.len() != FACTOR_NAMES.len() {
        return Err(format!(
            "{what} needs {} comma-separated values ({}), got {}",
            FACTOR_NAMES.len(),
            FACTOR_NAMES.join(", "),
            values.len()
        ));
    }
    Ok(values)
}

fn parse(args: &[String]) -> Result<Option<Options>, String> {
    let mut o = Options {
        path: "circle".into(),
        feed: None,
        swarm: 50,
        iterations: 100,
        algorithm: Algorithm::Improved,
        seed: 1,
        out: PathBuf::from("tuned.json"),
        lower: LOWER.to_vec(),
        upper: UPPER.to_vec(),
        plant: "paper".into(),
        loop_file: None,
        parameter_set: None,
        starts: Vec::new(),
        settle: 0.25,
        timeout: 60.0,
        worker: false,
        fitness: Fitness::Mean,
        threads: None,
    };
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        if flag == "-h" || flag == "--help" {
            return Ok(None);
        }
        if flag == WORKER_FLAG {
            o.worker = true;
            continue;
        }
        let value = it.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| -> Result<f64, String> {
            value
                .parse::<f64>()
                .map_err(|e| format!("{what} '{value}': {e}"))
        };
        let count = |what: &str| -> Result<usize, String> {
            value
                .parse::<usize>()
                .map_err(|e| format!("{what} '{value}': {e}"))
        };
        match flag.as_str() {
            "--path" => o.path = value.clone(),
            "--feed" => o.feed = Some(number("--feed")?),
            "--swarm" => o.swarm = count("--swarm")?,
            "--iters" => o.iterations = count("--iters")?,
            "--algorithm" => o.algorithm = value.parse()?,
            "--seed" => {
                o.seed = value
                    .parse()
                    .map_err(|e| format!("--seed '{value}': {e}"))?
            }
            "--out" => o.out = PathBuf::from(value),
            "--lower" => o.lower = parse_list(value, "--lower")?,
            "--upper" => o.upper = parse_list(value, "--upper")?,
            "--plant" => o.plant = value.clone(),
            "--loop" => o.loop_file = Some(PathBuf::from(value)),
            "--parameter-set" => o.parameter_set = Some(value.clone()),
            "--start" => o.starts.push(value.clone()),
            "--settle" => o.settle = number("--settle")?,
            "--timeout" => o.timeout = number("--timeout")?,
            "--fitness" => o.fitness = value.parse()?,
            "--threads" => o.threads = Some(count("--threads")?),
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    Ok(Some(o))
}

fn run(o: Options, args: &[String]) -> Result<(), String> {
    if let Some(threads) = o.threads.filter(|_| !o.worker) {
        if threads == 0 {
            return Err("--threads must be at least 1".into());
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build_global()
            .map_err(|e| e.to_string())?;
    }
    if o.lower.iter().any(|&v| v < 0.0) {
        return Err("--lower: the fuzzy factors cannot be negative".into());
    }
    let path = Path::from_spec(&o.path, None).map_err(|e| format!("--path: {e}"))?;
    let feed = o.feed.unwrap_or_else(|| preset_feed(&path));
    let plant_fmu = o.plant.ends_with(".fmu").then(|| PathBuf::from(&o.plant));
    let preset = if plant_fmu.is_some() {
        "paper"
    } else {
        o.plant.as_str()
    };
    let through_fmus = o.loop_file.is_some() || plant_fmu.is_some();
    if !through_fmus && (o.parameter_set.is_some() || !o.starts.is_empty()) {
        return Err("--parameter-set and --start need a loop of FMUs (--loop or --plant)".into());
    }
    if !(o.settle.is_finite() && o.settle >= 0.0) {
        return Err(format!(
            "--settle must be zero or more seconds, not {}",
            o.settle
        ));
    }
    let loop_file = match (&o.loop_file, through_fmus) {
        (Some(file), _) => Some(file.clone()),
        (None, true) => Some(default_loop()?),
        (None, false) => None,
    };
    if !(o.timeout.is_finite() && o.timeout > 0.0) {
        return Err(format!(
            "--timeout must be a positive number of seconds, not {}",
            o.timeout
        ));
    }
    let objective = match &loop_file {
        Some(loop_file) if o.worker => {
            return work(&o, loop_file, plant_fmu.as_deref(), feed, preset);
        }
        Some(_) => {
            let program =
                std::env::current_exe().map_err(|e| format!("cannot find this program: {e}"))?;
            Objective::Workers(Workers::start(program, args.to_vec())?)
        }
        None if o.worker => return Err(format!("{WORKER_FLAG} needs a loop of FMUs")),
        None => Objective::InProcess(ContourObjective::new(path, feed, preset, o.fitness)?),
    };
    let settings = PsoSettings {
        algorithm: o.algorithm,
        swarm: o.swarm,
        iterations: o.iterations,
        lower: o.lower.clone(),
        upper: o.upper.clone(),
        velocity_fraction: 0.2,
        seed: o.seed,
    };
    settings.validate()?;

    let started = Instant::now();
    let terminal = std::io::stderr().is_terminal();
    let bar = indicatif::ProgressBar::new(o.iterations as u64);
    if terminal {
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:30} iteration {pos}/{len}  best {msg}  elapsed {elapsed}  ETA {eta}",
            )
            .expect("valid template"),
        );
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = minimize(
        settings.clone(),
        |x| objective.evaluate(x),
        |iteration, best| {
            bar.set_position(iteration as u64);
            bar.set_message(format!("{:.4} um", best * 1e3));
            if !terminal {
                eprintln!(
                    "iteration {iteration}/{}: best fitness {:.4} um",
                    o.iterations,
                    best * 1e3
                );
            }
        },
    )?;
    bar.finish_and_clear();
    let elapsed = started.elapsed().as_secs_f64();
    if let Objective::Workers(workers) = &objective {
        // Not one candidate ran: no result to write, only why.
        let failures = workers.failures();
        if failures.len() >= settings.swarm * settings.iterations {
            return Err(format!(
                "every candidate failed; the first: {}",
                failures.first().map_or("", |f| f.reason.as_str())
            ));
        }
    }

    let factors: serde_json::Map<String, serde_json::Value> = FACTOR_NAMES
        .iter()
        .zip(&result.best)
        .map(|(name, value)| (name.to_string(), json!(value)))
        .collect();
    let mut document = json!({
        "factors": factors,
        "fitness_mm": result.fitness,
        "history_mm": result.history,
        "settings": {
            "path": o.path,
            "feed_mm_per_s": feed,
            "plant": o.plant,
            "fitness": o.fitness,
            "ts_s": objective.ts(),
            "algorithm": settings.algorithm,
            "swarm": settings.swarm,
            "iterations": settings.iterations,
            "lower": settings.lower,
            "upper": settings.upper,
            "velocity_fraction": settings.velocity_fraction,
            "seed": settings.seed,
        },
    });
    if let Some(loop_file) = &loop_file {
        document["settings"]["loop"] = json!(loop_file.display().to_string());
        if let Some(set) = &o.parameter_set {
            document["settings"]["parameter_set"] = json!(set);
        }
        if !o.starts.is_empty() {
            document["settings"]["starts"] = json!(o.starts);
        }
        document["settings"]["settle_s"] = json!(o.settle);
        document["settings"]["timeout_s"] = json!(o.timeout);
        document["settings"]["run_s"] = json!(objective.samples() as f64 * objective.ts());
    }
    if let Objective::Workers(workers) = &objective {
        let failed: Vec<_> = workers
            .failures()
            .into_iter()
            .map(|f| json!({ "factors": f.factors, "reason": f.reason }))
            .collect();
        document["failed_candidates"] = json!(failed);
    }
    let text = serde_json::to_string_pretty(&document).map_err(|e| e.to_string())? + "\n";
    // Written beside the target and renamed into place: a failed write leaves nothing.
    let partial = o.out.with_extension("json.partial");
    std::fs::write(&partial, text)
        .map_err(|e| format!("cannot write {}: {e}", partial.display()))?;
    std::fs::rename(&partial, &o.out).map_err(|e| {
        let _ = std::fs::remove_file(&partial);
        format!("cannot write {}: {e}", o.out.display())
    })?;
    eprintln!(
        "best {:?} |true contour error| {:.4} um after {} x {} evaluations in {elapsed:.2} s; wrote {}",
        o.fitness,
        result.fitness * 1e3,
        o.iterations,
        o.swarm,
        o.out.display()
    );
    Ok(())
}

/// The in-process objective, or the same through FMUs in worker processes.
#[allow(clippy::large_enum_variant)] // one per run
enum Objective {
    InProcess(ContourObjective),
    Workers(Workers),
}

impl Objective {
    fn evaluate(&self, factors: &[f64]) -> f64 {
        match self {
            Objective::InProcess(o) => o.evaluate(factors),
            Objective::Workers(w) => w.evaluate(factors),
        }
    }

    fn ts(&self) -> f64 {
        match self {
            Objective::InProcess(o) => o.ts(),
            Objective::Workers(w) => w.greeting().ts,
        }
    }

    fn samples(&self) -> usize {
        match self {
            Objective::InProcess(o) => o.simulator().samples(),
            Objective::Workers(w) => w.greeting().samples,
        }
    }
}

/// A worker's life (`--worker`): loads the loop with every FMU call watched, then scores
/// the candidates its parent sends (contour_tune::candidate_process).
fn work(
    o: &Options,
    loop_file: &std::path::Path,
    plant_fmu: Option<&std::path::Path>,
    feed: f64,
    preset: &str,
) -> Result<(), String> {
    // Watched from the start, as contour-cosim's runs: loading runs the libraries'
    // initialisers.
    let activity = Arc::new(Activity::default());
    let _watchdog = Watchdog::ending_process(
        activity.clone(),
        Duration::from_secs_f64(o.timeout),
        "ccc-tune",
    );
    // The answers go to a descriptor of their own: what an FMU prints goes to stderr.
    let answers =
        fmi2::private_stdout().map_err(|e| format!("cannot set the standard output aside: {e}"))?;
    let mut structure = SystemStructure::read(loop_file).map_err(|e| format!("--loop: {e}"))?;
    if let Some(plant) = plant_fmu {
        structure
            .replace_source("plant", plant)
            .map_err(|e| format!("--plant: {e}"))?;
    }
    let system = System::from_structure(structure, &activity).map_err(|e| e.to_string())?;
    let objective = FmuObjective::new(
        &system,
        &o.path,
        feed,
        preset,
        o.fitness,
        &loop_settings(o, &system)?,
        activity,
    )?;
    serve(
        &objective,
        std::io::stdin().lock(),
        std::io::BufWriter::new(answers),
    )
}

/// The loop's start values the options give: the parameter set's, then --start's.
fn loop_settings(o: &Options, system: &System) -> Result<LoopSettings, String> {
    let parameter_set = match &o.parameter_set {
        Some(name) => system
            .structure
            .parameter_set(name)
            .map_err(|e| format!("--parameter-set: {e}"))?
            .clone(),
        None => Vec::new(),
    };
    let starts = o
        .starts
        .iter()
        .map(|assignment| {
            system
                .parse_assignment(assignment)
                .map_err(|e| format!("--start {e}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(LoopSettings {
        parameter_set,
        starts,
        settle: o.settle,
    })
}

/// The shipped two-axis loop beside this program's build: <target>/fmu/two_axis.ssd.
fn default_loop() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this program: {e}"))?;
    let target = exe
        .parent()
        .and_then(|p| p.parent())
        .ok_or("this program has no target folder")?;
    Ok(target.join("fmu").join("two_axis.ssd"))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match parse(&args) {
        Ok(None) => {
            println!("{USAGE}");
            ExitCode::SUCCESS
        }
        Ok(Some(options)) => match run(options, &args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(message) => {
                eprintln!("ccc-tune: {message}");
                ExitCode::FAILURE
            }
        },
        Err(message) => {
            eprintln!("ccc-tune: {message}\n{USAGE}");
            ExitCode::from(2)
        }
    }
}
