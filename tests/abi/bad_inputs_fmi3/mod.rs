//! The catalogue of bad inputs for the fmi3 functions: the FMI 2.0 catalogue's abuse of the
//! ABI (`crate::bad_inputs`) mapped to FMI 3.0 Co-Simulation, on the same instances of the
//! same library, with the same refusals asserted the same way by the same machinery: each
//! case checks the exact status, a log line with that status in its category naming the
//! cause, and the aftermath (the instance usable and equal to an untouched twin, bit for
//! bit, or in Error or Fatal mode as the standard says), then for every fmi3Error the
//! recovery by fmi3SetFMUState to a state saved before the bad call and by fmi3Reset.
//!
//! Every case logs through FMI 3.0's callback (the message itself: no format, no
//! arguments), but those whose subject is an FMI 2.0 instance given to fmi3 functions:
//! the library tells that instance's importer, through its FMI 2.0 callback.
//!
//! FMI 3.0's own ways to go wrong are here too: the experiment comes with
//! fmi3EnterInitializationMode; nValues beside nValueReferences; the getters and setters of
//! types no variable has (Float32, Int8, …, Binary); an enumeration is an Int64; Boolean
//! bytes other than 0 and 1; the independent variable `time`; the out-pointers of
//! fmi3DoStep; a native resourcePath; the interface types, clocks and modes these FMUs do
//! not have. fmi3InstantiateCoSimulation returns no status: a NULL instance counts as
//! fmi3Error, an instance as fmi3OK. Nor does fmi3FreeInstance (or fmi2FreeInstance): a
//! case counts it as the status of the line it logs, fmi3Error when it refuses a handle.
//!
//! Needs the `test-hooks` feature (the `FaultProbe` model).

use std::ffi::c_void;

use crate::bad_inputs::*;
use crate::common::fmi3::*;
use crate::common::{
    cstr, fmi2Status, fmi2String, instantiate_raw, open_state, seal_state, Log, STATE_FORMAT,
};
use contour_fmu::framework::interface::UnitSystem;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Value, VarType, Variable};
use contour_fmu::models;

/// Declares the catalogue's groups, one a file, and lists them in `GROUPS`.
macro_rules! groups {
    ($($group:ident),* $(,)?) => {
        $(mod $group;)*
        /// The catalogue, one group per file.
        static GROUPS: &[&[Case<Fmi3>]] = &[$($group::CASES),*];
    };
}

groups![
    call_order,
    handles,
    null_arrays,
    non_finite,
    timing,
    references,
    parameters,
    state_bytes,
    foreign_states,
    unsupported,
    resources,
];

/// Every FMI 3.0 case, group by group.
fn cases() -> impl Iterator<Item = &'static Case<Fmi3>> {
    GROUPS.iter().flat_map(|group| group.iter())
}

/// The cases whose subject is an FMI 2.0 instance, given to fmi3 functions.
static ON_FMI2_INSTANCES: &[&[Case]] = &[
    handles::ON_FMI2_INSTANCES,
    foreign_states::ON_FMI2_INSTANCES,
];

// ---------------------------------------------------------------------------------------
// The C calls of FMI 3.0

/// FMI 3.0 Co-Simulation.
struct Fmi3;

/// The FMI 3.0 instantiation token of `model`'s mm interface.
fn token(model: &ModelInfo) -> &'static str {
    &models::interface(model, UnitSystem::Millimetre).instantiation_token
}

impl Api for Fmi3 {
    type Fmu = Instance3;
    const SET_STATE: &'static str = "fmi3SetFMUState";
    const RESET: &'static str = "fmi3Reset";

