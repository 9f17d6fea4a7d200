//! Multigrid V-cycles for the plate (Lee et al. §2.2, after Terzopoulos):
//! Gauss-Seidel smoothing with each spring's nodes relaxed as a block,
//! cubic B-spline prolongation `P`, its transpose as restriction, and
//! Galerkin coarse systems `A_c = Pᵀ A P`, solved directly (banded
//! Cholesky) on the coarsest grid, where the plate's affine modes live.
//!
//! Why Galerkin: rediscretising the plate on the coarse grid makes its
//! bending energy about half what the fine grid gives the interpolated
//! correction, so coarse corrections overshoot by up to 2× and the cycle
//! diverges. With `A_c = Pᵀ A P` the coarse correction is the energy-norm
//! projection, which never increases the error, and the springs' stiffness
//! (α ≫ bending) carries down exactly.
//!
//! Why B-spline prolongation: the plate's energy is in second derivatives.
//! A bilinear `P` puts a kink at every coarse node, so a smooth coarse
//! correction costs `2^level` times its true bending energy and the coarse
//! grids barely move the smooth, soft modes (a free edge swinging far from
//! any spring): measured, PCG needed 15, 21, 30, 39 iterations for a 0.001 px
//! update on grids 240 to 1920 px wide. Cubic B-spline subdivision (C², and
//! linear at the ends so affine modes reach the coarsest grid) removes the
//! kinks; coarse stencils grow from 5 × 5 to 7 × 7.
//!
//! Why spring blocks: a spring (α = 100 px⁻² against bending of about
//! 1 px⁻² per node) fixes one combination of its cell's nodes and leaves the
//! rest to bending, but point Gauss-Seidel divides every residual at a
//! sprung node by the spring's stiffness, so the bending around each spring
//! hardly relaxes and every spring leaves a slow mode for CG to remove: at
//! 1080p with 500 springs, 22 iterations (10 with α = 1). Relaxing each
//! spring's nodes together (a 4- to 16-node solve) took it to 8-10, with
//! one sweep each way instead of two.

use wide::f64x4;

use super::plate::Plate;

/// Smoothing sweeps (points, then spring blocks) before and after each
/// coarse-grid correction.
const PRE: usize = 1;
const POST: usize = 1;

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
    pub nx: usize,
    pub ny: usize,
    /// Stencil width: 5 or 7.
    side: usize,
    /// The distinct stencils, `side²` entries each; offset `(dx, dy)` at
    /// `(dy + r) * side + dx + r` with `r = side / 2`.
    rows: Vec<f64>,
    /// Per node, its stencil in `rows`.
    index: Vec<u32>,
    /// `1 / centre` per distinct stencil.
    inverse_diagonal: Vec<f64>,
}

