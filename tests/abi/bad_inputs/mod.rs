//! A catalogue of bad inputs, one table: every FMI function called in a wrong state, NULL
//! where an importer can err, NaN and infinities on every kind of input, integers out of
//! range, absurd parameters, corrupt and foreign FMU state bytes, missing resources and
//! malformed path files, on all eight models (and FaultProbe for the Error and Fatal modes).
//!
//! Each case asserts three things:
//! - the exact status;
//! - a log line with that status (fmi2Warning for a call that succeeds with a warning), in
//!   its category, naming the cause: the function, variable, parameter or file;
//! - the aftermath. The library refuses a bad call without changing anything, so the
//!   instance is usable: a normal step afterwards gives the same values as an untouched twin
//!   instance (`Usable`), or does once the parameters are corrected (`Corrected`). Where the
//!   standard says more is needed (a failed step: Error mode; a panic: Fatal) that is
//!   checked instead. And for every fmi2Error, the recovery FMI 2.0 §2.1.3 offers the
//!   importer must work: fmi2SetFMUstate to a state saved before the bad call, then fmi2Reset,
//!   each followed by a run equal to a twin's.
//!
//! fmi2Instantiate returns no status: a NULL instance counts as fmi2Error, an instance as
//! fmi2OK. All failing cases are reported together, by name.
//!
//! Needs the `test-hooks` feature (the `FaultProbe` model).
//!
//! The machinery is shared with the FMI 3.0 catalogue (`crate::bad_inputs_fmi3`): a case runs
//! on a [`Subject`] of either standard, whose C calls are that standard's [`Api`] (FMI 2.0's,
//! [`Fmi2`], is the default).

use std::ffi::{c_char, c_void};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock, PoisonError};

use crate::common::*;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Causality, Value, VarType, Variable};
use contour_fmu::models::{
    contour_ccc_2d, contour_ccc_5x, fault_probe, five_axis_plant, path_interpolator_2d,
    path_interpolator_5x, servo_drive, xy_servo_plant,
};

mod call_order;
mod calls;
mod foreign_states;
mod non_finite;
mod null_handles;
mod parameters;
mod path_files;
mod references;
mod resources;
mod state_bytes;
mod timing;

pub(crate) const C2: &ModelInfo = &contour_ccc_2d::INFO;
pub(crate) const C5: &ModelInfo = &contour_ccc_5x::INFO;
pub(crate) const F5: &ModelInfo = &five_axis_plant::INFO;
pub(crate) const P2: &ModelInfo = &path_interpolator_2d::INFO;
pub(crate) const P5: &ModelInfo = &path_interpolator_5x::INFO;
pub(crate) const XY: &ModelInfo = &xy_servo_plant::INFO;
pub(crate) const SD: &ModelInfo = &servo_drive::INFO;
pub(crate) const SR: &ModelInfo = &servo_drive::INFO_ROTARY;
pub(crate) const PROBE: &ModelInfo = &fault_probe::INFO;

/// Communication step of every run.
pub(crate) const H: f64 = 1e-3;
/// Steps the `Stepping` setup takes before the bad call.
const WARMUP: usize = 3;

/// Where the instance is when the bad call comes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Setup {
    /// No instance yet: the case calls fmi2Instantiate itself.
    NoInstance,
    Instantiated,
    Initialization,
    /// Initialized at t = 0 and stepped `WARMUP` times.
    Stepping,
    /// `Stepping`, then fmi2Terminate.
    Terminated,
    /// `Stepping`, then a failing step (FaultProbe only): Error mode.
    Failed,
    /// `Stepping`, then a panicking step (FaultProbe only): Fatal mode.
    Fatal,
}

/// The resource location the instance is created with.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Resources {
    Null,
    /// Passed as it is (to FMI 2.0 a URI, to FMI 3.0 a native path).
    Uri(&'static str),
    /// The catalogue's temp folder (holding the path files), as the standard names a
    /// folder: a file URI (FMI 2.0), a native path with a trailing separator (FMI 3.0).
    Folder,
    /// The temp folder as a file URI for either standard (to FMI 3.0 a mistake).
    FolderUri,
}

/// What the instance is good for after the bad call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum After {
    /// Carries on: a step gives the values an untouched twin gets.
    Usable,
    /// Carries on once every parameter and input is set back to its start value (the call
    /// left the bad value in place and the instance in initialization mode).
    Corrected,
    /// Accepted with a warning: the instance steps on (its values differ from the twin's).
    Steps,
    /// Error mode: steps are refused until fmi2SetFMUstate or fmi2Reset.
    ResetRequired,
    /// Fatal mode: only fmi2FreeFMUstate and fmi2FreeInstance are accepted.
    FreeOnly,
    /// fmi2Instantiate refused: there is no instance.
    NotCreated,
    /// The instance was freed: a further call is refused, and nothing is logged.
    Gone,
}

