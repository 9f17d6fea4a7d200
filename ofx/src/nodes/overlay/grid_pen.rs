//! The pen on the mesh: a node grabbed alone or with the selection,
//! Shift- or Ctrl-click adding a node to the selection or taking it out,
//! a rubber band in empty space selecting the nodes inside it, Delete
//! putting the selected (else the hovered) nodes back where the other
//! side has them, and rows and columns added (Shift+Ctrl-click, or the
//! buttons at the last point clicked on the grid) or removed.

use morphfx::features::Side;
use morphfx::geom::Vec2;
use morphfx::warp::mesh::{Line, Node};

use super::grid::{node_at, Grid};
use super::shapes::{self, refused};
use super::state::{Drag, Handle, Part};
use crate::nodes::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::plugin::Pen;
use ofx_layer::sync::Locked;
use ofx_layer::{Failure, Outcome};

/// A pen down on the grid node `h`: with Shift or Ctrl held, the node
/// joins the selection or leaves it (no drag); otherwise a drag of the
/// whole selection when the node is in it, else of the node alone (then
/// the selection), opening the drag's edit block.
pub(super) fn grab(instance: &NodeState, h: Handle, pen: Pen) -> Outcome<Option<Drag>> {
    let doc = shapes::document(instance, pen.time)?;
    let cols = doc
        .scene()
        .mesh_at(pen.time)
        .map(|m| m.a.cols())
        .ok_or_else(|| Failure::BadInput("Scene Text has no mesh".into()))?;
    let Part::Point(i) = h.part else {
        return Err(Failure::BadInput("a grid is grabbed by its nodes".into()));
    };
    let node = node_at(i, cols);
    let nodes = {
        let mut state = instance.overlay.locked();
        let mut selected = match state.grid_selection.take() {
            Some((side, nodes)) if side == h.side => nodes,
            _ => Vec::new(),
        };
        if state.shift || state.ctrl {
            match selected.iter().position(|n| *n == node) {
                Some(k) => {
                    selected.remove(k);
                }
                None => selected.push(node),
            }
            state.grid_selection = (!selected.is_empty()).then_some((h.side, selected));
            return Ok(None);
        }
        if !selected.contains(&node) {
            selected = vec![node];
        }
        state.grid_selection = Some((h.side, selected.clone()));
        selected
    };
    let label = match nodes.len() {
        1 => "Move Grid Node",
        _ => "Move Grid Nodes",
    };
    instance.params().begin_edit(label)?;
    Ok(Some(Drag::Grid {
        side: h.side,
        nodes,
        from: pen.at,
        before: Box::new(doc),
    }))
}

/// A pen down in empty space over an editable grid: the selection goes,
/// and a rubber band starts.
pub(super) fn start_band(instance: &NodeState, pen: Pen) -> Drag {
    instance.overlay.locked().grid_selection = None;
    Drag::Band {
        from: pen.at,
        to: pen.at,
    }
}

/// The band let go: the nodes inside it on the first of `sides` that has
/// any become the selection.
pub(super) fn end_band(instance: &NodeState, grid: Option<&Grid>, band: [Vec2; 2], sides: &[Side]) {
    let Some(grid) = grid else { return };
    let (lo, hi) = (
        Vec2::new(band[0].x.min(band[1].x), band[0].y.min(band[1].y)),
        Vec2::new(band[0].x.max(band[1].x), band[0].y.max(band[1].y)),
    );
    let inside = |p: &Vec2| p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y;
    let selection = sides.iter().find_map(|&side| {
        let mesh = grid.side(side);
        let nodes: Vec<Node> = (0..mesh.nodes().len())
            .filter(|&i| inside(&mesh.nodes()[i]))
            .map(|i| node_at(i, mesh.cols()))
            .collect();
        (!nodes.is_empty()).then_some((side, nodes))
    });
    instance.overlay.locked().grid_selection = selection;
}

