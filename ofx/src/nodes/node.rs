//! A node type as the OpenFX layer sees it: every [`Node`] is an
//! [`ImageEffect`] (its clips and params from its [`NodeKind`], its actions
//! handed to `render`, the buttons and the overlay), so a node's own file
//! states what it is and nothing more.

use std::ffi::CStr;
use std::marker::PhantomData;

use morphfx::geom::RectD;
use morphfx::warp::mesh::Line;

use super::kind::{NodeKind, MASK_CLIP, OUTPUT_CLIP, TIMING_CLIP, VERSION};
use super::state::NodeState;
use super::{grid, lines, overlay, params, render, snap, suggest, track};
use ofx_layer::clips::EffectHandle;
use ofx_layer::paint::Painter;
use ofx_layer::params::Params;
use ofx_layer::plugin::{
    Capabilities, ClipPlanes, ClipPreferences, ClipSpec, Components, Context, ContextSpec,
    DrawArgs, FramesNeeded, Identity, ImageEffect, Overlay, OverlayActions, ParamChange, Pen,
    PixelDepth, RenderArgs, Rois, Sequential, ThreadSafety,
};
use ofx_layer::{Outcome, Reply};

/// A MorphFX node type: a marker type stating what it is.
pub trait Node: Send + Sync + 'static {
    const KIND: &'static NodeKind;
}

/// An instance of node type `N`: what the OpenFX layer creates, holds and
/// hands each action to.
pub struct Effect<N> {
    state: NodeState,
    node: PhantomData<fn() -> N>,
}

impl<N> Effect<N> {
    fn state(&self) -> &NodeState {
        &self.state
    }
}

/// The pixel layouts every clip takes.
const COMPONENTS: &[Components] = &[Components::Rgba, Components::Rgb, Components::Alpha];

/// The layouts the mask and timing clips take: their alpha is what counts,
/// and a matte with no alpha (a grey or RGB render) counts by the mean of
/// its R, G and B, so a host hands it over as RGB rather than with an
/// alpha of 1 filled in.
const MATTE_COMPONENTS: &[Components] = &[Components::Alpha, Components::Rgba, Components::Rgb];

impl<N: Node> ImageEffect for Effect<N> {
    const ID: &'static CStr = N::KIND.id;
    const VERSION: (u32, u32) = VERSION;
    const LABEL: &'static str = N::KIND.label;
    const DESCRIPTION: &'static str = N::KIND.description;
    const GROUPING: &'static str = "MorphFX";
    const CONTEXTS: &'static [Context] = N::KIND.contexts;
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
    const OVERLAY: Option<OverlayActions<Self>> = Some(OverlayActions::of::<FeatureOverlay>());
    const MULTI_PLANE: bool = true;

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
        if N::KIND.timing_matte {
            clips.push(matte(TIMING_CLIP, false));
        }
        clips.push(matte(MASK_CLIP, true));
        clips.push(ClipSpec {
            temporal_access: false,
            ..source(OUTPUT_CLIP)
        });
        ContextSpec {
            clips,
            params: params::table_in_context(N::KIND, context),
        }
    }

    fn create(_: &EffectHandle, context: Context, params: Params) -> Outcome<Self> {
        lines::hide_unused(N::KIND, &params, 0.0);
        Ok(Effect {
            state: NodeState::create(N::KIND, context, params),
            node: PhantomData,
        })
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

    fn clip_planes(
        &self,
        effect: &EffectHandle,
        time: f64,
        out: &mut ClipPlanes,
    ) -> Outcome<Reply> {
        render::clip_planes(self.state(), effect, time, out)
    }
}

/// A param changed: the buttons act, Line Count shows its slots.
fn param_changed(node: &NodeState, effect: &EffectHandle, change: &ParamChange) -> Outcome {
    let time = change.time;
    if change.is(&params::SNAP_LINES) {
        snap::snap_lines(node, effect, time)
    } else if change.is(&params::TRACK_FORWARD) {
        track::track_lines(node, effect, time, 1)
    } else if change.is(&params::TRACK_BACKWARD) {
        track::track_lines(node, effect, time, -1)
    } else if change.is(&params::FINISH_SHAPE) {
        overlay::finish_shape(node);
        Ok(())
    } else if change.is(&params::DELETE_SHAPE) {
        overlay::delete_shape(node, effect, time)
    } else if change.is(&params::KEY_SHAPES) {
        overlay::shapes::key_here(node, effect, time)
    } else if change.is(&params::COPY_SCENE) {
        overlay::shapes::copy_scene(node, effect, time)
    } else if change.is(&params::SUGGEST_FEATURES) {
        suggest::suggest_features(node, effect, time)
    } else if change.is(&params::RESET_GRID) {
        grid::reset_grid(node, effect, time)
    } else if change.is(&params::ADD_ROW) {
        overlay::add_line(node, effect, time, Line::Row)
    } else if change.is(&params::ADD_COLUMN) {
        overlay::add_line(node, effect, time, Line::Column)
    } else if change.is(&params::REMOVE_ROW) {
        overlay::remove_line(node, effect, time, Line::Row)
    } else if change.is(&params::REMOVE_COLUMN) {
        overlay::remove_line(node, effect, time, Line::Column)
    } else if change.is(&params::LINE_COUNT) {
        lines::hide_unused(node.kind, node.params(), time);
        Ok(())
    } else if let Some(k) = params::clear_button_slot(&change.name) {
        lines::clear(node.kind, node.params(), k, time)
    } else {
        Ok(())
    }
}