    fn instantiate(model: &'static ModelInfo, name: &str, resources: Resources) -> Instance3 {
        let folder = folder().display();
        let location = match resources {
            Resources::Null => None,
            Resources::Uri(path) => Some(path.to_string()),
            Resources::Folder => Some(format!("{folder}{}", std::path::MAIN_SEPARATOR)),
            Resources::FolderUri => Some(format!("file://{folder}")),
        };
        let i = Instantiation {
            resources: location.as_deref().map(str::as_bytes),
            ..Instantiation::new(name, token(model))
        }
        .instantiate();
        assert!(!i.c.is_null(), "{location:?}: {:?}", i.records());
        i
    }
    fn handle(fmu: &Instance3) -> *mut c_void {
        fmu.c
    }
    fn log(fmu: &Instance3) -> &Log {
        &fmu.log
    }
    fn free(fmu: &mut Instance3) {
        fmu.free();
    }
    fn set_debug_logging(c: *mut c_void, on: bool, categories: &[fmi2String]) -> fmi2Status {
        let (n, p) = (categories.len(), categories.as_ptr());
        unsafe { lib3().fmi3SetDebugLogging(c, on, n, p) }
    }
    fn set(c: *mut c_void, v: &Variable, value: Value) -> fmi2Status {
        let (vr, lib) = (v.vr as u32, lib3());
        unsafe {
            match value {
                Value::Real(x) => lib.fmi3SetFloat64(c, &vr, 1, &x, 1),
                Value::Integer(x) if v.enumeration.is_some() => {
                    lib.fmi3SetInt64(c, &vr, 1, &i64::from(x), 1)
                }
                Value::Integer(x) => lib.fmi3SetInt32(c, &vr, 1, &x, 1),
                Value::Boolean(x) => lib.fmi3SetBoolean(c, &vr, 1, &x, 1),
                Value::String(x) => lib.fmi3SetString(c, &vr, 1, &cstr(&x).as_ptr(), 1),
            }
        }
    }
    /// Reals as their bits, Booleans as the byte the library wrote.
    fn get(c: *mut c_void, v: &Variable) -> (fmi2Status, String) {
        let (vr, lib) = (v.vr as u32, lib3());
        unsafe {
            match (v.var_type(), v.enumeration) {
                (VarType::Real, _) => {
                    let mut x = f64::NAN;
                    let status = lib.fmi3GetFloat64(c, &vr, 1, &mut x, 1);
                    (status, format!("{x:?} ({:#018x})", x.to_bits()))
                }
                (VarType::Integer, Some(_)) => {
                    let mut x = i64::MIN;
                    (lib.fmi3GetInt64(c, &vr, 1, &mut x, 1), x.to_string())
                }
                (VarType::Integer, None) => {
                    let mut x = i32::MIN;
                    (lib.fmi3GetInt32(c, &vr, 1, &mut x, 1), x.to_string())
                }
                (VarType::Boolean, _) => {
                    let mut byte = 0xA5u8;
                    let p = &mut byte as *mut u8 as *mut bool;
                    (lib.fmi3GetBoolean(c, &vr, 1, p, 1), byte.to_string())
                }
                (VarType::String, _) => {
                    let mut p: fmi3String = std::ptr::null();
                    let status = lib.fmi3GetString(c, &vr, 1, &mut p, 1);
                    let text = (!p.is_null()).then(|| std::ffi::CStr::from_ptr(p));
                    (status, format!("{text:?}"))
                }
            }
        }
    }
    fn enter_initialization(c: *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0) }
    }
    fn exit_initialization(c: *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3ExitInitializationMode(c) }
    }
    fn step(c: *mut c_void, t: f64, h: f64) -> fmi2Status {
        step(c, t, h).0
    }
    fn terminate(c: *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3Terminate(c) }
    }
    fn reset(c: *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3Reset(c) }
    }
    fn get_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3GetFMUState(c, state) }
    }
    fn set_state(c: *mut c_void, state: *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3SetFMUState(c, state) }
    }
    fn free_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status {
        unsafe { lib3().fmi3FreeFMUState(c, state) }
    }
    fn state_size(c: *mut c_void, state: *mut c_void, size: &mut usize) -> fmi2Status {
        unsafe { lib3().fmi3SerializedFMUStateSize(c, state, size) }
    }
    fn serialize(c: *mut c_void, state: *mut c_void, bytes: &mut [u8]) -> fmi2Status {
        let (p, n) = (bytes.as_mut_ptr(), bytes.len());
        unsafe { lib3().fmi3SerializeFMUState(c, state, p, n) }
    }
    fn deserialize(c: *mut c_void, bytes: &[u8], state: &mut *mut c_void) -> fmi2Status {
        let (p, n) = (bytes.as_ptr(), bytes.len());
        unsafe { lib3().fmi3DeserializeFMUState(c, p, n, state) }
    }
}

/// A good value for a variable, in a list of values to set.
#[derive(Clone, Copy, Debug)]
enum Set<'a> {
    Real(f64),
    /// An Int32 or an enumeration (which is set as an Int64).
    Int(i32),
    Text(&'a str),
}

use Set::{Int, Real, Text};

impl From<Set<'_>> for Value {
    fn from(value: Set) -> Value {
        match value {
            Real(x) => Value::Real(x),
            Int(x) => Value::Integer(x),
            Text(x) => Value::String(x.into()),
        }
    }
}

/// What fmi3DoStep reported beside its status.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Reported {
    event: bool,
    terminate: bool,
    early_return: bool,
    last_successful_time: f64,
}

