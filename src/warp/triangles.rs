//! Triangulated morphing (Wolberg: "The program builds triangles from these
//! points ... a linear blend of the contents of the triangles using
//! barycentric geometry"): the feature points, plus the frame's corners and
//! border points so the whole frame warps, triangulated by Delaunay (spade,
//! robust predicates) on their in-between positions; each triangle maps
//! affinely onto its source triangle.
//!
//! Seamless by construction: the map is evaluated by scan conversion in which
//! each pixel centre belongs to exactly one triangle. An edge's crossing of a
//! row is computed from the edge alone (endpoints in one canonical order,
//! exact at the endpoints), so the two triangles that share it see the same
//! number, and spans are half-open: no gaps, no pixel written twice. Affine
//! maps agree along a shared edge, so the map is continuous across it.

use rayon::prelude::*;
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

use crate::error::{Error, Result};
use crate::features::{Feature, Side, Tween};
use crate::geom::{PixelScale, RectD, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::Warp;

/// Border points per side of the frame, corners included.
pub const BORDER_POINTS: usize = 9;

#[derive(Debug, Clone, Copy)]
struct Node {
    at: Point2<f64>,
    source: Vec2,
}

impl HasPosition for Node {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.at
    }
}

/// One triangle: in-between vertices, and the affine map to the source,
/// `source = (m[0] x + m[1] y + m[2], m[3] x + m[4] y + m[5])`.
#[derive(Debug, Clone, Copy)]
struct Tri {
    v: [Vec2; 3],
    m: [f64; 6],
}

impl Tri {
    fn new(v: [Vec2; 3], s: [Vec2; 3]) -> Option<Tri> {
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let det = e1.x * e2.y - e1.y * e2.x;
        if det.abs() < 1e-12 || !det.is_finite() {
            return None;
        }
        let (f1, f2) = (s[1] - s[0], s[2] - s[0]);
        // Linear part L with L e1 = f1 and L e2 = f2.
        let inv = 1.0 / det;
        let (a, b) = (
            (f1.x * e2.y - f2.x * e1.y) * inv,
            (f2.x * e1.x - f1.x * e2.x) * inv,
        );
        let (c, d) = (
            (f1.y * e2.y - f2.y * e1.y) * inv,
            (f2.y * e1.x - f1.y * e2.x) * inv,
        );
        let m = [
            a,
            b,
            s[0].x - a * v[0].x - b * v[0].y,
            c,
            d,
            s[0].y - c * v[0].x - d * v[0].y,
        ];
        Some(Tri { v, m })
    }

    #[inline]
    fn apply(&self, p: Vec2) -> Vec2 {
        let m = &self.m;
        Vec2::new(
            m[0] * p.x + m[1] * p.y + m[2],
            m[3] * p.x + m[4] * p.y + m[5],
        )
    }

    /// Whether `p` lies in the closed triangle (either orientation).
    fn contains(&self, p: Vec2) -> bool {
        let side = |a: Vec2, b: Vec2| {
            let (e, d) = (b - a, p - a);
            e.x * d.y - e.y * d.x
        };
        let s = [
            side(self.v[0], self.v[1]),
            side(self.v[1], self.v[2]),
            side(self.v[2], self.v[0]),
        ];
        s.iter().all(|&x| x >= 0.0) || s.iter().all(|&x| x <= 0.0)
    }
}

/// The piecewise-affine warp of the image on one side toward the in-between
/// positions. Outside the triangulation (beyond the frame) points map to themselves.
#[derive(Debug, Clone)]
pub struct TriangleWarp {
    tris: Vec<Tri>,
    identity: bool,
}

