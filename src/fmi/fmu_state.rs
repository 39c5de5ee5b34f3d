//! FMU states on the FMI side, all of it: the snapshot (what an `fmi2FMUstate` holds), the
//! handles the importer gets for them, and their ownership and lifetime. The model's part
//! of a snapshot is the model's business (`crate::framework::saved_state`).
//!
//! A snapshot is a versioned, checksummed byte blob (never a memory copy), so a
//! serialized state can be stored, sent elsewhere and checked when it comes back.
//! Layout: `MAGIC` (8 bytes) · format version (u16 LE) · postcard payload · CRC-32 of
//! everything before it (u32 LE). The payload's model part starts with the model's own
//! state layout version (`crate::framework::saved_state::StateLayout`), checked by the
//! model. Format versions: 1 had model bytes without a layout version; 2 adds it.
//!
//! Every instance owns its FMU states ([`States`]): they are made, overwritten and freed
//! only through it, and die with it. An `fmi2FMUstate` is a handle of the slab's form
//! (slab.rs: the top bit set, so never a user-space address) with the kind bit set as
//! well (so it is never an instance handle) and a number from a counter that never
//! repeats (2^62 of them: a process cannot exhaust them). Handles are only ever used as
//! keys, never dereferenced: a freed, foreign or made-up handle is an error, not a read.
//! [`OWNERS`] knows every live state of the process with its instance, for the message
//! about a state passed to another instance than the one that made it.
//!
//! Lock order: an instance's slot may be held while [`OWNERS`] is locked (to add or remove
//! its FMU states), never the other way round; no code holds two slots at once (a message
//! about another instance's FMU state takes that instance's name from [`OWNERS`]).

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use serde::{Deserialize, Serialize};

use super::slab::{HANDLE_TAG, KIND_BIT};
use super::state_machine::Mode;
use super::status::{Failure, Outcome};
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
    #[serde(with = "crate::framework::saved_state::bytes")]
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

// ---------------------------------------------------------------------------------------
// The FMU states of an instance, and their owners

/// The instance an FMU state belongs to.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Owner {
    /// The instance's handle (its `fmi2Component`).
    instance: usize,
    /// For messages about the state in another instance.
    name: String,
}

/// Every live FMU state of the process, by handle, with its owner.
static OWNERS: Mutex<BTreeMap<usize, Owner>> = Mutex::new(BTreeMap::new());

// Nothing panics while holding the lock, but should it ever, the map is still consistent
// (each operation is a single insert or remove): keep using it.
fn owners() -> MutexGuard<'static, BTreeMap<usize, Owner>> {
    OWNERS.lock().unwrap_or_else(PoisonError::into_inner)
}

static NEXT_STATE: AtomicUsize = AtomicUsize::new(1);

/// A handle for a new FMU state, never handed out before.
fn new_handle() -> usize {
    HANDLE_TAG | KIND_BIT | NEXT_STATE.fetch_add(1, Ordering::Relaxed)
}

/// The live FMU states of one instance, by handle: their snapshots' bytes (so
/// serializing is a copy and every restore checks them). [`OWNERS`] knows them too.
pub struct States {
    /// The instance, the owner of every state here.
    owner: Owner,
    snapshots: BTreeMap<usize, Vec<u8>>,
    /// The FMU state argument's name in the instance's standard, for messages.
    argument: &'static str,
}

impl Drop for States {
    /// The FMU states die with their instance: unregister them, also one created by a
    /// call that was still running when another thread freed the instance.
    fn drop(&mut self) {
        let mut owners = owners();
        for handle in self.snapshots.keys() {
            owners.remove(handle);
        }
    }
}

impl States {
    /// No states yet, of the instance named `name` (its handle comes at registration).
    /// The states of the instance `name`; `argument` is how its standard's header names an
    /// FMU state argument in messages ("FMUstate" in FMI 2.0, "FMUState" in FMI 3.0).
    pub fn new(name: &str, argument: &'static str) -> Self {
        States {
            owner: Owner {
                instance: 0,
                name: name.to_owned(),
            },
            snapshots: BTreeMap::new(),
            argument,
        }
    }

