//! Multigrid V-cycles for the plate (seed 003 §2.2, after Terzopoulos):
//! Gauss-Seidel smoothing, bilinear prolongation `P`, full-weighting
//! restriction `Pᵀ`, and Galerkin coarse systems `A_c = Pᵀ A P`, solved
//! directly (Cholesky) on the coarsest grid, where the plate's affine modes
//! live.
//!
//! Why Galerkin: rediscretising the plate on the coarse grid makes its
//! bending energy about half what the fine grid gives the interpolated
//! correction (bilinear interpolation puts kinks at every coarse node), so
//! coarse corrections overshoot by up to 2× and the cycle diverges. With
//! `A_c = Pᵀ A P` the coarse correction is the energy-norm projection, which
//! never increases the error, and the springs' stiffness (α ≫ bending)
//! carries down exactly.

use wide::f64x4;

use super::plate::Plate;

/// Smoothing sweeps before and after each coarse-grid correction.
const PRE: usize = 2;
const POST: usize = 2;

/// A symmetric operator with a 5 × 5 stencil per node: the plate's 13-point
/// bending, its springs (which couple the nodes of a cell) and every
/// Galerkin product of them fit.
///
/// Nodes share their stencils: away from springs and edges every node has
/// the same one. Storing each distinct stencil once (a node holds an index)
/// keeps a 1080p plate's operator to about a megabyte instead of 26, so the
/// sweeps run from cache instead of streaming memory.
#[derive(Debug, Clone)]
pub struct Stencil {
    pub nx: usize,
    pub ny: usize,
    /// The distinct stencils; entry for offset `(dx, dy)` at
    /// `(dy + 2) * 5 + dx + 2`.
    rows: Vec<[f64; 25]>,
    /// Per node, its stencil in `rows`.
    index: Vec<u32>,
    /// `1 / row[centre]` per distinct stencil.
    inverse_diagonal: Vec<f64>,
}

#[inline]
fn slot(dx: i64, dy: i64) -> usize {
    ((dy + 2) * 5 + dx + 2) as usize
}

impl Stencil {
    fn new(nx: usize, ny: usize, rows: Vec<[f64; 25]>, index: Vec<u32>) -> Stencil {
        let inverse_diagonal = rows.iter().map(|r| 1.0 / r[slot(0, 0)]).collect();
        Stencil {
            nx,
            ny,
            rows,
            index,
            inverse_diagonal,
        }
    }

    /// The plate's `A` as a stencil. Interior nodes without springs take
    /// the constant biharmonic stencil; the rest are probed with unit vectors.
    pub fn of(plate: &Plate) -> Stencil {
        let (nx, ny) = (plate.nx, plate.ny);
        let bend = 1.0 / (plate.h * plate.h);
        let mut interior = [0.0; 25];
        for (dx, dy, v) in [
            (0, 0, 20.0),
            (1, 0, -8.0),
            (-1, 0, -8.0),
            (0, 1, -8.0),
            (0, -1, -8.0),
            (1, 1, 2.0),
            (1, -1, 2.0),
            (-1, 1, 2.0),
            (-1, -1, 2.0),
            (2, 0, 1.0),
            (-2, 0, 1.0),
            (0, 2, 1.0),
            (0, -2, 1.0),
        ] {
            interior[slot(dx, dy)] = v * bend;
        }
        interior[slot(0, 0)] += plate.beta * plate.h * plate.h;
        let mut sprung = vec![false; nx * ny];
        for s in &plate.springs {
            for &n in &s.nodes {
                sprung[n] = true;
            }
        }
        let mut unit = vec![0.0; nx * ny];
        let mut rows = vec![interior];
        let index = (0..nx * ny)
            .map(|n| {
                let (i, j) = ((n % nx) as i64, (n / nx) as i64);
                let inside = i >= 2 && j >= 2 && i + 2 < nx as i64 && j + 2 < ny as i64;
                if inside && !sprung[n] {
                    return 0;
                }
                let mut row = [0.0; 25];
                for dy in -2..=2 {
                    for dx in -2..=2 {
                        let (x, y) = (i + dx, j + dy);
                        if x < 0 || y < 0 || x >= nx as i64 || y >= ny as i64 {
                            continue;
                        }
                        let m = (y * nx as i64 + x) as usize;
                        unit[m] = 1.0;
                        row[slot(dx, dy)] = plate.apply_at(&unit, n);
                        unit[m] = 0.0;
                    }
                }
                rows.push(row);
                (rows.len() - 1) as u32
            })
            .collect();
        Stencil::new(nx, ny, rows, index)
    }

