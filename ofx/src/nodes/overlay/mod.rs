//! The viewer overlay of both nodes: every feature drawn (line slots,
//! Scene Text's shapes, Scene File's features dimmer) with directions,
//! names, connectors and in-between shapes, and edited with the pen: drag
//! a point or a whole feature, draw lines, points, polylines and curves,
//! insert and delete points. With method mesh, the scene's grids too, their
//! nodes dragged no further than the grid stays unfolded. The OpenFX layer turns interact actions into these
//! calls; `pen` holds what the pen does, `shapes` the Scene Text edits.

mod grid;
mod grid_pen;
mod hit;
mod outline;
pub mod paint;
mod pen;
pub mod shapes;
mod state;
mod view;

pub use grid_pen::{add_line, remove_line};
pub use pen::{down as pen_down, key_down, motion as pen_motion, up as pen_up};
pub use state::State;
pub use view::draw;

use crate::nodes::params::{
    slot_ids, DRAW_TOOL, LINE_COUNT, LINE_SLOTS, METHOD, OVERLAY_EDIT, OVERLAY_SHOW, SCENE_FILE,
    SCENE_TEXT,
};
use crate::nodes::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::sync::Locked;
use ofx_layer::{keys, Outcome, Reply};

/// The params every overlay redraw depends on (the interact is slaved to them).
pub fn slave_params() -> Vec<String> {
    let mut ids: Vec<String> = [
        LINE_COUNT.name(),
        OVERLAY_SHOW.name(),
        OVERLAY_EDIT.name(),
        DRAW_TOOL.name(),
        SCENE_TEXT.name(),
        SCENE_FILE.name(),
        METHOD.name(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for k in 1..=LINE_SLOTS {
        ids.extend(slot_ids(k).names());
    }
    ids
}

/// Key up: releases a modifier.
pub fn key_up(instance: &NodeState, sym: i32) -> Outcome<Reply> {
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
pub fn lose_focus(instance: &NodeState) -> Outcome<Reply> {
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
            "Delete Shape: grab a shape in the viewer first (the last one \
                drawn or grabbed is deleted)",
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
