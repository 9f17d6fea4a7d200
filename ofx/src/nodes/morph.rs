//! The Morph node: Source A and Source B warped toward the same features and
//! dissolved. General context (SourceA, SourceB) and transition context
//! (SourceFrom, SourceTo, progress from the host's Transition param).

use std::ffi::CStr;

use super::{Node, NodeKind, NodeState};
use crate::wrapper::plugin::Context;

pub struct Morph(NodeState);

impl Node for Morph {
    const KIND: NodeKind = NodeKind::Morph;
    const ID: &'static CStr = c"net.morphfx.Morph";
    const LABEL: &'static str = "MorphFX Morph";
    const DESCRIPTION: &'static str = "Feature-based morph (Beier-Neely field warping): warps A and B toward the in-between feature positions and dissolves them.";
    const CONTEXTS: &'static [Context] = &[Context::General, Context::Transition];
    fn new(state: NodeState) -> Self {
        Morph(state)
    }
    fn state(&self) -> &NodeState {
        &self.0
    }
}

/// Clip names (A, B) in a context.
pub fn source_clips(context: Context) -> [&'static str; 2] {
    if context == Context::Transition {
        ["SourceFrom", "SourceTo"]
    } else {
        ["SourceA", "SourceB"]
    }
}
