//! The warp `auto` searches over (Gao-Sederberg §3): a bilinear uniform B-spline
//! map `F_i` of the unit square with `2^i x 2^i` patches, i.e. a grid of
//! `(2^i + 1)^2` control points, each the image on B of a lattice point of A.
//! Origin bottom-left, y up, as in the paper and in our canonical coordinates.

use crate::error::{Error, Result};
use crate::geom::Vec2;

/// Deepest level a grid may have (`2^10` patches per side is finer than any
/// plate needs: a 4K plate's quads would be 4 pixels wide).
pub const MAX_LEVEL: u32 = 10;

/// The control points of a `2^level × 2^level` quad grid over the unit square.
#[derive(Clone, PartialEq)]
pub struct Grid {
    level: u32,
    /// Row `k` (y) major: point `(j, k)` is `pts[k * (n + 1) + j]`.
    pts: Vec<Vec2>,
}

impl std::fmt::Debug for Grid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Grid(level {}, {:?})", self.level, self.pts)
    }
}

/// Where a control point may move (Gao-Sederberg §5: corners are fixed, edge
/// vertices slide along their edge).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Freedom {
    /// A corner: does not move.
    Fixed,
    /// On the bottom or top edge: x moves.
    AlongX,
    /// On the left or right edge: y moves.
    AlongY,
    /// An inner point: moves in x and y.
    Free,
}

impl Grid {
    /// Lattice positions (3): the identity warp.
    pub fn identity(level: u32) -> Grid {
        let n = 1usize << level;
        let mut pts = Vec::with_capacity((n + 1) * (n + 1));
        for k in 0..=n {
            for j in 0..=n {
                pts.push(lattice(n, j, k));
            }
        }
        Grid { level, pts }
    }

    /// A grid from its points (row `k` major, bottom row first), refused when
    /// the count is not `(2^i + 1)^2` or a quad folds.
    pub fn from_points(pts: Vec<Vec2>) -> Result<Grid> {
        let level = (1..=MAX_LEVEL)
            .find(|&l| ((1usize << l) + 1).pow(2) == pts.len())
            .ok_or_else(|| {
                Error::Invalid(format!(
                    "{} points do not make a (2^i + 1) x (2^i + 1) grid (9, 25, 81, 289, ...)",
                    pts.len()
                ))
            })?;
        if let Some(p) = pts.iter().position(|p| !p.is_finite()) {
            return Err(Error::Invalid(format!("point {p} is not finite")));
        }
        let g = Grid { level, pts };
        if let Some((j, k)) = g.first_folded_quad() {
            return Err(Error::Invalid(format!(
                "the quad of columns {j}..{} and rows {k}..{} is not convex \
                    and counter-clockwise (the warp would fold)",
                j + 1,
                k + 1
            )));
        }
        Ok(g)
    }

    /// Quads per side are `2^level`.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// Patches per side, `2^level`.
    pub fn n(&self) -> usize {
        1 << self.level
    }

    /// Every point, row `k` major.
    pub fn points(&self) -> &[Vec2] {
        &self.pts
    }

    /// The index in [`Grid::points`] of point `(j, k)`.
    #[inline]
    pub fn index(&self, j: usize, k: usize) -> usize {
        k * (self.n() + 1) + j
    }

    /// Point `(j, k)`.
    #[inline]
    pub fn at(&self, j: usize, k: usize) -> Vec2 {
        self.pts[self.index(j, k)]
    }

    /// Moves point `(j, k)` to `p`.
    #[inline]
    pub fn set(&mut self, j: usize, k: usize, p: Vec2) {
        let i = self.index(j, k);
        self.pts[i] = p;
    }

    /// Corners of quad `Q_jk` counter-clockwise from its bottom-left.
    #[inline]
    pub fn quad(&self, j: usize, k: usize) -> [Vec2; 4] {
        [
            self.at(j, k),
            self.at(j + 1, k),
            self.at(j + 1, k + 1),
            self.at(j, k + 1),
        ]
    }

