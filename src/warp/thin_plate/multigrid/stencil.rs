//! The operator of one level: a square stencil per node, stored once per
//! distinct stencil.

use super::super::plate::Plate;
use super::galerkin::{children, parents, window_sum, Classes};

/// A symmetric operator with a square stencil per node: 5 × 5 on the plate
/// (its 13-point bending and its springs, which couple the nodes of a cell),
/// 7 × 7 on Galerkin levels.
///
/// Nodes share their stencils: away from springs and edges every node has
/// the same one. Storing each distinct stencil once (a node holds an index)
/// keeps a 1080p plate's operator to about a megabyte instead of 26, so the
/// sweeps run from cache instead of streaming memory.
#[derive(Debug, Clone)]
pub struct Stencil {
    /// Nodes in x.
    pub nx: usize,
    /// Nodes in y.
    pub ny: usize,
    /// Stencil width: 5 or 7.
    pub(super) side: usize,
    /// The distinct stencils, `side²` entries each; offset `(dx, dy)` at
    /// `(dy + r) * side + dx + r` with `r = side / 2`.
    pub(super) rows: Vec<f64>,
    /// Per node, its stencil in `rows`.
    pub(super) index: Vec<u32>,
    /// `1 / centre` per distinct stencil.
    pub(super) inverse_diagonal: Vec<f64>,
}

impl Stencil {
    /// A stencil whose rows are `row(i, j)` of one representative node per
    /// class of `classes`, computed in parallel.
    fn by_class(
        classes: &Classes,
        side: usize,
        row: impl Fn(usize, usize) -> Vec<f64> + Sync,
    ) -> Stencil {
        use rayon::prelude::*;
        let (nx, ny) = (classes.nx, classes.ny);
        let kx = classes.count(nx);
        let rows: Vec<f64> = (0..kx * classes.count(ny))
            .into_par_iter()
            .flat_map_iter(|c| {
                row(
                    classes.representative(c % kx, nx),
                    classes.representative(c / kx, ny),
                )
            })
            .collect();
        let index = (0..nx * ny)
            .map(|n| (classes.of(n / nx, ny) * kx + classes.of(n % nx, nx)) as u32)
            .collect();
        Stencil::new(nx, ny, side, rows, index)
    }

    pub(super) fn new(
        nx: usize,
        ny: usize,
        side: usize,
        rows: Vec<f64>,
        index: Vec<u32>,
    ) -> Stencil {
        let centre = side * side / 2;
        let inverse_diagonal = rows
            .chunks_exact(side * side)
            .map(|r| 1.0 / r[centre])
            .collect();
        Stencil {
            nx,
            ny,
            side,
            rows,
            index,
            inverse_diagonal,
        }
    }

    /// The plate's `A` probed node by node with unit vectors: with
    /// [`Stencil::galerkin`], the direct definition of the levels that
    /// [`Hierarchy::new`] builds from bending classes and springs, which
    /// its tests hold it to.
    #[cfg(test)]
    pub(crate) fn of(plate: &Plate) -> Stencil {
        let (nx, ny) = (plate.nx, plate.ny);
        let mut unit = vec![0.0; nx * ny];
        let rows = (0..nx * ny)
            .flat_map(|n| probe_row(plate, &mut unit, n % nx, n / nx))
            .collect();
        Stencil::new(nx, ny, 5, rows, (0..(nx * ny) as u32).collect())
    }

    /// The stencil of node `n` (`side²` entries).
    #[inline]
    pub fn row(&self, n: usize) -> &[f64] {
        let k = self.index[n] as usize * self.side * self.side;
        &self.rows[k..k + self.side * self.side]
    }

    /// Distinct stencils stored (the rest of the nodes share them).
    pub fn distinct(&self) -> usize {
        self.inverse_diagonal.len()
    }

    /// `(A f)` at node `n`.
    pub fn apply_at(&self, f: &[f64], n: usize) -> f64 {
        self.apply_ij(f, n % self.nx, n / self.nx)
    }

    /// `(A f)` at node `(i, j)`: the sweeps walk rows, so no node index is
    /// ever divided back into its coordinates.
    #[inline]
    pub(super) fn apply_ij(&self, f: &[f64], i: usize, j: usize) -> f64 {
        match self.side {
            5 => self.apply_with::<5>(f, i, j),
            _ => self.apply_with::<7>(f, i, j),
        }
    }

    #[inline(always)]
    pub(super) fn apply_with<const S: usize>(&self, f: &[f64], i: usize, j: usize) -> f64 {
        let (nx, ny, r) = (self.nx, self.ny, S / 2);
        let n = j * nx + i;
        let row = self.row(n);
        if i >= r && j >= r && i + r < nx && j + r < ny {
            return window_sum::<S>(row, f, n, nx, false);
        }
        let (i, j, r) = (i as i64, j as i64, r as i64);
        let mut v = 0.0;
        for dy in -r..=r {
            for dx in -r..=r {
                let (x, y) = (i + dx, j + dy);
                if x >= 0 && y >= 0 && x < nx as i64 && y < ny as i64 {
                    let tap = ((dy + r) * S as i64 + dx + r) as usize;
                    v += row[tap] * f[(y * nx as i64 + x) as usize];
                }
            }
        }
        v
    }

