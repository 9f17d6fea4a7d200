//! The viewer overlay of both nodes: the line slots drawn with their
//! numbers, directions and in-between lines, and edited with the pen
//! (drag an end, drag a line by its middle, drag in empty space for a new
//! line). The wrapper turns interact actions into these calls.

mod hit;
pub mod paint;

use std::sync::Mutex;

use morphfx::features::{Feature, Side, Tween};
use morphfx::geom::Vec2;
use morphfx::warp::field::line_pairs_toward;

use crate::wrapper::keys;
use crate::wrapper::paint::Painter;
pub use hit::{Handle, Part};
use paint::Frame;

use super::lines::{self, end_id, slot_lines, SlotLine};
use super::params::{
    slot_ids, EditSides, Reader, Settings, Show, LINE_COUNT, LINE_SLOTS, OVERLAY_EDIT, OVERLAY_SHOW,
};
use super::render::warp_inputs;
use super::{Node, NodeKind, NodeState};
use crate::wrapper::clips::EffectHandle;
use crate::wrapper::params::Params;
use crate::wrapper::plugin::{DrawArgs, Overlay, Pen};
use crate::wrapper::{Outcome, Reply};

/// The overlay's state between actions, per effect instance.
#[derive(Debug, Default)]
pub struct State {
    hover: Option<Handle>,
    drag: Option<Drag>,
    shift: bool,
    ctrl: bool,
    /// Canonical units per screen pixel as the last OpenGL draw measured
    /// them: some hosts report (1, 1) at every zoom.
    measured_pixel: Option<(f64, f64)>,
}

#[derive(Debug, Clone, Copy)]
enum Drag {
    /// Moving `handle`; the grabbed line's ends and the pen when it began.
    Move {
        handle: Handle,
        from: Vec2,
        ends: [Vec2; 2],
    },
    /// Drawing a new line into `slot` from `start`.
    New {
        slot: usize,
        start: Vec2,
        count_before: i32,
    },
}

/// Shortest new line kept, in screen pixels: a click is not a line.
const MIN_NEW_LINE_PX: f64 = 3.0;

/// The overlay both nodes share: the line slots, drawn and edited.
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
    fn pen_down(node: &N, _: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        pen_down(node.state(), pen)
    }
    fn pen_motion(
        node: &N,
        _: &EffectHandle,
        pen: Pen,
        redraw: &mut dyn FnMut(),
    ) -> Outcome<Reply> {
        pen_motion(node.state(), pen, redraw)
    }
    fn pen_up(node: &N, _: &EffectHandle, pen: Pen) -> Outcome<Reply> {
        pen_up(node.state(), pen)
    }
    fn key_down(node: &N, _: &EffectHandle, key: i32, time: f64) -> Outcome<Reply> {
        key_down(node.state(), key, time)
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
    let mut ids = vec![
        LINE_COUNT.name().to_owned(),
        OVERLAY_SHOW.name().to_owned(),
        OVERLAY_EDIT.name().to_owned(),
    ];
    for k in 1..=LINE_SLOTS {
        ids.extend(slot_ids(k).names());
    }
    ids
}

fn lock(state: &Mutex<State>) -> std::sync::MutexGuard<'_, State> {
    state.lock().unwrap_or_else(|e| e.into_inner())
}

