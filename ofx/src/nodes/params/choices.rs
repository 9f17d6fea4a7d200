//! The options of the nodes' choice params, in the order hosts save them.

use morphfx::choice::Choice;
use morphfx::transition::procedural::PatternKind;

/// What the viewer overlay shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Show {
    /// A's and B's lines, their connectors and the in-between lines.
    Both,
    /// A's lines only.
    A,
    /// B's lines only.
    B,
    /// The in-between lines at the current progress only.
    Between,
    /// Nothing.
    Off,
}

impl Choice for Show {
    const ALL: &'static [Self] = &[Show::Both, Show::A, Show::B, Show::Between, Show::Off];
    fn name(self) -> &'static str {
        match self {
            Show::Both => "A and B",
            Show::A => "A only",
            Show::B => "B only",
            Show::Between => "in-between",
            Show::Off => "off",
        }
    }
}

/// Which lines the overlay lets the pen move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EditSides {
    /// A's and B's.
    Both,
    /// A's only (B's are drawn, locked).
    A,
    /// B's only.
    B,
}

impl Choice for EditSides {
    const ALL: &'static [Self] = &[EditSides::Both, EditSides::A, EditSides::B];
    fn name(self) -> &'static str {
        match self {
            EditSides::Both => "A and B",
            EditSides::A => "A only",
            EditSides::B => "B only",
        }
    }
}

/// What a pen down in empty space in the viewer draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DrawTool {
    /// A drag draws a line into the next free slot.
    Line,
    /// A click adds a point feature to Scene Text.
    Point,
    /// Clicks add the control points of a polyline.
    Polyline,
    /// Clicks add the control points of a Catmull-Rom curve.
    Curve,
}

impl Choice for DrawTool {
    const ALL: &'static [Self] = &[
        DrawTool::Line,
        DrawTool::Point,
        DrawTool::Polyline,
        DrawTool::Curve,
    ];
    fn name(self) -> &'static str {
        match self {
            DrawTool::Line => "line",
            DrawTool::Point => "point",
            DrawTool::Polyline => "polyline",
            DrawTool::Curve => "curve",
        }
    }
}

/// The Transition param's options: uniform, then each procedural pattern
/// (curves come from the scene).
pub(super) const PATTERNS: [Option<PatternKind>; 5] = [
    None,
    Some(PatternKind::Ramp),
    Some(PatternKind::SineRows),
    Some(PatternKind::SineColumns),
    Some(PatternKind::Radial),
];

pub(super) fn pattern_label(p: Option<PatternKind>) -> &'static str {
    p.map_or("uniform", PatternKind::name)
}

/// How the field is evaluated (the tolerance is its own param).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EvaluationMode {
    Adaptive,
    Exact,
}

impl Choice for EvaluationMode {
    const ALL: &'static [Self] = &[EvaluationMode::Adaptive, EvaluationMode::Exact];
    fn name(self) -> &'static str {
        match self {
            EvaluationMode::Adaptive => "adaptive",
            EvaluationMode::Exact => "exact",
        }
    }
}

/// What a procedural transition paces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Affects {
    Both,
    Geometry,
    Colour,
}

impl Choice for Affects {
    const ALL: &'static [Self] = &[Affects::Both, Affects::Geometry, Affects::Colour];
    fn name(self) -> &'static str {
        match self {
            Affects::Both => "geometry and colour",
            Affects::Geometry => "geometry",
            Affects::Colour => "colour",
        }
    }
}