    /// The stencil of node `n`.
    #[inline]
    pub fn row(&self, n: usize) -> &[f64; 25] {
        &self.rows[self.index[n] as usize]
    }

    /// The stencil of node `n` and the inverse of its diagonal (interior
    /// diagonals are positive: bending alone makes them so).
    #[inline]
    fn row_and_inverse(&self, n: usize) -> (&[f64; 25], f64) {
        let k = self.index[n] as usize;
        (&self.rows[k], self.inverse_diagonal[k])
    }

    /// Distinct stencils stored (the rest of the nodes share them).
    pub fn distinct(&self) -> usize {
        self.rows.len()
    }

    /// `(A f)` at node `n`.
    pub fn apply_at(&self, f: &[f64], n: usize) -> f64 {
        self.apply_ij(f, n % self.nx, n / self.nx)
    }

    /// `(A f)` at node `(i, j)`: the sweeps walk rows, so no node index is
    /// ever divided back into its coordinates.
    #[inline]
    fn apply_ij(&self, f: &[f64], i: usize, j: usize) -> f64 {
        let (nx, ny) = (self.nx, self.ny);
        let n = j * nx + i;
        let row = self.row(n);
        if i >= 2 && j >= 2 && i + 2 < nx && j + 2 < ny {
            return window_sum(row, f, n, nx, &[0, 1, 2, 3, 4]);
        }
        let (i, j) = (i as i64, j as i64);
        let mut v = 0.0;
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (x, y) = (i + dx, j + dy);
                if x >= 0 && y >= 0 && x < nx as i64 && y < ny as i64 {
                    v += row[slot(dx, dy)] * f[(y * nx as i64 + x) as usize];
                }
            }
        }
        v
    }

    /// One Gauss-Seidel sweep, forward or backward (a forward sweep before
    /// the correction and a backward one after keep the V-cycle symmetric).
    ///
    /// Inside a row each update needs the two just before it, so those two
    /// travel in registers and everything else is summed independently of
    /// them: the chain from one node to the next is one fused multiply-add
    /// instead of a whole stencil (and no load waits on a fresh store).
    pub fn relax(&self, f: &mut [f64], b: &[f64], forward: bool) {
        let (nx, ny) = (self.nx, self.ny);
        let edge = |f: &mut [f64], i: usize, j: usize| {
            let k = j * nx + i;
            let d = self.row(k)[slot(0, 0)];
            if d > 0.0 {
                f[k] += (b[k] - self.apply_ij(f, i, j)) / d;
            }
        };
        let rows: Vec<usize> = if forward {
            (0..ny).collect()
        } else {
            (0..ny).rev().collect()
        };
        for j in rows {
            if j < 2 || j + 2 >= ny || nx < 5 {
                let columns: Vec<usize> = if forward {
                    (0..nx).collect()
                } else {
                    (0..nx).rev().collect()
                };
                for i in columns {
                    edge(f, i, j);
                }
                continue;
            }
            let k0 = j * nx;
            if forward {
                edge(f, 0, j);
                edge(f, 1, j);
                let (mut p2, mut p1) = (f[k0], f[k0 + 1]);
                for k in k0 + 2..k0 + nx - 2 {
                    let (r, inverse) = self.row_and_inverse(k);
                    let v = window_sum(r, f, k, nx, &[0, 1, 3, 4])
                        + (r[12] * f[k] + r[13] * f[k + 1] + r[14] * f[k + 2]);
                    let q = f[k] + (b[k] - v) * inverse;
                    let new = (-r[11] * inverse).mul_add(p1, (-r[10] * inverse).mul_add(p2, q));
                    f[k] = new;
                    (p2, p1) = (p1, new);
                }
                edge(f, nx - 2, j);
                edge(f, nx - 1, j);
            } else {
                edge(f, nx - 1, j);
                edge(f, nx - 2, j);
                let (mut p2, mut p1) = (f[k0 + nx - 1], f[k0 + nx - 2]);
                for k in (k0 + 2..k0 + nx - 2).rev() {
                    let (r, inverse) = self.row_and_inverse(k);
                    let v = window_sum(r, f, k, nx, &[0, 1, 3, 4])
                        + (r[10] * f[k - 2] + r[11] * f[k - 1] + r[12] * f[k]);
                    let q = f[k] + (b[k] - v) * inverse;
                    let new = (-r[13] * inverse).mul_add(p1, (-r[14] * inverse).mul_add(p2, q));
                    f[k] = new;
                    (p2, p1) = (p1, new);
                }
                edge(f, 1, j);
                edge(f, 0, j);
            }
        }
    }

    /// `out = A f`.
    pub fn apply(&self, f: &[f64], out: &mut [f64]) {
        for (j, row) in out.chunks_exact_mut(self.nx).enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = self.apply_ij(f, i, j);
            }
        }
    }

    pub fn residual(&self, f: &[f64], b: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; f.len()];
        self.apply(f, &mut r);
        for (r, b) in r.iter_mut().zip(b) {
            *r = b - *r;
        }
        r
    }

    /// `Pᵀ A P` on the grid of every other node.
    pub fn galerkin(&self) -> Stencil {
        let (nx, ny) = (self.nx, self.ny);
        let (cx, cy) = ((nx - 1) / 2 + 1, (ny - 1) / 2 + 1);
        let mut rows = Vec::new();
        // A coarse node whose 3 × 3 fine nodes share one stencil, with every
        // node they reach inside the grid, gets the product of that stencil
        // alone: computed once per shared stencil.
        let mut product_of: Vec<Option<u32>> = vec![None; self.rows.len()];
        let mut index = vec![0u32; cx * cy];
        for jc in 0..cy {
            for ic in 0..cx {
                let (fx, fy) = (2 * ic, 2 * jc);
                let inside = fx >= 3 && fy >= 3 && fx + 3 < nx && fy + 3 < ny;
                let shared = self.index[fy * nx + fx];
                let uniform = inside
                    && (fy - 1..=fy + 1)
                        .all(|y| (fx - 1..=fx + 1).all(|x| self.index[y * nx + x] == shared));
                if uniform {
                    if let Some(k) = product_of[shared as usize] {
                        index[jc * cx + ic] = k;
                        continue;
                    }
                }
                rows.push(self.galerkin_row(ic, jc));
                let k = (rows.len() - 1) as u32;
                if uniform {
                    product_of[shared as usize] = Some(k);
                }
                index[jc * cx + ic] = k;
            }
        }
        Stencil::new(cx, cy, rows, index)
    }

    /// Row `(ic, jc)` of `Pᵀ A P`.
    fn galerkin_row(&self, ic: usize, jc: usize) -> [f64; 25] {
        let (nx, ny) = (self.nx, self.ny);
        let mut row = [0.0; 25];
        // Fine nodes i that P feeds from coarse node I, with weight.
        for (fy, wy) in hat(jc, ny) {
            for (fx, wx) in hat(ic, nx) {
                let wi = wx * wy;
                let fine = self.row(fy * nx + fx);
                for dy in -2i64..=2 {
                    for dx in -2i64..=2 {
                        let (kx, ky) = (fx as i64 + dx, fy as i64 + dy);
                        if kx < 0 || ky < 0 || kx >= nx as i64 || ky >= ny as i64 {
                            continue;
                        }
                        let v = fine[slot(dx, dy)];
                        if v == 0.0 {
                            continue;
                        }
                        // Coarse nodes K that P reads fine node k from.
                        for (kcx, wkx) in parents(kx as usize) {
                            for (kcy, wky) in parents(ky as usize) {
                                let (ox, oy) = (kcx as i64 - ic as i64, kcy as i64 - jc as i64);
                                row[slot(ox, oy)] += wi * v * wkx * wky;
                            }
                        }
                    }
                }
            }
        }
        row
    }
}

