//! The Morph node: Source A and Source B warped toward the same features and
//! dissolved. General context (SourceA, SourceB) and transition context
//! (SourceFrom, SourceTo, progress from the host's Transition param).

use super::NodeInfo;

pub const INFO: NodeInfo = NodeInfo {
    id: "net.morphfx.Morph",
    label: "MorphFX Morph",
    description: "Feature-based morph (Beier-Neely field warping): warps A and B toward the in-between feature positions and dissolves them.",
    contexts: &[c"OfxImageEffectContextGeneral", c"OfxImageEffectContextTransition"],
};

/// Clip names (A, B) in a context.
pub fn source_clips(context: &str) -> [&'static str; 2] {
    if context == "OfxImageEffectContextTransition" {
        ["SourceFrom", "SourceTo"]
    } else {
        ["SourceA", "SourceB"]
    }
}
