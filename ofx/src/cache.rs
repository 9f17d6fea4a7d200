//! Warps cached in instance data: keyed by everything a map
//! (or an `auto` correspondence) depends on, shared by concurrent renders of
//! the same frame (the second thread waits for the first instead of computing
//! again), bounded in memory.
//!
//! One budget holds for the whole process, every cache of every instance
//! together (`MORPHFX_CACHE_MB`, default [`DEFAULT_BUDGET_MB`]): when a new
//! value takes the total over it, the least recently used values go, from
//! whichever cache holds them. A host with ten nodes then holds no more than
//! one with one, and a long sequence no more than a short one.

use std::fmt::Debug;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, Weak};

use morphfx::image::WarpMap;
use morphfx::warp::auto::Correspondence;

use ofx_layer::sync::Locked;

/// Default process-wide budget, MiB (a 1080p map is 16 MiB).
pub const DEFAULT_BUDGET_MB: usize = 256;

/// The process-wide budget in bytes: `MORPHFX_CACHE_MB`, else the default.
fn budget() -> usize {
    static BUDGET: OnceLock<usize> = OnceLock::new();
    *BUDGET.get_or_init(|| {
        let mb = std::env::var("MORPHFX_CACHE_MB")
            .ok()
            .and_then(|v| v.trim().parse::<usize>().ok())
            .unwrap_or(DEFAULT_BUDGET_MB);
        mb.saturating_mul(1 << 20)
    })
}

/// Bytes held by every cache of the process.
static USED: AtomicUsize = AtomicUsize::new(0);
/// Ticks on every use, so entries of different caches compare by age.
static CLOCK: AtomicU64 = AtomicU64::new(0);
/// Every live cache, for eviction across them.
static CACHES: Mutex<Vec<Weak<dyn Shrink>>> = Mutex::new(Vec::new());

/// What a cached value costs in memory.
pub trait Weigh {
    fn bytes(&self) -> usize;
}

impl Weigh for WarpMap {
    fn bytes(&self) -> usize {
        self.memory_bytes()
    }
}

impl Weigh for morphfx::warp::field::FieldMap {
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

/// A cache's entries, behind the lock eviction takes.
struct Entries<T>(Mutex<Vec<Entry<T>>>);

/// A cache as eviction sees it.
trait Shrink: Send + Sync {
    /// The last use of its oldest finished entry other than `keep`.
    fn oldest(&self, keep: Option<&Key>) -> Option<u64>;
    /// Drops that entry; the bytes it held.
    fn evict_oldest(&self, keep: Option<&Key>) -> usize;
}

impl<T> Entries<T> {
    /// The index of the oldest finished entry other than `keep`.
    fn oldest_of(entries: &[Entry<T>], keep: Option<&Key>) -> Option<usize> {
        entries
            .iter()
            .enumerate()
            .filter(|(_, e)| e.bytes > 0 && Some(&e.key) != keep)
            .min_by_key(|(_, e)| e.last_use)
            .map(|(i, _)| i)
    }
}

impl<T: Send + Sync> Shrink for Entries<T> {
    fn oldest(&self, keep: Option<&Key>) -> Option<u64> {
        let entries = self.0.locked();
        Self::oldest_of(&entries, keep).map(|i| entries[i].last_use)
    }

    fn evict_oldest(&self, keep: Option<&Key>) -> usize {
        let mut entries = self.0.locked();
        match Self::oldest_of(&entries, keep) {
            Some(i) => entries.swap_remove(i).bytes,
            None => 0,
        }
    }
}

pub struct Cache<T> {
    entries: Arc<Entries<T>>,
}

pub type WarpCache = Cache<WarpMap>;

impl<T: Weigh + Send + Sync + 'static> Default for Cache<T> {
    fn default() -> Self {
        Cache::new()
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

    /// The key of `base`'s inputs with `parts` besides: a render's inputs
    /// (a scene's worth of floats, the costly part to print) printed once
    /// and shared by its maps. `base`'s length leads, so where it ends is
    /// never in doubt.
    pub fn with(base: &Key, parts: &impl Debug) -> Key {
        use std::fmt::Write;
        let mut text = String::with_capacity(base.0.len() + 64);
        // Writing to a String cannot fail.
        let _ = write!(text, "{}:{}|{parts:?}", base.0.len(), base.0);
        Key(text.into())
    }
}

impl<T: Weigh + Send + Sync + 'static> Cache<T> {
    pub fn new() -> Self {
        let entries = Arc::new(Entries(Mutex::new(Vec::new())));
        let weak: Weak<dyn Shrink> = Arc::downgrade(&entries) as Weak<dyn Shrink>;
        let mut caches = CACHES.locked();
        caches.retain(|c| c.strong_count() > 0);
        caches.push(weak);
        Cache { entries }
    }

    pub fn get_or_compute<E>(
        &self,
        key: Key,
        compute: impl FnOnce() -> Result<T, E>,
    ) -> Result<Arc<T>, E> {
        let now = CLOCK.fetch_add(1, Ordering::Relaxed);
        let slot = {
            let mut entries = self.entries();
            match entries.iter_mut().find(|e| e.key == key) {
                Some(e) => {
                    e.last_use = now;
                    e.slot.clone()
                }
                None => {
                    let slot: Slot<T> = Arc::new(Mutex::new(None));
                    entries.push(Entry {
                        key: key.clone(),
                        slot: slot.clone(),
                        bytes: 0,
                        last_use: now,
                    });
                    slot
                }
            }
        };
        // Per-entry lock: threads wanting the same map wait here for one computation.
        let mut value = slot.locked();
        if let Some(map) = value.as_ref() {
            return Ok(map.clone());
        }
        let map = Arc::new(compute()?);
        *value = Some(map.clone());
        drop(value);
        self.account(&key, map.bytes());
        Ok(map)
    }

