//! One feature of A found on B, and how sure the match is.
//!
//! A point is matched by its patch, then checked from B back to A
//! (forward-backward) and for uniqueness. A line is matched end by end the
//! same way, so its ends land on the same structure (an edge's ends are
//! corners or where it stops, both fixed in two directions), and then
//! along its length: patches between the ends must find the same edge on
//! B, on the straight line between B's ends. An edge that bends on B, or
//! ends where A's does not, is no line pair.

use crate::features::FeatureKind;
use crate::geom::Vec2;
use crate::track::template::{Affine, Template, TrackSettings};
use crate::track::{Grey, Pyramid};

use super::suggestion::{SuggestSettings, Suggestion};

/// Pyramid levels searched: with a 12 px patch, motion of about 100 px
/// from the guide is found.
pub const LEVELS: usize = 4;

/// A's or B's pyramid as the matcher searches it.
pub fn pyramid(grey: &Grey) -> Pyramid {
    Pyramid::new(grey.clone(), LEVELS, 16)
}

/// Correlation below which a match counts for nothing.
pub const MIN_CORRELATION: f64 = 0.8;

/// The farthest (pixels) a patch along a line may settle from the line
/// between B's ends.
const OFF_LINE_PX: f64 = 1.0;

/// A's point `p` found on B from `start`, checked both ways and for
/// uniqueness; `None` when doubtful.
pub fn point(
    a: &Pyramid,
    b: &Pyramid,
    p: Vec2,
    start: Vec2,
    track: &TrackSettings,
    settings: &SuggestSettings,
) -> Option<Suggestion> {
    let forward = Template::new(a, p, track);
    let there = forward.find(b, Affine::at(start), track);
    if !there.ok {
        return None;
    }
    let q = there.warp.c;
    // Back from B to A, started where the guide's inverse puts q (the
    // identity's: q itself), not at p: the search must find p on its own.
    let backward = Template::new(b, q, track);
    let back = backward.find(a, Affine::at(q - (start - p)), track);
    if !back.ok {
        return None;
    }
    let round_trip = back.warp.c.distance(p);
    if round_trip > settings.round_trip {
        return None;
    }
    // Repeated texture: the patch must not settle as well elsewhere from
    // starts a patch away.
    let step = 2.0 * track.radius as f64;
    for d in [
        Vec2::new(step, 0.0),
        Vec2::new(-step, 0.0),
        Vec2::new(0.0, step),
        Vec2::new(0.0, -step),
    ] {
        let other = forward.find(b, Affine::at(q + d), track);
        let elsewhere = other.ok && other.warp.c.distance(q) > 2.0;
        if elsewhere && other.correlation >= there.correlation - 0.02 {
            return None;
        }
    }
    let correlation = there.correlation.min(back.correlation);
    let trip = (1.0 - round_trip / settings.round_trip).clamp(0.0, 1.0);
    Some(Suggestion {
        kind: FeatureKind::Point,
        a: vec![p],
        b: vec![q],
        confidence: (sure(correlation) * (0.5 + 0.5 * trip)).clamp(0.0, 1.0),
    })
}

/// A's line `p`–`q` found on B: each end as a point, then patches about
/// a patch apart between them, each started on the line between B's ends
/// and required to settle on it. Its confidence is its least sure part's.
pub fn line(
    a: &Pyramid,
    b: &Pyramid,
    [p, q]: [Vec2; 2],
    guide: &(dyn Fn(Vec2) -> Vec2 + Sync),
    track: &TrackSettings,
    settings: &SuggestSettings,
) -> Option<Suggestion> {
    let ends = [p, q].map(|e| point(a, b, e, guide(e), track, settings));
    let [Some(from), Some(to)] = ends else {
        return None;
    };
    let (bp, bq) = (from.b[0], to.b[0]);
    let inner = (p.distance(q) / (2.0 * track.radius as f64)).ceil() as usize;
    let mut least = from.confidence.min(to.confidence);
    for k in 1..inner {
        let t = k as f64 / inner as f64;
        let template = Template::new(a, p.lerp(q, t), track);
        let found = template.find(b, Affine::at(bp.lerp(bq, t)), track);
        let on_line = found.warp.c.distance_to_segment(bp, bq) <= OFF_LINE_PX;
        if !found.ok || found.correlation < MIN_CORRELATION || !on_line {
            return None;
        }
        least = least.min(sure(found.correlation));
    }
    Some(Suggestion {
        kind: FeatureKind::Line,
        a: vec![p, q],
        b: vec![bp, bq],
        confidence: least,
    })
}

