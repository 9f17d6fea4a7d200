//! What a node is to this layer: the [`ImageEffect`] trait (what it
//! declares as constants, what it does per action) and its [`Overlay`], with
//! every action's arguments as typed values and its answers as setters, so a
//! node never sees a property name or a status. Models: nih-plug's `Plugin`
//! (a trait with associated constants, one entry per type) and the OpenFX
//! Support library's `ImageEffect` (typed action arguments, host defaults).

use std::ffi::CStr;

use morphfx::geom::{RectD, RectI, Vec2};

use super::clips::EffectHandle;
pub use super::context::Context;
use super::paint::Painter;
use super::params::Params;
pub use super::planes::ClipPlanes;
use super::spec::{Id, ParamSpec};
use super::{Outcome, Reply};

/// The sample depths a node renders.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelDepth {
    Byte,
    Short,
    Float,
}

/// The pixel layouts a clip takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Components {
    Rgba,
    Rgb,
    Alpha,
}

/// How a node's renders may run side by side (`kOfxImageEffectPluginRenderThreadSafety`).
#[allow(dead_code)] // the spec's three answers; a node picks one
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ThreadSafety {
    /// Any number of renders at once, on any instances.
    FullySafe,
    /// One render at a time per instance.
    InstanceSafe,
    /// One render at a time in all.
    Unsafe,
}

/// Whether frames must be rendered in order (`kOfxImageEffectInstancePropSequentialRender`).
#[allow(dead_code)] // the spec's three answers; a node picks one
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sequential {
    /// Any order.
    No,
    /// In order only.
    Always,
    /// Any order is correct; in order is cheaper.
    Preferred,
}

/// What a node can do, as the host is told at describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Capabilities {
    pub depths: &'static [PixelDepth],
    pub thread_safety: ThreadSafety,
    /// The host may split frames across threads (else the node does).
    pub host_frame_threading: bool,
    pub tiles: bool,
    pub multi_resolution: bool,
    pub temporal_access: bool,
    pub multiple_clip_depths: bool,
    pub multiple_clip_aspects: bool,
    pub sequential: Sequential,
}

/// One clip a node defines in a context.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClipSpec {
    pub name: &'static str,
    pub components: &'static [Components],
    pub tiles: bool,
    pub temporal_access: bool,
    pub optional: bool,
    /// A mask input (`kOfxImageClipPropIsMask`): hosts show it as one.
    pub mask: bool,
}

/// What describe-in-context defines: the clips (`Output` among them) and the
/// params.
pub struct ContextSpec {
    pub clips: Vec<ClipSpec>,
    pub params: Vec<ParamSpec>,
}

/// A render or an identity question: one window of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderArgs {
    pub time: f64,
    /// Pixels.
    pub window: RectI,
    /// The host renders this instance's frames in order (warm starts allowed).
    pub sequential: bool,
    /// The host renders for a viewer while the instance is being
    /// manipulated, where the spec allows an approximation for UI purposes
    /// (`kOfxImageEffectPropInteractiveRenderStatus`).
    pub interactive: bool,
    /// The planes to fill (multi-planar hosts; see [`crate::planes`]): the
    /// colour plane alone where the host names none.
    pub planes: Vec<String>,
}

/// The clip (and its time) a node's output equals at some frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Identity {
    pub clip: &'static str,
    pub time: f64,
}

/// The instance-changed action for a param.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamChange {
    pub name: String,
    pub time: f64,
}

impl ParamChange {
    /// Whether the param that changed is `id`.
    pub fn is<K>(&self, id: &Id<K>) -> bool {
        self.name == id.name()
    }
}