pub(crate) type Call<A = Fmi2> = fn(&mut Subject<A>) -> fmi2Status;

pub(crate) struct Case<A: Api = Fmi2> {
    pub(crate) name: &'static str,
    pub(crate) model: &'static ModelInfo,
    setup: Setup,
    resources: Resources,
    /// The bad call (with the good calls it needs before it); returns its status.
    pub(crate) call: Call<A>,
    status: fmi2Status,
    /// A text the log line must contain (parts separated by `…` in that order); `None`:
    /// nothing may be logged (no instance or no logger to tell, or nothing wrong).
    pub(crate) log: Option<&'static str>,
    after: After,
}

pub(crate) const fn case<A: Api>(
    name: &'static str,
    model: &'static ModelInfo,
    setup: Setup,
    call: Call<A>,
    status: fmi2Status,
    log: Option<&'static str>,
    after: After,
) -> Case<A> {
    Case {
        name,
        model,
        setup,
        resources: Resources::Null,
        call,
        status,
        log,
        after,
    }
}

impl<A: Api> Case<A> {
    pub(crate) const fn with(self, resources: Resources) -> Case<A> {
        Case { resources, ..self }
    }
}

pub(crate) use After::*;
pub(crate) use Setup::*;

// ---------------------------------------------------------------------------------------
// The catalogue

/// The catalogue, one group per file.
static GROUPS: &[&[Case]] = &[
    call_order::CASES,
    null_handles::CASES,
    non_finite::CASES,
    timing::CASES,
    references::CASES,
    parameters::CASES,
    state_bytes::CASES,
    foreign_states::CASES,
    resources::CASES,
    path_files::CASES,
];

/// Every case of the catalogue, group by group.
fn cases() -> impl Iterator<Item = &'static Case> {
    GROUPS.iter().flat_map(|group| group.iter())
}

// ---------------------------------------------------------------------------------------
// The C calls of a standard

/// The C calls of one standard that the machinery makes (the cases make their own), each
/// one call: FMI 2.0's ([`Fmi2`]) here, FMI 3.0's in `crate::bad_inputs_fmi3`. The two
/// standards have the same status codes, and an instance and an FMU state are a `void*`
/// in both.
pub(crate) trait Api: Sized + 'static {
    /// An instance with its log, freed on drop.
    type Fmu;
    /// The recovery calls, for messages.
    const SET_STATE: &'static str;
    const RESET: &'static str;
    /// An instance of `model` named `name` (which must be accepted).
    fn instantiate(model: &'static ModelInfo, name: &str, resources: Resources) -> Self::Fmu;
    fn handle(fmu: &Self::Fmu) -> *mut c_void;
    fn log(fmu: &Self::Fmu) -> &Log;
    /// Frees the instance (once; its handle stays as it was).
    fn free(fmu: &mut Self::Fmu);
    fn set_debug_logging(c: *mut c_void, on: bool, categories: &[fmi2String]) -> fmi2Status;
    /// Sets `v` with the setter of its type.
    fn set(c: *mut c_void, v: &Variable, value: Value) -> fmi2Status;
    /// Reads `v` with the getter of its type, as text (exact: equal texts, equal bits).
    fn get(c: *mut c_void, v: &Variable) -> (fmi2Status, String);
    /// Into initialization mode for an experiment from t = 0 without a stop time.
    fn enter_initialization(c: *mut c_void) -> fmi2Status;
    fn exit_initialization(c: *mut c_void) -> fmi2Status;
    fn step(c: *mut c_void, t: f64, h: f64) -> fmi2Status;
    fn terminate(c: *mut c_void) -> fmi2Status;
    fn reset(c: *mut c_void) -> fmi2Status;
    fn get_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status;
    fn set_state(c: *mut c_void, state: *mut c_void) -> fmi2Status;
    fn free_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status;
    fn state_size(c: *mut c_void, state: *mut c_void, size: &mut usize) -> fmi2Status;
    fn serialize(c: *mut c_void, state: *mut c_void, bytes: &mut [u8]) -> fmi2Status;
    fn deserialize(c: *mut c_void, bytes: &[u8], state: &mut *mut c_void) -> fmi2Status;
}

/// FMI 2.0 Co-Simulation.
pub(crate) struct Fmi2;

impl Api for Fmi2 {
    type Fmu = Fmu;
    const SET_STATE: &'static str = "fmi2SetFMUstate";
    const RESET: &'static str = "fmi2Reset";

