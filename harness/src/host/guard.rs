//! Every function this host hands a plugin runs under [`guard`]: a panic in
//! our own code (a bug, or an assertion about what the plugin sent) is
//! caught before it reaches the plugin's C frames, recorded, and answered
//! with a failure the plugin can handle, never an unwind through C (which
//! Rust would turn into an abort of the whole process).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use crate::sync::Locked;

/// The callback a test arms to panic on its next call ([`panic_in`]).
static ARMED: Mutex<Option<&'static str>> = Mutex::new(None);

/// Makes the next call of host callback `name` panic (tests of [`guard`]).
pub fn panic_in(name: Option<&'static str>) {
    *ARMED.locked() = name;
}

/// Runs callback `name`'s `body`; on a panic, records it as a host failure
/// and returns `on_panic`.
pub fn guard<R>(on_panic: R, name: &'static str, body: impl FnOnce() -> R) -> R {
    let run = AssertUnwindSafe(|| {
        let armed = {
            let mut a = ARMED.locked();
            a.take_if(|n| *n == name).is_some()
        };
        if armed {
            panic!("{name}: armed to panic by a test");
        }
        body()
    });
    match catch_unwind(run) {
        Ok(r) => r,
        Err(e) => {
            let why = e
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| e.downcast_ref::<&str>().copied())
                .unwrap_or("a panic");
            super::checks::host_failure(format!("host callback {name} panicked: {why}"));
            on_panic
        }
    }
}