/// The stencil `row` at interior node `n` against `f` over the window rows
/// `dys` (0: two rows below). Four lanes of partial sums and a scalar, so the
/// taps do not form one long chain of additions.
#[inline(always)]
fn window_sum(row: &[f64; 25], f: &[f64], n: usize, nx: usize, dys: &[usize]) -> f64 {
    let base = n - 2 * nx - 2;
    let mut v = f64x4::ZERO;
    let mut tail = 0.0;
    for &dy in dys {
        let f: &[f64; 5] = f[base + dy * nx..base + dy * nx + 5].try_into().unwrap();
        let r: &[f64; 5] = row[dy * 5..dy * 5 + 5].try_into().unwrap();
        let (rv, fv) = (
            f64x4::from([r[0], r[1], r[2], r[3]]),
            f64x4::from([f[0], f[1], f[2], f[3]]),
        );
        v = rv.mul_add(fv, v);
        tail += r[4] * f[4];
    }
    v.reduce_add() + tail
}

/// The fine nodes (and weights) coarse node `c` feeds along one axis.
fn hat(c: usize, n: usize) -> impl Iterator<Item = (usize, f64)> {
    let i = 2 * c as i64;
    [(i - 1, 0.5), (i, 1.0), (i + 1, 0.5)]
        .into_iter()
        .filter(move |(x, _)| *x >= 0 && *x < n as i64)
        .map(|(x, w)| (x as usize, w))
}