/// Draws the overlay (returns at once when Show Lines is off). A pixel
/// scale measured from the OpenGL projection is kept for the pen events
/// that follow (they carry only the host's figure).
fn draw(instance: &NodeState, args: &DrawArgs, painter: &mut dyn Painter) -> Outcome<Reply> {
    let (kind, time, pixel) = (instance.kind, args.time, args.pixel);
    if args.measured {
        lock(&instance.overlay).measured_pixel = Some(pixel);
    }
    let params = instance.params();
    let show: Show = Reader::new(params, kind, time).choice(&OVERLAY_SHOW);
    if show == Show::Off {
        return Ok(Reply::Done);
    }
    let settings = Settings::read(params, time, kind);
    let slots = slot_lines(&Reader::new(params, kind, time));
    // A scene that does not parse still leaves the slots to draw.
    let (scene, t) = match warp_inputs(instance, &settings, time) {
        Ok(inputs) => {
            let n = inputs.features.len() - settings.lines.len();
            (inputs.features[..n].to_vec(), inputs.t)
        }
        Err(_) => (Vec::new(), settings.progress),
    };
    let between: Vec<[Vec2; 2]> = slots.iter().map(|l| in_between(l, t, &settings)).collect();
    let hover = lock(&instance.overlay).hover;
    paint::paint(
        painter,
        &Frame {
            slots: &slots,
            between: &between,
            scene: &scene,
            show,
            hover,
            pixel,
        },
    );
    Ok(Reply::Done)
}