    fn instantiate(model: &'static ModelInfo, name: &str, resources: Resources) -> Fmu {
        match resources {
            Resources::Null => Fmu::Made(Instance::named(model, name)),
            Resources::Uri(uri) => Fmu::raw(model, name, uri),
            Resources::Folder | Resources::FolderUri => {
                Fmu::raw(model, name, &format!("file://{}", folder().display()))
            }
        }
    }
    fn handle(fmu: &Fmu) -> *mut c_void {
        match fmu {
            Fmu::Made(i) => i.c,
            Fmu::Raw(r) => r.c,
        }
    }
    fn log(fmu: &Fmu) -> &Log {
        match fmu {
            Fmu::Made(i) => &i.log,
            Fmu::Raw(r) => &r.log,
        }
    }
    fn free(fmu: &mut Fmu) {
        match fmu {
            Fmu::Made(i) => i.free(),
            Fmu::Raw(r) => unsafe { lib().fmi2FreeInstance(r.c) },
        }
    }
    fn set_debug_logging(c: *mut c_void, on: bool, categories: &[fmi2String]) -> fmi2Status {
        let (n, p) = (categories.len(), categories.as_ptr());
        unsafe { lib().fmi2SetDebugLogging(c, on as fmi2Boolean, n, p) }
    }
    fn set(c: *mut c_void, v: &Variable, value: Value) -> fmi2Status {
        let vr = v.vr as u32;
        unsafe {
            match value {
                Value::Real(x) => lib().fmi2SetReal(c, &vr, 1, &x),
                Value::Integer(x) => lib().fmi2SetInteger(c, &vr, 1, &x),
                Value::Boolean(x) => lib().fmi2SetBoolean(c, &vr, 1, &(x as fmi2Boolean)),
                Value::String(x) => lib().fmi2SetString(c, &vr, 1, &cstr(&x).as_ptr()),
            }
        }
    }
    fn get(c: *mut c_void, v: &Variable) -> (fmi2Status, String) {
        let vr = v.vr as u32;
        unsafe {
            match v.var_type() {
                VarType::Real => {
                    let mut x = 0.0;
                    (lib().fmi2GetReal(c, &vr, 1, &mut x), format!("{x:?}"))
                }
                VarType::Integer => {
                    let mut x = 0;
                    (lib().fmi2GetInteger(c, &vr, 1, &mut x), x.to_string())
                }
                VarType::Boolean => {
                    let mut x = 0;
                    (lib().fmi2GetBoolean(c, &vr, 1, &mut x), x.to_string())
                }
                VarType::String => {
                    let mut x: fmi2String = std::ptr::null();
                    let s = lib().fmi2GetString(c, &vr, 1, &mut x);
                    let text = if x.is_null() {
                        "<NULL>".into()
                    } else {
                        std::ffi::CStr::from_ptr(x).to_string_lossy().into_owned()
                    };
                    (s, text)
                }
            }
        }
    }
    fn enter_initialization(c: *mut c_void) -> fmi2Status {
        let status = unsafe { lib().fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) };
        if status != OK {
            return status;
        }
        unsafe { lib().fmi2EnterInitializationMode(c) }
    }
    fn exit_initialization(c: *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2ExitInitializationMode(c) }
    }
    fn step(c: *mut c_void, t: f64, h: f64) -> fmi2Status {
        unsafe { lib().fmi2DoStep(c, t, h, 1) }
    }
    fn terminate(c: *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2Terminate(c) }
    }
    fn reset(c: *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2Reset(c) }
    }
    fn get_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2GetFMUstate(c, state) }
    }
    fn set_state(c: *mut c_void, state: *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2SetFMUstate(c, state) }
    }
    fn free_state(c: *mut c_void, state: &mut *mut c_void) -> fmi2Status {
        unsafe { lib().fmi2FreeFMUstate(c, state) }
    }
    fn state_size(c: *mut c_void, state: *mut c_void, size: &mut usize) -> fmi2Status {
        unsafe { lib().fmi2SerializedFMUstateSize(c, state, size) }
    }
    fn serialize(c: *mut c_void, state: *mut c_void, bytes: &mut [u8]) -> fmi2Status {
        let (p, n) = (bytes.as_mut_ptr() as *mut fmi2Byte, bytes.len());
        unsafe { lib().fmi2SerializeFMUstate(c, state, p, n) }
    }
    fn deserialize(c: *mut c_void, bytes: &[u8], state: &mut *mut c_void) -> fmi2Status {
        let (p, n) = (bytes.as_ptr() as *const fmi2Byte, bytes.len());
        unsafe { lib().fmi2DeSerializeFMUstate(c, p, n, state) }
    }
}

// ---------------------------------------------------------------------------------------
// The instance under test

