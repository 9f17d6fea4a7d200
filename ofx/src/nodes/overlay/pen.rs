//! What the pen does in the viewer: grab and drag a point or a whole
//! feature or a grid node, draw a line, a point, a polyline or a curve,
//! insert a point on a shape, delete with Delete or Backspace. Every edit is one undo step
//! (an edit block from pen down to pen up), and a drag writes its param
//! (a slot's end, or Scene Text) once per pen event.

use morphfx::features::{Feature, FeatureKind, Side};
use morphfx::geom::Vec2;

use super::hit;

use super::grid::Grid;
use super::grid_pen;
use super::outline::Outline;
use super::shapes::{self, refused};
use super::state::{editable, pixel_of, Building, Drag, Handle, Owner, Part, State};
use super::view::grabbable;
use crate::nodes::lines::{self, end_id};
use crate::nodes::params::{slot_ids, DrawTool, Reader, DRAW_TOOL, LINE_COUNT, LINE_SLOTS};
use crate::nodes::params::{OVERLAY_EDIT, OVERLAY_SHOW};
use crate::nodes::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::params::Params;
use ofx_layer::plugin::Pen;
use ofx_layer::sync::Locked;
use ofx_layer::{keys, Failure, Outcome, Reply};

/// Shortest new line kept, in screen pixels: a click is not a line.
const MIN_NEW_LINE_PX: f64 = 3.0;

/// Pen down: a click of a shape being drawn, else a grab of what is under
/// the pen, else the draw tool's new feature.
pub fn down(instance: &NodeState, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
    if instance.overlay.locked().building.is_some() {
        return building_click(instance, effect, pen);
    }
    let r = Reader::new(instance.params(), instance.kind, pen.time);
    let tool: DrawTool = r.choice(&DRAW_TOOL);
    let (handle, sides, on_grid) = {
        let state = instance.overlay.locked();
        let under = under_pen(instance, &r, &state, pen);
        let on_grid = under.grid.is_some();
        (
            under.handle.map(|h| (h, under.outlines)),
            under.sides,
            on_grid,
        )
    };
    if sides.is_empty() {
        return Ok(Reply::Default);
    }
    let (shift, ctrl) = {
        let state = instance.overlay.locked();
        (state.shift, state.ctrl)
    };
    if on_grid && shift && ctrl {
        grid_pen::add_at_pen(instance, effect, sides[0], pen)?;
        return Ok(Reply::Done);
    }
    let drag = match handle {
        Some((h, outlines)) => match h.owner {
            Owner::Slot(slot) => {
                let o = outlines.iter().find(|o| o.owner == h.owner);
                let ends = o.map_or([pen.at; 2], |o| {
                    let p = o.feature.points(h.side);
                    [p[0], p[1]]
                });
                start_slot_drag(instance, h, slot, ends, pen)?
            }
            Owner::Shape(feature) => match grab_shape(instance, h, feature, tool, pen) {
                Ok(drag) => drag,
                Err(why) => return refuse(instance, effect, why),
            },
            Owner::Grid => match grid_pen::grab(instance, h, pen) {
                Ok(Some(drag)) => {
                    grid_pen::remember_point(instance, h.side, pen.at);
                    drag
                }
                // A Shift- or Ctrl-click chose the node: nothing to drag.
                Ok(None) => return Ok(Reply::Done),
                Err(why) => return refuse(instance, effect, why),
            },
            Owner::File(_) => return Ok(Reply::Default),
        },
        // Over the grid, empty space is where a rubber band starts.
        None if on_grid => {
            grid_pen::remember_point(instance, sides[0], pen.at);
            grid_pen::start_band(instance, pen)
        }
        None => match tool {
            DrawTool::Line => match start_new_line(instance, pen)? {
                Some(drag) => drag,
                None => return Ok(Reply::Default),
            },
            DrawTool::Point => match new_point(instance, pen) {
                Ok(drag) => drag,
                Err(why) => return refuse(instance, effect, why),
            },
            DrawTool::Polyline | DrawTool::Curve => {
                return start_building(instance, effect, tool, pen);
            }
        },
    };
    if let Drag::Shape { feature, .. } = &drag {
        instance.overlay.locked().selected = Some(*feature);
    }
    instance.overlay.locked().drag = Some(drag.clone());
    if let Err(why) = write_drag(instance, &drag, pen) {
        instance.overlay.locked().drag = None;
        let _ = instance.params().end_edit();
        return refuse(instance, effect, why);
    }
    Ok(Reply::Done)
}

