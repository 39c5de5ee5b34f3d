//! Random sequences of FMI 2.0 and FMI 3.0 calls with random arguments against every
//! model (the eight packaged ones, FaultProbe and PassThrough) in both unit systems, over
//! a few instance slots, each made by `fmi2Instantiate` or `fmi3InstantiateCoSimulation`
//! (or by `Start`, which also initializes it, and the seeds: see there):
//! NULL, freed and foreign handles, one standard's instance passed to the other's
//! functions (FreeInstance included), wrong GUIDs and instantiation tokens (each
//! standard's in the other's instantiation), NaN/Inf/huge/zero/negative times and steps,
//! unknown value references and FMI 3.0's `time`, NULL arrays, `nValues` other than
//! `nValueReferences`, `fmi3Boolean` bytes other than 0 and 1, non-UTF-8 strings, FMU
//! states freed, foreign, made up, serialized, corrupted and deserialized, every
//! unsupported FMI 3.0 function, and loggers of both standards that call back into (and
//! free) an instance.
//!
//! Never passed: what is undefined behaviour on the caller's side in C (an array shorter
//! than the length given with it, a buffer shorter than the size given, a garbage address
//! where the library must write). The oracle: no panic except FaultProbe's injected one
//! (which must come back as Fatal), no Fatal from any other model, Error from every freed
//! or NULL handle, from every call with the other standard's instance, and wherever the
//! design promises a refusal (`nValues` other than `nValueReferences`, setting `time`, a
//! Boolean byte other than 0 and 1, an enumeration beyond Int32, a reference through a
//! type no variable has, every unsupported function, a NULL result of fmi3DoStep);
//! FreeInstance of the other standard leaves the instance alive; fmi3DoStep reports no
//! event, termination or early return.
//! And whatever AddressSanitizer and LeakSanitizer see: every instance is freed at the end
//! of each input.
#![no_main]

use std::ffi::{c_char, c_void, CStr, CString};
use std::ptr;
use std::sync::atomic::{AtomicUsize, Ordering};

use arbitrary::{Arbitrary, Unstructured};
use contour_fmu::framework::interface::Interface;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{VarType, Variable};
use contour_fmu::models;
use contour_fmu_fuzz::*;
use fmi2_bindings::{
    fmi2Boolean, fmi2CallbackFunctions, fmi2Component, fmi2FMUstate, fmi2Integer, fmi2Real,
    fmi2Status, fmi2String, fmi2ValueReference,
};
use fmi3_bindings::{
    fmi3Binary, fmi3Float32, fmi3Float64, fmi3Instance, fmi3InstanceEnvironment, fmi3Int16,
    fmi3Int32, fmi3Int64, fmi3Int8, fmi3IntervalQualifier, fmi3LogMessageCallback, fmi3Status,
    fmi3String, fmi3UInt16, fmi3UInt32, fmi3UInt64, fmi3UInt8, fmi3ValueReference,
};
use libfuzzer_sys::fuzz_target;

const SLOTS: usize = 4;
const MAX_CALLS: usize = 64;
/// Instantiations per input, both standards (each builds a model and its variable table).
const MAX_INSTANTIATIONS: usize = 8;
/// Longest step for a sampled model: at the shortest period the models accept (1 µs) it
/// is 5 000 samples, so an input stays cheap. (A longer step costs proportionally more
/// samples, by design: not worth fuzzing.)
const MAX_SAMPLED_STEP: f64 = 5e-3;

// The same numbers in both standards (fmi2Status and fmi3Status are C enums, both u32).
const OK: fmi2Status = 0;
const ERROR: fmi2Status = 3;
const FATAL: fmi2Status = 4;

#[derive(Arbitrary, Debug)]
struct Input {
    calls: Vec<Call>,
}

/// The standard a function or an instance belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Std {
    Fmi2,
    Fmi3,
}

/// An instance argument (`fmi2Component` or `fmi3Instance`).
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Handle {
    /// Whatever the slot holds, of either standard.
    Slot(u8),
    Freed(u8),
    /// One of our FMU states, as if it were an instance.
    State(u8),
    /// The address of a local variable: a foreign pointer.
    Stack,
    Int(usize),
    Null,
}

/// A Real argument: the special values, small numbers, or any bits.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Real {
    Zero,
    NegZero,
    One,
    MinusOne,
    NaN,
    Inf,
    NegInf,
    Max,
    Lowest,
    MinPositive,
    Subnormal,
    Huge,
    /// n · 10^-3.
    Milli(i16),
    Raw(f64),
}

impl Real {
    fn value(self) -> f64 {
        match self {
            Real::Zero => 0.0,
            Real::NegZero => -0.0,
            Real::One => 1.0,
            Real::MinusOne => -1.0,
            Real::NaN => f64::NAN,
            Real::Inf => f64::INFINITY,
            Real::NegInf => f64::NEG_INFINITY,
            Real::Max => f64::MAX,
            Real::Lowest => f64::MIN,
            Real::MinPositive => f64::MIN_POSITIVE,
            Real::Subnormal => 5e-324,
            Real::Huge => 1e300,
            Real::Milli(n) => f64::from(n) * 1e-3,
            Real::Raw(x) => x,
        }
    }
}

/// The communication point of `fmi2DoStep`.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Current {
    /// The instance's time (fmi2LastSuccessfulTime).
    Now,
    /// The instance's time plus something.
    NowPlus(Real),
    Any(Real),
}

/// The step size of `fmi2DoStep`.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Step {
    /// n · 10^-4 s.
    Ticks(u8),
    /// n · 10^-7 s.
    Micro(u16),
    Any(Real),
}

/// A C string argument.
#[derive(Arbitrary, Debug, Clone)]
enum Text {
    Null,
    Known(u8),
    NotUtf8,
    /// Any bytes up to a NUL, with '/', '\\' and '.' replaced: it never names a file.
    Any(Vec<u8>),
}

/// Strings that mean something to one model or another: path names, files under
/// fuzz/resources (relative when the resource location is given), labels.
fn known_texts() -> Vec<String> {
    let dir = resources_dir();
    let blade = dir.join("../../examples/cl/blade.cl");
    let mut texts: Vec<String> = [
        "circle",
        "line",
        "arc",
        "infinity",
        "trident",
        " Circle ",
        "spiral",
        "",
        " ",
        "tilted_helix",
        "figure_eight",
        "part.cl",
        "PART.CL",
        "tool.json",
        "planar.json",
        "bad.json",
        "bad.cl",
        "missing.cl",
        "missing.apt",
        "missing.json",
        "/nonexistent/x.json",
        "/nonexistent/x.cl",
        "resources",
        "probe",
        "%s%s%n%s",
        "logEvents",
        "logStatusWarning",
        "logStatusError",
        "logStatusFatal",
        "logAll",
        "logNothing",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for file in ["part.cl", "tool.json", "planar.json", "bad.json", "bad.cl"] {
        texts.push(dir.join(file).display().to_string());
    }
    texts.push(blade.display().to_string());
    texts
}

/// The built-in five-axis paths: 80 001 poses each, so a PathInterpolator5X on one costs
/// milliseconds to initialize and its FMU states are megabytes.
fn is_heavy_path(text: &str) -> bool {
    let t = text.trim();
    t == "tilted_helix" || t == "figure_eight"
}

/// A value reference argument.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum VrArg {
    /// The n-th variable of the called function's type (the usual case).
    OfType(u8),
    /// The n-th variable, whatever its type.
    Any(u8),
    /// Past the end of the table by n.
    Unknown(u16),
    /// FMI 3.0's independent variable (`Interface::time_vr`, the first after the table;
    /// unknown to FMI 2.0).
    Time,
    Max,
}

/// The variables a value reference picks among for a function.
#[derive(Clone, Copy)]
enum Kind {
    /// FMI 2.0's Real, FMI 3.0's Float64.
    Real,
    /// FMI 2.0's Integer: Integers and Enumerations.
    Integer,
    /// FMI 3.0's Int32: Integers.
    Int32,
    /// FMI 3.0's Int64: Enumerations.
    Enumeration,
    Boolean,
    String,
    /// A type no variable has (Float32, Int8, Binary, ...): any.
    Any,
}

impl Kind {
    fn has(self, v: &Variable) -> bool {
        let t = v.var_type();
        match self {
            Kind::Real => t == VarType::Real,
            Kind::Integer => t == VarType::Integer,
            Kind::Int32 => t == VarType::Integer && v.enumeration.is_none(),
            Kind::Enumeration => t == VarType::Integer && v.enumeration.is_some(),
            Kind::Boolean => t == VarType::Boolean,
            Kind::String => t == VarType::String,
            Kind::Any => true,
        }
    }
}

/// FMI 3.0's `nValues` beside `nValueReferences` (every variable here is a scalar, so
/// they must agree). The values array always has `nValues` elements.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Count {
    Same,
    More(u8),
    Fewer(u8),
}

impl Count {
    fn of(self, n_value_references: usize) -> usize {
        match self {
            Count::Same => n_value_references,
            Count::More(k) => n_value_references + 1 + k as usize % 4,
            Count::Fewer(k) => n_value_references.saturating_sub(1 + k as usize % 4),
        }
    }
}

/// An `fmi3Boolean` as the byte a C caller may put there: 0, 1 or anything (a careless
/// importer's `bool`); the library must read bytes, never a Rust `bool` of another value.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum BoolByte {
    False,
    True,
    Byte(u8),
}

impl BoolByte {
    fn byte(self) -> u8 {
        match self {
            BoolByte::False => 0,
            BoolByte::True => 1,
            BoolByte::Byte(b) => b,
        }
    }
}

/// An `fmi3Int64` (Enumerations): small (their items count from 1) or any.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Int64Arg {
    Small(i8),
    Any(i64),
}

