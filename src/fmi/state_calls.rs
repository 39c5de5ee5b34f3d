//! The FMU-state functions' bodies, the same in both standards (`fmi2FMUstate` and
//! `fmi3FMUState` are both `void*`): get, free, serialize and deserialize, with every
//! pointer the importer passes checked before it is followed.

use std::ffi::c_void;
use std::ptr;

use super::c_args::{slice, slice_mut};
use super::instance::Instance;
use super::slab::is_handle;
use super::standard::Standard;
use super::status::{Failure, Outcome};

/// An FMU state as the C ABI passes it: one of our handles, never an address.
pub type FmuStatePointer = *mut c_void;

/// The variable behind an `FMUState*` argument. The argument must be the address of the
/// importer's variable; if it is one of our FMU state handles instead (see [`free`]), it is
/// no address at all, so it is refused before it is dereferenced.
///
/// # Safety
/// `slot` is NULL, one of our handles, or points to a writable `FmuStatePointer`.
unsafe fn state_slot<'a>(
    slot: *mut FmuStatePointer,
    standard: Standard,
) -> Outcome<&'a mut FmuStatePointer> {
    let name = standard.fmu_state_argument();
    if is_handle(slot as usize) {
        // Live or freed, a handle of ours is not an address (see slab.rs).
        return Err(Failure::error(format!(
            "the {name}* argument is an FMU state, not the address of a variable holding one"
        )));
    }
    slot.as_mut()
        .ok_or_else(|| Failure::error(format!("{name} (the address of the variable) is NULL")))
}

/// `GetFMUState`: a new state, or an earlier one of this instance overwritten.
///
/// # Safety
/// `state` points to a variable holding NULL or a state this instance returned earlier.
pub unsafe fn get(instance: &mut Instance, state: *mut FmuStatePointer) -> Outcome {
    let slot = state_slot(state, instance.standard)?;
    let existing = *slot as usize;
    // Both standards: a non-NULL *FMUstate is an earlier state to be overwritten.
    if existing != 0 && !instance.states.contains(existing) {
        return Err(instance.states.unknown(existing));
    }
    let bytes = instance.snapshot()?;
    if existing == 0 {
        *slot = instance.states.add(bytes) as FmuStatePointer;
    } else {
        instance.states.overwrite(existing, bytes)?;
    }
    Ok(())
}

/// `FreeFMUState`.
///
/// # Safety
/// `state` is NULL, points to a variable holding NULL or a state of this instance, or (the
/// importer bug handled below) is a state of this instance itself.
pub unsafe fn free(instance: &mut Instance, state: *mut FmuStatePointer) -> Outcome {
    let handle = state as usize;
    // fmusim 0.0.39 calls fmi2FreeFMUstate(c, FMUState): the state instead of the address
    // of the variable holding it. Dereferencing it (as the standard signature asks) would
    // read our own state object as a pointer and then free whatever that points to: the
    // SIGSEGV this used to be. Handles are never user-space addresses (slab.rs), so the
    // misuse is recognised exactly, also with a freed state. We free the state and answer
    // OK (with a warning in the log):
    // - memory stays safe either way: the importer's variable keeps the stale value, but
    //   every later use of it is looked up here first and refused, never read;
    // - refusing would leak the state until the instance is freed and, worse, end
    //   fmusim's run (it aborts on any status above OK), although the intent is clear.
    if instance.states.contains(handle) {
        instance.states.free(handle)?;
        instance.log_warning(&format!(
            "{}: the argument is the FMU state {handle:#x} itself, not the address of a \
             variable holding it (an importer bug); the state was freed, the importer's \
             variable could not be set to NULL",
            super::state_machine::Call::FreeFmuState.name(instance.standard)
        ));
        return Ok(());
    }
    if is_handle(handle) {
        // The same misuse with another instance's state or a freed one: refused, and never
        // dereferenced (a handle is not an address).
        return Err(instance.states.unknown(handle));
    }
    // A NULL pointer (or a variable holding NULL) is ignored.
    let Some(slot) = state.as_mut() else {
        return Ok(());
    };
    if slot.is_null() {
        return Ok(());
    }
    instance.states.free(*slot as usize)?;
    *slot = ptr::null_mut();
    Ok(())
}

/// `SerializedFMUStateSize`.
///
/// # Safety
/// `state` as returned by this instance (only looked up); `size` NULL or writable.
pub unsafe fn serialized_size(
    instance: &mut Instance,
    state: FmuStatePointer,
    size: *mut usize,
) -> Outcome {
    let bytes = instance.states.bytes(state as usize)?;
    *size
        .as_mut()
        .ok_or_else(|| Failure::error("size is NULL"))? = bytes.len();
    Ok(())
}

/// `SerializeFMUState`.
///
/// # Safety
/// `state` as returned by this instance (only looked up); `serialized` has room for `size`
/// bytes.
pub unsafe fn serialize(
    instance: &mut Instance,
    state: FmuStatePointer,
    serialized: *mut u8,
    size: usize,
) -> Outcome {
    let bytes = instance.states.bytes(state as usize)?;
    if size < bytes.len() {
        return Err(Failure::error(format!(
            "buffer of {size} bytes is too small for the state's {} bytes",
            bytes.len()
        )));
    }
    let out = slice_mut(serialized, bytes.len(), "serializedState")?;
    out.copy_from_slice(bytes);
    Ok(())
}

/// `DeserializeFMUState`: the bytes checked as a restore would check them, then kept as a
/// state of this instance.
///
/// # Safety
/// `serialized` holds `size` readable bytes; `state` points to a writable variable.
pub unsafe fn deserialize(
    instance: &mut Instance,
    serialized: *const u8,
    size: usize,
    state: *mut FmuStatePointer,
) -> Outcome {
    let slot = state_slot(state, instance.standard)?;
    let bytes = slice(serialized, size, "serializedState")?;
    instance.check_snapshot(bytes)?;
    let existing = *slot as usize;
    // A state of this instance is reused; anything else in the variable (NULL, or whatever
    // an importer left there) is replaced by a new state, never read.
    if instance.states.contains(existing) {
        instance.states.overwrite(existing, bytes.to_vec())?;
    } else {
        *slot = instance.states.add(bytes.to_vec()) as FmuStatePointer;
    }
    Ok(())
}
