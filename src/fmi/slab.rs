//! The slab: values in slots, each behind its own lock, addressed by handles that are not
//! addresses. It knows nothing of what it stores (the registry keeps the instances in one,
//! registry.rs); it defines the form of every handle the library hands out.
//!
//! Handles are not addresses: the allocator hands freed addresses out again, and a stale
//! handle would then name a new value (an instance of another model, even). Every handle
//! has the top bit set ([`HANDLE_TAG`]), so that no handle is a user-space address on
//! x86-64 Linux: a handle can never be mistaken for the address of an importer's variable
//! (see `state_slot` in exports.rs). A slab's handle has the second-highest bit
//! ([`KIND_BIT`]) clear; handles of other kinds set it, so they are never a slab's (the FMU
//! states', fmu_state.rs).
//!
//! A handle is the index of its value's slot (the low [`INDEX_BITS`] bits) and the slot's
//! generation, which grows each time the slot gets a new value. A slot whose generations
//! are used up is never used again, so no two values ever get the same handle, and a stale
//! handle never names a new value.
//!
//! Looking a value up takes no global lock and allocates nothing, so the per-sample calls
//! on an instance (`fmi2DoStep`, `fmi2SetReal`, `fmi2GetReal`) stay allocation-free: the
//! handle's index selects a chunk of slots (one atomic load of a pointer published once,
//! chunks are never freed while the slab lives) and a slot in it; the slot's live handle
//! is compared with the handle before the slot is locked (a stale handle is refused
//! without waiting), and again once it is. A call holds the slot's lock from the lookup to
//! its end, so a call in flight keeps its value alive if another thread removes it
//! meanwhile: [`Slab::remove`] waits for the call, then takes the value out of the slot,
//! and the caller drops it outside the lock. A foreign, NULL, removed or made-up handle is
//! only ever compared with numbers the slab holds.

use std::cell::UnsafeCell;
use std::hint::spin_loop;
use std::marker::PhantomData;
use std::ops::{Deref, DerefMut};
use std::ptr;
use std::sync::atomic::{AtomicBool, AtomicPtr, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::Duration;

/// Top bit of every handle: above the 47-bit user address space of x86-64 Linux.
pub const HANDLE_TAG: usize = 1 << (usize::BITS - 1);
/// Clear in a slab's handles, set in handles of other kinds (the FMU states').
pub const KIND_BIT: usize = 1 << (usize::BITS - 2);
/// Bits of a slab handle that hold the slot index: at most 2^20 (a million) live
/// values (instances).
const INDEX_BITS: u32 = if usize::BITS >= 64 { 20 } else { 12 };
const INDEX_MASK: usize = (1 << INDEX_BITS) - 1;
/// The generations of a slot are 1..=MAX_GENERATION (the bits between the index and the
/// kind bit): 2^42 values, one after the other, in one slot.
const MAX_GENERATION: usize = (KIND_BIT >> INDEX_BITS) - 1;
/// Slots per chunk.
const CHUNK_BITS: u32 = 6;
const CHUNK: usize = 1 << CHUNK_BITS;
/// Chunks for every index: a table of 16 384 pointers, filled as values are inserted.
const CHUNKS: usize = 1 << (INDEX_BITS - CHUNK_BITS);

/// Whether `value` has the form of one of our handles (live or not). Such a value is never
/// a user-space address, so it must not be dereferenced as one.
pub fn is_handle(value: usize) -> bool {
    value & HANDLE_TAG != 0
}

// ---------------------------------------------------------------------------------------
// The slab: slots of values addressed by generation-checked handles

/// One slot: a value (or none) and the lock that guards it.
// Aligned to a cache line pair so that calls on values (instances) in neighbouring slots,
// made on different threads, do not share the line of their locks.
#[repr(align(128))]
struct Slot<T> {
    /// The handle of the value in the slot, 0 when there is none. Written only with the
    /// lock held; read without it to refuse a stale handle without waiting for the lock.
    live: AtomicUsize,
    /// The generation of the slot's last value. Written only by the inserter that owns
    /// the free slot.
    generation: AtomicUsize,
    locked: AtomicBool,
    value: UnsafeCell<Option<T>>,
}

impl<T> Slot<T> {
    const fn new() -> Self {
        Slot {
            live: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            locked: AtomicBool::new(false),
            value: UnsafeCell::new(None),
        }
    }

    /// Takes the lock: one compare-exchange when nobody holds it (the only case a correct
    /// importer produces: FMI 2.0 forbids overlapping calls on one instance), and the
    /// unlock is a plain store.
    #[inline]
    fn lock(&self) {
        if self
            .locked
            .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
            .is_err()
        {
            self.lock_contended();
        }
    }

    /// Waits for another call on the same slot (an importer calling one instance from two
    /// threads at once, or freeing it during a call): spins briefly, then yields, then
    /// sleeps in short naps, so a long step on the other thread costs little CPU.
    #[cold]
    #[inline(never)]
    fn lock_contended(&self) {
        let mut attempts = 0u32;
        loop {
            if !self.locked.load(Ordering::Relaxed)
                && self
                    .locked
                    .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
                    .is_ok()
            {
                return;
            }
            attempts = attempts.saturating_add(1);
            if attempts < 64 {
                spin_loop();
            } else if attempts < 128 {
                std::thread::yield_now();
            } else {
                std::thread::sleep(Duration::from_micros(50));
            }
        }
    }

    #[inline]
    fn unlock(&self) {
        self.locked.store(false, Ordering::Release);
    }
}

/// Values of type `T` in slots, each behind its own lock, addressed by handles that carry
/// the slot's index and generation. Slots live in chunks that are allocated as needed and
/// never freed while the slab lives (the registry's, in a static, lives as long as the
/// library), so any index that has a chunk can be read, whatever the handle's history.
pub struct Slab<T> {
    /// Chunk k: the `CHUNK` slots from index `k · CHUNK` on, published once with Release,
    /// null until then.
    chunks: [AtomicPtr<Slot<T>>; CHUNKS],
    allocator: Mutex<Allocator>,
    /// The slab owns the values in its chunks (for the drop check).
    owns: PhantomData<T>,
}

struct Allocator {
    /// Slots without a value whose generations are not used up.
    free: Vec<usize>,
    /// Slots handed out so far (the next fresh index).
    fresh: usize,
}

// SAFETY: a value in a slot is only reached through a `Guard` (while the slot's lock is
// held, as with a `Mutex<T>`) or moved in and out of the slot with the lock held, so
// sharing the slab between threads only ever moves values from one thread to another:
// `T: Send` suffices, as for `Mutex<T>: Sync`. Everything else is atomics and a mutex.
unsafe impl<T: Send> Sync for Slab<T> {}
unsafe impl<T: Send> Send for Slab<T> {}

/// The chunk of slot `index` and its position in the chunk.
#[inline]
fn chunk_of(index: usize) -> (usize, usize) {
    (index >> CHUNK_BITS, index & (CHUNK - 1))
}

/// The slot index and generation of a slab handle.
fn decode(handle: usize) -> Option<(usize, usize)> {
    (handle & (HANDLE_TAG | KIND_BIT) == HANDLE_TAG)
        .then_some((handle & INDEX_MASK, (handle & !HANDLE_TAG) >> INDEX_BITS))
}

/// A value of the slab, locked: other calls on it wait until the guard is dropped.
pub struct Guard<'a, T> {
    slot: &'a Slot<T>,
    value: &'a mut T,
}

