//! The tuner's objective through FMUs: every candidate's closed loop runs through the
//! loop of an SSP file (the user's own plant FMU, say) in contour-cosim, and its actual
//! positions and commands are judged as the in-process objective judges its own (the same reference,
//! true error and score: [`Simulator::metrics_of`](contour_core::sim::Simulator::metrics_of)).
//! A loop that reproduces the in-process simulator therefore scores every candidate bit
//! for bit alike, and the swarm takes the same path.
//!
//! A loop whose interpolator plans its reference (`accel` > 0: a part program's feeds,
//! exact stops and corners, with the feed-forward of the shipped parameter sets) runs until
//! the reference ends plus a settling time, measured once before the swarm starts; the
//! true error is then taken against the path as followed (blended with the loop's
//! tolerance), which the in-process simulator cannot run but can judge.
//!
//! The instances are made once per evaluating thread and reset between runs (fmi2Reset);
//! a loop with an FMU that allows one instance per process runs one candidate at a time,
//! and one whose FMU returned fmi2Fatal scores every later candidate as a failed run.

use std::sync::{Arc, Mutex};

use contour_core::geometry::Vector;
use contour_core::path::planar::Path;
use contour_cosim::fmi2::Activity;
use contour_cosim::simulation::End;
use contour_cosim::ssp::StartValues;
use contour_cosim::system::Resolved;
use contour_cosim::{Experiment, Recording, Scheme, Simulation, System, Value};

use crate::objective::{ContourObjective, Fitness, FACTOR_NAMES, PENALTY_MM};

/// The variables of the loop the tuner uses: the path and feed it sets, the factors it
/// tunes, the positions it judges.
const INTERPOLATOR: &str = "interpolator";
const CONTROLLER: &str = "controller";
const PLANT: &str = "plant";

/// The longest planned run the tuner measures, s: an hour of part program is no tuning
/// workload, and a reference that never ends must not hold the tuner.
const LONGEST_PLANNED_RUN: f64 = 3600.0;

/// What a tuning run sets in the loop besides the path, the feed and the factors.
#[derive(Clone, Debug, Default)]
pub struct LoopSettings {
    /// Start values set first: an SSP parameter set of the loop (the shipped loops' carry
    /// feed-forward and, for two axes, a plan).
    pub parameter_set: StartValues,
    /// Start values set last, overriding everything else (the command line's).
    pub starts: StartValues,
    /// With a planned reference: how long the run goes on after the reference ends, s.
    pub settle: f64,
}

impl LoopSettings {
    /// The last Real start value of `unit.name` these settings give.
    fn real(&self, unit: &str, name: &str) -> Option<f64> {
        self.parameter_set
            .iter()
            .chain(&self.starts)
            .rev()
            .find(|(u, n, _)| u == unit && n == name)
            .and_then(|(_, _, value)| match value {
                Value::Real(v) => Some(*v),
                Value::Integer(i) => Some(f64::from(*i)),
                _ => None,
            })
    }
}

pub struct FmuObjective<'a> {
    reference: ContourObjective,
    system: &'a System,
    experiment: Experiment,
    recording: Recording,
    fixed: Vec<(Resolved, Value)>,
    factors: Vec<Resolved>,
    idle: Mutex<Vec<Simulation<'a>>>,
    one_at_a_time: Option<Mutex<()>>,
    activity: Arc<Activity>,
}

