use super::{basis, Lattice};
use crate::geom::Vec2;

/// The least-squares control displacements of Lee, Wolberg et al. §5.3: each point asks
/// its 16 controls for `φ_kl = w_kl Δq / Σ w_ab²` (eq. 4, the smallest
/// displacements that move it by `Δq`); a control shared by several points
/// takes `Σ w_c² φ_c / Σ w_c²` (eq. 5). Controls no point reads stay zero.
/// Vector-valued so one pass serves both coordinates of a deformation; a
/// scalar surface uses `x` only.
#[derive(Debug, Clone)]
pub struct Approximation {
    geometry: Lattice,
    delta: Vec<Vec2>,
    omega: Vec<f64>,
}

impl Approximation {
    /// Accumulates onto the geometry (origin, spacing, size) of `lattice`.
    pub fn new(lattice: &Lattice) -> Self {
        let n = lattice.nx * lattice.ny;
        Approximation {
            geometry: Lattice {
                phi: Vec::new(),
                ..lattice.clone()
            },
            delta: vec![Vec2::ZERO; n],
            omega: vec![0.0; n],
        }
    }

    /// Point `p` should move by `dq` (or the surface should rise by `dq.x`).
    /// Points whose controls are not all stored are skipped: the caller sizes
    /// the lattice to cover them ([`Lattice::covering`]).
    pub fn add(&mut self, p: Vec2, dq: Vec2) {
        let g = &self.geometry;
        if !g.reaches(p) {
            return;
        }
        let (c, r, s, t) = g.locate(p);
        let (bs, bt) = (basis(s), basis(t));
        let mut sum_w2 = 0.0;
        for wt in bt {
            for ws in bs {
                sum_w2 += (ws * wt) * (ws * wt);
            }
        }
        for (l, wt) in bt.iter().enumerate() {
            let row = (r - 1 + l as i64) as usize * g.nx;
            for (k, ws) in bs.iter().enumerate() {
                let w = ws * wt;
                let i = row + (c - 1 + k as i64) as usize;
                // w² φ_kl = w² · w Δq / Σw².
                self.delta[i] += dq * (w * w * w / sum_w2);
                self.omega[i] += w * w;
            }
        }
    }

    /// The control lattices (x, y). With `bound`, each displacement is
    /// truncated to `|Δφ|∞ ≤ bound` (Theorem 1's 0.48 h keeps a deformation
    /// one-to-one).
    pub fn finish(self, bound: Option<f64>) -> (Lattice, Lattice) {
        let mut x = Lattice {
            phi: vec![0.0; self.delta.len()],
            ..self.geometry
        };
        let mut y = x.clone();
        for (i, (d, w)) in self.delta.iter().zip(&self.omega).enumerate() {
            if *w > 0.0 {
                let mut v = *d / *w;
                if let Some(b) = bound {
                    v = Vec2::new(v.x.clamp(-b, b), v.y.clamp(-b, b));
                }
                x.phi[i] = v.x;
                y.phi[i] = v.y;
            }
        }
        (x, y)
    }
}
