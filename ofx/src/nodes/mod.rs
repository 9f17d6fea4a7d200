//! The nodes, in safe Rust: what each declares (clips, params, capabilities)
//! and what each does per action. Every node is a [`Node`]: a name, a kind
//! and its [`NodeState`]; the generic layer (`wrapper`) reaches it as an
//! [`ImageEffect`] through the impl below, with typed arguments.
#![forbid(unsafe_code)]

mod lines;
pub mod morph;
pub mod overlay;
pub mod params;
mod render;
mod snap;
mod state;
mod track;
pub mod warp;

use std::ffi::CStr;

use morphfx::geom::RectD;

use crate::wrapper::clips::EffectHandle;
use crate::wrapper::params::Params;
use crate::wrapper::plugin::{
    Capabilities, ClipPreferences, ClipSpec, Components, Context, ContextSpec, FramesNeeded,
    Identity, ImageEffect, ParamChange, PixelDepth, RenderArgs, Rois, Sequential, ThreadSafety,
};
use crate::wrapper::{Outcome, Reply};
pub use morph::Morph;
pub use state::NodeState;
pub use warp::Warp;

/// Which node: the two differ in their sources, contexts and a few params.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeKind {
    Morph,
    Warp,
}

impl NodeKind {
    /// The source clips in `context`: (A, B) for Morph, (Source, none) for Warp.
    pub fn source_clips(self, context: Context) -> (&'static str, Option<&'static str>) {
        match self {
            NodeKind::Morph => {
                let [a, b] = morph::source_clips(context);
                (a, Some(b))
            }
            NodeKind::Warp => (warp::SOURCE_CLIP, None),
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            NodeKind::Morph => <Morph as Node>::LABEL,
            NodeKind::Warp => <Warp as Node>::LABEL,
        }
    }
}

/// A MorphFX node type: what sets it apart, and its state.
pub trait Node: Sized + Send + Sync + 'static {
    const KIND: NodeKind;
    const ID: &'static CStr;
    const LABEL: &'static str;
    const DESCRIPTION: &'static str;
    const CONTEXTS: &'static [Context];
    fn new(state: NodeState) -> Self;
    fn state(&self) -> &NodeState;
}

/// Both nodes' version.
pub const VERSION: (u32, u32) = (1, 0);

/// The pixel layouts every clip takes.
const COMPONENTS: &[Components] = &[Components::Rgba, Components::Rgb, Components::Alpha];

/// The layouts the mask and timing clips take: their alpha is what counts,
/// and a matte with no alpha (a grey or RGB render) counts by the mean of
/// its R, G and B, so a host hands it over as RGB rather than with an
/// alpha of 1 filled in.
const MATTE_COMPONENTS: &[Components] = &[Components::Alpha, Components::Rgba, Components::Rgb];

/// The optional mask input of both nodes: where the effect applies.
pub const MASK_CLIP: &str = "Mask";

/// The Morph node's optional timing matte: when each point of A turns.
pub const TIMING_CLIP: &str = "Timing";

impl<N: Node> ImageEffect for N {
    const ID: &'static CStr = N::ID;
    const VERSION: (u32, u32) = VERSION;
    const LABEL: &'static str = N::LABEL;
    const DESCRIPTION: &'static str = N::DESCRIPTION;
    const GROUPING: &'static str = "MorphFX";
    const CONTEXTS: &'static [Context] = N::CONTEXTS;
    const CAPABILITIES: Capabilities = Capabilities {
        depths: &[PixelDepth::Byte, PixelDepth::Short, PixelDepth::Float],
        thread_safety: ThreadSafety::FullySafe,
        // We split the window across threads ourselves (rayon).
        host_frame_threading: false,
        tiles: true,
        multi_resolution: true,
        temporal_access: true,
        multiple_clip_depths: false,
        multiple_clip_aspects: false,
        // Warm starts make a sequence cheaper in frame order, but any order
        // is correct (they are used only when the host says it renders in
        // order). FieldRenderTwiceAlways keeps its default (render each
        // field): a geometric warp must not mix the fields of interlaced
        // footage.
        sequential: Sequential::Preferred,
    };
    type Overlay = overlay::SlotOverlay;