/// A correlation as a share of the way from [`MIN_CORRELATION`] to 1.
fn sure(correlation: f64) -> f64 {
    ((correlation - MIN_CORRELATION) / (1.0 - MIN_CORRELATION)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::RectI;

    /// The share of pixel `(i, j)` inside the polygon `corners` (counter-
    /// clockwise), by 4 × 4 supersampling.
    fn coverage(corners: &[Vec2], i: i32, j: i32) -> f32 {
        let inside = |p: Vec2| {
            (0..corners.len()).all(|k| {
                let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                (b - a).x * (p - a).y - (b - a).y * (p - a).x >= 0.0
            })
        };
        let hits = (0..16)
            .filter(|k| {
                let p = Vec2::new(
                    i as f64 + (k % 4) as f64 / 4.0 + 0.125,
                    j as f64 + (k / 4) as f64 / 4.0 + 0.125,
                );
                inside(p)
            })
            .count();
        hits as f32 / 16.0
    }

    /// A bright slanted box on dark ground, everything moved by `shift`.
    fn plate(corners: &[Vec2], shift: Vec2, gain: f32) -> Grey {
        let moved: Vec<Vec2> = corners.iter().map(|c| *c + shift).collect();
        Grey::from_fn(RectI::from_size(192, 144), |i, j| {
            gain * (0.1 + coverage(&moved, i, j))
        })
    }

    fn settings() -> (TrackSettings, SuggestSettings) {
        let settings = SuggestSettings::default();
        let track = TrackSettings {
            radius: settings.radius,
            levels: LEVELS,
            iterations: 30,
            min_correlation: MIN_CORRELATION,
        };
        (track, settings)
    }

    const BOX: [Vec2; 4] = [
        Vec2::new(50.0, 40.0),
        Vec2::new(140.0, 52.0),
        Vec2::new(132.0, 112.0),
        Vec2::new(42.0, 100.0),
    ];

    /// A box's side found on a moved copy (a guide that knows nothing of
    /// the move): its ends where the box's corners went, sure.
    #[test]
    fn a_boxs_side_is_found_end_to_end_where_it_went() {
        let shift = Vec2::new(3.3, -2.1);
        let (a, b) = (plate(&BOX, Vec2::ZERO, 1.0), plate(&BOX, shift, 1.3));
        let (track, settings) = settings();
        let found = line(
            &pyramid(&a),
            &pyramid(&b),
            [BOX[0], BOX[1]],
            &|p| p,
            &track,
            &settings,
        )
        .expect("found");
        assert_eq!(found.kind, FeatureKind::Line);
        for (p, q) in found.a.iter().zip(&found.b) {
            assert!(q.distance(*p + shift) < 0.25, "{p:?} -> {q:?}");
        }
        assert!(found.confidence > 0.8, "{}", found.confidence);
    }

    /// On B the side is bent in the middle (a roof, not a wall): the ends
    /// still match as corners, but the edge between them is no straight
    /// line there, so there is no line pair.
    #[test]
    fn a_side_that_bends_on_b_is_no_line_pair() {
        let a = plate(&BOX, Vec2::ZERO, 1.0);
        let peak = BOX[0].lerp(BOX[1], 0.5) + Vec2::new(0.0, -6.0);
        let b = Grey::from_fn(RectI::from_size(192, 144), |i, j| {
            let roof = coverage(&[BOX[0], peak, BOX[1]], i, j);
            0.1 + (coverage(&BOX, i, j) + roof).min(1.0)
        });
        let (pa, pb) = (pyramid(&a), pyramid(&b));
        let (track, settings) = settings();
        for end in [BOX[0], BOX[1]] {
            let own = point(&pa, &pb, end, end, &track, &settings);
            assert!(own.is_some(), "the corner at {end:?} matches on its own");
        }
        let found = line(&pa, &pb, [BOX[0], BOX[1]], &|p| p, &track, &settings);
        assert_eq!(found, None);
    }
}