impl<T> Deref for Guard<'_, T> {
    type Target = T;
    #[inline]
    fn deref(&self) -> &T {
        &*self.value
    }
}

impl<T> DerefMut for Guard<'_, T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut T {
        &mut *self.value
    }
}

impl<T> Drop for Guard<'_, T> {
    #[inline]
    fn drop(&mut self) {
        self.slot.unlock();
    }
}

impl<T> Slab<T> {
    pub const fn new() -> Self {
        Slab {
            chunks: [const { AtomicPtr::new(ptr::null_mut()) }; CHUNKS],
            allocator: Mutex::new(Allocator {
                free: Vec::new(),
                fresh: 0,
            }),
            owns: PhantomData,
        }
    }

    fn allocator(&self) -> MutexGuard<'_, Allocator> {
        // Nothing panics while holding it; should it ever, the lists are still usable.
        self.allocator
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// Slot `index`, if its chunk exists.
    #[inline]
    fn slot(&self, index: usize) -> Option<&Slot<T>> {
        let (chunk, offset) = chunk_of(index);
        let first = self.chunks.get(chunk)?.load(Ordering::Acquire);
        if first.is_null() {
            return None;
        }
        // SAFETY: chunk `chunk` is an array of `CHUNK` initialised slots (`offset` is
        // below that by construction), published with Release after it was
        // written (the Acquire load above pairs with it) and freed only by `Drop`.
        Some(unsafe { &*first.add(offset) })
    }

    /// A slot without a value, with its chunk allocated; `None` when every index is in use.
    fn take_free_slot(&self) -> Option<usize> {
        let mut allocator = self.allocator();
        if let Some(index) = allocator.free.pop() {
            return Some(index);
        }
        let index = allocator.fresh;
        if index > INDEX_MASK {
            return None;
        }
        let (chunk, offset) = chunk_of(index);
        if offset == 0 {
            let slots: Box<[Slot<T>]> = (0..CHUNK).map(|_| Slot::new()).collect();
            let first = Box::into_raw(slots) as *mut Slot<T>;
            self.chunks[chunk].store(first, Ordering::Release);
        }
        allocator.fresh = index + 1;
        Some(index)
    }