/// What the pen is over: the sides it may grab, everything grabbable,
/// and the handle under it.
struct UnderPen {
    sides: Vec<Side>,
    outlines: Vec<Outline>,
    grid: Option<Grid>,
    handle: Option<Handle>,
}

fn under_pen(instance: &NodeState, r: &Reader<'_>, state: &State, pen: Pen) -> UnderPen {
    let sides = editable(r.choice(&OVERLAY_EDIT), r.choice(&OVERLAY_SHOW), state);
    let (outlines, grid) = grabbable(instance, r, pen.time);
    let handle = hit::hit(
        &outlines,
        grid.as_ref(),
        pen.at,
        pixel_of(state, &pen),
        &sides,
    );
    UnderPen {
        sides,
        outlines,
        grid,
        handle,
    }
}

/// Shows why an edit was refused, and traps the event (nothing else
/// should act on a click the user meant as an edit).
fn refuse(instance: &NodeState, effect: &EffectHandle, why: Failure) -> Outcome<Reply> {
    shapes::settle(instance, effect, Err(why))?;
    Ok(Reply::Done)
}

/// Grabs a slot's end (or its body), opening the drag's edit block.
fn start_slot_drag(
    instance: &NodeState,
    h: Handle,
    slot: usize,
    ends: [Vec2; 2],
    pen: Pen,
) -> Outcome<Drag> {
    instance.params().begin_edit(&format!("Move Line {slot}"))?;
    Ok(Drag::Slot {
        slot,
        side: h.side,
        part: h.part,
        from: pen.at,
        ends,
    })
}

/// A new line into the next free slot (none when all 64 are used).
fn start_new_line(instance: &NodeState, pen: Pen) -> Outcome<Option<Drag>> {
    let params = instance.params();
    let count = Reader::new(params, instance.kind, pen.time).int(&LINE_COUNT);
    if count as usize >= LINE_SLOTS {
        return Ok(None);
    }
    let slot = count as usize + 1;
    params.begin_edit(&format!("New Line {slot}"))?;
    params.set_int(&LINE_COUNT, slot as i32)?;
    params.set_int(&slot_ids(slot).enable, 1)?;
    Ok(Some(Drag::NewLine {
        slot,
        start: pen.at,
        count_before: count,
    }))
}

/// Grabs Scene Text's feature `feature`: a control point, its body (the
/// whole feature), or, with the polyline or curve tool, a new point
/// inserted where the pen is on a polyline or curve (then dragged).
fn grab_shape(
    instance: &NodeState,
    h: Handle,
    feature: usize,
    tool: DrawTool,
    pen: Pen,
) -> Outcome<Drag> {
    let mut doc = shapes::document(instance, pen.time)?;
    let inserting = matches!(tool, DrawTool::Polyline | DrawTool::Curve);
    let (point, label) = match h.part {
        Part::Point(i) => (Some(i), "Move Shape Point"),
        Part::Body { span, s } if inserting => {
            let kind = doc
                .scene()
                .features_at(pen.time)
                .get(feature)
                .map(|f| f.kind);
            if matches!(kind, Some(FeatureKind::Polyline | FeatureKind::Curve)) {
                doc.insert_point(feature, span, s).map_err(refused)?;
                (Some(span + 1), "Insert Shape Point")
            } else {
                (None, "Move Shape")
            }
        }
        Part::Body { .. } => (None, "Move Shape"),
    };
    let points = doc
        .scene()
        .features_at(pen.time)
        .get(feature)
        .map(|f| f.points(h.side).to_vec())
        .ok_or_else(|| Failure::BadInput(format!("Scene Text has no feature {feature}")))?;
    instance.params().begin_edit(label)?;
    Ok(Drag::Shape {
        feature,
        side: h.side,
        point,
        from: pen.at,
        points,
        before: Box::new(doc),
    })
}

