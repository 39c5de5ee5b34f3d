//! Which `fmi2Component` pointers are ours and alive: the instances, in a [`Slab`].
//!
//! An importer may pass anything: a freed instance, another library's instance, one of our
//! FMU states in place of its address (fmusim 0.0.39's `fmi2FreeFMUstate(c, state)`).
//! Pointers are therefore never dereferenced to find out what they are; they are looked
//! up here first (slab.rs says what a handle is, fmu_state.rs keeps the FMU states).
//!
//! The slot's lock is the instance's lock: a call holds it from the lookup to its end, so
//! a call in flight keeps its instance alive if another thread frees it meanwhile (an
//! importer bug, but not a use-after-free): `fmi2FreeInstance` waits for the call, then
//! takes the instance out of the slot and drops it outside the lock.
//!
//! The instance slab, the FMU states' owners (fmu_state.rs) and the planner the
//! instances share (plans.rs) are the library's only global mutable state, all here in
//! the FMI layer that owns the instances' lifetimes (contour-core keeps none but its
//! write-once cache of the built-in five-axis paths).

use super::instance::Instance;
use super::slab::{Guard, Slab};
use super::standard::Standard;

static INSTANCES: Slab<Instance> = Slab::new();

/// An instance found by its handle, locked for the call.
pub type InstanceGuard = Guard<'static, Instance>;

// The instances are shared between threads (every call locks its instance's slot): the
// compiler must agree that this is sound. `Instance` is `Send` (see the SAFETY note on
// `Logger`), which makes the slab `Sync`.
const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Slab<Instance>>();
};

/// Registers a new instance, telling it its handle; gives it back when the registry is
/// full.
pub fn add_instance(instance: Instance) -> Result<usize, Box<Instance>> {
    let mut instance = Some(instance);
    INSTANCES
        .insert(|handle| {
            let mut instance = instance.take().expect("taken once");
            instance.registered_as(handle);
            instance
        })
        .ok_or_else(|| Box::new(instance.take().expect("not taken by a failed insert")))
}

/// The live instance with `handle`, locked, if there is one.
#[inline]
pub fn instance(handle: usize) -> Option<InstanceGuard> {
    INSTANCES.lock(handle)
}

/// Unregisters an instance (waiting for a call in flight on it); the caller drops it,
/// outside any lock, and its FMU states are unregistered as it drops.
/// Takes the instance out of the registry if it is `standard`'s: the other standard's
/// `FreeInstance` leaves it alone.
pub fn remove_instance(handle: usize, standard: Standard) -> Option<Instance> {
    INSTANCES.remove_if(handle, |instance| instance.standard == standard)
}
