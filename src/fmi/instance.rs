//! One FMU instance: the model, its values, the FMI mode and the experiment's clock.
//! Every public method is one FMI function minus the C plumbing; the mode has already
//! been checked against the state machine by the caller.

use std::ffi::CString;

use super::fmu_state::{self, Snapshot, States};
use super::logger::{to_c_string, Category, Logger};
use super::standard::Standard;
use super::state_machine::{Call, Mode};
use super::status::{Failure, Outcome, Status};
use crate::framework::interface::Interface;
use crate::framework::model::{Environment, Model, ModelInfo};
use crate::framework::variables::{Causality, Value, Values, VarType, Variability, Variable, Vr};

/// Relative tolerance when comparing the importer's communication point with our clock:
/// importers accumulate time in floating point (fmpy: 0.009999999999999998).
const TIME_TOLERANCE: f64 = 1e-9;

/// What the per-sample calls need to know of a variable, by value reference (see
/// [`Access::of`]): one byte instead of the table's row, checked once per value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Access(u8);

impl Access {
    /// A Real variable: `fmi2GetReal` reads it as it is.
    const REAL: u8 = 1;
    /// A Real input without bounds: `fmi2SetReal` stores any finite value in any mode
    /// that allows the call, without telling the model (see [`Instance::set_reals`]).
    const FREE_REAL_INPUT: u8 = 2;

    fn of(v: &Variable) -> Access {
        let real = v.var_type() == VarType::Real;
        let free_input =
            real && v.causality == Causality::Input && v.min.is_none() && v.max.is_none();
        Access(
            if real { Self::REAL } else { 0 } | if free_input { Self::FREE_REAL_INPUT } else { 0 },
        )
    }

    fn has(self, flag: u8) -> bool {
        self.0 & flag != 0
    }
}

pub struct Instance {
    pub info: &'static ModelInfo,
    /// The standard whose functions made the instance, the only ones it answers.
    pub standard: Standard,
    /// [`Access`] of every variable, by value reference.
    access: Box<[Access]>,
    /// The Real outputs, in table order: checked for overflow after each step.
    real_outputs: Box<[Vr]>,
    /// The variables as the interface declares them (units, bounds): what `fmi2Set*`
    /// checks. `values` hold the model's units; `info.variables` checks them.
    variables: &'static [Variable],
    /// Interface value = model value × scale, by value reference.
    scale: &'static [f64],
    /// Whether the interface scales any value (an SI build with lengths).
    converts: bool,
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
    /// The live FMU states of this instance; they die with it.
    pub states: States,
}

fn time_matches(a: f64, b: f64) -> bool {
    // max(|a|, |b|, 1) by comparisons: `f64::max` spends instructions on NaN, but with a
    // NaN the left side is NaN and the answer false whatever the scale.
    let (a_abs, b_abs) = (a.abs(), b.abs());
    let scale = if a_abs > b_abs { a_abs } else { b_abs };
    let scale = if scale > 1.0 { scale } else { 1.0 };
    (a - b).abs() <= TIME_TOLERANCE * scale
}

