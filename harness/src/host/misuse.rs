//! Ways this host can be made to misbehave as hosts in the field do, so that
//! tests can hold the plugin to its answer for each: a clear failure status
//! and a message, never a crash. Nothing here is armed in normal use.
//!
//! What is armed holds for the whole process (the plugin has one host), so
//! [`arm`] also serialises the tests that use it: it waits for the previous
//! arming to be dropped.

use std::ffi::CStr;
use std::sync::{Mutex, MutexGuard};

use super::props::PropertySet;
use crate::sync::Locked;

/// One kind of misbehaviour.
#[derive(Clone, Copy)]
pub enum Misuse {
    /// `fetchSuite` answers null for this suite, whatever the version.
    WithholdSuite(&'static CStr),
    /// `clipGetImage` on this clip fails (`kOfxStatFailed`) with no message
    /// of the host's own.
    NoImage(&'static str),
    /// Every image `clipGetImage` hands out for this clip has its
    /// properties passed through this function first.
    TamperImage(&'static str, fn(&PropertySet)),
    /// `paramGetValue` and `paramGetValueAtTime` answer `kOfxStatErrUnknown`.
    UnreadableParams,
    /// The instance's param (first) is made with another OFX type
    /// (second) than its descriptor has.
    ParamType(&'static str, &'static str),
    /// The message suites print a message's format without its arguments,
    /// as Natron 2.5 does: `%%` as `%`, any other conversion as nothing.
    MessageArgumentsLost,
}

static ARMED: Mutex<Vec<Misuse>> = Mutex::new(Vec::new());
static SERIAL: Mutex<()> = Mutex::new(());

/// Misuses in force until dropped.
pub struct Armed {
    _serial: MutexGuard<'static, ()>,
}

impl Drop for Armed {
    fn drop(&mut self) {
        armed().clear();
    }
}

/// Arms `misuses` (none: a well-behaved host, still serialised with the
/// tests that arm some) until the returned value is dropped.
pub fn arm(misuses: &[Misuse]) -> Armed {
    let serial = SERIAL.locked();
    *armed() = misuses.to_vec();
    Armed { _serial: serial }
}

fn armed() -> MutexGuard<'static, Vec<Misuse>> {
    ARMED.locked()
}

pub(crate) fn withholds(suite: &CStr) -> bool {
    armed()
        .iter()
        .any(|m| matches!(m, Misuse::WithholdSuite(s) if *s == suite))
}

pub(crate) fn no_image(clip: &str) -> bool {
    armed()
        .iter()
        .any(|m| matches!(m, Misuse::NoImage(c) if *c == clip))
}

pub(crate) fn tamper_image(clip: &str, props: &PropertySet) {
    let tampers: Vec<fn(&PropertySet)> = armed()
        .iter()
        .filter_map(|m| match m {
            Misuse::TamperImage(c, f) if *c == clip => Some(*f),
            _ => None,
        })
        .collect();
    for f in tampers {
        f(props);
    }
}

pub(crate) fn params_unreadable() -> bool {
    armed()
        .iter()
        .any(|m| matches!(m, Misuse::UnreadableParams))
}

/// The type an instance's param `name` is armed to be made with.
pub(crate) fn param_type(name: &str) -> Option<&'static str> {
    armed().iter().find_map(|m| match m {
        Misuse::ParamType(p, kind) if *p == name => Some(*kind),
        _ => None,
    })
}

/// Asked by the message suites' C shim for each message.
#[unsafe(no_mangle)]
pub extern "C" fn mfx_messages_lose_arguments() -> std::ffi::c_int {
    super::guard::guard(0, "mfx_messages_lose_arguments", || {
        armed()
            .iter()
            .any(|m| matches!(m, Misuse::MessageArgumentsLost)) as std::ffi::c_int
    })
}
