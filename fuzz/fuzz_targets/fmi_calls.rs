//! Random sequences of FMI 2.0 calls with random arguments against every model (the six
//! packaged ones and FaultProbe), over a few instance slots: NULL, freed and foreign
//! handles, wrong GUIDs, NaN/Inf/huge/zero/negative times and steps, unknown value
//! references, NULL arrays, non-UTF-8 strings, FMU states freed, foreign, made up,
//! serialized, corrupted and deserialized, and a logger that calls back into (and
//! frees) an instance.
//!
//! Never passed: what is undefined behaviour on the caller's side in C (an array shorter
//! than `nvr`, a buffer shorter than the size given, a garbage address where the library
//! must write). The oracle: no panic except FaultProbe's injected one (which must come
//! back as fmi2Fatal), no fmi2Fatal from any other model, fmi2Error from every freed or
//! NULL handle, and whatever AddressSanitizer and LeakSanitizer see: every instance is
//! freed at the end of each input.
#![no_main]

use std::ffi::{c_char, CString};
use std::ptr;
use std::sync::atomic::Ordering;
use std::sync::OnceLock;

use arbitrary::Arbitrary;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::VarType;
use contour_fmu::models;
use contour_fmu_fuzz::*;
use fmi2_bindings::{
    fmi2Boolean, fmi2CallbackFunctions, fmi2Component, fmi2FMUstate, fmi2Integer, fmi2Real,
    fmi2Status, fmi2String, fmi2ValueReference,
};
use libfuzzer_sys::fuzz_target;

const SLOTS: usize = 4;
const MAX_CALLS: usize = 64;
/// Instantiations per input (each builds a model and its variable table).
const MAX_INSTANTIATIONS: usize = 8;
/// Longest step for a sampled model: at the shortest period the models accept (1 µs) it
/// is 5 000 samples, so an input stays cheap. (A longer step costs proportionally more
/// samples, by design: not worth fuzzing.)
const MAX_SAMPLED_STEP: f64 = 5e-3;

const OK: fmi2Status = 0;
const ERROR: fmi2Status = 3;
const FATAL: fmi2Status = 4;

#[derive(Arbitrary, Debug)]
struct Input {
    calls: Vec<Call>,
}

/// An `fmi2Component` argument.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum Handle {
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
    Max,
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Guid {
    Right,
    /// Another model's.
    Other(u8),
    Lowercase,
    Truncated(u8),
}

#[derive(Arbitrary, Debug, Clone)]
enum GuidArg {
    Model(Guid),
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

#[derive(Arbitrary, Debug, Clone, Copy)]
enum Callbacks {
    Checking,
    Quiet,
    NullStruct,
    NullLogger,
}

#[derive(Arbitrary, Debug, Clone, Copy)]
enum FmuType {
    CoSimulation,
    ModelExchange,
    Other(u32),
}

/// A value an `fmi2FMUstate` argument or variable holds.
#[derive(Arbitrary, Debug, Clone, Copy)]
enum StateArg {
    /// The n-th state made in this input (it may be freed, or another instance's).
    Made(u8),
    Null,
    Int(usize),
    /// An instance handle in place of a state.
    Instance(u8),
}

/// The `fmi2FMUstate*` argument: the address of a variable, or a misuse of it.
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
    /// A state serialized earlier in this input.
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

#[derive(Arbitrary, Debug, Clone)]
enum Call {
    GetTypesPlatform,
    GetVersion,
    Instantiate {
        slot: u8,
        model: u8,
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
    GetFmuState {
        c: Handle,
        slot: StateSlot,
    },
    SetFmuState {
        c: Handle,
        state: StateArg,
    },
    FreeFmuState {
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
    /// From now on the logger calls back into this instance (and perhaps frees it).
    Reenter {
        c: Handle,
        frees: bool,
    },
}

/// Every instantiable model with its GUID, computed once (a SHA-256 of the whole
/// variable table each time would be most of an input's work).
fn guids() -> &'static [(String, &'static ModelInfo)] {
    static GUIDS: OnceLock<Vec<(String, &'static ModelInfo)>> = OnceLock::new();
    GUIDS.get_or_init(|| {
        models::instantiable()
            .into_iter()
            .map(|m| (m.guid(), m))
            .collect()
    })
}

fn guid_of(model: &ModelInfo) -> &'static str {
    let (guid, _) = guids()
        .iter()
        .find(|(_, m)| std::ptr::eq(*m, model))
        .expect("an instantiable model");
    guid
}

fn model_of(guid: &str) -> Option<&'static ModelInfo> {
    guids().iter().find(|(g, _)| g == guid).map(|(_, m)| *m)
}