impl Int64Arg {
    fn value(self) -> i64 {
        match self {
            Int64Arg::Small(x) => i64::from(x),
            Int64Arg::Any(x) => x,
        }
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Guid {
    Right,
    /// Another interface's.
    Other(u8),
    Lowercase,
    Truncated(u8),
    /// The interface's FMI 3.0 instantiation token (never an FMI 2.0 GUID).
    Fmi3Token,
}

#[derive(Arbitrary, Debug, Clone)]
enum GuidArg {
    Model(Guid),
    Null,
    NotUtf8,
    Any(Vec<u8>),
}

/// The `instantiationToken` of `fmi3InstantiateCoSimulation`.
#[derive(Arbitrary, Debug, Clone)]
enum TokenArg {
    Right,
    /// Another interface's.
    Other(u8),
    /// The interface's FMI 2.0 GUID.
    Fmi2Guid,
    Uppercase,
    Truncated(u8),
    Null,
    NotUtf8,
    Any(Vec<u8>),
}

#[derive(Arbitrary, Debug, Clone)]
enum NameArg {
    Fixed,
    Null,
    Empty,
    Blank,
    NotUtf8,
    Any(Vec<u8>),
}

#[derive(Arbitrary, Debug, Clone)]
enum ResourceArg {
    Null,
    Ours,
    OursSlash,
    OursLocalhost,
    OursSingleSlash,
    Remote,
    Relative,
    BadEscape,
    NotUtf8,
    /// Any bytes up to a NUL, with '/' replaced: never a usable folder.
    Any(Vec<u8>),
}

/// FMI 3.0's `resourcePath`: a native path to the folder, with a trailing separator.
#[derive(Arbitrary, Debug, Clone)]
enum PathArg {
    Null,
    Ours,
    OursWithoutSlash,
    Empty,
    /// FMI 2.0's form (a `file:` URI), wrong here.
    Uri,
    Missing,
    Relative,
    NotUtf8,
    /// Any bytes up to a NUL, with '/' replaced: never a usable folder.
    Any(Vec<u8>),
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Callbacks {
    Checking,
    Quiet,
    NullStruct,
    NullLogger,
}

/// FMI 3.0's `logMessage`: ours, or NULL (allowed: the instance logs nothing).
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Logger3 {
    Checking,
    Null,
}

impl Logger3 {
    fn callback(self) -> fmi3LogMessageCallback {
        match self {
            Logger3::Checking => Some(checking_logger3),
            Logger3::Null => None,
        }
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum FmuType {
    CoSimulation,
    ModelExchange,
    Other(u32),
}

/// A value an FMU state argument or variable holds.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum StateArg {
    /// The n-th state made in this input (it may be freed, or another instance's, of
    /// either standard).
    Made(u8),
    Null,
    Int(usize),
    /// An instance handle in place of a state.
    Instance(u8),
}

/// The `FMUstate*` argument: the address of a variable, or a misuse of it.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum StateSlot {
    /// A variable holding this.
    Var(StateArg),
    Null,
    /// One of our states passed in place of the variable's address (fmusim 0.0.39's
    /// fmi2FreeFMUstate(c, state)); only handles, which the library recognises.
    StateItself(u8),
}

#[derive(Arbitrary, Debug, Clone)]
enum Bytes {
    /// A state serialized earlier in this input (by either standard).
    Serialized(u8),
    /// The same with one byte changed.
    Flipped(u8, u16, u8),
    Truncated(u8, u16),
    Any(Vec<u8>),
    /// NULL with this size.
    Null(u8),
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum BufferSize {
    Exact,
    Short(u8),
    Long(u8),
    Zero,
}

/// The FMU state functions, the same in both standards.
#[derive(Arbitrary, Debug, Clone)]
enum StateCall {
    Get {
        c: Handle,
        slot: StateSlot,
    },
    Set {
        c: Handle,
        state: StateArg,
    },
    Free {
        c: Handle,
        slot: StateSlot,
    },
    SerializedSize {
        c: Handle,
        state: StateArg,
        null_size: bool,
    },
    Serialize {
        c: Handle,
        state: StateArg,
        size: BufferSize,
        null_buffer: bool,
    },
    Deserialize {
        c: Handle,
        bytes: Bytes,
        slot: StateSlot,
    },
}

/// Which of fmi3DoStep's four results are NULL (bit i: the i-th); 0: none.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Outs {
    Valid,
    Null(u8),
}

/// The FMI 3.0 getters and setters of the types no variable here has.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum OtherType {
    Float32,
    Int8,
    UInt8,
    Int16,
    UInt16,
    UInt32,
    UInt64,
    Binary,
}

/// The FMI 3.0 functions these FMUs do not support (Model Exchange, Scheduled Execution,
/// clocks, configuration and event mode, dependencies, derivatives): `fmi3Error` always.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Unsupported {
    EnterEventMode,
    EnterStepMode,
    EnterConfigurationMode,
    ExitConfigurationMode,
    EvaluateDiscreteStates,
    UpdateDiscreteStates,
    EnterContinuousTimeMode,
    CompletedIntegratorStep,
    SetTime,
    SetContinuousStates,
    GetContinuousStateDerivatives,
    GetEventIndicators,
    GetContinuousStates,
    GetNominalsOfContinuousStates,
    GetNumberOfEventIndicators,
    GetNumberOfContinuousStates,
    GetClock,
    SetClock,
    GetIntervalDecimal,
    GetIntervalFraction,
    GetShiftDecimal,
    GetShiftFraction,
    SetIntervalDecimal,
    SetIntervalFraction,
    SetShiftDecimal,
    SetShiftFraction,
    ActivateModelPartition,
    GetNumberOfVariableDependencies,
    GetVariableDependencies,
    GetDirectionalDerivative,
    GetAdjointDerivative,
    GetOutputDerivatives,
}

#[derive(Arbitrary, Debug, Clone)]
enum Call {
    // FMI 2.0.
    GetTypesPlatform,
    GetVersion,
    Instantiate {
        slot: u8,
        interface: u8,
        guid: GuidArg,
        name: NameArg,
        resources: ResourceArg,
        callbacks: Callbacks,
        fmu_type: FmuType,
        visible: bool,
        logging_on: bool,
        environment: usize,
    },
    FreeInstance(Handle),
    SetDebugLogging {
        c: Handle,
        on: fmi2Boolean,
        categories: Vec<Text>,
        null_array: bool,
    },
    SetupExperiment {
        c: Handle,
        tolerance_defined: bool,
        tolerance: Real,
        start: Real,
        stop_defined: bool,
        stop: Real,
    },
    EnterInitializationMode(Handle),
    ExitInitializationMode(Handle),
    Terminate(Handle),
    Reset(Handle),
    DoStep {
        c: Handle,
        current: Current,
        step: Step,
        no_prior: bool,
    },
    CancelStep(Handle),
    GetReal {
        c: Handle,
        vrs: Vec<VrArg>,
        null_vr: bool,
        null_value: bool,
    },
    GetInteger {
        c: Handle,
        vrs: Vec<VrArg>,
        null_vr: bool,
        null_value: bool,
    },
    GetBoolean {
        c: Handle,
        vrs: Vec<VrArg>,
        null_vr: bool,
        null_value: bool,
    },
    GetString {
        c: Handle,
        vrs: Vec<VrArg>,
        null_vr: bool,
        null_value: bool,
    },
    SetReal {
        c: Handle,
        values: Vec<(VrArg, Real)>,
        null_vr: bool,
        null_value: bool,
    },
    SetInteger {
        c: Handle,
        values: Vec<(VrArg, i32)>,
        null_vr: bool,
        null_value: bool,
    },
    SetBoolean {
        c: Handle,
        values: Vec<(VrArg, i32)>,
        null_vr: bool,
        null_value: bool,
    },
    SetString {
        c: Handle,
        values: Vec<(VrArg, Text)>,
        null_vr: bool,
        null_value: bool,
    },
    /// fmi2GetFMUstate, fmi2SetFMUstate, ...
    State(StateCall),
    DirectionalDerivative {
        c: Handle,
        n_unknown: u8,
        n_known: u8,
        null_arrays: bool,
    },
    SetRealInputDerivatives {
        c: Handle,
        n: u8,
        null_arrays: bool,
    },
    GetRealOutputDerivatives {
        c: Handle,
        n: u8,
        null_arrays: bool,
    },
    Status {
        c: Handle,
        which: u8,
        kind: u32,
        null_value: bool,
    },
    /// From now on the logger (of either standard) calls back into this instance (and
    /// perhaps frees it).
    Reenter {
        c: Handle,
        frees: bool,
    },

