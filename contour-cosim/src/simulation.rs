//! Runs a loop: one instance per unit, made once and reset between runs (fmi2Reset), stepped
//! with a fixed communication step from t = 0 in one of two coupling schemes:
//!
//! - Gauss-Seidel: the units step one after another in the loop's order, each unit's inputs
//!   set from their sources just before it steps (controller, plant, interpolator: the
//!   controller acts on the reference and position at t_k, the plant integrates its command
//!   over [t_k, t_k+1)).
//! - Jacobi: every input set from the outputs at t_k, then every unit steps (what libcosim
//!   does; one step of delay per link).
//!
//! The calls are those of `contour_fmu.master` (Python, on fmpy), in the same order with
//! the same arguments, so both give the same trajectories bit for bit. t_k = k·h, from the
//! integer step count, never a running sum. Nothing is allocated while stepping.

use std::str::FromStr;
use std::sync::Arc;

use crate::fmi2::{Activity, CallFailed, Instance};
use crate::model_description::VariableType;
use crate::ssp::Value;
use crate::system::{Resolved, System};
use crate::Error;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scheme {
    GaussSeidel,
    Jacobi,
}

impl FromStr for Scheme {
    type Err = Error;
    fn from_str(text: &str) -> Result<Scheme, Error> {
        match text {
            "gauss-seidel" => Ok(Scheme::GaussSeidel),
            "jacobi" => Ok(Scheme::Jacobi),
            other => Err(Error::Refused(format!(
                "unknown coupling scheme {other:?}; expected gauss-seidel or jacobi"
            ))),
        }
    }
}

/// When a run ends.
#[derive(Clone, Debug, PartialEq)]
pub enum End {
    /// At this time (rounded to a whole number of steps); passed to fmi2SetupExperiment.
    Time(f64),
    /// `settle` seconds after the first step at which the Boolean `signal` (e.g. the
    /// interpolator's `done`) is true; a run whose signal stays false until `max_stop`
    /// fails. No stop time is passed to fmi2SetupExperiment.
    Signal {
        signal: Resolved,
        settle: f64,
        max_stop: f64,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    pub step: f64,
    pub end: End,
}

impl Experiment {
    /// The most rows a run's trace can have.
    pub fn longest(&self) -> usize {
        match &self.end {
            End::Time(stop) => self.steps(*stop) + 1,
            End::Signal {
                settle, max_stop, ..
            } => self.steps(*max_stop) + self.steps(*settle) + 1,
        }
    }

    /// Refuses a trace of `columns` that could hold more than `MAX_VALUES` values.
    pub fn check_trace(&self, columns: usize) -> Result<(), Error> {
        if self.longest().saturating_mul(columns) > MAX_VALUES {
            return Err(Error::Refused(format!(
                "{} rows of {columns} recorded columns is more than {MAX_VALUES} values; record fewer columns or a shorter run",
                self.longest()
            )));
        }
        Ok(())
    }

    /// Refuses a step or an end that is not a positive finite number of seconds, or that
    /// would take more than `MAX_STEPS` steps.
    pub fn checked(self) -> Result<Experiment, Error> {
        let positive = |what: &str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(Error::Refused(format!(
                    "the {what} must be a positive number of seconds, not {value}"
                )))
            }
        };
        positive("communication step", self.step)?;
        let last = match &self.end {
            End::Time(stop) => {
                positive("stop time", *stop)?;
                *stop
            }
            End::Signal {
                signal,
                settle,
                max_stop,
            } => {
                if signal.kind != VariableType::Boolean {
                    return Err(Error::Refused(format!(
                        "the end signal must be a Boolean, not a {}",
                        signal.kind.name()
                    )));
                }
                positive("longest run (max stop)", *max_stop)?;
                if !(settle.is_finite() && *settle >= 0.0) {
                    return Err(Error::Refused(format!(
                        "the settling time must be zero or more seconds, not {settle}"
                    )));
                }
                max_stop + settle
            }
        };
        if last / self.step > MAX_STEPS as f64 {
            return Err(Error::Refused(format!(
                "{last} s in steps of {} s is more than {MAX_STEPS} steps",
                self.step
            )));
        }
        Ok(self)
    }

    /// Whole steps in `seconds`, halves to even as Python's round() (the Python masters
    /// count steps with it).
    fn steps(&self, seconds: f64) -> usize {
        (seconds / self.step).round_ties_even() as usize
    }
}