/// Delete over the grid: the selected nodes, else `hovered` (a node),
/// put back where the other side has them, one undo step. Whether there
/// was anything to reset.
pub(super) fn reset(
    instance: &NodeState,
    effect: &EffectHandle,
    time: f64,
    hovered: Option<Handle>,
) -> Outcome<bool> {
    let selection = instance.overlay.locked().grid_selection.clone();
    let result = shapes::document(instance, time).and_then(|mut doc| {
        let cols = doc.scene().mesh_at(time).map_or(1, |m| m.a.cols());
        let (side, nodes) = match (selection, hovered) {
            (Some(chosen), _) => chosen,
            (
                None,
                Some(Handle {
                    side,
                    part: Part::Point(i),
                    ..
                }),
            ) => (side, vec![node_at(i, cols)]),
            _ => return Ok(false),
        };
        doc.reset_nodes(time, side, &nodes).map_err(refused)?;
        instance
            .params()
            .edit_block("Reset Grid Nodes", || shapes::write(instance, &doc))?;
        Ok(true)
    });
    let done = matches!(result, Ok(true));
    shapes::settle(instance, effect, result.map(|_| ()))?;
    Ok(done)
}

/// Where rows and columns go: the last pen down on the grid, and on which
/// side.
pub(super) fn remember_point(instance: &NodeState, side: Side, at: Vec2) {
    instance.overlay.locked().grid_point = Some((side, at));
}

/// Shift+Ctrl-click inside the grid: a line through the pen, a row where
/// the pen is nearer a column line than a row line (a row crosses the
/// columns there), else a column. One undo step.
pub(super) fn add_at_pen(
    instance: &NodeState,
    effect: &EffectHandle,
    side: Side,
    pen: Pen,
) -> Outcome {
    remember_point(instance, side, pen.at);
    let result = shapes::document(instance, pen.time).and_then(|doc| {
        let pair = doc.scene().mesh_at(pen.time);
        let (s, r) = pair.and_then(|p| p.locate(side, pen.at)).ok_or_else(|| {
            Failure::BadInput(
                "Shift+Ctrl-click inside the grid to add a row or column there".into(),
            )
        })?;
        let line = if (s - s.round()).abs() < (r - r.round()).abs() {
            Line::Row
        } else {
            Line::Column
        };
        add(instance, doc, (side, pen.at), pen.time, line)
    });
    shapes::settle(instance, effect, result)
}

/// The Add Row and Add Column buttons: a line through the last point
/// clicked on the grid.
pub fn add_line(instance: &NodeState, effect: &EffectHandle, time: f64, line: Line) -> Outcome {
    let point = instance.overlay.locked().grid_point;
    let result = match point {
        Some(at) => {
            shapes::document(instance, time).and_then(|doc| add(instance, doc, at, time, line))
        }
        None => Err(Failure::BadInput(format!(
            "Add {}: click the grid in the viewer where it goes first",
            title(line)
        ))),
    };
    shapes::settle(instance, effect, result)
}

/// The Remove Row and Remove Column buttons: the line nearest the last
/// point clicked on the grid (a border one stays).
pub fn remove_line(instance: &NodeState, effect: &EffectHandle, time: f64, line: Line) -> Outcome {
    let point = instance.overlay.locked().grid_point;
    let result = shapes::document(instance, time).and_then(|mut doc| {
        let located = point.and_then(|(side, at)| doc.scene().mesh_at(time)?.locate(side, at));
        let Some((s, r)) = located else {
            return Err(Failure::BadInput(format!(
                "Remove {}: click the grid in the viewer on the one to remove first",
                title(line)
            )));
        };
        let index = match line {
            Line::Row => r,
            Line::Column => s,
        };
        doc.remove_grid_line(line, index.round() as usize)
            .map_err(refused)?;
        write_reshaped(instance, &doc, &format!("Remove {}", title(line)))
    });
    shapes::settle(instance, effect, result)
}

fn add(
    instance: &NodeState,
    mut doc: morphfx::scene::edit::Document,
    (side, at): (Side, Vec2),
    time: f64,
    line: Line,
) -> Outcome {
    doc.add_grid_line(time, side, at, line).map_err(refused)?;
    write_reshaped(instance, &doc, &format!("Add {}", title(line)))
}

/// A mesh with a line more or less into Scene Text, one undo step.
fn write_reshaped(
    instance: &NodeState,
    doc: &morphfx::scene::edit::Document,
    label: &str,
) -> Outcome {
    instance
        .params()
        .edit_block(label, || shapes::write(instance, doc))?;
    // Node indices moved: a selection would name other nodes now.
    instance.overlay.locked().grid_selection = None;
    Ok(())
}

fn title(line: Line) -> &'static str {
    match line {
        Line::Row => "Row",
        Line::Column => "Column",
    }
}
