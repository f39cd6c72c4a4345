//! Values shared by every field that holds them at once: a field built while another holds the same
//! value (a live edit, a batch of renders) makes nothing again. The cache keeps weak references,
//! so a value goes with the last field that holds it.

use std::sync::{Arc, Mutex, Weak};

/// A cache of values by key, each alive while some field holds it.
pub(super) struct SharedCache<K, V>(Mutex<Vec<(K, Weak<V>)>>);

impl<K: PartialEq, V> SharedCache<K, V> {
    /// An empty cache (for a `static`).
    pub const fn new() -> Self {
        SharedCache(Mutex::new(Vec::new()))
    }

    /// The value of `key` some field holds, or a new one from `make` (run without the lock, so
    /// values of other keys are made in parallel).
    pub fn get_or_make<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<Arc<V>, E> {
        let lock = || {
            self.0
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
        };
        let held = lock()
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, value)| value.upgrade());
        if let Some(value) = held {
            return Ok(value);
        }
        let value = Arc::new(make()?);
        let mut cache = lock();
        cache.retain(|(k, held)| held.strong_count() > 0 && *k != key);
        cache.push((key, Arc::downgrade(&value)));
        Ok(value)
    }
}
