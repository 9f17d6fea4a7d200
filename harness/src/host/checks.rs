//! What this host saw a plugin do against the spec, and its own failures:
//! recorded as they happen, for tests to fail on.

use std::sync::Mutex;

use crate::sync::Locked;

/// What this host saw a plugin do against the spec, for tests to fail on.
static VIOLATIONS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Records a spec violation by the plugin (and says it on stderr).
pub fn violation(what: String) {
    eprintln!("morphfx: the plugin broke the OpenFX spec: {what}");
    VIOLATIONS.locked().push(what);
}

/// Records a failure of this host itself (a callback that panicked): kept
/// with the violations, so tests fail on it, but not blamed on the plugin.
pub fn host_failure(what: String) {
    eprintln!("morphfx: host failure: {what}");
    VIOLATIONS.locked().push(what);
}

/// Held by unit tests that read [`take_violations`], which is process-wide.
#[cfg(test)]
pub(crate) static VIOLATION_TESTS: Mutex<()> = Mutex::new(());

/// The spec violations seen so far in this process (taken).
pub fn take_violations() -> Vec<String> {
    std::mem::take(&mut *VIOLATIONS.locked())
}
