//! FMU state snapshots: a versioned, checksummed byte blob (never a memory copy), so a
//! serialized state can be stored, sent elsewhere and checked when it comes back.
//!
//! Layout: `MAGIC` (8 bytes) · format version (u16 LE) · postcard payload · CRC-32 of
//! everything before it (u32 LE). The payload's model part starts with the model's own
//! state layout version (`crate::framework::state_codec::StateLayout`), checked by the model.
//!
//! Format versions: 1 had model bytes without a layout version; 2 adds it.

use serde::{Deserialize, Serialize};

use super::state_machine::Mode;
use crate::framework::variables::Values;

const MAGIC: &[u8; 8] = b"CCCFMUst";
/// The library that wrote a state, for messages (each model's state layout version, not
/// the library version, decides whether a state can be read).
pub const LIBRARY_VERSION: &str = env!("CARGO_PKG_VERSION");
const FORMAT_VERSION: u16 = 2;
const HEADER: usize = MAGIC.len() + 2;
const TRAILER: usize = 4;

/// Everything needed to put an instance back where it was.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// [`LIBRARY_VERSION`] of the writer (informative).
    pub library: String,
    /// GUID of the model the state belongs to; restoring into another model is refused.
    pub guid: String,
    pub mode: Mode,
    pub time: f64,
    pub stop_time: Option<f64>,
    pub needs_initialize: bool,
    pub values: Values,
    /// The model's own state, from `Model::save_state`.
    pub model: Vec<u8>,
}

pub fn encode(snapshot: &Snapshot) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::with_capacity(256);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    let bytes = postcard::to_extend(snapshot, bytes)
        .map_err(|e| format!("cannot encode the FMU state: {e}"))?;
    let mut bytes = bytes;
    let crc = crc32fast::hash(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    Ok(bytes)
}

pub fn decode(bytes: &[u8]) -> Result<Snapshot, String> {
    if bytes.len() < HEADER + TRAILER || &bytes[..MAGIC.len()] != MAGIC {
        return Err("the bytes are not an FMU state of this library".into());
    }
    let version = u16::from_le_bytes([bytes[8], bytes[9]]);
    if version != FORMAT_VERSION {
        return Err(format!(
            "FMU state format version {version} is not supported (this library reads \
             {FORMAT_VERSION}): the state was saved by {} build of contour-fmu",
            if version < FORMAT_VERSION {
                "an older"
            } else {
                "a newer"
            }
        ));
    }
    let (body, trailer) = bytes.split_at(bytes.len() - TRAILER);
    let stored = u32::from_le_bytes(trailer.try_into().expect("4 bytes"));
    if crc32fast::hash(body) != stored {
        return Err("the FMU state is corrupt (checksum mismatch)".into());
    }
    let (snapshot, rest) = postcard::take_from_bytes::<Snapshot>(&body[HEADER..])
        .map_err(|e| format!("the FMU state is corrupt: {e}"))?;
    if !rest.is_empty() {
        return Err("the FMU state is corrupt: trailing bytes".into());
    }
    Ok(snapshot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::framework::variables::{Value, Values};

    fn sample() -> Snapshot {
        let mut values = Values::from_table(crate::models::xy_servo_plant::INFO.variables);
        values.set(0, Value::Real(1.5));
        Snapshot {
            library: LIBRARY_VERSION.into(),
            guid: "{guid}".into(),
            mode: Mode::StepComplete,
            time: 0.25,
            stop_time: Some(2.0),
            needs_initialize: false,
            values,
            model: vec![1, 2, 3],
        }
    }

    #[test]
    fn round_trip() {
        let s = sample();
        assert_eq!(decode(&encode(&s).unwrap()).unwrap(), s);
    }

    #[test]
    fn every_flipped_byte_and_truncation_is_detected() {
        let bytes = encode(&sample()).unwrap();
        for i in 0..bytes.len() {
            let mut bad = bytes.clone();
            bad[i] ^= 0x5a;
            assert!(decode(&bad).is_err(), "flip at {i}");
        }
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len]).is_err(), "truncated to {len}");
        }
    }
}