/// The slot's line at progress `t` as the field warp places it (line
/// interpolation included).
fn in_between(l: &SlotLine, t: f64, settings: &Settings) -> [Vec2; 2] {
    if l.a[0] == l.a[1] || l.b[0] == l.b[1] {
        return [0, 1].map(|k| l.a[k].lerp(l.b[k], t));
    }
    let f = [Feature::line(l.a, l.b)];
    let pairs = line_pairs_toward(&f, Side::A, Tween::uniform(t), &settings.warp.field);
    match pairs.first() {
        Some(pair) => [pair.dst.0, pair.dst.1],
        None => [0, 1].map(|k| l.a[k].lerp(l.b[k], t)),
    }
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

/// What the pen can reach at `pen.time`: the slots and the grabbable sides.
fn reach(kind: NodeKind, params: &Params, state: &State, time: f64) -> (Vec<SlotLine>, Vec<Side>) {
    let r = Reader::new(params, kind, time);
    let sides = editable(r.choice(&OVERLAY_EDIT), r.choice(&OVERLAY_SHOW), state);
    (slot_lines(&r), sides)
}

/// The pen's scale: the host's, unless an OpenGL draw measured another.
fn pixel_of(state: &State, pen: &Pen) -> (f64, f64) {
    state.measured_pixel.unwrap_or(pen.pixel)
}

/// Pen down: grabs the handle under the pen, or starts a new line in the
/// next free slot. One edit block (one undo step) until pen up.
fn pen_down(instance: &NodeState, pen: Pen) -> Outcome<Reply> {
    let kind = instance.kind;
    let params = instance.params();
    let drag = {
        let state = lock(&instance.overlay);
        let (slots, sides) = reach(kind, params, &state, pen.time);
        if sides.is_empty() {
            return Ok(Reply::Default);
        }
        match hit::hit(&slots, pen.at, pixel_of(&state, &pen), &sides) {
            Some(handle) => {
                let line = slots.iter().find(|l| l.slot == handle.slot);
                let ends = line.map_or([pen.at; 2], |l| l.side(handle.side));
                Drag::Move {
                    handle,
                    from: pen.at,
                    ends,
                }
            }
            None => {
                let count = Reader::new(params, kind, pen.time).int(&LINE_COUNT);
                if count as usize >= LINE_SLOTS {
                    return Ok(Reply::Default);
                }
                Drag::New {
                    slot: count as usize + 1,
                    start: pen.at,
                    count_before: count,
                }
            }
        }
    };
    match drag {
        Drag::Move { handle, .. } => params.begin_edit(&format!("Move Line {}", handle.slot))?,
        Drag::New { slot, .. } => {
            params.begin_edit(&format!("New Line {slot}"))?;
            params.set_int(LINE_COUNT.name(), slot as i32)?;
            params.set_int(slot_ids(slot).enable.name(), 1)?;
        }
    }
    lock(&instance.overlay).drag = Some(drag);
    write_drag(params, drag, pen)?;
    Ok(Reply::Done)
}

/// Writes where the drag puts its params for the pen at `pen`.
fn write_drag(params: &Params, drag: Drag, pen: Pen) -> Outcome {
    let xy = |p: Vec2| (p.x, p.y);
    match drag {
        Drag::Move { handle, from, ends } => {
            let id = |end| end_id(handle.slot, handle.side, end);
            match handle.part {
                Part::Start => params.move_point(id(0).name(), pen.time, xy(pen.at)),
                Part::End => params.move_point(id(1).name(), pen.time, xy(pen.at)),
                Part::Middle => {
                    let d = pen.at - from;
                    params.move_point(id(0).name(), pen.time, xy(ends[0] + d))?;
                    params.move_point(id(1).name(), pen.time, xy(ends[1] + d))
                }
            }
        }
        Drag::New { slot, start, .. } => {
            for side in [Side::A, Side::B] {
                params.move_point(end_id(slot, side, 0).name(), pen.time, xy(start))?;
                params.move_point(end_id(slot, side, 1).name(), pen.time, xy(pen.at))?;
            }
            Ok(())
        }
    }
}

/// Pen motion: moves what is dragged; otherwise tracks the handle under the
/// pen and asks for a redraw when it changes (and leaves the event to the
/// host).
fn pen_motion(instance: &NodeState, pen: Pen, redraw: &mut dyn FnMut()) -> Outcome<Reply> {
    let kind = instance.kind;
    let params = instance.params();
    let mut state = lock(&instance.overlay);
    if let Some(drag) = state.drag {
        drop(state);
        write_drag(params, drag, pen)?;
        return Ok(Reply::Done);
    }
    let (slots, sides) = reach(kind, params, &state, pen.time);
    let hover = hit::hit(&slots, pen.at, pixel_of(&state, &pen), &sides);
    if hover != state.hover {
        state.hover = hover;
        drop(state);
        redraw();
    }
    Ok(Reply::Default)
}

/// Pen up: the drag's last write, and its edit block closed. A click that
/// drew no line takes its slot back.
fn pen_up(instance: &NodeState, pen: Pen) -> Outcome<Reply> {
    let kind = instance.kind;
    let params = instance.params();
    let (drag, pixel) = {
        let mut state = lock(&instance.overlay);
        (state.drag.take(), pixel_of(&state, &pen))
    };
    let Some(drag) = drag else {
        return Ok(Reply::Default);
    };
    let written = match drag {
        Drag::New {
            start,
            count_before,
            ..
        } if screen_length(start, pen.at, pixel) < MIN_NEW_LINE_PX => {
            params.set_int(LINE_COUNT.name(), count_before)
        }
        _ => write_drag(params, drag, pen),
    };
    let closed = params.end_edit();
    written?;
    closed?;
    if matches!(drag, Drag::New { .. }) {
        lines::hide_unused(kind, params, pen.time);
    }
    Ok(Reply::Done)
}

fn screen_length(p: Vec2, q: Vec2, pixel: (f64, f64)) -> f64 {
    Vec2::new((q.x - p.x) / pixel.0, (q.y - p.y) / pixel.1).length()
}

/// Key down: modifiers narrow what the pen grabs (and stay the host's
/// too); Delete or BackSpace clears the hovered line.
fn key_down(instance: &NodeState, sym: i32, time: f64) -> Outcome<Reply> {
    let hovered = {
        let mut state = lock(&instance.overlay);
        if keys::SHIFT.contains(&sym) {
            state.shift = true;
        }
        if keys::CONTROL.contains(&sym) {
            state.ctrl = true;
        }
        if !keys::DELETE.contains(&sym) || state.drag.is_some() {
            return Ok(Reply::Default);
        }
        state.hover.take()
    };
    let Some(handle) = hovered else {
        return Ok(Reply::Default);
    };
    lines::clear(instance.kind, instance.params(), handle.slot, time)?;
    Ok(Reply::Done)
}

/// Key up: releases a modifier.
fn key_up(instance: &NodeState, sym: i32) -> Outcome<Reply> {
    let mut state = lock(&instance.overlay);
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
    let mut state = lock(&instance.overlay);
    state.shift = false;
    state.ctrl = false;
    state.hover = None;
    Ok(Reply::Default)
}