impl Instance {
    /// An instance of `interface`'s model that speaks the interface's units.
    pub fn with_interface(
        standard: Standard,
        interface: &'static Interface,
        environment: Environment,
        logger: Logger,
        name: &str,
    ) -> Self {
        let info = interface.model;
        Instance {
            info,
            standard,
            access: interface.variables.iter().map(Access::of).collect(),
            real_outputs: info
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output && v.var_type() == VarType::Real)
                .map(|v| v.vr)
                .collect(),
            variables: &interface.variables,
            scale: &interface.scale,
            converts: interface.converts(),
            guid: interface.guid.clone(),
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
            states: States::new(name, standard.fmu_state_argument()),
        }
    }

    /// The instance is in the registry as `handle` (its `fmi2Component`), the owner of
    /// the FMU states it makes.
    pub fn registered_as(&mut self, handle: usize) {
        self.states.registered_as(handle);
    }

    pub fn log_event(&self, message: &str) {
        self.logger.log(Status::Ok, Category::Events, message);
    }

    /// A warning about a call that still succeeds (category logStatusWarning).
    pub fn log_warning(&self, message: &str) {
        self.logger
            .log(Status::Warning, Category::StatusWarning, message);
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
            if let Err(message) = self.model.initialize(&mut self.values, self.time) {
                return Err(Failure::error(self.in_model_units(message)));
            }
            self.needs_initialize = false;
            for warning in self.model.take_warnings() {
                self.log_warning(&self.in_model_units(warning));
            }
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

    /// The variable as the interface declares it.
    fn variable(&self, vr: u32) -> Outcome<&'static crate::framework::variables::Variable> {
        self.variables
            .get(vr as usize)
            .ok_or_else(|| Failure::error(format!("unknown value reference {vr}")))
    }

    /// A value in the model's units from the interface's.
    fn to_model(&self, vr: Vr, value: Value) -> Value {
        match value {
            Value::Real(x) => Value::Real(x / self.scale[vr]),
            other => other,
        }
    }

    /// A value in the interface's units from the model's.
    fn to_interface(&self, vr: Vr, value: &Value) -> Value {
        match *value {
            Value::Real(x) => Value::Real(x * self.scale[vr]),
            ref other => other.clone(),
        }
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
            emit(i, &self.to_interface(vr as Vr, self.values.get(vr as Vr)));
        }
        Ok(())
    }

    /// `fmi2GetReal` and friends for one type: checks the type of every reference first.
    pub fn check_type(
        &self,
        vrs: &[u32],
        expected: crate::framework::variables::VarType,
    ) -> Outcome {
        for &vr in vrs {
            if !self.variable(vr).is_ok_and(|v| v.var_type() == expected) {
                return Err(self.wrong_type(vr, self.type_name(expected)));
            }
        }
        Ok(())
    }

    /// The value reference of FMI 3.0's independent variable `time`: the first after the
    /// table's.
    pub fn time_vr(&self) -> u32 {
        self.variables.len() as u32
    }

    /// The instance's time (s): the start time until the first step, then the end of the
    /// last successful one.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// FMI 3.0's integer types: an Enumeration is read and written as Int64 (`enumeration`
    /// true), every other Integer as Int32. Checks every reference first, as `check_type`.
    pub fn check_fmi3_integers(&self, vrs: &[u32], enumeration: bool) -> Outcome {
        let wanted = if enumeration { "Int64" } else { "Int32" };
        for &vr in vrs {
            let fits = self.variable(vr).is_ok_and(|v| {
                v.var_type() == VarType::Integer && v.enumeration.is_some() == enumeration
            });
            if !fits {
                return Err(self.wrong_type(vr, wanted));
            }
        }
        Ok(())
    }

    /// The refusal of a value reference through a getter or setter of another type
    /// (`wanted`, in the instance's standard's names): unknown, or of another type; in FMI
    /// 3.0 also the independent variable `time`, a Float64 of its own.
    pub fn wrong_type(&self, vr: u32, wanted: &str) -> Failure {
        if self.standard == Standard::Fmi3 && vr == self.time_vr() {
            return Failure::error(format!(
                "variable 'time' (value reference {vr}) is of type Float64, not {wanted}"
            ));
        }
        match self.variable(vr) {
            Err(unknown) => unknown,
            Ok(v) => Failure::error(format!(
                "variable '{}' (value reference {vr}) is of type {}, not {wanted}",
                v.name,
                self.variable_type_name(v)
            )),
        }
    }

    /// A type's name in the instance's standard (in FMI 3.0 an Integer that is no
    /// enumeration is an Int32).
    fn type_name(&self, var_type: VarType) -> &'static str {
        match (self.standard, var_type) {
            (Standard::Fmi2, _) => var_type.name(),
            (Standard::Fmi3, VarType::Real) => "Float64",
            (Standard::Fmi3, VarType::Integer) => "Int32",
            (Standard::Fmi3, VarType::Boolean) => "Boolean",
            (Standard::Fmi3, VarType::String) => "String",
        }
    }

    /// A variable's type in the instance's standard: FMI 3.0 reads an enumeration as Int64.
    fn variable_type_name(&self, v: &Variable) -> &'static str {
        match (self.standard, v.enumeration) {
            (Standard::Fmi3, Some(_)) => "Enumeration (Int64)",
            _ => self.type_name(v.var_type()),
        }
    }

    /// Whether every reference is a Real variable.
    #[inline]
    fn all_real(&self, vrs: &[u32]) -> bool {
        vrs.iter().all(|&vr| {
            self.access
                .get(vr as usize)
                .is_some_and(|a| a.has(Access::REAL))
        })
    }

    /// `fmi2GetReal` in the sample's case only: every reference a Real, and not in
    /// initialization mode (where a read may initialize the model first). Reads the
    /// values and returns `Some`; `None`, having written nothing, for any other call.
    #[inline]
    pub fn get_real_values(&self, vrs: &[u32], out: &mut [f64]) -> Option<()> {
        if self.mode == Mode::Initialization || !self.all_real(vrs) {
            return None;
        }
        for (slot, &vr) in out.iter_mut().zip(vrs) {
            *slot = self.values.real(vr as Vr) * self.scale[vr as usize];
        }
        Some(())
    }

    /// `fmi2GetReal`: [`Instance::check_type`] then [`Instance::get_values`], with one
    /// byte per value to check when every reference is a Real (the sample's case).
    #[inline]
    pub fn get_reals(&mut self, vrs: &[u32], out: &mut [f64]) -> Outcome {
        if !self.all_real(vrs) {
            return self.get_values_checked(vrs, VarType::Real, |i, v| match *v {
                Value::Real(x) => out[i] = x,
                _ => unreachable!("type checked"),
            });
        }
        if self.mode == Mode::Initialization {
            self.initialize_if_needed()?;
        }
        for (slot, &vr) in out.iter_mut().zip(vrs) {
            *slot = self.values.real(vr as Vr) * self.scale[vr as usize];
        }
        Ok(())
    }

    /// `fmi2SetReal` in the sample's case only: every reference a Real input without
    /// bounds and every value finite. Then [`Instance::set_values`] would find nothing to
    /// refuse and no parameter to pass on to the model: it would store the values in
    /// order and mark the model for initialization outside step mode, which is what this
    /// does, returning `Some`; `None`, having changed nothing, for any other call.
    #[inline]
    pub fn set_free_reals(&mut self, vrs: &[u32], values: &[f64]) -> Option<()> {
        // Finite in the model's units too: a finite value in m can overflow in mm. An
        // interface that converts nothing divides by nothing (x / 1 is x).
        let model_value = |vr: u32, x: f64| {
            if self.converts {
                x / self.scale[vr as usize]
            } else {
                x
            }
        };
        let free = vrs.len() == values.len()
            && vrs.iter().zip(values).all(|(&vr, &x)| {
                self.access
                    .get(vr as usize)
                    .is_some_and(|a| a.has(Access::FREE_REAL_INPUT))
                    && model_value(vr, x).is_finite()
            });
        if !free {
            return None;
        }
        for (&vr, &x) in vrs.iter().zip(values) {
            let value = model_value(vr, x);
            self.values.set_real(vr as Vr, value);
        }
        if self.mode != Mode::StepComplete {
            self.needs_initialize = true;
        }
        Some(())
    }

    /// `fmi2SetReal`: [`Instance::set_free_reals`] for the sample's case, else
    /// [`Instance::set_values`].
    #[inline]
    pub fn set_reals(&mut self, vrs: &[u32], values: &[f64]) -> Outcome {
        match self.set_free_reals(vrs, values) {
            Some(()) => Ok(()),
            None => self.set_values_cold(vrs, |i| Ok(Value::Real(values[i]))),
        }
    }

    /// [`Instance::check_type`] then [`Instance::get_values`] (out of line: the general
    /// case of the getters, and `fmi2GetReal`'s refusals).
    #[inline(never)]
    pub fn get_values_checked(
        &mut self,
        vrs: &[u32],
        var_type: VarType,
        emit: impl FnMut(usize, &Value),
    ) -> Outcome {
        self.check_type(vrs, var_type)?;
        self.get_values(vrs, emit)
    }

    /// [`Instance::set_values`], out of line (for `set_reals`: not the sample's case).
    #[cold]
    #[inline(never)]
    fn set_values_cold(
        &mut self,
        vrs: &[u32],
        value_at: impl Fn(usize) -> Result<Value, String>,
    ) -> Outcome {
        self.set_values(vrs, value_at)
    }

    /// Keeps C copies of strings alive until the next call on this instance.
    pub fn hold_strings(&mut self, vrs: &[u32]) -> Outcome<&[CString]> {
        self.check_type(vrs, crate::framework::variables::VarType::String)?;
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
            // And in the model's units, as a saved state is checked: a finite value in m
            // can overflow in mm, a bound can round across.
            if let Err(e) = self.info.variables[vr as usize].check(&self.to_model(vr as Vr, value))
            {
                return Err(Failure::error(self.in_model_units(e)));
            }
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
                            "parameter '{}' is fixed: set it before {}ExitInitializationMode",
                            v.name,
                            self.standard.prefix()
                        )));
                    }
                    tunable_changed = true;
                }
                _ => {}
            }
        }
        let backup = tunable_changed.then(|| self.values.clone());
        for (i, &vr) in vrs.iter().enumerate() {
            let value = self.to_model(vr as Vr, value_at(i).map_err(Failure::error)?);
            self.values.set(vr as Vr, value);
        }
        if self.mode != Mode::StepComplete {
            self.needs_initialize = true;
        }
        if let Some(backup) = backup {
            if let Err(message) = self.model.parameters_changed(&mut self.values) {
                self.values = backup;
                return Err(Failure::error(self.in_model_units(message)));
            }
        }
        Ok(())
    }

    /// A model's message as the importer should read it: the model speaks mm, so in an
    /// interface that scales lengths a message with numbers says which unit they are in
    /// (the interface cannot tell a length from a count inside the text).
    fn in_model_units(&self, message: String) -> String {
        if self.converts && message.contains(|c: char| c.is_ascii_digit()) {
            message + " (lengths in this message in mm, the model's own unit: 1 mm = 0.001 m)"
        } else {
            message
        }
    }

    /// `fmi2DoStep`. The checks of the arguments run first, as one condition; a step they
    /// refuse is explained by [`Instance::refuse_step`], out of line.
    #[inline]
    pub fn do_step(&mut self, current: f64, step: f64) -> Outcome {
        let end = current + step;
        let acceptable = step.is_finite()
            && step > 0.0
            && current.is_finite()
            && time_matches(current, self.time)
            && end - current >= 0.5 * step
            && self
                .stop_time
                .is_none_or(|stop| end <= stop || time_matches(end, stop));
        if !acceptable {
            return Err(self.refuse_step(current, step));
        }
        // Refused before anything changes: the mode stays.
        if let Err(e) = self.model.check_step(current, step) {
            return Err(Failure::error(format!(
                "communication step size {step:e} s refused: {e}"
            )));
        }
        if let Err(message) = self.model.do_step(&mut self.values, current, step) {
            self.mode = Mode::Error;
            return Err(Failure::error(format!(
                "step at t = {current} failed: {}",
                self.in_model_units(message)
            )));
        }
        for warning in self.model.take_warnings() {
            self.log_warning(&self.in_model_units(warning));
        }
        // Never report success with a non-finite output: parameters at the edge of f64
        // (an inertia of 1e-300) can overflow a model, the importer would carry the NaN
        // on, and a state saved now could not be restored.
        for &vr in self.real_outputs.iter() {
            if !matches!(self.values.get(vr), Value::Real(x) if x.is_finite()) {
                return Err(self.overflowed(current, vr));
            }
        }
        self.time = end;
        self.last_successful_time = end;
        Ok(())
    }

    /// Why `do_step` refused its arguments: the first of its checks that fails.
    #[cold]
    #[inline(never)]
    fn refuse_step(&self, current: f64, step: f64) -> Failure {
        if !(step.is_finite() && step > 0.0) {
            return Failure::error(format!(
                "communication step size must be finite and > 0 (got {step})"
            ));
        }
        if !current.is_finite() || !time_matches(current, self.time) {
            return Failure::error(format!(
                "communication point {current} does not match the instance time {}",
                self.time
            ));
        }
        let end = current + step;
        // Far from t = 0 a step can vanish in rounding (1e300 + 1e-3 == 1e300): a sampled
        // model would then wait for ever for its next sample to fall due.
        if end - current < 0.5 * step {
            return Failure::error(format!(
                "communication step size {step:e} s is lost in the rounding of the time \
                 {current:e} s"
            ));
        }
        let stop = self.stop_time.unwrap_or(f64::NAN);
        Failure::error(format!("step to t = {end} would pass the stop time {stop}"))
    }

    /// The failure of a step that left the output `vr` non-finite.
    #[cold]
    #[inline(never)]
    fn overflowed(&mut self, current: f64, vr: Vr) -> Failure {
        let v = &self.info.variables[vr];
        self.mode = Mode::Error;
        Failure::error(format!(
            "step at t = {current} failed: output '{}' = {} is not finite (the model \
             overflowed: check the parameters and inputs)",
            v.name,
            self.values.real(v.vr)
        ))
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

    /// Checks that serialized bytes are a state of this model, without applying them: the
    /// envelope (magic, format, checksum), the GUID, every variable value like a `fmi2Set`
    /// would, and the model's internal state (its layout version, then its values).
    pub fn check_snapshot(&self, bytes: &[u8]) -> Outcome<Snapshot> {
        let snapshot = self.check_envelope(bytes)?;
        self.model
            .check_state(&snapshot.model, snapshot.time)
            .map_err(|e| invalid_model_state(&snapshot, e))?;
        Ok(snapshot)
    }

    /// [`Instance::check_snapshot`] without the model's internal state.
    fn check_envelope(&self, bytes: &[u8]) -> Outcome<Snapshot> {
        let snapshot = fmu_state::decode(bytes).map_err(Failure::error)?;
        if snapshot.guid != self.guid {
            return Err(Failure::error(format!(
                "the FMU state belongs to another model or interface (GUID {}), not this {} ({})",
                snapshot.guid, self.info.identifier, self.guid
            )));
        }
        let table = self.info.variables;
        if snapshot.values.len() != table.len() {
            return Err(Failure::error(
                "the FMU state does not fit this model's variables",
            ));
        }
        for v in table {
            let value = snapshot.values.get(v.vr);
            if value.var_type() != v.var_type() {
                return Err(Failure::error(format!(
                    "the FMU state does not fit this model's variables ('{}' is not a {})",
                    v.name,
                    v.var_type().name()
                )));
            }
            if v.causality != Causality::Output {
                v.check(value)
                    .map_err(|e| Failure::error(format!("the FMU state is invalid: {e}")))?;
            }
        }
        if snapshot.mode == Mode::Fatal {
            return Err(Failure::error(
                "the FMU state was saved after a fatal error",
            ));
        }
        if !snapshot.time.is_finite() || snapshot.stop_time.is_some_and(|t| !t.is_finite()) {
            return Err(Failure::error(format!(
                "the FMU state is invalid: time {} / stop time {:?} not finite",
                snapshot.time, snapshot.stop_time
            )));
        }
        Ok(snapshot)
    }

    /// Restores a snapshot with everything it holds, the mode included (as the Reference
    /// FMUs do): a state saved while stepping can be set into a freshly instantiated
    /// instance, which then steps on without initialization (fmusim's
    /// `--initial-fmu-state-file`), and an instance that set a state continues exactly as
    /// the one that saved it. Nothing changes when it is refused.
    pub fn restore(&mut self, bytes: &[u8]) -> Outcome {
        // The model's state is decoded once: restore_state checks what check_state would
        // and changes nothing when it refuses.
        let snapshot = self.check_envelope(bytes)?;
        self.model
            .restore_state(&snapshot.model, snapshot.time)
            .map_err(|e| invalid_model_state(&snapshot, e))?;
        self.values = snapshot.values;
        self.mode = snapshot.mode;
        self.time = snapshot.time;
        self.last_successful_time = snapshot.time;
        self.stop_time = snapshot.stop_time;
        self.needs_initialize = snapshot.needs_initialize;
        Ok(())
    }

    /// Restores one of this instance's FMU states.
    pub fn restore_state(&mut self, handle: usize) -> Outcome {
        let bytes = self.states.bytes(handle)?.to_vec();
        self.restore(&bytes)
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
            &format!("{}: {}", call.name(self.standard), failure.message),
        );
        failure.status
    }
}