    // FMI 3.0.
    GetVersion3,
    Instantiate3 {
        slot: u8,
        interface: u8,
        token: TokenArg,
        name: NameArg,
        resources: PathArg,
        logger: Logger3,
        visible: bool,
        logging_on: bool,
        event_mode_used: bool,
        early_return_allowed: bool,
        /// Required intermediate variables: none below 251, else 1 to 5 (refused).
        intermediate: u8,
        intermediate_callback: bool,
        environment: usize,
    },
    /// An instance of either standard made and initialized as an importer does it (the
    /// right GUID or token, our resources, the checking logger, start time n ms, no stop
    /// time), so that stepping, values in step mode, the FMU states of a running instance
    /// and FaultProbe's failures are one call away: from nothing, the five calls this
    /// takes are seldom found (the corpus the FMI 2.0-only target had grown, 3 934
    /// inputs, stepped one model of the ten and never reached FaultProbe's panic).
    Start {
        slot: u8,
        interface: u8,
        fmi3: bool,
        start_ms: u8,
        logging_on: bool,
    },
    /// fmi3InstantiateModelExchange or fmi3InstantiateScheduledExecution: always NULL.
    InstantiateOther3 {
        scheduled: bool,
        interface: u8,
        token: TokenArg,
        name: NameArg,
        logger: Logger3,
        logging_on: bool,
        callbacks: bool,
    },
    FreeInstance3(Handle),
    SetDebugLogging3 {
        c: Handle,
        on: bool,
        categories: Vec<Text>,
        null_array: bool,
    },
    EnterInitializationMode3 {
        c: Handle,
        tolerance_defined: bool,
        tolerance: Real,
        start: Real,
        stop_defined: bool,
        stop: Real,
    },
    ExitInitializationMode3(Handle),
    Terminate3(Handle),
    Reset3(Handle),
    DoStep3 {
        c: Handle,
        current: Current,
        step: Step,
        no_prior: bool,
        outs: Outs,
    },
    GetFloat64 {
        c: Handle,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    GetInt32 {
        c: Handle,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    GetInt64 {
        c: Handle,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    GetBoolean3 {
        c: Handle,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    GetString3 {
        c: Handle,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    SetFloat64 {
        c: Handle,
        values: Vec<(VrArg, Real)>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    SetInt32 {
        c: Handle,
        values: Vec<(VrArg, i32)>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    SetInt64 {
        c: Handle,
        values: Vec<(VrArg, Int64Arg)>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    SetBoolean3 {
        c: Handle,
        values: Vec<(VrArg, BoolByte)>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    SetString3 {
        c: Handle,
        values: Vec<(VrArg, Text)>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    /// fmi3GetFloat32, fmi3SetInt8, ..., fmi3SetBinary.
    OtherType3 {
        c: Handle,
        ty: OtherType,
        set: bool,
        vrs: Vec<VrArg>,
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    },
    /// fmi3GetFMUState, fmi3SetFMUState, ...
    State3(StateCall),
    Unsupported3 {
        c: Handle,
        which: Unsupported,
        vrs: Vec<VrArg>,
        n: u8,
        null_arrays: bool,
        x: Real,
    },
}

/// One instance slot.
#[derive(Clone, Copy)]
struct Live {
    c: fmi2Component,
    interface: &'static Interface,
    std: Std,
}

impl Live {
    fn model(&self) -> &'static ModelInfo {
        self.interface.model
    }
}

/// Everything one input made; freed at the end.
struct Session {
    interfaces: &'static [Interface],
    texts: Vec<String>,
    slots: [Option<Live>; SLOTS],
    freed: Vec<fmi2Component>,
    /// Every FMU state handed out (by either standard), freed ones included.
    states: Vec<fmi2FMUstate>,
    serialized: Vec<Vec<u8>>,
    /// Kept alive for every instance that may still use them (the library copies them
    /// today, but the standard lets it keep the pointer): boxed, so they never move.
    #[allow(clippy::vec_box)]
    callbacks: Vec<Box<fmi2CallbackFunctions>>,
    instantiations: usize,
    /// One built-in five-axis path per input at most (see `is_heavy_path`).
    heavy_used: bool,
    /// A local variable whose address is the foreign handle.
    foreign: u64,
}

fn c_string(bytes: &[u8]) -> CString {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    CString::new(&bytes[..end]).expect("cut at the first NUL")
}

/// Bytes that name no file: no separator, no extension.
fn no_file(bytes: &[u8]) -> Vec<u8> {
    bytes
        .iter()
        .map(|&b| {
            if matches!(b, b'/' | b'\\' | b'.') {
                b'_'
            } else {
                b
            }
        })
        .collect()
}

/// Bytes that name no folder: no separator.
fn no_folder(bytes: &[u8]) -> Vec<u8> {
    bytes
        .iter()
        .map(|&b| if b == b'/' { b'_' } else { b })
        .collect()
}

const NOT_UTF8: &[u8] = b"caf\xe9\xff\xfe";

fn name_arg(name: &NameArg) -> Option<CString> {
    match name {
        NameArg::Fixed => Some(c_string(b"fuzzed instance")),
        NameArg::Null => None,
        NameArg::Empty => Some(c_string(b"")),
        NameArg::Blank => Some(c_string(b" \t ")),
        NameArg::NotUtf8 => Some(c_string(NOT_UTF8)),
        NameArg::Any(bytes) => Some(c_string(bytes)),
    }
}

fn as_ptr(s: &Option<CString>) -> *const c_char {
    s.as_ref().map_or(ptr::null(), |s| s.as_ptr())
}

/// `v` with `n` elements: cut, or padded with `pad`.
fn resized<T: Copy>(mut v: Vec<T>, n: usize, pad: T) -> Vec<T> {
    v.resize(n, pad);
    v
}

fn or_null<T>(null: bool, p: *const T) -> *const T {
    if null {
        ptr::null()
    } else {
        p
    }
}

fn or_null_mut<T>(null: bool, p: *mut T) -> *mut T {
    if null {
        ptr::null_mut()
    } else {
        p
    }
}

// Callbacks the library must never call: nothing here has intermediate updates or clocks.
unsafe extern "C" fn never_intermediate_update(
    _: fmi3InstanceEnvironment,
    _: fmi3Float64,
    _: bool,
    _: bool,
    _: bool,
    _: bool,
    _: *mut bool,
    _: *mut fmi3Float64,
) {
    panic!("fmi3IntermediateUpdateCallback called: no variable has intermediateUpdate");
}

unsafe extern "C" fn never_clock_update(_: fmi3InstanceEnvironment) {
    panic!("fmi3ClockUpdateCallback called: no clocks");
}

unsafe extern "C" fn never_lock_preemption() {
    panic!("fmi3LockPreemptionCallback called: no Scheduled Execution");
}

type InstanceFn = unsafe extern "C" fn(*mut c_void) -> u32;
type StateVarFn = unsafe extern "C" fn(*mut c_void, *mut *mut c_void) -> u32;

impl Std {
    fn of(function: &str) -> Std {
        if function.starts_with("fmi3") {
            Std::Fmi3
        } else {
            Std::Fmi2
        }
    }

    fn name(self, fmi2: &'static str, fmi3: &'static str) -> &'static str {
        match self {
            Std::Fmi2 => fmi2,
            Std::Fmi3 => fmi3,
        }
    }

    fn free_instance(self) -> unsafe extern "C" fn(*mut c_void) {
        match self {
            Std::Fmi2 => fmi2FreeInstance,
            Std::Fmi3 => fmi3FreeInstance,
        }
    }

    fn exit_initialization_mode(self) -> InstanceFn {
        match self {
            Std::Fmi2 => fmi2ExitInitializationMode,
            Std::Fmi3 => fmi3ExitInitializationMode,
        }
    }

    fn terminate(self) -> InstanceFn {
        match self {
            Std::Fmi2 => fmi2Terminate,
            Std::Fmi3 => fmi3Terminate,
        }
    }

    fn reset(self) -> InstanceFn {
        match self {
            Std::Fmi2 => fmi2Reset,
            Std::Fmi3 => fmi3Reset,
        }
    }

    fn get_state(self) -> StateVarFn {
        match self {
            Std::Fmi2 => fmi2GetFMUstate,
            Std::Fmi3 => fmi3GetFMUState,
        }
    }

    fn free_state(self) -> StateVarFn {
        match self {
            Std::Fmi2 => fmi2FreeFMUstate,
            Std::Fmi3 => fmi3FreeFMUState,
        }
    }

    fn set_state(self) -> unsafe extern "C" fn(*mut c_void, *mut c_void) -> u32 {
        match self {
            Std::Fmi2 => fmi2SetFMUstate,
            Std::Fmi3 => fmi3SetFMUState,
        }
    }

    fn serialized_size(self) -> unsafe extern "C" fn(*mut c_void, *mut c_void, *mut usize) -> u32 {
        match self {
            Std::Fmi2 => fmi2SerializedFMUstateSize,
            Std::Fmi3 => fmi3SerializedFMUStateSize,
        }
    }

    unsafe fn serialize(self, c: *mut c_void, state: *mut c_void, out: *mut u8, n: usize) -> u32 {
        match self {
            Std::Fmi2 => fmi2SerializeFMUstate(c, state, out as *mut c_char, n),
            Std::Fmi3 => fmi3SerializeFMUState(c, state, out, n),
        }
    }

    unsafe fn deserialize(
        self,
        c: *mut c_void,
        bytes: *const u8,
        n: usize,
        slot: *mut *mut c_void,
    ) -> u32 {
        match self {
            Std::Fmi2 => fmi2DeSerializeFMUstate(c, bytes as *const c_char, n, slot),
            Std::Fmi3 => fmi3DeserializeFMUState(c, bytes, n, slot),
        }
    }

    /// Whether `c` is a live instance of this standard: FreeFMUState with NULL does
    /// nothing and answers OK in every mode, Fatal included; Error for anything else.
    unsafe fn is_live(self, c: *mut c_void) -> bool {
        self.free_state()(c, ptr::null_mut()) == OK
    }
}

fn freed_by_logger(c: fmi2Component) -> bool {
    FREED_BY_LOGGER
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .contains(&(c as usize))
}

impl Session {
    fn new() -> Self {
        FREED_BY_LOGGER
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clear();
        Session {
            interfaces: models::interfaces(),
            texts: known_texts(),
            slots: [None; SLOTS],
            freed: Vec::new(),
            states: Vec::new(),
            serialized: Vec::new(),
            callbacks: Vec::new(),
            instantiations: 0,
            heavy_used: false,
            foreign: 0x4343_4346_4d55_3201,
        }
    }

    /// The pointer for `h` and, when it is one of our live instances, the instance.
    fn handle(&mut self, h: Handle) -> (fmi2Component, Option<Live>) {
        match h {
            Handle::Slot(i) => match self.slots[i as usize % SLOTS] {
                Some(live) => (live.c, Some(live)),
                None => (ptr::null_mut(), None),
            },
            Handle::Freed(i) if !self.freed.is_empty() => {
                (self.freed[i as usize % self.freed.len()], None)
            }
            Handle::State(i) if !self.states.is_empty() => {
                (self.states[i as usize % self.states.len()], None)
            }
            Handle::Stack => (&mut self.foreign as *mut u64 as fmi2Component, None),
            Handle::Int(x) => {
                // Compare-tracing may turn a made-up number into a live handle.
                let live = self.live().find(|l| l.c as usize == x);
                (x as fmi2Component, live)
            }
            _ => (ptr::null_mut(), None),
        }
    }

    fn live(&self) -> impl Iterator<Item = Live> + '_ {
        self.slots.iter().flatten().copied()
    }

    /// The interface whose table picks value references for a call on `live` (any
    /// model's when the handle is not a live instance).
    fn table(&self, live: Option<Live>) -> &'static Interface {
        live.map_or(&self.interfaces[0], |l| l.interface)
    }

    /// The checks every status is subject to.
    fn check(&self, what: &str, h: Handle, live: Option<Live>, status: fmi2Status) {
        assert!((0..=4).contains(&status), "{what}: status {status}");
        match h {
            // Dead for good: handles are never reused.
            Handle::Freed(_) | Handle::Null | Handle::Stack => {
                assert_eq!(status, ERROR, "{what} on a handle that is not an instance")
            }
            Handle::State(_) => assert_eq!(status, ERROR, "{what} on an FMU state"),
            Handle::Slot(_) | Handle::Int(_) => {}
        }
        if let Some(live) = live {
            if live.std != Std::of(what) {
                assert_eq!(
                    status, ERROR,
                    "{what} on an instance of the other standard ({:?})",
                    live.std
                );
            }
        }
        if status == FATAL {
            FATALS.fetch_add(1, Ordering::Relaxed);
            let model = live.map_or("?", |l| l.model().identifier);
            assert_eq!(model, "FaultProbe", "{what}: Fatal from {model}");
        }
    }

    fn vr(&self, table: &Interface, arg: VrArg, kind: Kind) -> fmi2ValueReference {
        let n = table.variables.len() as u32;
        match arg {
            VrArg::OfType(i) => {
                let of_type: Vec<u32> = table
                    .variables
                    .iter()
                    .filter(|v| kind.has(v))
                    .map(|v| v.vr as u32)
                    .collect();
                if of_type.is_empty() {
                    u32::from(i) % n
                } else {
                    of_type[i as usize % of_type.len()]
                }
            }
            VrArg::Any(i) => u32::from(i) % n,
            VrArg::Unknown(k) => n + u32::from(k),
            VrArg::Time => table.time_vr(),
            VrArg::Max => u32::MAX,
        }
    }

    fn vrs(&self, table: &Interface, args: &[VrArg], kind: Kind) -> Vec<fmi2ValueReference> {
        args.iter().map(|&v| self.vr(table, v, kind)).collect()
    }

    fn text(&mut self, arg: &Text, model: Option<&ModelInfo>) -> Option<CString> {
        let mut bytes = match arg {
            Text::Null => return None,
            Text::Known(i) => self.texts[*i as usize % self.texts.len()]
                .clone()
                .into_bytes(),
            Text::NotUtf8 => NOT_UTF8.to_vec(),
            Text::Any(bytes) => no_file(bytes),
        };
        // A built-in five-axis path once per input; afterwards the small CL file.
        let is_5x = model.is_some_and(|m| m.identifier == "PathInterpolator5X");
        if is_5x && is_heavy_path(&String::from_utf8_lossy(&bytes)) {
            if self.heavy_used {
                bytes = b"part.cl".to_vec();
            }
            self.heavy_used = true;
        }
        Some(c_string(&bytes))
    }

    fn state_value(&mut self, arg: StateArg) -> fmi2FMUstate {
        match arg {
            StateArg::Made(i) if !self.states.is_empty() => {
                self.states[i as usize % self.states.len()]
            }
            StateArg::Int(x) => x as fmi2FMUstate,
            StateArg::Instance(i) => self.handle(Handle::Slot(i)).0,
            _ => ptr::null_mut(),
        }
    }

    /// Calls `f` with the `FMUstate*` argument `slot`; remembers a state the library
    /// wrote to the variable.
    fn with_state_slot(
        &mut self,
        slot: StateSlot,
        f: impl FnOnce(*mut fmi2FMUstate) -> fmi2Status,
    ) -> fmi2Status {
        match slot {
            StateSlot::Var(arg) => {
                let mut var = self.state_value(arg);
                let before = var;
                let status = f(&mut var);
                if var != before && !var.is_null() {
                    self.states.push(var);
                }
                status
            }
            StateSlot::StateItself(i) if !self.states.is_empty() => {
                f(self.states[i as usize % self.states.len()] as *mut fmi2FMUstate)
            }
            _ => f(ptr::null_mut()),
        }
    }

    /// PathInterpolator5X starts on the built-in helix: it gets the small CL file instead
    /// (after instantiation and reset), keeping inputs cheap; an input may still set a
    /// built-in once (see `text`).
    unsafe fn tame(&mut self, live: Live) {
        if live.model().identifier != "PathInterpolator5X" {
            return;
        }
        let vr = self.vr(live.interface, VrArg::OfType(0), Kind::String);
        let value = c"part.cl".as_ptr();
        match live.std {
            Std::Fmi2 => fmi2SetString(live.c, &vr, 1, &value),
            Std::Fmi3 => fmi3SetString(live.c, &vr, 1, &value, 1),
        };
    }

    /// Puts a new instance in `slot`, freeing the one there.
    unsafe fn occupy(&mut self, slot: u8, live: Live) {
        let slot = slot as usize % SLOTS;
        if let Some(old) = self.slots[slot].take() {
            old.std.free_instance()(old.c);
            self.freed.push(old.c);
        }
        self.slots[slot] = Some(live);
        self.tame(live);
    }

    /// fmi2FreeInstance or fmi3FreeInstance: an instance of the standard is gone, one of
    /// the other standard stays.
    unsafe fn free_instance(&mut self, std: Std, h: Handle) {
        let (c, live) = self.handle(h);
        std.free_instance()(c);
        let Some(live) = live else {
            return;
        };
        if live.std == std {
            for slot in &mut self.slots {
                if slot.is_some_and(|l| l.c == c) {
                    *slot = None;
                }
            }
            self.freed.push(c);
        } else if !freed_by_logger(c) {
            assert!(
                live.std.is_live(c),
                "{} freed an instance of the other standard",
                std.name("fmi2FreeInstance", "fmi3FreeInstance")
            );
        }
    }

    /// The time of `c` now (0 when it cannot say), for a step from "now".
    unsafe fn now(&self, std: Std, c: fmi2Component, live: Option<Live>) -> f64 {
        let mut now = 0.0;
        let status = match std {
            Std::Fmi2 => fmi2GetRealStatus(c, 2, &mut now),
            Std::Fmi3 => {
                let vr = self.table(live).time_vr();
                fmi3GetFloat64(c, &vr, 1, &mut now, 1)
            }
        };
        if status == OK {
            now
        } else {
            0.0
        }
    }

    /// The communication point and step of a DoStep: a sampled model (or one we cannot
    /// name) gets no step longer than MAX_SAMPLED_STEP; plants integrate any step at once.
    fn step(now: f64, current: Current, step: Step, live: Option<Live>) -> (f64, f64) {
        let current = match current {
            Current::Now => now,
            Current::NowPlus(x) => now + x.value(),
            Current::Any(x) => x.value(),
        };
        let mut step = match step {
            Step::Ticks(n) => f64::from(n) * 1e-4,
            Step::Micro(n) => f64::from(n) * 1e-7,
            Step::Any(x) => x.value(),
        };
        let any_step = live.is_some_and(|l| {
            matches!(
                l.model().identifier,
                "XYServoPlant" | "FiveAxisPlant" | "FaultProbe"
            )
        });
        if !any_step && step > MAX_SAMPLED_STEP {
            step = MAX_SAMPLED_STEP;
        }
        (current, step)
    }

    unsafe fn instantiate(&mut self, call: &Call) {
        let Call::Instantiate {
            slot,
            interface,
            guid,
            name,
            resources,
            callbacks,
            fmu_type,
            visible,
            logging_on,
            environment,
        } = call
        else {
            unreachable!("called with Instantiate")
        };
        if self.instantiations >= MAX_INSTANTIATIONS {
            return;
        }
        self.instantiations += 1;
        let interfaces = self.interfaces;
        let iface = &interfaces[*interface as usize % interfaces.len()];
        let guid: Option<CString> = match guid {
            GuidArg::Model(g) => {
                let text = match g {
                    Guid::Right => iface.guid.clone(),
                    Guid::Other(i) => interfaces[*i as usize % interfaces.len()].guid.clone(),
                    Guid::Lowercase => iface.guid.to_uppercase(),
                    Guid::Truncated(n) => iface.guid[..(*n as usize % iface.guid.len())].into(),
                    Guid::Fmi3Token => iface.instantiation_token.clone(),
                };
                Some(c_string(text.as_bytes()))
            }
            GuidArg::Null => None,
            GuidArg::NotUtf8 => Some(c_string(NOT_UTF8)),
            GuidArg::Any(bytes) => Some(c_string(bytes)),
        };
        let name = name_arg(name);
        let ours = resources_uri();
        let resources: Option<CString> = match resources {
            ResourceArg::Null => None,
            ResourceArg::Ours => Some(c_string(ours.as_bytes())),
            ResourceArg::OursSlash => Some(c_string(format!("{ours}/").as_bytes())),
            ResourceArg::OursLocalhost => Some(c_string(
                ours.replacen("file://", "file://localhost", 1).as_bytes(),
            )),
            ResourceArg::OursSingleSlash => {
                Some(c_string(ours.replacen("file://", "file:", 1).as_bytes()))
            }
            ResourceArg::Remote => Some(c_string(b"file://server/share/resources")),
            ResourceArg::Relative => Some(c_string(b"file:resources")),
            ResourceArg::BadEscape => Some(c_string(b"file:///tmp/%zz%2")),
            ResourceArg::NotUtf8 => Some(c_string(b"file:///tmp/\xff\xfe")),
            ResourceArg::Any(bytes) => Some(c_string(&no_folder(bytes))),
        };
        let functions: *const fmi2CallbackFunctions = match *callbacks {
            Callbacks::NullStruct => ptr::null(),
            other => {
                let mut f = match other {
                    Callbacks::Quiet => quiet_callbacks(),
                    _ => checking_callbacks(*environment),
                };
                if matches!(other, Callbacks::NullLogger) {
                    f.logger = None;
                }
                self.callbacks.push(Box::new(f));
                &**self.callbacks.last().expect("just pushed")
            }
        };
        let fmu_type = match fmu_type {
            FmuType::CoSimulation => 1,
            FmuType::ModelExchange => 0,
            FmuType::Other(t) => *t,
        };
        let c = fmi2Instantiate(
            as_ptr(&name),
            fmu_type,
            as_ptr(&guid),
            as_ptr(&resources),
            functions,
            *visible as fmi2Boolean,
            *logging_on as fmi2Boolean,
        );
        if c.is_null() {
            return;
        }
        // Whatever the GUID named is what was instantiated.
        let interface = guid
            .as_ref()
            .and_then(|g| models::by_guid(g.to_str().ok()?))
            .expect("fmi2Instantiate succeeded with a GUID of no interface");
        self.occupy(
            *slot,
            Live {
                c,
                interface,
                std: Std::Fmi2,
            },
        );
    }

    fn token(&self, iface: &Interface, token: &TokenArg) -> Option<CString> {
        let text = match token {
            TokenArg::Right => iface.instantiation_token.clone(),
            TokenArg::Other(i) => self.interfaces[*i as usize % self.interfaces.len()]
                .instantiation_token
                .clone(),
            TokenArg::Fmi2Guid => iface.guid.clone(),
            TokenArg::Uppercase => iface.instantiation_token.to_uppercase(),
            TokenArg::Truncated(n) => {
                let t = &iface.instantiation_token;
                t[..(*n as usize % t.len())].to_string()
            }
            TokenArg::Null => return None,
            TokenArg::NotUtf8 => return Some(c_string(NOT_UTF8)),
            TokenArg::Any(bytes) => return Some(c_string(bytes)),
        };
        Some(c_string(text.as_bytes()))
    }

    unsafe fn instantiate3(&mut self, call: &Call) {
        let Call::Instantiate3 {
            slot,
            interface,
            token,
            name,
            resources,
            logger,
            visible,
            logging_on,
            event_mode_used,
            early_return_allowed,
            intermediate,
            intermediate_callback,
            environment,
        } = call
        else {
            unreachable!("called with Instantiate3")
        };
        if self.instantiations >= MAX_INSTANTIATIONS {
            return;
        }
        self.instantiations += 1;
        let iface = &self.interfaces[*interface as usize % self.interfaces.len()];
        let token = self.token(iface, token);
        let name = name_arg(name);
        let ours = resources_dir().display().to_string();
        let path: Option<CString> = match resources {
            PathArg::Null => None,
            PathArg::Ours => Some(c_string(format!("{ours}/").as_bytes())),
            PathArg::OursWithoutSlash => Some(c_string(ours.as_bytes())),
            PathArg::Empty => Some(c_string(b"")),
            PathArg::Uri => Some(c_string(resources_uri().as_bytes())),
            PathArg::Missing => Some(c_string(b"/nonexistent/resources/")),
            PathArg::Relative => Some(c_string(b"resources/")),
            PathArg::NotUtf8 => Some(c_string(b"/tmp/\xff\xfe/")),
            PathArg::Any(bytes) => Some(c_string(&no_folder(bytes))),
        };
        let n_intermediate = intermediate.saturating_sub(250) as usize;
        let required: Vec<fmi3ValueReference> = (0..n_intermediate as u32).collect();
        let c = fmi3InstantiateCoSimulation(
            as_ptr(&name),
            as_ptr(&token),
            as_ptr(&path),
            *visible,
            *logging_on,
            *event_mode_used,
            *early_return_allowed,
            if required.is_empty() {
                ptr::null()
            } else {
                required.as_ptr()
            },
            required.len(),
            *environment as fmi3InstanceEnvironment,
            logger.callback(),
            if *intermediate_callback {
                Some(never_intermediate_update)
            } else {
                None
            },
        );
        if c.is_null() {
            return;
        }
        assert_eq!(
            n_intermediate, 0,
            "fmi3InstantiateCoSimulation succeeded with intermediate variables"
        );
        let blank = name
            .as_ref()
            .is_none_or(|n| n.to_str().map_or(true, |n| n.trim().is_empty()));
        assert!(
            !blank,
            "fmi3InstantiateCoSimulation succeeded with a NULL or blank name"
        );
        // Whatever the token named is what was instantiated.
        let interface = token
            .as_ref()
            .and_then(|t| models::by_instantiation_token(t.to_str().ok()?))
            .expect("fmi3InstantiateCoSimulation succeeded with a token of no interface");
        self.occupy(
            *slot,
            Live {
                c,
                interface,
                std: Std::Fmi3,
            },
        );
    }

    /// [`Call::Start`]: every step must succeed.
    unsafe fn start(
        &mut self,
        slot: u8,
        interface: u8,
        fmi3: bool,
        start_ms: u8,
        logging_on: bool,
    ) {
        if self.instantiations >= MAX_INSTANTIATIONS {
            return;
        }
        self.instantiations += 1;
        let iface = &self.interfaces[interface as usize % self.interfaces.len()];
        let name = c"started".as_ptr();
        let start = f64::from(start_ms) * 1e-3;
        let (c, std) = if fmi3 {
            let token = c_string(iface.instantiation_token.as_bytes());
            let path = c_string(format!("{}/", resources_dir().display()).as_bytes());
            let c = fmi3InstantiateCoSimulation(
                name,
                token.as_ptr(),
                path.as_ptr(),
                false,
                logging_on,
                false,
                false,
                ptr::null(),
                0,
                ptr::null_mut(),
                Some(checking_logger3),
                None,
            );
            (c, Std::Fmi3)
        } else {
            let guid = c_string(iface.guid.as_bytes());
            let uri = c_string(resources_uri().as_bytes());
            self.callbacks.push(Box::new(checking_callbacks(0)));
            let functions: *const fmi2CallbackFunctions =
                &**self.callbacks.last().expect("just pushed");
            let c = fmi2Instantiate(
                name,
                1,
                guid.as_ptr(),
                uri.as_ptr(),
                functions,
                0,
                logging_on as fmi2Boolean,
            );
            (c, Std::Fmi2)
        };
        let what = format!(
            "{} ({}) through {std:?}",
            iface.model.identifier,
            iface.units.name()
        );
        assert!(
            !c.is_null(),
            "{what}: not instantiated with its own GUID or token"
        );
        self.occupy(
            slot,
            Live {
                c,
                interface: iface,
                std,
            },
        );
        let statuses = match std {
            Std::Fmi2 => [
                fmi2SetupExperiment(c, 0, 0.0, start, 0, 0.0),
                fmi2EnterInitializationMode(c),
                fmi2ExitInitializationMode(c),
            ],
            Std::Fmi3 => [
                OK,
                fmi3EnterInitializationMode(c, false, 0.0, start, false, 0.0),
                fmi3ExitInitializationMode(c),
            ],
        };
        // (Unless the logger, calling back into a made-up handle that turned out to be
        // this one, freed it.)
        if !freed_by_logger(c) {
            assert_eq!(statuses, [OK; 3], "{what}: not started at t = {start}");
        }
    }

    /// fmi3InstantiateModelExchange and fmi3InstantiateScheduledExecution: always NULL.
    unsafe fn instantiate_other3(&mut self, call: &Call) {
        let Call::InstantiateOther3 {
            scheduled,
            interface,
            token,
            name,
            logger,
            logging_on,
            callbacks,
        } = call
        else {
            unreachable!("called with InstantiateOther3")
        };
        let iface = &self.interfaces[*interface as usize % self.interfaces.len()];
        let token = self.token(iface, token);
        let name = name_arg(name);
        let path = c_string(format!("{}/", resources_dir().display()).as_bytes());
        let c = if *scheduled {
            fmi3InstantiateScheduledExecution(
                as_ptr(&name),
                as_ptr(&token),
                path.as_ptr(),
                false,
                *logging_on,
                ptr::null_mut(),
                logger.callback(),
                callbacks.then_some(never_clock_update as unsafe extern "C" fn(_)),
                callbacks.then_some(never_lock_preemption as unsafe extern "C" fn()),
                callbacks.then_some(never_lock_preemption as unsafe extern "C" fn()),
            )
        } else {
            fmi3InstantiateModelExchange(
                as_ptr(&name),
                as_ptr(&token),
                path.as_ptr(),
                false,
                *logging_on,
                ptr::null_mut(),
                logger.callback(),
            )
        };
        if !c.is_null() {
            // Not ours to use: free it before failing, so the report is about this.
            fmi3FreeInstance(c);
            panic!("an FMI 3.0 instantiation of another interface type succeeded");
        }
    }

    /// An FMI 3.0 getter with `nValues` values of `init` through `f`; what it wrote if
    /// it answered OK.
    #[allow(clippy::too_many_arguments)]
    unsafe fn get3<T: Copy>(
        &mut self,
        what: &str,
        h: Handle,
        vrs: &[VrArg],
        kind: Kind,
        n_values: Count,
        (null_vr, null_value): (bool, bool),
        init: T,
        f: impl FnOnce(fmi3Instance, *const fmi3ValueReference, usize, *mut T, usize) -> fmi3Status,
    ) -> Option<Vec<T>> {
        let (c, live) = self.handle(h);
        let vrs = self.vrs(self.table(live), vrs, kind);
        let n = n_values.of(vrs.len());
        let mut values = vec![init; n];
        let status = f(
            c,
            or_null(null_vr, vrs.as_ptr()),
            vrs.len(),
            or_null_mut(null_value, values.as_mut_ptr()),
            n,
        );
        self.check(what, h, live, status);
        if n != vrs.len() {
            assert_eq!(status, ERROR, "{what}: nValues {n} != nValueReferences");
        }
        (status == OK && !null_value).then_some(values)
    }

    /// An FMI 3.0 setter of `values` (cut or padded with `pad` to `nValues`) through `f`.
    #[allow(clippy::too_many_arguments)]
    unsafe fn set3<T: Copy>(
        &mut self,
        what: &str,
        h: Handle,
        live: Option<Live>,
        c: fmi3Instance,
        vrs: &[fmi3ValueReference],
        values: Vec<T>,
        pad: T,
        n_values: Count,
        (null_vr, null_value): (bool, bool),
        f: impl FnOnce(fmi3Instance, *const fmi3ValueReference, usize, *const T, usize) -> fmi3Status,
    ) -> fmi3Status {
        let n = n_values.of(vrs.len());
        let values = resized(values, n, pad);
        let status = f(
            c,
            or_null(null_vr, vrs.as_ptr()),
            vrs.len(),
            or_null(null_value, values.as_ptr()),
            n,
        );
        self.check(what, h, live, status);
        if n != vrs.len() {
            assert_eq!(status, ERROR, "{what}: nValues {n} != nValueReferences");
        }
        status
    }

    /// A getter or setter of a type no variable has: Error for any reference.
    #[allow(clippy::too_many_arguments)]
    unsafe fn other_type3(
        &mut self,
        h: Handle,
        ty: OtherType,
        set: bool,
        vrs: &[VrArg],
        n_values: Count,
        null_vr: bool,
        null_value: bool,
    ) {
        let (c, live) = self.handle(h);
        let vrs = self.vrs(self.table(live), vrs, Kind::Any);
        let (vr, nvr) = (or_null(null_vr, vrs.as_ptr()), vrs.len());
        let n = n_values.of(nvr);
        // Each values array of `n` zeros, NULL if asked.
        macro_rules! call {
            ($get:ident, $set:ident, $t:ty) => {{
                let mut values: Vec<$t> = vec![<$t>::default(); n];
                if set {
                    let p = or_null(null_value, values.as_ptr());
                    (stringify!($set), $set(c, vr, nvr, p, n))
                } else {
                    let p = or_null_mut(null_value, values.as_mut_ptr());
                    (stringify!($get), $get(c, vr, nvr, p, n))
                }
            }};
        }
        let (what, status) = match ty {
            OtherType::Float32 => call!(fmi3GetFloat32, fmi3SetFloat32, fmi3Float32),
            OtherType::Int8 => call!(fmi3GetInt8, fmi3SetInt8, fmi3Int8),
            OtherType::UInt8 => call!(fmi3GetUInt8, fmi3SetUInt8, fmi3UInt8),
            OtherType::Int16 => call!(fmi3GetInt16, fmi3SetInt16, fmi3Int16),
            OtherType::UInt16 => call!(fmi3GetUInt16, fmi3SetUInt16, fmi3UInt16),
            OtherType::UInt32 => call!(fmi3GetUInt32, fmi3SetUInt32, fmi3UInt32),
            OtherType::UInt64 => call!(fmi3GetUInt64, fmi3SetUInt64, fmi3UInt64),
            OtherType::Binary => {
                let data = b"bytes";
                let mut sizes = vec![data.len(); n];
                let mut values: Vec<fmi3Binary> = vec![data.as_ptr(); n];
                if set {
                    let status = fmi3SetBinary(
                        c,
                        vr,
                        nvr,
                        or_null(null_value, sizes.as_ptr()),
                        or_null(null_value, values.as_ptr()),
                        n,
                    );
                    ("fmi3SetBinary", status)
                } else {
                    let status = fmi3GetBinary(
                        c,
                        vr,
                        nvr,
                        or_null_mut(null_value, sizes.as_mut_ptr()),
                        or_null_mut(null_value, values.as_mut_ptr()),
                        n,
                    );
                    ("fmi3GetBinary", status)
                }
            }
        };
        self.check(what, h, live, status);
        if nvr > 0 {
            assert_eq!(status, ERROR, "{what}: no variable has this type");
        }
    }

    /// An unsupported FMI 3.0 function, with arrays of the lengths it is given (`vrs`
    /// for value references, `n` for states, indicators, seeds) or NULL: always Error.
    unsafe fn unsupported3(
        &mut self,
        h: Handle,
        which: Unsupported,
        vrs: &[VrArg],
        n: u8,
        null: bool,
        x: Real,
    ) {
        let (c, live) = self.handle(h);
        let vrs = self.vrs(self.table(live), vrs, Kind::Any);
        let (vr, nvr) = (or_null(null, vrs.as_ptr()), vrs.len());
        let first = vrs.first().copied().unwrap_or(0);
        let n = n as usize % 8;
        let (mut reals, mut counts, mut more) =
            (vec![0.0; n.max(nvr)], vec![0u64; nvr], vec![1u64; nvr]);
        let mut qualifiers: Vec<fmi3IntervalQualifier> = vec![0; nvr];
        let mut flags = [false; 5];
        let mut time = 0.0;
        let mut size = 0usize;
        let r = or_null_mut(null, reals.as_mut_ptr());
        let (name, status) = match which {
            Unsupported::EnterEventMode => ("fmi3EnterEventMode", fmi3EnterEventMode(c)),
            Unsupported::EnterStepMode => ("fmi3EnterStepMode", fmi3EnterStepMode(c)),
            Unsupported::EnterConfigurationMode => {
                ("fmi3EnterConfigurationMode", fmi3EnterConfigurationMode(c))
            }
            Unsupported::ExitConfigurationMode => {
                ("fmi3ExitConfigurationMode", fmi3ExitConfigurationMode(c))
            }
            Unsupported::EvaluateDiscreteStates => {
                ("fmi3EvaluateDiscreteStates", fmi3EvaluateDiscreteStates(c))
            }
            Unsupported::UpdateDiscreteStates => {
                let [a, b, d, e, g] = &mut flags;
                let status = if null {
                    fmi3UpdateDiscreteStates(
                        c,
                        ptr::null_mut(),
                        ptr::null_mut(),
                        ptr::null_mut(),
                        ptr::null_mut(),
                        ptr::null_mut(),
                        ptr::null_mut(),
                    )
                } else {
                    fmi3UpdateDiscreteStates(c, a, b, d, e, g, &mut time)
                };
                ("fmi3UpdateDiscreteStates", status)
            }
            Unsupported::EnterContinuousTimeMode => (
                "fmi3EnterContinuousTimeMode",
                fmi3EnterContinuousTimeMode(c),
            ),
            Unsupported::CompletedIntegratorStep => {
                let [a, b, ..] = &mut flags;
                let status = if null {
                    fmi3CompletedIntegratorStep(c, true, ptr::null_mut(), ptr::null_mut())
                } else {
                    fmi3CompletedIntegratorStep(c, false, a, b)
                };
                ("fmi3CompletedIntegratorStep", status)
            }
            Unsupported::SetTime => ("fmi3SetTime", fmi3SetTime(c, x.value())),
            Unsupported::SetContinuousStates => {
                ("fmi3SetContinuousStates", fmi3SetContinuousStates(c, r, n))
            }
            Unsupported::GetContinuousStateDerivatives => (
                "fmi3GetContinuousStateDerivatives",
                fmi3GetContinuousStateDerivatives(c, r, n),
            ),
            Unsupported::GetEventIndicators => {
                ("fmi3GetEventIndicators", fmi3GetEventIndicators(c, r, n))
            }
            Unsupported::GetContinuousStates => {
                ("fmi3GetContinuousStates", fmi3GetContinuousStates(c, r, n))
            }
            Unsupported::GetNominalsOfContinuousStates => (
                "fmi3GetNominalsOfContinuousStates",
                fmi3GetNominalsOfContinuousStates(c, r, n),
            ),
            Unsupported::GetNumberOfEventIndicators => (
                "fmi3GetNumberOfEventIndicators",
                fmi3GetNumberOfEventIndicators(c, or_null_mut(null, &mut size)),
            ),
            Unsupported::GetNumberOfContinuousStates => (
                "fmi3GetNumberOfContinuousStates",
                fmi3GetNumberOfContinuousStates(c, or_null_mut(null, &mut size)),
            ),
            Unsupported::GetClock => {
                let mut clocks = vec![false; nvr];
                let p = or_null_mut(null, clocks.as_mut_ptr());
                ("fmi3GetClock", fmi3GetClock(c, vr, nvr, p))
            }
            Unsupported::SetClock => {
                let clocks = vec![true; nvr];
                let p = or_null(null, clocks.as_ptr());
                ("fmi3SetClock", fmi3SetClock(c, vr, nvr, p))
            }
            Unsupported::GetIntervalDecimal => {
                let q = or_null_mut(null, qualifiers.as_mut_ptr());
                (
                    "fmi3GetIntervalDecimal",
                    fmi3GetIntervalDecimal(c, vr, nvr, r, q),
                )
            }
            Unsupported::GetIntervalFraction => {
                let q = or_null_mut(null, qualifiers.as_mut_ptr());
                let (a, b) = (
                    or_null_mut(null, counts.as_mut_ptr()),
                    or_null_mut(null, more.as_mut_ptr()),
                );
                (
                    "fmi3GetIntervalFraction",
                    fmi3GetIntervalFraction(c, vr, nvr, a, b, q),
                )
            }
            Unsupported::GetShiftDecimal => {
                ("fmi3GetShiftDecimal", fmi3GetShiftDecimal(c, vr, nvr, r))
            }
            Unsupported::GetShiftFraction => {
                let (a, b) = (
                    or_null_mut(null, counts.as_mut_ptr()),
                    or_null_mut(null, more.as_mut_ptr()),
                );
                (
                    "fmi3GetShiftFraction",
                    fmi3GetShiftFraction(c, vr, nvr, a, b),
                )
            }
            Unsupported::SetIntervalDecimal => (
                "fmi3SetIntervalDecimal",
                fmi3SetIntervalDecimal(c, vr, nvr, r),
            ),
            Unsupported::SetIntervalFraction => {
                let (a, b) = (or_null(null, counts.as_ptr()), or_null(null, more.as_ptr()));
                (
                    "fmi3SetIntervalFraction",
                    fmi3SetIntervalFraction(c, vr, nvr, a, b),
                )
            }
            Unsupported::SetShiftDecimal => {
                ("fmi3SetShiftDecimal", fmi3SetShiftDecimal(c, vr, nvr, r))
            }
            Unsupported::SetShiftFraction => {
                let (a, b) = (or_null(null, counts.as_ptr()), or_null(null, more.as_ptr()));
                (
                    "fmi3SetShiftFraction",
                    fmi3SetShiftFraction(c, vr, nvr, a, b),
                )
            }
            Unsupported::ActivateModelPartition => (
                "fmi3ActivateModelPartition",
                fmi3ActivateModelPartition(c, first, x.value()),
            ),
            Unsupported::GetNumberOfVariableDependencies => (
                "fmi3GetNumberOfVariableDependencies",
                fmi3GetNumberOfVariableDependencies(c, first, or_null_mut(null, &mut size)),
            ),
            Unsupported::GetVariableDependencies => {
                let mut indices = vec![0usize; n];
                let mut independents = vec![0u32; n];
                let mut their_indices = vec![0usize; n];
                let mut kinds = vec![0u32; n];
                (
                    "fmi3GetVariableDependencies",
                    fmi3GetVariableDependencies(
                        c,
                        first,
                        or_null_mut(null, indices.as_mut_ptr()),
                        or_null_mut(null, independents.as_mut_ptr()),
                        or_null_mut(null, their_indices.as_mut_ptr()),
                        or_null_mut(null, kinds.as_mut_ptr()),
                        n,
                    ),
                )
            }
            Unsupported::GetDirectionalDerivative | Unsupported::GetAdjointDerivative => {
                // Unknowns: the references; knowns: the same; a seed of n, a sensitivity
                // of as many as there are references.
                let seed = vec![1.0; n];
                let mut sensitivity = vec![0.0; nvr];
                let (s, out) = (
                    or_null(null, seed.as_ptr()),
                    or_null_mut(null, sensitivity.as_mut_ptr()),
                );
                if matches!(which, Unsupported::GetDirectionalDerivative) {
                    (
                        "fmi3GetDirectionalDerivative",
                        fmi3GetDirectionalDerivative(c, vr, nvr, vr, nvr, s, n, out, nvr),
                    )
                } else {
                    (
                        "fmi3GetAdjointDerivative",
                        fmi3GetAdjointDerivative(c, vr, nvr, vr, nvr, s, n, out, nvr),
                    )
                }
            }
            Unsupported::GetOutputDerivatives => {
                let orders = vec![1; nvr];
                (
                    "fmi3GetOutputDerivatives",
                    fmi3GetOutputDerivatives(
                        c,
                        vr,
                        nvr,
                        or_null(null, orders.as_ptr()),
                        or_null_mut(null, reals.as_mut_ptr()),
                        nvr,
                    ),
                )
            }
        };
        self.check(name, h, live, status);
        assert_eq!(status, ERROR, "{name} is not supported");
    }

    /// The FMU state functions of `std`.
    unsafe fn state_call(&mut self, std: Std, call: &StateCall) {
        match call {
            StateCall::Get { c: h, slot } => {
                let (c, live) = self.handle(*h);
                let status = self.with_state_slot(*slot, |s| std.get_state()(c, s));
                self.check(
                    std.name("fmi2GetFMUstate", "fmi3GetFMUState"),
                    *h,
                    live,
                    status,
                );
            }
            StateCall::Set { c: h, state } => {
                let (c, live) = self.handle(*h);
                let state = self.state_value(*state);
                let status = std.set_state()(c, state);
                self.check(
                    std.name("fmi2SetFMUstate", "fmi3SetFMUState"),
                    *h,
                    live,
                    status,
                );
            }
            StateCall::Free { c: h, slot } => {
                let (c, live) = self.handle(*h);
                let status = self.with_state_slot(*slot, |s| std.free_state()(c, s));
                let what = std.name("fmi2FreeFMUstate", "fmi3FreeFMUState");
                self.check(what, *h, live, status);
            }
            StateCall::SerializedSize {
                c: h,
                state,
                null_size,
            } => {
                let (c, live) = self.handle(*h);
                let state = self.state_value(*state);
                let mut size = 0usize;
                let status = std.serialized_size()(c, state, or_null_mut(*null_size, &mut size));
                let what = std.name("fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize");
                self.check(what, *h, live, status);
            }
            StateCall::Serialize {
                c: h,
                state,
                size,
                null_buffer,
            } => {
                let (c, live) = self.handle(*h);
                let state = self.state_value(*state);
                let mut exact = 0usize;
                if std.serialized_size()(c, state, &mut exact) != OK {
                    exact = 16;
                }
                let len = match size {
                    BufferSize::Exact => exact,
                    BufferSize::Short(n) => exact.saturating_sub(1 + *n as usize),
                    BufferSize::Long(n) => exact + *n as usize,
                    BufferSize::Zero => 0,
                };
                let mut buffer = vec![0u8; len];
                let out = or_null_mut(*null_buffer, buffer.as_mut_ptr());
                let status = std.serialize(c, state, out, len);
                let what = std.name("fmi2SerializeFMUstate", "fmi3SerializeFMUState");
                self.check(what, *h, live, status);
                if status == OK && len >= exact && !*null_buffer {
                    buffer.truncate(exact);
                    if self.serialized.len() < 8 {
                        self.serialized.push(buffer);
                    }
                }
            }
            StateCall::Deserialize { c: h, bytes, slot } => {
                let (c, live) = self.handle(*h);
                let pick = |i: u8| -> Vec<u8> {
                    if self.serialized.is_empty() {
                        Vec::new()
                    } else {
                        self.serialized[i as usize % self.serialized.len()].clone()
                    }
                };
                let (data, null_size): (Vec<u8>, Option<usize>) = match bytes {
                    Bytes::Serialized(i) => (pick(*i), None),
                    Bytes::Flipped(i, at, xor) => {
                        let mut data = pick(*i);
                        if !data.is_empty() {
                            let at = *at as usize % data.len();
                            data[at] ^= xor.max(&1);
                        }
                        (data, None)
                    }
                    Bytes::Truncated(i, keep) => {
                        let mut data = pick(*i);
                        data.truncate(*keep as usize % (data.len() + 1));
                        (data, None)
                    }
                    Bytes::Any(data) => (data.clone(), None),
                    Bytes::Null(n) => (Vec::new(), Some(*n as usize)),
                };
                let (pointer, size) = match null_size {
                    Some(n) => (ptr::null(), n),
                    None => (data.as_ptr(), data.len()),
                };
                let status = self.with_state_slot(*slot, |s| std.deserialize(c, pointer, size, s));
                let what = std.name("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState");
                self.check(what, *h, live, status);
            }
        }
    }

    unsafe fn run(&mut self, call: &Call) {
        match call {
            Call::GetTypesPlatform => {
                assert_eq!(CStr::from_ptr(fmi2GetTypesPlatform()), c"default");
            }
            Call::GetVersion => {
                assert_eq!(CStr::from_ptr(fmi2GetVersion()), c"2.0");
            }
            Call::Instantiate { .. } => self.instantiate(call),
            Call::FreeInstance(h) => self.free_instance(Std::Fmi2, *h),
            Call::SetDebugLogging {
                c: h,
                on,
                categories,
                null_array,
            } => {
                let (c, live) = self.handle(*h);
                let texts: Vec<Option<CString>> =
                    categories.iter().map(|t| self.text(t, None)).collect();
                let pointers: Vec<fmi2String> = texts.iter().map(as_ptr).collect();
                let array = or_null(*null_array, pointers.as_ptr());
                let status = fmi2SetDebugLogging(c, *on, pointers.len(), array);
                self.check("fmi2SetDebugLogging", *h, live, status);
            }
            Call::SetupExperiment {
                c: h,
                tolerance_defined,
                tolerance,
                start,
                stop_defined,
                stop,
            } => {
                let (c, live) = self.handle(*h);
                let status = fmi2SetupExperiment(
                    c,
                    *tolerance_defined as fmi2Boolean,
                    tolerance.value(),
                    start.value(),
                    *stop_defined as fmi2Boolean,
                    stop.value(),
                );
                self.check("fmi2SetupExperiment", *h, live, status);
            }
            Call::EnterInitializationMode(h) => {
                let (c, live) = self.handle(*h);
                let status = fmi2EnterInitializationMode(c);
                self.check("fmi2EnterInitializationMode", *h, live, status);
            }
            Call::ExitInitializationMode(h) => self.instance_call(
                Std::Fmi2.exit_initialization_mode(),
                "fmi2ExitInitializationMode",
                *h,
            ),
            Call::Terminate(h) => self.instance_call(Std::Fmi2.terminate(), "fmi2Terminate", *h),
            Call::Reset(h) => self.instance_call(Std::Fmi2.reset(), "fmi2Reset", *h),
            Call::DoStep {
                c: h,
                current,
                step,
                no_prior,
            } => {
                let (c, live) = self.handle(*h);
                let now = self.now(Std::Fmi2, c, live);
                let (current, step) = Self::step(now, *current, *step, live);
                let status = fmi2DoStep(c, current, step, *no_prior as fmi2Boolean);
                self.check("fmi2DoStep", *h, live, status);
            }
            Call::CancelStep(h) => {
                let (c, live) = self.handle(*h);
                let status = fmi2CancelStep(c);
                self.check("fmi2CancelStep", *h, live, status);
            }
            Call::GetReal {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let vrs = self.vrs(self.table(live), vrs, Kind::Real);
                let mut values = vec![0.0 as fmi2Real; vrs.len()];
                let status = fmi2GetReal(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null_mut(*null_value, values.as_mut_ptr()),
                );
                self.check("fmi2GetReal", *h, live, status);
            }
            Call::GetInteger {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let vrs = self.vrs(self.table(live), vrs, Kind::Integer);
                let mut values = vec![0 as fmi2Integer; vrs.len()];
                let status = fmi2GetInteger(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null_mut(*null_value, values.as_mut_ptr()),
                );
                self.check("fmi2GetInteger", *h, live, status);
            }
            Call::GetBoolean {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let vrs = self.vrs(self.table(live), vrs, Kind::Boolean);
                let mut values = vec![0 as fmi2Boolean; vrs.len()];
                let status = fmi2GetBoolean(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null_mut(*null_value, values.as_mut_ptr()),
                );
                self.check("fmi2GetBoolean", *h, live, status);
            }
            Call::GetString {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let vrs = self.vrs(self.table(live), vrs, Kind::String);
                let mut values: Vec<fmi2String> = vec![ptr::null(); vrs.len()];
                let status = fmi2GetString(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null_mut(*null_value, values.as_mut_ptr()),
                );
                self.check("fmi2GetString", *h, live, status);
                if status == OK && !*null_value {
                    read_strings("fmi2GetString", &values);
                }
            }
            Call::SetReal {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi2Real>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Real), x.value()))
                    .unzip();
                let status = fmi2SetReal(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null(*null_value, values.as_ptr()),
                );
                self.check("fmi2SetReal", *h, live, status);
            }
            Call::SetInteger {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi2Integer>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Integer), x))
                    .unzip();
                let status = fmi2SetInteger(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null(*null_value, values.as_ptr()),
                );
                self.check("fmi2SetInteger", *h, live, status);
            }
            Call::SetBoolean {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi2Boolean>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Boolean), x))
                    .unzip();
                let status = fmi2SetBoolean(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null(*null_value, values.as_ptr()),
                );
                self.check("fmi2SetBoolean", *h, live, status);
            }
            Call::SetString {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let vrs: Vec<u32> = values
                    .iter()
                    .map(|(v, _)| self.vr(table, *v, Kind::String))
                    .collect();
                let model = live.map(|l| l.model());
                let texts: Vec<Option<CString>> =
                    values.iter().map(|(_, t)| self.text(t, model)).collect();
                let pointers: Vec<fmi2String> = texts.iter().map(as_ptr).collect();
                let status = fmi2SetString(
                    c,
                    or_null(*null_vr, vrs.as_ptr()),
                    vrs.len(),
                    or_null(*null_value, pointers.as_ptr()),
                );
                self.check("fmi2SetString", *h, live, status);
            }
            Call::State(call) => self.state_call(Std::Fmi2, call),
            Call::DirectionalDerivative {
                c: h,
                n_unknown,
                n_known,
                null_arrays,
            } => {
                let (c, live) = self.handle(*h);
                let (nu, nk) = (*n_unknown as usize % 8, *n_known as usize % 8);
                let (vu, vk) = (vec![0u32; nu], vec![0u32; nk]);
                let dk = vec![1.0; nk];
                let mut du = vec![0.0; nu];
                let null = *null_arrays;
                let status = fmi2GetDirectionalDerivative(
                    c,
                    or_null(null, vu.as_ptr()),
                    nu,
                    or_null(null, vk.as_ptr()),
                    nk,
                    or_null(null, dk.as_ptr()),
                    or_null_mut(null, du.as_mut_ptr()),
                );
                self.check("fmi2GetDirectionalDerivative", *h, live, status);
            }
            Call::SetRealInputDerivatives {
                c: h,
                n,
                null_arrays,
            } => {
                let (c, live) = self.handle(*h);
                let n = *n as usize % 8;
                let (vr, order, value) = (vec![0u32; n], vec![1; n], vec![0.0; n]);
                let null = *null_arrays;
                let status = fmi2SetRealInputDerivatives(
                    c,
                    or_null(null, vr.as_ptr()),
                    n,
                    or_null(null, order.as_ptr()),
                    or_null(null, value.as_ptr()),
                );
                self.check("fmi2SetRealInputDerivatives", *h, live, status);
            }
            Call::GetRealOutputDerivatives {
                c: h,
                n,
                null_arrays,
            } => {
                let (c, live) = self.handle(*h);
                let n = *n as usize % 8;
                let (vr, order) = (vec![0u32; n], vec![1; n]);
                let mut value = vec![0.0; n];
                let null = *null_arrays;
                let status = fmi2GetRealOutputDerivatives(
                    c,
                    or_null(null, vr.as_ptr()),
                    n,
                    or_null(null, order.as_ptr()),
                    or_null_mut(null, value.as_mut_ptr()),
                );
                self.check("fmi2GetRealOutputDerivatives", *h, live, status);
            }
            Call::Status {
                c: h,
                which,
                kind,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                // Mostly the four kinds of FMI 2.0, sometimes any number.
                let kind = if *kind > 16 { kind % 4 } else { *kind };
                let null = *null_value;
                let status = match which % 5 {
                    0 => {
                        let mut v: fmi2Status = 0;
                        fmi2GetStatus(c, kind, or_null_mut(null, &mut v))
                    }
                    1 => {
                        let mut v: fmi2Real = 0.0;
                        fmi2GetRealStatus(c, kind, or_null_mut(null, &mut v))
                    }
                    2 => {
                        let mut v: fmi2Integer = 0;
                        fmi2GetIntegerStatus(c, kind, or_null_mut(null, &mut v))
                    }
                    3 => {
                        let mut v: fmi2Boolean = 0;
                        fmi2GetBooleanStatus(c, kind, or_null_mut(null, &mut v))
                    }
                    _ => {
                        let mut v: fmi2String = ptr::null();
                        fmi2GetStringStatus(c, kind, or_null_mut(null, &mut v))
                    }
                };
                self.check("fmi2Get*Status", *h, live, status);
            }
            Call::Reenter { c: h, frees } => {
                let (c, _) = self.handle(*h);
                REENTER.store(c as usize, Ordering::Relaxed);
                REENTER_FREES.store(*frees, Ordering::Relaxed);
            }