    /// Stores the value `make` builds from its handle (it must not panic: the slot would be
    /// lost, harmlessly); `None`, without calling `make`, when the slab is full.
    pub fn insert(&self, make: impl FnOnce(usize) -> T) -> Option<usize> {
        let index = self.take_free_slot()?;
        let slot = self.slot(index).expect("a slot handed out has its chunk");
        // The slot is free and ours alone: no other inserter has it, and lookups do not
        // get past `live`, which is 0.
        let generation = slot.generation.load(Ordering::Relaxed) + 1;
        debug_assert!(generation <= MAX_GENERATION);
        slot.generation.store(generation, Ordering::Relaxed);
        let handle = HANDLE_TAG | generation << INDEX_BITS | index;
        let value = make(handle);
        slot.lock();
        // SAFETY: the lock is held, so nothing else reaches the value.
        unsafe { *slot.value.get() = Some(value) };
        slot.live.store(handle, Ordering::Release);
        slot.unlock();
        Some(handle)
    }

    /// The live value with `handle`, locked; `None` for any other number (NULL, a freed
    /// or foreign handle), which is only compared, never followed.
    #[inline]
    pub fn lock(&self, handle: usize) -> Option<Guard<'_, T>> {
        let (index, _) = decode(handle)?;
        let slot = self.slot(index)?;
        if slot.live.load(Ordering::Acquire) != handle {
            return None;
        }
        slot.lock();
        // Freed (and perhaps reused) between the check and the lock?
        if slot.live.load(Ordering::Relaxed) != handle {
            slot.unlock();
            return None;
        }
        // SAFETY: the lock is held until the guard drops it, and `live` names a value.
        match unsafe { (*slot.value.get()).as_mut() } {
            Some(value) => Some(Guard { slot, value }),
            None => {
                slot.unlock();
                None
            }
        }
    }

    /// Takes the live value with `handle` out of the slab (waiting for a call that holds
    /// it); the handle is refused from then on. The caller drops the value, outside any
    /// lock.
    #[cfg(test)]
    pub fn remove(&self, handle: usize) -> Option<T> {
        self.remove_if(handle, |_| true)
    }

    /// [`Slab::remove`] when `qualifies` says so of the value (under the lock: a value
    /// that does not qualify stays, untouched).
    pub fn remove_if(&self, handle: usize, qualifies: impl FnOnce(&T) -> bool) -> Option<T> {
        let (index, generation) = decode(handle)?;
        let slot = self.slot(index)?;
        if slot.live.load(Ordering::Acquire) != handle {
            return None;
        }
        slot.lock();
        // SAFETY (the read of the value): the lock is held.
        if slot.live.load(Ordering::Relaxed) != handle
            || !unsafe { (*slot.value.get()).as_ref() }.is_some_and(qualifies)
        {
            slot.unlock();
            return None;
        }
        slot.live.store(0, Ordering::Release);
        // SAFETY: the lock is held.
        let value = unsafe { (*slot.value.get()).take() };
        slot.unlock();
        // A slot whose generations are used up is retired: its handles never come back.
        if generation < MAX_GENERATION {
            self.allocator().free.push(index);
        }
        value
    }
}

impl<T> Drop for Slab<T> {
    /// Frees the chunks (a slab in a static, as the registry's, is never dropped).
    fn drop(&mut self) {
        for first in &mut self.chunks {
            let first = *first.get_mut();
            if !first.is_null() {
                let slots = ptr::slice_from_raw_parts_mut(first, CHUNK);
                // SAFETY: allocated in `take_free_slot` as a boxed slice of this length,
                // and no guard can outlive `&mut self`.
                drop(unsafe { Box::from_raw(slots) });
            }
        }
    }
}

