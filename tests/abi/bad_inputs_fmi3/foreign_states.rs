//! Foreign FMU states: bytes of another model or interface, and handles of another
//! instance, of either standard.

use super::*;

/// The serialized state of a stepped FMI 2.0 instance of `model`.
fn fmi2_bytes(model: &'static ModelInfo) -> Vec<u8> {
    Subject::<Fmi2>::state_bytes_of(model)
}

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "state bytes of another model",
        SD,
        Stepping,
        |s| s.deserialize(&Subject::<Fmi3>::state_bytes_of(SR)).0,
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state belongs to another model or interface (GUID"),
        Usable,
    ),
    case(
        "two-axis interpolator state bytes into the five-axis one",
        P5,
        Initialization,
        |s| s.deserialize(&Subject::<Fmi3>::state_bytes_of(P2)).0,
        ERROR3,
        Some("the FMU state belongs to another model or interface"),
        Usable,
    ),
    case(
        "state bytes of the SI interface into the mm one",
        XY,
        Stepping,
        |s| {
            let si = models::interface(XY, UnitSystem::Si);
            let other = Instance3::new(si);
            other.start();
            s.deserialize(&other.serialize()).0
        },
        ERROR3,
        Some("the FMU state belongs to another model or interface (GUID…not this XYServoPlant"),
        Usable,
    ),
    case(
        "another model's state under this model's GUID",
        C5,
        Stepping,
        |s| {
            let (format, mut envelope) = open_state(&Subject::<Fmi3>::state_bytes_of(PROBE));
            envelope.guid = C5.guid();
            s.deserialize(&seal_state(format, &envelope)).0
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state does not fit this model's variables"),
        Usable,
    ),
    case(
        "an FMU state handle of another FMI 3.0 instance",
        XY,
        Stepping,
        |s| {
            let other = Subject::<Fmi3>::create(XY, Instantiated, Resources::Null, "other");
            Fmi3::set_state(s.c(), other.saved)
        },
        ERROR3,
        Some("fmi3SetFMUState: FMUState 0x…belongs to instance 'other', not to this one"),
        Usable,
    ),
    case(
        "an FMU state handle of an FMI 2.0 instance of the model",
        C2,
        Stepping,
        |s| {
            let other = Subject::<Fmi2>::create(C2, Stepping, Resources::Null, "fmi2");
            Fmi3::set_state(s.c(), other.saved)
        },
        ERROR3,
        Some("fmi3SetFMUState: FMUState 0x…belongs to instance 'fmi2', not to this one"),
        Usable,
    ),
    case(
        "fmi3FreeFMUState of another instance's state",
        P2,
        Stepping,
        |s| {
            let mut other = Subject::<Fmi3>::create(P2, Instantiated, Resources::Null, "owner");
            Fmi3::free_state(s.c(), &mut other.saved)
        },
        ERROR3,
        Some("fmi3FreeFMUState: FMUState 0x…belongs to instance 'owner', not to this one"),
        Usable,
    ),
    case(
        "fmi3SerializeFMUState of another instance's state",
        F5,
        Stepping,
        |s| {
            let other = Subject::<Fmi3>::create(F5, Instantiated, Resources::Null, "owner");
            Fmi3::serialize(s.c(), other.saved, &mut [0; 4096])
        },
        ERROR3,
        Some("fmi3SerializeFMUState: FMUState 0x…belongs to instance 'owner', not to this one"),
        Usable,
    ),
    case(
        "state bytes of another FMI 3.0 instance of the model (accepted)",
        C2,
        Stepping,
        |s| {
            // The other instance ran the same steps: restoring its state changes nothing.
            let mut other = Subject::<Fmi3>::create(C2, Stepping, Resources::Null, "other");
            let (status, state) = s.deserialize(&other.saved_bytes());
            s.ok(status);
            other.free();
            Fmi3::set_state(s.c(), state)
        },
        OK3,
        None,
        Usable,
    ),
    case(
        "state bytes of an FMI 2.0 instance of the model (accepted: one GUID in both)",
        P5,
        Stepping,
        |s| {
            let (status, state) = s.deserialize(&fmi2_bytes(P5));
            s.ok(status);
            Fmi3::set_state(s.c(), state)
        },
        OK3,
        None,
        Usable,
    ),
];

/// An FMI 3.0 instance's states given to an FMI 2.0 instance.
pub(super) static ON_FMI2_INSTANCES: &[Case] = &[
    case(
        "an FMU state handle of an FMI 3.0 instance given to fmi2SetFMUstate",
        XY,
        Stepping,
        |s| {
            let other = Subject::<Fmi3>::create(XY, Stepping, Resources::Null, "fmi3");
            Fmi2::set_state(s.c(), other.saved)
        },
        ERROR3,
        Some("fmi2SetFMUstate: FMUstate 0x…belongs to instance 'fmi3', not to this one"),
        Usable,
    ),
    case(
        "state bytes of another model's FMI 3.0 instance into an FMI 2.0 one",
        SR,
        Stepping,
        |s| s.deserialize(&Subject::<Fmi3>::state_bytes_of(SD)).0,
        ERROR3,
        Some("fmi2DeSerializeFMUstate: the FMU state belongs to another model or interface"),
        Usable,
    ),
];