            // FMI 3.0.
            Call::GetVersion3 => {
                assert_eq!(CStr::from_ptr(fmi3GetVersion()), c"3.0");
            }
            Call::Instantiate3 { .. } => self.instantiate3(call),
            Call::InstantiateOther3 { .. } => self.instantiate_other3(call),
            Call::Start {
                slot,
                interface,
                fmi3,
                start_ms,
                logging_on,
            } => self.start(*slot, *interface, *fmi3, *start_ms, *logging_on),
            Call::FreeInstance3(h) => self.free_instance(Std::Fmi3, *h),
            Call::SetDebugLogging3 {
                c: h,
                on,
                categories,
                null_array,
            } => {
                let (c, live) = self.handle(*h);
                let texts: Vec<Option<CString>> =
                    categories.iter().map(|t| self.text(t, None)).collect();
                let pointers: Vec<fmi3String> = texts.iter().map(as_ptr).collect();
                let array = or_null(*null_array, pointers.as_ptr());
                let status = fmi3SetDebugLogging(c, *on, pointers.len(), array);
                self.check("fmi3SetDebugLogging", *h, live, status);
            }
            Call::EnterInitializationMode3 {
                c: h,
                tolerance_defined,
                tolerance,
                start,
                stop_defined,
                stop,
            } => {
                let (c, live) = self.handle(*h);
                let status = fmi3EnterInitializationMode(
                    c,
                    *tolerance_defined,
                    tolerance.value(),
                    start.value(),
                    *stop_defined,
                    stop.value(),
                );
                self.check("fmi3EnterInitializationMode", *h, live, status);
            }
            Call::ExitInitializationMode3(h) => self.instance_call(
                Std::Fmi3.exit_initialization_mode(),
                "fmi3ExitInitializationMode",
                *h,
            ),
            Call::Terminate3(h) => self.instance_call(Std::Fmi3.terminate(), "fmi3Terminate", *h),
            Call::Reset3(h) => self.instance_call(Std::Fmi3.reset(), "fmi3Reset", *h),
            Call::DoStep3 {
                c: h,
                current,
                step,
                no_prior,
                outs,
            } => {
                let (c, live) = self.handle(*h);
                let now = self.now(Std::Fmi3, c, live);
                let (current, step) = Self::step(now, *current, *step, live);
                let null = match outs {
                    Outs::Valid => 0,
                    Outs::Null(mask) => mask & 0xf,
                };
                // Set to what the library must overwrite.
                let (mut event, mut terminate, mut early, mut last) = (true, true, true, f64::NAN);
                let status = fmi3DoStep(
                    c,
                    current,
                    step,
                    *no_prior,
                    or_null_mut(null & 1 != 0, &mut event),
                    or_null_mut(null & 2 != 0, &mut terminate),
                    or_null_mut(null & 4 != 0, &mut early),
                    or_null_mut(null & 8 != 0, &mut last),
                );
                self.check("fmi3DoStep", *h, live, status);
                if null != 0 {
                    assert_eq!(status, ERROR, "fmi3DoStep with a NULL result pointer");
                } else if status == OK {
                    assert!(
                        !event && !terminate && !early,
                        "fmi3DoStep: event {event}, terminate {terminate}, early return {early}"
                    );
                }
            }
            Call::GetFloat64 {
                c: h,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => {
                self.get3(
                    "fmi3GetFloat64",
                    *h,
                    vrs,
                    Kind::Real,
                    *n_values,
                    (*null_vr, *null_value),
                    0.0,
                    |c, vr, nvr, v, n| fmi3GetFloat64(c, vr, nvr, v, n),
                );
            }
            Call::GetInt32 {
                c: h,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => {
                self.get3(
                    "fmi3GetInt32",
                    *h,
                    vrs,
                    Kind::Int32,
                    *n_values,
                    (*null_vr, *null_value),
                    0 as fmi3Int32,
                    |c, vr, nvr, v, n| fmi3GetInt32(c, vr, nvr, v, n),
                );
            }
            Call::GetInt64 {
                c: h,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => {
                self.get3(
                    "fmi3GetInt64",
                    *h,
                    vrs,
                    Kind::Enumeration,
                    *n_values,
                    (*null_vr, *null_value),
                    0 as fmi3Int64,
                    |c, vr, nvr, v, n| fmi3GetInt64(c, vr, nvr, v, n),
                );
            }
            Call::GetBoolean3 {
                c: h,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => {
                // Bytes (set to 0xAA, which must be overwritten), read as bytes: a C bool.
                let values = self.get3(
                    "fmi3GetBoolean",
                    *h,
                    vrs,
                    Kind::Boolean,
                    *n_values,
                    (*null_vr, *null_value),
                    0xaa_u8,
                    |c, vr, nvr, v, n| fmi3GetBoolean(c, vr, nvr, v as *mut bool, n),
                );
                for b in values.unwrap_or_default() {
                    assert!(b <= 1, "fmi3GetBoolean wrote the byte {b}");
                }
            }
            Call::GetString3 {
                c: h,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => {
                let values = self.get3(
                    "fmi3GetString",
                    *h,
                    vrs,
                    Kind::String,
                    *n_values,
                    (*null_vr, *null_value),
                    ptr::null(),
                    |c, vr, nvr, v, n| fmi3GetString(c, vr, nvr, v, n),
                );
                read_strings("fmi3GetString", &values.unwrap_or_default());
            }
            Call::SetFloat64 {
                c: h,
                values,
                n_values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi3Float64>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Real), x.value()))
                    .unzip();
                let status = self.set3(
                    "fmi3SetFloat64",
                    *h,
                    live,
                    c,
                    &vrs,
                    values,
                    0.0,
                    *n_values,
                    (*null_vr, *null_value),
                    |c, vr, nvr, v, n| fmi3SetFloat64(c, vr, nvr, v, n),
                );
                if vrs.contains(&table.time_vr()) {
                    assert_eq!(status, ERROR, "fmi3SetFloat64 set the independent variable");
                }
            }
            Call::SetInt32 {
                c: h,
                values,
                n_values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi3Int32>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Int32), x))
                    .unzip();
                self.set3(
                    "fmi3SetInt32",
                    *h,
                    live,
                    c,
                    &vrs,
                    values,
                    0,
                    *n_values,
                    (*null_vr, *null_value),
                    |c, vr, nvr, v, n| fmi3SetInt32(c, vr, nvr, v, n),
                );
            }
            Call::SetInt64 {
                c: h,
                values,
                n_values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, values): (Vec<u32>, Vec<fmi3Int64>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, Kind::Enumeration), x.value()))
                    .unzip();
                let n = n_values.of(vrs.len());
                let beyond = values.iter().take(n).any(|&x| i32::try_from(x).is_err());
                let status = self.set3(
                    "fmi3SetInt64",
                    *h,
                    live,
                    c,
                    &vrs,
                    values,
                    1,
                    *n_values,
                    (*null_vr, *null_value),
                    |c, vr, nvr, v, n| fmi3SetInt64(c, vr, nvr, v, n),
                );
                if beyond && !*null_value {
                    assert_eq!(status, ERROR, "fmi3SetInt64 took a value beyond Int32");
                }
            }
            Call::SetBoolean3 {
                c: h,
                values,
                n_values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let (vrs, bytes): (Vec<u32>, Vec<u8>) = values
                    .iter()
                    .map(|&(v, b)| (self.vr(table, v, Kind::Boolean), b.byte()))
                    .unzip();
                let n = n_values.of(vrs.len());
                let not_a_bool = bytes.iter().take(n).any(|&b| b > 1);
                // The bytes go through a `*const bool` as a C caller's would; never read
                // here as a Rust bool.
                let status = self.set3(
                    "fmi3SetBoolean",
                    *h,
                    live,
                    c,
                    &vrs,
                    bytes,
                    0,
                    *n_values,
                    (*null_vr, *null_value),
                    |c, vr, nvr, v, n| fmi3SetBoolean(c, vr, nvr, v as *const bool, n),
                );
                if not_a_bool && !*null_value {
                    assert_eq!(status, ERROR, "fmi3SetBoolean took a byte other than 0, 1");
                }
            }
            Call::SetString3 {
                c: h,
                values,
                n_values,
                null_vr,
                null_value,
            } => {
                let (c, live) = self.handle(*h);
                let table = self.table(live);
                let vrs: Vec<u32> = values
                    .iter()
                    .map(|(v, _)| self.vr(table, *v, Kind::String))
                    .collect();
                let model = live.map(|l| l.model());
                let texts: Vec<Option<CString>> =
                    values.iter().map(|(_, t)| self.text(t, model)).collect();
                let pointers: Vec<fmi3String> = texts.iter().map(as_ptr).collect();
                self.set3(
                    "fmi3SetString",
                    *h,
                    live,
                    c,
                    &vrs,
                    pointers,
                    ptr::null(),
                    *n_values,
                    (*null_vr, *null_value),
                    |c, vr, nvr, v, n| fmi3SetString(c, vr, nvr, v, n),
                );
            }
            Call::OtherType3 {
                c: h,
                ty,
                set,
                vrs,
                n_values,
                null_vr,
                null_value,
            } => self.other_type3(*h, *ty, *set, vrs, *n_values, *null_vr, *null_value),
            Call::State3(call) => self.state_call(Std::Fmi3, call),
            Call::Unsupported3 {
                c: h,
                which,
                vrs,
                n,
                null_arrays,
                x,
            } => self.unsupported3(*h, *which, vrs, *n, *null_arrays, *x),
        }
    }

    /// A function of `c` alone (ExitInitializationMode, Terminate, Reset).
    unsafe fn instance_call(&mut self, f: InstanceFn, what: &str, h: Handle) {
        let (c, live) = self.handle(h);
        let status = f(c);
        self.check(what, h, live, status);
        if what.ends_with("Reset") && status == OK {
            if let Some(live) = live {
                self.tame(live);
            }
        }
    }

    /// Frees every instance (their states with them); then no handle of this input may
    /// answer as an instance of either standard.
    unsafe fn finish(mut self) {
        REENTER.store(0, Ordering::Relaxed);
        for slot in 0..SLOTS {
            if let Some(live) = self.slots[slot].take() {
                // Alive until freed here, unless the logger freed it.
                if !freed_by_logger(live.c) {
                    assert!(
                        live.std.is_live(live.c),
                        "an instance was freed by a call that should not free it"
                    );
                }
                live.std.free_instance()(live.c);
                self.freed.push(live.c);
            }
        }
        for &c in &self.freed {
            fmi2FreeInstance(c);
            fmi3FreeInstance(c);
            for std in [Std::Fmi2, Std::Fmi3] {
                assert!(!std.is_live(c), "a freed instance answered");
            }
        }
        for &s in &self.states {
            for std in [Std::Fmi2, Std::Fmi3] {
                assert!(!std.is_live(s), "an FMU state answered as an instance");
            }
        }
    }
}