impl Stencil {
    fn new(nx: usize, ny: usize, side: usize, rows: Vec<f64>, index: Vec<u32>) -> Stencil {
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
    fn apply_ij(&self, f: &[f64], i: usize, j: usize) -> f64 {
        match self.side {
            5 => self.apply_with::<5>(f, i, j),
            _ => self.apply_with::<7>(f, i, j),
        }
    }

    #[inline(always)]
    fn apply_with<const S: usize>(&self, f: &[f64], i: usize, j: usize) -> f64 {
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
    fn relax_with<const S: usize>(&self, f: &mut [f64], b: &[f64], forward: bool) {
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
    fn row_and_inverse(&self, n: usize) -> (&[f64], f64) {
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
    fn bending(plate: &Plate) -> (Stencil, Classes) {
        let bare = Plate::new(plate.nx, plate.ny, plate.h, plate.alpha, plate.beta, &[]);
        let classes = Classes::new(plate.nx, plate.ny, 2);
        let stencil = classes.stencil(5, |i, j| {
            probe_row(&bare, &mut vec![0.0; bare.nx * bare.ny], i, j).to_vec()
        });
        (stencil, classes)
    }

    /// `Pᵀ B P` for a class-shared `self` (no springs): one product per
    /// class of coarse node, whose rows can differ only where the fine
    /// rows they gather from do, or where `P` meets an end.
    fn galerkin_by_class(&self, fine: &Classes) -> (Stencil, Classes) {
        let (cx, cy) = ((self.nx - 1) / 2 + 1, (self.ny - 1) / 2 + 1);
        // Coarse node `c` gathers the rows of fine nodes `2c − 2..=2c + 2`
        // (P's reach), which must all be of the fine interior class, and
        // their taps reach `side / 2` further, where none may be an end node
        // (P is cut there): `2c − 2 ≥ fine margin` and `2c − 2 − side / 2 ≥
        // 1`, likewise from the other end. This settles at 3.
        let margin = (fine.margin + 2).max(self.side / 2 + 3).div_ceil(2);
        let classes = Classes::new(cx, cy, margin);
        let stencil = classes.stencil(7, |i, j| self.galerkin_row(i, j, cx, cy).to_vec());
        (stencil, classes)
    }

    /// `self + α Σ u uᵀ` over `springs` (each a few nodes and weights): the
    /// nodes a spring touches get rows of their own.
    fn with_springs(&self, springs: &[Vec<(usize, f64)>], alpha: f64) -> Stencil {
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
    fn galerkin_row(&self, ic: usize, jc: usize, cx: usize, cy: usize) -> [f64; 49] {
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
fn probe_row(plate: &Plate, unit: &mut [f64], i: usize, j: usize) -> [f64; 25] {
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

/// Nodes whose operator rows can differ only by how near they are to the
/// edges: on each axis, the `margin` nodes at either end are classes of
/// their own and the rest one interior class (every node its own class on
/// an axis too short for that).
#[derive(Debug, Clone, Copy)]
struct Classes {
    nx: usize,
    ny: usize,
    margin: usize,
}

impl Classes {
    fn new(nx: usize, ny: usize, margin: usize) -> Classes {
        Classes { nx, ny, margin }
    }

    fn count(&self, n: usize) -> usize {
        let m = self.margin;
        if n < 2 * m + 1 {
            n
        } else {
            2 * m + 1
        }
    }

    /// Class of node `i` of `n`: `0..m` from the low end, `m` inside,
    /// `m + 1..=2m` toward the high end.
    fn of(&self, i: usize, n: usize) -> usize {
        let m = self.margin;
        if n < 2 * m + 1 || i < m {
            i
        } else if i + m >= n {
            2 * m + 1 + i - n
        } else {
            m
        }
    }

    /// A node of class `c` on an axis of `n`.
    fn representative(&self, c: usize, n: usize) -> usize {
        let m = self.margin;
        if n < 2 * m + 1 || c <= m {
            c
        } else {
            n + c - 2 * m - 1
        }
    }

    /// A stencil whose rows are `row(i, j)` of one representative node per
    /// class, computed in parallel.
    fn stencil(&self, side: usize, row: impl Fn(usize, usize) -> Vec<f64> + Sync) -> Stencil {
        use rayon::prelude::*;
        let (nx, ny) = (self.nx, self.ny);
        let kx = self.count(nx);
        let rows: Vec<f64> = (0..kx * self.count(ny))
            .into_par_iter()
            .flat_map_iter(|c| {
                row(
                    self.representative(c % kx, nx),
                    self.representative(c / kx, ny),
                )
            })
            .collect();
        let index = (0..nx * ny)
            .map(|n| (self.of(n / nx, ny) * kx + self.of(n % nx, nx)) as u32)
            .collect();
        Stencil::new(nx, ny, side, rows, index)
    }
}

/// `Pᵀ u` for a spring's weights `u` on a fine grid `nx` wide, onto the
/// `cx × cy` coarse grid.
fn restrict_spring(u: &[(usize, f64)], nx: usize, cx: usize, cy: usize) -> Vec<(usize, f64)> {
    let mut out: Vec<(usize, f64)> = Vec::with_capacity(16);
    for &(n, w) in u {
        for (px, wx) in parents(n % nx, cx) {
            for (py, wy) in parents(n / nx, cy) {
                let c = py * cx + px;
                match out.iter_mut().find(|(k, _)| *k == c) {
                    Some(e) => e.1 += w * wx * wy,
                    None => out.push((c, w * wx * wy)),
                }
            }
        }
    }
    out
}

/// The `S × S` stencil `row` at interior node `n` against `f`; with
/// `skip_centre`, the centre row is left out (the sweeps add it). Four lanes
/// of partial sums and a scalar, so the taps do not form one long chain.
#[inline(always)]
fn window_sum<const S: usize>(
    row: &[f64],
    f: &[f64],
    n: usize,
    nx: usize,
    skip_centre: bool,
) -> f64 {
    let r = S / 2;
    let base = n - r * nx - r;
    let mut v = f64x4::ZERO;
    let mut tail = 0.0;
    for dy in 0..S {
        if skip_centre && dy == r {
            continue;
        }
        let f = &f[base + dy * nx..base + dy * nx + S];
        let w = &row[dy * S..dy * S + S];
        let (wv, fv) = (
            f64x4::from([w[0], w[1], w[2], w[3]]),
            f64x4::from([f[0], f[1], f[2], f[3]]),
        );
        v = wv.mul_add(fv, v);
        for t in 4..S {
            tail += w[t] * f[t];
        }
    }
    v.reduce_add() + tail
}

/// The coarse nodes (and weights) fine node `x` is interpolated from, on an
/// axis of `cn` coarse nodes: cubic B-spline subdivision (even nodes
/// `(c[i−1] + 6c[i] + c[i+1]) / 8`, odd nodes `(c[i] + c[i+1]) / 2`), with
/// the missing control past an end extrapolated linearly, which makes the
/// end node interpolate (so affine functions pass exactly).
fn parents(x: usize, cn: usize) -> impl Iterator<Item = (usize, f64)> {
    let c = x / 2;
    let weights = if x % 2 == 1 {
        [(c, 0.5), (c + 1, 0.5), (c, 0.0)]
    } else if c == 0 || c + 1 >= cn {
        [(c, 1.0), (c, 0.0), (c, 0.0)]
    } else {
        [(c - 1, 0.125), (c, 0.75), (c + 1, 0.125)]
    };
    weights.into_iter().filter(|(_, w)| *w != 0.0)
}

/// The fine nodes (and weights) coarse node `c` feeds, on an axis of `n`
/// fine nodes: `P`'s column, read from its rows.
fn children(c: usize, n: usize) -> impl Iterator<Item = (usize, f64)> {
    let cn = (n - 1) / 2 + 1;
    ((2 * c).saturating_sub(2)..=(2 * c + 2).min(n - 1)).flat_map(move |x| {
        parents(x, cn)
            .filter(move |(p, _)| *p == c)
            .map(move |(_, w)| (x, w))
    })
}

/// A grid hierarchy, finest first. Node `(i, j)` of level `l + 1` is node
/// `(2i, 2j)` of level `l`.
pub struct Hierarchy {
    /// The finest plate (its springs give the right-hand sides).
    pub plate: Plate,
    pub levels: Vec<Stencil>,
    /// `transfers[l]`: between level `l` and `l + 1`.
    transfers: Vec<Transfer>,
    coarse: Cholesky,
    /// Per level, each spring's nodes solved together in the smoother.
    blocks: Vec<Vec<Block>>,
}

/// A spring's nodes on one level and the inverse of `A` restricted to them:
/// relaxed together, the stiff spring and the soft bending around it move
/// as one (point Gauss-Seidel moves a sprung node by its residual over the
/// spring's stiffness, so the bending around a spring barely relaxes).
struct Block {
    nodes: Vec<usize>,
    inverse: Vec<f64>,
}

impl Block {
    /// One block per distinct set of nodes the springs touch (on coarse
    /// grids many springs share one).
    fn all(a: &Stencil, springs: &[Vec<(usize, f64)>]) -> Vec<Block> {
        let mut sets: Vec<Vec<usize>> = springs
            .iter()
            .map(|u| {
                let mut nodes: Vec<usize> = u.iter().map(|&(n, _)| n).collect();
                nodes.sort_unstable();
                nodes
            })
            .collect();
        sets.sort_unstable();
        sets.dedup();
        use rayon::prelude::*;
        sets.into_par_iter()
            .map(|nodes| Block::new(a, nodes))
            .collect()
    }

    fn new(a: &Stencil, nodes: Vec<usize>) -> Block {
        let k = nodes.len();
        // 2 × 2 on the plate; `Pᵀ` takes a run of n nodes per axis to at
        // most (n + 5) / 2, so a support stays within 4 × 4 on every level.
        assert!(k <= 16, "a spring block of {k} nodes");
        let (nx, side) = (a.nx, a.side);
        let r = (side / 2) as i64;
        let mut m = vec![0.0; k * k];
        for (p, &na) in nodes.iter().enumerate() {
            let row = a.row(na);
            for (q, &nb) in nodes.iter().enumerate() {
                let dx = (nb % nx) as i64 - (na % nx) as i64;
                let dy = (nb / nx) as i64 - (na / nx) as i64;
                m[p * k + q] = row[((dy + r) * side as i64 + dx + r) as usize];
            }
        }
        Block {
            nodes,
            inverse: invert_spd(&m, k),
        }
    }

    /// `f_B += A_BB⁻¹ (b − A f)_B`.
    fn relax(&self, a: &Stencil, f: &mut [f64], b: &[f64]) {
        let k = self.nodes.len();
        let mut r = [0.0; 16];
        for (p, &n) in self.nodes.iter().enumerate() {
            r[p] = b[n] - a.apply_at(f, n);
        }
        for (p, &n) in self.nodes.iter().enumerate() {
            let row = &self.inverse[p * k..p * k + k];
            f[n] += row.iter().zip(&r[..k]).map(|(w, v)| w * v).sum::<f64>();
        }
    }
}

/// The inverse of a small symmetric positive definite matrix (Gauss-Jordan).
fn invert_spd(m: &[f64], k: usize) -> Vec<f64> {
    let mut a = m.to_vec();
    let mut inv: Vec<f64> = (0..k * k)
        .map(|x| if x / k == x % k { 1.0 } else { 0.0 })
        .collect();
    for c in 0..k {
        let d = a[c * k + c];
        for x in 0..k {
            a[c * k + x] /= d;
            inv[c * k + x] /= d;
        }
        for r in 0..k {
            if r != c {
                let g = a[r * k + c];
                for x in 0..k {
                    a[r * k + x] -= g * a[c * k + x];
                    inv[r * k + x] -= g * inv[c * k + x];
                }
            }
        }
    }
    inv
}

/// How a solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// `‖b − A f‖₂` before the first cycle and after each.
    pub residuals: Vec<f64>,
    /// The largest change of any node in each cycle.
    pub moved: Vec<f64>,
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
        // Each level as bending plus springs (see `Classes`): the Galerkin
        // product of a sum is the sum of the products, so a coarse level is
        // one product per class of node and a restriction per spring, not
        // a product per node near a spring (70 ms at 1080p, 500 springs).
        let (mut bending, mut classes) = Stencil::bending(&plate);
        let mut springs: Vec<Vec<(usize, f64)>> = plate
            .springs
            .iter()
            .map(|s| s.nodes.into_iter().zip(s.weights).collect())
            .collect();
        let mut stencils = vec![bending.with_springs(&springs, alpha)];
        let mut blocks = vec![Block::all(&stencils[0], &springs)];
        for _ in 1..levels {
            let (fine_nx, cx, cy) = (
                bending.nx,
                (bending.nx - 1) / 2 + 1,
                (bending.ny - 1) / 2 + 1,
            );
            (bending, classes) = bending.galerkin_by_class(&classes);
            springs = springs
                .iter()
                .map(|u| restrict_spring(u, fine_nx, cx, cy))
                .collect();
            stencils.push(bending.with_springs(&springs, alpha));
            blocks.push(Block::all(stencils.last().unwrap(), &springs));
        }
        let coarse = Cholesky::of(&stencils[stencils.len() - 1]);
        let transfers = stencils[..stencils.len() - 1]
            .iter()
            .map(|s| Transfer::new(s.nx, s.ny))
            .collect();
        Hierarchy {
            plate,
            levels: stencils,
            transfers,
            coarse,
            blocks,
        }
    }

    /// Solves from `f` until an iteration moves no node by more than
    /// `tolerance` (the solution's own units: px for a warp) or after
    /// `max_cycles`: conjugate gradients preconditioned by one V-cycle per
    /// iteration.
    ///
    /// Plain V-cycles stall here: a stiff spring pins a whole coarse cell,
    /// so the coarse grids cannot correct the plate right next to it and a
    /// few error modes decay at 0.96 per cycle. The V-cycle is symmetric
    /// (forward sweeps then blocks down, blocks reversed then backward sweeps
    /// up, exact coarse solve), so it is a valid preconditioner, and CG
    /// removes exactly those few slow modes.
    ///
    /// Why not stop on the residual: the soft modes (a free edge swinging
    /// between springs) leave almost no residual while they are pixels off;
    /// a relative residual of 1e-4 stopped 5 px short of the solution at a
    /// frame's edge. How far the last iteration moved the plate is what
    /// shows in the picture (and CG's steps shrink geometrically, so the
    /// rest of the way is of the same order).
    pub fn solve(&self, f: &mut [f64], b: &[f64], tolerance: f64, max_cycles: usize) -> Report {
        let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let a = &self.levels[0];
        let mut r = a.residual(f, b);
        let mut residuals = vec![dot(&r, &r).sqrt()];
        let mut moved = Vec::new();
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
            if rz <= 0.0 || moved.last().is_some_and(|m| *m <= tolerance) {
                break;
            }
            a.apply(&p, &mut ap);
            let step = rz / dot(&p, &ap);
            let mut largest = 0.0f64;
            for k in 0..f.len() {
                f[k] += step * p[k];
                r[k] -= step * ap[k];
                largest = largest.max(p[k].abs());
            }
            residuals.push(dot(&r, &r).sqrt());
            moved.push(step.abs() * largest);
            z = precondition(&r);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            for (pk, zk) in p.iter_mut().zip(&z) {
                *pk = zk + beta * *pk;
            }
        }
        Report { residuals, moved }
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
            for block in &self.blocks[l] {
                block.relax(a, f, b);
            }
        }
        let r = a.residual(f, b);
        let rc = self.transfers[l].restrict(&r);
        let mut e = vec![0.0; rc.len()];
        self.cycle(l + 1, &mut e, &rc);
        self.transfers[l].prolong_add(&e, f);
        for _ in 0..POST {
            for block in self.blocks[l].iter().rev() {
                block.relax(a, f, b);
            }
            a.relax(f, b, false);
        }
    }
}

/// `P` between a fine grid and the grid of every other node, per axis, as
/// tables built once per level: which coarse nodes each fine node reads
/// (`parents`) and which fine nodes each coarse node feeds (`children`).
struct Transfer {
    fine: (usize, usize),
    coarse: (usize, usize),
    parents: [Vec<Vec<(usize, f64)>>; 2],
    children: [Vec<Vec<(usize, f64)>>; 2],
}

impl Transfer {
    fn new(nx: usize, ny: usize) -> Transfer {
        let (cx, cy) = ((nx - 1) / 2 + 1, (ny - 1) / 2 + 1);
        let up = |n: usize, cn: usize| (0..n).map(|x| parents(x, cn).collect()).collect();
        let down = |n: usize, cn: usize| (0..cn).map(|c| children(c, n).collect()).collect();
        Transfer {
            fine: (nx, ny),
            coarse: (cx, cy),
            parents: [up(nx, cx), up(ny, cy)],
            children: [down(nx, cx), down(ny, cy)],
        }
    }

    /// `Pᵀ r`, separable (rows, then columns).
    fn restrict(&self, r: &[f64]) -> Vec<f64> {
        let ((nx, ny), (cx, cy)) = (self.fine, self.coarse);
        let mut wide = vec![0.0; cx * ny];
        for (row, out) in r.chunks_exact(nx).zip(wide.chunks_exact_mut(cx)) {
            for (o, column) in out.iter_mut().zip(&self.children[0]) {
                *o = column.iter().map(|&(x, w)| w * row[x]).sum();
            }
        }
        let mut rc = vec![0.0; cx * cy];
        for (out, rows) in rc.chunks_exact_mut(cx).zip(&self.children[1]) {
            for &(y, wy) in rows {
                for (o, v) in out.iter_mut().zip(&wide[y * cx..(y + 1) * cx]) {
                    *o += wy * v;
                }
            }
        }
        rc
    }

    /// `f += P e`: a coarse row interpolated in y once per fine row, then in x.
    fn prolong_add(&self, e: &[f64], f: &mut [f64]) {
        let cx = self.coarse.0;
        let mut mixed = vec![0.0; cx];
        for (out, rows) in f.chunks_exact_mut(self.fine.0).zip(&self.parents[1]) {
            mixed.fill(0.0);
            for &(c, wy) in rows {
                for (m, v) in mixed.iter_mut().zip(&e[c * cx..(c + 1) * cx]) {
                    *m += wy * v;
                }
            }
            for (o, from) in out.iter_mut().zip(&self.parents[0]) {
                *o += from.iter().map(|&(c, w)| w * mixed[c]).sum::<f64>();
            }
        }
    }
}

/// A banded Cholesky factor of a (small) stencil operator, with a tiny
/// ridge so a plate with no springs and no glue (affine modes free) still
/// factors. Row-major nodes and an `S × S` stencil put every entry within
/// `(S / 2)(nx + 1)` of the diagonal, so factoring costs `n · band²` rather
/// than `n³`: a coarsest grid of a few hundred nodes stays cheap, and the
/// V-cycle stops there instead of smoothing grids the springs crowd.
pub struct Cholesky {
    n: usize,
    band: usize,
    /// `L[i][j]` at `i * (band + 1) + (i − j)`, for `i − band ≤ j ≤ i`.
    l: Vec<f64>,
}

impl Cholesky {
    pub fn of(s: &Stencil) -> Cholesky {
        let (nx, n) = (s.nx, s.nx * s.ny);
        let r = s.side / 2;
        let band = (r * (nx + 1)).min(n.saturating_sub(1));
        let width = band + 1;
        let mut l = vec![0.0; n * width];
        let (side, ri) = (s.side as i64, r as i64);
        for i in 0..n {
            let row = s.row(i);
            let (x, y) = ((i % nx) as i64, (i / nx) as i64);
            for dy in -ri..=0 {
                for dx in -ri..=ri {
                    let (cx, cy) = (x + dx, y + dy);
                    let j = cy * nx as i64 + cx;
                    if cx < 0 || cy < 0 || cx >= nx as i64 || j > i as i64 {
                        continue;
                    }
                    l[i * width + i - j as usize] = row[((dy + ri) * side + dx + ri) as usize];
                }
            }
        }
        let largest = (0..n).fold(0.0f64, |m, i| m.max(l[i * width]));
        let ridge = 1e-12 * largest;
        for i in 0..n {
            l[i * width] += ridge;
            for j in i.saturating_sub(band)..=i {
                let k0 = i.saturating_sub(band).max(j.saturating_sub(band));
                let mut v = l[i * width + i - j];
                for k in k0..j {
                    v -= l[i * width + i - k] * l[j * width + j - k];
                }
                l[i * width + i - j] = if i == j {
                    v.max(ridge).sqrt()
                } else {
                    v / l[j * width]
                };
            }
        }
        Cholesky { n, band, l }
    }

    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let (n, band, l) = (self.n, self.band, &self.l);
        let width = band + 1;
        let mut y = b.to_vec();
        for i in 0..n {
            for k in i.saturating_sub(band)..i {
                y[i] -= l[i * width + i - k] * y[k];
            }
            y[i] /= l[i * width];
        }
        for i in (0..n).rev() {
            for k in i + 1..(i + band + 1).min(n) {
                y[i] -= l[k * width + k - i] * y[k];
            }
            y[i] /= l[i * width];
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Lcg;

    /// A plate 33 × 17 with springs and a little glue (so the system is
    /// well conditioned and the ridge does not show) and its two Galerkin
    /// levels: wide enough that the band is narrower than the system.
    fn levels() -> (Hierarchy, Vec<Vec<(usize, f64)>>) {
        let mut r = Lcg::new(8);
        let at: Vec<(f64, f64)> = (0..14)
            .map(|_| (r.range(0.0, 32.0), r.range(0.0, 16.0)))
            .collect();
        let h = Hierarchy::new(33, 17, 4.0, 100.0, 1e-3, &at, 3);
        let springs = h
            .plate
            .springs
            .iter()
            .map(|s| s.nodes.into_iter().zip(s.weights).collect())
            .collect();
        (h, springs)
    }

    fn random(n: usize, seed: u64) -> Vec<f64> {
        let mut r = Lcg::new(seed);
        (0..n).map(|_| r.range(-1.0, 1.0)).collect()
    }

    #[test]
    fn banded_cholesky_solves_each_level() {
        let (h, _) = levels();
        for a in &h.levels {
            let n = a.nx * a.ny;
            let c = Cholesky::of(a);
            assert!(c.band < n - 1, "banded, not dense");
            let b = random(n, 5);
            let x = c.solve(&b);
            let mut ax = vec![0.0; n];
            a.apply(&x, &mut ax);
            // Backward error (residual against the sizes of A's rows and of
            // x), room left for the ridge (1e-12 of the largest diagonal).
            let size = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (k, (got, want)) in ax.iter().zip(&b).enumerate() {
                let scale = a.row(k).iter().map(|v| v.abs()).sum::<f64>() * size;
                assert!(
                    (got - want).abs() < 1e-9 * scale,
                    "{}x{} node {k}: {got} vs {want}, scale {scale}",
                    a.nx,
                    a.ny
                );
            }
        }
    }

    #[test]
    fn a_spring_block_solves_its_nodes_exactly() {
        let (h, springs) = levels();
        let a = &h.levels[0];
        let n = a.nx * a.ny;
        let (b, mut f) = (random(n, 6), random(n, 7));
        let blocks = Block::all(a, &springs);
        for block in &blocks {
            let before = f.clone();
            block.relax(a, &mut f, &b);
            for (k, (x, y)) in f.iter().zip(&before).enumerate() {
                if !block.nodes.contains(&k) {
                    assert_eq!(x, y, "only the block's nodes move");
                }
            }
            for &k in &block.nodes {
                let r = b[k] - a.apply_at(&f, k);
                assert!(
                    r.abs() < 1e-9 * a.row(k).iter().map(|v| v.abs()).sum::<f64>(),
                    "node {k}: {r}"
                );
            }
        }
        // Springs sharing a cell share a block.
        assert!(blocks.len() <= springs.len());
    }

    #[test]
    fn restriction_is_the_transpose_of_prolongation() {
        let transfer = Transfer::new(17, 13);
        let mut r = Lcg::new(3);
        let e: Vec<f64> = (0..9 * 7).map(|_| r.range(-1.0, 1.0)).collect();
        let v: Vec<f64> = (0..17 * 13).map(|_| r.range(-1.0, 1.0)).collect();
        let mut pe = vec![0.0; 17 * 13];
        transfer.prolong_add(&e, &mut pe);
        let lhs: f64 = pe.iter().zip(&v).map(|(a, b)| a * b).sum();
        let rhs: f64 = e
            .iter()
            .zip(transfer.restrict(&v))
            .map(|(a, b)| a * b)
            .sum();
        assert!(
            (lhs - rhs).abs() < 1e-12 * lhs.abs().max(1.0),
            "{lhs} vs {rhs}"
        );
        // A linear function on the coarse grid is the same
        // function on the fine one (coarse node (i, j) is fine (2i, 2j)).
        let linear = |x: f64, y: f64| 3.0 * x - 2.0 * y + 1.0;
        let e: Vec<f64> = (0..9 * 7)
            .map(|k| linear(2.0 * (k % 9) as f64, 2.0 * (k / 9) as f64))
            .collect();
        let mut f = vec![0.0; 17 * 13];
        transfer.prolong_add(&e, &mut f);
        for (k, v) in f.iter().enumerate() {
            assert!((v - linear((k % 17) as f64, (k / 17) as f64)).abs() < 1e-12);
        }
    }
}