impl<'a> FmuObjective<'a> {
    /// The loop of `system` on `path` (its text as the interpolator's `path` parameter
    /// takes it) at `feed`, judged as the in-process objective with the `plant` preset
    /// and `fitness` judges: the interpolator and the controller (for its program
    /// estimator) get the path, the controller the factors; the plant's `pos.x`, `pos.y`
    /// are judged. A loop without these variables is refused, and so is a planned
    /// reference that does not end. Every FMU call counts in `activity` (a watchdog's).
    pub fn new(
        system: &'a System,
        path: &str,
        feed: f64,
        plant: &str,
        fitness: Fitness,
        settings: &LoopSettings,
        activity: Arc<Activity>,
    ) -> Result<Self, String> {
        let in_loop = |e: contour_cosim::Error| format!("the loop: {e}");
        let named = |unit: &str, name: &str| system.resolve(unit, name).map_err(in_loop);
        // The path as the interpolator and the program estimator follow it.
        let tolerance = settings.real(INTERPOLATOR, "tolerance").unwrap_or(0.0);
        let mut values = settings.parameter_set.clone();
        values.extend([
            (
                INTERPOLATOR.into(),
                "path".into(),
                Value::String(path.into()),
            ),
            (INTERPOLATOR.into(), "feed".into(), Value::Real(feed)),
            (CONTROLLER.into(), "path".into(), Value::String(path.into())),
            (
                CONTROLLER.into(),
                "tolerance".into(),
                Value::Real(tolerance),
            ),
        ]);
        values.extend(settings.starts.iter().cloned());
        let fixed = system.start_values(&values).map_err(in_loop)?;
        let factors = FACTOR_NAMES
            .iter()
            .map(|f| named(CONTROLLER, &format!("fuzzy.{f}")))
            .collect::<Result<Vec<_>, _>>()?;
        let recording = Recording::new(
            system,
            &[
                (PLANT.into(), "pos.x".into()),
                (PLANT.into(), "pos.y".into()),
                (CONTROLLER.into(), "u.x".into()),
                (CONTROLLER.into(), "u.y".into()),
            ],
        )
        .map_err(in_loop)?;
        let shape = Path::from_spec(path, None).map_err(|e| format!("--path: {e}"))?;
        let mut objective = FmuObjective {
            reference: ContourObjective::new(shape.clone(), feed, plant, fitness)?,
            system,
            experiment: Experiment {
                step: 1.0,
                end: End::Time(1.0),
            },
            recording,
            fixed,
            factors: factors.clone(),
            idle: Mutex::new(Vec::new()),
            one_at_a_time: system.once_per_process().then(|| Mutex::new(())),
            activity,
        };
        let ts = objective.reference.ts();
        let planned = settings.real(INTERPOLATOR, "accel").unwrap_or(0.0) > 0.0;
        // The run's samples t_0 … t_(n-1), as the in-process run has them (a planned
        // run's as long as the loop takes), and one step more for the controller's
        // command at the last sample.
        let steps = if planned {
            let end = Experiment {
                step: ts,
                end: End::Signal {
                    signal: named(INTERPOLATOR, "done")?,
                    settle: settings.settle,
                    max_stop: LONGEST_PLANNED_RUN,
                },
            }
            .checked()
            .map_err(|e| e.to_string())?;
            let steps = objective
                .run(&end, &[])
                .map_err(|e| format!("the planned run: {e}"))?
                .steps;
            objective.reference = ContourObjective::lasting(
                shape.blended(tolerance),
                feed,
                plant,
                fitness,
                Some(steps.saturating_sub(1) as f64 * ts),
            )?;
            steps
        } else {
            objective.reference.simulator().samples()
        };
        objective.experiment = Experiment {
            step: ts,
            end: End::Time(steps.max(1) as f64 * ts),
        }
        .checked()
        .map_err(|e| e.to_string())?;
        Ok(objective)
    }

    /// The in-process objective whose reference and score this one uses.
    pub fn reference(&self) -> &ContourObjective {
        &self.reference
    }

    /// One run of the loop with these factors: the plant's positions at t_0 … t_(n-1)
    /// with the controller's command at each.
    fn samples(&self, factors: &[f64]) -> Result<Vec<(Vector<2>, Vector<2>)>, String> {
        let trace = self.run(&self.experiment, factors)?;
        // Row k: the position at t_k; the command of sample k is in row k + 1.
        Ok((0..trace.steps)
            .map(|k| {
                let (now, next) = (trace.row(k), trace.row(k + 1));
                (
                    Vector::<2>::new(now[0], now[1]),
                    Vector::<2>::new(next[2], next[3]),
                )
            })
            .collect())
    }

    /// One run of `experiment` with these factors (none: the controller's own).
    fn run(
        &self,
        experiment: &Experiment,
        factors: &[f64],
    ) -> Result<contour_cosim::Trace, String> {
        // A loop with an FMU that allows one instance per process runs one at a time.
        let _alone = match &self.one_at_a_time {
            Some(lock) => Some(lock.lock().map_err(|e| e.to_string())?),
            None => None,
        };
        let taken = self.idle.lock().map_err(|e| e.to_string())?.pop();
        let mut simulation = match taken {
            Some(s) => s,
            None => Simulation::watched(
                self.system,
                Scheme::GaussSeidel,
                false,
                self.activity.clone(),
            )
            .map_err(|e| e.to_string())?,
        };
        let mut start = self.fixed.clone();
        start.extend(
            self.factors
                .iter()
                .zip(factors)
                .map(|(&target, &value)| (target, Value::Real(value))),
        );
        let trace = simulation
            .run(experiment, &start, &self.recording)
            .map_err(|e| e.to_string());
        if !simulation.fatal() {
            self.idle
                .lock()
                .map_err(|e| e.to_string())?
                .push(simulation);
        }
        trace
    }

    /// The fitness (mm) of these factors, as [`ContourObjective::evaluate`] gives it; a run
    /// the FMUs end (an error) scores as a run that cannot start.
    pub fn evaluate(&self, factors: &[f64]) -> f64 {
        match self.samples(factors) {
            Ok(positions) => self
                .reference
                .score(&self.reference.simulator().metrics_of(positions)),
            Err(_) => 2.0 * PENALTY_MM,
        }
    }
}
