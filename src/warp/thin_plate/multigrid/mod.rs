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

use super::plate::Plate;

/// Smoothing sweeps (points, then spring blocks) before and after each
/// coarse-grid correction.
const PRE: usize = 1;
const POST: usize = 1;

mod block;
mod cholesky;
mod galerkin;
mod stencil;
mod transfer;

use block::Block;
use cholesky::Cholesky;
use galerkin::restrict_spring;
pub use stencil::Stencil;
use transfer::Transfer;

/// A grid hierarchy, finest first. Node `(i, j)` of level `l + 1` is node
/// `(2i, 2j)` of level `l`.
pub struct Hierarchy {
    /// The finest plate (its springs give the right-hand sides).
    pub plate: Plate,
    /// Each level's operator, finest first.
    pub levels: Vec<Stencil>,
    /// `transfers[l]`: between level `l` and `l + 1`.
    transfers: Vec<Transfer>,
    coarse: Cholesky,
    /// Per level, each spring's nodes solved together in the smoother.
    blocks: Vec<Vec<Block>>,
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
