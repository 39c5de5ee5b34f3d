//! Things made once and shared while used: instances on the same input share what was
//! made from it, and a restored state finds it instead of making it again (a plan or an
//! exact-distance index takes milliseconds; an importer may restore at every step).
//! Whoever owns the instances owns the cache (the FMU library one per process); the core
//! keeps no state of its own.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, Weak};

/// Values made from keys, each kept while someone holds it, and the one used last.
pub struct Shared<K, V> {
    /// Each value alive with the key it was made from (compared in full).
    alive: Mutex<Vec<(K, Weak<V>)>>,
    /// The value used last, kept after its holder lets go of it: a restore into an
    /// instance that has not made it finds it still.
    recent: Mutex<Option<Arc<V>>>,
    /// Values made (not found kept).
    made: AtomicU64,
}

impl<K, V> Default for Shared<K, V> {
    fn default() -> Self {
        Shared {
            alive: Mutex::new(Vec::new()),
            recent: Mutex::new(None),
            made: AtomicU64::new(0),
        }
    }
}

impl<K, V> std::fmt::Debug for Shared<K, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Shared")
            .field("made", &self.made())
            .finish_non_exhaustive()
    }
}

impl<K, V> Shared<K, V> {
    /// How many values were made, not found kept.
    pub fn made(&self) -> u64 {
        self.made.load(Ordering::Relaxed)
    }

    /// The value of the key `is_key` finds (compared in full), kept, or made now by `make`
    /// and kept under `key()`.
    pub fn get_or_make<E>(
        &self,
        is_key: impl Fn(&K) -> bool,
        key: impl FnOnce() -> K,
        make: impl FnOnce() -> Result<V, E>,
    ) -> Result<Arc<V>, E> {
        let kept = {
            let mut alive = self.alive.lock().unwrap_or_else(|e| e.into_inner());
            alive.retain(|(_, value)| value.strong_count() > 0);
            alive
                .iter()
                .find(|(k, _)| is_key(k))
                .and_then(|(_, value)| value.upgrade())
        };
        let value = match kept {
            Some(value) => value,
            None => {
                self.made.fetch_add(1, Ordering::Relaxed);
                let value = Arc::new(make()?);
                self.alive
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push((key(), Arc::downgrade(&value)));
                value
            }
        };
        *self.recent.lock().unwrap_or_else(|e| e.into_inner()) = Some(Arc::clone(&value));
        Ok(value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_is_made_once_per_key_and_kept_while_held_or_used_last() {
        let shared: Shared<u32, String> = Shared::default();
        let get = |k: u32| {
            shared.get_or_make(
                |&key| key == k,
                || k,
                || Ok::<_, &str>(format!("value {k}")),
            )
        };
        let a = get(1).unwrap();
        let b = get(1).unwrap();
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(shared.made(), 1);
        let c = get(2).unwrap();
        assert_eq!((c.as_str(), shared.made()), ("value 2", 2));
        // Let go of by everyone but the cache's last used: that one is still found.
        drop((a, b));
        let again = get(2).unwrap();
        assert!(Arc::ptr_eq(&again, &c));
        drop((again, c));
        get(2).unwrap();
        assert_eq!(shared.made(), 2);
        get(1).unwrap();
        assert_eq!(shared.made(), 3, "let go of: made again");
        // A failure keeps nothing.
        assert_eq!(
            shared.get_or_make(|&k| k == 3, || 3, || Err("no")),
            Err("no")
        );
        assert_eq!(shared.made(), 4);
        assert!(Arc::ptr_eq(&get(1).unwrap(), &get(1).unwrap()));
    }
}
