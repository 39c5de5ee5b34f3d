//! One FMU instance: the model, its values, the FMI mode and the experiment's clock.
//! Every public method is one FMI function minus the C plumbing; the mode has already
//! been checked against the state machine by the caller.

use std::ffi::CString;

use super::fmu_state::{self, Snapshot};
use super::logger::{to_c_string, Category, Logger};
use super::state_machine::{Call, Mode};
use super::status::{Failure, Outcome, Status};
use crate::models::{Causality, Environment, Model, ModelInfo, Value, Values, Variability, Vr};

/// Relative tolerance when comparing the importer's communication point with our clock:
/// importers accumulate time in floating point (fmpy: 0.009999999999999998).
const TIME_TOLERANCE: f64 = 1e-9;

pub struct Instance {
    pub info: &'static ModelInfo,
    guid: String,
    environment: Environment,
    model: Box<dyn Model>,
    values: Values,
    pub mode: Mode,
    time: f64,
    stop_time: Option<f64>,
    last_successful_time: f64,
    /// Parameters or inputs changed in initialization mode since the model last
    /// initialized from them.
    needs_initialize: bool,
    pub logger: Logger,
    /// Strings handed out by the last `fmi2GetString`, valid until the next call.
    returned_strings: Vec<CString>,
}

fn time_matches(a: f64, b: f64) -> bool {
    (a - b).abs() <= TIME_TOLERANCE * a.abs().max(b.abs()).max(1.0)
}

impl Instance {
    pub fn new(info: &'static ModelInfo, environment: Environment, logger: Logger) -> Self {
        Instance {
            info,
            guid: info.guid(),
            model: (info.create)(&environment),
            environment,
            values: Values::from_table(info.variables),
            mode: Mode::Instantiated,
            time: 0.0,
            stop_time: None,
            last_successful_time: 0.0,
            needs_initialize: true,
            logger,
            returned_strings: Vec::new(),
        }
    }

    pub fn log_event(&self, message: &str) {
        self.logger.log(Status::Ok, Category::Events, message);
    }

    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Outcome {
        if !start.is_finite() {
            return Err(Failure::error(format!("start time {start} is not finite")));
        }
        if let Some(stop) = stop {
            if !(stop.is_finite() && stop >= start) {
                return Err(Failure::error(format!(
                    "stop time {stop} must be finite and not before the start time {start}"
                )));
            }
        }
        self.time = start;
        self.last_successful_time = start;
        self.stop_time = stop;
        Ok(())
    }

    pub fn enter_initialization_mode(&mut self) -> Outcome {
        self.mode = Mode::Initialization;
        self.needs_initialize = true;
        self.log_event("entered initialization mode");
        Ok(())
    }

    /// Lets the model (re)compute its state and outputs from the current parameters.
    fn initialize_if_needed(&mut self) -> Outcome {
        if self.needs_initialize {
            self.model
                .initialize(&mut self.values, self.time)
                .map_err(Failure::error)?;
            self.needs_initialize = false;
        }
        Ok(())
    }

    pub fn exit_initialization_mode(&mut self) -> Outcome {
        self.needs_initialize = true;
        self.initialize_if_needed()?;
        self.mode = Mode::StepComplete;
        self.log_event(&format!("initialized at t = {}", self.time));
        Ok(())
    }

    pub fn terminate(&mut self) -> Outcome {
        self.mode = Mode::Terminated;
        self.log_event(&format!("terminated at t = {}", self.time));
        Ok(())
    }

    /// Back to the state right after instantiation, with start values.
    pub fn reset(&mut self) -> Outcome {
        self.model = (self.info.create)(&self.environment);
        self.values = Values::from_table(self.info.variables);
        self.mode = Mode::Instantiated;
        self.time = 0.0;
        self.stop_time = None;
        self.last_successful_time = 0.0;
        self.needs_initialize = true;
        self.log_event("reset to start values");
        Ok(())
    }

