//! Uniform sampling of polylines and curves into corresponding points
//! (Lee, Wolberg et al. §4.2: "20 points per segment"), shared by every point-based method
//! and by the field method's treatment of curves.

use super::{catmull_rom, catmull_rom_closed, Feature, FeatureKind, Side};
use crate::geom::Vec2;

/// Samples per polyline or curve span when a method needs scattered points.
pub const DEFAULT_SAMPLES_PER_SEGMENT: usize = 20;

/// A corresponding pair of positions on A and B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointPair {
    /// Position on A.
    pub a: Vec2,
    /// Position on B.
    pub b: Vec2,
}

impl Feature {
    /// The feature's points on one side, sampled `per_segment` times per span
    /// (end point included once; a closed feature's first point is not
    /// repeated). Points and lines return their control points.
    pub fn sampled(&self, side: Side, per_segment: usize) -> Vec<Vec2> {
        sample_points(self.kind, self.closed, self.points(side), per_segment)
    }

    /// The feature on one side as the chain of points to draw or to cut into
    /// segments: [`Feature::sampled`], back to the first point when closed.
    pub fn outline(&self, side: Side, per_segment: usize) -> Vec<Vec2> {
        outline(self.kind, self.closed, self.points(side), per_segment)
    }

    /// Corresponding point pairs along the feature (same sampling on both sides,
    /// so the i-th samples correspond).
    pub fn point_pairs(&self, per_segment: usize) -> Vec<PointPair> {
        let a = self.sampled(Side::A, per_segment);
        let b = self.sampled(Side::B, per_segment);
        a.into_iter()
            .zip(b)
            .map(|(a, b)| PointPair { a, b })
            .collect()
    }
}

/// `points` of a feature of `kind` sampled `per_segment` times per span (the end point
/// once); points and lines give their control points. A `closed` polyline
/// or curve has one more span, from its last point back to its first, and
/// its samples stop short of the first point's second visit.
pub fn sample_points(
    kind: FeatureKind,
    closed: bool,
    points: &[Vec2],
    per_segment: usize,
) -> Vec<Vec2> {
    let per_segment = per_segment.max(1);
    match kind {
        FeatureKind::Point | FeatureKind::Line => points.to_vec(),
        FeatureKind::Polyline | FeatureKind::Curve => {
            let n = points.len();
            let spans = if closed { n } else { n.saturating_sub(1) };
            let mut out = Vec::with_capacity(spans * per_segment + 1);
            for span in 0..spans {
                let next = points[(span + 1) % n];
                for k in 0..per_segment {
                    let s = k as f64 / per_segment as f64;
                    out.push(match (kind, closed) {
                        (FeatureKind::Curve, true) => catmull_rom_closed(points, span, s),
                        (FeatureKind::Curve, false) => catmull_rom(points, span, s),
                        _ => points[span].lerp(next, s),
                    });
                }
            }
            if !closed {
                out.extend(points.last().copied());
            }
            out
        }
    }
}

/// [`sample_points`] as a chain to draw or cut into segments: a closed
/// feature's chain ends where it began.
pub fn outline(kind: FeatureKind, closed: bool, points: &[Vec2], per_segment: usize) -> Vec<Vec2> {
    let mut out = sample_points(kind, closed, points, per_segment);
    if closed && out.len() > 1 {
        out.push(out[0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polyline_sampling_is_uniform_per_segment_and_keeps_control_points() {
        let pts = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(20.0, 0.0),
            Vec2::new(20.0, 10.0),
        ];
        let f = Feature::new(FeatureKind::Polyline, pts.clone(), pts.clone());
        let s = f.sampled(Side::A, 20);
        assert_eq!(s.len(), 41);
        assert_eq!(s[0], pts[0]);
        assert_eq!(s[20], pts[1]);
        assert_eq!(s[40], pts[2]);
        assert_eq!(s[1], Vec2::new(1.0, 0.0));
        assert_eq!(s[21], Vec2::new(20.0, 0.5));
    }

    #[test]
    fn a_closed_polyline_has_a_span_back_to_its_first_point() {
        let pts = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(20.0, 0.0),
            Vec2::new(20.0, 10.0),
        ];
        let f = Feature::new(FeatureKind::Polyline, pts.clone(), pts.clone()).closed(true);
        let s = f.sampled(Side::A, 20);
        assert_eq!(s.len(), 60, "three spans, the first point once");
        assert_eq!(s[40], pts[2]);
        assert_eq!(s[50], Vec2::new(10.0, 5.0), "halfway back to the first");
        let o = f.outline(Side::A, 20);
        assert_eq!((o.len(), o[0], o[60]), (61, pts[0], pts[0]));
    }

    #[test]
    fn pairs_correspond_index_by_index() {
        let a = vec![Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0)];
        let b = vec![Vec2::new(0.0, 5.0), Vec2::new(0.0, 15.0)];
        let f = Feature::new(FeatureKind::Curve, a, b);
        let pairs = f.point_pairs(4);
        assert_eq!(pairs.len(), 5);
        assert_eq!(pairs[2].a, Vec2::new(5.0, 0.0));
        assert_eq!(pairs[2].b, Vec2::new(0.0, 10.0));
    }
}
