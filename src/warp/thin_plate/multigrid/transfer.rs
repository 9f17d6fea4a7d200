//! Moving corrections between levels: cubic B-spline prolongation and
//! its transpose.

use super::galerkin::{children, parents};

/// `P` between a fine grid and the grid of every other node, per axis, as
/// tables built once per level: which coarse nodes each fine node reads
/// (`parents`) and which fine nodes each coarse node feeds (`children`).
pub(super) struct Transfer {
    pub(super) fine: (usize, usize),
    pub(super) coarse: (usize, usize),
    pub(super) parents: [Vec<Vec<(usize, f64)>>; 2],
    pub(super) children: [Vec<Vec<(usize, f64)>>; 2],
}

impl Transfer {
    pub(super) fn new(nx: usize, ny: usize) -> Transfer {
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
    pub(super) fn restrict(&self, r: &[f64]) -> Vec<f64> {
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
    pub(super) fn prolong_add(&self, e: &[f64], f: &mut [f64]) {
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
