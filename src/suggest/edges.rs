//! Where an artist would put a line: along a straight edge. A simplified
//! line segment detector after Grompone von Gioi et al. (LSD): regions are
//! grown from the strongest gradients over neighbours whose gradient
//! points the same way (within 22.5°), and a region is a segment when it
//! is a long, thin, well-filled rectangle. A gentle curve fills a wide
//! rectangle thinly and is left to points; texture grows no long region.

use crate::geom::Vec2;
use crate::track::Grey;

/// One straight edge: its ends (pixel centres of the grey it was found
/// on), and its mean gradient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// One end.
    pub p: Vec2,
    /// The other end.
    pub q: Vec2,
    /// The mean gradient magnitude over the edge (grey units per pixel).
    pub strength: f64,
}

impl Segment {
    /// Its length, pixels.
    pub fn length(&self) -> f64 {
        self.p.distance(self.q)
    }
}

/// The least gradient counted as edge, grey units per pixel: on the log
/// scale suggestions are made on, a step of about a third of a stop
/// spread over three pixels. Grain of a few percent stays below it.
pub const MIN_GRADIENT: f64 = 0.12;

/// The largest spread (pixels, root mean square across the edge, weighted
/// by gradient) of a region still counted as one straight edge: a soft
/// edge's gradient is a pixel or so wide however strong it is, where the
/// band over the threshold widens with its strength. A curve spreads
/// further, and so does an edge with texture beside it.
const MAX_SPREAD: f64 = 1.0;

/// The least share of its rectangle (four spreads wide) a region must
/// fill.
const MIN_DENSITY: f64 = 0.55;

/// The cosine of the largest angle between a pixel's gradient and its
/// region's (22.5°, LSD's).
const ALIGNED: f64 = 0.923_879_5;

/// The straight edges of `grey` at least `min_length` pixels long with
/// both ends `margin` pixels clear of the plate's edges, longest first.
pub fn segments(grey: &Grey, min_length: f64, margin: f64) -> Vec<Segment> {
    let b = grey.bounds;
    let (w, h) = (b.width(), b.height());
    if w < 3 || h < 3 {
        return Vec::new();
    }
    let gradient = gradients(grey);
    let mut order: Vec<usize> = (0..w * h)
        .filter(|&k| gradient[k].length() >= MIN_GRADIENT)
        .collect();
    order.sort_by(|&x, &y| gradient[y].length().total_cmp(&gradient[x].length()));
    let mut used = vec![false; w * h];
    let mut found = Vec::new();
    for seed in order {
        if used[seed] {
            continue;
        }
        let region = grow(seed, &gradient, &mut used, w, h);
        let centre = |k: usize| {
            Vec2::new(
                (b.x1 + (k % w) as i32) as f64 + 0.5,
                (b.y1 + (k / w) as i32) as f64 + 0.5,
            )
        };
        let Some(s) = rectangle(&region, &gradient, centre) else {
            continue;
        };
        let inside = |p: Vec2| {
            p.x - b.x1 as f64 >= margin
                && b.x2 as f64 - p.x >= margin
                && p.y - b.y1 as f64 >= margin
                && b.y2 as f64 - p.y >= margin
        };
        if s.length() >= min_length && inside(s.p) && inside(s.q) {
            found.push(s);
        }
    }
    found.sort_by(|s, t| t.length().total_cmp(&s.length()));
    found
}

/// The gradient at every pixel, by central differences.
fn gradients(grey: &Grey) -> Vec<Vec2> {
    let b = grey.bounds;
    let value = |i: i32, j: i32| {
        grey.sample(Vec2::new((b.x1 + i) as f64 + 0.5, (b.y1 + j) as f64 + 0.5)) as f64
    };
    (0..b.height() as i32)
        .flat_map(|j| (0..b.width() as i32).map(move |i| (i, j)))
        .map(|(i, j)| {
            Vec2::new(
                0.5 * (value(i + 1, j) - value(i - 1, j)),
                0.5 * (value(i, j + 1) - value(i, j - 1)),
            )
        })
        .collect()
}

/// The region grown from `seed`: 8-connected pixels of strong gradient
/// pointing within 22.5° of the region's mean gradient direction, marked
/// used as they join.
fn grow(seed: usize, gradient: &[Vec2], used: &mut [bool], w: usize, h: usize) -> Vec<usize> {
    let unit = |k: usize| gradient[k] * (1.0 / gradient[k].length());
    let mut region = vec![seed];
    let mut sum = unit(seed);
    used[seed] = true;
    let mut next = 0;
    while next < region.len() {
        let k = region[next];
        next += 1;
        let (i, j) = ((k % w) as i64, (k / w) as i64);
        for (di, dj) in NEIGHBOURS {
            let (x, y) = (i + di, j + dj);
            if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                continue;
            }
            let n = y as usize * w + x as usize;
            if used[n] || gradient[n].length() < MIN_GRADIENT {
                continue;
            }
            let direction = sum * (1.0 / sum.length());
            if unit(n).dot(direction) >= ALIGNED {
                used[n] = true;
                sum += unit(n);
                region.push(n);
            }
        }
    }
    region
}

