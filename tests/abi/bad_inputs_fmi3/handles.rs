//! Instantiation refused, and NULL, freed, made-up and foreign handles: another library's
//! pointer, an FMU state for an instance, and an instance of the other standard (each
//! standard's functions refuse the other's instances, and tell that instance's importer).

use std::ptr::null;

use super::*;

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "fmi3InstantiateCoSimulation with a NULL instance name",
        XY,
        NoInstance,
        |s| {
            let token = s.token();
            s.instantiate(Instantiation {
                name: None,
                ..Instantiation::new("", token)
            })
        },
        ERROR3,
        Some("fmi3InstantiateCoSimulation: the instance name is NULL or empty"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateCoSimulation with a blank instance name",
        C2,
        NoInstance,
        |s| s.instantiate(Instantiation::new(" \t", s.token())),
        ERROR3,
        Some("fmi3InstantiateCoSimulation: the instance name is NULL or empty"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateCoSimulation with a NULL instantiation token",
        P2,
        NoInstance,
        |s| {
            s.instantiate(Instantiation {
                token: None,
                ..Instantiation::new("a", "")
            })
        },
        ERROR3,
        Some("fmi3InstantiateCoSimulation: the instantiation token is NULL or not UTF-8"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateCoSimulation with an unknown instantiation token",
        F5,
        NoInstance,
        |s| s.instantiate(Instantiation::new("a", "{00000000-0000-0000-0000-000000000000}")),
        ERROR3,
        Some("fmi3InstantiateCoSimulation: unknown instantiation token {00000000-0000-0000-0000-000000000000}: the modelDescription.xml does not match this binary (it serves "),
        NotCreated,
    ),
    case(
        "fmi3InstantiateCoSimulation with the model's FMI 2.0 GUID",
        P5,
        NoInstance,
        |s| {
            let guid = s.model.guid();
            s.instantiate(Instantiation::new("a", &guid))
        },
        ERROR3,
        Some("(it is an FMI 2.0 GUID: the FMI 2.0 modelDescription.xml belongs to fmi2Instantiate)"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateCoSimulation asking for intermediate variables",
        C5,
        NoInstance,
        |s| {
            s.instantiate(Instantiation {
                intermediate: &[0, 1],
                ..Instantiation::new("a", s.token())
            })
        },
        ERROR3,
        Some("fmi3InstantiateCoSimulation: 2 intermediate variables requested: these FMUs have no intermediate update"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateModelExchange (no Model Exchange: NULL, and why)",
        SD,
        NoInstance,
        |s| {
            s.instantiate_other(|name, token, environment, log| unsafe {
                let lib = lib3();
                lib.fmi3InstantiateModelExchange(name, token, null(), false, false, environment, log)
            })
        },
        ERROR3,
        Some("fmi3InstantiateModelExchange: these FMUs are Co-Simulation only (no <ModelExchange>)"),
        NotCreated,
    ),
    case(
        "fmi3InstantiateScheduledExecution (no Scheduled Execution: NULL, and why)",
        SR,
        NoInstance,
        |s| {
            s.instantiate_other(|name, token, environment, log| unsafe {
                let lib = lib3();
                lib.fmi3InstantiateScheduledExecution(
                    name, token, null(), false, false, environment, log, None, None, None,
                )
            })
        },
        ERROR3,
        Some("fmi3InstantiateScheduledExecution: these FMUs are Co-Simulation only (no <ScheduledExecution>)"),
        NotCreated,
    ),
    case(
        "an instance without a log callback (FMI 3.0 allows it): refused calls log nothing",
        C2,
        NoInstance,
        |s| {
            let status = s.instantiate(Instantiation {
                logger: false,
                ..Instantiation::new("silent", s.token())
            });
            s.ok(status);
            s.ok(s.set_debug_logging(true, &["logAll"]));
            s.step(0.0, f64::NAN)
        },
        ERROR3,
        None,
        Usable,
    ),
    case(
        "a NULL fmi3Instance (no instance to log to)",
        XY,
        Stepping,
        |s| step(std::ptr::null_mut(), s.time, H).0,
        ERROR3,
        None,
        Usable,
    ),
    case(
        "a freed fmi3Instance (no instance to log to)",
        C5,
        Stepping,
        |s| {
            s.free();
            s.step(s.time, H)
        },
        ERROR3,
        None,
        Gone,
    ),
    case(
        "a made-up fmi3Instance (another library's pointer)",
        P5,
        Stepping,
        |s| {
            let mut block = [0u64; 16];
            step(block.as_mut_ptr() as fmi3Instance, s.time, H).0
        },
        ERROR3,
        None,
        Usable,
    ),
    case(
        "an FMU state as the fmi3Instance",
        F5,
        Stepping,
        |s| step(s.saved, s.time, H).0,
        ERROR3,
        None,
        Usable,
    ),
    case(
        "fmi3FreeInstance of NULL (ignored)",
        SD,
        Stepping,
        |_| {
            unsafe { lib3().fmi3FreeInstance(std::ptr::null_mut()) };
            OK3
        },
        OK3,
        None,
        Usable,
    ),
    case(
        "fmi3FreeInstance twice (the second ignored)",
        P2,
        Stepping,
        |s| {
            s.free();
            unsafe { lib3().fmi3FreeInstance(s.c()) };
            OK3
        },
        OK3,
        None,
        Gone,
    ),
    // An FMI 3.0 instance given to fmi2 functions: refused, and its importer told through
    // its FMI 3.0 callback.
    case(
        "fmi2DoStep with an FMI 3.0 instance",
        XY,
        Stepping,
        |s| unsafe { crate::common::lib().fmi2DoStep(s.c(), s.time, H, 0) },
        ERROR3,
        Some("fmi2DoStep: called with an instance made by fmi3InstantiateCoSimulation: an FMI 3.0 instance answers only the fmi3 functions"),
        Usable,
    ),
    case(
        "fmi2SetupExperiment with an FMI 3.0 instance",
        P2,
        Instantiated,
        |s| unsafe { crate::common::lib().fmi2SetupExperiment(s.c(), 0, 0.0, 0.0, 0, 0.0) },
        ERROR3,
        Some("fmi2SetupExperiment: called with an instance made by fmi3InstantiateCoSimulation"),
        Usable,
    ),
    case(
        "fmi2SetReal with an FMI 3.0 instance (even a good value)",
        C2,
        Initialization,
        |s| {
            let vr = s.vr("Ts");
            unsafe { crate::common::lib().fmi2SetReal(s.c(), &vr, 1, &0.002) }
        },
        ERROR3,
        Some("fmi2SetReal: called with an instance made by fmi3InstantiateCoSimulation"),
        Usable,
    ),
    case(
        "fmi2GetFMUstate with an FMI 3.0 instance",
        F5,
        Terminated,
        |s| {
            let mut state = std::ptr::null_mut();
            unsafe { crate::common::lib().fmi2GetFMUstate(s.c(), &mut state) }
        },
        ERROR3,
        Some("fmi2GetFMUstate: called with an instance made by fmi3InstantiateCoSimulation"),
        Usable,
    ),
    case(
        "fmi2FreeInstance with an FMI 3.0 instance (which stays)",
        C5,
        Stepping,
        |s| {
            unsafe { crate::common::lib().fmi2FreeInstance(s.c()) };
            ERROR3
        },
        ERROR3,
        Some("fmi2FreeInstance: called with an instance made by fmi3InstantiateCoSimulation"),
        Usable,
    ),
];

/// An FMI 2.0 instance given to fmi3 functions: refused, and its importer told through its
/// FMI 2.0 callback.
pub(super) static ON_FMI2_INSTANCES: &[Case] = &[
    case(
        "fmi2Instantiate with the model's FMI 3.0 instantiation token",
        C5,
        NoInstance,
        |s| {
            let token = Some(token(s.model));
            let co_simulation = crate::common::fmi2Type_fmi2CoSimulation;
            let (c, log, _) = instantiate_raw(Some("a"), co_simulation, token, None, true);
            s.refused = Some(log);
            if c.is_null() {
                ERROR3
            } else {
                unsafe { crate::common::lib().fmi2FreeInstance(c) };
                OK3
            }
        },
        ERROR3,
        Some("fmi2Instantiate: unknown GUID {…}: the modelDescription.xml does not match this binary"),
        NotCreated,
    ),
    case(
        "fmi3DoStep with an FMI 2.0 instance",
        XY,
        Stepping,
        |s| step(s.c(), s.time, H).0,
        ERROR3,
        Some("fmi3DoStep: called with an instance made by fmi2Instantiate: an FMI 2.0 instance answers only the fmi2 functions"),
        Usable,
    ),
    case(
        "fmi3EnterInitializationMode with an FMI 2.0 instance",
        P5,
        Instantiated,
        |s| unsafe { lib3().fmi3EnterInitializationMode(s.c(), false, 0.0, 0.0, false, 0.0) },
        ERROR3,
        Some("fmi3EnterInitializationMode: called with an instance made by fmi2Instantiate"),
        Usable,
    ),
    case(
        "fmi3SetFloat64 with an FMI 2.0 instance (even NaN: refused first as foreign)",
        C2,
        Initialization,
        |s| {
            let vr = s.vr("Ts");
            unsafe { lib3().fmi3SetFloat64(s.c(), &vr, 1, &f64::NAN, 1) }
        },
        ERROR3,
        Some("fmi3SetFloat64: called with an instance made by fmi2Instantiate"),
        Usable,
    ),
    case(
        "fmi3GetBoolean with an FMI 2.0 instance",
        P2,
        Terminated,
        |s| {
            let (vr, mut value) = (s.vr("done"), false);
            unsafe { lib3().fmi3GetBoolean(s.c(), &vr, 1, &mut value, 1) }
        },
        ERROR3,
        Some("fmi3GetBoolean: called with an instance made by fmi2Instantiate"),
        Usable,
    ),
    case(
        "fmi3EnterEventMode with an FMI 2.0 instance",
        F5,
        Stepping,
        |s| unsafe { lib3().fmi3EnterEventMode(s.c()) },
        ERROR3,
        Some("fmi3EnterEventMode: called with an instance made by fmi2Instantiate"),
        Usable,
    ),
    case(
        "fmi3FreeInstance with an FMI 2.0 instance (which stays)",
        SD,
        Stepping,
        |s| {
            unsafe { lib3().fmi3FreeInstance(s.c()) };
            ERROR3
        },
        ERROR3,
        Some("fmi3FreeInstance: called with an instance made by fmi2Instantiate"),
        Usable,
    ),
];