/// The strings a getter returned with OK: non-NULL, NUL-terminated, read now (valid
/// until the next call on the instance).
unsafe fn read_strings(what: &str, values: &[*const c_char]) {
    for &s in values {
        assert!(!s.is_null(), "{what}: NULL string with OK");
        let _ = CStr::from_ptr(s).to_bytes().len();
    }
}

/// Fatal statuses seen (from FaultProbe: any other is a failed check).
static FATALS: AtomicUsize = AtomicUsize::new(0);

/// One input, as the fuzzer runs it.
fn run_input(input: &Input) {
    let mut session = Session::new();
    for call in input.calls.iter().take(MAX_CALLS) {
        // SAFETY: every pointer passed is NULL, a handle, or points to live memory of the
        // size the call is told (see the module comment).
        unsafe { session.run(call) };
    }
    unsafe { session.finish() };
}

// ---------------------------------------------------------------------------------------
// Seeds: sequences random bytes seldom reach (FaultProbe's injected panic and failure
// after a Start, in each standard; the FMU states of a stepping FMI 3.0 instance; one
// instance of each standard with every handle and state passed to the other), written by
// the target binary itself (`CONTOUR_FUZZ_SEEDS=<folder>`, as fuzz/common.sh does) so
// that they follow the input format: each is written as `arbitrary` reads it, decoded
// back and compared with the sequence it should be (a change to the calls fails here,
// loudly), then run.