/// An instance made by fmi2Instantiate with a resource location (the harness's `Instance`
/// has none); freed on drop.
pub(crate) struct Raw {
    c: fmi2Component,
    log: Box<Log>,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Drop for Raw {
    fn drop(&mut self) {
        unsafe { lib().fmi2FreeInstance(self.c) };
    }
}

pub(crate) enum Fmu {
    Made(Instance),
    Raw(Raw),
}

impl Fmu {
    fn raw(model: &ModelInfo, name: &str, uri: &str) -> Fmu {
        let guid = model.guid();
        let (c, log, callbacks) = instantiate_raw(
            Some(name),
            fmi2Type_fmi2CoSimulation,
            Some(&guid),
            Some(uri),
            true,
        );
        assert!(!c.is_null(), "{uri}: {:?}", log.records.lock().unwrap());
        Fmu::Raw(Raw {
            c,
            log,
            _callbacks: callbacks,
        })
    }
}

/// Which GUID a case passes to fmi2Instantiate.
#[derive(Clone, Copy)]
enum Guid {
    Own,
    Null,
}

/// One instance of a case's model, brought into the case's setup; the FMU state saved
/// there (or just before the Error or Fatal mode) and the time.
pub(crate) struct Subject<A: Api = Fmi2> {
    pub(crate) model: &'static ModelInfo,
    pub(crate) fmu: Option<A::Fmu>,
    /// The log of a refused instantiation.
    pub(crate) refused: Option<Box<Log>>,
    freed: bool,
    pub(crate) saved: *mut c_void,
    saved_at: (Setup, f64),
    pub(crate) time: f64,
}

/// The catalogue's folder for path files (`write_path_files`).
pub(crate) fn folder() -> &'static Path {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        std::env::temp_dir().join(format!("contour_fmu_bad_inputs_{}", std::process::id()))
    })
}

impl Subject {
    fn new(
        model: &'static ModelInfo,
        setup: Setup,
        resources: Resources,
        name: &'static str,
    ) -> Self {
        Self::create(model, setup, resources, name)
    }

    /// The harness's instance (cases with a resource location use the C calls below).
    fn i(&self) -> &Instance {
        match &self.fmu {
            Some(Fmu::Made(i)) => i,
            _ => panic!("the case needs an instance made without a resource location"),
        }
    }

    fn instantiate(
        &mut self,
        name: Option<&str>,
        fmu_type: fmi2Type,
        guid: Guid,
        resources: Option<&str>,
    ) -> fmi2Status {
        let own = self.model.guid();
        let guid = match guid {
            Guid::Own => Some(own.as_str()),
            Guid::Null => None,
        };
        let (c, log, callbacks) = instantiate_raw(name, fmu_type, guid, resources, true);
        if c.is_null() {
            self.refused = Some(log);
            return ERROR;
        }
        self.fmu = Some(Fmu::Raw(Raw {
            c,
            log,
            _callbacks: callbacks,
        }));
        OK
    }

    /// fmi2Instantiate with NULL callbacks, or callbacks without a logger.
    fn instantiate_without_logger(&mut self, null_callbacks: bool) -> fmi2Status {
        let log = Box::<Log>::default();
        let mut functions = callbacks(&log);
        functions.logger = None;
        let (name, guid) = (cstr("a"), cstr(&self.model.guid()));
        let functions: *const fmi2CallbackFunctions = if null_callbacks {
            std::ptr::null()
        } else {
            &*functions
        };
        let c = unsafe {
            lib().fmi2Instantiate(
                name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                functions,
                0,
                0,
            )
        };
        if !c.is_null() {
            unsafe { lib().fmi2FreeInstance(c) };
            return OK;
        }
        self.refused = Some(log);
        ERROR
    }
}

impl<A: Api> Subject<A> {
    /// An instance of `model` in `setup` (none for `NoInstance`), its log cleared.
    pub(crate) fn create(
        model: &'static ModelInfo,
        setup: Setup,
        resources: Resources,
        name: &'static str,
    ) -> Self {
        let mut s = Subject {
            model,
            fmu: None,
            refused: None,
            freed: false,
            saved: std::ptr::null_mut(),
            saved_at: (setup, 0.0),
            time: 0.0,
        };
        if setup == NoInstance {
            return s;
        }
        s.fmu = Some(A::instantiate(model, name, resources));
        s.log_warnings();
        s.bring(setup);
        s.log().records.lock().unwrap().clear();
        s
    }

    /// Warnings and discards are only logged when asked for (errors always are).
    fn log_warnings(&self) {
        let categories = ["logStatusWarning", "logStatusError", "logStatusFatal"];
        self.ok(self.set_debug_logging(true, &categories));
    }

    pub(crate) fn set_debug_logging(&self, on: bool, categories: &[&str]) -> fmi2Status {
        let names: Vec<_> = categories.iter().map(|c| cstr(c)).collect();
        let pointers: Vec<fmi2String> = names.iter().map(|c| c.as_ptr()).collect();
        A::set_debug_logging(self.c(), on, &pointers)
    }

    pub(crate) fn c(&self) -> *mut c_void {
        self.fmu.as_ref().map_or(std::ptr::null_mut(), A::handle)
    }

    pub(crate) fn log(&self) -> &Log {
        match (&self.fmu, &self.refused) {
            (Some(fmu), _) => A::log(fmu),
            (None, Some(log)) => log,
            (None, None) => panic!("no instance and no log"),
        }
    }

