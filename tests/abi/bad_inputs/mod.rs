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

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::common::*;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Causality, VarType};
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

const C2: &ModelInfo = &contour_ccc_2d::INFO;
const C5: &ModelInfo = &contour_ccc_5x::INFO;
const F5: &ModelInfo = &five_axis_plant::INFO;
const P2: &ModelInfo = &path_interpolator_2d::INFO;
const P5: &ModelInfo = &path_interpolator_5x::INFO;
const XY: &ModelInfo = &xy_servo_plant::INFO;
const SD: &ModelInfo = &servo_drive::INFO;
const SR: &ModelInfo = &servo_drive::INFO_ROTARY;
const PROBE: &ModelInfo = &fault_probe::INFO;

/// Communication step of every run.
const H: f64 = 1e-3;
/// Steps the `Stepping` setup takes before the bad call.
const WARMUP: usize = 3;

/// Where the instance is when the bad call comes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Setup {
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
enum Resources {
    Null,
    Uri(&'static str),
    /// The catalogue's temp folder (holding the path files), as a file URI.
    Folder,
}

/// What the instance is good for after the bad call.
#[derive(Clone, Copy, Debug, PartialEq)]
enum After {
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

type Call = fn(&mut Subject) -> fmi2Status;

struct Case {
    name: &'static str,
    model: &'static ModelInfo,
    setup: Setup,
    resources: Resources,
    /// The bad call (with the good calls it needs before it); returns its status.
    call: Call,
    status: fmi2Status,
    /// A text the log line must contain (parts separated by `…` in that order); `None`:
    /// nothing may be logged (no instance or no logger to tell, or nothing wrong).
    log: Option<&'static str>,
    after: After,
}

const fn case(
    name: &'static str,
    model: &'static ModelInfo,
    setup: Setup,
    call: Call,
    status: fmi2Status,
    log: Option<&'static str>,
    after: After,
) -> Case {
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

impl Case {
    const fn with(self, resources: Resources) -> Case {
        Case { resources, ..self }
    }
}

use After::*;
use Setup::*;

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
// The instance under test

/// An instance made by fmi2Instantiate with a resource location (the harness's `Instance`
/// has none); freed on drop.
struct Raw {
    c: fmi2Component,
    log: Box<Log>,
    _callbacks: Box<fmi2CallbackFunctions>,
}

impl Drop for Raw {
    fn drop(&mut self) {
        unsafe { lib().fmi2FreeInstance(self.c) };
    }
}

enum Fmu {
    Made(Instance),
    Raw(Raw),
}

/// Which GUID a case passes to fmi2Instantiate.
#[derive(Clone, Copy)]
enum Guid {
    Own,
    Null,
}

/// One instance of a case's model, brought into the case's setup; the FMU state saved
/// there (or just before the Error or Fatal mode) and the time.
struct Subject {
    model: &'static ModelInfo,
    name: &'static str,
    fmu: Option<Fmu>,
    /// The log of a refused fmi2Instantiate.
    refused: Option<Box<Log>>,
    freed: bool,
    saved: fmi2FMUstate,
    saved_at: (Setup, f64),
    time: f64,
}

/// The catalogue's folder for path files (`write_path_files`).
fn folder() -> &'static Path {
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
        let mut s = Subject {
            model,
            name,
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
        let fmu = match resources {
            Resources::Null => Fmu::Made(Instance::named(model, name)),
            Resources::Uri(uri) => s.raw(uri),
            Resources::Folder => s.raw(&format!("file://{}", folder().display())),
        };
        s.fmu = Some(fmu);
        s.log_warnings();
        s.bring(setup);
        s.log().records.lock().unwrap().clear();
        s
    }

    fn raw(&self, uri: &str) -> Fmu {
        let guid = self.model.guid();
        let (c, log, callbacks) = instantiate_raw(
            Some(self.name),
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

    /// Warnings and discards are only logged when asked for (errors always are).
    fn log_warnings(&self) {
        let categories = ["logStatusWarning", "logStatusError", "logStatusFatal"];
        let names: Vec<_> = categories.iter().map(|c| cstr(c)).collect();
        let pointers: Vec<fmi2String> = names.iter().map(|c| c.as_ptr()).collect();
        let s = unsafe { lib().fmi2SetDebugLogging(self.c(), 1, 3, pointers.as_ptr()) };
        self.ok(s);
    }

    fn c(&self) -> fmi2Component {
        match &self.fmu {
            Some(Fmu::Made(i)) => i.c,
            Some(Fmu::Raw(r)) => r.c,
            None => std::ptr::null_mut(),
        }
    }

    /// The harness's instance (cases with a resource location use the C calls below).
    fn i(&self) -> &Instance {
        match &self.fmu {
            Some(Fmu::Made(i)) => i,
            _ => panic!("the case needs an instance made without a resource location"),
        }
    }

    fn log(&self) -> &Log {
        match (&self.fmu, &self.refused) {
            (Some(Fmu::Made(i)), _) => &i.log,
            (Some(Fmu::Raw(r)), _) => &r.log,
            (None, Some(log)) => log,
            (None, None) => panic!("no instance and no log"),
        }
    }

    fn records(&self) -> Vec<Record> {
        self.log().records.lock().unwrap().clone()
    }

    fn last_error(&self) -> String {
        let records = self.records();
        let last = records.iter().rev().find(|r| r.status >= ERROR);
        last.map(|r| r.message.clone()).unwrap_or_default()
    }

    /// A good call that must succeed.
    fn ok(&self, status: fmi2Status) {
        assert_eq!(status, OK, "a good call failed: {}", self.last_error());
    }

    fn vr(&self, name: &str) -> u32 {
        let v = self.model.variables.iter().find(|v| v.name == name);
        v.unwrap_or_else(|| panic!("{} has no variable '{name}'", self.model.identifier))
            .vr as u32
    }

    fn file(&self, name: &str) -> String {
        folder().join(name).display().to_string()
    }

    fn free(&mut self) {
        match &mut self.fmu {
            Some(Fmu::Made(i)) => i.free(),
            Some(Fmu::Raw(r)) => unsafe { lib().fmi2FreeInstance(r.c) },
            None => {}
        }
        self.freed = true;
    }

    // The C calls, on either kind of instance.

    fn set_real(&self, name: &str, value: f64) -> fmi2Status {
        let vr = self.vr(name);
        unsafe { lib().fmi2SetReal(self.c(), &vr, 1, &value) }
    }
    fn set_integer(&self, name: &str, value: i32) -> fmi2Status {
        let vr = self.vr(name);
        unsafe { lib().fmi2SetInteger(self.c(), &vr, 1, &value) }
    }
    fn set_boolean(&self, name: &str, value: bool) -> fmi2Status {
        let (vr, value) = (self.vr(name), value as fmi2Boolean);
        unsafe { lib().fmi2SetBoolean(self.c(), &vr, 1, &value) }
    }
    fn set_string(&self, name: &str, value: &str) -> fmi2Status {
        let (vr, value) = (self.vr(name), cstr(value));
        unsafe { lib().fmi2SetString(self.c(), &vr, 1, &value.as_ptr()) }
    }

    /// Sets a bad value (which must be accepted), then ends initialization: the bad call.
    fn exit_with(&mut self, set: fn(&mut Subject) -> fmi2Status) -> fmi2Status {
        let status = set(self);
        self.ok(status);
        unsafe { lib().fmi2ExitInitializationMode(self.c()) }
    }

    /// Real inputs at time `t` (any finite values: the same for the instance and its twin),
    /// then one step.
    fn drive(&mut self) {
        for v in self.model.variables {
            if v.causality == Causality::Input && v.var_type() == VarType::Real {
                let value = 0.25 + 0.1 * v.vr as f64 + self.time;
                self.ok(unsafe { lib().fmi2SetReal(self.c(), &(v.vr as u32), 1, &value) });
            }
        }
        self.ok(unsafe { lib().fmi2DoStep(self.c(), self.time, H, 1) });
        self.time += H;
    }

    fn start(&mut self) {
        let c = self.c();
        self.ok(unsafe { lib().fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) });
        self.ok(unsafe { lib().fmi2EnterInitializationMode(c) });
        self.ok(unsafe { lib().fmi2ExitInitializationMode(c) });
        self.time = 0.0;
    }

    fn save(&mut self, setup: Setup) {
        let s = unsafe { lib().fmi2GetFMUstate(self.c(), &mut self.saved) };
        self.ok(s);
        self.saved_at = (setup, self.time);
    }

    /// Brings a new instance into `setup`, saving an FMU state on the way.
    fn bring(&mut self, setup: Setup) {
        let c = self.c();
        match setup {
            NoInstance | Instantiated => self.save(Instantiated),
            Initialization => {
                self.ok(unsafe { lib().fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) });
                self.ok(unsafe { lib().fmi2EnterInitializationMode(c) });
                self.save(Initialization);
            }
            Stepping | Terminated | Failed | Fatal => {
                self.start();
                for _ in 0..WARMUP {
                    self.drive();
                }
                self.save(Stepping);
                match setup {
                    Terminated => self.ok(unsafe { lib().fmi2Terminate(c) }),
                    Failed | Fatal => {
                        let fault = if setup == Failed { "fail" } else { "panic" };
                        self.ok(self.set_boolean(fault, true));
                        let expected = if setup == Failed { ERROR } else { FATAL };
                        assert_eq!(unsafe { lib().fmi2DoStep(c, self.time, H, 1) }, expected);
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
                self.ok(unsafe { lib().fmi2ExitInitializationMode(self.c()) });
                self.time = 0.0;
                self.drive();
            }
            Stepping => self.drive(),
            Terminated | Failed | Fatal => {}
        }
        self.values()
    }

    fn values(&self) -> Vec<String> {
        let c = self.c();
        self.model
            .variables
            .iter()
            .map(|v| {
                let vr = v.vr as u32;
                let (status, value) = unsafe {
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
                };
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
            let status = match v.start {
                contour_fmu::framework::variables::Start::Real(x) => {
                    self.set_real(&v.name.to_string(), x)
                }
                contour_fmu::framework::variables::Start::Integer(x) => {
                    self.set_integer(&v.name.to_string(), x)
                }
                contour_fmu::framework::variables::Start::Boolean(x) => {
                    self.set_boolean(&v.name.to_string(), x)
                }
                contour_fmu::framework::variables::Start::String(x) => {
                    self.set_string(&v.name.to_string(), x)
                }
            };
            self.ok(status);
        }
    }

    fn saved_bytes(&self) -> Vec<u8> {
        let (status, bytes) = self.i().serialize(self.saved);
        self.ok(status);
        bytes
    }

    /// The saved state with `edit` applied inside a valid envelope, deserialized.
    fn resealed(&self, edit: impl FnOnce(&mut StateEnvelope)) -> fmi2Status {
        let (format, mut envelope) = open_state(&self.saved_bytes());
        edit(&mut envelope);
        self.i().deserialize(&seal_state(format, &envelope)).0
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

/// The serialized state of a fresh, stepped instance of `model`.
fn state_bytes_of(model: &'static ModelInfo) -> Vec<u8> {
    Subject::new(model, Stepping, Resources::Null, "foreign").saved_bytes()
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

/// Removes the path files, also when the test fails.
struct Cleanup;

impl Drop for Cleanup {
    fn drop(&mut self) {
        std::fs::remove_dir_all(folder()).ok();
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
fn run(case: &Case) -> Result<(), String> {
    let mut s = Subject::new(case.model, case.setup, case.resources, "catalogue");
    let status = (case.call)(&mut s);
    let records = s.records();
    if status != case.status {
        return Err(format!(
            "status {status}, expected {}; log: {records:?}",
            case.status
        ));
    }

    // The log line naming the cause.
    match case.log {
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
    let twin = || Subject::new(case.model, resume_from, case.resources_of_twin(), "twin");
    let mut expected_twin = None;
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
            let refused = s.i().step(s.time, H);
            let message = s.last_error();
            if refused != ERROR || !message.contains("illegal call sequence (state Error)") {
                return Err(format!("a step in Error mode gave {refused}: {message}"));
            }
        }
        FreeOnly => {
            if s.i().reset() != ERROR || s.i().get_reals(&[0]).0 != ERROR {
                return Err("fmi2Reset or fmi2GetReal accepted after a fatal error".into());
            }
            // The states an importer holds can still be released, then the instance.
            let mut saved = s.saved;
            s.ok(s.i().free_state(&mut saved));
            s.free();
        }
        NotCreated => {
            if s.fmu.is_some() {
                return Err("an instance was created".into());
            }
        }
        Gone => {
            let before = s.records().len();
            if s.i().get_reals(&[0]).0 != ERROR || s.records().len() != before {
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
                Subject::new(case.model, case.setup, case.resources_of_twin(), "twin")
            });
            t.ok(unsafe { lib().fmi2SetFMUstate(t.c(), t.saved) });
            t.time = time;
            let expected = t.resume(mode);
            let restored = unsafe { lib().fmi2SetFMUstate(s.c(), s.saved) };
            if restored != OK {
                return Err(format!(
                    "fmi2SetFMUstate after the error: {}",
                    s.last_error()
                ));
            }
            s.time = time;
            same("after fmi2SetFMUstate", &s.resume(mode), &expected)?;
        }
        if unsafe { lib().fmi2Reset(s.c()) } != OK {
            return Err(format!("fmi2Reset after the error: {}", s.last_error()));
        }
        let mut fresh = Subject::new(case.model, Instantiated, case.resources_of_twin(), "twin");
        let expected = fresh.resume(Instantiated);
        same("after fmi2Reset", &s.resume(Instantiated), &expected)?;
    }
    Ok(())
}

impl Case {
    /// The twin is made like the instance, except for a case that instantiates it itself.
    fn resources_of_twin(&self) -> Resources {
        if self.setup == NoInstance {
            Resources::Null
        } else {
            self.resources
        }
    }
}

#[test]
fn the_catalogue_of_bad_inputs() {
    write_path_files();
    let _cleanup = Cleanup;
    let mut failures = Vec::new();
    for case in cases() {
        let outcome = catch_unwind(AssertUnwindSafe(|| run(case)));
        let problem = match outcome {
            Ok(Ok(())) => continue,
            Ok(Err(problem)) => problem,
            Err(panic) => panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "panic".into()),
        };
        failures.push(format!(
            "- {} ({}): {problem}",
            case.name, case.model.identifier
        ));
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases().count(),
        failures.join("\n")
    );
}

/// The catalogue covers what it claims: enough cases, every instance function in a wrong
/// mode, every model.
#[test]
fn the_catalogue_is_complete() {
    assert!(cases().count() >= 40, "{}", cases().count());
    let mut names: Vec<&str> = cases().map(|c| c.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), cases().count(), "case names are unique");
    for model in contour_fmu::models::all() {
        assert!(
            cases().any(|c| std::ptr::eq(c.model, model)),
            "{}",
            model.identifier
        );
    }
    let illegal = |function: &str| {
        cases().any(|c| {
            c.log
                .is_some_and(|l| l.starts_with(&format!("{function}: illegal call sequence")))
        })
    };
    // Every function but the five FMI 2.0 allows in any state (§4.3.3).
    let anywhere = [
        "fmi2GetTypesPlatform",
        "fmi2GetVersion",
        "fmi2Instantiate",
        "fmi2FreeInstance",
        "fmi2FreeFMUstate",
    ];
    for function in FMI2_CO_SIMULATION.iter().filter(|f| !anywhere.contains(f)) {
        assert!(illegal(function), "{function} in a wrong mode");
    }
}