    fn entries(&self) -> std::sync::MutexGuard<'_, Vec<Entry<T>>> {
        self.entries.0.locked()
    }

    fn account(&self, key: &Key, bytes: usize) {
        {
            let mut entries = self.entries();
            // Evicted while it was computed: it is not held, so not counted.
            let Some(e) = entries.iter_mut().find(|e| e.key == *key) else {
                return;
            };
            e.bytes = bytes;
        }
        USED.fetch_add(bytes, Ordering::AcqRel);
        self.shrink(key);
    }

    /// Evicts the least recently used entries of the whole process (never
    /// `keep`, the value just made) until the total fits the budget.
    fn shrink(&self, keep: &Key) {
        let caches = CACHES.locked();
        let me: *const Entries<T> = Arc::as_ptr(&self.entries);
        while USED.load(Ordering::Acquire) > budget() {
            let oldest = caches
                .iter()
                .filter_map(|w| w.upgrade())
                .filter_map(|c| {
                    let own = std::ptr::addr_eq(Arc::as_ptr(&c), me);
                    let age = c.oldest(if own { Some(keep) } else { None })?;
                    Some((age, c, own))
                })
                .min_by_key(|(age, _, _)| *age);
            let Some((_, cache, own)) = oldest else { break };
            let freed = cache.evict_oldest(if own { Some(keep) } else { None });
            if freed == 0 {
                break;
            }
            USED.fetch_sub(freed, Ordering::AcqRel);
        }
    }

    /// Takes `key`'s value out of the cache, when it is made: whoever
    /// holds the last `Arc` may then edit it in place instead of copying.
    pub fn take(&self, key: &Key) -> Option<Arc<T>> {
        let entry = {
            let mut entries = self.entries();
            let at = entries.iter().position(|e| e.key == *key && e.bytes > 0)?;
            entries.swap_remove(at)
        };
        USED.fetch_sub(entry.bytes, Ordering::AcqRel);
        let value = entry.slot.locked().take();
        value
    }

    pub fn clear(&self) {
        let freed: usize = self.entries().drain(..).map(|e| e.bytes).sum();
        USED.fetch_sub(freed, Ordering::AcqRel);
    }

    #[cfg(test)]
    pub fn bytes(&self) -> usize {
        self.entries().iter().map(|e| e.bytes).sum()
    }
}

impl<T> Drop for Cache<T> {
    /// Gives its bytes back; drained under the lock eviction takes, so an
    /// entry is never counted off twice.
    fn drop(&mut self) {
        let mut entries = self.entries.0.locked();
        let freed: usize = entries.drain(..).map(|e| e.bytes).sum();
        USED.fetch_sub(freed, Ordering::AcqRel);
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

    /// A value taken out is the caller's alone: its bytes leave the
    /// budget, the key misses afterwards, and nothing is taken twice.
    #[test]
    fn a_taken_value_leaves_the_cache_and_its_budget() {
        let cache = WarpCache::default();
        let made = cache
            .get_or_compute::<()>(Key::of(&"a"), || Ok(map(64)))
            .unwrap();
        cache
            .get_or_compute::<()>(Key::of(&"b"), || Ok(map(8)))
            .unwrap();
        assert_eq!(cache.bytes(), 72 * 8);
        let taken = cache.take(&Key::of(&"a")).expect("made, so taken");
        assert!(Arc::ptr_eq(&taken, &made));
        drop(made);
        assert!(Arc::try_unwrap(taken).is_ok(), "no other holder");
        assert_eq!(cache.bytes(), 8 * 8);
        assert!(cache.take(&Key::of(&"a")).is_none());
        let calls = std::sync::atomic::AtomicUsize::new(0);
        cache
            .get_or_compute::<()>(Key::of(&"a"), || {
                calls.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                Ok(map(64))
            })
            .unwrap();
        assert_eq!(
            calls.load(std::sync::atomic::Ordering::SeqCst),
            1,
            "made again"
        );
    }

    /// A key built on a base differs with either part, and where the base
    /// ends is never in doubt.
    #[test]
    fn keys_with_a_base_tell_apart_both_parts() {
        let (a, b) = (Key::of(&"x"), Key::of(&"x|1"));
        assert_eq!(Key::with(&a, &1), Key::with(&Key::of(&"x"), &1));
        assert_ne!(Key::with(&a, &1), Key::with(&a, &2));
        assert_ne!(Key::with(&a, &1), Key::with(&b, &1));
        // Text that would read the same without the base's length.
        let (short, long) = (Key(Arc::from("ab")), Key(Arc::from("ab|1")));
        assert_ne!(Key::with(&short, &"1|2"), Key::with(&long, &"2"));
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

    /// Every cache of the process together stays within the one budget,
    /// the oldest values going first, whichever cache holds them.
    #[test]
    fn all_caches_together_stay_within_the_process_budget() {
        let map_bytes = map(1 << 20).bytes(); // 8 MiB
        let per_budget = budget() / map_bytes;
        let (first, second) = (WarpCache::default(), WarpCache::default());
        first
            .get_or_compute::<()>(Key::of(&"old"), || Ok(map(1 << 20)))
            .unwrap();
        for k in 0..per_budget + 3 {
            second
                .get_or_compute::<()>(Key::of(&k), || Ok(map(1 << 20)))
                .unwrap();
        }
        assert!(first.bytes() + second.bytes() <= budget());
        assert_eq!(
            first.bytes(),
            0,
            "the oldest value, in the other cache, went first"
        );
        assert!(second.bytes() >= budget() - map_bytes);
    }
}
