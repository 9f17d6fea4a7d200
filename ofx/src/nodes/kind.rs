//! What the nodes share as vocabulary: the [`NodeKind`] each node type
//! states about itself, and the clip names.
//! Everything that sets one node apart is a field of its kind, and the
//! rest of `nodes/` asks the kind named questions ([`NodeKind::has_b`],
//! [`NodeKind::methods`], ...): a new node type writes a kind, and the
//! compiler names any field it leaves out.

use std::ffi::CStr;

use morphfx::make_warp::Method;
use morphfx::views::View;

use ofx_layer::plugin::Context;

/// What a node type is: its identity for hosts, its inputs, and what it
/// offers. Every field is stated by the node's own file.
#[derive(Debug, PartialEq)]
pub struct NodeKind {
    /// The plugin identifier, reverse-domain style; also what tables are
    /// kept by.
    pub id: &'static CStr,
    pub label: &'static str,
    pub description: &'static str,
    pub contexts: &'static [Context],
    pub sources: Sources,
    /// Has the Timing matte input (when each point of A turns into B).
    pub timing_matte: bool,
    /// The Method param's options, in the order hosts save (only ever
    /// append).
    pub methods: &'static [Method],
    /// The View param's options, in the order hosts save.
    pub views: &'static [View],
    /// Views labelled otherwise than by their own name on this node.
    pub view_labels: &'static [(View, &'static str)],
}

/// A node's source clips.
#[derive(Debug, PartialEq)]
pub enum Sources {
    /// One source, named the same in every context.
    One(&'static str),
    /// Sources A and B: their names in the general and the transition
    /// context.
    Two {
        general: [&'static str; 2],
        transition: [&'static str; 2],
    },
}

impl NodeKind {
    /// The source clips in `context`: A, and B where the node has one.
    pub fn source_clips(&self, context: Context) -> (&'static str, Option<&'static str>) {
        match self.sources {
            Sources::One(a) => (a, None),
            Sources::Two { transition, .. } if context == Context::Transition => {
                (transition[0], Some(transition[1]))
            }
            Sources::Two { general, .. } => (general[0], Some(general[1])),
        }
    }

    /// Warps two sources toward each other and dissolves them (else warps
    /// its one source): B's clip, frame offset and views exist, and at
    /// t = 1 the output is B.
    pub fn has_b(&self) -> bool {
        matches!(self.sources, Sources::Two { .. })
    }

    /// Offers `auto`, the warp found from both pictures (and its params).
    pub fn has_auto(&self) -> bool {
        self.methods.contains(&Method::Auto)
    }

    /// `view`'s option label on this node.
    pub fn view_label(&self, view: View) -> &'static str {
        use morphfx::choice::Choice;
        self.view_labels
            .iter()
            .find(|(v, _)| *v == view)
            .map_or(view.name(), |(_, label)| label)
    }
}

/// Both nodes' version.
pub const VERSION: (u32, u32) = (1, 0);

/// The optional mask input of every node: where the effect applies.
pub const MASK_CLIP: &str = "Mask";

/// The optional timing matte of nodes that have one: when each point of A
/// turns.
pub const TIMING_CLIP: &str = "Timing";

/// The output clip, as the spec names it.
pub const OUTPUT_CLIP: &str = "Output";
