//! The image effect contexts a node can be made in.

use std::ffi::CStr;

use super::{Failure, Outcome};

/// The contexts (OFX "image effect contexts") a node can be made in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Context {
    /// One `Source` clip.
    Filter,
    /// Any clips the node defines.
    General,
    /// `SourceFrom` and `SourceTo`, and the host's `Transition` param.
    Transition,
}

impl Context {
    pub const ALL: [Context; 3] = [Context::Filter, Context::General, Context::Transition];

    /// The spec's name of the context.
    pub fn name(self) -> &'static CStr {
        match self {
            Context::Filter => c"OfxImageEffectContextFilter",
            Context::General => c"OfxImageEffectContextGeneral",
            Context::Transition => c"OfxImageEffectContextTransition",
        }
    }

    /// The context the spec calls `name`, if a node can be made in it.
    pub fn named(name: &str) -> Option<Context> {
        Context::ALL
            .into_iter()
            .find(|c| c.name().to_bytes() == name.as_bytes())
    }
}

impl Context {
    /// The context the host names `name`, or the error that names it.
    pub(super) fn from_host(name: &str) -> Outcome<Context> {
        Context::named(name).ok_or_else(|| {
            Failure::Failed(format!(
                "context {name} is not one this plugin can be made in"
            ))
        })
    }
}