    fn variable(&self, vr: u32) -> Outcome<&'static crate::models::Variable> {
        self.info
            .variable(vr as Vr)
            .ok_or_else(|| Failure::error(format!("unknown value reference {vr}")))
    }

    /// Reads values after checking every reference and type; `emit` receives them in order.
    pub fn get_values(&mut self, vrs: &[u32], mut emit: impl FnMut(usize, &Value)) -> Outcome {
        if self.mode == Mode::Initialization {
            self.initialize_if_needed()?;
        }
        for &vr in vrs {
            self.variable(vr)?;
        }
        for (i, &vr) in vrs.iter().enumerate() {
            emit(i, self.values.get(vr as Vr));
        }
        Ok(())
    }

    /// `fmi2GetReal` and friends for one type: checks the type of every reference first.
    pub fn check_type(&self, vrs: &[u32], expected: crate::models::VarType) -> Outcome {
        for &vr in vrs {
            let v = self.variable(vr)?;
            if v.var_type() != expected {
                return Err(Failure::error(format!(
                    "variable '{}' (value reference {vr}) is of type {}, not {}",
                    v.name,
                    v.var_type().name(),
                    expected.name()
                )));
            }
        }
        Ok(())
    }

    /// Keeps C copies of strings alive until the next call on this instance.
    pub fn hold_strings(&mut self, vrs: &[u32]) -> Outcome<&[CString]> {
        self.check_type(vrs, crate::models::VarType::String)?;
        if self.mode == Mode::Initialization {
            self.initialize_if_needed()?;
        }
        self.returned_strings.clear();
        for &vr in vrs {
            let text = self.values.string(vr as Vr);
            self.returned_strings.push(to_c_string(text));
        }
        Ok(&self.returned_strings)
    }

    /// Sets values atomically: every (reference, value) pair is checked against the
    /// table, the mode and the variable's bounds before any is stored, so a refused call
    /// changes nothing.
    pub fn set_values(
        &mut self,
        vrs: &[u32],
        value_at: impl Fn(usize) -> Result<Value, String>,
    ) -> Outcome {
        let mut tunable_changed = false;
        for (i, &vr) in vrs.iter().enumerate() {
            let v = self.variable(vr)?;
            let value = value_at(i).map_err(Failure::error)?;
            v.check(&value).map_err(Failure::error)?;
            match (v.causality, self.mode) {
                (Causality::Output, _) => {
                    return Err(Failure::error(format!(
                        "variable '{}' is an output and cannot be set",
                        v.name
                    )))
                }
                (Causality::Parameter, Mode::StepComplete) => {
                    if v.variability != Variability::Tunable {
                        return Err(Failure::error(format!(
                            "parameter '{}' is fixed: set it before fmi2ExitInitializationMode",
                            v.name
                        )));
                    }
                    tunable_changed = true;
                }
                _ => {}
            }
        }
        let backup = tunable_changed.then(|| self.values.clone());
        for (i, &vr) in vrs.iter().enumerate() {
            let value = value_at(i).map_err(Failure::error)?;
            self.values.set(vr as Vr, value);
        }
        if self.mode != Mode::StepComplete {
            self.needs_initialize = true;
        }
        if let Some(backup) = backup {
            if let Err(message) = self.model.parameters_changed(&mut self.values) {
                self.values = backup;
                return Err(Failure::error(message));
            }
        }
        Ok(())
    }

    pub fn do_step(&mut self, current: f64, step: f64) -> Outcome {
        if !(step.is_finite() && step > 0.0) {
            return Err(Failure::error(format!(
                "communication step size must be finite and > 0 (got {step})"
            )));
        }
        if !current.is_finite() || !time_matches(current, self.time) {
            return Err(Failure::error(format!(
                "communication point {current} does not match the instance time {}",
                self.time
            )));
        }
        let end = current + step;
        if let Some(stop) = self.stop_time {
            if end > stop && !time_matches(end, stop) {
                return Err(Failure::error(format!(
                    "step to t = {end} would pass the stop time {stop}"
                )));
            }
        }
        if let Err(message) = self.model.do_step(&mut self.values, current, step) {
            self.mode = Mode::Error;
            return Err(Failure::error(format!(
                "step at t = {current} failed: {message}"
            )));
        }
        self.time = end;
        self.last_successful_time = end;
        Ok(())
    }

    pub fn last_successful_time(&self) -> f64 {
        self.last_successful_time
    }

    pub fn snapshot(&self) -> Outcome<Vec<u8>> {
        let model = self.model.save_state().map_err(Failure::error)?;
        fmu_state::encode(&Snapshot {
            library: fmu_state::LIBRARY_VERSION.to_string(),
            guid: self.guid.clone(),
            mode: self.mode,
            time: self.time,
            stop_time: self.stop_time,
            needs_initialize: self.needs_initialize,
            values: self.values.clone(),
            model,
        })
        .map_err(Failure::error)
    }

    /// Checks that serialized bytes are a state of this model, without applying them.
    pub fn check_snapshot(&self, bytes: &[u8]) -> Outcome<Snapshot> {
        let snapshot = fmu_state::decode(bytes).map_err(Failure::error)?;
        if snapshot.guid != self.guid {
            return Err(Failure::error(format!(
                "the FMU state belongs to another model (GUID {}), not {} ({})",
                snapshot.guid, self.info.identifier, self.guid
            )));
        }
        if snapshot.library != fmu_state::LIBRARY_VERSION {
            // The GUID covers the interface, not the model's internal state layout.
            return Err(Failure::error(format!(
                "the FMU state was saved by contour-fmu {}, this is {}",
                snapshot.library,
                fmu_state::LIBRARY_VERSION
            )));
        }
        let table = self.info.variables;
        let fits = snapshot.values.len() == table.len()
            && table.iter().all(|v| {
                let value = snapshot.values.get(v.vr);
                value.var_type() == v.var_type()
                    && (v.causality == Causality::Output || v.check(value).is_ok())
            });
        if !fits || snapshot.mode == Mode::Fatal {
            return Err(Failure::error(
                "the FMU state does not fit this model's variables",
            ));
        }
        Ok(snapshot)
    }

    /// The mode after restoring a snapshot taken in `saved`: the state machine has no
    /// transition for fmi2SetFMUstate, so the mode stays, except that a snapshot is the way
    /// out of the error state. Mixing states from before and after initialization is refused.
    fn mode_after_restore(&self, saved: Mode) -> Outcome<Mode> {
        let initialized = |m: Mode| !matches!(m, Mode::Instantiated | Mode::Initialization);
        if self.mode == Mode::Error {
            return Ok(saved);
        }
        if initialized(saved) != initialized(self.mode) {
            return Err(Failure::error(format!(
                "the FMU state was saved {} initialization and cannot be restored {} it",
                if initialized(saved) {
                    "after"
                } else {
                    "before"
                },
                if initialized(self.mode) {
                    "after"
                } else {
                    "before"
                },
            )));
        }
        Ok(self.mode)
    }

    /// Restores a snapshot; nothing changes when it is refused.
    pub fn restore(&mut self, bytes: &[u8]) -> Outcome {
        let snapshot = self.check_snapshot(bytes)?;
        let mode = self.mode_after_restore(snapshot.mode)?;
        self.model
            .restore_state(&snapshot.model)
            .map_err(Failure::error)?;
        self.values = snapshot.values;
        self.mode = mode;
        self.time = snapshot.time;
        self.last_successful_time = snapshot.time;
        self.stop_time = snapshot.stop_time;
        self.needs_initialize = snapshot.needs_initialize;
        Ok(())
    }

    pub fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Outcome {
        let mut categories = Vec::with_capacity(names.len());
        for name in names {
            categories.push(Category::from_name(name).ok_or_else(|| {
                Failure::error(format!(
                    "unknown log category '{name}' (known: logEvents, logStatusWarning, \
                     logStatusError, logStatusFatal, logAll)"
                ))
            })?);
        }
        self.logger.set(on, &categories);
        Ok(())
    }

    /// Logs a failed call with the function's name and returns its status code.
    pub fn report(&self, call: Call, failure: &Failure) -> Status {
        self.logger.log(
            failure.status,
            Category::for_status(failure.status),
            &format!("{}: {}", call.name(), failure.message),
        );
        failure.status
    }
}
