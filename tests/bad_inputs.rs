//! A catalogue of bad inputs, one table: every FMI function called in a wrong state, NULL
//! where an importer can err, NaN and infinities on every kind of input, integers out of
//! range, absurd parameters, corrupt and foreign FMU state bytes, missing resources and
//! malformed path files, on all six models (and FaultProbe for the Error and Fatal modes).
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
#![cfg(feature = "test-hooks")]

mod common;

use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::*;
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::{Causality, VarType};
use contour_fmu::models::{
    contour_ccc_2d, contour_ccc_5x, fault_probe, five_axis_plant, path_interpolator_2d,
    path_interpolator_5x, xy_servo_plant,
};

const C2: &ModelInfo = &contour_ccc_2d::INFO;
const C5: &ModelInfo = &contour_ccc_5x::INFO;
const F5: &ModelInfo = &five_axis_plant::INFO;
const P2: &ModelInfo = &path_interpolator_2d::INFO;
const P5: &ModelInfo = &path_interpolator_5x::INFO;
const XY: &ModelInfo = &xy_servo_plant::INFO;
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

static CASES: &[Case] = &[
    // --- Every instance function in a mode where FMI 2.0 (§4.3.3) does not allow it ---
    case(
        "fmi2SetDebugLogging after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().set_debug_logging(true, &[]),
        ERROR,
        Some("fmi2SetDebugLogging: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2SetupExperiment while stepping",
        XY,
        Stepping,
        |s| s.i().setup(0.0, None),
        ERROR,
        Some("fmi2SetupExperiment: illegal call sequence (state StepComplete)"),
        Usable,
    ),
    case(
        "fmi2EnterInitializationMode while stepping",
        C2,
        Stepping,
        |s| s.i().enter_init(),
        ERROR,
        Some("fmi2EnterInitializationMode: illegal call sequence (state StepComplete)"),
        Usable,
    ),
    case(
        "fmi2ExitInitializationMode before entering it",
        P2,
        Instantiated,
        |s| s.i().exit_init(),
        ERROR,
        Some("fmi2ExitInitializationMode: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2Terminate in initialization mode",
        F5,
        Initialization,
        |s| s.i().terminate(),
        ERROR,
        Some("fmi2Terminate: illegal call sequence (state Initialization)"),
        Usable,
    ),
    case(
        "fmi2Reset after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().reset(),
        ERROR,
        Some("fmi2Reset: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2GetReal before initialization",
        C5,
        Instantiated,
        |s| s.i().get_reals(&[s.vr("u.X")]).0,
        ERROR,
        Some("fmi2GetReal: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2GetInteger before initialization",
        C5,
        Instantiated,
        |s| s.i().get_integer(s.vr("hmm.band")).0,
        ERROR,
        Some("fmi2GetInteger: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2GetBoolean before initialization",
        P5,
        Instantiated,
        |s| s.i().get_boolean(s.vr("done")).0,
        ERROR,
        Some("fmi2GetBoolean: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2GetString before initialization",
        P2,
        Instantiated,
        |s| s.i().get_string(s.vr("path")).0,
        ERROR,
        Some("fmi2GetString: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2SetReal after fmi2Terminate",
        XY,
        Terminated,
        |s| s.set_real("u.x", 1.0),
        ERROR,
        Some("fmi2SetReal: illegal call sequence (state Terminated)"),
        Usable,
    ),
    case(
        "fmi2SetInteger after fmi2Terminate",
        C2,
        Terminated,
        |s| s.set_integer("estimator", 2),
        ERROR,
        Some("fmi2SetInteger: illegal call sequence (state Terminated)"),
        Usable,
    ),
    case(
        "fmi2SetBoolean in Error mode",
        PROBE,
        Failed,
        |s| s.set_boolean("fail", false),
        ERROR,
        Some("fmi2SetBoolean: illegal call sequence (state Error)"),
        ResetRequired,
    ),
    case(
        "fmi2SetString after fmi2Terminate",
        P5,
        Terminated,
        |s| s.set_string("path", "figure_eight"),
        ERROR,
        Some("fmi2SetString: illegal call sequence (state Terminated)"),
        Usable,
    ),
    case(
        "fmi2GetFMUstate after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().get_state().0,
        ERROR,
        Some("fmi2GetFMUstate: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2SetFMUstate after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().set_state(s.saved),
        ERROR,
        Some("fmi2SetFMUstate: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2SerializedFMUstateSize after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().state_size(s.saved).0,
        ERROR,
        Some("fmi2SerializedFMUstateSize: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2SerializeFMUstate after a fatal error",
        PROBE,
        Fatal,
        |s| {
            let mut buffer = [0 as fmi2Byte; 64];
            unsafe { lib().fmi2SerializeFMUstate(s.c(), s.saved, buffer.as_mut_ptr(), 64) }
        },
        ERROR,
        Some("fmi2SerializeFMUstate: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2DeSerializeFMUstate after a fatal error",
        PROBE,
        Fatal,
        |s| s.i().deserialize(b"any bytes").0,
        ERROR,
        Some("fmi2DeSerializeFMUstate: illegal call sequence (state Fatal)"),
        FreeOnly,
    ),
    case(
        "fmi2GetDirectionalDerivative before initialization",
        F5,
        Instantiated,
        |s| {
            let (vr, dv, mut out) = (0u32, 1.0, 0.0);
            unsafe { lib().fmi2GetDirectionalDerivative(s.c(), &vr, 1, &vr, 1, &dv, &mut out) }
        },
        ERROR,
        Some("fmi2GetDirectionalDerivative: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2SetRealInputDerivatives after fmi2Terminate",
        XY,
        Terminated,
        |s| {
            let (vr, order, v) = (s.vr("u.x"), 1, 0.0);
            unsafe { lib().fmi2SetRealInputDerivatives(s.c(), &vr, 1, &order, &v) }
        },
        ERROR,
        Some("fmi2SetRealInputDerivatives: illegal call sequence (state Terminated)"),
        Usable,
    ),
    case(
        "fmi2GetRealOutputDerivatives in initialization mode",
        C2,
        Initialization,
        |s| {
            let (vr, order, mut v) = (s.vr("u.x"), 1, 0.0);
            unsafe { lib().fmi2GetRealOutputDerivatives(s.c(), &vr, 1, &order, &mut v) }
        },
        ERROR,
        Some("fmi2GetRealOutputDerivatives: illegal call sequence (state Initialization)"),
        Usable,
    ),
    case(
        "fmi2DoStep in initialization mode",
        C2,
        Initialization,
        |s| s.i().step(0.0, H),
        ERROR,
        Some("fmi2DoStep: illegal call sequence (state Initialization)"),
        Usable,
    ),
    case(
        "fmi2DoStep after fmi2Terminate",
        P2,
        Terminated,
        |s| s.i().step(s.time, H),
        ERROR,
        Some("fmi2DoStep: illegal call sequence (state Terminated)"),
        Usable,
    ),
    case(
        "fmi2DoStep in Error mode",
        PROBE,
        Failed,
        |s| s.i().step(s.time, H),
        ERROR,
        Some("fmi2DoStep: illegal call sequence (state Error)"),
        ResetRequired,
    ),
    case(
        "fmi2CancelStep without a step in progress",
        XY,
        Stepping,
        |s| unsafe { lib().fmi2CancelStep(s.c()) },
        ERROR,
        Some("fmi2CancelStep: illegal call sequence (state StepComplete)"),
        Usable,
    ),
    case(
        "fmi2GetStatus in initialization mode",
        P5,
        Initialization,
        |s| {
            let mut v = 0;
            unsafe { lib().fmi2GetStatus(s.c(), fmi2StatusKind_fmi2DoStepStatus, &mut v) }
        },
        ERROR,
        Some("fmi2GetStatus: illegal call sequence (state Initialization)"),
        Usable,
    ),
    case(
        "fmi2GetRealStatus before initialization",
        F5,
        Instantiated,
        |s| {
            let mut v = 0.0;
            let kind = fmi2StatusKind_fmi2LastSuccessfulTime;
            unsafe { lib().fmi2GetRealStatus(s.c(), kind, &mut v) }
        },
        ERROR,
        Some("fmi2GetRealStatus: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    case(
        "fmi2GetIntegerStatus in Error mode",
        PROBE,
        Failed,
        |s| {
            let mut v = 0;
            let kind = fmi2StatusKind_fmi2DoStepStatus;
            unsafe { lib().fmi2GetIntegerStatus(s.c(), kind, &mut v) }
        },
        ERROR,
        Some("fmi2GetIntegerStatus: illegal call sequence (state Error)"),
        ResetRequired,
    ),
    case(
        "fmi2GetBooleanStatus in initialization mode",
        C5,
        Initialization,
        |s| {
            let mut v = 0;
            let kind = fmi2StatusKind_fmi2Terminated;
            unsafe { lib().fmi2GetBooleanStatus(s.c(), kind, &mut v) }
        },
        ERROR,
        Some("fmi2GetBooleanStatus: illegal call sequence (state Initialization)"),
        Usable,
    ),
    case(
        "fmi2GetStringStatus before initialization",
        XY,
        Instantiated,
        |s| {
            let mut v: fmi2String = std::ptr::null();
            let kind = fmi2StatusKind_fmi2PendingStatus;
            unsafe { lib().fmi2GetStringStatus(s.c(), kind, &mut v) }
        },
        ERROR,
        Some("fmi2GetStringStatus: illegal call sequence (state Instantiated)"),
        Usable,
    ),
    // Allowed now, but not provided (the model description says so).
    case(
        "fmi2GetDirectionalDerivative, not provided",
        C2,
        Stepping,
        |s| {
            let (vr, dv, mut out) = (s.vr("u.x"), 1.0, 0.0);
            unsafe { lib().fmi2GetDirectionalDerivative(s.c(), &vr, 1, &vr, 1, &dv, &mut out) }
        },
        ERROR,
        Some("fmi2GetDirectionalDerivative: not supported (providesDirectionalDerivative"),
        Usable,
    ),
    case(
        "fmi2GetStatus: no asynchronous step to report",
        P2,
        Stepping,
        |s| {
            let mut v = 0;
            unsafe { lib().fmi2GetStatus(s.c(), fmi2StatusKind_fmi2DoStepStatus, &mut v) }
        },
        DISCARD,
        Some("fmi2GetStatus: no asynchronous step status"),
        Usable,
    ),
    case(
        "fmi2GetRealStatus of a kind without a Real value",
        F5,
        Stepping,
        |s| {
            let mut v = 0.0;
            let kind = fmi2StatusKind_fmi2DoStepStatus;
            unsafe { lib().fmi2GetRealStatus(s.c(), kind, &mut v) }
        },
        DISCARD,
        Some("fmi2GetRealStatus: status kind 0 has no Real value"),
        Usable,
    ),
    // --- NULL (and dead handles) where an importer can err ---
    case(
        "fmi2Instantiate with a NULL instance name",
        XY,
        NoInstance,
        |s| s.instantiate(None, fmi2Type_fmi2CoSimulation, Guid::Own, None),
        ERROR,
        Some("fmi2Instantiate: the instance name is NULL or empty"),
        NotCreated,
    ),
    case(
        "fmi2Instantiate with a blank instance name",
        C2,
        NoInstance,
        |s| s.instantiate(Some("  "), fmi2Type_fmi2CoSimulation, Guid::Own, None),
        ERROR,
        Some("fmi2Instantiate: the instance name is NULL or empty"),
        NotCreated,
    ),
    case(
        "fmi2Instantiate with a NULL GUID",
        P2,
        NoInstance,
        |s| s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Null, None),
        ERROR,
        Some("fmi2Instantiate: the GUID is NULL"),
        NotCreated,
    ),
    case(
        "fmi2Instantiate with NULL callbacks (no logger to tell)",
        F5,
        NoInstance,
        |s| s.instantiate_without_logger(true),
        ERROR,
        None,
        NotCreated,
    ),
    case(
        "fmi2Instantiate with a NULL logger (no logger to tell)",
        P5,
        NoInstance,
        |s| s.instantiate_without_logger(false),
        ERROR,
        None,
        NotCreated,
    ),
    case(
        "a NULL fmi2Component (no instance to log to)",
        XY,
        Stepping,
        |s| unsafe { lib().fmi2DoStep(std::ptr::null_mut(), s.time, H, 1) },
        ERROR,
        None,
        Usable,
    ),
    case(
        "a freed fmi2Component (no instance to log to)",
        C5,
        Stepping,
        |s| {
            s.free();
            unsafe { lib().fmi2DoStep(s.c(), s.time, H, 1) }
        },
        ERROR,
        None,
        Gone,
    ),
    case(
        "fmi2GetReal with a NULL vr array",
        C2,
        Stepping,
        |s| {
            let mut out = [0.0; 2];
            unsafe { lib().fmi2GetReal(s.c(), std::ptr::null(), 2, out.as_mut_ptr()) }
        },
        ERROR,
        Some("fmi2GetReal: vr is NULL but its length is 2"),
        Usable,
    ),
    case(
        "fmi2GetReal with a NULL value array",
        F5,
        Stepping,
        |s| {
            let vr = s.vr("pos.X");
            unsafe { lib().fmi2GetReal(s.c(), &vr, 1, std::ptr::null_mut()) }
        },
        ERROR,
        Some("fmi2GetReal: value is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi2SetReal with a NULL value array",
        XY,
        Initialization,
        |s| {
            let vr = s.vr("x.J");
            unsafe { lib().fmi2SetReal(s.c(), &vr, 1, std::ptr::null()) }
        },
        ERROR,
        Some("fmi2SetReal: value is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi2SetInteger with a NULL vr array",
        C5,
        Initialization,
        |s| {
            let v = 8;
            unsafe { lib().fmi2SetInteger(s.c(), std::ptr::null(), 1, &v) }
        },
        ERROR,
        Some("fmi2SetInteger: vr is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi2SetString with a NULL string",
        P2,
        Initialization,
        |s| {
            let (vr, v) = (s.vr("path"), std::ptr::null::<c_char>());
            unsafe { lib().fmi2SetString(s.c(), &vr, 1, &v) }
        },
        ERROR,
        Some("fmi2SetString: a string value is NULL or not UTF-8"),
        Usable,
    ),
    case(
        "fmi2GetString with a NULL value array",
        P5,
        Stepping,
        |s| {
            let vr = s.vr("path");
            unsafe { lib().fmi2GetString(s.c(), &vr, 1, std::ptr::null_mut()) }
        },
        ERROR,
        Some("fmi2GetString: value is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi2SetDebugLogging with a NULL category array",
        C2,
        Initialization,
        |s| unsafe { lib().fmi2SetDebugLogging(s.c(), 1, 2, std::ptr::null()) },
        ERROR,
        Some("fmi2SetDebugLogging: categories is NULL but its length is 2"),
        Usable,
    ),
    case(
        "fmi2SetDebugLogging with an unknown category",
        XY,
        Stepping,
        |s| s.i().set_debug_logging(true, &["logEverything"]),
        ERROR,
        Some("fmi2SetDebugLogging: unknown log category 'logEverything'"),
        Usable,
    ),
    case(
        "fmi2GetFMUstate with a NULL FMUstate*",
        XY,
        Stepping,
        |s| unsafe { lib().fmi2GetFMUstate(s.c(), std::ptr::null_mut()) },
        ERROR,
        Some("fmi2GetFMUstate: FMUstate (the address of the variable) is NULL"),
        Usable,
    ),
    case(
        "fmi2SetFMUstate with a NULL state",
        C2,
        Stepping,
        |s| s.i().set_state(std::ptr::null_mut()),
        ERROR,
        Some("fmi2SetFMUstate: FMUstate is NULL"),
        Usable,
    ),
    case(
        "fmi2FreeFMUstate with NULL (ignored, as the standard says)",
        P2,
        Stepping,
        |s| s.i().free_state_raw(std::ptr::null_mut()),
        OK,
        None,
        Usable,
    ),
    case(
        "fmi2FreeFMUstate with the state instead of its address (fmusim 0.0.39)",
        F5,
        Stepping,
        |s| {
            let (status, state) = s.i().get_state();
            s.ok(status);
            s.i().free_state_raw(state as *mut fmi2FMUstate)
        },
        OK,
        Some("fmi2FreeFMUstate: the argument is the FMU state"),
        Usable,
    ),
    case(
        "fmi2SerializedFMUstateSize with a NULL size",
        C5,
        Stepping,
        |s| unsafe { lib().fmi2SerializedFMUstateSize(s.c(), s.saved, std::ptr::null_mut()) },
        ERROR,
        Some("fmi2SerializedFMUstateSize: size is NULL"),
        Usable,
    ),
    case(
        "fmi2SerializeFMUstate into a NULL buffer",
        P5,
        Stepping,
        |s| {
            let size = s.i().state_size(s.saved).1;
            unsafe { lib().fmi2SerializeFMUstate(s.c(), s.saved, std::ptr::null_mut(), size) }
        },
        ERROR,
        Some("fmi2SerializeFMUstate: serializedState is NULL but its length is"),
        Usable,
    ),
    case(
        "fmi2DeSerializeFMUstate from NULL bytes",
        XY,
        Stepping,
        |s| {
            let mut state: fmi2FMUstate = std::ptr::null_mut();
            unsafe { lib().fmi2DeSerializeFMUstate(s.c(), std::ptr::null(), 100, &mut state) }
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: serializedState is NULL but its length is 100"),
        Usable,
    ),
    case(
        "fmi2DeSerializeFMUstate into a NULL FMUstate*",
        C2,
        Stepping,
        |s| {
            let bytes = s.saved_bytes();
            let p = bytes.as_ptr() as *const fmi2Byte;
            unsafe { lib().fmi2DeSerializeFMUstate(s.c(), p, bytes.len(), std::ptr::null_mut()) }
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: FMUstate (the address of the variable) is NULL"),
        Usable,
    ),
    case(
        "fmi2GetRealStatus into a NULL value",
        XY,
        Stepping,
        |s| {
            let kind = fmi2StatusKind_fmi2LastSuccessfulTime;
            unsafe { lib().fmi2GetRealStatus(s.c(), kind, std::ptr::null_mut()) }
        },
        ERROR,
        Some("fmi2GetRealStatus: value is NULL"),
        Usable,
    ),
    // --- NaN and infinities on every kind of input ---
    case(
        "NaN on a Real input",
        XY,
        Stepping,
        |s| s.set_real("u.x", f64::NAN),
        ERROR,
        Some("fmi2SetReal: variable 'u.x' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "+Inf on a Real input",
        C2,
        Stepping,
        |s| s.set_real("ref.y", f64::INFINITY),
        ERROR,
        Some("fmi2SetReal: variable 'ref.y' refuses the non-finite value inf"),
        Usable,
    ),
    case(
        "-Inf on a Real input, in initialization mode",
        C5,
        Initialization,
        |s| s.set_real("pos.A", f64::NEG_INFINITY),
        ERROR,
        Some("fmi2SetReal: variable 'pos.A' refuses the non-finite value -inf"),
        Usable,
    ),
    case(
        "NaN on a Real parameter",
        P2,
        Initialization,
        |s| s.set_real("feed", f64::NAN),
        ERROR,
        Some("fmi2SetReal: variable 'feed' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "+Inf on a Real parameter before initialization",
        F5,
        Instantiated,
        |s| s.set_real("X.J", f64::INFINITY),
        ERROR,
        Some("fmi2SetReal: variable 'X.J' refuses the non-finite value inf"),
        Usable,
    ),
    case(
        "NaN on an unbounded Real parameter",
        C5,
        Initialization,
        |s| s.set_real("toolLength", f64::NAN),
        ERROR,
        Some("fmi2SetReal: variable 'toolLength' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "NaN on a pivot of the five-axis interpolator",
        P5,
        Initialization,
        |s| s.set_real("pivot.C.x", f64::NAN),
        ERROR,
        Some("fmi2SetReal: variable 'pivot.C.x' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "NaN on a tunable parameter while stepping",
        PROBE,
        Stepping,
        |s| s.set_real("gain", f64::NAN),
        ERROR,
        Some("fmi2SetReal: variable 'gain' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "-Inf on a tunable parameter while stepping",
        PROBE,
        Stepping,
        |s| s.set_real("gain", f64::NEG_INFINITY),
        ERROR,
        Some("fmi2SetReal: variable 'gain' refuses the non-finite value -inf"),
        Usable,
    ),
    case(
        "NaN as the communication step size",
        XY,
        Stepping,
        |s| s.i().step(s.time, f64::NAN),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got NaN)"),
        Usable,
    ),
    case(
        "+Inf as the communication step size",
        P2,
        Stepping,
        |s| s.i().step(s.time, f64::INFINITY),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got inf)"),
        Usable,
    ),
    case(
        "a communication step of 1e300 s (a sampled model would never return)",
        C2,
        Stepping,
        |s| s.i().step(s.time, 1e300),
        ERROR,
        Some("fmi2DoStep: communication step size 1e300 s refused: it would take 1e303 samples of Ts = 0.001 s"),
        Usable,
    ),
    case(
        "a communication step of 1e5 s (1e8 samples)",
        P5,
        Stepping,
        |s| s.i().step(s.time, 1e5),
        ERROR,
        Some("fmi2DoStep: communication step size 1e5 s refused: it would take"),
        Usable,
    ),
    case(
        "NaN as the communication point",
        C5,
        Stepping,
        |s| s.i().step(f64::NAN, H),
        ERROR,
        Some("fmi2DoStep: communication point NaN does not match the instance time"),
        Usable,
    ),
    case(
        "-Inf as the communication point",
        P5,
        Stepping,
        |s| s.i().step(f64::NEG_INFINITY, H),
        ERROR,
        Some("fmi2DoStep: communication point -inf does not match the instance time"),
        Usable,
    ),
    case(
        "NaN as the start time",
        XY,
        Instantiated,
        |s| unsafe { lib().fmi2SetupExperiment(s.c(), 0, 0.0, f64::NAN, 0, 0.0) },
        ERROR,
        Some("fmi2SetupExperiment: start time NaN is not finite"),
        Usable,
    ),
    case(
        "+Inf as the stop time",
        P2,
        Instantiated,
        |s| s.i().setup(0.0, Some(f64::INFINITY)),
        ERROR,
        Some("fmi2SetupExperiment: stop time inf must be finite"),
        Usable,
    ),
    // --- Other bad times, parameters set while stepping, failing models ---
    case(
        "a zero communication step size",
        C2,
        Stepping,
        |s| s.i().step(s.time, 0.0),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got 0)"),
        Usable,
    ),
    case(
        "a negative communication step size",
        F5,
        Stepping,
        |s| s.i().step(s.time, -H),
        ERROR,
        Some("fmi2DoStep: communication step size must be finite and > 0 (got -0.001)"),
        Usable,
    ),
    case(
        "a communication point behind the instance time",
        XY,
        Stepping,
        |s| s.i().step(0.0, H),
        ERROR,
        Some("fmi2DoStep: communication point 0 does not match the instance time"),
        Usable,
    ),
    case(
        "a stop time before the start time",
        C2,
        Instantiated,
        |s| s.i().setup(1.0, Some(0.5)),
        ERROR,
        Some("fmi2SetupExperiment: stop time 0.5 must be finite and not before the start time 1"),
        Usable,
    ),
    case(
        "a tunable parameter the model refuses while stepping",
        PROBE,
        Stepping,
        |s| s.set_real("gain", 12.0),
        ERROR,
        Some("fmi2SetReal: parameter 'gain' must be < 10 (got 12)"),
        Usable,
    ),
    case(
        "a fixed parameter set while stepping",
        XY,
        Stepping,
        |s| s.set_real("x.J", 0.02),
        ERROR,
        Some("fmi2SetReal: parameter 'x.J' is fixed"),
        Usable,
    ),
    case(
        "a failing model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| {
            let status = s.set_boolean("fail", true);
            s.ok(status);
            s.i().step(s.time, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0.003 failed: FaultProbe: injected failure"),
        ResetRequired,
    ),
    case(
        "a panicking model step (FaultProbe)",
        PROBE,
        Stepping,
        |s| {
            let status = s.set_boolean("panic", true);
            s.ok(status);
            s.i().step(s.time, H)
        },
        FATAL,
        Some("fmi2DoStep: internal error (panic): FaultProbe: injected panic"),
        FreeOnly,
    ),
    // --- Integers out of range, unknown references, wrong types ---
    case(
        "an enumeration value of 0",
        C2,
        Initialization,
        |s| s.set_integer("estimator", 0),
        ERROR,
        Some("fmi2SetInteger: variable 'estimator' = 0 is not a value of its enumeration"),
        Usable,
    ),
    case(
        "an enumeration value of i32::MIN",
        C2,
        Instantiated,
        |s| s.set_integer("estimator", i32::MIN),
        ERROR,
        Some("fmi2SetInteger: variable 'estimator' = -2147483648 is not a value"),
        Usable,
    ),
    case(
        "an Integer parameter below its minimum",
        C5,
        Initialization,
        |s| s.set_integer("hmm.band", 1),
        ERROR,
        Some("fmi2SetInteger: variable 'hmm.band' = 1 is below its minimum 2"),
        Usable,
    ),
    case(
        "an Integer parameter above its maximum",
        C5,
        Instantiated,
        |s| s.set_integer("hmm.maxSkip", 65),
        ERROR,
        Some("fmi2SetInteger: variable 'hmm.maxSkip' = 65 is above its maximum 64"),
        Usable,
    ),
    case(
        "i32::MAX on an Integer parameter",
        C5,
        Initialization,
        |s| s.set_integer("hmm.lag", i32::MAX),
        ERROR,
        Some("fmi2SetInteger: variable 'hmm.lag' = 2147483647 is above its maximum 4096"),
        Usable,
    ),
    case(
        "an unknown value reference among good ones (nothing is set)",
        XY,
        Initialization,
        |s| s.i().set_reals(&[s.vr("x.J"), 9999], &[0.02, 1.0]),
        ERROR,
        Some("fmi2SetReal: unknown value reference 9999"),
        Usable,
    ),
    case(
        "fmi2GetInteger on a Real variable",
        F5,
        Stepping,
        |s| s.i().get_integer(s.vr("pos.X")).0,
        ERROR,
        Some("fmi2GetInteger: variable 'pos.X' (value reference"),
        Usable,
    ),
    case(
        "fmi2SetBoolean on an Integer parameter",
        C5,
        Initialization,
        |s| s.set_boolean("hmm.band", true),
        ERROR,
        Some("fmi2SetBoolean: variable 'hmm.band' is of type Integer, not Boolean"),
        Usable,
    ),
    case(
        "fmi2SetReal on an output",
        P2,
        Stepping,
        |s| s.set_real("ref.x", 1.0),
        ERROR,
        Some("fmi2SetReal: variable 'ref.x' is an output and cannot be set"),
        Usable,
    ),
    // --- Absurd parameters: refused when set, when initialization ends (within their
    // bounds but not physical), or when the first step overflows ---
    case(
        "Ts = 0 (controller)",
        C2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s (got 0)"),
        Corrected,
    ),
    case(
        "Ts < 0 (five-axis controller)",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", -1e-3)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s (got -0.001)"),
        Corrected,
    ),
    case(
        "Ts of 1 ns (five-axis interpolator)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Ts", 1e-9)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Ts' must be at least 1e-6 s"),
        Corrected,
    ),
    case(
        "a negative feed",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("feed", -5.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'feed' must be > 0 (got -5)"),
        Corrected,
    ),
    case(
        "a zero feed (five-axis)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("feed", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'feed' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a line of zero length",
        P2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_string("path", "line");
                s.ok(status);
                s.i().set_reals(&[s.vr("line.x1"), s.vr("line.y1")], &[0.0, 0.0])
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'line.*'"),
        Corrected,
    ),
    case(
        "an arc of negative radius",
        P2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_string("path", "arc");
                s.ok(status);
                s.set_real("arc.r", -3.0)
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'arc.*': invalid path: arc radius"),
        Corrected,
    ),
    case(
        "an arc estimator of zero radius",
        C2,
        Initialization,
        |s| {
            s.exit_with(|s| {
                let status = s.set_integer("estimator", 3);
                s.ok(status);
                s.set_real("arc.r", 0.0)
            })
        },
        ERROR,
        Some("fmi2ExitInitializationMode: parameters 'arc.*': invalid path: arc radius"),
        Corrected,
    ),
    case(
        "a zero contour correction limit",
        C2,
        Initialization,
        |s| s.exit_with(|s| s.set_real("ccc.limit", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter ccc.limit = 0 is invalid"),
        Corrected,
    ),
    case(
        "a negative position-loop gain",
        C2,
        Initialization,
        |s| s.set_real("axis.y.Ki", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'axis.y.Ki' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a negative damping of the Jacobian inverse",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("damping", -1.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter damping = -1 is invalid"),
        Corrected,
    ),
    case(
        "a zero tool length",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("toolLength", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter toolLength = 0 is invalid"),
        Corrected,
    ),
    case(
        "a negative tool length",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("toolLength", -150.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter toolLength = -150 is invalid"),
        Corrected,
    ),
    case(
        "a zero mapping beam",
        C5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("hmm.beam", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter hmm.beam = 0 is invalid"),
        Corrected,
    ),
    case(
        "a zero inertia",
        XY,
        Initialization,
        |s| s.exit_with(|s| s.set_real("x.J", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'x.J' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a negative viscous friction (damping)",
        XY,
        Initialization,
        |s| s.set_real("y.B", -1.0),
        ERROR,
        Some("fmi2SetReal: variable 'y.B' = -1 is below its minimum 0"),
        Usable,
    ),
    case(
        "a zero gear ratio",
        F5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("A.ratio", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'A.ratio' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "a zero ball-screw lead",
        F5,
        Initialization,
        |s| s.exit_with(|s| s.set_real("Z.lead", 0.0)),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'Z.lead' must be > 0 (got 0)"),
        Corrected,
    ),
    case(
        "an inertia of 1e-300 (the plant overflows in its first step)",
        XY,
        Initialization,
        |s| {
            let status = s.exit_with(|s| s.set_real("x.J", 1e-300));
            s.ok(status);
            s.i().step(0.0, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0 failed: output 'pos.x' = NaN is not finite"),
        ResetRequired,
    ),
    case(
        "a velocity-loop gain of 1e300 (the plant overflows in its first step)",
        F5,
        Initialization,
        |s| {
            let status = s.exit_with(|s| s.set_real("X.Kvp", 1e300));
            s.ok(status);
            s.i().step(0.0, H)
        },
        ERROR,
        Some("fmi2DoStep: step at t = 0 failed: output 'pos.X' = NaN is not finite"),
        ResetRequired,
    ),
    case(
        "an unknown built-in path",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "spiral")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': unknown path 'spiral'"),
        Corrected,
    ),
    case(
        "an unknown five-axis built-in path",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "spiral")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': invalid path: unknown five-axis path \"spiral\""),
        Corrected,
    ),
    // --- Corrupt FMU state bytes ---
    case(
        "state bytes truncated by one byte",
        XY,
        Stepping,
        |s| {
            let bytes = s.saved_bytes();
            s.i().deserialize(&bytes[..bytes.len() - 1]).0
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state is corrupt (checksum mismatch)"),
        Usable,
    ),
    case(
        "state bytes truncated inside the header",
        P5,
        Stepping,
        |s| s.i().deserialize(&s.saved_bytes()[..9]).0,
        ERROR,
        Some("fmi2DeSerializeFMUstate: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "no state bytes at all",
        F5,
        Stepping,
        |s| s.i().deserialize(&[]).0,
        ERROR,
        Some("fmi2DeSerializeFMUstate: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "a flipped byte in the state bytes",
        C2,
        Stepping,
        |s| {
            let mut bytes = s.saved_bytes();
            let middle = bytes.len() / 2;
            bytes[middle] ^= 0x10;
            s.i().deserialize(&bytes).0
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state is corrupt (checksum mismatch)"),
        Usable,
    ),
    case(
        "state bytes with a wrong magic",
        P2,
        Stepping,
        |s| {
            let mut bytes = s.saved_bytes();
            bytes[0] = b'X';
            s.i().deserialize(&bytes).0
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "state bytes of a future format version",
        C5,
        Stepping,
        |s| {
            let (_, envelope) = open_state(&s.saved_bytes());
            s.i().deserialize(&seal_state(STATE_FORMAT + 1, &envelope)).0
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: FMU state format version 3 is not supported (this library reads 2): the state was saved by a newer build"),
        Usable,
    ),
    case(
        "a model state of a future layout version",
        XY,
        Stepping,
        |s| s.resealed(|e| e.model[..2].copy_from_slice(&99u16.to_le_bytes())),
        ERROR,
        Some("the XYServoPlant state has internal layout version 99"),
        Usable,
    ),
    case(
        "a NaN inside checksummed state bytes",
        XY,
        Stepping,
        |s| {
            let vr = s.vr("u.x") as usize;
            s.resealed(|e| e.values.set(vr, contour_fmu::framework::variables::Value::Real(f64::NAN)))
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state is invalid: variable 'u.x' refuses the non-finite value NaN"),
        Usable,
    ),
    case(
        "a state saved after a fatal error",
        F5,
        Stepping,
        |s| s.resealed(|e| e.mode = 6),
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state was saved after a fatal error"),
        Usable,
    ),
    case(
        "a state with a non-finite time",
        P2,
        Stepping,
        |s| s.resealed(|e| e.time = f64::INFINITY),
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state is invalid: time inf"),
        Usable,
    ),
    case(
        "text instead of state bytes",
        C2,
        Initialization,
        |s| s.i().deserialize(b"not an FMU state, just text").0,
        ERROR,
        Some("fmi2DeSerializeFMUstate: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "a serialization buffer too small",
        F5,
        Stepping,
        |s| {
            let mut small = [0 as fmi2Byte; 4];
            unsafe { lib().fmi2SerializeFMUstate(s.c(), s.saved, small.as_mut_ptr(), 4) }
        },
        ERROR,
        Some("fmi2SerializeFMUstate: buffer of 4 bytes is too small"),
        Usable,
    ),
    case(
        "fmi2SetFMUstate with a freed state",
        C5,
        Stepping,
        |s| {
            let (status, mut state) = s.i().get_state();
            s.ok(status);
            let stale = state;
            let status = s.i().free_state(&mut state);
            s.ok(status);
            s.i().set_state(stale)
        },
        ERROR,
        Some("is not a live FMU state of this instance"),
        Usable,
    ),
    case(
        "fmi2SetFMUstate with a made-up pointer",
        P5,
        Stepping,
        |s| {
            let mut block = [0u64; 8];
            s.i().set_state(block.as_mut_ptr() as fmi2FMUstate)
        },
        ERROR,
        Some("fmi2SetFMUstate: FMUstate 0x"),
        Usable,
    ),
    case(
        "fmi2GetFMUstate into a variable holding a made-up state",
        XY,
        Stepping,
        |s| {
            let mut block = [0u64; 8];
            let mut state = block.as_mut_ptr() as fmi2FMUstate;
            unsafe { lib().fmi2GetFMUstate(s.c(), &mut state) }
        },
        ERROR,
        Some("is not a live FMU state of this instance"),
        Usable,
    ),
    // --- Foreign FMU states ---
    case(
        "state bytes of another model",
        XY,
        Stepping,
        |s| s.i().deserialize(&state_bytes_of(C2)).0,
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state belongs to another model"),
        Usable,
    ),
    case(
        "five-axis interpolator state bytes into the two-axis one",
        P2,
        Stepping,
        |s| s.i().deserialize(&state_bytes_of(P5)).0,
        ERROR,
        Some("the FMU state belongs to another model"),
        Usable,
    ),
    case(
        "FaultProbe state bytes into the five-axis controller",
        C5,
        Initialization,
        |s| s.i().deserialize(&state_bytes_of(PROBE)).0,
        ERROR,
        Some("the FMU state belongs to another model"),
        Usable,
    ),
    case(
        "another model's state under this model's GUID",
        F5,
        Stepping,
        |s| {
            let (format, mut envelope) = open_state(&state_bytes_of(XY));
            envelope.guid = F5.guid();
            s.i().deserialize(&seal_state(format, &envelope)).0
        },
        ERROR,
        Some("fmi2DeSerializeFMUstate: the FMU state does not fit this model's variables"),
        Usable,
    ),
    case(
        "an FMU state handle of another instance",
        XY,
        Stepping,
        |s| {
            let other = Instance::named(XY, "other");
            let (status, state) = other.get_state();
            s.ok(status);
            s.i().set_state(state)
        },
        ERROR,
        Some("belongs to instance 'other', not to this one"),
        Usable,
    ),
    case(
        "an FMU state handle of another model's instance",
        P2,
        Stepping,
        |s| {
            let other = Instance::named(C2, "controller");
            let (status, state) = other.get_state();
            s.ok(status);
            s.i().set_state(state)
        },
        ERROR,
        Some("belongs to instance 'controller', not to this one"),
        Usable,
    ),
    case(
        "state bytes of another instance of the same model (accepted)",
        C2,
        Stepping,
        |s| {
            // The other instance ran the same steps: restoring its state changes nothing.
            let mut other = Subject::new(C2, Stepping, Resources::Null, "other");
            let (status, state) = s.i().deserialize(&other.saved_bytes());
            s.ok(status);
            other.free();
            s.i().set_state(state)
        },
        OK,
        None,
        Usable,
    ),
    // --- Missing resources ---
    case(
        "a resource location that is not a file URI",
        P2,
        NoInstance,
        |s| {
            let uri = Some("http://example.org/resources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("fmi2Instantiate: resource location 'http://example.org/resources' is not a file: URI; continuing without resources"),
        Usable,
    ),
    case(
        "a resource location on a remote host",
        P5,
        NoInstance,
        |s| {
            let uri = Some("file://server/share/resources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("names the remote host 'server'"),
        Usable,
    ),
    case(
        "a resource location with a bad %-escape",
        XY,
        NoInstance,
        |s| {
            let uri = Some("file:///tmp/res%zzources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("has a bad %-escape"),
        Usable,
    ),
    case(
        "a relative path file without a resource location",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "part.json")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': part.json: cannot read…the importer gave no usable resource location"),
        Corrected,
    ),
    case(
        "a relative CL file with a resource location that is not a file URI",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "blade.cl")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': blade.cl: cannot read…the importer gave no usable resource location"),
        Corrected,
    )
    .with(Resources::Uri("http://example.org/resources")),
    case(
        "a relative CL file missing from the resources folder",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "absent.cl")),
        ERROR,
        Some("absent.cl: cannot read"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "an absolute NURBS file that does not exist",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("absent.json"))),
        ERROR,
        Some("absent.json: cannot read"),
        Corrected,
    ),
    case(
        "an absolute two-curve file that does not exist",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("absent.json"))),
        ERROR,
        Some("absent.json: cannot read"),
        Corrected,
    ),
    // --- Malformed path files (written by `write_path_files`) ---
    case(
        "a NURBS file with a JSON syntax error",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("syntax.json"))),
        ERROR,
        Some("syntax.json:3:"),
        Corrected,
    ),
    case(
        "a NURBS file with a misspelt key",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("typo.json"))),
        ERROR,
        Some("typo.json:1:"),
        Corrected,
    ),
    case(
        "a NURBS file with a wrong knot count",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("knots.json"))),
        ERROR,
        Some("knots.json: knot count must be control points + degree + 1"),
        Corrected,
    ),
    case(
        "a malformed NURBS file named relative to the resources folder",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "syntax.json")),
        ERROR,
        Some("syntax.json:3:"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a CL record with a field that is not a number",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("word.cl"))),
        ERROR,
        Some("word.cl:4: GOTO: 'abc' is not a finite number"),
        Corrected,
    ),
    case(
        "a CL record with NaN",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("nan.cl"))),
        ERROR,
        Some("nan.cl:2: GOTO: 'NaN' is not a finite number"),
        Corrected,
    ),
    case(
        "a CL record with four numbers",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "count.cl")),
        ERROR,
        Some("count.cl:3: GOTO needs x,y,z or x,y,z,i,j,k, got 4 numbers"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a CL record with a zero tool axis",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("zero_axis.cl"))),
        ERROR,
        Some("zero_axis.cl:2: GOTO: the tool axis i,j,k is zero"),
        Corrected,
    ),
    case(
        "a CL file ending in a continuation",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("dangling.cl"))),
        ERROR,
        Some("dangling.cl:3: the last record ends in a continuation '$'"),
        Corrected,
    ),
    case(
        "a CL file with a single point",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("single.cl"))),
        ERROR,
        Some("single.cl: a path needs at least two GOTO points, found 1"),
        Corrected,
    ),
    case(
        "a two-curve file of the wrong shape",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("curves.json"))),
        ERROR,
        Some("curves.json:1:"),
        Corrected,
    ),
    case(
        "a CL tool axis that is not a unit vector (normalised, with a warning)",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("long_axis.cl"))),
        OK,
        Some("long_axis.cl:2: tool axis of length 2 normalised"),
        Steps,
    ),
];

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
    let files: [(&str, &str); 11] = [
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
    for case in CASES {
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
        CASES.len(),
        failures.join("\n")
    );
}

/// The catalogue covers what it claims: enough cases, every instance function in a wrong
/// mode, every model.
#[test]
fn the_catalogue_is_complete() {
    assert!(CASES.len() >= 40, "{}", CASES.len());
    let mut names: Vec<&str> = CASES.iter().map(|c| c.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), CASES.len(), "case names are unique");
    for model in contour_fmu::models::all() {
        assert!(
            CASES.iter().any(|c| std::ptr::eq(c.model, model)),
            "{}",
            model.identifier
        );
    }
    let illegal = |function: &str| {
        CASES.iter().any(|c| {
            c.log
                .is_some_and(|l| l.starts_with(&format!("{function}: illegal call sequence")))
        })
    };
    for function in [
        "fmi2SetDebugLogging",
        "fmi2SetupExperiment",
        "fmi2EnterInitializationMode",
        "fmi2ExitInitializationMode",
        "fmi2Terminate",
        "fmi2Reset",
        "fmi2GetReal",
        "fmi2GetInteger",
        "fmi2GetBoolean",
        "fmi2GetString",
        "fmi2SetReal",
        "fmi2SetInteger",
        "fmi2SetBoolean",
        "fmi2SetString",
        "fmi2GetFMUstate",
        "fmi2SetFMUstate",
        "fmi2SerializedFMUstateSize",
        "fmi2SerializeFMUstate",
        "fmi2DeSerializeFMUstate",
        "fmi2GetDirectionalDerivative",
        "fmi2SetRealInputDerivatives",
        "fmi2GetRealOutputDerivatives",
        "fmi2DoStep",
        "fmi2CancelStep",
        "fmi2GetStatus",
        "fmi2GetRealStatus",
        "fmi2GetIntegerStatus",
        "fmi2GetBooleanStatus",
        "fmi2GetStringStatus",
    ] {
        assert!(illegal(function), "{function} in a wrong mode");
    }
}