    pub(crate) fn records(&self) -> Vec<Record> {
        self.log().records.lock().unwrap().clone()
    }

    pub(crate) fn last_error(&self) -> String {
        let records = self.records();
        let last = records.iter().rev().find(|r| r.status >= ERROR);
        last.map(|r| r.message.clone()).unwrap_or_default()
    }

    /// A good call that must succeed.
    pub(crate) fn ok(&self, status: fmi2Status) {
        assert_eq!(status, OK, "a good call failed: {}", self.last_error());
    }

    pub(crate) fn variable(&self, name: &str) -> &'static Variable {
        let v = self.model.variables.iter().find(|v| v.name == name);
        v.unwrap_or_else(|| panic!("{} has no variable '{name}'", self.model.identifier))
    }

    pub(crate) fn vr(&self, name: &str) -> u32 {
        self.variable(name).vr as u32
    }

    pub(crate) fn file(&self, name: &str) -> String {
        folder().join(name).display().to_string()
    }

    pub(crate) fn free(&mut self) {
        if let Some(fmu) = &mut self.fmu {
            A::free(fmu);
        }
        self.freed = true;
    }

    // The C calls, on either kind of instance.

    pub(crate) fn set_real(&self, name: &str, value: f64) -> fmi2Status {
        A::set(self.c(), self.variable(name), Value::Real(value))
    }
    pub(crate) fn set_integer(&self, name: &str, value: i32) -> fmi2Status {
        A::set(self.c(), self.variable(name), Value::Integer(value))
    }
    pub(crate) fn set_boolean(&self, name: &str, value: bool) -> fmi2Status {
        A::set(self.c(), self.variable(name), Value::Boolean(value))
    }
    pub(crate) fn set_string(&self, name: &str, value: &str) -> fmi2Status {
        A::set(self.c(), self.variable(name), Value::String(value.into()))
    }

    /// Sets a bad value (which must be accepted), then ends initialization: the bad call.
    pub(crate) fn exit_with(&mut self, set: fn(&mut Subject<A>) -> fmi2Status) -> fmi2Status {
        let status = set(self);
        self.ok(status);
        A::exit_initialization(self.c())
    }

    /// Real inputs at time `t` (any finite values: the same for the instance and its twin),
    /// then one step.
    fn drive(&mut self) {
        for v in self.model.variables {
            if v.causality == Causality::Input && v.var_type() == VarType::Real {
                let value = 0.25 + 0.1 * v.vr as f64 + self.time;
                self.ok(A::set(self.c(), v, Value::Real(value)));
            }
        }
        self.ok(A::step(self.c(), self.time, H));
        self.time += H;
    }

    fn start(&mut self) {
        let c = self.c();
        self.ok(A::enter_initialization(c));
        self.ok(A::exit_initialization(c));
        self.time = 0.0;
    }

    fn save(&mut self, setup: Setup) {
        let s = A::get_state(self.c(), &mut self.saved);
        self.ok(s);
        self.saved_at = (setup, self.time);
    }

    /// Brings a new instance into `setup`, saving an FMU state on the way.
    fn bring(&mut self, setup: Setup) {
        let c = self.c();
        match setup {
            NoInstance | Instantiated => self.save(Instantiated),
            Initialization => {
                self.ok(A::enter_initialization(c));
                self.save(Initialization);
            }
            Stepping | Terminated | Failed | Fatal => {
                self.start();
                for _ in 0..WARMUP {
                    self.drive();
                }
                self.save(Stepping);
                match setup {
                    Terminated => self.ok(A::terminate(c)),
                    Failed | Fatal => {
                        let fault = if setup == Failed { "fail" } else { "panic" };
                        self.ok(self.set_boolean(fault, true));
                        let expected = if setup == Failed { ERROR } else { FATAL };
                        assert_eq!(A::step(c, self.time, H), expected);
                    }
                    _ => {}
                }
            }
        }
    }

    /// Carries on from `setup` with one normal step where one is allowed, then reads
    /// every variable (as "name = value", exact).
    fn resume(&mut self, setup: Setup) -> Vec<String> {
        match setup {
            NoInstance | Instantiated => {
                self.start();
                self.drive();
            }
            Initialization => {
                self.ok(A::exit_initialization(self.c()));
                self.time = 0.0;
                self.drive();
            }
            Stepping => self.drive(),
            Terminated | Failed | Fatal => {}
        }
        self.values()
    }

    pub(crate) fn values(&self) -> Vec<String> {
        self.model
            .variables
            .iter()
            .map(|v| {
                let (status, value) = A::get(self.c(), v);
                self.ok(status);
                format!("{} = {value}", v.name)
            })
            .collect()
    }

    /// Puts every parameter and input back to its start value (in initialization mode).
    fn correct(&self) {
        for v in self.model.variables {
            if v.causality == Causality::Output {
                continue;
            }
            self.ok(A::set(self.c(), v, Value::from(v.start)));
        }
    }

    /// The bytes of the state `state` of this instance.
    pub(crate) fn serialized(&self, state: *mut c_void) -> Vec<u8> {
        let mut size = 0;
        self.ok(A::state_size(self.c(), state, &mut size));
        let mut bytes = vec![0u8; size];
        self.ok(A::serialize(self.c(), state, &mut bytes));
        bytes
    }

    pub(crate) fn saved_bytes(&self) -> Vec<u8> {
        self.serialized(self.saved)
    }

    /// `bytes` deserialized into a new FMU state of this instance; the status and state.
    pub(crate) fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, *mut c_void) {
        let mut state = std::ptr::null_mut();
        (A::deserialize(self.c(), bytes, &mut state), state)
    }

    /// The saved state with `edit` applied inside a valid envelope, deserialized.
    pub(crate) fn resealed(&self, edit: impl FnOnce(&mut StateEnvelope)) -> fmi2Status {
        let (format, mut envelope) = open_state(&self.saved_bytes());
        edit(&mut envelope);
        self.deserialize(&seal_state(format, &envelope)).0
    }

    /// The serialized state of a fresh, stepped instance of `model`.
    pub(crate) fn state_bytes_of(model: &'static ModelInfo) -> Vec<u8> {
        Self::create(model, Stepping, Resources::Null, "foreign").saved_bytes()
    }
}