/// The longest run, in steps.
pub const MAX_STEPS: usize = 10_000_000;
/// The most values a run's trace may hold (steps + 1 rows × columns): 800 MB.
pub const MAX_VALUES: usize = 100_000_000;
/// Values reserved for a trace up front, at most.
const RESERVED_VALUES: usize = 1 << 24;

/// Values recorded at every t_k of a run, t_0 to t_n (after the last step): row k holds
/// every column at t_k, before the step from t_k.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    pub step: f64,
    pub columns: Vec<String>,
    /// Steps taken (rows: steps + 1).
    pub steps: usize,
    /// Row-major.
    pub values: Vec<f64>,
}

impl Trace {
    pub fn row(&self, k: usize) -> &[f64] {
        &self.values[k * self.columns.len()..(k + 1) * self.columns.len()]
    }
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.columns.iter().position(|c| c == name)?;
        Some(
            self.values
                .iter()
                .skip(i)
                .step_by(self.columns.len())
                .copied()
                .collect(),
        )
    }
}

/// Consecutive variables of one unit and type, read or written with one call.
#[derive(Clone, Debug)]
struct Group {
    unit: usize,
    kind: VariableType,
    value_references: Vec<u32>,
}

/// Groups `variables` in their order; a new group starts where the unit or type changes.
fn grouped(variables: impl IntoIterator<Item = Resolved>) -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    for v in variables {
        match groups.last_mut() {
            Some(g) if g.unit == v.unit && g.kind == v.kind => {
                g.value_references.push(v.value_reference)
            }
            _ => groups.push(Group {
                unit: v.unit,
                kind: v.kind,
                value_references: vec![v.value_reference],
            }),
        }
    }
    groups
}

/// Connections from one unit to another, of one type: one get and one set.
#[derive(Clone, Debug)]
struct Transfer {
    from: Group,
    to: Group,
}

fn transfers(connections: &[(Resolved, Resolved)]) -> Vec<Transfer> {
    let mut out: Vec<Transfer> = Vec::new();
    for (from, to) in connections {
        match out.last_mut() {
            Some(t)
                if t.from.unit == from.unit
                    && t.to.unit == to.unit
                    && t.from.kind == from.kind
                    && from.unit != to.unit =>
            {
                t.from.value_references.push(from.value_reference);
                t.to.value_references.push(to.value_reference);
            }
            _ => out.push(Transfer {
                from: Group {
                    unit: from.unit,
                    kind: from.kind,
                    value_references: vec![from.value_reference],
                },
                to: Group {
                    unit: to.unit,
                    kind: to.kind,
                    value_references: vec![to.value_reference],
                },
            }),
        }
    }
    out
}

/// The variables a run records, resolved once.
pub struct Recording {
    columns: Vec<String>,
    groups: Vec<Group>,
}

impl Recording {
    /// `columns` as (unit, variable); Real, Integer and Boolean variables (as numbers).
    pub fn new(system: &System, columns: &[(String, String)]) -> Result<Recording, Error> {
        let mut resolved = Vec::new();
        for (unit, name) in columns {
            let variable = system.resolve(unit, name)?;
            if variable.kind == VariableType::String {
                return Err(Error::Refused(format!(
                    "{unit}.{name} is a String; only numbers are recorded"
                )));
            }
            resolved.push(variable);
        }
        Ok(Recording {
            columns: columns.iter().map(|(u, n)| format!("{u}.{n}")).collect(),
            groups: grouped(resolved),
        })
    }

    /// The columns' names, "unit.variable".
    pub fn columns(&self) -> &[String] {
        &self.columns
    }
}

/// Scratch space for transfers and reads, sized once.
#[derive(Default)]
struct Buffers {
    reals: Vec<f64>,
    integers: Vec<i32>,
}

impl Buffers {
    fn fit(&mut self, groups: impl Iterator<Item = usize>) {
        let most = groups.max().unwrap_or(0);
        self.reals.resize(most.max(self.reals.len()), 0.0);
        self.integers.resize(most.max(self.integers.len()), 0);
    }
}

/// The instances of a loop, made once and reused run after run.
pub struct Simulation<'a> {
    system: &'a System,
    scheme: Scheme,
    instances: Vec<Instance>,
    activity: Arc<Activity>,
    echo: bool,
    /// Instances that have run and need fmi2Reset before the next run.
    used: bool,
    first: Vec<Transfer>,
    before_step: Vec<Vec<Transfer>>,
    buffers: Buffers,
}

