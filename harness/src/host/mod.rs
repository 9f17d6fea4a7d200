//! The host side of OpenFX: loads a bundle through its C ABI and drives the
//! action sequence a real host follows. All `unsafe` of the harness lives in
//! this module, each block with its safety argument.

pub mod allocator;
mod bundle;
mod checks;
pub mod effect;
pub mod frame;
pub mod guard;
mod instance;
mod interact_suites;
pub mod misuse;
pub mod overlay;
pub mod params;
pub mod planes;
pub mod props;
pub mod services;

pub use crate::error::{ErrorKind, HostError, BAD_INPUT_ID};
pub use bundle::{bundle_binary, this_binary, Bundle, HostOptions, PluginInfo};
#[cfg(test)]
pub(crate) use checks::VIOLATION_TESTS;
pub use checks::{host_failure, take_violations, violation};
pub use effect::{take_unowned_messages, Effect, FrameSource, Message};
pub use frame::Frame;
pub use instance::{ClipPlanes, Instance, OutputSpec};