    /// How point `(j, k)` may move.
    pub fn freedom(&self, j: usize, k: usize) -> Freedom {
        let n = self.n();
        let (xe, ye) = (j == 0 || j == n, k == 0 || k == n);
        match (xe, ye) {
            (true, true) => Freedom::Fixed,
            (false, true) => Freedom::AlongX,
            (true, false) => Freedom::AlongY,
            (false, false) => Freedom::Free,
        }
    }

    /// The equivalent warp one level finer (4): the bilinear map itself
    /// evaluated at the finer lattice.
    pub fn refined(&self) -> Grid {
        let n = self.n();
        let m = 2 * n;
        let mut pts = Vec::with_capacity((m + 1) * (m + 1));
        for k in 0..=m {
            for j in 0..=m {
                let p = |a: usize, b: usize| self.at(a, b);
                let (j0, j1, k0, k1) = (j / 2, j.div_ceil(2), k / 2, k.div_ceil(2));
                pts.push((p(j0, k0) + p(j1, k0) + p(j0, k1) + p(j1, k1)) * 0.25);
            }
        }
        Grid {
            level: self.level + 1,
            pts,
        }
    }

    /// `F(u)` for `u` in the unit square (clamped to it).
    pub fn eval(&self, u: Vec2) -> Vec2 {
        let n = self.n();
        let (x, y) = (
            u.x.clamp(0.0, 1.0) * n as f64,
            u.y.clamp(0.0, 1.0) * n as f64,
        );
        let (j, k) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
        bilinear(&self.quad(j, k), x - j as f64, y - k as f64)
    }

    /// The first quad that is not strictly convex and counter-clockwise.
    pub fn first_folded_quad(&self) -> Option<(usize, usize)> {
        let n = self.n();
        (0..n)
            .flat_map(|k| (0..n).map(move |j| (j, k)))
            .find(|&(j, k)| !is_convex_ccw(&self.quad(j, k)))
    }

    /// Onto (Gao-Sederberg §3): corners at the corners, edge points on their edges.
    pub fn is_onto(&self) -> bool {
        let n = self.n();
        (0..=n).all(|k| {
            (0..=n).all(|j| {
                let (p, l) = (self.at(j, k), lattice(n, j, k));
                match self.freedom(j, k) {
                    Freedom::Fixed => p == l,
                    Freedom::AlongX => p.y == l.y && p.x > 0.0 && p.x < 1.0,
                    Freedom::AlongY => p.x == l.x && p.y > 0.0 && p.y < 1.0,
                    Freedom::Free => true,
                }
            })
        })
    }

    /// Pulls a grid that has left the frame's edges back onto them (Gao-Sederberg
    /// §6.2: a user's initial warp may pull away; F_3 is forced onto). A
    /// boundary point whose snap would fold a quad goes back to its lattice
    /// position instead; returns false (grid unchanged) if even that folds.
    pub fn make_onto(&mut self) -> bool {
        let n = self.n();
        let before = self.clone();
        for k in 0..=n {
            for j in 0..=n {
                let (p, l) = (self.at(j, k), lattice(n, j, k));
                let snapped = match self.freedom(j, k) {
                    Freedom::Fixed => l,
                    Freedom::AlongX => Vec2::new(p.x.clamp(0.0, 1.0), l.y),
                    Freedom::AlongY => Vec2::new(l.x, p.y.clamp(0.0, 1.0)),
                    Freedom::Free => continue,
                };
                self.set(j, k, snapped);
            }
        }
        // Boundary points whose quads fold go to their lattice positions.
        for k in 0..=n {
            for j in 0..=n {
                if self.freedom(j, k) != Freedom::Free && !self.star_is_legal(j, k) {
                    self.set(j, k, lattice(n, j, k));
                }
            }
        }
        if self.first_folded_quad().is_some() {
            *self = before;
            return false;
        }
        true
    }

