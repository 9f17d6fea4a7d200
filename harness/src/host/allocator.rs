//! The process's allocator, set for rendering frames.
//!
//! glibc gives each thread that allocates its own arena (up to eight per
//! core). A sequence render allocates 30 MB frames on the reader, the
//! render and the writer threads; memory a frame freed in one arena cannot
//! hold the next frame allocated in another, so the resident size grows
//! with the threads, not with the work: 709 MB for a 1080p morph that needs
//! under 400 (docs/PERFORMANCE.md). Two arenas keep it at 375 MB, at the
//! same speed.

/// Limits glibc to two arenas. Call before any other thread starts.
pub fn tune_for_frames() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a parameter of glibc's allocator; it is
    // called at start-up, before the process has other threads.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 2);
    }
}