    /// The instance now has `handle`, before it makes any state.
    pub fn registered_as(&mut self, handle: usize) {
        self.owner.instance = handle;
    }

    /// Whether `handle` is a live FMU state of this instance.
    pub fn contains(&self, handle: usize) -> bool {
        self.snapshots.contains_key(&handle)
    }

    /// Why `handle` is not usable as an FMU state of this instance.
    pub fn unknown(&self, handle: usize) -> Failure {
        if handle == 0 {
            return Failure::error(format!("{} is NULL", self.argument));
        }
        let owner = owners().get(&handle).cloned();
        match owner {
            Some(owner) if owner.instance != self.owner.instance => Failure::error(format!(
                "{} {handle:#x} belongs to instance '{}', not to this one: an FMU state \
                 can only be used with the instance that made it (serialize it and \
                 deserialize it here to move it)",
                self.argument, owner.name
            )),
            _ => Failure::error(format!(
                "{} {handle:#x} is not a live FMU state of this instance (already \
                 freed, or not an FMU state)",
                self.argument
            )),
        }
    }

    /// The snapshot's bytes of one of this instance's FMU states.
    pub fn bytes(&self, handle: usize) -> Outcome<&[u8]> {
        self.snapshots
            .get(&handle)
            .map(Vec::as_slice)
            .ok_or_else(|| self.unknown(handle))
    }

    /// Stores a new FMU state; returns its handle.
    pub fn add(&mut self, bytes: Vec<u8>) -> usize {
        let handle = new_handle();
        self.snapshots.insert(handle, bytes);
        owners().insert(handle, self.owner.clone());
        handle
    }

    /// Replaces the bytes of one of this instance's FMU states.
    pub fn overwrite(&mut self, handle: usize, bytes: Vec<u8>) -> Outcome {
        match self.snapshots.get_mut(&handle) {
            Some(stored) => {
                *stored = bytes;
                Ok(())
            }
            None => Err(self.unknown(handle)),
        }
    }

    /// Frees one of this instance's FMU states.
    pub fn free(&mut self, handle: usize) -> Outcome {
        if self.snapshots.remove(&handle).is_none() {
            return Err(self.unknown(handle));
        }
        owners().remove(&handle);
        Ok(())
    }
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

    /// A state's handle has the form of a handle (never an address) and is never a slab's
    /// (an instance's).
    #[test]
    fn state_handles_are_never_instance_handles() {
        let slab = crate::fmi::slab::Slab::new();
        let instance = slab.insert(|_| ()).unwrap();
        let state = new_handle();
        assert!(crate::fmi::slab::is_handle(state));
        assert_ne!(state, instance);
        assert!(slab.lock(state).is_none());
        assert!(slab.remove(state).is_none());
        assert_ne!(new_handle(), state);
    }

    /// A state used with another instance is named with its owner; it dies with it.
    #[test]
    fn states_belong_to_their_instance() {
        let mut first = States::new("first", "FMUstate");
        first.registered_as(HANDLE_TAG | 1);
        let mut second = States::new("second", "FMUstate");
        second.registered_as(HANDLE_TAG | 2);
        let state = first.add(vec![1, 2]);
        assert_eq!(first.bytes(state).unwrap(), &[1, 2]);
        assert!(!second.contains(state));
        let message = second.bytes(state).unwrap_err().message;
        assert!(message.contains("belongs to instance 'first'"), "{message}");
        assert!(second.free(state).is_err());
        first.overwrite(state, vec![3]).unwrap();
        assert_eq!(first.bytes(state).unwrap(), &[3]);
        drop(first);
        let message = second.unknown(state).message;
        assert!(message.contains("not a live FMU state"), "{message}");
        assert_eq!(second.unknown(0).message, "FMUstate is NULL");
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