const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The segment a region makes, when it is a thin, well-filled rectangle:
/// along its principal axis (pixels weighted by gradient), from end to
/// end, through its weighted centre (the edge's middle, where the
/// gradient peaks).
fn rectangle(region: &[usize], gradient: &[Vec2], at: impl Fn(usize) -> Vec2) -> Option<Segment> {
    if region.len() < 8 {
        return None;
    }
    let weight = |k: usize| gradient[k].length();
    let total: f64 = region.iter().map(|&k| weight(k)).sum();
    let centre = region
        .iter()
        .fold(Vec2::ZERO, |s, &k| s + at(k) * weight(k))
        * (1.0 / total);
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for &k in region {
        let d = at(k) - centre;
        xx += weight(k) * d.x * d.x;
        xy += weight(k) * d.x * d.y;
        yy += weight(k) * d.y * d.y;
    }
    // The principal axis: the larger eigenvector of the inertia.
    let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
    let along = Vec2::new(angle.cos(), angle.sin());
    let across = Vec2::new(-along.y, along.x);
    let (mut t0, mut t1, mut spread) = (f64::MAX, f64::MIN, 0.0);
    for &k in region {
        let d = at(k) - centre;
        let t = d.dot(along);
        (t0, t1) = (t0.min(t), t1.max(t));
        spread += weight(k) * d.dot(across).powi(2);
    }
    let length = t1 - t0 + 1.0;
    let spread = (spread / total).sqrt();
    let density = region.len() as f64 / (length * (4.0 * spread).max(1.0));
    if spread > MAX_SPREAD || density < MIN_DENSITY {
        return None;
    }
    Some(Segment {
        p: centre + along * (t0 + 0.5),
        q: centre + along * (t1 - 0.5),
        strength: total / region.len() as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::RectI;

    /// A bright square on dark ground, a stop and a half apart: its four
    /// sides are four segments, each along a side from near one corner to
    /// near the next.
    #[test]
    fn a_squares_four_sides_are_four_segments() {
        let grey = Grey::from_fn(RectI::from_size(96, 96), |i, j| {
            let inside = (24..72).contains(&i) && (24..72).contains(&j);
            if inside {
                1.5
            } else {
                0.0
            }
        });
        let found = segments(&grey, 20.0, 4.0);
        assert_eq!(found.len(), 4, "{found:?}");
        for s in &found {
            let vertical = (s.p.x - s.q.x).abs() < 0.5;
            let (fixed, ends) = if vertical {
                (s.p.x, [s.p.y, s.q.y])
            } else {
                assert!((s.p.y - s.q.y).abs() < 0.5, "{s:?}");
                (s.p.y, [s.p.x, s.q.x])
            };
            // The edge lies between pixels 23 and 24 or 71 and 72.
            assert!(
                (fixed - 24.0).abs() < 0.6 || (fixed - 72.0).abs() < 0.6,
                "{s:?}"
            );
            let (lo, hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
            assert!(
                (22.0..=28.0).contains(&lo) && (68.0..=74.0).contains(&hi),
                "{s:?}"
            );
        }
    }

    /// A circle's edge turns everywhere, texture has no long edges, a flat
    /// plate has none: no segments.
    #[test]
    fn curves_texture_and_flat_plates_give_no_segments() {
        let circle = Grey::from_fn(RectI::from_size(128, 128), |i, j| {
            let d = ((i as f64 - 64.0).powi(2) + (j as f64 - 64.0).powi(2)).sqrt();
            if d < 40.0 {
                1.5
            } else {
                0.0
            }
        });
        assert!(segments(&circle, 30.0, 4.0).is_empty());
        let mut noise = crate::testing::Lcg::new(7);
        let values: Vec<f32> = (0..128 * 128)
            .map(|_| noise.range(0.0, 2.0) as f32)
            .collect();
        let texture = Grey::from_fn(RectI::from_size(128, 128), |i, j| {
            values[j as usize * 128 + i as usize]
        });
        assert!(segments(&texture, 20.0, 4.0).is_empty());
        let flat = Grey::from_fn(RectI::from_size(64, 64), |_, _| 0.5);
        assert!(segments(&flat, 10.0, 4.0).is_empty());
    }

    /// A slanted edge is found along its slant, where it is.
    #[test]
    fn a_slanted_edge_is_found_where_it_lies() {
        // The edge y = 0.4 x + 20, bright above, antialiased over a pixel.
        let grey = Grey::from_fn(RectI::from_size(128, 96), |i, j| {
            let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
            let d = (y - 0.4 * x - 20.0) / (1.0f64 + 0.16).sqrt();
            (1.5 * (d + 0.5).clamp(0.0, 1.0)) as f32
        });
        let found = segments(&grey, 40.0, 0.0);
        assert_eq!(found.len(), 1, "{found:?}");
        let s = found[0];
        for p in [s.p, s.q] {
            let off = (p.y - 0.4 * p.x - 20.0) / (1.0f64 + 0.16).sqrt();
            assert!(off.abs() < 0.5, "{s:?} off the edge by {off}");
        }
        assert!(s.length() > 100.0, "{s:?}");
    }
}
