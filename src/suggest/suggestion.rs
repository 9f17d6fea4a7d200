//! What a suggestion is, what the search is asked for, and how two
//! suggestions are weighed against each other when they are picked.

use crate::features::FeatureKind;
use crate::geom::Vec2;

/// What `suggest` proposes, and how sure it must be.
#[derive(Debug, Clone, PartialEq)]
pub struct SuggestSettings {
    /// Pairs proposed at most.
    pub count: usize,
    /// Pairs less sure than this are dropped.
    pub min_confidence: f64,
    /// The farthest apart (A pixels) a point found from B back to A may
    /// land from where it started.
    pub round_trip: f64,
    /// Half the side of the matched patch (pixels).
    pub radius: usize,
}

impl Default for SuggestSettings {
    fn default() -> Self {
        SuggestSettings {
            count: 40,
            min_confidence: 0.5,
            round_trip: 0.75,
            radius: 12,
        }
    }
}

/// One proposed pair: a point or a line on A, where it is on B, how sure.
#[derive(Debug, Clone, PartialEq)]
pub struct Suggestion {
    /// A point, or a line along a straight edge.
    pub kind: FeatureKind,
    /// Its points on A (A's pixel coordinates).
    pub a: Vec<Vec2>,
    /// Where they are on B (B's pixel coordinates).
    pub b: Vec<Vec2>,
    /// `[0, 1]`: the match's correlation and its round trip, combined.
    pub confidence: f64,
}

impl Suggestion {
    /// The least distance between the two on A (a line counts along its
    /// length).
    pub(super) fn gap(&self, other: &Suggestion) -> f64 {
        let one_way = |x: &Suggestion, y: &Suggestion| {
            x.a.iter()
                .map(|&p| distance(p, &y.a))
                .fold(f64::MAX, f64::min)
        };
        one_way(self, other).min(one_way(other, self))
    }

    /// How much it is worth to the warp: its confidence, times a line's
    /// length in patch sides (a long, sure edge holds more of the picture
    /// straight than a short one).
    pub(super) fn worth(&self) -> f64 {
        let length: f64 = self.a.windows(2).map(|s| s[0].distance(s[1])).sum();
        self.confidence * (1.0 + length / WORTH_LENGTH)
    }

    /// Whether the two are too close to both be suggested: closer than
    /// `clear`, unless both are lines that meet at an angle (the sides of
    /// a box share its corners; a line beside a parallel one says nothing
    /// new).
    pub(super) fn crowds(&self, other: &Suggestion, clear: f64) -> bool {
        let direction = |s: &Suggestion| {
            let d = s.a[s.a.len() - 1] - s.a[0];
            d * (1.0 / d.length().max(1e-9))
        };
        let lines = self.kind == FeatureKind::Line && other.kind == FeatureKind::Line;
        let across = lines && direction(self).dot(direction(other)).abs() < MEETING_COS;
        !across && self.gap(other) < clear
    }
}

/// The length by which a line's worth grows by its confidence, pixels.
const WORTH_LENGTH: f64 = 25.0;

/// Lines whose directions are further apart than 60° may meet.
const MEETING_COS: f64 = 0.5;

/// From `p` to the nearest of `points` (a line's: along it).
pub(super) fn distance(p: Vec2, points: &[Vec2]) -> f64 {
    match points {
        [q] => p.distance(*q),
        _ => points
            .windows(2)
            .map(|s| p.distance_to_segment(s[0], s[1]))
            .fold(f64::MAX, f64::min),
    }
}