/// The point tool: a point feature at the pen, dragged until pen up.
fn new_point(instance: &NodeState, pen: Pen) -> Outcome<Drag> {
    let mut doc = shapes::document(instance, pen.time)?;
    let feature = doc
        .add_feature(&Feature::point(pen.at, pen.at))
        .map_err(refused)?;
    instance.params().begin_edit("New Point")?;
    Ok(Drag::Shape {
        feature,
        side: Side::A,
        point: None,
        from: pen.at,
        points: vec![pen.at],
        before: Box::new(doc),
    })
}

/// Writes where the drag puts its params for the pen at `pen`.
fn write_drag(instance: &NodeState, drag: &Drag, pen: Pen) -> Outcome {
    let params = instance.params();
    let xy = |p: Vec2| (p.x, p.y);
    match drag {
        Drag::Slot {
            slot,
            side,
            part,
            from,
            ends,
        } => {
            let id = |end| end_id(*slot, *side, end);
            match *part {
                Part::Point(end) => params.move_point(&id(end), pen.time, xy(pen.at)),
                Part::Body { .. } => {
                    let d = pen.at - *from;
                    params.move_point(&id(0), pen.time, xy(ends[0] + d))?;
                    params.move_point(&id(1), pen.time, xy(ends[1] + d))
                }
            }
        }
        Drag::NewLine { slot, start, .. } => {
            for side in [Side::A, Side::B] {
                params.move_point(&end_id(*slot, side, 0), pen.time, xy(*start))?;
                params.move_point(&end_id(*slot, side, 1), pen.time, xy(pen.at))?;
            }
            Ok(())
        }
        Drag::Band { .. } => Ok(()),
        Drag::Grid {
            side,
            nodes,
            from,
            before,
        } => {
            // The fold guard: the nodes stop where the grid would fold.
            let mut doc = (**before).clone();
            doc.drag_nodes(pen.time, *side, nodes, pen.at - *from)
                .map_err(refused)?;
            shapes::write(instance, &doc)
        }
        Drag::Shape {
            feature,
            side,
            point,
            from,
            points,
            before,
        } => {
            let mut doc = (**before).clone();
            let edit = match point {
                Some(i) => doc.set_point(pen.time, *feature, *side, *i, pen.at),
                None => doc.move_feature(pen.time, *feature, *side, points, pen.at - *from),
            };
            edit.map_err(refused)?;
            shapes::write(instance, &doc)
        }
    }
}

/// Pen motion: moves what is dragged; otherwise tracks the handle under the
/// pen and asks for a redraw when it changes (and leaves the event to the
/// host).
pub fn motion(
    instance: &NodeState,
    effect: &EffectHandle,
    pen: Pen,
    redraw: &mut dyn FnMut(),
) -> Outcome<Reply> {
    let drag = {
        let mut state = instance.overlay.locked();
        if let Some(Drag::Band { to, .. }) = state.drag.as_mut() {
            *to = pen.at;
            drop(state);
            redraw();
            return Ok(Reply::Done);
        }
        state.drag.clone()
    };
    if let Some(drag) = drag {
        // A drag that would break the scene keeps its last good position.
        return match write_drag(instance, &drag, pen) {
            Err(why @ Failure::BadInput(_)) => refuse(instance, effect, why),
            other => other.map(|()| Reply::Done),
        };
    }
    let r = Reader::new(instance.params(), instance.kind, pen.time);
    let mut state = instance.overlay.locked();
    let hover = under_pen(instance, &r, &state, pen).handle;
    // While a shape is drawn, every motion moves its rubber band.
    let building = match state.building.as_mut() {
        Some(b) => {
            b.cursor = Some(pen.at);
            true
        }
        None => false,
    };
    if hover != state.hover || building {
        state.hover = hover;
        drop(state);
        redraw();
    }
    Ok(Reply::Default)
}