/// The coarse nodes (and weights) fine node `k` is interpolated from.
fn parents(k: usize) -> impl Iterator<Item = (usize, f64)> {
    let (c, odd) = (k / 2, k % 2 == 1);
    let pair = if odd {
        [(c, 0.5), (c + 1, 0.5)]
    } else {
        [(c, 1.0), (c, 0.0)]
    };
    pair.into_iter().filter(|(_, w)| *w != 0.0)
}

/// A grid hierarchy, finest first. Node `(i, j)` of level `l + 1` is node
/// `(2i, 2j)` of level `l`.
pub struct Hierarchy {
    /// The finest plate (its springs give the right-hand sides).
    pub plate: Plate,
    pub levels: Vec<Stencil>,
    coarse: Cholesky,
}

/// How a solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// `‖b − A f‖₂` before the first cycle and after each.
    pub residuals: Vec<f64>,
}

impl Hierarchy {
    /// Levels for a fine grid of `nx × ny` nodes whose cell counts are
    /// divisible by `2^(levels − 1)`; springs at fine-grid node coordinates.
    pub fn new(
        nx: usize,
        ny: usize,
        h: f64,
        alpha: f64,
        beta: f64,
        at: &[(f64, f64)],
        levels: usize,
    ) -> Hierarchy {
        let plate = Plate::new(nx, ny, h, alpha, beta, at);
        let mut stencils = vec![Stencil::of(&plate)];
        for _ in 1..levels {
            let next = stencils[stencils.len() - 1].galerkin();
            stencils.push(next);
        }
        let coarse = Cholesky::of(&stencils[stencils.len() - 1]);
        Hierarchy {
            plate,
            levels: stencils,
            coarse,
        }
    }

