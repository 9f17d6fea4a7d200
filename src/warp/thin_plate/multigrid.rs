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

use super::plate::Plate;

/// Smoothing sweeps before and after each coarse-grid correction.
const PRE: usize = 2;
const POST: usize = 2;

/// A symmetric operator with a 5 × 5 stencil per node: the plate's 13-point
/// bending, its springs (which couple the nodes of a cell) and every
/// Galerkin product of them fit.
#[derive(Debug, Clone)]
pub struct Stencil {
    pub nx: usize,
    pub ny: usize,
    /// Entry for offset `(dx, dy)` at `(dy + 2) * 5 + dx + 2`.
    pub a: Vec<[f64; 25]>,
}

#[inline]
fn slot(dx: i64, dy: i64) -> usize {
    ((dy + 2) * 5 + dx + 2) as usize
}

impl Stencil {
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
        let a = (0..nx * ny)
            .map(|n| {
                let (i, j) = ((n % nx) as i64, (n / nx) as i64);
                let inside = i >= 2 && j >= 2 && i + 2 < nx as i64 && j + 2 < ny as i64;
                if inside && !sprung[n] {
                    return interior;
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
                row
            })
            .collect();
        Stencil { nx, ny, a }
    }

    #[inline]
    pub fn apply_at(&self, f: &[f64], n: usize) -> f64 {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let (i, j) = ((n % self.nx) as i64, (n / self.nx) as i64);
        let row = &self.a[n];
        let mut v = 0.0;
        if i >= 2 && j >= 2 && i + 2 < nx && j + 2 < ny {
            let base = n - 2 * self.nx - 2;
            for dy in 0..5 {
                let f = &f[base + dy * self.nx..base + dy * self.nx + 5];
                let r = &row[dy * 5..dy * 5 + 5];
                v += r[0] * f[0] + r[1] * f[1] + r[2] * f[2] + r[3] * f[3] + r[4] * f[4];
            }
            return v;
        }
        for dy in -2..=2 {
            for dx in -2..=2 {
                let (x, y) = (i + dx, j + dy);
                if x >= 0 && y >= 0 && x < nx && y < ny {
                    v += row[slot(dx, dy)] * f[(y * nx + x) as usize];
                }
            }
        }
        v
    }

    /// One Gauss-Seidel sweep, forward or backward (a forward sweep before
    /// the correction and a backward one after keep the V-cycle symmetric).
    pub fn relax(&self, f: &mut [f64], b: &[f64], forward: bool) {
        let n = self.nx * self.ny;
        let mut step = |k: usize| {
            let d = self.a[k][slot(0, 0)];
            if d > 0.0 {
                f[k] += (b[k] - self.apply_at(f, k)) / d;
            }
        };
        if forward {
            (0..n).for_each(&mut step);
        } else {
            (0..n).rev().for_each(&mut step);
        }
    }

    pub fn residual(&self, f: &[f64], b: &[f64]) -> Vec<f64> {
        (0..self.nx * self.ny)
            .map(|k| b[k] - self.apply_at(f, k))
            .collect()
    }

    /// `Pᵀ A P` on the grid of every other node.
    pub fn galerkin(&self) -> Stencil {
        let (nx, ny) = (self.nx, self.ny);
        let (cx, cy) = ((nx - 1) / 2 + 1, (ny - 1) / 2 + 1);
        let mut a = vec![[0.0; 25]; cx * cy];
        for jc in 0..cy {
            for ic in 0..cx {
                let row = &mut a[jc * cx + ic];
                // Fine nodes i that P feeds from coarse node I, with weight.
                for (fy, wy) in hat(jc, ny) {
                    for (fx, wx) in hat(ic, nx) {
                        let wi = wx * wy;
                        let fi = fy * nx + fx;
                        for dy in -2i64..=2 {
                            for dx in -2i64..=2 {
                                let (kx, ky) = (fx as i64 + dx, fy as i64 + dy);
                                if kx < 0 || ky < 0 || kx >= nx as i64 || ky >= ny as i64 {
                                    continue;
                                }
                                let v = self.a[fi][slot(dx, dy)];
                                if v == 0.0 {
                                    continue;
                                }
                                // Coarse nodes K that P reads fine node k from.
                                for (kcx, wkx) in parents(kx as usize) {
                                    for (kcy, wky) in parents(ky as usize) {
                                        let (ox, oy) =
                                            (kcx as i64 - ic as i64, kcy as i64 - jc as i64);
                                        row[slot(ox, oy)] += wi * v * wkx * wky;
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        Stencil { nx: cx, ny: cy, a }
    }
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
            for (k, v) in ap.iter_mut().enumerate() {
                *v = a.apply_at(&p, k);
            }
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

/// `Pᵀ r`.
fn restrict(fine: &Stencil, coarse: &Stencil, r: &[f64]) -> Vec<f64> {
    let mut rc = vec![0.0; coarse.nx * coarse.ny];
    for jc in 0..coarse.ny {
        for ic in 0..coarse.nx {
            let mut sum = 0.0;
            for (y, wy) in hat(jc, fine.ny) {
                for (x, wx) in hat(ic, fine.nx) {
                    sum += wx * wy * r[y * fine.nx + x];
                }
            }
            rc[jc * coarse.nx + ic] = sum;
        }
    }
    rc
}

/// `f += P e`: bilinear interpolation of the coarse correction.
fn prolong_add(coarse: &Stencil, fine: &Stencil, e: &[f64], f: &mut [f64]) {
    for y in 0..fine.ny {
        for x in 0..fine.nx {
            let mut v = 0.0;
            for (cy, wy) in parents(y) {
                for (cx, wx) in parents(x) {
                    v += wx * wy * e[cy * coarse.nx + cx];
                }
            }
            f[y * fine.nx + x] += v;
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
