//! Suggested correspondences: feature pairs MorphFX proposes between two
//! different plates, for the artist to keep, move or delete.
//!
//! Features go where an artist would put them: lines along A's longest
//! straight edges ([`segments`]) and points at its corners ([`corners`]),
//! spread over the frame. Each is looked for on B with the tracker's
//! template (an affine patch with a gain and offset of brightness, coarse
//! to fine: [`crate::track::template`]), starting where a guide map (the
//! identity between the frames, or a coarse warp) says it went. A pair is
//! kept only when the match is sure: well correlated, found again from B
//! back to A at the same place (forward-backward), and unique (searches
//! started a patch away in each direction do not settle elsewhere as
//! well); a line's ends each so, and its length on one straight edge of B.
//! What is kept carries a confidence in `[0, 1]`; what is doubtful is
//! dropped. Suggestions keep clear of the user's own features and of each
//! other.

mod corners;
mod edges;
mod matching;
mod suggestion;

pub use corners::{corners, Corner, MIN_STRENGTH};
pub use edges::{segments, Segment};
pub use suggestion::{SuggestSettings, Suggestion};

use crate::error::{Error, Result};
use crate::features::Feature;
use crate::geom::{RectD, Vec2};
use crate::track::template::TrackSettings;
use crate::track::Grey;
use crate::warp::auto::{correspond, AutoSettings, Correspondence, WorkImage};
use matching::{pyramid, LEVELS, MIN_CORRELATION};
use suggestion::distance;

/// The share of `count` that may be lines: a warp needs its points all
/// over the picture; lines hold its strongest edges straight.
const LINE_SHARE: f64 = 0.25;

/// Pairs between `a` and `b` (each in its own pixel coordinates, pixel
/// centres at half-integers, y up): lines along A's longest straight edges
/// and points at its corners, best `settings.count` spread over A. `guide`
/// maps a point of A to where the search on B starts; `keep_clear` are A
/// points (the user's features) no suggestion may come near. An error
/// when A has no structure to match, or when nothing matched surely
/// enough.
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
    // Structure is found on the first halving: grain and aliasing are
    // smoothed away, and a corner a pixel off is as good a feature.
    let half = &pa.levels[pa.levels.len().min(2) - 1];
    let scale = (a.bounds.width() / half.bounds.width().max(1)).max(1) as f64;
    let margin = (settings.radius + 2) as f64;
    let clear = 0.5 * spacing;
    let clear_of_user = |points: &[Vec2]| keep_clear.iter().all(|q| distance(*q, points) >= clear);
    let edges: Vec<[Vec2; 2]> = segments(
        half,
        shortest_line(spacing, settings) / scale,
        margin / scale,
    )
    .iter()
    .map(|s| [s.p * scale, s.q * scale])
    .filter(|ends| clear_of_user(ends))
    .take(settings.count.max(1))
    .collect();
    let found = corners(half, spacing / scale, margin / scale);
    if found.is_empty() && edges.is_empty() {
        return Err(Error::Invalid(
            "A has no corners or texture to match (a blank or flat plate): nothing to suggest"
                .into(),
        ));
    }
    let candidates: Vec<Vec2> = found
        .iter()
        .map(|c| c.at * scale)
        .filter(|p| clear_of_user(&[*p]))
        .take(4 * settings.count.max(1))
        .collect();
    let good = |s: &Suggestion| s.confidence >= settings.min_confidence;
    let lines: Vec<Suggestion> = edges
        .par_iter()
        .filter_map(|&ends| matching::line(&pa, &pb, ends, guide, &track, settings))
        .filter(good)
        .collect();
    let points: Vec<Suggestion> = candidates
        .par_iter()
        .filter_map(|&p| matching::point(&pa, &pb, p, guide(p), &track, settings))
        .filter(good)
        .collect();
    let most_lines = (LINE_SHARE * settings.count as f64).floor() as usize;
    let kept = spread_out(lines, Vec::new(), a, most_lines, clear);
    let kept = spread_out(points, kept, a, settings.count, clear);
    if kept.is_empty() {
        return Err(Error::Invalid(format!(
            "none of A's {} corners and {} edges was found on B surely enough (confidence {} \
             or more): the plates may not show the same structure",
            candidates.len(),
            edges.len(),
            settings.min_confidence
        )));
    }
    Ok(kept)
}

/// `kept` and then as many of `matched` as make `count` in all, spread
/// over A: the worthiest of each of about `count` cells first (a warp
/// needs its features all over the picture, not the `count` surest in its
/// busiest corner), then the worthiest of the rest; none crowding
/// another.
fn spread_out(
    mut matched: Vec<Suggestion>,
    mut kept: Vec<Suggestion>,
    a: &Grey,
    count: usize,
    clear: f64,
) -> Vec<Suggestion> {
    matched.sort_by(|p, q| q.worth().total_cmp(&p.worth()));
    let b = a.bounds;
    let cell = ((b.width() * b.height()) as f64 / count.max(1) as f64).sqrt();
    let key = |s: &Suggestion| {
        let mid = s.a.iter().fold(Vec2::ZERO, |m, p| m + *p) * (1.0 / s.a.len() as f64);
        let (x, y) = (mid.x - b.x1 as f64, mid.y - b.y1 as f64);
        ((x / cell).floor() as i64, (y / cell).floor() as i64)
    };
    let mut cells = std::collections::HashSet::new();
    let (firsts, rest): (Vec<Suggestion>, Vec<Suggestion>) =
        matched.into_iter().partition(|s| cells.insert(key(s)));
    for s in firsts.into_iter().chain(rest) {
        if kept.len() < count && kept.iter().all(|k| !k.crowds(&s, clear)) {
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

/// The shortest line suggested: three patch radii (its ends' patches
/// and one between them), or most of the spacing between suggestions (a
/// shorter line says little more than a point would).
fn shortest_line(spacing: f64, settings: &SuggestSettings) -> f64 {
    (0.75 * spacing).max(3.0 * settings.radius as f64)
}

/// The distance between suggestions: `count` of them spread over A.
fn spacing(a: &Grey, count: usize) -> f64 {
    let area = (a.bounds.width() * a.bounds.height()) as f64;
    (area / (2 * count.max(1)) as f64).sqrt().max(8.0)
}