/// The serialized state of a fresh, stepped instance of `model`.
fn state_bytes_of(model: &'static ModelInfo) -> Vec<u8> {
    Subject::<Fmi2>::state_bytes_of(model)
}

// ---------------------------------------------------------------------------------------
// Path files

fn write_path_files() {
    let files: [(&str, &str); 19] = [
        (
            "syntax.json",
            "{\n  \"degree\": 1,\n  \"knots\": [0, 0,, 1, 1],\n  \"control_points\": [[0, 0], [3, 4]]\n}\n",
        ),
        (
            "typo.json",
            r#"{"degree": 1, "knot": [0, 0, 1, 1], "control_points": [[0, 0], [3, 4]]}"#,
        ),
        (
            "knots.json",
            r#"{"degree": 1, "knots": [0, 0, 1], "control_points": [[0, 0], [3, 4]]}"#,
        ),
        (
            "word.cl",
            "PARTNO/TEST\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,1\nGOTO/2,abc,0,0,0,1\n",
        ),
        ("nan.cl", "MULTAX\nGOTO/NaN,0,0,0,0,1\nGOTO/1,0,0,0,0,1\n"),
        (
            "count.cl",
            "GOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,1\nGOTO/1,2,3,4\n",
        ),
        ("zero_axis.cl", "GOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,0\n"),
        (
            "dangling.cl",
            "GOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,1\nGOTO/2,0,$\n",
        ),
        ("single.cl", "PARTNO/ONE\nGOTO/0,0,0,0,0,1\nFINI\n"),
        ("curves.json", r#"{"tip": 3}"#),
        (
            "long_axis.cl",
            "GOTO/0,0,0,0,0,1\nGOTO/10,0,0,0,0,2\nGOTO/20,0,0,0,0,1\n",
        ),
        (
            "far.json",
            r#"{"tip": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[-1e308, 0, 0], [1e308, 0, 0]]},
                "second": {"degree": 1, "knots": [0, 0, 1, 1], "control_points": [[-1e308, 0, 100], [1e308, 0, 100]]},
                "length": 100}"#,
        ),
        ("far.cl", "GOTO/-1e308,0,0,0,0,1\nGOTO/1e308,0,0,0,0,1\n"),
        ("plane.ngc", "G21 G90\nG1 X10 F600\nG18 G2 X0 Z10 I-5 K5\n"),
        ("off_circle.ngc", "G1 X10 F600\nG2 X0 Y10 I0 J5\n"),
        ("helix.ngc", "G0 Z5\nG1 X10 F600\nG1 X20 Z-1\n"),
        ("expression.ngc", "G21\nG1 X[1+2] F600\n"),
        ("drill.ngc", "G21\nG0 Z5\nG1 X10 F600\nG81 X20 Z-2 F100\n"),
        // A slot 4 mm wide under G42 D7.
        (
            "compensated.ngc",
            "G0 X-10 Y-10\nG42 D7 G1 X0 Y0 F600\nG1 X10\nG1 Y10\nG1 X14\nG1 Y0\nG1 X30\n",
        ),
    ];
    std::fs::create_dir_all(folder()).unwrap();
    for (name, text) in files {
        std::fs::write(folder().join(name), text).unwrap();
    }
}

/// The path files, there while a catalogue runs: written by the first catalogue to start,
/// removed by the last to end (also when its test fails); the two catalogues may run at
/// once.
pub(crate) struct PathFiles;

