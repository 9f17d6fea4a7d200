//! Features as Beier-Neely line pairs, and lines interpolated over `t`.

use super::settings::{FieldSettings, LineInterpolation};
use crate::features::{Feature, FeatureKind, Side, Tween};
use crate::geom::Vec2;

/// A directed segment in the output (`dst`) and where it comes from in the
/// source image (`src`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinePair {
    /// The segment in the output.
    pub dst: (Vec2, Vec2),
    /// The segment in the source image.
    pub src: (Vec2, Vec2),
}

/// The line pairs that warp the image on `side` toward the features at `t`.
/// With per-point rates, `endpoints` moves each end at its own rate and
/// `center-angle` moves the line at the mean of its ends' rates.
///
/// Polylines give one line per segment and curves one per sample interval.
/// A point becomes a unit-length horizontal line on both sides: with equal
/// orientation and length the pair is a pure translation by the point's motion,
/// and its distance term is the distance to the point (within half a pixel).
pub fn line_pairs_toward(
    features: &[Feature],
    side: Side,
    t: Tween<'_>,
    settings: &FieldSettings,
) -> Vec<LinePair> {
    let mut pairs = Vec::new();
    for f in features {
        let (a, b) = (
            segments(f, Side::A, settings),
            segments(f, Side::B, settings),
        );
        for (sa, sb) in a.into_iter().zip(b) {
            let (r0, r1) = (t.rate(sa.0), t.rate(sa.1));
            let dst = match settings.interpolation {
                _ if r0 == r1 => interpolate_line(sa, sb, r0, settings.interpolation),
                LineInterpolation::Endpoints => (t.between(sa.0, sb.0), t.between(sa.1, sb.1)),
                mode => interpolate_line(sa, sb, 0.5 * (r0 + r1), mode),
            };
            let src = match side {
                Side::A => sa,
                Side::B => sb,
            };
            // Degenerate sampled segments carry no direction; skip them.
            if dst.0 != dst.1 && src.0 != src.1 {
                pairs.push(LinePair { dst, src });
            }
        }
    }
    pairs
}

fn segments(f: &Feature, side: Side, settings: &FieldSettings) -> Vec<(Vec2, Vec2)> {
    let pts = f.points(side);
    match f.kind {
        FeatureKind::Point => vec![(pts[0], pts[0] + Vec2::new(1.0, 0.0))],
        FeatureKind::Line => vec![(pts[0], pts[1])],
        FeatureKind::Polyline => f
            .outline(side, 1)
            .windows(2)
            .map(|w| (w[0], w[1]))
            .collect(),
        FeatureKind::Curve => f
            .outline(side, settings.curve_samples)
            .windows(2)
            .map(|w| (w[0], w[1]))
            .collect(),
    }
}

/// The line at `t` between its A position `a` and its B position `b`.
/// `t = 0` and `t = 1` return `a` and `b` bit for bit, so the end frames are
/// identity warps.
pub fn interpolate_line(
    a: (Vec2, Vec2),
    b: (Vec2, Vec2),
    t: f64,
    mode: LineInterpolation,
) -> (Vec2, Vec2) {
    if t == 0.0 {
        return a;
    }
    if t == 1.0 {
        return b;
    }
    match mode {
        LineInterpolation::Endpoints => (a.0.lerp(b.0, t), a.1.lerp(b.1, t)),
        LineInterpolation::CenterAngle => {
            let (ca, cb) = ((a.0 + a.1) * 0.5, (b.0 + b.1) * 0.5);
            let (da, db) = (a.1 - a.0, b.1 - b.0);
            let (ta, tb) = (da.y.atan2(da.x), db.y.atan2(db.x));
            // Turn the short way round.
            let mut turn = tb - ta;
            turn -= (turn / std::f64::consts::TAU).round() * std::f64::consts::TAU;
            let angle = ta + turn * t;
            let len = da.length() + (db.length() - da.length()) * t;
            let c = ca.lerp(cb, t);
            let half = Vec2::new(angle.cos(), angle.sin()) * (len * 0.5);
            (c - half, c + half)
        }
    }
}
