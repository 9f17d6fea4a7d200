//! The Morph node: Source A and Source B warped toward the same features and
//! dissolved. General context (SourceA, SourceB) and transition context
//! (SourceFrom, SourceTo, progress from the host's Transition param).

use morphfx::choice::Choice;
use morphfx::make_warp::Method;
use morphfx::views::View;

use super::kind::{NodeKind, Sources};
use super::node::Node;
use ofx_layer::plugin::Context;

pub struct Morph;

impl Node for Morph {
    const KIND: &'static NodeKind = &NodeKind {
        id: c"net.morphfx.Morph",
        label: "MorphFX Morph",
        description: "Feature-based morph (Beier-Neely field warping): warps A and \
            B toward the in-between feature positions and dissolves \
            them.",
        contexts: &[Context::General, Context::Transition],
        sources: Sources::Two {
            general: ["SourceA", "SourceB"],
            transition: ["SourceFrom", "SourceTo"],
        },
        timing_matte: true,
        methods: Method::ALL,
        views: View::ALL,
        view_labels: &[],
    };
}
