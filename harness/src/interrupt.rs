//! Ctrl-C and SIGTERM (how farm managers stop a job): the frame being
//! rendered is dropped, the frames already rendered finish writing, and
//! `morphfx` says which frames are complete and exits with status 130,
//! leaving no partial file under any name. A second signal stops at once.

use std::sync::atomic::{AtomicUsize, Ordering};

static SIGNALS: AtomicUsize = AtomicUsize::new(0);

/// The exit status of an interrupted run (128 + SIGINT, as shells report it).
pub const EXIT_STATUS: i32 = 130;

/// Handles SIGINT and SIGTERM from now on. A failure to install (another
/// handler owns them) leaves the default: the process dies, and outputs
/// still never stand half-written under their final names.
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        if SIGNALS.fetch_add(1, Ordering::SeqCst) > 0 {
            eprintln!("morphfx: interrupted again: stopping now");
            std::process::exit(EXIT_STATUS);
        }
        eprintln!("morphfx: interrupted: finishing the frames already rendered");
    });
}

/// Whether the user (or the farm) asked the run to stop.
pub fn requested() -> bool {
    SIGNALS.load(Ordering::SeqCst) > 0
}
