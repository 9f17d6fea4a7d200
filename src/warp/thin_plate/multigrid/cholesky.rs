//! The coarsest level's direct solve: a banded Cholesky factor.

use super::stencil::Stencil;

/// A banded Cholesky factor of a (small) stencil operator, with a tiny
/// ridge so a plate with no springs and no glue (affine modes free) still
/// factors. Row-major nodes and an `S × S` stencil put every entry within
/// `(S / 2)(nx + 1)` of the diagonal, so factoring costs `n · band²` rather
/// than `n³`: a coarsest grid of a few hundred nodes stays cheap, and the
/// V-cycle stops there instead of smoothing grids the springs crowd.
pub struct Cholesky {
    pub(super) n: usize,
    pub(super) band: usize,
    /// `L[i][j]` at `i * (band + 1) + (i − j)`, for `i − band ≤ j ≤ i`.
    pub(super) l: Vec<f64>,
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