/// fmi3DoStep with all four out-pointers; the status and what it wrote into them (they
/// start as `true` and NaN, so what was not written shows).
fn step(c: *mut c_void, t: f64, h: f64) -> (fmi3Status, Reported) {
    let (mut event, mut terminate, mut early, mut last) = (true, true, true, f64::NAN);
    let status = unsafe {
        lib3().fmi3DoStep(
            c,
            t,
            h,
            false,
            &mut event,
            &mut terminate,
            &mut early,
            &mut last,
        )
    };
    let reported = Reported {
        event,
        terminate,
        early_return: early,
        last_successful_time: last,
    };
    (status, reported)
}

/// A getter of FMI 3.0 as the binding has it (`Fmi3Binding::fmi3GetInt8`, …).
type Getter<T> =
    unsafe fn(&Fmi3Binding, fmi3Instance, *const u32, usize, *mut T, usize) -> fmi3Status;
/// A setter of FMI 3.0 as the binding has it.
type Setter<T> =
    unsafe fn(&Fmi3Binding, fmi3Instance, *const u32, usize, *const T, usize) -> fmi3Status;

/// The calls the FMI 3.0 cases make beside the generic ones.
impl Subject<Fmi3> {
    /// fmi3DoStep from `t` over `h`.
    fn step(&self, t: f64, h: f64) -> fmi3Status {
        step(self.c(), t, h).0
    }

    /// fmi3DoStep from `t` over `h`, which must report no event, no early return, no
    /// termination and `last` (bit for bit) as the last successful time, whatever its
    /// status.
    fn step_reporting(&self, t: f64, h: f64, last: f64) -> fmi3Status {
        let (status, reported) = step(self.c(), t, h);
        let expected = Reported {
            event: false,
            terminate: false,
            early_return: false,
            last_successful_time: last,
        };
        assert!(
            reported.last_successful_time.to_bits() == last.to_bits() && reported == expected,
            "fmi3DoStep reported {reported:?}, expected {expected:?}"
        );
        status
    }

    /// fmi3DoStep of one step from the subject's time with the out-pointer number `null`
    /// (0 eventHandlingNeeded, 1 terminateSimulation, 2 earlyReturn, 3 lastSuccessfulTime)
    /// NULL.
    fn step_with_null(&self, null: usize) -> fmi3Status {
        let (mut flags, mut last) = ([false; 3], 0.0);
        let [event, terminate, early] = flags.each_mut().map(|f| f as *mut bool);
        let or_null = |i, p: *mut bool| if i == null { std::ptr::null_mut() } else { p };
        let last = if null == 3 {
            std::ptr::null_mut()
        } else {
            &mut last as *mut f64
        };
        let (event, terminate, early) =
            (or_null(0, event), or_null(1, terminate), or_null(2, early));
        unsafe { lib3().fmi3DoStep(self.c(), self.time, H, false, event, terminate, early, last) }
    }

    /// A new FMU state of the instance, freed again: its handle, stale.
    fn freed_state(&self) -> fmi3FMUState {
        let mut state = std::ptr::null_mut();
        self.ok(Fmi3::get_state(self.c(), &mut state));
        let stale = state;
        self.ok(Fmi3::free_state(self.c(), &mut state));
        stale
    }

    /// fmi3GetDirectionalDerivative of the first variable by itself.
    fn directional_derivative(&self) -> fmi3Status {
        let (vr, seed, mut out, c) = (0u32, 1.0, 0.0, self.c());
        let lib = lib3();
        unsafe { lib.fmi3GetDirectionalDerivative(c, &vr, 1, &vr, 1, &seed, 1, &mut out, 1) }
    }

    /// fmi3GetAdjointDerivative of the first variable by itself.
    fn adjoint_derivative(&self) -> fmi3Status {
        let (vr, seed, mut out, c) = (0u32, 1.0, 0.0, self.c());
        unsafe { lib3().fmi3GetAdjointDerivative(c, &vr, 1, &vr, 1, &seed, 1, &mut out, 1) }
    }

    /// Sets `values` (which must be accepted), then ends initialization: the bad call.
    fn exit_after(&self, values: &[(&str, Set)]) -> fmi3Status {
        for &(name, value) in values {
            self.ok(Fmi3::set(self.c(), self.variable(name), value.into()));
        }
        Fmi3::exit_initialization(self.c())
    }

    /// [`Subject::exit_after`], which must succeed, then the first step: the bad call.
    fn first_step_after(&self, values: &[(&str, Set)]) -> fmi3Status {
        self.ok(self.exit_after(values));
        self.step_reporting(0.0, H, 0.0)
    }

