//! The viewer overlay of both nodes: every feature drawn (line slots,
//! Scene Text's shapes, Scene File's features dimmer) with directions,
//! names, connectors and in-between shapes, and edited with the pen: drag
//! a point or a whole feature, draw lines, points, polylines and curves,
//! insert and delete points. The wrapper turns interact actions into these
//! calls; `pen` holds what the pen does, `shapes` the Scene Text edits.

mod hit;
mod outline;
pub mod paint;
mod pen;
pub mod shapes;

use morphfx::features::Side;
use morphfx::geom::Vec2;
use morphfx::scene::edit::Document;

use crate::wrapper::keys;
use crate::wrapper::paint::Painter;
pub use hit::{Handle, Part};
pub use outline::{Outline, Owner};
use paint::Frame;

use super::lines::slot_lines;
use super::params::{
    slot_ids, EditSides, Reader, Settings, Show, DRAW_TOOL, LINE_COUNT, LINE_SLOTS, OVERLAY_EDIT,
    OVERLAY_SHOW, SCENE_FILE, SCENE_TEXT,
};
use super::render::{load_scene, warp_inputs};
use super::{Node, NodeState};
use crate::sync::Locked;
use crate::wrapper::clips::EffectHandle;
use crate::wrapper::plugin::{DrawArgs, Overlay, Pen};
use crate::wrapper::{Outcome, Reply};

/// The overlay's state between actions, per effect instance.
#[derive(Debug, Default)]
pub struct State {
    hover: Option<Handle>,
    drag: Option<Drag>,
    /// The polyline or curve being drawn, click by click.
    building: Option<Building>,
    /// The Scene Text shape last drawn or grabbed (Delete Shape's target).
    selected: Option<usize>,
    /// An edit was refused and its message is on the node.
    refused: bool,
    shift: bool,
    ctrl: bool,
    /// Canonical units per screen pixel as the last OpenGL draw measured
    /// them: some hosts report (1, 1) at every zoom.
    measured_pixel: Option<(f64, f64)>,
}

#[derive(Debug, Clone)]
enum Drag {
    /// Moving part `part` of slot `slot`'s line on `side`; the line's ends
    /// and the pen when it began.
    Slot {
        slot: usize,
        side: Side,
        part: Part,
        from: Vec2,
        ends: [Vec2; 2],
    },
    /// Drawing a new line into `slot` from `start`.
    NewLine {
        slot: usize,
        start: Vec2,
        count_before: i32,
    },
    /// Moving Scene Text's feature `feature` on `side`: one point, or all of
    /// them by the pen's motion. Each event edits `before` afresh, so only
    /// the grabbed numbers change whatever the path.
    Shape {
        feature: usize,
        side: Side,
        point: Option<usize>,
        from: Vec2,
        points: Vec<Vec2>,
        before: Box<Document>,
    },
}

/// A polyline or curve being drawn.
#[derive(Debug, Clone)]
struct Building {
    kind: morphfx::features::FeatureKind,
    points: Vec<Vec2>,
    /// Its index in Scene Text once it has two points (and is written).
    feature: Option<usize>,
    /// Where the pen last hovered: the next point's rubber band runs there.
    cursor: Option<Vec2>,
}

/// Shortest new line kept, in screen pixels: a click is not a line.
const MIN_NEW_LINE_PX: f64 = 3.0;

/// The overlay both nodes share.
pub struct SlotOverlay;

impl<N: Node> Overlay<N> for SlotOverlay {
    fn slave_params() -> Vec<String> {
        slave_params()
    }
    fn draw(
        node: &N,
        _: &EffectHandle,
        args: &DrawArgs,
        painter: &mut dyn Painter,
    ) -> Outcome<Reply> {
        draw(node.state(), args, painter)
    }
    fn pen_down(node: &N, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        pen::down(node.state(), effect, pen)
    }
    fn pen_motion(
        node: &N,
        effect: &EffectHandle,
        pen: Pen,
        redraw: &mut dyn FnMut(),
    ) -> Outcome<Reply> {
        pen::motion(node.state(), effect, pen, redraw)
    }
    fn pen_up(node: &N, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        pen::up(node.state(), effect, pen)
    }
    fn key_down(node: &N, effect: &EffectHandle, key: i32, time: f64) -> Outcome<Reply> {
        pen::key_down(node.state(), effect, key, time)
    }
    fn key_up(node: &N, _: &EffectHandle, key: i32) -> Outcome<Reply> {
        key_up(node.state(), key)
    }
    fn lose_focus(node: &N, _: &EffectHandle) -> Outcome<Reply> {
        lose_focus(node.state())
    }
}

