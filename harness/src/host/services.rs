//! The host's service suites: memory, multi-thread, progress and time line.
//! Plugins may fetch any of them; each call checks its handles and answers
//! with an OFX status, never a crash.

use std::alloc::Layout;
use std::ffi::{c_char, c_int, c_uint, c_void, CStr};
use std::sync::{Condvar, Mutex};

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::memory::*;
use openfx::sys::image_effect_v1::multi_thread::*;
use openfx::sys::image_effect_v1::progress::*;
use openfx::sys::image_effect_v1::time_line::*;

use super::effect::live_effect;
use crate::sync::Locked;

// ---- memory -------------------------------------------------------------

/// Every block starts with a header holding its total size, so `memoryFree`
/// can rebuild the layout; 16-byte alignment as `malloc` gives.
const HEADER: usize = 16;

unsafe extern "C" fn memory_alloc(
    _handle: *mut c_void,
    n_bytes: usize,
    out: *mut *mut c_void,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_alloc", || {
        if out.is_null() {
            return kOfxStatErrBadHandle;
        }
        let Some(total) = n_bytes.checked_add(HEADER) else {
            return kOfxStatErrMemory;
        };
        let Ok(layout) = Layout::from_size_align(total, HEADER) else {
            return kOfxStatErrMemory;
        };
        // SAFETY: `layout` has a non-zero size (HEADER > 0).
        let base = unsafe { std::alloc::alloc(layout) };
        if base.is_null() {
            return kOfxStatErrMemory;
        }
        // SAFETY: `base` is valid for `total >= HEADER` bytes and 16-aligned;
        // `out` was checked non-null and points to the plugin's pointer slot.
        unsafe {
            (base as *mut usize).write(total);
            *out = base.add(HEADER) as *mut c_void;
        }
        kOfxStatOK
    })
}

unsafe extern "C" fn memory_free(data: *mut c_void) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "memory_free", || {
        if data.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: `data` came from `memory_alloc`, so HEADER bytes before it hold
        // the block's total size and the block was allocated with this layout.
        unsafe {
            let base = (data as *mut u8).sub(HEADER);
            let total = (base as *const usize).read();
            std::alloc::dealloc(base, Layout::from_size_align_unchecked(total, HEADER));
        }
        kOfxStatOK
    })
}

pub static MEMORY_SUITE: OfxMemorySuiteV1 = OfxMemorySuiteV1 {
    memoryAlloc: Some(memory_alloc),
    memoryFree: Some(memory_free),
};

// ---- multi-thread -------------------------------------------------------

thread_local! {
    /// This thread's index inside a `multiThread` call, if it was spawned by one.
    static THREAD_INDEX: std::cell::Cell<Option<c_uint>> = const { std::cell::Cell::new(None) };
}

fn cpus() -> c_uint {
    std::thread::available_parallelism().map_or(1, |n| n.get() as c_uint)
}

unsafe extern "C" fn multi_thread(
    func: OfxThreadFunctionV1,
    n_threads: c_uint,
    arg: *mut c_void,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "multi_thread", || {
        let Some(func) = func else {
            return kOfxStatErrBadHandle;
        };
        let n = if n_threads == 0 { cpus() } else { n_threads };
        let arg = arg as usize;
        let panicked = std::thread::scope(|s| {
            let handles: Vec<_> = (0..n)
                .map(|k| {
                    s.spawn(move || {
                        THREAD_INDEX.with(|t| t.set(Some(k)));
                        // SAFETY: the plugin's own function with its own argument,
                        // called as the multi-thread suite specifies.
                        unsafe { func(k, n, arg as *mut c_void) }
                    })
                })
                .collect();
            handles.into_iter().any(|h| h.join().is_err())
        });
        if panicked {
            kOfxStatFailed
        } else {
            kOfxStatOK
        }
    })
}

unsafe extern "C" fn multi_thread_num_cpus(n: *mut c_uint) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "multi_thread_num_cpus", || {
        if n.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: checked non-null; the plugin passes a pointer to its variable.
        unsafe { *n = cpus() };
        kOfxStatOK
    })
}

unsafe extern "C" fn multi_thread_index(index: *mut c_uint) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "multi_thread_index", || {
        if index.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: checked non-null.
        unsafe { *index = THREAD_INDEX.with(|t| t.get()).unwrap_or(0) };
        kOfxStatOK
    })
}

