//! Corrupt FMU state bytes through fmi3DeserializeFMUState, and FMU state handles that are
//! freed or made up.

use super::*;
use contour_fmu::framework::variables::Value as V;

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "state bytes truncated by one byte",
        C5,
        Stepping,
        |s| {
            let bytes = s.saved_bytes();
            s.deserialize(&bytes[..bytes.len() - 1]).0
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state is corrupt (checksum mismatch)"),
        Usable,
    ),
    case(
        "state bytes truncated inside the header",
        XY,
        Stepping,
        |s| s.deserialize(&s.saved_bytes()[..7]).0,
        ERROR3,
        Some("fmi3DeserializeFMUState: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "no state bytes at all",
        SD,
        Instantiated,
        |s| s.deserialize(&[]).0,
        ERROR3,
        Some("fmi3DeserializeFMUState: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "a flipped bit in the last byte (the checksum)",
        P2,
        Stepping,
        |s| {
            let mut bytes = s.saved_bytes();
            *bytes.last_mut().unwrap() ^= 1;
            s.deserialize(&bytes).0
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state is corrupt (checksum mismatch)"),
        Usable,
    ),
    case(
        "state bytes with a wrong magic",
        F5,
        Stepping,
        |s| {
            let mut bytes = s.saved_bytes();
            bytes[7] = b'?';
            s.deserialize(&bytes).0
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the bytes are not an FMU state of this library"),
        Usable,
    ),
    case(
        "state bytes of an old format version",
        P5,
        Stepping,
        |s| {
            let (_, envelope) = open_state(&s.saved_bytes());
            s.deserialize(&seal_state(STATE_FORMAT - 1, &envelope)).0
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: FMU state format version 1 is not supported (this library reads 2)"),
        Usable,
    ),
    case(
        "a model state of a future layout version",
        C2,
        Stepping,
        |s| s.resealed(|e| e.model[..2].copy_from_slice(&u16::MAX.to_le_bytes())),
        ERROR3,
        Some("the ContourCCC2D state has internal layout version 65535"),
        Usable,
    ),
    case(
        "-Inf inside checksummed state bytes",
        F5,
        Initialization,
        |s| {
            let vr = s.vr("u.C") as usize;
            s.resealed(|e| e.values.set(vr, V::Real(f64::NEG_INFINITY)))
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state is invalid: variable 'u.C' refuses the non-finite value -inf"),
        Usable,
    ),
    case(
        "an enumeration out of range inside checksummed state bytes",
        C2,
        Stepping,
        |s| {
            let vr = s.vr("estimator") as usize;
            s.resealed(|e| e.values.set(vr, V::Integer(9)))
        },
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state is invalid: variable 'estimator' = 9 is not a value of its enumeration"),
        Usable,
    ),
    case(
        "a state saved after a fatal error",
        PROBE,
        Stepping,
        |s| s.resealed(|e| e.mode = 6),
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state was saved after a fatal error"),
        Usable,
    ),
    case(
        "a state with a NaN stop time",
        SR,
        Stepping,
        |s| s.resealed(|e| e.stop_time = Some(f64::NAN)),
        ERROR3,
        Some("fmi3DeserializeFMUState: the FMU state is invalid: time 0.003 / stop time Some(NaN) not finite"),
        Usable,
    ),
    case(
        "text instead of state bytes",
        PROBE,
        Initialization,
        |s| s.deserialize(b"CCCFMUst, and then some text").0,
        ERROR3,
        Some("fmi3DeserializeFMUState:"),
        Usable,
    ),
    case(
        "a serialization buffer one byte too small",
        XY,
        Stepping,
        |s| {
            let mut small = vec![0u8; s.saved_bytes().len() - 1];
            Fmi3::serialize(s.c(), s.saved, &mut small)
        },
        ERROR3,
        Some("fmi3SerializeFMUState: buffer of"),
        Usable,
    ),
    case(
        "fmi3SetFMUState with a freed state",
        P5,
        Stepping,
        |s| Fmi3::set_state(s.c(), s.freed_state()),
        ERROR3,
        Some("fmi3SetFMUState: FMUState 0x…is not a live FMU state of this instance"),
        Usable,
    ),
    case(
        "fmi3FreeFMUState of a variable holding a freed state",
        C5,
        Stepping,
        |s| Fmi3::free_state(s.c(), &mut s.freed_state()),
        ERROR3,
        Some("fmi3FreeFMUState: FMUState 0x…is not a live FMU state of this instance"),
        Usable,
    ),
    case(
        "fmi3FreeFMUState with a freed state instead of its address",
        F5,
        Stepping,
        |s| unsafe { lib3().fmi3FreeFMUState(s.c(), s.freed_state() as *mut fmi3FMUState) },
        ERROR3,
        Some("fmi3FreeFMUState: FMUState 0x…is not a live FMU state of this instance"),
        Usable,
    ),
    case(
        "fmi3SerializedFMUStateSize of a freed state",
        SD,
        Stepping,
        |s| Fmi3::state_size(s.c(), s.freed_state(), &mut 0),
        ERROR3,
        Some("fmi3SerializedFMUStateSize: FMUState 0x…is not a live FMU state of this instance"),
        Usable,
    ),
    case(
        "fmi3SetFMUState with a made-up pointer",
        C2,
        Stepping,
        |s| {
            let mut block = [0u64; 8];
            Fmi3::set_state(s.c(), block.as_mut_ptr() as fmi3FMUState)
        },
        ERROR3,
        Some("fmi3SetFMUState: FMUState 0x"),
        Usable,
    ),
    case(
        "fmi3GetFMUState into a variable holding a made-up state",
        P2,
        Stepping,
        |s| {
            let mut block = [0u64; 8];
            let mut state = block.as_mut_ptr() as fmi3FMUState;
            Fmi3::get_state(s.c(), &mut state)
        },
        ERROR3,
        Some("fmi3GetFMUState: FMUState 0x…is not a live FMU state of this instance"),
        Usable,
    ),
];