/// Pen up: the drag's last write, and its edit block closed. A click that
/// drew no line takes its slot back.
pub fn up(instance: &NodeState, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
    let params = instance.params();
    let (drag, pixel) = {
        let mut state = instance.overlay.locked();
        (state.drag.take(), pixel_of(&state, &pen))
    };
    let Some(drag) = drag else {
        return Ok(Reply::Default);
    };
    if let Drag::Band { from, .. } = drag {
        let r = Reader::new(params, instance.kind, pen.time);
        let sides = {
            let state = instance.overlay.locked();
            editable(r.choice(&OVERLAY_EDIT), r.choice(&OVERLAY_SHOW), &state)
        };
        let (_, grid) = grabbable(instance, &r, pen.time);
        grid_pen::end_band(instance, grid.as_ref(), [from, pen.at], &sides);
        return Ok(Reply::Done);
    }
    let written = match &drag {
        Drag::NewLine {
            start,
            count_before,
            ..
        } if screen_length(*start, pen.at, pixel) < MIN_NEW_LINE_PX => {
            params.set_int(&LINE_COUNT, *count_before)
        }
        _ => write_drag(instance, &drag, pen),
    };
    let closed = params.end_edit();
    if matches!(drag, Drag::NewLine { .. }) {
        lines::hide_unused(instance.kind, params, pen.time);
    }
    match written {
        Err(why @ Failure::BadInput(_)) => {
            closed?;
            refuse(instance, effect, why)
        }
        other => {
            other?;
            closed?;
            shapes::settle(instance, effect, Ok(()))?;
            Ok(Reply::Done)
        }
    }
}

fn screen_length(p: Vec2, q: Vec2, pixel: (f64, f64)) -> f64 {
    Vec2::new((q.x - p.x) / pixel.0, (q.y - p.y) / pixel.1).length()
}

/// The first click of a polyline or curve: its first point, kept in the
/// overlay (a shape needs two points to be a scene feature).
fn start_building(
    instance: &NodeState,
    effect: &EffectHandle,
    tool: DrawTool,
    pen: Pen,
) -> Outcome<Reply> {
    // Refused up front when Scene Text cannot be edited.
    if let Err(why) = shapes::document(instance, pen.time) {
        return refuse(instance, effect, why);
    }
    let kind = match tool {
        DrawTool::Curve => FeatureKind::Curve,
        _ => FeatureKind::Polyline,
    };
    let mut state = instance.overlay.locked();
    state.building = Some(Building {
        kind,
        points: vec![pen.at],
        feature: None,
        cursor: None,
    });
    Ok(Reply::Done)
}

/// A click while a polyline or curve is being drawn: on the first point
/// (three or more points) closes it; on the last point (a double click)
/// ends it open; elsewhere adds a control point. One undo step per click.
fn building_click(instance: &NodeState, effect: &EffectHandle, pen: Pen) -> Outcome<Reply> {
    let (b, pixel) = {
        let state = instance.overlay.locked();
        let Some(b) = state.building.clone() else {
            return Ok(Reply::Default);
        };
        (b, pixel_of(&state, &pen))
    };
    let near = |p: Vec2| screen_length(p, pen.at, pixel) <= hit::RADIUS_PX;
    let first = b.points[0];
    let last = *b.points.last().unwrap_or(&first);
    if b.points.len() >= 3 && near(first) {
        return end_building(instance, effect, pen.time, &b, true);
    }
    if near(last) {
        return end_building(instance, effect, pen.time, &b, false);
    }
    let result = shapes::document(instance, pen.time).and_then(|mut doc| {
        let feature = match b.feature {
            Some(i) => {
                doc.append_point(i, pen.at).map_err(refused)?;
                i
            }
            None => {
                let f = Feature::new(b.kind, vec![first, pen.at], vec![first, pen.at]);
                doc.add_feature(&f).map_err(refused)?
            }
        };
        let label = format!("Draw {}", b.kind.name());
        instance
            .params()
            .edit_block(&label, || shapes::write(instance, &doc))?;
        Ok(feature)
    });
    match result {
        Ok(feature) => {
            let mut state = instance.overlay.locked();
            if let Some(building) = state.building.as_mut() {
                building.points.push(pen.at);
                building.feature = Some(feature);
            }
            state.selected = Some(feature);
            drop(state);
            shapes::settle(instance, effect, Ok(()))?;
            Ok(Reply::Done)
        }
        Err(why) => refuse(instance, effect, why),
    }
}

