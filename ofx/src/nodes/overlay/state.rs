//! The overlay's state between actions, per effect instance: what the pen
//! is over, holds and is drawing, and the keys held. The node's state
//! holds one; nothing here reads the host.

use morphfx::features::{FeatureKind, Side};
use morphfx::geom::Vec2;
use morphfx::scene::edit::Document;
use morphfx::warp::mesh::Node;

use crate::nodes::params::{EditSides, Show};
use ofx_layer::plugin::Pen;

/// Where a feature lives, which says how an edit reaches it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    /// Line slot `k` (from 1): its params.
    Slot(usize),
    /// Feature `i` of Scene Text: edited in the text.
    Shape(usize),
    /// Feature `i` of Scene File: drawn, never edited.
    File(usize),
    /// Scene Text's mesh (a handle's point is a node, row-major from the
    /// bottom row).
    Grid,
}

/// Which part of a feature the pen holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Part {
    /// Control point `i` (a line's start is 0, its end 1).
    Point(usize),
    /// The body, in span `span` at its parameter `s` in `[0, 1]`: dragging
    /// moves the whole feature; a polyline or curve tool inserts a point.
    Body { span: usize, s: f64 },
}

/// A grabbable part of one feature on one side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Handle {
    pub owner: Owner,
    /// A's position or B's.
    pub side: Side,
    pub part: Part,
}

/// The overlay's state between actions, per effect instance.
#[derive(Debug, Default)]
pub struct State {
    pub(super) hover: Option<Handle>,
    pub(super) drag: Option<Drag>,
    /// The polyline or curve being drawn, click by click.
    pub(super) building: Option<Building>,
    /// The Scene Text shape last drawn or grabbed (Delete Shape's target).
    pub(super) selected: Option<usize>,
    /// The grid nodes selected, all on one side: a drag of one of them
    /// moves them all, Delete resets them.
    pub(super) grid_selection: Option<(Side, Vec<Node>)>,
    /// The last pen down on the grid and its side: where Add Row and its
    /// kin act.
    pub(super) grid_point: Option<(Side, Vec2)>,
    /// An edit was refused and its message is on the node.
    pub(super) refused: bool,
    pub(super) shift: bool,
    pub(super) ctrl: bool,
    /// Canonical units per screen pixel as the last OpenGL draw measured
    /// them: some hosts report (1, 1) at every zoom.
    pub(super) measured_pixel: Option<(f64, f64)>,
}

#[derive(Debug, Clone)]
pub(super) enum Drag {
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
    /// A rubber band from `from` to `to` selecting grid nodes (no edit).
    Band { from: Vec2, to: Vec2 },
    /// Moving Scene Text's mesh nodes `nodes` on `side` by the pen's
    /// motion since `from`; each event edits `before` afresh, no further
    /// than the grid stays unfolded.
    Grid {
        side: Side,
        nodes: Vec<Node>,
        from: Vec2,
        before: Box<Document>,
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
pub(super) struct Building {
    pub(super) kind: FeatureKind,
    pub(super) points: Vec<Vec2>,
    /// Its index in Scene Text once it has two points (and is written).
    pub(super) feature: Option<usize>,
    /// Where the pen last hovered: the next point's rubber band runs there.
    pub(super) cursor: Option<Vec2>,
}

/// The sides the pen may grab: the Edit Lines param, narrowed by Shift (A)
/// or Ctrl (B), among the sides shown.
pub(super) fn editable(edit: EditSides, show: Show, state: &State) -> Vec<Side> {
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
pub(super) fn pixel_of(state: &State, pen: &Pen) -> (f64, f64) {
    state.measured_pixel.unwrap_or(pen.pixel)
}
