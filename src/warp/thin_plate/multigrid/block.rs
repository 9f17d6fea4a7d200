//! Spring blocks: the nodes of one spring's support relaxed together.

use super::stencil::Stencil;

/// A spring's nodes on one level and the inverse of `A` restricted to them:
/// relaxed together, the stiff spring and the soft bending around it move
/// as one (point Gauss-Seidel moves a sprung node by its residual over the
/// spring's stiffness, so the bending around a spring barely relaxes).
pub(super) struct Block {
    pub(super) nodes: Vec<usize>,
    pub(super) inverse: Vec<f64>,
}

impl Block {
    /// One block per distinct set of nodes the springs touch (on coarse
    /// grids many springs share one).
    pub(super) fn all(a: &Stencil, springs: &[Vec<(usize, f64)>]) -> Vec<Block> {
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

    pub(super) fn new(a: &Stencil, nodes: Vec<usize>) -> Block {
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
    pub(super) fn relax(&self, a: &Stencil, f: &mut [f64], b: &[f64]) {
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
pub(super) fn invert_spd(m: &[f64], k: usize) -> Vec<f64> {
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
