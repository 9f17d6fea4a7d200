//! The output mesh's node quads bucketed on a coarse grid, so that finding
//! the cell a point lies in (Newton's cold start) costs a bucket's quads,
//! not the mesh's. Maps restart Newton cold at points fixed in the image
//! (so that any window of a map gives the same bits), and a 256 × 256 mesh
//! has 65 025 quads to look through.

use crate::geom::Vec2;

/// Node quads (bottom left, bottom right, top right, top left) and, per
/// bucket of a grid over their bounds, the quads whose bounds reach it,
/// in increasing order.
#[derive(Debug, Clone)]
pub(super) struct Quads {
    quads: Vec<[Vec2; 4]>,
    lo: Vec2,
    /// Buckets per unit of position, across and up.
    per: Vec2,
    across: usize,
    up: usize,
    buckets: Vec<Vec<u32>>,
}

impl Quads {
    /// `quads` bucketed over the bounds `lo..hi` of their nodes.
    pub(super) fn new(quads: Vec<[Vec2; 4]>, lo: Vec2, hi: Vec2) -> Quads {
        // About one quad a bucket.
        let side = (quads.len() as f64).sqrt().ceil().max(1.0) as usize;
        let size = hi - lo;
        let per = Vec2::new(
            side as f64 / size.x.max(f64::MIN_POSITIVE),
            side as f64 / size.y.max(f64::MIN_POSITIVE),
        );
        let mut index = Quads {
            quads: Vec::new(),
            lo,
            per,
            across: side,
            up: side,
            buckets: vec![Vec::new(); side * side],
        };
        for (k, q) in quads.iter().enumerate() {
            let (min, max) = q.iter().fold((q[0], q[0]), |(a, b), p| {
                (
                    Vec2::new(a.x.min(p.x), a.y.min(p.y)),
                    Vec2::new(b.x.max(p.x), b.y.max(p.y)),
                )
            });
            let ((i0, j0), (i1, j1)) = (index.bucket(min), index.bucket(max));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    index.buckets[j * side + i].push(k as u32);
                }
            }
        }
        index.quads = quads;
        index
    }

    /// The bucket holding `p`, clamped to the grid.
    fn bucket(&self, p: Vec2) -> (usize, usize) {
        let at = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        let d = p - self.lo;
        (
            at(d.x * self.per.x, self.across),
            at(d.y * self.per.y, self.up),
        )
    }

    /// Every quad, in mesh order.
    pub(super) fn all(&self) -> &[[Vec2; 4]] {
        &self.quads
    }

    /// The first quad (in mesh order) that holds `p`, edges included.
    pub(super) fn holding(&self, p: Vec2) -> Option<usize> {
        let inside = |q: &[Vec2; 4]| {
            (0..4).all(|k| {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                let (e, d) = (b - a, p - a);
                e.x * d.y - e.y * d.x >= 0.0
            })
        };
        let (i, j) = self.bucket(p);
        self.buckets[j * self.across + i]
            .iter()
            .map(|&k| k as usize)
            .find(|&k| inside(&self.quads[k]))
    }
}

/// Where `p` lies in the bilinear quad `q` (bottom left, bottom right,
/// top right, top left), `(u, v)` in `[0, 1]²`: a few Newton steps from its
/// centre, enough for a start.
pub(super) fn within(q: &[Vec2; 4], p: Vec2) -> (f64, f64) {
    let [a, b, c, d] = *q;
    let (mut u, mut v) = (0.5, 0.5);
    for _ in 0..4 {
        let at =
            a * ((1.0 - u) * (1.0 - v)) + b * (u * (1.0 - v)) + c * (u * v) + d * ((1.0 - u) * v);
        let du = (b - a) * (1.0 - v) + (c - d) * v;
        let dv = (d - a) * (1.0 - u) + (c - b) * u;
        let det = du.x * dv.y - du.y * dv.x;
        if det.abs() < 1e-12 {
            break;
        }
        let e = p - at;
        u = (u + (e.x * dv.y - e.y * dv.x) / det).clamp(0.0, 1.0);
        v = (v + (du.x * e.y - du.y * e.x) / det).clamp(0.0, 1.0);
    }
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against the plain search over every quad, at points on a fine
    /// lattice over a bent 9 × 7 mesh and past its edges.
    #[test]
    fn the_buckets_find_the_quad_the_plain_search_finds() {
        let (rows, cols) = (7, 9);
        let node = |r: usize, c: usize| {
            let p = Vec2::new(30.0 * c as f64, 25.0 * r as f64);
            let inner = r > 0 && c > 0 && r + 1 < rows && c + 1 < cols;
            if inner {
                p + Vec2::new(9.0 * (p.y * 0.05).sin(), 7.0 * (p.x * 0.04).cos())
            } else {
                p
            }
        };
        let mut quads = Vec::new();
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                quads.push([
                    node(r, c),
                    node(r, c + 1),
                    node(r + 1, c + 1),
                    node(r + 1, c),
                ]);
            }
        }
        let plain = |p: Vec2| {
            quads.iter().position(|q| {
                (0..4).all(|k| {
                    let (a, b) = (q[k], q[(k + 1) % 4]);
                    let (e, d) = (b - a, p - a);
                    e.x * d.y - e.y * d.x >= 0.0
                })
            })
        };
        let index = Quads::new(quads.clone(), Vec2::new(0.0, 0.0), Vec2::new(240.0, 150.0));
        let mut found = 0;
        for j in -20..340 {
            for i in -20..520 {
                let p = Vec2::new(i as f64 * 0.5, j as f64 * 0.5);
                assert_eq!(index.holding(p), plain(p), "{p:?}");
                found += plain(p).is_some() as usize;
            }
        }
        assert!(found > 100_000, "{found} points inside");
    }

    /// A point made from known `(u, v)` in a skewed quad comes back.
    #[test]
    fn a_point_in_a_quad_is_placed_where_it_lies() {
        let q = [
            Vec2::new(0.0, 0.0),
            Vec2::new(40.0, 5.0),
            Vec2::new(50.0, 38.0),
            Vec2::new(-6.0, 30.0),
        ];
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.93, 0.07), (0.7, 0.95)] {
            let p = q[0] * ((1.0 - u) * (1.0 - v))
                + q[1] * (u * (1.0 - v))
                + q[2] * (u * v)
                + q[3] * ((1.0 - u) * v);
            let (gu, gv) = within(&q, p);
            assert!(
                (gu - u).abs() < 1e-6 && (gv - v).abs() < 1e-6,
                "{u}, {v}: {gu}, {gv}"
            );
        }
    }
}