/// The params every overlay redraw depends on (the interact is slaved to them).
fn slave_params() -> Vec<String> {
    let mut ids: Vec<String> = [
        LINE_COUNT.name(),
        OVERLAY_SHOW.name(),
        OVERLAY_EDIT.name(),
        DRAW_TOOL.name(),
        SCENE_TEXT.name(),
        SCENE_FILE.name(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for k in 1..=LINE_SLOTS {
        ids.extend(slot_ids(k).names());
    }
    ids
}

/// Every feature of the node at `time`, with the progress and the frames
/// Scene Text's shapes are keyed at. A scene that does not parse is drawn
/// as nothing (the slots still are).
struct View {
    outlines: Vec<Outline>,
    t: f64,
    keys: Vec<f64>,
    settings: Settings,
}

fn view(instance: &NodeState, time: f64) -> View {
    let settings = Settings::read(instance.params(), time, instance.kind);
    let slots = slot_lines(&Reader::new(instance.params(), instance.kind, time));
    let from_file = !settings.scene_file.trim().is_empty();
    let mut outlines = Vec::new();
    let mut t = settings.progress;
    if let Ok(inputs) = warp_inputs(instance, &settings, time) {
        let n = inputs.features.len() - settings.lines.len();
        let owner = |i| {
            if from_file {
                Owner::File(i)
            } else {
                Owner::Shape(i)
            }
        };
        outlines.extend(
            inputs.features[..n]
                .iter()
                .enumerate()
                .map(|(i, f)| Outline {
                    owner: owner(i),
                    feature: f.clone(),
                }),
        );
        t = inputs.t;
    }
    let keys = match load_scene(instance, &settings) {
        Ok(Some(scene)) if !from_file => scene.keyframes.iter().map(|k| k.frame).collect(),
        _ => Vec::new(),
    };
    outlines.extend(slots.iter().map(Outline::slot));
    View {
        outlines,
        t,
        keys,
        settings,
    }
}

/// Draws the overlay (returns at once when Show Lines is off). A pixel
/// scale measured from the OpenGL projection is kept for the pen events
/// that follow (they carry only the host's figure).
fn draw(instance: &NodeState, args: &DrawArgs, painter: &mut dyn Painter) -> Outcome<Reply> {
    let (kind, time, pixel) = (instance.kind, args.time, args.pixel);
    if args.measured {
        instance.overlay.locked().measured_pixel = Some(pixel);
    }
    let show: Show = Reader::new(instance.params(), kind, time).choice(&OVERLAY_SHOW);
    if show == Show::Off {
        return Ok(Reply::Done);
    }
    let v = view(instance, time);
    let field = &v.settings.warp.field;
    let between: Vec<Vec<Vec2>> = v
        .outlines
        .iter()
        .map(|o| outline::in_between(o, v.t, field))
        .collect();
    let (hover, building) = {
        let state = instance.overlay.locked();
        let building = state
            .building
            .as_ref()
            .map(|b| (b.points.clone(), b.cursor));
        (state.hover, building.unwrap_or_default())
    };
    paint::paint(
        painter,
        &Frame {
            outlines: &v.outlines,
            between: &between,
            show,
            hover,
            pixel,
            keys: (&v.keys, time),
            building: (&building.0, building.1),
        },
    );
    Ok(Reply::Done)
}

/// The sides the pen may grab: the Edit Lines param, narrowed by Shift (A)
/// or Ctrl (B), among the sides shown.
fn editable(edit: EditSides, show: Show, state: &State) -> Vec<Side> {
    let wanted: &[Side] = match (state.shift, state.ctrl, edit) {
        (true, false, _) => &[Side::A],
        (false, true, _) => &[Side::B],
        (_, _, EditSides::A) => &[Side::A],
        (_, _, EditSides::B) => &[Side::B],
        (_, _, EditSides::Both) if show == Show::B => &[Side::B, Side::A],
        (_, _, EditSides::Both) => &[Side::A, Side::B],
    };
    let shown = |s: &Side| match show {
        Show::Both => true,
        Show::A => *s == Side::A,
        Show::B => *s == Side::B,
        Show::Between | Show::Off => false,
    };
    wanted.iter().copied().filter(shown).collect()
}

/// The pen's scale: the host's, unless an OpenGL draw measured another.
fn pixel_of(state: &State, pen: &Pen) -> (f64, f64) {
    state.measured_pixel.unwrap_or(pen.pixel)
}

/// Key up: releases a modifier.
fn key_up(instance: &NodeState, sym: i32) -> Outcome<Reply> {
    let mut state = instance.overlay.locked();
    if keys::SHIFT.contains(&sym) {
        state.shift = false;
    }
    if keys::CONTROL.contains(&sym) {
        state.ctrl = false;
    }
    Ok(Reply::Default)
}

/// Focus lost: no key is held any more as far as we can know, and nothing
/// is under the pen.
fn lose_focus(instance: &NodeState) -> Outcome<Reply> {
    let mut state = instance.overlay.locked();
    state.shift = false;
    state.ctrl = false;
    state.hover = None;
    Ok(Reply::Default)
}

/// The Finish Shape button: the polyline or curve being drawn ends open.
pub fn finish_shape(instance: &NodeState) {
    let mut state = instance.overlay.locked();
    if let Some(b) = state.building.take() {
        state.selected = b.feature.or(state.selected);
    }
}

/// The Delete Shape button: the shape last drawn or grabbed leaves Scene Text.
pub fn delete_shape(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let selected = {
        let mut state = instance.overlay.locked();
        state.building = None;
        state.hover = None;
        state.selected.take()
    };
    let Some(feature) = selected else {
        effect.warning(
            c"net.morphfx.overlay.select",
            "Delete Shape: grab a shape in the viewer first (the last one drawn or grabbed is deleted)",
        );
        return Ok(());
    };
    let result = shapes::document(instance, time).and_then(|mut doc| {
        doc.delete_feature(feature).map_err(shapes::refused)?;
        instance
            .params()
            .edit_block("Delete Shape", || shapes::write(instance, &doc))
    });
    shapes::settle(instance, effect, result)
}