    /// Sets FaultProbe's `fault` ("fail" or "panic"), then steps: the bad call. A step
    /// that fails reports where it started from as the last successful time.
    fn step_failing(&self, fault: &str) -> fmi3Status {
        self.ok(self.set_boolean(fault, true));
        let (status, reported) = step(self.c(), self.time, H);
        if status == ERROR3 {
            assert_eq!(reported.last_successful_time, self.time, "{reported:?}");
        }
        status
    }

    /// fmi3GetBinary of the variable `name`.
    fn get_binary(&self, name: &str) -> fmi3Status {
        let (vr, mut size, mut value) = (self.vr(name), 0usize, std::ptr::null());
        unsafe { lib3().fmi3GetBinary(self.c(), &vr, 1, &mut size, &mut value, 1) }
    }

    /// fmi3SetBinary of `bytes` into the variable `name`.
    fn set_binary(&self, name: &str, bytes: &[u8]) -> fmi3Status {
        let (vr, size, value) = (self.vr(name), bytes.len(), bytes.as_ptr());
        unsafe { lib3().fmi3SetBinary(self.c(), &vr, 1, &size, &value, 1) }
    }

    /// fmi3GetOutputDerivatives of the first derivative of `name`.
    fn output_derivative(&self, name: &str) -> fmi3Status {
        let (vr, order, mut out) = (self.vr(name), 1, 0.0);
        unsafe { lib3().fmi3GetOutputDerivatives(self.c(), &vr, 1, &order, &mut out, 1) }
    }

    /// An instantiation function of an interface type these FMUs do not have, called by
    /// `instantiate` with a name, the model's token, a log and its callback: NULL counts
    /// as fmi3Error (the log kept), an instance as fmi3OK (freed).
    fn instantiate_other(
        &mut self,
        instantiate: impl FnOnce(
            fmi3String,
            fmi3String,
            fmi3InstanceEnvironment,
            fmi3LogMessageCallback,
        ) -> fmi3Instance,
    ) -> fmi3Status {
        let log = Box::<Log>::default();
        let (name, token) = (cstr("a"), cstr(self.token()));
        let environment = &*log as *const Log as fmi3InstanceEnvironment;
        let c = instantiate(
            name.as_ptr(),
            token.as_ptr(),
            environment,
            log_message_callback(),
        );
        self.refused = Some(log);
        if c.is_null() {
            return ERROR3;
        }
        unsafe { lib3().fmi3FreeInstance(c) };
        OK3
    }

    /// The value references of `names`.
    fn vrs(&self, names: &[&str]) -> Vec<u32> {
        names.iter().map(|name| self.vr(name)).collect()
    }

    /// The value reference of the independent variable `time`.
    fn time_vr(&self) -> u32 {
        models::interface(self.model, UnitSystem::Millimetre).time_vr()
    }

    /// fmi3SetFloat64 of `values` into `vrs`, nValues the values' count.
    fn set_float64(&self, vrs: &[u32], values: &[f64]) -> fmi3Status {
        self.set_as(Fmi3Binding::fmi3SetFloat64, vrs, values)
    }

    /// fmi3SetInt64 into the variable `name`.
    fn set_int64(&self, name: &str, value: i64) -> fmi3Status {
        self.set_as(Fmi3Binding::fmi3SetInt64, &[self.vr(name)], &[value])
    }

    /// fmi3SetInt32 into the variable `name`.
    fn set_int32(&self, name: &str, value: i32) -> fmi3Status {
        self.set_as(Fmi3Binding::fmi3SetInt32, &[self.vr(name)], &[value])
    }

    /// fmi3SetBoolean of the bytes `bytes` (a C bool is one byte) into the variables `names`.
    fn set_boolean_bytes(&self, names: &[&str], bytes: &[u8]) -> fmi3Status {
        let vrs = self.vrs(names);
        let values = bytes.as_ptr() as *const bool;
        unsafe { lib3().fmi3SetBoolean(self.c(), vrs.as_ptr(), vrs.len(), values, bytes.len()) }
    }

    /// A setter of any type: `values` into `vrs` (nValues the values' count).
    fn set_as<T>(&self, set: Setter<T>, vrs: &[u32], values: &[T]) -> fmi3Status {
        let (v, n) = (values.as_ptr(), values.len());
        unsafe { set(lib3(), self.c(), vrs.as_ptr(), vrs.len(), v, n) }
    }