impl<'a> Simulation<'a> {
    /// Instantiates every unit of `system`, in the step order. `echo` prints what the
    /// FMUs log on stderr (otherwise it only goes into the messages of failed runs).
    pub fn new(system: &'a System, scheme: Scheme, echo: bool) -> Result<Simulation<'a>, Error> {
        Simulation::watched(system, scheme, echo, Arc::new(Activity::default()))
    }

    /// As `new`, counting the FMU calls in `activity` (which a watchdog may already watch).
    pub fn watched(
        system: &'a System,
        scheme: Scheme,
        echo: bool,
        activity: Arc<Activity>,
    ) -> Result<Simulation<'a>, Error> {
        let (first, before_step) = match scheme {
            Scheme::Jacobi => (
                transfers(&system.connections),
                vec![Vec::new(); system.units.len()],
            ),
            Scheme::GaussSeidel => (
                Vec::new(),
                (0..system.units.len())
                    .map(|unit| {
                        let into: Vec<_> = system
                            .connections
                            .iter()
                            .filter(|(_, to)| to.unit == unit)
                            .copied()
                            .collect();
                        transfers(&into)
                    })
                    .collect(),
            ),
        };
        let mut buffers = Buffers::default();
        buffers.fit(
            first
                .iter()
                .chain(before_step.iter().flatten())
                .map(|t| t.from.value_references.len()),
        );
        let mut simulation = Simulation {
            system,
            scheme,
            instances: Vec::new(),
            activity,
            echo,
            used: false,
            first,
            before_step,
            buffers,
        };
        simulation.instantiate()?;
        Ok(simulation)
    }

    pub fn scheme(&self) -> Scheme {
        self.scheme
    }

    /// The count of FMU calls made (odd while one is under way), for a watchdog.
    pub fn activity(&self) -> Arc<Activity> {
        self.activity.clone()
    }

    fn instantiate(&mut self) -> Result<(), Error> {
        // All or none: a unit that fails leaves no half-made set behind.
        self.instances.clear();
        self.used = false;
        let mut instances = Vec::with_capacity(self.system.units.len());
        for unit in &self.system.units {
            let fmu = &unit.fmu;
            let instance = Instance::new(
                fmu.library.clone(),
                &unit.name,
                &fmu.description.guid,
                &fmu.resources(),
                self.activity.clone(),
                self.echo,
            )
            .map_err(|why| Error::Failed(format!("{}: {why}", unit.name)))?;
            instances.push(instance);
        }
        self.instances = instances;
        Ok(())
    }

    /// Whether a call of one of the loop's FMUs returned fmi2Fatal: none of that FMU's
    /// functions may be called again in this process.
    pub fn fatal(&self) -> bool {
        self.system
            .units
            .iter()
            .any(|u| crate::fmi2::is_fatal(&u.fmu.library))
    }

    /// A failed call as the run's error: the unit, the call, its status, when, and the
    /// last messages the unit's FMU logged.
    fn failed(&self, unit: usize, failure: CallFailed, time: Option<f64>) -> Error {
        let messages: Vec<String> = self.instances.get(unit).map_or_else(Vec::new, |i| {
            i.messages()
                .iter()
                .rev()
                .take(3)
                .rev()
                .map(|m| format!("{}: {}", m.status, m.text))
                .collect()
        });
        let at = time.map_or_else(String::new, |t| format!(" at t = {t}"));
        let said = if messages.is_empty() {
            String::new()
        } else {
            format!(" ({})", messages.join("; "))
        };
        Error::Failed(format!(
            "{}: {} returned {}{at}{said}",
            self.system.units[unit].name, failure.call, failure.status
        ))
    }

    /// One run from t = 0 with `start_values` (from `System::start_values`) set in
    /// initialization mode, then the loop's initial copies; returns the `recording`'s
    /// values at every step. After a failed run the instances are made anew for the next.
    pub fn run(
        &mut self,
        experiment: &Experiment,
        start_values: &[(Resolved, Value)],
        recording: &Recording,
    ) -> Result<Trace, Error> {
        if self.instances.is_empty() {
            self.instantiate()?;
        }
        let result = self.run_once(experiment, start_values, recording);
        if result.is_err() {
            // Drop now: the next run starts from fresh instances.
            self.instances.clear();
        }
        result
    }