    /// One Gauss-Seidel sweep, forward or backward (a forward sweep before
    /// the correction and a backward one after keep the V-cycle symmetric).
    pub fn relax(&self, f: &mut [f64], b: &[f64], forward: bool) {
        match self.side {
            5 => self.relax_with::<5>(f, b, forward),
            _ => self.relax_with::<7>(f, b, forward),
        }
    }

    /// Inside a row each update needs the `S / 2` just before it, so those
    /// travel in registers and everything else is summed independently of
    /// them: the chain from one node to the next is one fused multiply-add
    /// instead of a whole stencil (and no load waits on a fresh store).
    pub(super) fn relax_with<const S: usize>(&self, f: &mut [f64], b: &[f64], forward: bool) {
        let (nx, ny, r) = (self.nx, self.ny, S / 2);
        let edge = |f: &mut [f64], i: usize, j: usize| {
            let k = j * nx + i;
            let d = self.row(k)[S * S / 2];
            if d > 0.0 {
                f[k] += (b[k] - self.apply_with::<S>(f, i, j)) / d;
            }
        };
        // The m-th node of a run of n in sweep order.
        let nth = |m: usize, n: usize| if forward { m } else { n - 1 - m };
        let centre = S * r;
        for jj in 0..ny {
            let j = nth(jj, ny);
            if j < r || j + r >= ny || nx < S {
                for ii in 0..nx {
                    edge(f, nth(ii, nx), j);
                }
                continue;
            }
            for ii in 0..r {
                edge(f, nth(ii, nx), j);
            }
            // fresh[m]: the value updated m + 1 nodes ago; its tap in the
            // centre row is `r ∓ (m + 1)`. The taps from the node on are old.
            let behind = |m: usize| if forward { r - 1 - m } else { r + 1 + m };
            let ahead = if forward { r..S } else { 0..r + 1 };
            let inner = nx - 2 * r;
            let k0 = j * nx + r;
            let first = k0 + nth(0, inner);
            let mut fresh = [0.0; 3];
            for (m, v) in fresh.iter_mut().enumerate().take(r) {
                *v = if forward {
                    f[first - 1 - m]
                } else {
                    f[first + 1 + m]
                };
            }
            for step in 0..inner {
                let k = k0 + nth(step, inner);
                let (row, inverse) = self.row_and_inverse(k);
                let base = k - r;
                let mut v = window_sum::<S>(row, f, k, nx, true);
                for t in ahead.clone() {
                    v += row[centre + t] * f[base + t];
                }
                let mut new = f[k] + (b[k] - v) * inverse;
                for m in (0..r).rev() {
                    new = (-row[centre + behind(m)] * inverse).mul_add(fresh[m], new);
                }
                f[k] = new;
                fresh.copy_within(0..2, 1);
                fresh[0] = new;
            }
            for ii in nx - r..nx {
                edge(f, nth(ii, nx), j);
            }
        }
    }

    #[inline]
    pub(super) fn row_and_inverse(&self, n: usize) -> (&[f64], f64) {
        (self.row(n), self.inverse_diagonal[self.index[n] as usize])
    }