static PATH_FILE_USERS: Mutex<usize> = Mutex::new(0);

impl PathFiles {
    pub(crate) fn written() -> PathFiles {
        let mut users = PATH_FILE_USERS
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        if *users == 0 {
            write_path_files();
        }
        *users += 1;
        PathFiles
    }
}

impl Drop for PathFiles {
    fn drop(&mut self) {
        let mut users = PATH_FILE_USERS
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        *users -= 1;
        if *users == 0 {
            std::fs::remove_dir_all(folder()).ok();
        }
    }
}

// ---------------------------------------------------------------------------------------
// Running a case

fn category(status: fmi2Status) -> &'static str {
    match status {
        ERROR => "logStatusError",
        FATAL => "logStatusFatal",
        _ => "logStatusWarning",
    }
}

/// Whether `message` holds the parts of `text` separated by `…`, in that order.
fn contains_in_order(message: &str, text: &str) -> bool {
    let mut rest = message;
    text.split('…').all(|part| match rest.find(part) {
        Some(at) => {
            rest = &rest[at + part.len()..];
            true
        }
        None => false,
    })
}

/// The same values, or the first difference.
fn same(what: &str, got: &[String], expected: &[String]) -> Result<(), String> {
    match got.iter().zip(expected).find(|(a, b)| a != b) {
        None if got.len() == expected.len() => Ok(()),
        None => Err(format!(
            "{what}: {} values, expected {}",
            got.len(),
            expected.len()
        )),
        Some((a, b)) => Err(format!("{what}: {a}, the twin has {b}")),
    }
}

/// Runs one case; the problems found.
fn run<A: Api>(case: &Case<A>) -> Result<(), String> {
    check(case, case.call, case.log)
}

/// Runs `case` with `call` as its bad call and `log` as the text its log line must contain
/// (for cases made as the test runs, one per variable, say); the problems found.
pub(crate) fn check<A: Api>(
    case: &Case<A>,
    call: impl FnOnce(&mut Subject<A>) -> fmi2Status,
    log: Option<&str>,
) -> Result<(), String> {
    let mut s = Subject::<A>::create(case.model, case.setup, case.resources, "catalogue");
    let status = call(&mut s);
    let records = s.records();
    if status != case.status {
        return Err(format!(
            "status {status}, expected {}; log: {records:?}",
            case.status
        ));
    }

    // The log line naming the cause.
    match log {
        Some(text) => {
            let level = if case.status == OK {
                WARNING
            } else {
                case.status
            };
            let found = records.iter().any(|r| {
                r.status == level
                    && r.category == category(level)
                    && contains_in_order(&r.message, text)
            });
            if !found {
                return Err(format!(
                    "no {} line containing '{text}': {records:?}",
                    category(level)
                ));
            }
        }
        None if !records.is_empty() => return Err(format!("unexpected log lines: {records:?}")),
        None => {}
    }

    // The aftermath.
    let resume_from = if case.setup == NoInstance {
        Instantiated
    } else {
        case.setup
    };
    let twin = || Subject::<A>::create(case.model, resume_from, case.resources_of_twin(), "twin");
    let mut expected_twin = None;
    // A call any live instance answers but a fatal or freed one refuses: the Real getter
    // for value reference 0.
    let real = |s: &Subject<A>| A::get(s.c(), &Variable::input("vr 0", 0.0, "")).0;
    match case.after {
        Usable | Corrected => {
            if case.after == Corrected {
                s.correct();
            }
            let mut t = twin();
            // Nothing of the refused call was stored (also an input the next step would
            // overwrite), where values can be read.
            if case.after == Usable && matches!(resume_from, Initialization | Stepping | Terminated)
            {
                same("the values", &s.values(), &t.values())?;
            }
            let expected = t.resume(resume_from);
            same("the next step", &s.resume(resume_from), &expected)?;
            expected_twin = Some(t);
        }
        Steps => {
            // The call ended initialization (with a warning): the instance steps on from 0.
            s.time = 0.0;
            s.resume(Stepping);
        }
        ResetRequired => {
            let refused = A::step(s.c(), s.time, H);
            let message = s.last_error();
            if refused != ERROR || !message.contains("illegal call sequence (state Error)") {
                return Err(format!("a step in Error mode gave {refused}: {message}"));
            }
        }
        FreeOnly => {
            if A::reset(s.c()) != ERROR || real(&s) != ERROR {
                return Err(format!(
                    "{} or a getter accepted after a fatal error",
                    A::RESET
                ));
            }
            // The states an importer holds can still be released, then the instance.
            let mut saved = s.saved;
            s.ok(A::free_state(s.c(), &mut saved));
            s.free();
        }
        NotCreated => {
            if s.fmu.is_some() {
                return Err("an instance was created".into());
            }
        }
        Gone => {
            let before = s.records().len();
            if real(&s) != ERROR || s.records().len() != before {
                return Err("the freed instance answered or logged".into());
            }
        }
    }

    // FMI 2.0 §2.1.3: after fmi2Error the importer may restore a state saved before, or
    // reset the instance; both must give a working instance again.
    if status == ERROR && matches!(case.after, Usable | Corrected | ResetRequired) {
        if !s.saved.is_null() {
            let (mode, time) = s.saved_at;
            let mut t = expected_twin.unwrap_or_else(|| {
                Subject::<A>::create(case.model, case.setup, case.resources_of_twin(), "twin")
            });
            t.ok(A::set_state(t.c(), t.saved));
            t.time = time;
            let expected = t.resume(mode);
            let restored = A::set_state(s.c(), s.saved);
            if restored != OK {
                return Err(format!(
                    "{} after the error: {}",
                    A::SET_STATE,
                    s.last_error()
                ));
            }
            s.time = time;
            same(
                &format!("after {}", A::SET_STATE),
                &s.resume(mode),
                &expected,
            )?;
        }
        if A::reset(s.c()) != OK {
            return Err(format!("{} after the error: {}", A::RESET, s.last_error()));
        }
        let mut fresh =
            Subject::<A>::create(case.model, Instantiated, case.resources_of_twin(), "twin");
        let expected = fresh.resume(Instantiated);
        same(
            &format!("after {}", A::RESET),
            &s.resume(Instantiated),
            &expected,
        )?;
    }
    Ok(())
}