/// Bytes as `arbitrary` 1.x reads them: an enum is a u32 whose high bits choose the
/// variant (found by decoding, so reordered or added variants change nothing here), a
/// bool and a u8 one byte, an i32 four (little-endian), each element of a Vec a 1 before
/// it and a 0 after the last (the input's own list ends with the data instead).
#[derive(Default)]
struct Encoder(Vec<u8>);

impl Encoder {
    /// The variant of `T` whose Debug text begins with `name`.
    fn tag<T: for<'a> Arbitrary<'a> + std::fmt::Debug>(mut self, name: &str) -> Self {
        let x = (0..=255u32)
            .map(|i| i << 24)
            .find(|&x| {
                let mut bytes = x.to_le_bytes().to_vec();
                bytes.resize(256, 0);
                let value = T::arbitrary(&mut Unstructured::new(&bytes)).expect("decodes");
                format!("{value:?}")
                    .strip_prefix(name)
                    .is_some_and(|rest| !rest.starts_with(|c: char| c.is_alphanumeric()))
            })
            .unwrap_or_else(|| panic!("no variant {name} of {}", std::any::type_name::<T>()));
        self.0.extend(x.to_le_bytes());
        self
    }

    fn u8(mut self, x: u8) -> Self {
        self.0.push(x);
        self
    }

