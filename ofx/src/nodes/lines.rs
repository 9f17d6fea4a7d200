//! The line slots as the user edits them: read at a time with their
//! numbers, cleared, and hidden beyond Line Count.

use morphfx::features::Side;
use morphfx::geom::Vec2;

use super::kind::NodeKind;
use super::params::{
    slot_clear, slot_group, slot_ids, spec, Reader, SlotIds, LINE_COUNT, LINE_SLOTS,
};
use ofx_layer::params::Params;
use ofx_layer::spec::{Id, Kind, Point};
use ofx_layer::Outcome;

/// One enabled slot's lines at a time: A's and B's, start then end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlotLine {
    /// The slot's number, from 1.
    pub slot: usize,
    /// The line on A.
    pub a: [Vec2; 2],
    /// The line on B.
    pub b: [Vec2; 2],
}

impl SlotLine {
    /// The line on `side`.
    pub fn side(&self, side: Side) -> [Vec2; 2] {
        match side {
            Side::A => self.a,
            Side::B => self.b,
        }
    }
}

/// The param id of slot `slot`'s end `end` (0: start, 1: end) on `side`.
pub fn end_id(slot: usize, side: Side, end: usize) -> Id<Point> {
    let SlotIds { a, b, .. } = slot_ids(slot);
    let [start, stop] = match side {
        Side::A => a,
        Side::B => b,
    };
    if end == 0 {
        start
    } else {
        stop
    }
}

/// The enabled slots up to Line Count whose ends are all finite, even
/// zero-length ones (a line being drawn starts with no length).
pub fn slot_lines(r: &Reader<'_>) -> Vec<SlotLine> {
    let mut lines = Vec::new();
    for k in 1..=(r.int(&LINE_COUNT).max(0) as usize).min(LINE_SLOTS) {
        let ids = slot_ids(k);
        if !r.bool(&ids.enable) {
            continue;
        }
        let ends = ids.ends().map(|id| r.point(id));
        if let [Some(a0), Some(a1), Some(b0), Some(b1)] = ends {
            if [a0, a1, b0, b1].iter().all(|p| p.is_finite()) {
                lines.push(SlotLine {
                    slot: k,
                    a: [a0, a1],
                    b: [b0, b1],
                });
            }
        }
    }
    lines
}

/// Clears slot `k`: its ends lose their keys and go back to their
/// defaults, and it is turned off; a trailing run of disabled slots leaves
/// Line Count. One undo step.
pub fn clear(kind: &'static NodeKind, params: &Params, k: usize, time: f64) -> Outcome {
    let enable = slot_ids(k).enable;
    params.edit_block(&format!("Clear Line {k}"), || {
        for side in [Side::A, Side::B] {
            for end in 0..2 {
                let id = end_id(k, side, end);
                // A host without keyframes (or without this call) has no
                // keys to delete: the value below is all there is.
                let _ = params.delete_all_keys(&id);
                params.set_point(&id, default_point(kind, &id))?;
            }
        }
        params.set_int(&enable, 0)?;
        let r = Reader::new(params, kind, time);
        let mut count = r.int(&LINE_COUNT).max(0) as usize;
        while count > 0 && !r.bool(&slot_ids(count).enable) {
            count -= 1;
        }
        params.set_int(&LINE_COUNT, count as i32)
    })?;
    hide_unused(kind, params, time);
    Ok(())
}

fn default_point(kind: &'static NodeKind, id: &Id<Point>) -> (f64, f64) {
    match spec(kind, id.name()).map(|p| p.kind()) {
        Some(Kind::Point { default }) => *default,
        _ => (0.0, 0.0),
    }
}

/// Shows the slots up to Line Count and hides the rest. Best effort: a
/// host that cannot hide params shows them all, which is only untidy.
pub fn hide_unused(kind: &'static NodeKind, params: &Params, time: f64) {
    let count = Reader::new(params, kind, time).int(&LINE_COUNT).max(0) as usize;
    for k in 1..=LINE_SLOTS {
        let secret = k > count;
        let ids = slot_ids(k);
        let _ = params.set_secret(&slot_group(k), secret);
        let _ = params.set_secret(&ids.enable, secret);
        for id in ids.ends() {
            let _ = params.set_secret(id, secret);
        }
        let _ = params.set_secret(&slot_clear(k), secret);
    }
}
