//! The one-pass mesh map: each mesh is a tensor-product Catmull-Rom surface
//! `S(s, r)` over its node indices (uniform parameters, end tangents from
//! linearly extrapolated phantom nodes, so straight rows stay straight). An
//! output point `p` is located on the in-between surface by Newton's method,
//! `S_to(s, r) = p`, and sampled at `S_from(s, r)`. Row neighbours start from
//! each other's solution, so most pixels converge in one or two steps.

use rayon::prelude::*;

use super::{Mesh, MeshPair};
use crate::features::{Side, Tween};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::Warp;

/// Catmull-Rom basis in powers of the local parameter (times 2).
const M: [[f64; 4]; 4] = [
    [0.0, 2.0, 0.0, 0.0],
    [-1.0, 0.0, 1.0, 0.0],
    [2.0, -5.0, 4.0, -1.0],
    [-1.0, 3.0, -3.0, 1.0],
];

/// Newton stops when the located point is this close (canonical pixels).
const TOLERANCE: f64 = 1e-7;
const MAX_STEPS: usize = 16;

/// Surface parameters `(s, r)`: column and row index, fractional.
type Params = (f64, f64);

/// One mesh as bicubic patches in power form, one per cell.
#[derive(Debug, Clone)]
struct Surface {
    rows: usize,
    cols: usize,
    /// Per cell: x then y coefficients, `c[i * 4 + j]` for `u^i v^j`.
    coef: Vec<[[f64; 16]; 2]>,
    /// The node quads, for finding a starting cell, and their bounds.
    quads: Vec<[Vec2; 4]>,
    bounds: (Vec2, Vec2),
}