impl TriangleWarp {
    /// Triangulates every feature's points (polylines and curves sampled
    /// `per_segment` times per span, Lee, Wolberg et al. §4.2) with the border of `frame`.
    /// Where two features meet at one in-between position, the first wins.
    pub fn toward<'a>(
        features: &[Feature],
        side: Side,
        t: impl Into<Tween<'a>>,
        per_segment: usize,
        frame: RectD,
    ) -> Result<TriangleWarp> {
        if !frame.is_valid() {
            return Err(Error::Invalid(format!(
                "triangles: the frame {frame:?} is empty or not finite"
            )));
        }
        let t = t.into();
        let mut nodes = Vec::new();
        for f in features {
            for pair in f.point_pairs(per_segment) {
                let source = match side {
                    Side::A => pair.a,
                    Side::B => pair.b,
                };
                nodes.push((t.between(pair.a, pair.b), source));
            }
        }
        for k in 0..BORDER_POINTS - 1 {
            let s = k as f64 / (BORDER_POINTS - 1) as f64;
            let (x, y) = (frame.x1 + s * frame.width(), frame.y1 + s * frame.height());
            let (x_rev, y_rev) = (frame.x2 - s * frame.width(), frame.y2 - s * frame.height());
            for p in [
                Vec2::new(x, frame.y1),
                Vec2::new(frame.x2, y),
                Vec2::new(x_rev, frame.y2),
                Vec2::new(frame.x1, y_rev),
            ] {
                nodes.push((p, p));
            }
        }
        let mut dt: DelaunayTriangulation<Node> = DelaunayTriangulation::new();
        for (at, source) in nodes {
            if !(at.is_finite() && source.is_finite()) {
                return Err(Error::Invalid(format!(
                    "triangles: a feature point is not finite ({at:?} → {source:?})"
                )));
            }
            let at = Point2::new(at.x, at.y);
            if dt.locate_vertex(at).is_some() {
                continue;
            }
            dt.insert(Node { at, source }).map_err(|e| {
                Error::Invalid(format!(
                    "triangles: cannot triangulate the point ({}, {}): {e:?}",
                    at.x, at.y
                ))
            })?;
        }
        let identity = dt.vertices().all(|v| {
            let n = v.data();
            n.source == Vec2::new(n.at.x, n.at.y)
        });
        let tris = dt
            .inner_faces()
            .filter_map(|f| {
                let [a, b, c] = f.vertices().map(|v| *v.data());
                let v = [a, b, c].map(|n| Vec2::new(n.at.x, n.at.y));
                Tri::new(v, [a.source, b.source, c.source])
            })
            .collect();
        Ok(TriangleWarp { tris, identity })
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True when there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Calls `span(j, i1, i2, tri)` for every run of pixel centres `i1..i2` of
    /// row `j` in `rows` that lies in triangle `tri` (pixels at `scale`).
    fn scan(
        &self,
        scale: PixelScale,
        rows: std::ops::Range<i32>,
        mut span: impl FnMut(i32, i32, i32, usize),
    ) {
        for (index, tri) in self.tris.iter().enumerate() {
            let mut v = tri.v.map(|p| scale.to_pixel(p));
            v.sort_by(|a, b| {
                (a.y, a.x)
                    .partial_cmp(&(b.y, b.x))
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            // Rows whose centre y lies in [v0.y, v2.y).
            let j_lo = ((v[0].y - 0.5).ceil() as i64).max(rows.start as i64);
            let j_hi = ((v[2].y - 0.5).ceil() as i64).min(rows.end as i64);
            for j in j_lo..j_hi {
                let y = j as f64 + 0.5;
                let long = crossing(v[0], v[2], y);
                let short = if y < v[1].y {
                    crossing(v[0], v[1], y)
                } else {
                    crossing(v[1], v[2], y)
                };
                let (l, r) = if long <= short {
                    (long, short)
                } else {
                    (short, long)
                };
                // Centres i + 0.5 in [l, r).
                let i1 = (l - 0.5).ceil();
                let i2 = (r - 0.5).ceil();
                if i2 > i1 {
                    span(j as i32, i1 as i32, i2 as i32, index);
                }
            }
        }
    }

    #[cfg(test)]
    pub(crate) fn coverage(&self, window: RectI, scale: PixelScale) -> Vec<u32> {
        let mut count = vec![0u32; window.area()];
        let w = window.width();
        self.scan(scale, window.y1..window.y2, |j, i1, i2, _| {
            let row = (j - window.y1) as usize * w;
            for i in i1.max(window.x1)..i2.min(window.x2) {
                count[row + (i - window.x1) as usize] += 1;
            }
        });
        count
    }

    #[cfg(test)]
    pub(crate) fn shared_edges_agree(&self, samples: usize) -> f64 {
        // Largest disagreement between the two affine maps of triangles that
        // share an edge, at points along that edge.
        let mut worst: f64 = 0.0;
        for (i, a) in self.tris.iter().enumerate() {
            for b in &self.tris[i + 1..] {
                for e in 0..3 {
                    let (p, q) = (a.v[e], a.v[(e + 1) % 3]);
                    if b.v.contains(&p) && b.v.contains(&q) {
                        for k in 0..=samples {
                            let x = p.lerp(q, k as f64 / samples as f64);
                            worst = worst.max(a.apply(x).distance(b.apply(x)));
                        }
                    }
                }
            }
        }
        worst
    }
}

/// Where the edge `p → q` crosses height `y`. The edge is taken in one order
/// whichever triangle asks, and its endpoints are returned exactly, so
/// neighbours agree to the bit.
#[inline]
fn crossing(p: Vec2, q: Vec2, y: f64) -> f64 {
    let (p, q) = if (p.y, p.x) <= (q.y, q.x) {
        (p, q)
    } else {
        (q, p)
    };
    if y == p.y {
        p.x
    } else if y == q.y {
        q.x
    } else {
        p.x + (y - p.y) * (q.x - p.x) / (q.y - p.y)
    }
}

impl Warp for TriangleWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        if self.identity {
            return p;
        }
        self.tris
            .iter()
            .find(|t| t.contains(p))
            .map_or(p, |t| t.apply(p))
    }

    fn is_identity(&self) -> bool {
        self.identity
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.identity {
            return WarpMap::identity(window, scale);
        }
        const BAND: usize = 32;
        let w = window.width();
        let mut pos = vec![[0f32; 2]; window.area()];
        if w == 0 {
            return WarpMap::new(window, scale, pos);
        }
        pos.par_chunks_mut(w * BAND)
            .enumerate()
            .for_each(|(band, out)| {
                let j0 = window.y1 + (band * BAND) as i32;
                let j1 = j0 + (out.len() / w) as i32;
                // Outside every triangle (beyond the frame): the identity.
                for (k, o) in out.iter_mut().enumerate() {
                    let c = scale.pixel_centre(window.x1 + (k % w) as i32, j0 + (k / w) as i32);
                    *o = [c.x as f32, c.y as f32];
                }
                self.scan(scale, j0..j1, |j, i1, i2, tri| {
                    let tri = &self.tris[tri];
                    let row = (j - j0) as usize * w;
                    for i in i1.max(window.x1)..i2.min(window.x2) {
                        let q = tri.apply(scale.pixel_centre(i, j));
                        out[row + (i - window.x1) as usize] = [q.x as f32, q.y as f32];
                    }
                });
            });
        WarpMap::new(window, scale, pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::FeatureKind;

    const FRAME: RectD = RectD::new(0.0, 0.0, 96.0, 64.0);

    /// A small deterministic generator (no dependency for tests).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn random_points(seed: u64, n: usize) -> Vec<Feature> {
        let mut r = Lcg(seed);
        (0..n)
            .map(|k| {
                // Every third point stays still on a pixel centre or edge
                // (at every t), where rasterisation ties are decided.
                let still = k % 3 == 0;
                let snap = |v: f64| if still { (v * 2.0).round() / 2.0 } else { v };
                let a = Vec2::new(snap(4.0 + 88.0 * r.next()), snap(4.0 + 56.0 * r.next()));
                let d = Vec2::new(12.0 * r.next() - 6.0, 12.0 * r.next() - 6.0);
                let b = if still { a } else { a + d };
                Feature::point(a, b)
            })
            .collect()
    }

    #[test]
    fn every_feature_point_maps_exactly() {
        for seed in 1..6 {
            let features = random_points(seed, 40);
            for (side, t) in [
                (Side::A, 0.3),
                (Side::B, 0.3),
                (Side::A, 1.0),
                (Side::B, 0.0),
            ] {
                let w = TriangleWarp::toward(&features, side, t, 20, FRAME).unwrap();
                for f in &features {
                    let at = f.a[0].lerp(f.b[0], t);
                    let want = match side {
                        Side::A => f.a[0],
                        Side::B => f.b[0],
                    };
                    let got = w.map(at);
                    assert!(
                        got.distance(want) < 1e-9,
                        "seed {seed}: {at:?} → {got:?}, want {want:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn every_pixel_is_written_exactly_once() {
        let window = RectI::from_size(96, 64);
        for seed in 1..8 {
            let mut features = random_points(seed, 60);
            // A collinear run and two points that meet mid-way.
            features.extend((0..5).map(|k| {
                let p = Vec2::new(10.0 + 10.0 * k as f64, 32.0);
                Feature::point(p, p + Vec2::new(0.0, 3.0))
            }));
            features.push(Feature::point(Vec2::new(40.0, 40.0), Vec2::new(50.0, 40.0)));
            features.push(Feature::point(Vec2::new(50.0, 40.0), Vec2::new(40.0, 40.0)));
            for scale in [PixelScale::UNIT, PixelScale::new(0.5, 0.5, 1.0)] {
                let w = TriangleWarp::toward(&features, Side::A, 0.5, 20, FRAME).unwrap();
                let win = RectI::new(0, 0, (96.0 * scale.x) as i32, (64.0 * scale.y) as i32);
                let count = w.coverage(if scale.is_unit() { window } else { win }, scale);
                let bad: Vec<_> = count.iter().enumerate().filter(|(_, c)| **c != 1).collect();
                assert!(
                    bad.is_empty(),
                    "seed {seed}: {} pixels not covered exactly once, first {:?}",
                    bad.len(),
                    bad.first()
                );
            }
        }
    }

    #[test]
    fn the_map_is_continuous_across_shared_edges() {
        let features = random_points(7, 80);
        let w = TriangleWarp::toward(&features, Side::B, 0.6, 20, FRAME).unwrap();
        assert!(w.len() > 100);
        assert!(w.shared_edges_agree(8) < 1e-9);
    }

    #[test]
    fn the_dense_map_matches_the_pointwise_map() {
        let features = random_points(3, 50);
        let w = TriangleWarp::toward(&features, Side::A, 0.8, 20, FRAME).unwrap();
        let window = RectI::new(-4, -4, 100, 68); // beyond the frame: identity
        let map = w.map_window(window, PixelScale::UNIT);
        for j in window.y1..window.y2 {
            for i in window.x1..window.x2 {
                let c = PixelScale::UNIT.pixel_centre(i, j);
                let got = map.get(i, j);
                assert!(
                    got.distance(w.map(c)) < 1e-3,
                    "({i}, {j}): {got:?} vs {:?}",
                    w.map(c)
                );
            }
        }
        assert_eq!(map.get(-3, 10), PixelScale::UNIT.pixel_centre(-3, 10));
    }

    #[test]
    fn identical_sides_give_the_identity_and_curves_are_sampled() {
        let p = |x, y| Vec2::new(x, y);
        let same = vec![Feature::new(
            FeatureKind::Curve,
            vec![p(10.0, 10.0), p(30.0, 40.0), p(60.0, 20.0)],
            vec![p(10.0, 10.0), p(30.0, 40.0), p(60.0, 20.0)],
        )];
        assert!(TriangleWarp::toward(&same, Side::A, 0.5, 20, FRAME)
            .unwrap()
            .is_identity());
        let moved = vec![Feature::new(
            FeatureKind::Curve,
            vec![p(10.0, 10.0), p(30.0, 40.0), p(60.0, 20.0)],
            vec![p(12.0, 10.0), p(30.0, 44.0), p(60.0, 24.0)],
        )];
        let w = TriangleWarp::toward(&moved, Side::A, 1.0, 20, FRAME).unwrap();
        // 2 spans × 20 samples + 1, plus 32 border points.
        assert!(w.len() >= 41 + 32 - 2);
        // A sample point mid-curve lands on its A position.
        let pairs = moved[0].point_pairs(20);
        let mid = pairs[20];
        assert!(w.map(mid.b).distance(mid.a) < 1e-9);
    }

    #[test]
    fn bad_frames_are_refused() {
        let f = random_points(1, 3);
        let e = TriangleWarp::toward(&f, Side::A, 0.5, 20, RectD::new(0.0, 0.0, 0.0, 10.0))
            .unwrap_err();
        assert!(e.to_string().contains("frame"), "{e}");
    }
}