unsafe extern "C" fn multi_thread_is_spawned() -> c_int {
    super::guard::guard(0, "multi_thread_is_spawned", || {
        THREAD_INDEX.with(|t| t.get()).is_some() as c_int
    })
}

/// A recursive mutex (OFX mutexes may be locked again by their owner).
struct RecursiveMutex {
    state: Mutex<(Option<std::thread::ThreadId>, c_int)>,
    freed: Condvar,
}

impl RecursiveMutex {
    fn try_lock(&self, wait: bool) -> bool {
        let me = std::thread::current().id();
        let mut s = self.state.locked();
        loop {
            match s.0 {
                None => {
                    *s = (Some(me), 1);
                    return true;
                }
                Some(owner) if owner == me => {
                    s.1 += 1;
                    return true;
                }
                Some(_) if wait => s = self.freed.wait(s).unwrap_or_else(|e| e.into_inner()),
                Some(_) => return false,
            }
        }
    }

    fn unlock(&self) -> bool {
        let me = std::thread::current().id();
        let mut s = self.state.locked();
        if s.0 != Some(me) {
            return false;
        }
        s.1 -= 1;
        if s.1 == 0 {
            s.0 = None;
            self.freed.notify_one();
        }
        true
    }
}

unsafe fn mutex_of<'a>(m: OfxMutexHandle) -> Option<&'a RecursiveMutex> {
    // SAFETY: mutex handles we hand out are leaked boxes until `mutexDestroy`.
    unsafe { (m as *const RecursiveMutex).as_ref() }
}

unsafe extern "C" fn mutex_create(out: *mut OfxMutexHandle, lock_count: c_int) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "mutex_create", || {
        if out.is_null() {
            return kOfxStatErrBadHandle;
        }
        let m = Box::new(RecursiveMutex {
            state: Mutex::new((None, 0)),
            freed: Condvar::new(),
        });
        for _ in 0..lock_count.max(0) {
            m.try_lock(true);
        }
        // SAFETY: checked non-null; ownership of the box passes to the handle.
        unsafe { *out = Box::into_raw(m) as OfxMutexHandle };
        kOfxStatOK
    })
}

unsafe extern "C" fn mutex_destroy(m: OfxMutexHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "mutex_destroy", || {
        if m.is_null() {
            return kOfxStatErrBadHandle;
        }
        // SAFETY: `m` came from `mutex_create` and is destroyed once.
        drop(unsafe { Box::from_raw(m as *mut RecursiveMutex) });
        kOfxStatOK
    })
}

unsafe extern "C" fn mutex_lock(m: OfxMutexHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "mutex_lock", || {
        // SAFETY: see `mutex_of`.
        match unsafe { mutex_of(m) } {
            Some(m) if m.try_lock(true) => kOfxStatOK,
            _ => kOfxStatErrBadHandle,
        }
    })
}

unsafe extern "C" fn mutex_unlock(m: OfxMutexHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "mutex_unlock", || {
        // SAFETY: see `mutex_of`.
        match unsafe { mutex_of(m) } {
            Some(m) if m.unlock() => kOfxStatOK,
            _ => kOfxStatErrBadHandle,
        }
    })
}

unsafe extern "C" fn mutex_try_lock(m: OfxMutexHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "mutex_try_lock", || {
        // SAFETY: see `mutex_of`.
        match unsafe { mutex_of(m) } {
            Some(m) if m.try_lock(false) => kOfxStatOK,
            Some(_) => kOfxStatFailed,
            None => kOfxStatErrBadHandle,
        }
    })
}

pub static MULTI_THREAD_SUITE: OfxMultiThreadSuiteV1 = OfxMultiThreadSuiteV1 {
    multiThread: Some(multi_thread),
    multiThreadNumCPUs: Some(multi_thread_num_cpus),
    multiThreadIndex: Some(multi_thread_index),
    multiThreadIsSpawnedThread: Some(multi_thread_is_spawned),
    mutexCreate: Some(mutex_create),
    mutexDestroy: Some(mutex_destroy),
    mutexLock: Some(mutex_lock),
    mutexUnLock: Some(mutex_unlock),
    mutexTryLock: Some(mutex_try_lock),
};