/// One instance slot.
#[derive(Clone, Copy)]
struct Live {
    c: fmi2Component,
    model: &'static ModelInfo,
}

/// Everything one input made; freed at the end.
struct Session {
    models: Vec<&'static ModelInfo>,
    texts: Vec<String>,
    slots: [Option<Live>; SLOTS],
    freed: Vec<fmi2Component>,
    /// Every FMU state handed out, freed ones included.
    states: Vec<fmi2FMUstate>,
    serialized: Vec<Vec<u8>>,
    /// Kept alive for every instance that may still use them (the library copies them
    /// today, but the standard lets it keep the pointer).
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

const NOT_UTF8: &[u8] = b"caf\xe9\xff\xfe";

impl Session {
    fn new() -> Self {
        Session {
            models: models::instantiable(),
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

    /// The pointer for `h` and, when it is one of our live instances, its model.
    fn handle(&mut self, h: Handle) -> (fmi2Component, Option<&'static ModelInfo>) {
        match h {
            Handle::Slot(i) => match self.slots[i as usize % SLOTS] {
                Some(live) => (live.c, Some(live.model)),
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
                let model = self.live().find(|l| l.c as usize == x).map(|l| l.model);
                (x as fmi2Component, model)
            }
            _ => (ptr::null_mut(), None),
        }
    }

    fn live(&self) -> impl Iterator<Item = Live> + '_ {
        self.slots.iter().flatten().copied()
    }

    /// The model whose table picks value references for a call on `model` (any model's
    /// when the handle is not a live instance).
    fn table(&self, model: Option<&'static ModelInfo>) -> &'static ModelInfo {
        model.unwrap_or(self.models[0])
    }

    /// The checks every status is subject to.
    fn check(&self, what: &str, h: Handle, model: Option<&ModelInfo>, status: fmi2Status) {
        assert!((0..=4).contains(&status), "{what}: status {status}");
        match h {
            // Dead for good: handles are never reused.
            Handle::Freed(_) | Handle::Null | Handle::Stack => {
                assert_eq!(status, ERROR, "{what} on a handle that is not an instance")
            }
            Handle::State(_) => assert_eq!(status, ERROR, "{what} on an FMU state"),
            Handle::Slot(_) | Handle::Int(_) => {}
        }
        if status == FATAL {
            let model = model.map_or("?", |m| m.identifier);
            assert_eq!(model, "FaultProbe", "{what}: fmi2Fatal from {model}");
        }
    }

    fn vr(&self, table: &ModelInfo, arg: VrArg, var_type: VarType) -> fmi2ValueReference {
        let n = table.variables.len() as u32;
        match arg {
            VrArg::OfType(i) => {
                let of_type: Vec<u32> = table
                    .variables
                    .iter()
                    .filter(|v| v.var_type() == var_type)
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
            VrArg::Max => u32::MAX,
        }
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

    /// Calls `f` with the `fmi2FMUstate*` argument `slot`; remembers a state the library
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
    unsafe fn tame(&mut self, c: fmi2Component, model: &ModelInfo) {
        if model.identifier != "PathInterpolator5X" {
            return;
        }
        let vr = self.vr(model, VrArg::OfType(0), VarType::String);
        let value = c"part.cl".as_ptr();
        fmi2SetString(c, &vr, 1, &value);
    }

    unsafe fn instantiate(
        &mut self,
        slot: u8,
        model: u8,
        guid: &GuidArg,
        name: &NameArg,
        resources: &ResourceArg,
        callbacks: Callbacks,
        fmu_type: FmuType,
        visible: bool,
        logging_on: bool,
        environment: usize,
    ) {
        if self.instantiations >= MAX_INSTANTIATIONS {
            return;
        }
        self.instantiations += 1;
        let info = self.models[model as usize % self.models.len()];
        let guid: Option<CString> = match guid {
            GuidArg::Model(g) => {
                let text = match g {
                    Guid::Right => guid_of(info).to_string(),
                    Guid::Other(i) => {
                        guid_of(self.models[*i as usize % self.models.len()]).to_string()
                    }
                    Guid::Lowercase => guid_of(info).to_uppercase(),
                    Guid::Truncated(n) => {
                        let g = guid_of(info);
                        g[..(*n as usize % g.len())].to_string()
                    }
                };
                Some(c_string(text.as_bytes()))
            }
            GuidArg::Null => None,
            GuidArg::NotUtf8 => Some(c_string(NOT_UTF8)),
            GuidArg::Any(bytes) => Some(c_string(bytes)),
        };
        let name: Option<CString> = match name {
            NameArg::Fixed => Some(c_string(b"fuzzed instance")),
            NameArg::Null => None,
            NameArg::Empty => Some(c_string(b"")),
            NameArg::Blank => Some(c_string(b" \t ")),
            NameArg::NotUtf8 => Some(c_string(NOT_UTF8)),
            NameArg::Any(bytes) => Some(c_string(bytes)),
        };
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
            ResourceArg::Any(bytes) => Some(c_string(
                &bytes
                    .iter()
                    .map(|&b| if b == b'/' { b'_' } else { b })
                    .collect::<Vec<u8>>(),
            )),
        };
        let functions: *const fmi2CallbackFunctions = match callbacks {
            Callbacks::NullStruct => ptr::null(),
            other => {
                let mut f = match other {
                    Callbacks::Quiet => quiet_callbacks(),
                    _ => checking_callbacks(environment),
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
            FmuType::Other(t) => t,
        };
        let as_ptr = |s: &Option<CString>| s.as_ref().map_or(ptr::null(), |s| s.as_ptr());
        let c = fmi2Instantiate(
            as_ptr(&name),
            fmu_type,
            as_ptr(&guid),
            as_ptr(&resources),
            functions,
            visible as fmi2Boolean,
            logging_on as fmi2Boolean,
        );
        if c.is_null() {
            return;
        }
        // Whatever the GUID named is what was instantiated.
        let model = guid
            .as_ref()
            .and_then(|g| model_of(g.to_str().ok()?))
            .expect("fmi2Instantiate succeeded with a GUID of no model");
        let slot = slot as usize % SLOTS;
        if let Some(old) = self.slots[slot].take() {
            fmi2FreeInstance(old.c);
            self.freed.push(old.c);
        }
        self.slots[slot] = Some(Live { c, model });
        self.tame(c, model);
    }

    unsafe fn run(&mut self, call: &Call) {
        match call {
            Call::GetTypesPlatform => {
                assert_eq!(std::ffi::CStr::from_ptr(fmi2GetTypesPlatform()), c"default");
            }
            Call::GetVersion => {
                assert_eq!(std::ffi::CStr::from_ptr(fmi2GetVersion()), c"2.0");
            }
            Call::Instantiate {
                slot,
                model,
                guid,
                name,
                resources,
                callbacks,
                fmu_type,
                visible,
                logging_on,
                environment,
            } => self.instantiate(
                *slot,
                *model,
                guid,
                name,
                resources,
                *callbacks,
                *fmu_type,
                *visible,
                *logging_on,
                *environment,
            ),
            Call::FreeInstance(h) => {
                let (c, _) = self.handle(*h);
                fmi2FreeInstance(c);
                if let Handle::Slot(i) = h {
                    if let Some(live) = self.slots[*i as usize % SLOTS].take() {
                        self.freed.push(live.c);
                    }
                }
            }
            Call::SetDebugLogging {
                c: h,
                on,
                categories,
                null_array,
            } => {
                let (c, model) = self.handle(*h);
                let texts: Vec<Option<CString>> =
                    categories.iter().map(|t| self.text(t, None)).collect();
                let pointers: Vec<fmi2String> = texts
                    .iter()
                    .map(|t| t.as_ref().map_or(ptr::null(), |t| t.as_ptr()))
                    .collect();
                let array = if *null_array {
                    ptr::null()
                } else {
                    pointers.as_ptr()
                };
                let status = fmi2SetDebugLogging(c, *on, pointers.len(), array);
                self.check("fmi2SetDebugLogging", *h, model, status);
            }
            Call::SetupExperiment {
                c: h,
                tolerance_defined,
                tolerance,
                start,
                stop_defined,
                stop,
            } => {
                let (c, model) = self.handle(*h);
                let status = fmi2SetupExperiment(
                    c,
                    *tolerance_defined as fmi2Boolean,
                    tolerance.value(),
                    start.value(),
                    *stop_defined as fmi2Boolean,
                    stop.value(),
                );
                self.check("fmi2SetupExperiment", *h, model, status);
            }
            Call::EnterInitializationMode(h) => {
                let (c, model) = self.handle(*h);
                let status = fmi2EnterInitializationMode(c);
                self.check("fmi2EnterInitializationMode", *h, model, status);
            }
            Call::ExitInitializationMode(h) => {
                let (c, model) = self.handle(*h);
                let status = fmi2ExitInitializationMode(c);
                self.check("fmi2ExitInitializationMode", *h, model, status);
            }
            Call::Terminate(h) => {
                let (c, model) = self.handle(*h);
                let status = fmi2Terminate(c);
                self.check("fmi2Terminate", *h, model, status);
            }
            Call::Reset(h) => {
                let (c, model) = self.handle(*h);
                let status = fmi2Reset(c);
                self.check("fmi2Reset", *h, model, status);
                if let (OK, Some(model)) = (status, model) {
                    self.tame(c, model);
                }
            }
            Call::DoStep {
                c: h,
                current,
                step,
                no_prior,
            } => {
                let (c, model) = self.handle(*h);
                let mut now = 0.0;
                if fmi2GetRealStatus(c, 2, &mut now) != OK {
                    now = 0.0;
                }
                let current = match current {
                    Current::Now => now,
                    Current::NowPlus(x) => now + x.value(),
                    Current::Any(x) => x.value(),
                };
                let mut step = match step {
                    Step::Ticks(n) => f64::from(*n) * 1e-4,
                    Step::Micro(n) => f64::from(*n) * 1e-7,
                    Step::Any(x) => x.value(),
                };
                // Plants integrate any step at once; a sampled model (or one we cannot
                // name) gets no step longer than MAX_SAMPLED_STEP.
                let any_step = model.is_some_and(|m| {
                    matches!(
                        m.identifier,
                        "XYServoPlant" | "FiveAxisPlant" | "FaultProbe"
                    )
                });
                if !any_step && step > MAX_SAMPLED_STEP {
                    step = MAX_SAMPLED_STEP;
                }
                let status = fmi2DoStep(c, current, step, *no_prior as fmi2Boolean);
                self.check("fmi2DoStep", *h, model, status);
            }
            Call::CancelStep(h) => {
                let (c, model) = self.handle(*h);
                let status = fmi2CancelStep(c);
                self.check("fmi2CancelStep", *h, model, status);
            }
            Call::GetReal {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let vrs: Vec<u32> = vrs
                    .iter()
                    .map(|&v| self.vr(table, v, VarType::Real))
                    .collect();
                let mut values = vec![0.0 as fmi2Real; vrs.len()];
                let status = fmi2GetReal(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null_mut()
                    } else {
                        values.as_mut_ptr()
                    },
                );
                self.check("fmi2GetReal", *h, model, status);
            }
            Call::GetInteger {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let vrs: Vec<u32> = vrs
                    .iter()
                    .map(|&v| self.vr(table, v, VarType::Integer))
                    .collect();
                let mut values = vec![0 as fmi2Integer; vrs.len()];
                let status = fmi2GetInteger(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null_mut()
                    } else {
                        values.as_mut_ptr()
                    },
                );
                self.check("fmi2GetInteger", *h, model, status);
            }
            Call::GetBoolean {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let vrs: Vec<u32> = vrs
                    .iter()
                    .map(|&v| self.vr(table, v, VarType::Boolean))
                    .collect();
                let mut values = vec![0 as fmi2Boolean; vrs.len()];
                let status = fmi2GetBoolean(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null_mut()
                    } else {
                        values.as_mut_ptr()
                    },
                );
                self.check("fmi2GetBoolean", *h, model, status);
            }
            Call::GetString {
                c: h,
                vrs,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let vrs: Vec<u32> = vrs
                    .iter()
                    .map(|&v| self.vr(table, v, VarType::String))
                    .collect();
                let mut values: Vec<fmi2String> = vec![ptr::null(); vrs.len()];
                let status = fmi2GetString(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null_mut()
                    } else {
                        values.as_mut_ptr()
                    },
                );
                self.check("fmi2GetString", *h, model, status);
                if status == OK && !*null_value {
                    // Valid until the next call on the instance: read them all now.
                    for &s in &values {
                        assert!(!s.is_null(), "fmi2GetString: NULL string with fmi2OK");
                        let _ = std::ffi::CStr::from_ptr(s).to_bytes().len();
                    }
                }
            }
            Call::SetReal {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let (vrs, values): (Vec<u32>, Vec<fmi2Real>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, VarType::Real), x.value()))
                    .unzip();
                let status = fmi2SetReal(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null()
                    } else {
                        values.as_ptr()
                    },
                );
                self.check("fmi2SetReal", *h, model, status);
            }
            Call::SetInteger {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let (vrs, values): (Vec<u32>, Vec<fmi2Integer>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, VarType::Integer), x))
                    .unzip();
                let status = fmi2SetInteger(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null()
                    } else {
                        values.as_ptr()
                    },
                );
                self.check("fmi2SetInteger", *h, model, status);
            }
            Call::SetBoolean {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let (vrs, values): (Vec<u32>, Vec<fmi2Boolean>) = values
                    .iter()
                    .map(|&(v, x)| (self.vr(table, v, VarType::Boolean), x))
                    .unzip();
                let status = fmi2SetBoolean(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null()
                    } else {
                        values.as_ptr()
                    },
                );
                self.check("fmi2SetBoolean", *h, model, status);
            }
            Call::SetString {
                c: h,
                values,
                null_vr,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                let table = self.table(model);
                let vrs: Vec<u32> = values
                    .iter()
                    .map(|(v, _)| self.vr(table, *v, VarType::String))
                    .collect();
                let texts: Vec<Option<CString>> =
                    values.iter().map(|(_, t)| self.text(t, model)).collect();
                let pointers: Vec<fmi2String> = texts
                    .iter()
                    .map(|t| t.as_ref().map_or(ptr::null(), |t| t.as_ptr()))
                    .collect();
                let status = fmi2SetString(
                    c,
                    if *null_vr { ptr::null() } else { vrs.as_ptr() },
                    vrs.len(),
                    if *null_value {
                        ptr::null()
                    } else {
                        pointers.as_ptr()
                    },
                );
                self.check("fmi2SetString", *h, model, status);
            }
            Call::GetFmuState { c: h, slot } => {
                let (c, model) = self.handle(*h);
                let status = self.with_state_slot(*slot, |s| fmi2GetFMUstate(c, s));
                self.check("fmi2GetFMUstate", *h, model, status);
            }
            Call::SetFmuState { c: h, state } => {
                let (c, model) = self.handle(*h);
                let state = self.state_value(*state);
                let status = fmi2SetFMUstate(c, state);
                self.check("fmi2SetFMUstate", *h, model, status);
            }
            Call::FreeFmuState { c: h, slot } => {
                let (c, model) = self.handle(*h);
                let status = self.with_state_slot(*slot, |s| fmi2FreeFMUstate(c, s));
                self.check("fmi2FreeFMUstate", *h, model, status);
            }
            Call::SerializedSize {
                c: h,
                state,
                null_size,
            } => {
                let (c, model) = self.handle(*h);
                let state = self.state_value(*state);
                let mut size = 0usize;
                let out = if *null_size {
                    ptr::null_mut()
                } else {
                    &mut size as *mut usize
                };
                let status = fmi2SerializedFMUstateSize(c, state, out);
                self.check("fmi2SerializedFMUstateSize", *h, model, status);
            }
            Call::Serialize {
                c: h,
                state,
                size,
                null_buffer,
            } => {
                let (c, model) = self.handle(*h);
                let state = self.state_value(*state);
                let mut exact = 0usize;
                if fmi2SerializedFMUstateSize(c, state, &mut exact) != OK {
                    exact = 16;
                }
                let len = match size {
                    BufferSize::Exact => exact,
                    BufferSize::Short(n) => exact.saturating_sub(1 + *n as usize),
                    BufferSize::Long(n) => exact + *n as usize,
                    BufferSize::Zero => 0,
                };
                let mut buffer = vec![0u8; len];
                let out = if *null_buffer {
                    ptr::null_mut()
                } else {
                    buffer.as_mut_ptr() as *mut c_char
                };
                let status = fmi2SerializeFMUstate(c, state, out, len);
                self.check("fmi2SerializeFMUstate", *h, model, status);
                if status == OK && len >= exact && !*null_buffer {
                    buffer.truncate(exact);
                    if self.serialized.len() < 8 {
                        self.serialized.push(buffer);
                    }
                }
            }
            Call::Deserialize { c: h, bytes, slot } => {
                let (c, model) = self.handle(*h);
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
                    None => (data.as_ptr() as *const c_char, data.len()),
                };
                let status =
                    self.with_state_slot(*slot, |s| fmi2DeSerializeFMUstate(c, pointer, size, s));
                self.check("fmi2DeSerializeFMUstate", *h, model, status);
            }
            Call::DirectionalDerivative {
                c: h,
                n_unknown,
                n_known,
                null_arrays,
            } => {
                let (c, model) = self.handle(*h);
                let (nu, nk) = (*n_unknown as usize % 8, *n_known as usize % 8);
                let (vu, vk) = (vec![0u32; nu], vec![0u32; nk]);
                let dk = vec![1.0; nk];
                let mut du = vec![0.0; nu];
                let status = if *null_arrays {
                    fmi2GetDirectionalDerivative(
                        c,
                        ptr::null(),
                        nu,
                        ptr::null(),
                        nk,
                        ptr::null(),
                        ptr::null_mut(),
                    )
                } else {
                    fmi2GetDirectionalDerivative(
                        c,
                        vu.as_ptr(),
                        nu,
                        vk.as_ptr(),
                        nk,
                        dk.as_ptr(),
                        du.as_mut_ptr(),
                    )
                };
                self.check("fmi2GetDirectionalDerivative", *h, model, status);
            }
            Call::SetRealInputDerivatives {
                c: h,
                n,
                null_arrays,
            } => {
                let (c, model) = self.handle(*h);
                let n = *n as usize % 8;
                let (vr, order, value) = (vec![0u32; n], vec![1; n], vec![0.0; n]);
                let status = if *null_arrays {
                    fmi2SetRealInputDerivatives(c, ptr::null(), n, ptr::null(), ptr::null())
                } else {
                    fmi2SetRealInputDerivatives(c, vr.as_ptr(), n, order.as_ptr(), value.as_ptr())
                };
                self.check("fmi2SetRealInputDerivatives", *h, model, status);
            }
            Call::GetRealOutputDerivatives {
                c: h,
                n,
                null_arrays,
            } => {
                let (c, model) = self.handle(*h);
                let n = *n as usize % 8;
                let (vr, order) = (vec![0u32; n], vec![1; n]);
                let mut value = vec![0.0; n];
                let status = if *null_arrays {
                    fmi2GetRealOutputDerivatives(c, ptr::null(), n, ptr::null(), ptr::null_mut())
                } else {
                    fmi2GetRealOutputDerivatives(
                        c,
                        vr.as_ptr(),
                        n,
                        order.as_ptr(),
                        value.as_mut_ptr(),
                    )
                };
                self.check("fmi2GetRealOutputDerivatives", *h, model, status);
            }
            Call::Status {
                c: h,
                which,
                kind,
                null_value,
            } => {
                let (c, model) = self.handle(*h);
                // Mostly the four kinds of FMI 2.0, sometimes any number.
                let kind = if *kind > 16 { kind % 4 } else { *kind };
                let null = *null_value;
                let status = match which % 5 {
                    0 => {
                        let mut v: fmi2Status = 0;
                        fmi2GetStatus(c, kind, if null { ptr::null_mut() } else { &mut v })
                    }
                    1 => {
                        let mut v: fmi2Real = 0.0;
                        fmi2GetRealStatus(c, kind, if null { ptr::null_mut() } else { &mut v })
                    }
                    2 => {
                        let mut v: fmi2Integer = 0;
                        fmi2GetIntegerStatus(c, kind, if null { ptr::null_mut() } else { &mut v })
                    }
                    3 => {
                        let mut v: fmi2Boolean = 0;
                        fmi2GetBooleanStatus(c, kind, if null { ptr::null_mut() } else { &mut v })
                    }
                    _ => {
                        let mut v: fmi2String = ptr::null();
                        fmi2GetStringStatus(c, kind, if null { ptr::null_mut() } else { &mut v })
                    }
                };
                self.check("fmi2Get*Status", *h, model, status);
            }
            Call::Reenter { c: h, frees } => {
                let (c, _) = self.handle(*h);
                REENTER.store(c as usize, Ordering::Relaxed);
                REENTER_FREES.store(*frees, Ordering::Relaxed);
            }
        }
    }

    /// Frees every instance (their states with them); then no handle of this input may
    /// answer as an instance.
    unsafe fn finish(mut self) {
        REENTER.store(0, Ordering::Relaxed);
        for slot in 0..SLOTS {
            if let Some(live) = self.slots[slot].take() {
                fmi2FreeInstance(live.c);
                self.freed.push(live.c);
            }
        }
        for &c in &self.freed {
            fmi2FreeInstance(c);
            assert_eq!(fmi2Terminate(c), ERROR, "a freed instance answered");
        }
        for &s in &self.states {
            assert_eq!(
                fmi2Terminate(s),
                ERROR,
                "an FMU state answered as an instance"
            );
        }
    }
}

fuzz_target!(
    init: {
        install_panic_hook();
        // Plans within the 10 s a fuzz input may take (FUZZ_SAMPLE_BUDGET): a longer
        // one is refused like any other.
        contour_fmu::fmi2::set_plan_sample_budget(FUZZ_SAMPLE_BUDGET);
    },
    |input: Input| {
        let mut session = Session::new();
        for call in input.calls.iter().take(MAX_CALLS) {
            // SAFETY: every pointer passed is NULL, a handle, or points to live memory of
            // the size the call is told (see the module comment).
            unsafe { session.run(call) };
        }
        unsafe { session.finish() };
    }
);