    fn bool(self, b: bool) -> Self {
        self.u8(b as u8)
    }

    fn i32(mut self, x: i32) -> Self {
        self.0.extend(x.to_le_bytes());
        self
    }

    /// Another element of a list follows.
    fn item(self) -> Self {
        self.u8(1)
    }

    /// The end of a list.
    fn end(self) -> Self {
        self.u8(0)
    }

    fn call(self, name: &str) -> Self {
        self.item().tag::<Call>(name)
    }

    fn slot(self, i: u8) -> Self {
        self.tag::<Handle>("Slot").u8(i)
    }

    fn start(self, slot: u8, interface: u8, fmi3: bool) -> Self {
        self.call("Start")
            .u8(slot)
            .u8(interface)
            .bool(fmi3)
            .u8(0)
            .bool(true)
    }

    /// DoStep or DoStep3 from now, 1 ms.
    fn step(self, fmi3: bool, slot: u8) -> Self {
        let e = self
            .call(if fmi3 { "DoStep3" } else { "DoStep" })
            .slot(slot)
            .tag::<Current>("Now")
            .tag::<Step>("Ticks")
            .u8(10)
            .bool(false);
        if fmi3 {
            e.tag::<Outs>("Valid")
        } else {
            e
        }
    }

    fn state_var(self) -> Self {
        self.tag::<StateSlot>("Var").tag::<StateArg>("Null")
    }
}