    fn run_once(
        &mut self,
        experiment: &Experiment,
        start_values: &[(Resolved, Value)],
        recording: &Recording,
    ) -> Result<Trace, Error> {
        for instance in &self.instances {
            instance.clear_messages();
        }
        if std::mem::replace(&mut self.used, true) {
            for unit in 0..self.instances.len() {
                self.instances[unit]
                    .reset()
                    .map_err(|f| self.failed(unit, f, None))?;
            }
        }
        let stop = match experiment.end {
            End::Time(stop) => Some(stop),
            End::Signal { .. } => None,
        };
        for unit in 0..self.instances.len() {
            let instance = &mut self.instances[unit];
            let mut done = instance
                .setup_experiment(0.0, stop)
                .and_then(|()| instance.enter_initialization_mode());
            for (target, value) in start_values.iter().filter(|(t, _)| t.unit == unit) {
                done = done.and_then(|()| set(instance, target.value_reference, value));
            }
            done.map_err(|f| self.failed(unit, f, None))?;
        }
        for (from, to) in &self.system.initial_copies {
            let value = self
                .get(*from)
                .map_err(|f| self.failed(from.unit, f, None))?;
            set(&mut self.instances[to.unit], to.value_reference, &value)
                .map_err(|f| self.failed(to.unit, f, None))?;
        }
        for unit in 0..self.instances.len() {
            self.instances[unit]
                .exit_initialization_mode()
                .map_err(|f| self.failed(unit, f, None))?;
        }
        self.step(experiment, recording)
    }

    /// The value of `variable` now: after a run, the value the run ended with.
    pub fn value(&mut self, variable: Resolved) -> Result<Value, Error> {
        if self.instances.is_empty() {
            return Err(Error::Failed(
                "no instances: the last run failed, so its values are gone".into(),
            ));
        }
        self.get(variable)
            .map_err(|f| self.failed(variable.unit, f, None))
    }

    fn get(&mut self, variable: Resolved) -> Result<Value, CallFailed> {
        let instance = &mut self.instances[variable.unit];
        let vr = [variable.value_reference];
        Ok(match variable.kind {
            VariableType::Real => {
                let mut v = [0.0];
                instance.get_real(&vr, &mut v)?;
                Value::Real(v[0])
            }
            VariableType::Integer => {
                let mut v = [0];
                instance.get_integer(&vr, &mut v)?;
                Value::Integer(v[0])
            }
            VariableType::Boolean => {
                let mut v = [0];
                instance.get_boolean(&vr, &mut v)?;
                Value::Boolean(v[0] != 0)
            }
            VariableType::String => Value::String(instance.get_string(variable.value_reference)?),
        })
    }

    fn step(&mut self, experiment: &Experiment, recording: &Recording) -> Result<Trace, Error> {
        let h = experiment.step;
        let (mut limit, mut signal, settle) = match &experiment.end {
            End::Time(stop) => (experiment.steps(*stop), None, 0),
            End::Signal {
                signal,
                settle,
                max_stop,
            } => (
                experiment.steps(*max_stop),
                Some(*signal),
                experiment.steps(*settle),
            ),
        };
        let width = recording.columns.len();
        experiment.check_trace(width)?;
        // Exact for a run to a stop time; a run to a signal usually ends well before its
        // longest, so it starts smaller and grows (never while the FMUs step a sample).
        let rows = limit + settle + 1;
        let mut values = Vec::with_capacity((rows * width).min(RESERVED_VALUES));
        self.buffers
            .fit(recording.groups.iter().map(|g| g.value_references.len()));
        let mut k = 0;
        loop {
            // As contour_fmu.stepping: the signal is asked before each step, not after the last.
            if let Some(done) = signal.filter(|_| k < limit) {
                let mut flag = [0];
                self.instances[done.unit]
                    .get_boolean(&[done.value_reference], &mut flag)
                    .map_err(|f| self.failed(done.unit, f, Some(k as f64 * h)))?;
                if flag[0] != 0 {
                    limit = k + settle;
                    signal = None;
                }
            }
            self.record(recording, &mut values)
                .map_err(|(unit, f)| self.failed(unit, f, Some(k as f64 * h)))?;
            if k == limit {
                break;
            }
            let t = k as f64 * h;
            self.exchange(None)
                .map_err(|(unit, f)| self.failed(unit, f, Some(t)))?;
            for unit in 0..self.instances.len() {
                self.exchange(Some(unit))
                    .map_err(|(u, f)| self.failed(u, f, Some(t)))?;
                self.instances[unit]
                    .do_step(t, h)
                    .map_err(|f| self.failed(unit, f, Some(t)))?;
            }
            k += 1;
        }
        if signal.is_some() {
            let max_stop = match experiment.end {
                End::Signal { max_stop, .. } => max_stop,
                End::Time(_) => unreachable!("only a signal can be waited for"),
            };
            return Err(Error::Failed(format!(
                "the end signal never came within the longest run, {max_stop} s"
            )));
        }
        Ok(Trace {
            step: h,
            columns: recording.columns.clone(),
            steps: k,
            values,
        })
    }