    fn describe_in_context(context: Context) -> ContextSpec {
        let (a, b) = N::KIND.source_clips(context);
        let source = |name| ClipSpec {
            name,
            components: COMPONENTS,
            tiles: true,
            temporal_access: true,
            optional: false,
            mask: false,
        };
        let mut clips: Vec<ClipSpec> = std::iter::once(a).chain(b).map(source).collect();
        // Mattes: alpha is what is read (an RGB matte's mean); the timing
        // matte may be read anywhere on A.
        let matte = |name, mask| ClipSpec {
            name,
            components: MATTE_COMPONENTS,
            tiles: true,
            temporal_access: false,
            optional: true,
            mask,
        };
        if N::KIND == NodeKind::Morph {
            clips.push(matte(TIMING_CLIP, false));
        }
        clips.push(matte(MASK_CLIP, true));
        clips.push(ClipSpec {
            temporal_access: false,
            ..source("Output")
        });
        ContextSpec {
            clips,
            params: params::table_in_context(N::KIND, context),
        }
    }

    fn create(_: &EffectHandle, context: Context, params: Params) -> Outcome<Self> {
        Ok(N::new(NodeState::create(N::KIND, context, params)))
    }

    fn purge(&self) {
        self.state().purge();
    }

    fn region_of_definition(&self, effect: &EffectHandle, time: f64) -> Outcome<Option<RectD>> {
        render::region_of_definition(self.state(), effect, time)
    }

    fn regions_of_interest(
        &self,
        effect: &EffectHandle,
        time: f64,
        out: &mut Rois,
    ) -> Outcome<Reply> {
        render::regions_of_interest(self.state(), effect, time, out)
    }

    fn frames_needed(
        &self,
        effect: &EffectHandle,
        time: f64,
        out: &mut FramesNeeded,
    ) -> Outcome<Reply> {
        render::frames_needed(self.state(), effect, time, out)
    }

    fn clip_preferences(&self, effect: &EffectHandle, out: &mut ClipPreferences) -> Outcome<Reply> {
        render::clip_preferences(self.state(), effect, out)
    }

    fn is_identity(&self, effect: &EffectHandle, args: &RenderArgs) -> Outcome<Option<Identity>> {
        render::is_identity(self.state(), effect, args)
    }

    fn render(&self, effect: &EffectHandle, args: &RenderArgs) -> Outcome {
        render::render(self.state(), effect, args)
    }

    fn param_changed(&self, effect: &EffectHandle, change: &ParamChange) -> Outcome {
        param_changed(self.state(), effect, change)
    }
}

/// A param changed: the buttons act, Line Count shows its slots.
fn param_changed(node: &NodeState, effect: &EffectHandle, change: &ParamChange) -> Outcome {
    let (name, time) = (change.name.as_str(), change.time);
    if name == params::SNAP_LINES.name() {
        snap::snap_lines(node, effect, time)
    } else if name == params::TRACK_FORWARD.name() {
        track::track_lines(node, effect, time, 1)
    } else if name == params::TRACK_BACKWARD.name() {
        track::track_lines(node, effect, time, -1)
    } else if name == params::FINISH_SHAPE.name() {
        overlay::finish_shape(node);
        Ok(())
    } else if name == params::DELETE_SHAPE.name() {
        overlay::delete_shape(node, effect, time)
    } else if name == params::KEY_SHAPES.name() {
        overlay::shapes::key_here(node, effect, time)
    } else if name == params::COPY_SCENE.name() {
        overlay::shapes::copy_scene(node, effect, time)
    } else if name == params::LINE_COUNT.name() {
        lines::hide_unused(node.kind, node.params(), time);
        Ok(())
    } else if let Some(k) = params::clear_button_slot(name) {
        lines::clear(node.kind, node.params(), k, time)
    } else {
        Ok(())
    }
}
