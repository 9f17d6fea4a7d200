//! Suggested correspondences: feature pairs MorphFX proposes between two
//! different plates, for the artist to keep, move or delete.
//!
//! Points go where an artist would put them, at corners of A
//! ([`corners`]), spread over the frame. Each is looked for on B with the
//! tracker's template (an affine patch with a gain and offset of
//! brightness, coarse to fine: [`crate::track::template`]), starting where
//! a guide map (the identity between the frames, or a coarse warp) says it
//! went. A pair is kept only when the match is sure: well correlated, found
//! again from B back to A at the same place (forward-backward), and unique
//! (searches started a patch away in each direction do not settle
//! elsewhere as well). What is kept carries a confidence in `[0, 1]`;
//! what is doubtful is dropped. Suggestions keep clear of the user's own
//! features and of each other.

mod corners;

pub use corners::{corners, Corner, MIN_STRENGTH};

use crate::error::{Error, Result};
use crate::features::Feature;
use crate::geom::{RectD, Vec2};
use crate::track::template::{Affine, Template, TrackSettings};
use crate::track::{Grey, Pyramid};
use crate::warp::auto::{correspond, AutoSettings, Correspondence, WorkImage};

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

/// One proposed pair: a point on A, where it is on B, how sure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Suggestion {
    /// The point on A (A's pixel coordinates).
    pub a: Vec2,
    /// Where it is on B (B's pixel coordinates).
    pub b: Vec2,
    /// `[0, 1]`: the match's correlation and its round trip, combined.
    pub confidence: f64,
}

/// Correlation below which a match counts for nothing.
const MIN_CORRELATION: f64 = 0.8;

/// Pyramid levels searched: with a 12 px patch, motion of about 100 px
/// from the guide is found.
const LEVELS: usize = 4;

/// Pairs between `a` and `b` (each in its own pixel coordinates, pixel
/// centres at half-integers, y up), strongest structure first, best
/// `settings.count` by confidence. `guide` maps a point of A to where the
/// search on B starts; `keep_clear` are A points (the user's features)
/// no suggestion may come near. An error when A has no structure to
/// match, or when nothing matched surely enough.
pub fn suggest(
    a: &Grey,
    b: &Grey,
    guide: &(dyn Fn(Vec2) -> Vec2 + Sync),
    keep_clear: &[Vec2],
    settings: &SuggestSettings,
) -> Result<Vec<Suggestion>> {
    use rayon::prelude::*;
    let track = TrackSettings {
        radius: settings.radius,
        levels: LEVELS,
        iterations: 30,
        min_correlation: MIN_CORRELATION,
    };
    let spacing = spacing(a, settings.count);
    let (pa, pb) = (pyramid(a), pyramid(b));
    // Corners are found on the first halving: grain and aliasing are
    // smoothed away, and a corner a pixel off is as good a feature.
    let half = &pa.levels[pa.levels.len().min(2) - 1];
    let scale = (a.bounds.width() / half.bounds.width().max(1)).max(1) as f64;
    let margin = (settings.radius + 2) as f64;
    let found = corners(half, spacing / scale, margin / scale);
    if found.is_empty() {
        return Err(Error::Invalid(
            "A has no corners or texture to match (a blank or flat plate): nothing to suggest"
                .into(),
        ));
    }
    let clear = 0.5 * spacing;
    let candidates: Vec<Vec2> = found
        .iter()
        .map(|c| c.at * scale)
        .filter(|p| keep_clear.iter().all(|q| p.distance(*q) >= clear))
        .take(4 * settings.count.max(1))
        .collect();
    let matched: Vec<Suggestion> = candidates
        .par_iter()
        .filter_map(|&p| pair(&pa, &pb, p, guide(p), &track, settings))
        .filter(|s| s.confidence >= settings.min_confidence)
        .collect();
    let kept = spread_out(matched, a, settings.count, clear);
    if kept.is_empty() {
        return Err(Error::Invalid(format!(
            "none of A's {} corners was found on B surely enough (confidence {} or more): \
             the plates may not show the same structure",
            candidates.len(),
            settings.min_confidence
        )));
    }
    Ok(kept)
}

