//! NULL (and dead handles) where an importer can err.

use super::*;

pub(super) static CASES: &[Case] = &[
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
];