impl<A: Api> Case<A> {
    /// The twin is made like the instance, except for a case that instantiates it itself.
    fn resources_of_twin(&self) -> Resources {
        if self.setup == NoInstance {
            Resources::Null
        } else {
            self.resources
        }
    }
}

/// What a case reports: nothing, its problem, or its panic's message.
pub(crate) fn problem(outcome: std::thread::Result<Result<(), String>>) -> Option<String> {
    match outcome {
        Ok(Ok(())) => None,
        Ok(Err(problem)) => Some(problem),
        Err(panic) => Some(
            panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "panic".into()),
        ),
    }
}

/// Runs the cases, each on its own (a panic is caught); a line for each that failed.
pub(crate) fn failures<'a, A: Api>(cases: impl Iterator<Item = &'a Case<A>>) -> Vec<String> {
    cases
        .filter_map(|case| {
            let problem = problem(catch_unwind(AssertUnwindSafe(|| run(case))))?;
            Some(format!(
                "- {} ({}): {problem}",
                case.name, case.model.identifier
            ))
        })
        .collect()
}

/// Fails with every failing case of the `total`, by name.
pub(crate) fn assert_none_failed(failures: &[String], total: usize) {
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        total,
        failures.join("\n")
    );
}

#[test]
fn the_catalogue_of_bad_inputs() {
    let _files = PathFiles::written();
    assert_none_failed(&failures(cases()), cases().count());
}

/// The catalogue covers what it claims: enough cases, every instance function in a wrong
/// mode, every model.
#[test]
fn the_catalogue_is_complete() {
    // Every function but the five FMI 2.0 allows in any state (§4.3.3).
    let anywhere = [
        "fmi2GetTypesPlatform",
        "fmi2GetVersion",
        "fmi2Instantiate",
        "fmi2FreeInstance",
        "fmi2FreeFMUstate",
    ];
    let cases: Vec<Summary> = cases().map(Case::summary).collect();
    assert_complete(&cases, 40, &FMI2_CO_SIMULATION, &anywhere);
}

/// A case as [`assert_complete`] sees it: its name, model and log text.
pub(crate) type Summary = (&'static str, &'static ModelInfo, Option<&'static str>);

impl<A: Api> Case<A> {
    pub(crate) fn summary(&self) -> Summary {
        (self.name, self.model, self.log)
    }
}

/// A catalogue covers what it claims: at least `min` cases, named uniquely, on every model,
/// and every one of `functions` but those allowed `anywhere` called in a wrong mode.
pub(crate) fn assert_complete(
    cases: &[Summary],
    min: usize,
    functions: &[&str],
    anywhere: &[&str],
) {
    assert!(cases.len() >= min, "{}", cases.len());
    let mut names: Vec<&str> = cases.iter().map(|c| c.0).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), cases.len(), "case names are unique");
    for model in contour_fmu::models::all() {
        assert!(
            cases.iter().any(|c| std::ptr::eq(c.1, model)),
            "{}",
            model.identifier
        );
    }
    let illegal = |function: &str| {
        cases.iter().any(|c| {
            c.2.is_some_and(|l| l.starts_with(&format!("{function}: illegal call sequence")))
        })
    };
    for function in functions.iter().filter(|f| !anywhere.contains(f)) {
        assert!(illegal(function), "{function} in a wrong mode");
    }
}
