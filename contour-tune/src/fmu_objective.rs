//! The tuner's objective through FMUs: every candidate's closed loop runs through the
//! loop of an SSP file (the user's own plant FMU, say) in contour-cosim, and its actual
//! positions are judged as the in-process objective judges its own (the same reference,
//! true error and score: [`Simulator::metrics_of`](contour_core::sim::Simulator::metrics_of)).
//! A loop that reproduces the in-process simulator therefore scores every candidate bit
//! for bit alike, and the swarm takes the same path.
//!
//! The instances are made once per evaluating thread and reset between runs (fmi2Reset).

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
            ],
        )
        .map_err(|e| format!("the loop: {e}"))?;
        // The run's samples t_0 … t_(n-1), as the in-process run has them.
        let steps = reference.simulator().samples().saturating_sub(1).max(1);
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
        })
    }

    /// The in-process objective whose reference and score this one uses.
    pub fn reference(&self) -> &ContourObjective {
        &self.reference
    }

    /// One run of the loop with these factors: the plant's positions at t_0 … t_(n-1).
    fn positions(&self, factors: &[f64]) -> Result<Vec<Vector<2>>, String> {
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
        self.idle
            .lock()
            .map_err(|e| e.to_string())?
            .push(simulation);
        let trace = trace?;
        Ok((0..=trace.steps)
            .map(|k| Vector::<2>::new(trace.row(k)[0], trace.row(k)[1]))
            .collect())
    }

    /// The fitness (mm) of these factors, as [`ContourObjective::evaluate`] gives it; a run
    /// the FMUs end (an error) scores as a run that cannot start.
    pub fn evaluate(&self, factors: &[f64]) -> f64 {
        match self.positions(factors) {
            Ok(positions) => self
                .reference
                .score(&self.reference.simulator().metrics_of(positions)),
            Err(_) => 2.0 * PENALTY_MM,
        }
    }
}
