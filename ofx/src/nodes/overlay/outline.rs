//! What the overlay shows and edits at one time: every feature of the node
//! (its line slots, the shapes of Scene Text, the features of Scene File)
//! with who owns it, and its in-between shape at the progress.

use morphfx::features::{Feature, FeatureKind, Side, Tween};
use morphfx::geom::Vec2;
use morphfx::warp::field::{line_pairs_toward, FieldSettings};

use super::state::Owner;
use crate::nodes::lines::SlotLine;

/// Samples per curve span drawn and hit-tested: smooth at any zoom a
/// compositor works at, and cheap (60 shapes × 20 points: 19k samples).
pub const CURVE_SAMPLES: usize = 8;

/// One feature as the overlay sees it at a time.
#[derive(Debug, Clone, PartialEq)]
pub struct Outline {
    pub owner: Owner,
    /// Its positions on A and B at the time.
    pub feature: Feature,
}

impl Outline {
    /// A line slot's line.
    pub fn slot(l: &SlotLine) -> Outline {
        Outline {
            owner: Owner::Slot(l.slot),
            feature: Feature::new(FeatureKind::Line, l.a.to_vec(), l.b.to_vec()),
        }
    }

    /// Whether the pen may edit it.
    pub fn editable(&self) -> bool {
        !matches!(self.owner, Owner::File(_))
    }

    /// Its label: the slot's number, else the feature's name, else `#n`
    /// (its place in the scene, from 1); for a suggestion, its confidence in
    /// percent (dozens of them share a picture: a name each would bury it).
    pub fn label(&self) -> String {
        match (self.owner, &self.feature.name, self.feature.confidence) {
            (Owner::Slot(k), _, _) => k.to_string(),
            (_, _, Some(c)) => format!("{:.0}%", c * 100.0),
            (_, Some(name), None) => name.clone(),
            (Owner::Shape(i) | Owner::File(i), None, None) => format!("#{}", i + 1),
            (Owner::Grid, None, None) => "grid".into(),
        }
    }

    /// The chain of points drawn for `side` (curves sampled, closed shapes
    /// back to their start).
    pub fn chain(&self, side: Side) -> Vec<Vec2> {
        self.feature.outline(side, per_span(self.feature.kind))
    }
}

/// Chain samples per span of a feature of `kind`.
pub fn per_span(kind: FeatureKind) -> usize {
    match kind {
        FeatureKind::Curve => CURVE_SAMPLES,
        _ => 1,
    }
}

/// The outline's in-between chain at progress `t`: lines as the field warp
/// places them (its line interpolation), other shapes point by point.
pub fn in_between(o: &Outline, t: f64, field: &FieldSettings) -> Vec<Vec2> {
    let f = &o.feature;
    if f.kind == FeatureKind::Line && f.a[0] != f.a[1] && f.b[0] != f.b[1] {
        let pairs = line_pairs_toward(std::slice::from_ref(f), Side::A, Tween::uniform(t), field);
        if let Some(pair) = pairs.first() {
            return vec![pair.dst.0, pair.dst.1];
        }
    }
    let moved = Feature {
        a: f.points_at(t),
        ..f.clone()
    };
    moved.outline(Side::A, per_span(f.kind))
}
