//! Which `fmi2Component` and `fmi2FMUstate` pointers are ours and alive.
//!
//! An importer may pass anything: a freed instance, another library's instance, one of our
//! FMU states in place of its address (fmusim 0.0.39's `fmi2FreeFMUstate(c, state)`).
//! Pointers are therefore never dereferenced to find out what they are; they are looked
//! up here first. Instances live in an `Arc`, so a call that found its instance keeps it
//! alive even if another thread frees it meanwhile (an importer bug, but not a
//! use-after-free).
//!
//! Handles are not addresses: the allocator hands freed addresses out again, and a stale
//! handle would then name a new instance or state (of another model, even). They are
//! numbers from one counter that never repeats, with the top bit set so that no handle is
//! a user-space address on x86-64 Linux: a handle can never be mistaken for the address
//! of an importer's variable (see `state_slot` in exports.rs). Importers treat both
//! `fmi2Component` and `fmi2FMUstate` as opaque.
//!
//! The registry is the library's only global mutable state. A lookup takes a read lock and
//! walks a `BTreeMap`: no allocation, so `fmi2DoStep` stays allocation-free.
//!
//! Lock order: an instance's mutex may be held while the registry lock is taken (to add or
//! remove its FMU states), never the other way round: nothing here locks an instance.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
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
    /// Live instances by handle.
    instances: BTreeMap<usize, Arc<InstanceCell>>,
    /// Live FMU states by handle, with the handle of the instance that owns them (the
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

/// Top bit of every handle: above the 47-bit user address space of x86-64 Linux.
const HANDLE_TAG: usize = 1 << (usize::BITS - 1);

static NEXT_HANDLE: AtomicUsize = AtomicUsize::new(1);

/// A handle never handed out before (for an instance or an FMU state).
pub fn new_handle() -> usize {
    // 2^63 handles: a process cannot exhaust them.
    HANDLE_TAG | NEXT_HANDLE.fetch_add(1, Ordering::Relaxed)
}

/// Whether `value` has the form of one of our handles (live or not). Such a value is never
/// a user-space address, so it must not be dereferenced as one.
pub fn is_handle(value: usize) -> bool {
    value & HANDLE_TAG != 0
}

/// Registers a new instance under `handle` (from [`new_handle`]).
pub fn add_instance(handle: usize, cell: Arc<InstanceCell>) {
    write().instances.insert(handle, cell);
}

/// The live instance with `handle`, if there is one.
pub fn instance(handle: usize) -> Option<Arc<InstanceCell>> {
    read().instances.get(&handle).cloned()
}

/// Unregisters an instance and its FMU states; the caller drops the returned cell (outside
/// the registry lock), which frees the instance once no call uses it any more.
pub fn remove_instance(handle: usize) -> Option<Arc<InstanceCell>> {
    let mut registry = write();
    registry.states.retain(|_, owner| *owner != handle);
    registry.instances.remove(&handle)
}

/// Records that the FMU state `state` belongs to the instance `owner` (both handles).
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

/// The name of the live instance with `handle`.
pub fn instance_name(handle: usize) -> Option<String> {
    read().instances.get(&handle).map(|cell| cell.name.clone())
}