/// At most `count` of `matched`, spread over A: the surest of each of
/// about `count` cells first (a warp needs its features all over the
/// picture, not the `count` surest in its busiest corner), then the surest
/// of the rest; none closer than `clear` to another.
fn spread_out(mut matched: Vec<Suggestion>, a: &Grey, count: usize, clear: f64) -> Vec<Suggestion> {
    matched.sort_by(|p, q| q.confidence.total_cmp(&p.confidence));
    let b = a.bounds;
    let cell = ((b.width() * b.height()) as f64 / count.max(1) as f64).sqrt();
    let key = |p: Vec2| {
        let (x, y) = (p.x - b.x1 as f64, p.y - b.y1 as f64);
        ((x / cell).floor() as i64, (y / cell).floor() as i64)
    };
    let mut cells = std::collections::HashSet::new();
    let (firsts, rest): (Vec<Suggestion>, Vec<Suggestion>) =
        matched.into_iter().partition(|s| cells.insert(key(s.a)));
    let mut kept: Vec<Suggestion> = Vec::new();
    for s in firsts.into_iter().chain(rest) {
        if kept.len() < count && kept.iter().all(|k| k.a.distance(s.a) >= clear) {
            kept.push(s);
        }
    }
    kept
}

/// A plate's luminance as the matcher should see it: on a log scale, so an
/// HDR plate's highlights do not drown its shadows' texture (a gain
/// between the plates becomes an offset, which the match ignores).
pub fn perceptual(linear: &Grey) -> Grey {
    let floor = 1.0 / 256.0;
    Grey::from_fn(linear.bounds, |i, j| {
        let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
        (linear.sample(p).max(0.0) + floor).log2()
    })
}

/// The longer side, in pixels, the guide's pictures are brought down to:
/// the least-work search sees a picture's large shapes (a face's outline,
/// where its eyes are), which is what a guide needs, in well under a
/// second.
pub const GUIDE_SIDE: usize = 256;

/// A guide for plates of different subjects: the least-work warp of A
/// onto B (Gao and Sederberg), found on the pictures brought down to about
/// [`GUIDE_SIDE`] pixels, with `anchors` (the user's features) held.
/// Frames are the plates' canonical frames; the map it gives takes A's
/// canonical points to B's.
pub fn work_guide(
    a: &WorkImage,
    a_frame: RectD,
    b: &WorkImage,
    b_frame: RectD,
    anchors: &[Feature],
) -> Result<Correspondence> {
    let small = |im: &WorkImage| {
        if im.width.max(im.height) <= GUIDE_SIDE {
            return im.clone();
        }
        let mut levels = im.halvings(8);
        let fit = levels
            .iter()
            .position(|l| l.width.max(l.height) <= GUIDE_SIDE);
        match fit {
            Some(k) => levels.swap_remove(k),
            None => levels.pop().unwrap_or_else(|| im.clone()),
        }
    };
    let (sa, sb) = (small(a), small(b));
    let settings = AutoSettings::default();
    let (found, _) = correspond(&sa, a_frame, &sb, b_frame, anchors, 4, &settings, None)?;
    Ok(found)
}

/// The distance between suggestions: `count` of them spread over A.
fn spacing(a: &Grey, count: usize) -> f64 {
    let area = (a.bounds.width() * a.bounds.height()) as f64;
    (area / (2 * count.max(1)) as f64).sqrt().max(8.0)
}

fn pyramid(grey: &Grey) -> Pyramid {
    Pyramid::new(grey.clone(), LEVELS, 16)
}

/// A's point `p` found on B from `start`, checked both ways and for
/// uniqueness; `None` when doubtful.
fn pair(
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
    let sure = ((correlation - MIN_CORRELATION) / (1.0 - MIN_CORRELATION)).clamp(0.0, 1.0);
    let trip = (1.0 - round_trip / settings.round_trip).clamp(0.0, 1.0);
    Some(Suggestion {
        a: p,
        b: q,
        confidence: (sure * (0.5 + 0.5 * trip)).clamp(0.0, 1.0),
    })
}