/// A region of interest per input clip, set by the node.
#[derive(Debug, Default)]
pub struct Rois {
    pub(super) set: Vec<(&'static str, RectD)>,
}

impl Rois {
    pub fn set(&mut self, clip: &'static str, region: RectD) {
        self.set.push((clip, region));
    }
}

/// The frames each input clip is needed at, set by the node.
#[derive(Debug, Default)]
pub struct FramesNeeded {
    pub(super) set: Vec<(&'static str, (f64, f64))>,
}

impl FramesNeeded {
    pub fn set(&mut self, clip: &'static str, range: (f64, f64)) {
        self.set.push((clip, range));
    }
}

/// The clip preferences a node answers.
#[derive(Debug, Default)]
pub struct ClipPreferences {
    pub(super) frame_varying: Option<bool>,
    pub(super) premultiplied_output: Option<bool>,
    pub(super) rgba_output: bool,
}

impl ClipPreferences {
    /// The output changes from frame to frame even when the inputs do not.
    pub fn set_frame_varying(&mut self, varying: bool) {
        self.frame_varying = Some(varying);
    }
    /// The output's colour is premultiplied by its alpha (else straight).
    pub fn set_premultiplied_output(&mut self, premultiplied: bool) {
        self.premultiplied_output = Some(premultiplied);
    }
    /// The output must be RGBA whatever the sources are (its alpha carries
    /// what the node shows), where a host would otherwise follow RGB sources.
    pub fn set_rgba_output(&mut self) {
        self.rgba_output = true;
    }
}

/// An OFX image effect. One type per plugin of the bundle; its instances
/// are values of the type, made in `create` and dropped at destroy. What
/// an effect does not answer is left to the host's default behaviour, as
/// the spec defines it for each action (`kOfxStatReplyDefault`).
pub trait ImageEffect: Sized + Send + Sync + 'static {
    /// The plugin identifier, reverse-domain style.
    const ID: &'static CStr;
    /// (major, minor).
    const VERSION: (u32, u32);
    const LABEL: &'static str;
    const DESCRIPTION: &'static str;
    /// Where hosts list it.
    const GROUPING: &'static str;
    const CONTEXTS: &'static [Context];
    const CAPABILITIES: Capabilities;
    /// The effect reads and makes every plane of its sources where the host
    /// offers the multi-plane extension: it then answers
    /// [`ImageEffect::clip_planes`] and fills every plane a render names.
    const MULTI_PLANE: bool = false;
    /// The viewer overlay, if the effect draws one:
    /// `Some(OverlayActions::of::<TheOverlay>())`.
    const OVERLAY: Option<OverlayActions<Self>> = None;

    /// The clips and params of a context.
    fn describe_in_context(context: Context) -> ContextSpec;

    /// An instance, its params bound to the host's.
    fn create(effect: &EffectHandle, context: Context, params: Params) -> Outcome<Self>;

    fn render(&self, effect: &EffectHandle, args: &RenderArgs) -> Outcome;

    /// Frees what the instance caches.
    fn purge(&self) {}

    /// The output's region of definition; `None` leaves it to the host's default.
    fn region_of_definition(&self, _effect: &EffectHandle, _time: f64) -> Outcome<Option<RectD>> {
        Ok(None)
    }

    /// Each input's region needed to render the output at `time`.
    fn regions_of_interest(
        &self,
        _effect: &EffectHandle,
        _time: f64,
        _out: &mut Rois,
    ) -> Outcome<Reply> {
        Ok(Reply::Default)
    }

    fn frames_needed(
        &self,
        _effect: &EffectHandle,
        _time: f64,
        _out: &mut FramesNeeded,
    ) -> Outcome<Reply> {
        Ok(Reply::Default)
    }

    fn clip_preferences(
        &self,
        _effect: &EffectHandle,
        _out: &mut ClipPreferences,
    ) -> Outcome<Reply> {
        Ok(Reply::Default)
    }

    /// The source the output equals unchanged, if any.
    fn is_identity(&self, _effect: &EffectHandle, _args: &RenderArgs) -> Outcome<Option<Identity>> {
        Ok(None)
    }

    fn param_changed(&self, _effect: &EffectHandle, _change: &ParamChange) -> Outcome {
        Ok(())
    }

    /// The planes each clip needs at `time` and the output makes
    /// (multi-planar effects, `GetClipComponents`).
    fn clip_planes(
        &self,
        _effect: &EffectHandle,
        _time: f64,
        _out: &mut ClipPlanes,
    ) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
}

/// A pen event: when, where (canonical), and the view's canonical units
/// per screen pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pen {
    /// The effect's time.
    pub time: f64,
    /// The pen's position, canonical.
    pub at: Vec2,
    /// Canonical units per screen pixel.
    pub pixel: (f64, f64),
}

/// A draw action: when, and the view's canonical units per screen pixel,
/// measured from the OpenGL projection where the host's own figure cannot
/// be trusted (some hosts say (1, 1) at every zoom).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawArgs {
    pub time: f64,
    pub pixel: (f64, f64),
    /// `pixel` was measured from the projection, not told by the host.
    pub measured: bool,
}

/// A viewer overlay: its actions on an instance of effect `E`. Only
/// drawing is required; what the overlay does not handle is left to the
/// host.
pub trait Overlay<E>: 'static {
    /// Params whose changes redraw the overlay.
    fn slave_params() -> Vec<String> {
        Vec::new()
    }
    fn draw(
        node: &E,
        effect: &EffectHandle,
        args: &DrawArgs,
        painter: &mut dyn Painter,
    ) -> Outcome<Reply>;
    fn pen_down(_node: &E, _effect: &EffectHandle, _pen: Pen) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
    /// `redraw` asks the host to draw the overlay again.
    fn pen_motion(
        _node: &E,
        _effect: &EffectHandle,
        _pen: Pen,
        _redraw: &mut dyn FnMut(),
    ) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
    fn pen_up(_node: &E, _effect: &EffectHandle, _pen: Pen) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
    /// A key pressed (or repeating): its OFX key symbol (see `keys`).
    fn key_down(_node: &E, _effect: &EffectHandle, _key: i32, _time: f64) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
    fn key_up(_node: &E, _effect: &EffectHandle, _key: i32) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
    fn lose_focus(_node: &E, _effect: &EffectHandle) -> Outcome<Reply> {
        Ok(Reply::Default)
    }
}

