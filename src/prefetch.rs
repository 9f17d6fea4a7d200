//! Cache hints: lines a loop will read soon, asked of the memory system
//! where its stream prefetchers cannot guess them (a warp's taps, rows read
//! in short runs with gaps between). Hints only: nothing read or written
//! changes, and on targets with no safe prefetch wrapper they do nothing.

/// Asks the cache for the line holding `v`.
#[inline(always)]
pub(crate) fn line<T>(v: &T) {
    #[cfg(target_arch = "x86_64")]
    safe_arch::prefetch_t0(v);
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// Asks the cache for every line `v` lies on: one element per 64 bytes
/// from the first, whichever line that starts on, and the last.
#[inline(always)]
pub(crate) fn lines<T>(v: &[T]) {
    let step = (64 / std::mem::size_of::<T>().max(1)).max(1);
    v.iter().step_by(step).chain(v.last()).for_each(line);
}
