//! The morph of a solved correspondence: A's lattice and B's control points
//! are two meshes of bilinear quads; the in-between mesh at `t` is their
//! blend, and a pixel of the in-between finds its quad, its patch coordinates
//! (inverse bilinear) and their place on the source side.

use crate::features::{Side, Tween};
use crate::geom::{RectD, Vec2};
use crate::warp::Warp;

use super::grid::{bilinear, inverse_bilinear, Grid};

/// Quads whose bounding boxes overlap each bucket, over the in-between
/// mesh's bounding box: a point tests only a few quads.
struct Buckets {
    origin: Vec2,
    cell: Vec2,
    size: usize,
    lists: Vec<Vec<u32>>,
}

/// The reverse map of a quad grid warp: each output point found in its quad and mapped by
/// the quad's bilinear patch.
pub struct QuadWarp {
    n: usize,
    /// The in-between positions (canonical pixels).
    to: Vec<Vec2>,
    /// The source side's positions.
    from: Vec<Vec2>,
    buckets: Buckets,
    identity: bool,
}

impl QuadWarp {
    /// The warp of `side` toward the blend at `t` of the two meshes `a`, `b`
    /// (the same grid's points in A's and B's canonical pixels).
    pub fn toward(
        grid: &Grid,
        a_frame: RectD,
        b_frame: RectD,
        side: Side,
        t: Tween<'_>,
    ) -> QuadWarp {
        let place = |f: RectD, p: Vec2| Vec2::new(f.x1 + p.x * f.width(), f.y1 + p.y * f.height());
        let n = grid.n();
        let a: Vec<Vec2> = (0..=n)
            .flat_map(|k| (0..=n).map(move |j| super::grid::lattice(n, j, k)))
            .map(|p| place(a_frame, p))
            .collect();
        let b: Vec<Vec2> = grid.points().iter().map(|&p| place(b_frame, p)).collect();
        let to: Vec<Vec2> = a.iter().zip(&b).map(|(&p, &q)| t.between(p, q)).collect();
        let from = match side {
            Side::A => a,
            Side::B => b,
        };
        let identity = to == from;
        let buckets = Buckets::new(n, &to);
        QuadWarp {
            n,
            to,
            from,
            buckets,
            identity,
        }
    }

    fn quad(pts: &[Vec2], n: usize, q: usize) -> [Vec2; 4] {
        let (j, k) = (q % n, q / n);
        let i = k * (n + 1) + j;
        [pts[i], pts[i + 1], pts[i + n + 2], pts[i + n + 1]]
    }
}

impl Buckets {
    fn new(n: usize, to: &[Vec2]) -> Buckets {
        let (mut lo, mut hi) = (to[0], to[0]);
        for p in to {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        let size = n.clamp(1, 512);
        let cell = Vec2::new(
            ((hi.x - lo.x) / size as f64).max(1e-9),
            ((hi.y - lo.y) / size as f64).max(1e-9),
        );
        let mut lists = vec![Vec::new(); size * size];
        let clampi = |v: f64| (v.max(0.0) as usize).min(size - 1);
        for q in 0..n * n {
            let c = QuadWarp::quad(to, n, q);
            let (mut qlo, mut qhi) = (c[0], c[0]);
            for p in &c[1..] {
                qlo = Vec2::new(qlo.x.min(p.x), qlo.y.min(p.y));
                qhi = Vec2::new(qhi.x.max(p.x), qhi.y.max(p.y));
            }
            let (x0, x1) = (
                clampi((qlo.x - lo.x) / cell.x),
                clampi((qhi.x - lo.x) / cell.x),
            );
            let (y0, y1) = (
                clampi((qlo.y - lo.y) / cell.y),
                clampi((qhi.y - lo.y) / cell.y),
            );
            for y in y0..=y1 {
                for x in x0..=x1 {
                    lists[y * size + x].push(q as u32);
                }
            }
        }
        Buckets {
            origin: lo,
            cell,
            size,
            lists,
        }
    }

    fn at(&self, p: Vec2) -> &[u32] {
        let (x, y) = (
            (p.x - self.origin.x) / self.cell.x,
            (p.y - self.origin.y) / self.cell.y,
        );
        let s = self.size as f64;
        if !(x >= 0.0 && y >= 0.0 && x <= s && y <= s) {
            return &[];
        }
        let (i, j) = (
            (x as usize).min(self.size - 1),
            (y as usize).min(self.size - 1),
        );
        &self.lists[j * self.size + i]
    }
}

impl Warp for QuadWarp {
    /// Outside the mesh (beyond the frame) the warp is the identity.
    fn map(&self, p: Vec2) -> Vec2 {
        // Pixels on a shared edge belong to either quad (both give the same
        // point); a hair of slack closes rounding gaps.
        for &q in self.buckets.at(p) {
            let c = QuadWarp::quad(&self.to, self.n, q as usize);
            if let Some((s, t)) = inverse_bilinear(&c, p, 1e-9) {
                let f = QuadWarp::quad(&self.from, self.n, q as usize);
                return bilinear(&f, s.clamp(0.0, 1.0), t.clamp(0.0, 1.0));
            }
        }
        p
    }

    fn is_identity(&self) -> bool {
        self.identity
    }
}