    /// The transfers done before the units step (`None`, Jacobi) or before `unit` steps
    /// (Gauss-Seidel). A failure names the unit whose call failed.
    fn exchange(&mut self, unit: Option<usize>) -> Result<(), (usize, CallFailed)> {
        let transfers = match unit {
            None => &self.first,
            Some(u) => &self.before_step[u],
        };
        for t in transfers {
            let n = t.from.value_references.len();
            let (source, target) = (t.from.unit, t.to.unit);
            match t.from.kind {
                VariableType::Real => {
                    let buffer = &mut self.buffers.reals[..n];
                    self.instances[source]
                        .get_real(&t.from.value_references, buffer)
                        .map_err(|f| (source, f))?;
                    self.instances[target]
                        .set_real(&t.to.value_references, buffer)
                        .map_err(|f| (target, f))?;
                }
                VariableType::Integer | VariableType::Boolean => {
                    let buffer = &mut self.buffers.integers[..n];
                    let boolean = t.from.kind == VariableType::Boolean;
                    let from = &mut self.instances[source];
                    if boolean {
                        from.get_boolean(&t.from.value_references, buffer)
                    } else {
                        from.get_integer(&t.from.value_references, buffer)
                    }
                    .map_err(|f| (source, f))?;
                    let to = &mut self.instances[target];
                    if boolean {
                        to.set_boolean(&t.to.value_references, buffer)
                    } else {
                        to.set_integer(&t.to.value_references, buffer)
                    }
                    .map_err(|f| (target, f))?;
                }
                VariableType::String => {
                    for (&from, &to) in t.from.value_references.iter().zip(&t.to.value_references) {
                        let text = self.instances[source]
                            .get_string(from)
                            .map_err(|f| (source, f))?;
                        self.instances[target]
                            .set_string(to, &text)
                            .map_err(|f| (target, f))?;
                    }
                }
            }
        }
        Ok(())
    }

    fn record(
        &mut self,
        recording: &Recording,
        values: &mut Vec<f64>,
    ) -> Result<(), (usize, CallFailed)> {
        for group in &recording.groups {
            let n = group.value_references.len();
            let instance = &mut self.instances[group.unit];
            match group.kind {
                VariableType::Real => {
                    let buffer = &mut self.buffers.reals[..n];
                    instance
                        .get_real(&group.value_references, buffer)
                        .map_err(|f| (group.unit, f))?;
                    values.extend_from_slice(buffer);
                }
                VariableType::Integer | VariableType::Boolean => {
                    let buffer = &mut self.buffers.integers[..n];
                    if group.kind == VariableType::Boolean {
                        instance.get_boolean(&group.value_references, buffer)
                    } else {
                        instance.get_integer(&group.value_references, buffer)
                    }
                    .map_err(|f| (group.unit, f))?;
                    values.extend(buffer.iter().map(|&v| f64::from(v)));
                }
                VariableType::String => unreachable!("Recording refuses strings"),
            }
        }
        Ok(())
    }
}

impl Drop for Simulation<'_> {
    fn drop(&mut self) {
        for instance in &mut self.instances {
            // An instance in an error state may refuse; it is freed all the same.
            let _ = instance.terminate();
        }
    }
}

fn set(instance: &mut Instance, vr: u32, value: &Value) -> Result<(), CallFailed> {
    match value {
        Value::Real(v) => instance.set_real(&[vr], &[*v]),
        Value::Integer(v) => instance.set_integer(&[vr], &[*v]),
        Value::Boolean(v) => instance.set_boolean(&[vr], &[i32::from(*v)]),
        Value::String(v) => instance.set_string(vr, v),
    }
}