/// The refusal of a snapshot whose model state is invalid, naming the build that saved it.
fn invalid_model_state(snapshot: &Snapshot, e: String) -> Failure {
    Failure::error(format!(
        "the FMU state is invalid (saved by contour-fmu {}): {e}",
        snapshot.library
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::framework::model::Environment;
    use crate::models::path_interpolator_2d;

    fn started_at(start: f64) -> Instance {
        let logger = Logger::new(None, std::ptr::null_mut(), "t", false);
        let interface = crate::models::interface(
            &path_interpolator_2d::INFO,
            crate::framework::interface::UnitSystem::Millimetre,
        );
        let mut instance = Instance::with_interface(
            Standard::Fmi2,
            interface,
            Environment::default(),
            logger,
            "t",
        );
        instance.setup_experiment(start, None).unwrap();
        instance.enter_initialization_mode().unwrap();
        instance.exit_initialization_mode().unwrap();
        instance
    }

    /// At t = 1e300 a 1 ms step is lost in rounding; the interpolator used to loop for
    /// ever waiting for a sample that never fell due.
    #[test]
    fn a_step_lost_in_the_rounding_of_the_time_is_refused() {
        let mut far = started_at(1e300);
        let failure = far.do_step(1e300, 1e-3).unwrap_err();
        assert!(failure.message.contains("rounding"), "{}", failure.message);
        assert_eq!(far.mode, Mode::StepComplete);
        assert_eq!(
            started_at(0.0).do_step(0.0, 1e-3).map_err(|f| f.message),
            Ok(())
        );
    }
}
