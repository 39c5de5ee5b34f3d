//! NULL arrays with a non-zero length, nValues that is not nValueReferences (every variable
//! here is a scalar), NULL strings and categories, NULL out-pointers of the FMU-state
//! functions and of fmi3DoStep.

use super::*;

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "fmi3GetFloat64 with a NULL valueReferences array",
        C2,
        Stepping,
        |s| s.get_for_null(Fmi3Binding::fmi3GetFloat64, 2),
        ERROR3,
        Some("fmi3GetFloat64: valueReferences is NULL but its length is 2"),
        Usable,
    ),
    case(
        "fmi3GetFloat64 with a NULL values array",
        F5,
        Stepping,
        |s| s.get_into_null(Fmi3Binding::fmi3GetFloat64, "pos.X"),
        ERROR3,
        Some("fmi3GetFloat64: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetFloat64 with a NULL values array",
        XY,
        Initialization,
        |s| s.set_from_null(Fmi3Binding::fmi3SetFloat64, "x.J"),
        ERROR3,
        Some("fmi3SetFloat64: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetFloat64 of an input with a NULL values array while stepping",
        SD,
        Stepping,
        |s| s.set_from_null(Fmi3Binding::fmi3SetFloat64, "u"),
        ERROR3,
        Some("fmi3SetFloat64: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetInt32 with a NULL valueReferences array",
        C5,
        Initialization,
        |s| unsafe { lib3().fmi3SetInt32(s.c(), std::ptr::null(), 1, &8, 1) },
        ERROR3,
        Some("fmi3SetInt32: valueReferences is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3GetInt32 with a NULL values array",
        PROBE,
        Stepping,
        |s| s.get_into_null(Fmi3Binding::fmi3GetInt32, "steps"),
        ERROR3,
        Some("fmi3GetInt32: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetInt64 with a NULL values array",
        C2,
        Initialization,
        |s| s.set_from_null(Fmi3Binding::fmi3SetInt64, "estimator"),
        ERROR3,
        Some("fmi3SetInt64: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3GetInt64 with a NULL valueReferences array",
        P2,
        Stepping,
        |s| s.get_for_null(Fmi3Binding::fmi3GetInt64, 1),
        ERROR3,
        Some("fmi3GetInt64: valueReferences is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetBoolean with a NULL values array",
        PROBE,
        Stepping,
        |s| s.set_from_null(Fmi3Binding::fmi3SetBoolean, "fail"),
        ERROR3,
        Some("fmi3SetBoolean: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3GetBoolean with a NULL values array",
        P5,
        Stepping,
        |s| s.get_into_null(Fmi3Binding::fmi3GetBoolean, "done"),
        ERROR3,
        Some("fmi3GetBoolean: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3SetString with a NULL string",
        P2,
        Initialization,
        |s| {
            let (vr, v) = (s.vr("path"), std::ptr::null());
            unsafe { lib3().fmi3SetString(s.c(), &vr, 1, &v, 1) }
        },
        ERROR3,
        Some("fmi3SetString: a string value is NULL or not UTF-8"),
        Usable,
    ),
    case(
        "fmi3SetString with a string that is not UTF-8",
        PROBE,
        Stepping,
        |s| {
            let (vr, bytes) = (s.vr("note"), b"caf\xe9\0");
            let v = bytes.as_ptr() as fmi3String;
            unsafe { lib3().fmi3SetString(s.c(), &vr, 1, &v, 1) }
        },
        ERROR3,
        Some("fmi3SetString: a string value is NULL or not UTF-8"),
        Usable,
    ),
    case(
        "fmi3GetString with a NULL values array",
        P5,
        Stepping,
        |s| s.get_into_null(Fmi3Binding::fmi3GetString, "path"),
        ERROR3,
        Some("fmi3GetString: values is NULL but its length is 1"),
        Usable,
    ),
    case(
        "fmi3GetUInt16 with a NULL valueReferences array",
        F5,
        Stepping,
        |s| s.get_for_null(Fmi3Binding::fmi3GetUInt16, 3),
        ERROR3,
        Some("fmi3GetUInt16: valueReferences is NULL but its length is 3"),
        Usable,
    ),
    case(
        "fmi3GetFloat64 of nothing, with NULL arrays (accepted)",
        XY,
        Stepping,
        |s| unsafe { lib3().fmi3GetFloat64(s.c(), std::ptr::null(), 0, std::ptr::null_mut(), 0) },
        OK3,
        None,
        Usable,
    ),
    case(
        "fmi3SetDebugLogging with a NULL categories array",
        C2,
        Initialization,
        |s| unsafe { lib3().fmi3SetDebugLogging(s.c(), true, 2, std::ptr::null()) },
        ERROR3,
        Some("fmi3SetDebugLogging: categories is NULL but its length is 2"),
        Usable,
    ),
    case(
        "fmi3SetDebugLogging with a NULL category",
        SR,
        Stepping,
        |s| {
            let categories = [c"logEvents".as_ptr(), std::ptr::null()];
            unsafe { lib3().fmi3SetDebugLogging(s.c(), true, 2, categories.as_ptr()) }
        },
        ERROR3,
        Some("fmi3SetDebugLogging: a category is NULL or not UTF-8"),
        Usable,
    ),
    case(
        "fmi3SetDebugLogging with an unknown category",
        XY,
        Stepping,
        |s| s.set_debug_logging(true, &["logStatusWarning", "logEverything"]),
        ERROR3,
        Some("fmi3SetDebugLogging: unknown log category 'logEverything'"),
        Usable,
    ),
    // nValues beside nValueReferences.
    case(
        "fmi3SetFloat64 with two values for one reference",
        C2,
        Stepping,
        |s| s.set_float64(&[s.vr("ref.x")], &[1.0, 2.0]),
        ERROR3,
        Some("fmi3SetFloat64: nValues = 2 but nValueReferences = 1: every variable of these FMUs is a scalar, one value per reference"),
        Usable,
    ),
    case(
        "fmi3SetFloat64 with no value for one reference",
        XY,
        Initialization,
        |s| s.set_float64(&[s.vr("x.J")], &[]),
        ERROR3,
        Some("fmi3SetFloat64: nValues = 0 but nValueReferences = 1"),
        Usable,
    ),
    case(
        "fmi3GetFloat64 with one value for two references",
        F5,
        Stepping,
        |s| {
            let (vrs, mut out) = (s.vrs(&["pos.X", "pos.Y"]), 0.0);
            unsafe { lib3().fmi3GetFloat64(s.c(), vrs.as_ptr(), 2, &mut out, 1) }
        },
        ERROR3,
        Some("fmi3GetFloat64: nValues = 1 but nValueReferences = 2"),
        Usable,
    ),
    case(
        "fmi3SetInt32 with two values for one reference",
        C5,
        Initialization,
        |s| s.set_as(Fmi3Binding::fmi3SetInt32, &[s.vr("hmm.lag")], &[8, 9]),
        ERROR3,
        Some("fmi3SetInt32: nValues = 2 but nValueReferences = 1"),
        Usable,
    ),
    case(
        "fmi3GetInt64 with two values for one reference",
        C2,
        Stepping,
        |s| {
            let (vr, mut out) = (s.vr("estimator"), [0i64; 2]);
            unsafe { lib3().fmi3GetInt64(s.c(), &vr, 1, out.as_mut_ptr(), 2) }
        },
        ERROR3,
        Some("fmi3GetInt64: nValues = 2 but nValueReferences = 1"),
        Usable,
    ),
    case(
        "fmi3SetBoolean with one value for two references",
        PROBE,
        Stepping,
        |s| {
            let vrs = s.vrs(&["fail", "panic"]);
            unsafe { lib3().fmi3SetBoolean(s.c(), vrs.as_ptr(), 2, &true, 1) }
        },
        ERROR3,
        Some("fmi3SetBoolean: nValues = 1 but nValueReferences = 2"),
        Usable,
    ),
    case(
        "fmi3GetString with two values for one reference",
        P2,
        Initialization,
        |s| {
            let (vr, mut out) = (s.vr("path"), [std::ptr::null(); 2]);
            unsafe { lib3().fmi3GetString(s.c(), &vr, 1, out.as_mut_ptr(), 2) }
        },
        ERROR3,
        Some("fmi3GetString: nValues = 2 but nValueReferences = 1"),
        Usable,
    ),
    case(
        "fmi3SetString with no value for one reference",
        P5,
        Initialization,
        |s| {
            let vr = s.vr("path");
            unsafe { lib3().fmi3SetString(s.c(), &vr, 1, std::ptr::null(), 0) }
        },
        ERROR3,
        Some("fmi3SetString: nValues = 0 but nValueReferences = 1"),
        Usable,
    ),
    // The FMU-state functions' pointers.
    case(
        "fmi3GetFMUState with a NULL FMUState*",
        XY,
        Stepping,
        |s| unsafe { lib3().fmi3GetFMUState(s.c(), std::ptr::null_mut()) },
        ERROR3,
        Some("fmi3GetFMUState: FMUState (the address of the variable) is NULL"),
        Usable,
    ),
    case(
        "fmi3SetFMUState with a NULL state",
        C2,
        Stepping,
        |s| unsafe { lib3().fmi3SetFMUState(s.c(), std::ptr::null_mut()) },
        ERROR3,
        Some("fmi3SetFMUState: FMUState is NULL"),
        Usable,
    ),
    case(
        "fmi3FreeFMUState with NULL (ignored)",
        P2,
        Stepping,
        |s| unsafe { lib3().fmi3FreeFMUState(s.c(), std::ptr::null_mut()) },
        OK3,
        None,
        Usable,
    ),
    case(
        "fmi3FreeFMUState with the state instead of its address",
        F5,
        Stepping,
        |s| {
            let mut state = std::ptr::null_mut();
            s.ok(Fmi3::get_state(s.c(), &mut state));
            unsafe { lib3().fmi3FreeFMUState(s.c(), state as *mut fmi3FMUState) }
        },
        OK3,
        Some("fmi3FreeFMUState: the argument is the FMU state"),
        Usable,
    ),
    case(
        "fmi3SerializedFMUStateSize with a NULL size",
        C5,
        Stepping,
        |s| unsafe { lib3().fmi3SerializedFMUStateSize(s.c(), s.saved, std::ptr::null_mut()) },
        ERROR3,
        Some("fmi3SerializedFMUStateSize: size is NULL"),
        Usable,
    ),
    case(
        "fmi3SerializeFMUState into a NULL buffer",
        P5,
        Stepping,
        |s| {
            let size = s.saved_bytes().len();
            unsafe { lib3().fmi3SerializeFMUState(s.c(), s.saved, std::ptr::null_mut(), size) }
        },
        ERROR3,
        Some("fmi3SerializeFMUState: serializedState is NULL but its length is"),
        Usable,
    ),
    case(
        "fmi3DeserializeFMUState from NULL bytes",
        XY,
        Stepping,
        |s| {
            let mut state = std::ptr::null_mut();
            unsafe { lib3().fmi3DeserializeFMUState(s.c(), std::ptr::null(), 100, &mut state) }
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: serializedState is NULL but its length is 100"),
        Usable,
    ),
    case(
        "fmi3DeserializeFMUState into a NULL FMUState*",
        C2,
        Stepping,
        |s| {
            let bytes = s.saved_bytes();
            let (p, n) = (bytes.as_ptr(), bytes.len());
            unsafe { lib3().fmi3DeserializeFMUState(s.c(), p, n, std::ptr::null_mut()) }
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: FMUState (the address of the variable) is NULL"),
        Usable,
    ),
    // fmi3DoStep's four results: refused before the step when any is NULL.
    case(
        "fmi3DoStep with a NULL eventHandlingNeeded",
        XY,
        Stepping,
        |s| s.step_with_null(0),
        ERROR3,
        Some("fmi3DoStep: eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime is NULL"),
        Usable,
    ),
    case(
        "fmi3DoStep with a NULL terminateSimulation",
        C5,
        Stepping,
        |s| s.step_with_null(1),
        ERROR3,
        Some("fmi3DoStep: eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime is NULL"),
        Usable,
    ),
    case(
        "fmi3DoStep with a NULL earlyReturn",
        P5,
        Stepping,
        |s| s.step_with_null(2),
        ERROR3,
        Some("fmi3DoStep: eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime is NULL"),
        Usable,
    ),
    case(
        "fmi3DoStep with a NULL lastSuccessfulTime",
        SD,
        Stepping,
        |s| s.step_with_null(3),
        ERROR3,
        Some("fmi3DoStep: eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime is NULL"),
        Usable,
    ),
];