fn interface_index(identifier: &str, units: &str) -> u8 {
    models::interfaces()
        .iter()
        .position(|i| i.model.identifier == identifier && i.units.name() == units)
        .unwrap_or_else(|| panic!("no interface {identifier} ({units})")) as u8
}

fn start(slot: u8, interface: u8, fmi3: bool) -> Call {
    Call::Start {
        slot,
        interface,
        fmi3,
        start_ms: 0,
        logging_on: true,
    }
}

fn step(fmi3: bool, slot: u8) -> Call {
    let (c, current, step) = (Handle::Slot(slot), Current::Now, Step::Ticks(10));
    if fmi3 {
        Call::DoStep3 {
            c,
            current,
            step,
            no_prior: false,
            outs: Outs::Valid,
        }
    } else {
        Call::DoStep {
            c,
            current,
            step,
            no_prior: false,
        }
    }
}

/// Each seed: its name, the calls, the bytes that must decode to them, and whether it must
/// bring a Fatal (FaultProbe's panic).
fn seeds() -> Vec<(&'static str, Vec<Call>, Encoder, bool)> {
    let probe = interface_index("FaultProbe", "mm");
    let ccc = interface_index("ContourCCC2D", "SI");
    let interpolator = interface_index("PathInterpolator2D", "mm");
    let mut seeds = Vec::new();
    for fmi3 in [false, true] {
        // Start; set `panic` (FaultProbe's first Boolean); step: Fatal; step again: Error;
        // FreeInstance of the other standard (the instance stays); on a fresh instance
        // `fail` (its second Boolean) and a step: Error.
        let (this, other) = if fmi3 {
            ("FreeInstance3", "FreeInstance")
        } else {
            ("FreeInstance", "FreeInstance3")
        };
        // The slot-th Boolean of slot `slot`: 0 `panic`, 1 `fail`.
        let set_boolean = |slot: u8| {
            if fmi3 {
                Call::SetBoolean3 {
                    c: Handle::Slot(slot),
                    values: vec![(VrArg::OfType(slot), BoolByte::True)],
                    n_values: Count::Same,
                    null_vr: false,
                    null_value: false,
                }
            } else {
                Call::SetBoolean {
                    c: Handle::Slot(slot),
                    values: vec![(VrArg::OfType(slot), 1)],
                    null_vr: false,
                    null_value: false,
                }
            }
        };
        let free = |name: &str, slot: u8| match name {
            "FreeInstance" => Call::FreeInstance(Handle::Slot(slot)),
            _ => Call::FreeInstance3(Handle::Slot(slot)),
        };
        let calls = vec![
            start(0, probe, fmi3),
            set_boolean(0),
            step(fmi3, 0),
            step(fmi3, 0),
            free(other, 0),
            start(1, probe, fmi3),
            set_boolean(1),
            step(fmi3, 1),
            free(this, 0),
            free(other, 1),
        ];
        let mut e = Encoder::default();
        e = e.start(0, probe, fmi3);
        for slot in [0u8, 1] {
            if slot == 1 {
                e = e.call(other).slot(0).start(1, probe, fmi3);
            }
            e = if fmi3 {
                e.call("SetBoolean3")
                    .slot(slot)
                    .item()
                    .tag::<VrArg>("OfType")
                    .u8(slot)
                    .tag::<BoolByte>("True")
                    .end()
                    .tag::<Count>("Same")
                    .bool(false)
                    .bool(false)
            } else {
                e.call("SetBoolean")
                    .slot(slot)
                    .item()
                    .tag::<VrArg>("OfType")
                    .u8(slot)
                    .i32(1)
                    .end()
                    .bool(false)
                    .bool(false)
            };
            e = e.step(fmi3, slot);
            if slot == 0 {
                e = e.step(fmi3, 0);
            }
        }
        e = e.call(this).slot(0).call(other).slot(1);
        let name = if fmi3 {
            "fmi3-fault-probe"
        } else {
            "fmi2-fault-probe"
        };
        seeds.push((name, calls, e, true));
    }
    // A stepping FMI 3.0 instance's states: get, serialize, deserialize, set; its time.
    let calls = vec![
        start(0, ccc, true),
        step(true, 0),
        step(true, 0),
        Call::State3(StateCall::Get {
            c: Handle::Slot(0),
            slot: StateSlot::Var(StateArg::Null),
        }),
        Call::State3(StateCall::Serialize {
            c: Handle::Slot(0),
            state: StateArg::Made(0),
            size: BufferSize::Exact,
            null_buffer: false,
        }),
        Call::State3(StateCall::Deserialize {
            c: Handle::Slot(0),
            bytes: Bytes::Serialized(0),
            slot: StateSlot::Var(StateArg::Null),
        }),
        Call::State3(StateCall::Set {
            c: Handle::Slot(0),
            state: StateArg::Made(1),
        }),
        Call::GetFloat64 {
            c: Handle::Slot(0),
            vrs: vec![VrArg::Time, VrArg::OfType(0)],
            n_values: Count::Same,
            null_vr: false,
            null_value: false,
        },
        step(true, 0),
    ];
    let e = Encoder::default()
        .start(0, ccc, true)
        .step(true, 0)
        .step(true, 0)
        .call("State3")
        .tag::<StateCall>("Get")
        .slot(0)
        .state_var()
        .call("State3")
        .tag::<StateCall>("Serialize")
        .slot(0)
        .tag::<StateArg>("Made")
        .u8(0)
        .tag::<BufferSize>("Exact")
        .bool(false)
        .call("State3")
        .tag::<StateCall>("Deserialize")
        .slot(0)
        .tag::<Bytes>("Serialized")
        .u8(0)
        .state_var()
        .call("State3")
        .tag::<StateCall>("Set")
        .slot(0)
        .tag::<StateArg>("Made")
        .u8(1)
        .call("GetFloat64")
        .slot(0)
        .item()
        .tag::<VrArg>("Time")
        .item()
        .tag::<VrArg>("OfType")
        .u8(0)
        .end()
        .tag::<Count>("Same")
        .bool(false)
        .bool(false)
        .step(true, 0);
    seeds.push(("fmi3-states", calls, e, false));
    // One instance of each standard on the same interface, each given the other's handle
    // and FMU state (refused), and the FMI 2.0 state serialized, deserialized by the FMI
    // 3.0 instance (the bytes are the same in both standards), set and stepped.
    let calls = vec![
        start(0, interpolator, false),
        start(1, interpolator, true),
        step(false, 0),
        step(true, 1),
        Call::State(StateCall::Get {
            c: Handle::Slot(0),
            slot: StateSlot::Var(StateArg::Null),
        }),
        Call::State3(StateCall::Set {
            c: Handle::Slot(1),
            state: StateArg::Made(0),
        }),
        Call::State(StateCall::Serialize {
            c: Handle::Slot(0),
            state: StateArg::Made(0),
            size: BufferSize::Exact,
            null_buffer: false,
        }),
        Call::State3(StateCall::Deserialize {
            c: Handle::Slot(1),
            bytes: Bytes::Serialized(0),
            slot: StateSlot::Var(StateArg::Null),
        }),
        Call::State3(StateCall::Set {
            c: Handle::Slot(1),
            state: StateArg::Made(1),
        }),
        step(true, 1),
        step(true, 0),
        step(false, 1),
        Call::FreeInstance3(Handle::Slot(0)),
        Call::FreeInstance(Handle::Slot(1)),
    ];
    let e = Encoder::default()
        .start(0, interpolator, false)
        .start(1, interpolator, true)
        .step(false, 0)
        .step(true, 1)
        .call("State")
        .tag::<StateCall>("Get")
        .slot(0)
        .state_var()
        .call("State3")
        .tag::<StateCall>("Set")
        .slot(1)
        .tag::<StateArg>("Made")
        .u8(0)
        .call("State")
        .tag::<StateCall>("Serialize")
        .slot(0)
        .tag::<StateArg>("Made")
        .u8(0)
        .tag::<BufferSize>("Exact")
        .bool(false)
        .call("State3")
        .tag::<StateCall>("Deserialize")
        .slot(1)
        .tag::<Bytes>("Serialized")
        .u8(0)
        .state_var()
        .call("State3")
        .tag::<StateCall>("Set")
        .slot(1)
        .tag::<StateArg>("Made")
        .u8(1)
        .step(true, 1)
        .step(true, 0)
        .step(false, 1)
        .call("FreeInstance3")
        .slot(0)
        .call("FreeInstance")
        .slot(1);
    seeds.push(("both-standards", calls, e, false));
    seeds
}

/// Writes the seeds to `dir`, each checked: it decodes to its calls and runs clean (a
/// FaultProbe seed bringing its Fatal).
fn write_seeds(dir: &std::path::Path) {
    std::fs::create_dir_all(dir).expect("seed folder");
    for (name, calls, bytes, fatal) in seeds() {
        let decoded =
            Input::arbitrary_take_rest(Unstructured::new(&bytes.0)).expect("a seed decodes");
        let expected = Input { calls };
        assert_eq!(
            format!("{decoded:?}"),
            format!("{expected:?}"),
            "seed {name}: its bytes do not decode to its calls (the calls changed?)"
        );
        let before = FATALS.load(Ordering::Relaxed);
        run_input(&decoded);
        let fatals = FATALS.load(Ordering::Relaxed) - before;
        assert_eq!(fatal, fatals > 0, "seed {name}: {fatals} Fatal statuses");
        std::fs::write(dir.join(format!("seed-{name}")), &bytes.0).expect("seed file");
    }
}

fuzz_target!(
    init: {
        install_panic_hook();
        // Plans within the 10 s a fuzz input may take (FUZZ_SAMPLE_BUDGET): a longer
        // one is refused like any other.
        contour_fmu::fmi::set_plan_sample_budget(FUZZ_SAMPLE_BUDGET);
        if let Some(dir) = std::env::var_os("CONTOUR_FUZZ_SEEDS") {
            write_seeds(std::path::Path::new(&dir));
            std::process::exit(0);
        }
    },
    |input: Input| run_input(&input)
);