/// Ends the shape being drawn, closed or open.
fn end_building(
    instance: &NodeState,
    effect: &EffectHandle,
    time: f64,
    b: &Building,
    close: bool,
) -> Outcome<Reply> {
    {
        let mut state = instance.overlay.locked();
        state.building = None;
        state.selected = b.feature.or(state.selected);
    }
    let (Some(feature), true) = (b.feature, close) else {
        return Ok(Reply::Done);
    };
    let result = shapes::document(instance, time).and_then(|mut doc| {
        doc.set_closed(feature, true).map_err(refused)?;
        instance
            .params()
            .edit_block("Close Shape", || shapes::write(instance, &doc))
    });
    shapes::settle(instance, effect, result)?;
    Ok(Reply::Done)
}

/// Key down: modifiers narrow what the pen grabs (and stay the host's
/// too); Return ends a shape being drawn, Escape drops its unwritten first
/// point; Delete or Backspace deletes the hovered point (a slot's whole
/// line, or a shape left too short) or, over a body, the feature; over a
/// grid node, puts it back where the other side has it.
pub fn key_down(
    instance: &NodeState,
    effect: &EffectHandle,
    sym: i32,
    time: f64,
) -> Outcome<Reply> {
    let hovered = {
        let mut state = instance.overlay.locked();
        if keys::SHIFT.contains(&sym) {
            state.shift = true;
        }
        if keys::CONTROL.contains(&sym) {
            state.ctrl = true;
        }
        if keys::FINISH.contains(&sym) || keys::ESCAPE.contains(&sym) {
            return match state.building.take() {
                Some(b) => {
                    state.selected = b.feature.or(state.selected);
                    Ok(Reply::Done)
                }
                None => Ok(Reply::Default),
            };
        }
        if !keys::DELETE.contains(&sym) || state.drag.is_some() {
            return Ok(Reply::Default);
        }
        state.hover.take()
    };
    let Some(handle) = hovered else {
        let selected = instance.overlay.locked().grid_selection.is_some();
        if selected && grid_pen::reset(instance, effect, time, None)? {
            return Ok(Reply::Done);
        }
        return Ok(Reply::Default);
    };
    match (handle.owner, handle.part) {
        (Owner::Slot(k), _) => lines::clear(instance.kind, instance.params(), k, time)?,
        (Owner::Shape(feature), part) => {
            let result = shapes::document(instance, time).and_then(|mut doc| {
                match part {
                    Part::Point(i) => doc.delete_point(feature, i).map(|_| ()),
                    Part::Body { .. } => doc.delete_feature(feature),
                }
                .map_err(refused)?;
                delete_block(instance.params(), || shapes::write(instance, &doc))
            });
            instance.overlay.locked().selected = None;
            shapes::settle(instance, effect, result)?;
        }
        (Owner::Grid, _) => {
            if !grid_pen::reset(instance, effect, time, Some(handle))? {
                return Ok(Reply::Default);
            }
        }
        (Owner::File(_), _) => return Ok(Reply::Default),
    }
    Ok(Reply::Done)
}

fn delete_block(params: &Params, write: impl FnOnce() -> Outcome) -> Outcome {
    params.edit_block("Delete", write)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_length_is_in_screen_pixels() {
        let (p, q) = (Vec2::new(0.0, 0.0), Vec2::new(8.0, 6.0));
        assert_eq!(screen_length(p, q, (1.0, 1.0)), 10.0);
        assert_eq!(screen_length(p, q, (2.0, 2.0)), 5.0);
    }
}
