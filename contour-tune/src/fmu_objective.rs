//! The tuner's objective through FMUs: every candidate's closed loop runs through the
//! loop of an SSP file (the user's own plant FMU, say) in contour-cosim, and its actual
//! positions and commands are judged as the in-process objective judges its own (the same reference,
//! true error and score: [`Simulator::metrics_of`](contour_core::sim::Simulator::metrics_of)).
//! A loop that reproduces the in-process simulator therefore scores every candidate bit
//! for bit alike, and the swarm takes the same path.
//!
//! The instances are made once per evaluating thread and reset between runs (fmi2Reset);
//! a loop with an FMU that allows one instance per process runs one candidate at a time,
//! and one whose FMU returned fmi2Fatal scores every later candidate as a failed run.

use std::sync::Mutex;

use contour_core::geometry::Vector;
use contour_cosim::simulation::End;
use contour_cosim::system::Resolved;
use contour_cosim::{Experiment, Recording, Scheme, Simulation, System, Value};

use crate::objective::{ContourObjective, FACTOR_NAMES, PENALTY_MM};

/// The variables of the loop the tuner uses: the path and feed it sets, the factors it
/// tunes, the positions it judges.
const INTERPOLATOR: &str = "interpolator";
const CONTROLLER: &str = "controller";
const PLANT: &str = "plant";

pub struct FmuObjective<'a> {
    reference: ContourObjective,
    system: &'a System,
    experiment: Experiment,
    recording: Recording,
    fixed: Vec<(Resolved, Value)>,
    factors: Vec<Resolved>,
    idle: Mutex<Vec<Simulation<'a>>>,
    one_at_a_time: Option<Mutex<()>>,
}

impl<'a> FmuObjective<'a> {
    /// The loop of `system` on the path and feed of `reference` (the in-process objective
    /// that gives the reference samples, the true error and the score): the interpolator
    /// gets `path` (its `path` parameter's text) and the feed, the controller the factors;
    /// the plant's `pos.x`, `pos.y` are judged. A loop without these variables is refused.
    pub fn new(
        system: &'a System,
        reference: ContourObjective,
        path: &str,
        feed: f64,
    ) -> Result<Self, String> {
        let named = |unit: &str, name: &str| {
            system
                .resolve(unit, name)
                .map_err(|e| format!("the loop: {e}"))
        };
        let fixed = system
            .start_values(&[
                (
                    INTERPOLATOR.into(),
                    "path".into(),
                    Value::String(path.into()),
                ),
                (INTERPOLATOR.into(), "feed".into(), Value::Real(feed)),
            ])
            .map_err(|e| format!("the loop: {e}"))?;
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
        .map_err(|e| format!("the loop: {e}"))?;
        // The run's samples t_0 … t_(n-1), as the in-process run has them, and one step
        // more for the controller's command at the last sample.
        let steps = reference.simulator().samples().max(1);
        let experiment = Experiment {
            step: reference.ts(),
            end: End::Time(steps as f64 * reference.ts()),
        }
        .checked()
        .map_err(|e| e.to_string())?;
        Ok(FmuObjective {
            reference,
            system,
            experiment,
            recording,
            fixed,
            factors,
            idle: Mutex::new(Vec::new()),
            one_at_a_time: system.once_per_process().then(|| Mutex::new(())),
        })
    }

    /// The in-process objective whose reference and score this one uses.
    pub fn reference(&self) -> &ContourObjective {
        &self.reference
    }

    /// One run of the loop with these factors: the plant's positions at t_0 … t_(n-1)
    /// with the controller's command at each.
    fn samples(&self, factors: &[f64]) -> Result<Vec<(Vector<2>, Vector<2>)>, String> {
        // A loop with an FMU that allows one instance per process runs one at a time.
        let _alone = match &self.one_at_a_time {
            Some(lock) => Some(lock.lock().map_err(|e| e.to_string())?),
            None => None,
        };
        let taken = self.idle.lock().map_err(|e| e.to_string())?.pop();
        let mut simulation = match taken {
            Some(s) => s,
            None => Simulation::new(self.system, Scheme::GaussSeidel, false)
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
            .run(&self.experiment, &start, &self.recording)
            .map_err(|e| e.to_string());
        if !simulation.fatal() {
            self.idle
                .lock()
                .map_err(|e| e.to_string())?
                .push(simulation);
        }
        let trace = trace?;
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
