//! Warps cached in instance data: keyed by everything a map
//! (or an `auto` correspondence) depends on, shared by concurrent renders of
//! the same frame (the second thread waits for the first instead of computing
//! again), bounded in memory.

use std::fmt::Debug;
use std::sync::{Arc, Mutex};

use morphfx::image::WarpMap;
use morphfx::warp::auto::Correspondence;

/// Default memory budget for cached maps (a 1080p map is 16 MiB).
pub const DEFAULT_BUDGET_BYTES: usize = 512 << 20;

/// What a cached value costs in memory.
pub trait Weigh {
    fn bytes(&self) -> usize;
}

impl Weigh for WarpMap {
    fn bytes(&self) -> usize {
        self.memory_bytes()
    }
}

impl Weigh for morphfx::transition::Weights {
    fn bytes(&self) -> usize {
        self.memory_bytes()
    }
}

impl Weigh for Correspondence {
    fn bytes(&self) -> usize {
        std::mem::size_of_val(self.grid.points())
    }
}

type Slot<T> = Arc<Mutex<Option<Arc<T>>>>;

struct Entry<T> {
    key: Key,
    slot: Slot<T>,
    bytes: usize,
    last_use: u64,
}

pub struct Cache<T> {
    entries: Mutex<(Vec<Entry<T>>, u64)>,
    budget: usize,
}

pub type WarpCache = Cache<WarpMap>;

impl<T: Weigh> Default for Cache<T> {
    fn default() -> Self {
        Cache::new(DEFAULT_BUDGET_BYTES)
    }
}

/// A cache key: the `Debug` text of everything a value depends on, kept
/// whole and compared in full on every lookup (never a hash, which two
/// inputs could share). Rust prints a float as the shortest decimal that
/// reads back to the same bits, so equal keys mean bit-equal inputs (NaNs
/// aside: features and settings that reach a cache are finite).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Key(Arc<str>);

impl Key {
    pub fn of(parts: &impl Debug) -> Key {
        Key(format!("{parts:?}").into())
    }
}

impl<T: Weigh> Cache<T> {
    pub fn new(budget: usize) -> Self {
        Cache {
            entries: Mutex::new((Vec::new(), 0)),
            budget,
        }
    }

    pub fn get_or_compute<E>(
        &self,
        key: Key,
        compute: impl FnOnce() -> Result<T, E>,
    ) -> Result<Arc<T>, E> {
        let slot = {
            let mut guard = self.entries.lock().unwrap_or_else(|e| e.into_inner());
            let (entries, clock) = &mut *guard;
            *clock += 1;
            match entries.iter_mut().find(|e| e.key == key) {
                Some(e) => {
                    e.last_use = *clock;
                    e.slot.clone()
                }
                None => {
                    let slot: Slot<T> = Arc::new(Mutex::new(None));
                    entries.push(Entry {
                        key: key.clone(),
                        slot: slot.clone(),
                        bytes: 0,
                        last_use: *clock,
                    });
                    slot
                }
            }
        };
        // Per-entry lock: threads wanting the same map wait here for one computation.
        let mut value = slot.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(map) = value.as_ref() {
            return Ok(map.clone());
        }
        let map = Arc::new(compute()?);
        *value = Some(map.clone());
        drop(value);
        self.account(&key, map.bytes());
        Ok(map)
    }

    fn account(&self, key: &Key, bytes: usize) {
        let mut guard = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        let (entries, _) = &mut *guard;
        if let Some(e) = entries.iter_mut().find(|e| e.key == *key) {
            e.bytes = bytes;
        }
        // Evict least recently used entries (never the one just made) over budget.
        while entries.iter().map(|e| e.bytes).sum::<usize>() > self.budget && entries.len() > 1 {
            let Some((i, _)) = entries
                .iter()
                .enumerate()
                .filter(|(_, e)| e.key != *key)
                .min_by_key(|(_, e)| e.last_use)
            else {
                break;
            };
            entries.swap_remove(i);
        }
    }

    pub fn clear(&self) {
        self.entries
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .0
            .clear();
    }

    #[cfg(test)]
    pub fn bytes(&self) -> usize {
        self.entries
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .0
            .iter()
            .map(|e| e.bytes)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use morphfx::geom::{PixelScale, RectI};

    fn map(w: usize) -> WarpMap {
        WarpMap::new(
            RectI::from_size(w, 1),
            PixelScale::UNIT,
            vec![[0.0, 0.0]; w],
        )
    }

    #[test]
    fn computes_once_per_key_even_across_threads() {
        let cache = WarpCache::default();
        let calls = std::sync::atomic::AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    cache
                        .get_or_compute::<()>(Key::of(&42), || {
                            calls.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                            std::thread::sleep(std::time::Duration::from_millis(20));
                            Ok(map(4))
                        })
                        .unwrap();
                });
            }
        });
        assert_eq!(calls.load(std::sync::atomic::Ordering::SeqCst), 1);
    }

    /// Keys differ wherever their inputs' bits do, however close the values.
    #[test]
    fn keys_tell_apart_inputs_one_bit_apart() {
        let x = 0.1f64;
        let next = f64::from_bits(x.to_bits() + 1);
        assert_ne!(Key::of(&(x, 1)), Key::of(&(next, 1)));
        assert_ne!(Key::of(&0.0f64), Key::of(&-0.0f64));
        assert_eq!(Key::of(&(x, "a")), Key::of(&(0.1f64, "a")));
        let cache = WarpCache::default();
        let a = cache
            .get_or_compute::<()>(Key::of(&x), || Ok(map(1)))
            .unwrap();
        let b = cache
            .get_or_compute::<()>(Key::of(&next), || Ok(map(2)))
            .unwrap();
        assert_eq!((a.window.width(), b.window.width()), (1, 2));
    }

    #[test]
    fn stays_within_its_budget() {
        let cache = WarpCache::new(100 * 8);
        for k in 0..10 {
            cache
                .get_or_compute::<()>(Key::of(&k), || Ok(map(40)))
                .unwrap();
        }
        assert!(cache.bytes() <= 100 * 8);
    }
}