impl Surface {
    fn new(mesh: &Mesh) -> Surface {
        let (rows, cols) = (mesh.rows(), mesh.cols());
        // Phantom nodes one step outside continue the border linearly.
        let node = |r: isize, c: isize| -> Vec2 {
            let along_c = |r: usize, c: isize| -> Vec2 {
                let last = cols as isize - 1;
                if c < 0 {
                    mesh.node(r, 0) * 2.0 - mesh.node(r, 1)
                } else if c > last {
                    mesh.node(r, cols - 1) * 2.0 - mesh.node(r, cols - 2)
                } else {
                    mesh.node(r, c as usize)
                }
            };
            let last = rows as isize - 1;
            if r < 0 {
                along_c(0, c) * 2.0 - along_c(1, c)
            } else if r > last {
                along_c(rows - 1, c) * 2.0 - along_c(rows - 2, c)
            } else {
                along_c(r as usize, c)
            }
        };
        let mut coef = Vec::with_capacity((rows - 1) * (cols - 1));
        let mut quads = Vec::with_capacity(coef.capacity());
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let p = |b: usize, a: usize| {
                    node(r as isize - 1 + b as isize, c as isize - 1 + a as isize)
                };
                let mut cell = [[0.0; 16]; 2];
                for i in 0..4 {
                    for j in 0..4 {
                        let mut acc = Vec2::default();
                        for (a, mia) in M[i].iter().enumerate() {
                            for (b, mjb) in M[j].iter().enumerate() {
                                let w = mia * mjb;
                                if w != 0.0 {
                                    acc += p(b, a) * w;
                                }
                            }
                        }
                        cell[0][i * 4 + j] = 0.25 * acc.x;
                        cell[1][i * 4 + j] = 0.25 * acc.y;
                    }
                }
                coef.push(cell);
                quads.push([
                    mesh.node(r, c),
                    mesh.node(r, c + 1),
                    mesh.node(r + 1, c + 1),
                    mesh.node(r + 1, c),
                ]);
            }
        }
        let lo = mesh
            .nodes()
            .iter()
            .fold(Vec2::new(f64::MAX, f64::MAX), |m, p| {
                Vec2::new(m.x.min(p.x), m.y.min(p.y))
            });
        let hi = mesh
            .nodes()
            .iter()
            .fold(Vec2::new(f64::MIN, f64::MIN), |m, p| {
                Vec2::new(m.x.max(p.x), m.y.max(p.y))
            });
        Surface {
            rows,
            cols,
            coef,
            quads,
            bounds: (lo, hi),
        }
    }

    /// `S(s, r)` and its partial derivatives.
    #[inline]
    fn eval(&self, s: f64, r: f64) -> (Vec2, Vec2, Vec2) {
        let c = (s.floor() as isize).clamp(0, self.cols as isize - 2) as usize;
        let k = (r.floor() as isize).clamp(0, self.rows as isize - 2) as usize;
        let (u, v) = (s - c as f64, r - k as f64);
        let cell = &self.coef[k * (self.cols - 1) + c];
        let pu = [1.0, u, u * u, u * u * u];
        let du = [0.0, 1.0, 2.0 * u, 3.0 * u * u];
        let pv = [1.0, v, v * v, v * v * v];
        let dv = [0.0, 1.0, 2.0 * v, 3.0 * v * v];
        let mut out = [[0.0; 3]; 2];
        for (axis, o) in cell.iter().zip(out.iter_mut()) {
            for i in 0..4 {
                let row = &axis[i * 4..i * 4 + 4];
                let cv = row[0] * pv[0] + row[1] * pv[1] + row[2] * pv[2] + row[3] * pv[3];
                let cdv = row[1] * dv[1] + row[2] * dv[2] + row[3] * dv[3];
                o[0] += pu[i] * cv;
                o[1] += du[i] * cv;
                o[2] += pu[i] * cdv;
            }
        }
        (
            Vec2::new(out[0][0], out[1][0]),
            Vec2::new(out[0][1], out[1][1]),
            Vec2::new(out[0][2], out[1][2]),
        )
    }

    /// `S(s, r)` alone (no derivatives): where a located point samples.
    #[inline]
    fn position(&self, s: f64, r: f64) -> Vec2 {
        let c = (s.floor() as isize).clamp(0, self.cols as isize - 2) as usize;
        let k = (r.floor() as isize).clamp(0, self.rows as isize - 2) as usize;
        let (u, v) = (s - c as f64, r - k as f64);
        let cell = &self.coef[k * (self.cols - 1) + c];
        let pu = [1.0, u, u * u, u * u * u];
        let pv = [1.0, v, v * v, v * v * v];
        let mut out = [0.0; 2];
        for (axis, o) in cell.iter().zip(out.iter_mut()) {
            for i in 0..4 {
                let row = &axis[i * 4..i * 4 + 4];
                let cv = row[0] * pv[0] + row[1] * pv[1] + row[2] * pv[2] + row[3] * pv[3];
                *o += pu[i] * cv;
            }
        }
        Vec2::new(out[0], out[1])
    }

    fn inside_domain(&self, s: f64, r: f64) -> bool {
        let eps = 1e-9;
        s >= -eps
            && s <= (self.cols - 1) as f64 + eps
            && r >= -eps
            && r <= (self.rows - 1) as f64 + eps
    }

    /// Newton from `(s, r)`; the parameters where `S = p`, if found.
    fn solve(&self, p: Vec2, mut s: f64, mut r: f64) -> Option<(f64, f64)> {
        let (hi_s, hi_r) = (self.cols as f64, self.rows as f64);
        for _ in 0..MAX_STEPS {
            let (q, du, dv) = self.eval(s, r);
            let e = p - q;
            if e.length_squared() <= TOLERANCE * TOLERANCE {
                return Some((s, r));
            }
            let det = du.x * dv.y - du.y * dv.x;
            if det.abs() < 1e-12 || !det.is_finite() {
                return None;
            }
            let mut ds = (e.x * dv.y - e.y * dv.x) / det;
            let mut dr = (du.x * e.y - du.y * e.x) / det;
            // At most one cell per step: the patches are only locally cubic.
            let m = ds.abs().max(dr.abs());
            if m > 1.0 {
                ds /= m;
                dr /= m;
            }
            s = (s + ds).clamp(-1.0, hi_s);
            r = (r + dr).clamp(-1.0, hi_r);
            // Newton converges quadratically: a step of `m` cells leaves an
            // error of about m² cells (the patches bend by about their
            // slope per cell), so after one this small the point lies within
            // ~1e-6 px on a 100 px cell, under the f32 map's rounding: no
            // need to evaluate again.
            if m < 1e-4 {
                return Some((s, r));
            }
        }
        None
    }

    /// A starting point: the centre of the cell whose node quad holds `p`.
    fn start(&self, p: Vec2) -> Option<(f64, f64)> {
        let (lo, hi) = self.bounds;
        if p.x < lo.x || p.y < lo.y || p.x > hi.x || p.y > hi.y {
            return None;
        }
        let inside = |q: &[Vec2; 4]| {
            (0..4).all(|k| {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                let (e, d) = (b - a, p - a);
                e.x * d.y - e.y * d.x >= 0.0
            })
        };
        let k = self.quads.iter().position(inside)?;
        let cells = self.cols - 1;
        Some(((k % cells) as f64 + 0.5, (k / cells) as f64 + 0.5))
    }
}

/// The reverse map of a mesh pair's warp: output positions on mesh `to`,
/// source positions on mesh `from`. Outside the meshes (whose borders are
/// frozen, so the two agree there) every point maps to itself.
#[derive(Debug, Clone)]
pub struct MeshWarp {
    to: Surface,
    from: Surface,
    identity: bool,
}

impl MeshWarp {
    /// The reverse map from mesh `to` (output) to mesh `from` (source).
    pub fn new(from: &Mesh, to: &Mesh) -> MeshWarp {
        MeshWarp {
            to: Surface::new(to),
            from: Surface::new(from),
            identity: from == to,
        }
    }