    /// A getter of any type for `vrs` (nValues as many).
    fn get_as<T: Default + Clone>(&self, get: Getter<T>, vrs: &[u32]) -> fmi3Status {
        let mut out = vec![T::default(); vrs.len()];
        let (v, n) = (out.as_mut_ptr(), out.len());
        unsafe { get(lib3(), self.c(), vrs.as_ptr(), vrs.len(), v, n) }
    }

    /// A getter of any type for `n` value references in a NULL array.
    fn get_for_null<T: Default + Clone>(&self, get: Getter<T>, n: usize) -> fmi3Status {
        let mut out = vec![T::default(); n];
        unsafe { get(lib3(), self.c(), std::ptr::null(), n, out.as_mut_ptr(), n) }
    }

    /// A getter of any type for the variable `name`, into a NULL array.
    fn get_into_null<T>(&self, get: Getter<T>, name: &str) -> fmi3Status {
        let (vr, null) = (self.vr(name), std::ptr::null_mut());
        unsafe { get(lib3(), self.c(), &vr, 1, null, 1) }
    }

    /// A setter of any type for the variable `name`, from a NULL array.
    fn set_from_null<T>(&self, set: Setter<T>, name: &str) -> fmi3Status {
        let (vr, null) = (self.vr(name), std::ptr::null());
        unsafe { set(lib3(), self.c(), &vr, 1, null, 1) }
    }

    /// A function of the instance alone (fmi3Terminate, fmi3EnterEventMode, …).
    fn call(&self, function: unsafe fn(&Fmi3Binding, fmi3Instance) -> fmi3Status) -> fmi3Status {
        unsafe { function(lib3(), self.c()) }
    }

    /// fmi3EnterInitializationMode for an experiment from `start` to `stop`.
    fn enter_init(&self, start: f64, stop: Option<f64>) -> fmi3Status {
        let (defined, stop) = (stop.is_some(), stop.unwrap_or(0.0));
        unsafe { lib3().fmi3EnterInitializationMode(self.c(), false, 0.0, start, defined, stop) }
    }

    /// fmi3InstantiateCoSimulation as `arguments` say, for a case without an instance: an
    /// instance is the subject's (fmi3OK), NULL leaves the log (fmi3Error).
    fn instantiate(&mut self, arguments: Instantiation) -> fmi3Status {
        let mut i = arguments.instantiate();
        if i.c.is_null() {
            self.refused = Some(std::mem::take(&mut i.log));
            return ERROR3;
        }
        self.fmu = Some(i);
        OK3
    }

    /// The token of the subject's model.
    fn token(&self) -> &'static str {
        token(self.model)
    }
}

// ---------------------------------------------------------------------------------------
// The tests

#[test]
fn the_fmi3_catalogue_of_bad_inputs() {
    let _files = PathFiles::written();
    let mut failed = failures(cases());
    failed.extend(failures(ON_FMI2_INSTANCES.iter().flat_map(|g| g.iter())));
    let total = cases().count() + ON_FMI2_INSTANCES.iter().map(|g| g.len()).sum::<usize>();
    assert_none_failed(&failed, total);
}

/// The catalogue covers what it claims: every fmi3 instance function in a wrong mode (the
/// FMI 3.0 state machine), every model, and every function of what these FMUs do not
/// support answering fmi3Error with why.
#[test]
fn the_fmi3_catalogue_is_complete() {
    // Allowed in any state, or not taking an instance.
    let anywhere = [
        "fmi3GetVersion",
        "fmi3InstantiateModelExchange",
        "fmi3InstantiateCoSimulation",
        "fmi3InstantiateScheduledExecution",
        "fmi3FreeInstance",
        "fmi3FreeFMUState",
    ];
    // Answered with "not supported" in any live mode: a wrong mode is only Fatal.
    let everywhere = || unsupported::EVERYWHERE.iter().flat_map(|(_, f)| f.iter());
    let restricted: Vec<&str> = contour_fmu::fmi::FMI3_FUNCTIONS
        .iter()
        .copied()
        .filter(|f| !everywhere().any(|g| g == f))
        .collect();
    let all: Vec<Summary> = cases().map(|c| c.summary()).collect();
    assert_complete(&all, 250, &restricted, &anywhere);
    let says = |text: &str| all.iter().any(|c| c.2.is_some_and(|l| l.starts_with(text)));
    for (why, functions) in unsupported::EVERYWHERE {
        for function in *functions {
            let refusal = format!("{function}: not supported: {why}");
            assert!(says(&refusal), "{function} answering '{refusal}'");
        }
    }
    for function in unsupported::ALSO {
        assert!(says(&format!("{function}: not supported")), "{function}");
    }
}