/// An overlay's actions on effect `E`, as the layer calls them: what
/// [`ImageEffect::OVERLAY`] holds.
pub struct OverlayActions<E> {
    pub(super) slave_params: fn() -> Vec<String>,
    pub(super) draw: fn(&E, &EffectHandle, &DrawArgs, &mut dyn Painter) -> Outcome<Reply>,
    pub(super) pen_down: fn(&E, &EffectHandle, Pen) -> Outcome<Reply>,
    pub(super) pen_motion: fn(&E, &EffectHandle, Pen, &mut dyn FnMut()) -> Outcome<Reply>,
    pub(super) pen_up: fn(&E, &EffectHandle, Pen) -> Outcome<Reply>,
    pub(super) key_down: fn(&E, &EffectHandle, i32, f64) -> Outcome<Reply>,
    pub(super) key_up: fn(&E, &EffectHandle, i32) -> Outcome<Reply>,
    pub(super) lose_focus: fn(&E, &EffectHandle) -> Outcome<Reply>,
}

impl<E> OverlayActions<E> {
    /// Overlay `O`'s actions.
    pub const fn of<O: Overlay<E>>() -> Self {
        OverlayActions {
            slave_params: O::slave_params,
            draw: O::draw,
            pen_down: O::pen_down,
            pen_motion: O::pen_motion,
            pen_up: O::pen_up,
            key_down: O::key_down,
            key_up: O::key_up,
            lose_focus: O::lose_focus,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An effect that states what it is and renders, and nothing more.
    struct Minimal;

    impl ImageEffect for Minimal {
        const ID: &'static CStr = c"test.Minimal";
        const VERSION: (u32, u32) = (1, 0);
        const LABEL: &'static str = "Minimal";
        const DESCRIPTION: &'static str = "Renders; the host does the rest.";
        const GROUPING: &'static str = "Test";
        const CONTEXTS: &'static [Context] = &[Context::Filter];
        const CAPABILITIES: Capabilities = Capabilities {
            depths: &[PixelDepth::Float],
            thread_safety: ThreadSafety::FullySafe,
            host_frame_threading: true,
            tiles: true,
            multi_resolution: true,
            temporal_access: false,
            multiple_clip_depths: false,
            multiple_clip_aspects: false,
            sequential: Sequential::No,
        };
        fn describe_in_context(_: Context) -> ContextSpec {
            ContextSpec {
                clips: Vec::new(),
                params: Vec::new(),
            }
        }
        fn create(_: &EffectHandle, _: Context, _: Params) -> Outcome<Self> {
            Ok(Minimal)
        }
        fn render(&self, _: &EffectHandle, _: &RenderArgs) -> Outcome {
            Ok(())
        }
    }

    /// Describe, create and render are all an effect must write: it has no
    /// overlay, and every other action is left to the host.
    #[test]
    fn an_effect_needs_only_describe_create_and_render() {
        assert!(Minimal::OVERLAY.is_none());
        let (effect, time) = (EffectHandle::unbound(), 1.0);
        let args = RenderArgs {
            time,
            window: RectI::default(),
            sequential: false,
            interactive: false,
            planes: Vec::new(),
        };
        let m = Minimal;
        assert_eq!(m.region_of_definition(&effect, time), Ok(None));
        let mut rois = Rois::default();
        assert_eq!(
            m.regions_of_interest(&effect, time, &mut rois),
            Ok(Reply::Default)
        );
        assert!(rois.set.is_empty());
        let mut frames = FramesNeeded::default();
        assert_eq!(
            m.frames_needed(&effect, time, &mut frames),
            Ok(Reply::Default)
        );
        let mut prefs = ClipPreferences::default();
        assert_eq!(m.clip_preferences(&effect, &mut prefs), Ok(Reply::Default));
        assert_eq!(m.is_identity(&effect, &args), Ok(None));
        let change = ParamChange {
            name: "x".into(),
            time,
        };
        assert_eq!(m.param_changed(&effect, &change), Ok(()));
        const { assert!(!Minimal::MULTI_PLANE) };
        let mut planes = ClipPlanes::default();
        assert_eq!(
            m.clip_planes(&effect, time, &mut planes),
            Ok(Reply::Default)
        );
        assert_eq!(planes, ClipPlanes::default());
    }
}
