//! Which `fmi2Component` and `fmi2FMUstate` pointers are ours and alive.
//!
//! An importer may pass anything: a freed instance, another library's instance, one of our
//! FMU states in place of its address (fmusim 0.0.39's `fmi2FreeFMUstate(c, state)`).
//! Pointers are therefore never dereferenced to find out what they are; they are looked
//! up here by their address first. Instances live in an `Arc`, so a call that found its
//! instance keeps it alive even if another thread frees it meanwhile (an importer bug, but
//! not a use-after-free).
//!
//! The registry is the library's only global mutable state. A lookup takes a read lock and
//! walks a `BTreeMap`: no allocation, so `fmi2DoStep` stays allocation-free.
//!
//! Lock order: an instance's mutex may be held while the registry lock is taken (to add or
//! remove its FMU states), never the other way round: nothing here locks an instance.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError, RwLock, RwLockReadGuard, RwLockWriteGuard};

use super::instance::Instance;

/// What an `fmi2Component` points to: the `Arc`'s allocation.
pub struct InstanceCell {
    /// The instance name, readable without locking the instance (for messages about
    /// FMU states that belong to it).
    pub name: String,
    pub instance: Mutex<Instance>,
}

// The instance cell is shared between threads (through the `Arc`s in the registry and
// the calls in flight): the compiler must agree that this is sound. `Instance` is `Send`
// (see the SAFETY note on `Logger`), which makes `Mutex<Instance>` `Send + Sync`.
const _: () = {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<InstanceCell>();
    assert_send_sync::<Arc<InstanceCell>>();
    assert_send_sync::<RwLock<Registry>>();
};

struct Registry {
    /// Live instances by address.
    instances: BTreeMap<usize, Arc<InstanceCell>>,
    /// Live FMU states by address, with the address of the instance that owns them (the
    /// states themselves live in their instance).
    states: BTreeMap<usize, usize>,
}

static REGISTRY: RwLock<Registry> = RwLock::new(Registry {
    instances: BTreeMap::new(),
    states: BTreeMap::new(),
});

// Nothing panics while holding the lock, but should it ever, the maps are still
// consistent (each operation is a single insert or remove): keep using them.
fn read() -> RwLockReadGuard<'static, Registry> {
    REGISTRY.read().unwrap_or_else(PoisonError::into_inner)
}

fn write() -> RwLockWriteGuard<'static, Registry> {
    REGISTRY.write().unwrap_or_else(PoisonError::into_inner)
}

/// The address an instance is known by (and the `fmi2Component` the importer gets).
pub fn address_of(cell: &Arc<InstanceCell>) -> usize {
    Arc::as_ptr(cell) as usize
}

/// Registers a new instance; returns its address.
pub fn add_instance(cell: Arc<InstanceCell>) -> usize {
    let address = address_of(&cell);
    write().instances.insert(address, cell);
    address
}

/// The live instance at `address`, if there is one.
pub fn instance(address: usize) -> Option<Arc<InstanceCell>> {
    read().instances.get(&address).cloned()
}

/// Unregisters an instance and its FMU states; the caller drops the returned cell (outside
/// the registry lock), which frees the instance once no call uses it any more.
pub fn remove_instance(address: usize) -> Option<Arc<InstanceCell>> {
    let mut registry = write();
    registry.states.retain(|_, owner| *owner != address);
    registry.instances.remove(&address)
}

/// Records that the FMU state at `state` belongs to the instance at `owner`.
pub fn add_state(state: usize, owner: usize) {
    write().states.insert(state, owner);
}

pub fn remove_state(state: usize) {
    write().states.remove(&state);
}

/// The instance an FMU state belongs to, if `state` is a live FMU state.
pub fn state_owner(state: usize) -> Option<usize> {
    read().states.get(&state).copied()
}

/// The name of the live instance at `address`.
pub fn instance_name(address: usize) -> Option<String> {
    read().instances.get(&address).map(|cell| cell.name.clone())
}