    /// Solves from `f` until `‖b − A f‖ ≤ tolerance · ‖b‖` or `max_cycles`:
    /// conjugate gradients preconditioned by one V-cycle per iteration.
    ///
    /// Plain V-cycles stall here: a stiff spring pins a whole coarse cell,
    /// so the coarse grids cannot correct the plate right next to it and a
    /// few error modes decay at 0.96 per cycle. The V-cycle is symmetric
    /// (forward sweeps down, backward up, exact coarse solve), so it is a
    /// valid preconditioner, and CG removes exactly those few slow modes.
    pub fn solve(&self, f: &mut [f64], b: &[f64], tolerance: f64, max_cycles: usize) -> Report {
        let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let a = &self.levels[0];
        let target = tolerance * dot(b, b).sqrt();
        let mut r = a.residual(f, b);
        let mut residuals = vec![dot(&r, &r).sqrt()];
        let precondition = |r: &[f64]| {
            let mut z = vec![0.0; r.len()];
            self.cycle(0, &mut z, r);
            z
        };
        let mut z = precondition(&r);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let mut ap = vec![0.0; r.len()];
        for _ in 0..max_cycles {
            if *residuals.last().unwrap_or(&0.0) <= target || rz <= 0.0 {
                break;
            }
            a.apply(&p, &mut ap);
            let step = rz / dot(&p, &ap);
            for k in 0..f.len() {
                f[k] += step * p[k];
                r[k] -= step * ap[k];
            }
            residuals.push(dot(&r, &r).sqrt());
            z = precondition(&r);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for (pk, zk) in p.iter_mut().zip(&z) {
                *pk = zk + beta * *pk;
            }
        }
        Report { residuals }
    }

    /// One V-cycle on level `l`.
    pub fn cycle(&self, l: usize, f: &mut [f64], b: &[f64]) {
        let a = &self.levels[l];
        if l + 1 == self.levels.len() {
            f.copy_from_slice(&self.coarse.solve(b));
            return;
        }
        for _ in 0..PRE {
            a.relax(f, b, true);
        }
        let r = a.residual(f, b);
        let coarse = &self.levels[l + 1];
        let rc = restrict(a, coarse, &r);
        let mut e = vec![0.0; rc.len()];
        self.cycle(l + 1, &mut e, &rc);
        prolong_add(coarse, a, &e, f);
        for _ in 0..POST {
            a.relax(f, b, false);
        }
    }
}

/// `Pᵀ r`: full weighting, separable (rows, then columns).
fn restrict(fine: &Stencil, coarse: &Stencil, r: &[f64]) -> Vec<f64> {
    let (nx, cx) = (fine.nx, coarse.nx);
    let gather = |c: usize, n: usize, at: &dyn Fn(usize) -> f64| -> f64 {
        hat(c, n).map(|(x, w)| w * at(x)).sum()
    };
    let mut wide = vec![0.0; cx * fine.ny];
    for (row, out) in r.chunks_exact(nx).zip(wide.chunks_exact_mut(cx)) {
        for (ic, o) in out.iter_mut().enumerate() {
            *o = gather(ic, nx, &|x| row[x]);
        }
    }
    let mut rc = vec![0.0; cx * coarse.ny];
    for (jc, out) in rc.chunks_exact_mut(cx).enumerate() {
        for (y, wy) in hat(jc, fine.ny) {
            for (o, v) in out.iter_mut().zip(&wide[y * cx..(y + 1) * cx]) {
                *o += wy * v;
            }
        }
    }
    rc
}

/// `f += P e`: bilinear interpolation of the coarse correction, a coarse
/// row interpolated in y once per fine row, then in x.
fn prolong_add(coarse: &Stencil, fine: &Stencil, e: &[f64], f: &mut [f64]) {
    let cx = coarse.nx;
    let mut mixed = vec![0.0; cx];
    for (y, out) in f.chunks_exact_mut(fine.nx).enumerate() {
        mixed.fill(0.0);
        for (cy, wy) in parents(y) {
            for (m, v) in mixed.iter_mut().zip(&e[cy * cx..(cy + 1) * cx]) {
                *m += wy * v;
            }
        }
        for (x, o) in out.iter_mut().enumerate() {
            *o += if x % 2 == 0 {
                mixed[x / 2]
            } else {
                0.5 * (mixed[x / 2] + mixed[x / 2 + 1])
            };
        }
    }
}

