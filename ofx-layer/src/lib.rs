//! The generic OpenFX layer: all FFI and all `unsafe` of the plugin, and it
//! names no node. Nodes implement [`plugin::ImageEffect`] and its
//! [`plugin::Overlay`]; [`export!`] makes the bundle's entry points
//! from a list of node types. Each `unsafe` block states why it is sound;
//! every entry point null-checks, catches unwinds and maps errors to OFX
//! statuses (`dispatch`, `interact`): no panic crosses the C ABI.

mod attach;
pub mod clips;
mod context;
mod cpu;
mod describe;
mod dispatch;
mod draw;
pub mod exports;
mod gl;
mod host;
mod interact;
pub mod keys;
pub mod paint;
pub mod params;
pub mod planes;
pub mod plugin;
mod props;
pub mod spec;
pub mod sync;

/// The OpenFX bindings the [`export!`] macro names.
#[doc(hidden)]
pub use openfx::sys;

pub use host::verbose;

use std::ffi::{CStr, CString};

use openfx::sys::generic::core::*;

/// Why an action did not succeed.
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// The user's input cannot be rendered (bad scene, missing clip, ...):
    /// reported through the message suite with id [`BAD_INPUT_ID`].
    BadInput(String),
    /// Something else went wrong; reported as an error message.
    Failed(String),
    /// A host call answered this status.
    Status(OfxStatus, String),
}

/// Message id under which bad-input errors are posted, so a host (our harness)
/// can tell the user's mistakes from internal failures.
pub const BAD_INPUT_ID: &CStr = c"net.morphfx.BadInput";

pub type Outcome<T = ()> = Result<T, Failure>;

/// How an action that did not fail ended: the nodes answer this, never an
/// `OfxStatus` (the layer alone speaks statuses).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply {
    /// Done (`kOfxStatOK`).
    Done,
    /// Left to the host's default behaviour (`kOfxStatReplyDefault`).
    Default,
}

impl From<morphfx::Error> for Failure {
    fn from(e: morphfx::Error) -> Self {
        match e {
            morphfx::Error::Unsupported(_)
            | morphfx::Error::Scene { .. }
            | morphfx::Error::Invalid(_) => Failure::BadInput(e.to_string()),
            morphfx::Error::Cancelled => Failure::Failed(e.to_string()),
        }
    }
}

impl Failure {
    pub fn status(&self) -> OfxStatus {
        match self {
            Failure::BadInput(_) | Failure::Failed(_) => kOfxStatFailed,
            Failure::Status(s, _) => *s,
        }
    }
    pub fn message(&self) -> &str {
        match self {
            Failure::BadInput(m) | Failure::Failed(m) | Failure::Status(_, m) => m,
        }
    }
}

/// `text` as a printf format that prints it as it is: every `%` doubled and
/// NULs made spaces. Messages go to the host as the format alone, with no
/// variadic argument: Natron 2.5 passes a message's `va_list` on as if it
/// were one argument, so a `"%s"` format with the text beside it arrives
/// blank there, while a format with no conversion reads nothing in any host.
pub fn printf_literal(text: &str) -> CString {
    CString::new(text.replace('\0', " ").replace('%', "%%")).unwrap_or_default()
}

/// Turns a host status into a result, naming the call that produced it.
pub fn check(status: OfxStatus, what: &str) -> Outcome {
    if status == kOfxStatOK {
        Ok(())
    } else {
        Err(Failure::Status(
            status,
            format!("{what} failed: the host answered {}", status_name(status)),
        ))
    }
}

/// A status as the spec names it, so a message read by a host's support
/// staff says what the host answered without a header to hand.
#[allow(non_upper_case_globals)] // the spec's names, matched as constants
pub fn status_name(status: OfxStatus) -> String {
    let name = match status {
        kOfxStatOK => "kOfxStatOK",
        kOfxStatFailed => "kOfxStatFailed",
        kOfxStatErrFatal => "kOfxStatErrFatal",
        kOfxStatErrUnknown => "kOfxStatErrUnknown",
        kOfxStatErrMissingHostFeature => "kOfxStatErrMissingHostFeature",
        kOfxStatErrUnsupported => "kOfxStatErrUnsupported",
        kOfxStatErrExists => "kOfxStatErrExists",
        kOfxStatErrFormat => "kOfxStatErrFormat",
        kOfxStatErrMemory => "kOfxStatErrMemory",
        kOfxStatErrBadHandle => "kOfxStatErrBadHandle",
        kOfxStatErrBadIndex => "kOfxStatErrBadIndex",
        kOfxStatErrValue => "kOfxStatErrValue",
        kOfxStatReplyYes => "kOfxStatReplyYes",
        kOfxStatReplyNo => "kOfxStatReplyNo",
        kOfxStatReplyDefault => "kOfxStatReplyDefault",
        _ => return format!("status {status}"),
    };
    format!("{name} ({status})")
}