/// The overlay every node shares: its features drawn and edited.
pub struct FeatureOverlay;

impl<N: Node> Overlay<Effect<N>> for FeatureOverlay {
    fn slave_params() -> Vec<String> {
        overlay::slave_params()
    }
    fn draw(
        node: &Effect<N>,
        _: &EffectHandle,
        args: &DrawArgs,
        p: &mut dyn Painter,
    ) -> Outcome<Reply> {
        overlay::draw(node.state(), args, p)
    }
    fn pen_down(node: &Effect<N>, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        overlay::pen_down(node.state(), effect, pen)
    }
    fn pen_motion(
        node: &Effect<N>,
        effect: &EffectHandle,
        pen: Pen,
        redraw: &mut dyn FnMut(),
    ) -> Outcome<Reply> {
        overlay::pen_motion(node.state(), effect, pen, redraw)
    }
    fn pen_up(node: &Effect<N>, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        overlay::pen_up(node.state(), effect, pen)
    }
    fn key_down(node: &Effect<N>, effect: &EffectHandle, key: i32, time: f64) -> Outcome<Reply> {
        overlay::key_down(node.state(), effect, key, time)
    }
    fn key_up(node: &Effect<N>, _: &EffectHandle, key: i32) -> Outcome<Reply> {
        overlay::key_up(node.state(), key)
    }
    fn lose_focus(node: &Effect<N>, _: &EffectHandle) -> Outcome<Reply> {
        overlay::lose_focus(node.state())
    }
}

#[cfg(test)]
mod tests {
    use morphfx::make_warp::Method;
    use morphfx::views::View;
    use ofx_layer::params::Params;
    use ofx_layer::plugin::{Context, ImageEffect};

    use super::{Effect, Node};
    use crate::nodes::kind::{NodeKind, Sources};
    use crate::nodes::params::METHOD;

    /// A third node, made as docs/architecture.md says: a marker type and
    /// its kind, nothing else.
    struct Blend;

    impl Node for Blend {
        const KIND: &'static NodeKind = &NodeKind {
            id: c"net.morphfx.test.Blend",
            label: "Blend",
            description: "A third node of Morph's engine, in a test.",
            contexts: &[Context::General],
            sources: Sources::Two {
                general: ["First", "Second"],
                transition: ["From", "To"],
            },
            timing_matte: false,
            methods: &[Method::Field, Method::Triangles],
            views: &[View::Morph, View::Ghost],
            view_labels: &[(View::Ghost, "differences")],
        };
    }

    #[test]
    fn a_third_node_is_described_from_its_kind_alone() {
        let spec = Effect::<Blend>::describe_in_context(Context::General);
        let clips: Vec<&str> = spec.clips.iter().map(|c| c.name).collect();
        assert_eq!(clips, ["First", "Second", "Mask", "Output"]);
        let choice = |id: &str| {
            let p = spec.params.iter().find(|p| p.id() == id).expect(id);
            match p.kind() {
                ofx_layer::spec::Kind::Choice { options, .. } => options.clone(),
                other => panic!("{id} is {other:?}"),
            }
        };
        assert_eq!(choice(METHOD.name()), ["field", "triangles"]);
        assert_eq!(choice("view"), ["morph", "differences"]);
        // No auto method, so none of its params; two sources, so both
        // frame offsets.
        assert!(spec.params.iter().all(|p| !p.id().starts_with("auto_")));
        assert!(spec.params.iter().any(|p| p.id() == "frame_offset_b"));
        assert_eq!(<Effect<Blend> as ImageEffect>::LABEL, "Blend");
        assert!(<Effect<Blend> as ImageEffect>::OVERLAY.is_some());
        let made = Effect::<Blend>::create_unbound(Context::General);
        assert!(made.state().kind.has_b());
    }

    impl<N: Node> Effect<N> {
        /// An instance over params bound to no host.
        fn create_unbound(context: Context) -> Self {
            Effect {
                state: crate::nodes::state::NodeState::create(N::KIND, context, Params::unbound()),
                node: std::marker::PhantomData,
            }
        }
    }
}