/// A dense Cholesky factor of a (small) stencil operator, with a tiny ridge
/// so a plate with no springs and no glue (affine modes free) still factors.
pub struct Cholesky {
    n: usize,
    l: Vec<f64>,
}

impl Cholesky {
    pub fn of(s: &Stencil) -> Cholesky {
        let n = s.nx * s.ny;
        let mut a = vec![0.0; n * n];
        let mut unit = vec![0.0; n];
        for m in 0..n {
            unit[m] = 1.0;
            for k in 0..n {
                a[k * n + m] = s.apply_at(&unit, k);
            }
            unit[m] = 0.0;
        }
        let largest = (0..n).fold(0.0f64, |m, k| m.max(a[k * n + k]));
        let ridge = 1e-12 * largest;
        for k in 0..n {
            a[k * n + k] += ridge;
        }
        for j in 0..n {
            let mut d = a[j * n + j];
            for k in 0..j {
                d -= a[j * n + k] * a[j * n + k];
            }
            let d = d.max(ridge).sqrt();
            a[j * n + j] = d;
            for i in j + 1..n {
                let mut v = a[i * n + j];
                for k in 0..j {
                    v -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = v / d;
            }
        }
        Cholesky { n, l: a }
    }

    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let (n, l) = (self.n, &self.l);
        let mut y = b.to_vec();
        for i in 0..n {
            for k in 0..i {
                y[i] -= l[i * n + k] * y[k];
            }
            y[i] /= l[i * n + i];
        }
        for i in (0..n).rev() {
            for k in i + 1..n {
                y[i] -= l[k * n + i] * y[k];
            }
            y[i] /= l[i * n + i];
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Lcg;

    fn grid(nx: usize, ny: usize) -> Stencil {
        Stencil::new(nx, ny, vec![[0.0; 25]], vec![0; nx * ny])
    }

    #[test]
    fn restriction_is_the_transpose_of_prolongation() {
        let (fine, coarse) = (grid(17, 13), grid(9, 7));
        let mut r = Lcg::new(3);
        let e: Vec<f64> = (0..9 * 7).map(|_| r.range(-1.0, 1.0)).collect();
        let v: Vec<f64> = (0..17 * 13).map(|_| r.range(-1.0, 1.0)).collect();
        let mut pe = vec![0.0; 17 * 13];
        prolong_add(&coarse, &fine, &e, &mut pe);
        let lhs: f64 = pe.iter().zip(&v).map(|(a, b)| a * b).sum();
        let rhs: f64 = e
            .iter()
            .zip(restrict(&fine, &coarse, &v))
            .map(|(a, b)| a * b)
            .sum();
        assert!(
            (lhs - rhs).abs() < 1e-12 * lhs.abs().max(1.0),
            "{lhs} vs {rhs}"
        );
        // Bilinear: a linear function on the coarse grid is the same
        // function on the fine one (coarse node (i, j) is fine (2i, 2j)).
        let linear = |x: f64, y: f64| 3.0 * x - 2.0 * y + 1.0;
        let e: Vec<f64> = (0..9 * 7)
            .map(|k| linear(2.0 * (k % 9) as f64, 2.0 * (k / 9) as f64))
            .collect();
        let mut f = vec![0.0; 17 * 13];
        prolong_add(&coarse, &fine, &e, &mut f);
        for (k, v) in f.iter().enumerate() {
            assert!((v - linear((k % 17) as f64, (k / 17) as f64)).abs() < 1e-12);
        }
    }
}
