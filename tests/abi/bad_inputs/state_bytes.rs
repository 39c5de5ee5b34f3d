//! Corrupt FMU state bytes.

use super::*;

pub(super) static CASES: &[Case] = &[
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
];
