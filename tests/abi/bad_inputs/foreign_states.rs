//! Foreign FMU states.

use super::*;

pub(super) static CASES: &[Case] = &[
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
];