// ---- progress -----------------------------------------------------------

unsafe fn text(s: *const c_char) -> String {
    if s.is_null() {
        String::new()
    } else {
        // SAFETY: OFX strings are NUL-terminated.
        unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned()
    }
}

unsafe extern "C" fn progress_start_v2(
    instance: *mut c_void,
    message: *const c_char,
    _id: *const c_char,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "progress_start_v2", || {
        let Some(e) = live_effect(instance) else {
            return kOfxStatErrBadHandle;
        };
        // SAFETY: see `text`.
        let label = unsafe { text(message) };
        *e.progress.locked() = Some((label, 0.0));
        kOfxStatOK
    })
}

unsafe extern "C" fn progress_start_v1(instance: *mut c_void, label: *const c_char) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "progress_start_v1", || {
        // SAFETY: same contract as V2 without a message id.
        unsafe { progress_start_v2(instance, label, std::ptr::null()) }
    })
}

unsafe extern "C" fn progress_update(instance: *mut c_void, progress: f64) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "progress_update", || {
        let Some(e) = live_effect(instance) else {
            return kOfxStatErrBadHandle;
        };
        match e.progress.locked().as_mut() {
            Some(task) => {
                task.1 = progress.clamp(0.0, 1.0);
                e.progress_log.locked().push(task.1);
                match *e.cancel_at.locked() {
                    Some(at) if task.1 >= at => kOfxStatReplyNo,
                    _ => kOfxStatOK,
                }
            }
            None => kOfxStatFailed,
        }
    })
}

unsafe extern "C" fn progress_end(instance: *mut c_void) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "progress_end", || {
        let Some(e) = live_effect(instance) else {
            return kOfxStatErrBadHandle;
        };
        *e.progress.locked() = None;
        kOfxStatOK
    })
}

pub static PROGRESS_SUITE_V1: OfxProgressSuiteV1 = OfxProgressSuiteV1 {
    progressStart: Some(progress_start_v1),
    progressUpdate: Some(progress_update),
    progressEnd: Some(progress_end),
};

pub static PROGRESS_SUITE_V2: OfxProgressSuiteV2 = OfxProgressSuiteV2 {
    progressStart: Some(progress_start_v2),
    progressUpdate: Some(progress_update),
    progressEnd: Some(progress_end),
};

// ---- time line ----------------------------------------------------------

unsafe extern "C" fn get_time(instance: *mut c_void, time: *mut f64) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_time", || {
        match live_effect(instance) {
            Some(e) if !time.is_null() => {
                let t = e.timeline.locked().0;
                // SAFETY: checked non-null.
                unsafe { *time = t };
                kOfxStatOK
            }
            _ => kOfxStatErrBadHandle,
        }
    })
}

unsafe extern "C" fn goto_time(instance: *mut c_void, time: f64) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "goto_time", || {
        match live_effect(instance) {
            Some(e) if time.is_finite() => {
                e.timeline.locked().0 = time;
                kOfxStatOK
            }
            Some(_) => kOfxStatErrValue,
            None => kOfxStatErrBadHandle,
        }
    })
}

unsafe extern "C" fn get_time_bounds(
    instance: *mut c_void,
    first: *mut f64,
    last: *mut f64,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_time_bounds", || {
        match live_effect(instance) {
            Some(e) if !first.is_null() && !last.is_null() => {
                let (_, a, b) = *e.timeline.locked();
                // SAFETY: both checked non-null.
                unsafe {
                    *first = a;
                    *last = b;
                }
                kOfxStatOK
            }
            _ => kOfxStatErrBadHandle,
        }
    })
}

