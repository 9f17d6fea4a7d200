//! Ctrl-C and SIGTERM (how farm managers stop a job): the frame being
//! rendered is dropped, the frames already rendered finish writing, and
//! `morphfx` names the first frame not written, says which are complete and
//! exits with status 2 (the contract's statuses are 0, 2 and 1), leaving no
//! partial file under any name. A second signal stops at once.

use std::sync::atomic::{AtomicUsize, Ordering};

static SIGNALS: AtomicUsize = AtomicUsize::new(0);

/// Handles SIGINT and SIGTERM from now on. A failure to install (another
/// handler owns them) leaves the default: the process dies, and outputs
/// still never stand half-written under their final names.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        if SIGNALS.fetch_add(1, Ordering::SeqCst) > 0 {
            eprintln!("morphfx: interrupted again: stopping now");
            // The status the first signal's message would have ended with.
            std::process::exit(2);
        }
        eprintln!("morphfx: interrupted: finishing the frames already rendered");
    });
}

/// Whether the user (or the farm) asked the run to stop.
pub fn requested() -> bool {
    SIGNALS.load(Ordering::SeqCst) > 0
}