    /// `out = A f`.
    pub fn apply(&self, f: &[f64], out: &mut [f64]) {
        for (j, row) in out.chunks_exact_mut(self.nx).enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = self.apply_ij(f, i, j);
            }
        }
    }

    /// `b − A f`.
    pub fn residual(&self, f: &[f64], b: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; f.len()];
        self.apply(f, &mut r);
        for (r, b) in r.iter_mut().zip(b) {
            *r = b - *r;
        }
        r
    }

    /// The bending (and glue) part of the plate's `A`, one row per class
    /// of node (see [`Classes`]): the plate's rows differ only within two
    /// nodes of an edge.
    pub(super) fn bending(plate: &Plate) -> (Stencil, Classes) {
        let bare = Plate::new(plate.nx, plate.ny, plate.h, plate.alpha, plate.beta, &[]);
        let classes = Classes::new(plate.nx, plate.ny, 2);
        let stencil = Stencil::by_class(&classes, 5, |i, j| {
            probe_row(&bare, &mut vec![0.0; bare.nx * bare.ny], i, j).to_vec()
        });
        (stencil, classes)
    }

    /// `Pᵀ B P` for a class-shared `self` (no springs): one product per
    /// class of coarse node, whose rows can differ only where the fine
    /// rows they gather from do, or where `P` meets an end.
    pub(super) fn galerkin_by_class(&self, fine: &Classes) -> (Stencil, Classes) {
        let (cx, cy) = ((self.nx - 1) / 2 + 1, (self.ny - 1) / 2 + 1);
        // Coarse node `c` gathers the rows of fine nodes `2c − 2..=2c + 2`
        // (P's reach), which must all be of the fine interior class, and
        // their taps reach `side / 2` further, where none may be an end node
        // (P is cut there): `2c − 2 ≥ fine margin` and `2c − 2 − side / 2 ≥
        // 1`, likewise from the other end. This settles at 3.
        let margin = (fine.margin + 2).max(self.side / 2 + 3).div_ceil(2);
        let classes = Classes::new(cx, cy, margin);
        let stencil =
            Stencil::by_class(&classes, 7, |i, j| self.galerkin_row(i, j, cx, cy).to_vec());
        (stencil, classes)
    }

    /// `self + α Σ u uᵀ` over `springs` (each a few nodes and weights): the
    /// nodes a spring touches get rows of their own.
    pub(super) fn with_springs(&self, springs: &[Vec<(usize, f64)>], alpha: f64) -> Stencil {
        let (nx, side) = (self.nx, self.side);
        let (r, area) = ((side / 2) as i64, side * side);
        let mut rows = self.rows.clone();
        let mut index = self.index.clone();
        let mut own = vec![false; index.len()];
        for u in springs {
            for &(a, wa) in u {
                if !own[a] {
                    own[a] = true;
                    let k = index[a] as usize * area;
                    rows.extend_from_within(k..k + area);
                    index[a] = (rows.len() / area - 1) as u32;
                }
                let row = index[a] as usize * area;
                for &(b, wb) in u {
                    let dx = (b % nx) as i64 - (a % nx) as i64;
                    let dy = (b / nx) as i64 - (a / nx) as i64;
                    assert!(
                        dx.abs() <= r && dy.abs() <= r,
                        "a spring wider than the stencil"
                    );
                    rows[row + ((dy + r) * side as i64 + dx + r) as usize] += alpha * wa * wb;
                }
            }
        }
        Stencil::new(self.nx, self.ny, side, rows, index)
    }

    /// `Pᵀ A P` on the grid of every other node (a 7 × 7 stencil), row by
    /// row; see [`Stencil::of`].
    #[cfg(test)]
    pub(crate) fn galerkin(&self) -> Stencil {
        let (cx, cy) = ((self.nx - 1) / 2 + 1, (self.ny - 1) / 2 + 1);
        let rows = (0..cx * cy)
            .flat_map(|n| self.galerkin_row(n % cx, n / cx, cx, cy))
            .collect();
        Stencil::new(cx, cy, 7, rows, (0..(cx * cy) as u32).collect())
    }

    /// Row `(ic, jc)` of `Pᵀ A P` on a `cx × cy` coarse grid.
    pub(super) fn galerkin_row(&self, ic: usize, jc: usize, cx: usize, cy: usize) -> [f64; 49] {
        let (nx, ny, s) = (self.nx, self.ny, self.side);
        let r = (s / 2) as i64;
        let mut row = [0.0; 49];
        for (fy, wy) in children(jc, ny) {
            for (fx, wx) in children(ic, nx) {
                let wi = wx * wy;
                let fine = self.row(fy * nx + fx);
                for dy in -r..=r {
                    for dx in -r..=r {
                        let (kx, ky) = (fx as i64 + dx, fy as i64 + dy);
                        if kx < 0 || ky < 0 || kx >= nx as i64 || ky >= ny as i64 {
                            continue;
                        }
                        let v = fine[((dy + r) * s as i64 + dx + r) as usize];
                        if v == 0.0 {
                            continue;
                        }
                        for (kcx, wkx) in parents(kx as usize, cx) {
                            for (kcy, wky) in parents(ky as usize, cy) {
                                let (ox, oy) = (kcx as i64 - ic as i64, kcy as i64 - jc as i64);
                                row[((oy + 3) * 7 + ox + 3) as usize] += wi * v * wkx * wky;
                            }
                        }
                    }
                }
            }
        }
        row
    }
}

/// Row `(i, j)` of the plate's `A` (5 × 5), probed with unit vectors
/// (`unit`: all zeros, left so).
pub(super) fn probe_row(plate: &Plate, unit: &mut [f64], i: usize, j: usize) -> [f64; 25] {
    let (nx, ny) = (plate.nx as i64, plate.ny as i64);
    let n = j * plate.nx + i;
    let mut row = [0.0; 25];
    for dy in -2..=2 {
        for dx in -2..=2 {
            let (x, y) = (i as i64 + dx, j as i64 + dy);
            if x < 0 || y < 0 || x >= nx || y >= ny {
                continue;
            }
            let m = (y * nx + x) as usize;
            unit[m] = 1.0;
            row[((dy + 2) * 5 + dx + 2) as usize] = plate.apply_at(unit, n);
            unit[m] = 0.0;
        }
    }
    row
}