pub static TIME_LINE_SUITE: OfxTimeLineSuiteV1 = OfxTimeLineSuiteV1 {
    getTime: Some(get_time),
    gotoTime: Some(goto_time),
    getTimeBounds: Some(get_time_bounds),
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::host::Effect;
    use std::sync::atomic::{AtomicU32, Ordering};

    #[test]
    fn memory_blocks_are_aligned_writable_and_freed() {
        let mut p: *mut c_void = std::ptr::null_mut();
        // SAFETY: a valid out pointer; the block is written within its size and freed once.
        unsafe {
            assert_eq!(memory_alloc(std::ptr::null_mut(), 1000, &mut p), kOfxStatOK);
            assert_eq!(p as usize % 16, 0);
            std::ptr::write_bytes(p as *mut u8, 0xAB, 1000);
            assert_eq!(memory_free(p), kOfxStatOK);
            assert_eq!(memory_free(std::ptr::null_mut()), kOfxStatErrBadHandle);
            assert_eq!(
                memory_alloc(std::ptr::null_mut(), usize::MAX, &mut p),
                kOfxStatErrMemory
            );
        }
    }

    unsafe extern "C" fn count(index: c_uint, max: c_uint, arg: *mut c_void) {
        // SAFETY: the test passes a pointer to an AtomicU32 that outlives the call.
        let hits = unsafe { &*(arg as *const AtomicU32) };
        assert!(index < max);
        let mut me = 99;
        // SAFETY: a valid out pointer.
        unsafe { multi_thread_index(&mut me) };
        assert_eq!(me, index);
        // SAFETY: no arguments.
        assert_eq!(unsafe { multi_thread_is_spawned() }, 1);
        hits.fetch_add(1 << index, Ordering::SeqCst);
    }

    #[test]
    fn multi_thread_runs_each_index_once_and_mutexes_exclude() {
        let hits = AtomicU32::new(0);
        // SAFETY: `count` reads `hits`, which lives across the call.
        let st = unsafe { multi_thread(Some(count), 5, &hits as *const _ as *mut c_void) };
        assert_eq!(st, kOfxStatOK);
        assert_eq!(hits.load(Ordering::SeqCst), 0b11111);
        // SAFETY: no arguments.
        assert_eq!(unsafe { multi_thread_is_spawned() }, 0);

        let mut m: OfxMutexHandle = std::ptr::null_mut();
        // SAFETY: handles from mutex_create, used and destroyed in order.
        unsafe {
            assert_eq!(mutex_create(&mut m, 0), kOfxStatOK);
            assert_eq!(mutex_lock(m), kOfxStatOK);
            assert_eq!(mutex_try_lock(m), kOfxStatOK, "recursive for its owner");
            let mp = m as usize;
            let other = std::thread::spawn(move || mutex_try_lock(mp as OfxMutexHandle))
                .join()
                .unwrap();
            assert_eq!(other, kOfxStatFailed, "held by another thread");
            assert_eq!(mutex_unlock(m), kOfxStatOK);
            assert_eq!(mutex_unlock(m), kOfxStatOK);
            assert_eq!(mutex_unlock(m), kOfxStatErrBadHandle, "not held");
            assert_eq!(mutex_destroy(m), kOfxStatOK);
        }
    }

    #[test]
    fn progress_and_time_line_track_the_effect_and_refuse_unknown_handles() {
        let e = Effect::new();
        let h = e.handle() as *mut c_void;
        *e.timeline.lock().unwrap() = (1010.0, 1001.0, 1048.0);
        let (mut t, mut a, mut b) = (0.0, 0.0, 0.0);
        // SAFETY: live effect handle and valid out pointers; bogus handle refused.
        unsafe {
            assert_eq!(
                progress_start_v2(h, c"Solving".as_ptr(), std::ptr::null()),
                kOfxStatOK
            );
            assert_eq!(progress_update(h, 0.25), kOfxStatOK);
            assert_eq!(
                *e.progress.lock().unwrap(),
                Some(("Solving".to_string(), 0.25))
            );
            assert_eq!(progress_end(h), kOfxStatOK);
            assert_eq!(progress_update(h, 0.5), kOfxStatFailed, "no task open");
            assert_eq!(get_time(h, &mut t), kOfxStatOK);
            assert_eq!(get_time_bounds(h, &mut a, &mut b), kOfxStatOK);
            assert_eq!((t, a, b), (1010.0, 1001.0, 1048.0));
            assert_eq!(goto_time(h, 1020.0), kOfxStatOK);
            assert_eq!(get_time(h, &mut t), kOfxStatOK);
            assert_eq!(t, 1020.0);
            let bogus = 0x10 as *mut c_void;
            assert_eq!(get_time(bogus, &mut t), kOfxStatErrBadHandle);
            assert_eq!(progress_update(bogus, 0.1), kOfxStatErrBadHandle);
        }
    }
}
