//! The Warp node: one source warped toward the features' positions at `t`
//! (t = 1 lands A's features on B's positions). Filter and general contexts.

use std::ffi::CStr;

use super::{Node, NodeKind, NodeState};
use crate::wrapper::plugin::Context;

pub struct Warp(NodeState);

impl Node for Warp {
    const KIND: NodeKind = NodeKind::Warp;
    const ID: &'static CStr = c"net.morphfx.Warp";
    const LABEL: &'static str = "MorphFX Warp";
    const DESCRIPTION: &'static str =
        "Warps one image so its features (A positions) move toward their B positions by progress t.";
    const CONTEXTS: &'static [Context] = &[Context::Filter, Context::General];
    fn new(state: NodeState) -> Self {
        Warp(state)
    }
    fn state(&self) -> &NodeState {
        &self.0
    }
}

pub const SOURCE_CLIP: &str = "Source";