    /// The quads around point `(j, k)` are all convex and counter-clockwise.
    pub fn star_is_legal(&self, j: usize, k: usize) -> bool {
        let n = self.n();
        let js = j.saturating_sub(1)..=j.min(n - 1);
        js.clone().all(|qj| {
            (k.saturating_sub(1)..=k.min(n - 1)).all(|qk| is_convex_ccw(&self.quad(qj, qk)))
        })
    }
}

/// Lattice position of point `(j, k)` of an `n x n` grid.
#[inline]
pub fn lattice(n: usize, j: usize, k: usize) -> Vec2 {
    Vec2::new(j as f64 / n as f64, k as f64 / n as f64)
}

/// The bilinear patch through `q` (counter-clockwise from bottom-left) at
/// local `(s, t)` in the unit square.
#[inline]
pub fn bilinear(q: &[Vec2; 4], s: f64, t: f64) -> Vec2 {
    let bottom = q[0] + (q[1] - q[0]) * s;
    let top = q[3] + (q[2] - q[3]) * s;
    bottom + (top - bottom) * t
}

#[inline]
fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Strictly convex and counter-clockwise: every turn is a left turn. Such a
/// quad's bilinear patch is one-to-one (its Jacobian is a convex combination
/// of the corner turns).
pub fn is_convex_ccw(q: &[Vec2; 4]) -> bool {
    (0..4).all(|c| {
        let (p, a, b) = (q[c], q[(c + 1) % 4], q[(c + 3) % 4]);
        cross(a - p, b - p) > 0.0
    })
}

/// Local `(s, t)` of `p` in the bilinear patch through `q` (counter-clockwise
/// from bottom-left), if it lies within `slack` of the patch: the quadratic in
/// `t` solved in its stable form, then one Newton step for the last bits.
pub fn inverse_bilinear(q: &[Vec2; 4], p: Vec2, slack: f64) -> Option<(f64, f64)> {
    let e = q[1] - q[0];
    let f = q[3] - q[0];
    let g = q[0] - q[1] + q[2] - q[3];
    let h = p - q[0];
    let k2 = cross(g, f);
    let k1 = cross(e, f) + cross(h, g);
    let k0 = cross(h, e);
    let size = cross(e, f).abs().max(1e-300);
    let t_roots: [f64; 2] = if k2.abs() <= 1e-12 * size {
        if k1 == 0.0 {
            return None;
        }
        [-k0 / k1, f64::NAN]
    } else {
        let disc = k1 * k1 - 4.0 * k0 * k2;
        if disc < 0.0 {
            return None;
        }
        let qq = -0.5 * (k1 + k1.signum() * disc.sqrt());
        [qq / k2, if qq != 0.0 { k0 / qq } else { f64::NAN }]
    };
    let lo = -slack;
    let hi = 1.0 + slack;
    for t in t_roots {
        if !(t >= lo && t <= hi) {
            continue;
        }
        let (dx, dy) = (e.x + g.x * t, e.y + g.y * t);
        let s = if dx.abs() >= dy.abs() {
            (h.x - f.x * t) / dx
        } else {
            (h.y - f.y * t) / dy
        };
        if !(s >= lo && s <= hi) {
            continue;
        }
        return Some(newton(q, p, s, t));
    }
    None
}

/// One Newton step on `bilinear(q, s, t) = p`.
fn newton(q: &[Vec2; 4], p: Vec2, s: f64, t: f64) -> (f64, f64) {
    let r = bilinear(q, s, t) - p;
    let ds = (q[1] - q[0]) * (1.0 - t) + (q[2] - q[3]) * t;
    let dt = (q[3] - q[0]) * (1.0 - s) + (q[2] - q[1]) * s;
    let det = cross(ds, dt);
    if det.abs() < 1e-300 {
        return (s, t);
    }
    (s - cross(r, dt) / det, t - cross(ds, r) / det)
}