impl<T> Default for Slab<T> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicU64;
    use std::sync::Barrier;

    #[test]
    fn every_index_has_a_place() {
        assert_eq!(chunk_of(0), (0, 0));
        assert_eq!(chunk_of(CHUNK - 1), (0, CHUNK - 1));
        assert_eq!(chunk_of(CHUNK), (1, 0));
        assert_eq!(chunk_of(INDEX_MASK), (CHUNKS - 1, CHUNK - 1));
        // A handle's bits: tag, kind, generation, index, without overlap.
        assert_eq!(MAX_GENERATION << INDEX_BITS & INDEX_MASK, 0);
        assert_eq!((MAX_GENERATION << INDEX_BITS) & (HANDLE_TAG | KIND_BIT), 0);
        assert_eq!(
            HANDLE_TAG | KIND_BIT | MAX_GENERATION << INDEX_BITS | INDEX_MASK,
            usize::MAX
        );
    }

    #[test]
    fn handles_are_tagged_and_never_name_a_later_value() {
        let slab = Slab::new();
        let first = slab.insert(|_| 1u32).unwrap();
        assert!(is_handle(first));
        assert_eq!(*slab.lock(first).unwrap(), 1);
        assert_eq!(slab.remove(first), Some(1));
        assert!(slab.lock(first).is_none());
        assert_eq!(slab.remove(first), None);
        // The slot is reused at once, under a new generation.
        let second = slab.insert(|_| 2).unwrap();
        assert_eq!(second & INDEX_MASK, first & INDEX_MASK);
        assert_ne!(second, first);
        assert!(slab.lock(first).is_none());
        assert_eq!(*slab.lock(second).unwrap(), 2);
        // Made-up numbers: no tag, the kind bit, an index without a chunk, a slot never
        // used, NULL, a handle of another kind (an FMU state's form).
        for made_up in [
            second & !HANDLE_TAG,
            second | KIND_BIT,
            HANDLE_TAG | 1 << INDEX_BITS | INDEX_MASK,
            HANDLE_TAG | 1 << INDEX_BITS | 5,
            0,
            HANDLE_TAG | KIND_BIT | 1,
        ] {
            assert!(slab.lock(made_up).is_none(), "{made_up:#x}");
            assert!(slab.remove(made_up).is_none(), "{made_up:#x}");
        }
        assert_eq!(*slab.lock(second).unwrap(), 2);
    }

    #[test]
    fn a_slot_whose_generations_are_used_up_is_retired() {
        let slab = Slab::new();
        let handle = slab.insert(|_| 0u8).unwrap();
        let index = handle & INDEX_MASK;
        slab.remove(handle);
        let slot = slab.slot(index).unwrap();
        slot.generation.store(MAX_GENERATION - 1, Ordering::Relaxed);
        let last = slab.insert(|_| 1).unwrap();
        assert_eq!(last, HANDLE_TAG | MAX_GENERATION << INDEX_BITS | index);
        assert!(decode(last).is_some_and(|(i, g)| i == index && g == MAX_GENERATION));
        assert_eq!(slab.remove(last), Some(1));
        let next = slab.insert(|_| 2).unwrap();
        assert_ne!(next & INDEX_MASK, index);
    }

    /// A call holding a value keeps it: a removal on another thread waits for the guard,
    /// and the value is gone only afterwards.
    #[test]
    fn a_removal_waits_for_the_call_in_flight() {
        let slab = Slab::new();
        let handle = slab.insert(|_| vec![1u64, 2, 3]).unwrap();
        let removed = AtomicBool::new(false);
        let barrier = Barrier::new(2);
        std::thread::scope(|scope| {
            let mut guard = slab.lock(handle).unwrap();
            scope.spawn(|| {
                barrier.wait();
                let value = slab.remove(handle);
                removed.store(true, Ordering::SeqCst);
                assert_eq!(value, Some(vec![1, 2, 3, 4]));
            });
            barrier.wait();
            std::thread::sleep(Duration::from_millis(50));
            assert!(!removed.load(Ordering::SeqCst), "removed during the call");
            guard.push(4);
            drop(guard);
        });
        assert!(removed.load(Ordering::SeqCst));
        assert!(slab.lock(handle).is_none());
    }

    /// Calls on many threads, each on its own values and on the others' (overlapping, as
    /// a broken importer would), while values come and go: every locked value is the
    /// one its handle named, and no two calls hold one value at once.
    #[test]
    fn concurrent_calls_inserts_and_removals_stay_consistent() {
        struct Counted {
            handle: usize,
            inside: AtomicU64,
        }
        let slab = Slab::<Counted>::new();
        let shared: Vec<usize> = (0..4)
            .map(|_| {
                slab.insert(|handle| Counted {
                    handle,
                    inside: AtomicU64::new(0),
                })
                .unwrap()
            })
            .collect();
        std::thread::scope(|scope| {
            for _ in 0..4 {
                scope.spawn(|| {
                    for round in 0..2000 {
                        let own = slab
                            .insert(|handle| Counted {
                                handle,
                                inside: AtomicU64::new(0),
                            })
                            .unwrap();
                        for &h in shared.iter().chain([&own]) {
                            let guard = slab.lock(h).unwrap();
                            assert_eq!(guard.handle, h);
                            assert_eq!(guard.inside.fetch_add(1, Ordering::Relaxed), 0);
                            if round % 64 == 0 {
                                std::thread::yield_now();
                            }
                            guard.inside.fetch_sub(1, Ordering::Relaxed);
                        }
                        let value = slab.remove(own).unwrap();
                        assert_eq!(value.handle, own);
                        assert!(slab.lock(own).is_none());
                    }
                });
            }
        });
        for h in shared {
            assert!(slab.remove(h).is_some());
        }
    }
}
