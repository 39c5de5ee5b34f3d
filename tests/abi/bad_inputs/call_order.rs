//! Every instance function in a mode where FMI 2.0 (§4.3.3) does not allow it, and what is allowed but not provided.

use super::*;

pub(super) static CASES: &[Case] = &[
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
];