    /// The warp of the image on `side` toward the in-between mesh at `t`.
    pub fn toward<'a>(pair: &MeshPair, side: Side, t: impl Into<Tween<'a>>) -> MeshWarp {
        MeshWarp::new(pair.side(side), &pair.tween(t.into()))
    }

    /// `p` mapped, starting Newton at `guess`; returns the parameters used so
    /// the next pixel can start there.
    #[inline]
    fn locate(&self, p: Vec2, guess: Option<(f64, f64)>) -> (Vec2, Option<(f64, f64)>) {
        let found = guess
            .and_then(|(s, r)| self.to.solve(p, s, r))
            .filter(|&(s, r)| self.to.inside_domain(s, r))
            .or_else(|| {
                let (s, r) = self.to.start(p)?;
                self.to.solve(p, s, r)
            });
        match found {
            Some((s, r)) if self.to.inside_domain(s, r) => (self.from.position(s, r), Some((s, r))),
            _ => (p, None),
        }
    }

    fn map_run(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        let mut guess = None;
        for i in 0..xs.len() {
            let (q, g) = self.locate(Vec2::new(xs[i] as f64, ys[i] as f64), guess);
            guess = g.or(guess);
            out_x[i] = q.x as f32;
            out_y[i] = q.y as f32;
        }
    }
}

impl Warp for MeshWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        if self.identity {
            return p;
        }
        self.locate(p, None).0
    }

    fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        if self.identity {
            out_x.copy_from_slice(xs);
            out_y.copy_from_slice(ys);
            return;
        }
        self.map_run(xs, ys, out_x, out_y);
    }

    fn is_identity(&self) -> bool {
        self.identity
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.identity {
            return WarpMap::identity(window, scale);
        }
        let w = window.width();
        let mut pos = vec![[0f32; 2]; window.area()];
        if w > 0 {
            pos.par_chunks_mut(w).enumerate().for_each(|(row, out)| {
                let j = window.y1 + row as i32;
                // Start each pixel where the last two solutions point: one
                // Newton step usually lands within tolerance.
                let (mut prev, mut before): (Option<Params>, Option<Params>) = (None, None);
                for (k, o) in out.iter_mut().enumerate() {
                    let guess = match (prev, before) {
                        (Some(a), Some(b)) => Some((2.0 * a.0 - b.0, 2.0 * a.1 - b.1)),
                        _ => prev,
                    };
                    let (q, g) = self.locate(scale.pixel_centre(window.x1 + k as i32, j), guess);
                    if g.is_some() {
                        (before, prev) = (prev, g);
                    } else {
                        (before, prev) = (None, None);
                    }
                    *o = [q.x as f32, q.y as f32];
                }
            });
        }
        WarpMap::new(window, scale, pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(s, r)` with `S(s, r) = p` to 1e-10 px, by plain Newton from the
    /// cell the point lies in: no warm start, no early exit.
    fn strict(surface: &Surface, p: Vec2) -> Option<(f64, f64)> {
        let (mut s, mut r) = surface.start(p)?;
        for _ in 0..50 {
            let (q, du, dv) = surface.eval(s, r);
            let e = p - q;
            if e.length() < 1e-10 {
                return Some((s, r));
            }
            let det = du.x * dv.y - du.y * dv.x;
            s += (e.x * dv.y - e.y * dv.x) / det;
            r += (du.x * e.y - du.y * e.x) / det;
        }
        None
    }

    #[test]
    fn the_dense_map_matches_a_strict_solve_on_a_curved_mesh() {
        let (w, h) = (240.0, 160.0);
        let src = Mesh::regular(7, 9, 0.0, 0.0, w, h).unwrap();
        let dst = src.map_nodes(|r, c, p| {
            if r == 0 || c == 0 || r == 6 || c == 8 {
                return p;
            }
            p + Vec2::new(9.0 * (p.y * 0.05).sin(), 7.0 * (p.x * 0.04).cos())
        });
        let warp = MeshWarp::new(&src, &dst);
        let window = RectI::from_size(w as usize, h as usize);
        let map = warp.map_window(window, PixelScale::UNIT);
        let mut worst = 0.0f64;
        let mut solved = 0;
        for j in 0..h as i32 {
            for i in 0..w as i32 {
                let p = PixelScale::UNIT.pixel_centre(i, j);
                let Some((s, r)) = strict(&warp.to, p) else {
                    continue;
                };
                if !warp.to.inside_domain(s, r) {
                    continue;
                }
                solved += 1;
                worst = worst.max(map.get(i, j).distance(warp.from.position(s, r)));
            }
        }
        assert!(solved > 30_000, "{solved} pixels solved");
        // f32 positions near 240 px round by up to 1e-5 px.
        assert!(
            worst < 5e-5,
            "dense map strays {worst} px from the strict solve"
        );
    }
}
