//! The snake's linear system `(β DᵀD + Γ) x = b`: symmetric positive definite
//! and pentadiagonal (`D` takes second differences of an open snake), so it is
//! factored once per run (banded LDLᵀ) and solved per iteration in O(n).

/// An LDLᵀ factorisation of a symmetric matrix with two off-diagonals.
#[derive(Debug, Clone)]
pub struct Banded {
    /// `d[i]`, and the unit lower factor's `l1[i] = L[i][i-1]`, `l2[i] = L[i][i-2]`.
    d: Vec<f64>,
    l1: Vec<f64>,
    l2: Vec<f64>,
}

impl Banded {
    /// `β DᵀD + diag(gamma)` for `n` points, factored.
    pub fn bending(n: usize, beta: f64, gamma: &[f64]) -> Banded {
        // Diagonals of DᵀD: row i of D is (1, −2, 1) at columns i..i+3.
        let (mut a0, mut a1, mut a2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for r in 0..n.saturating_sub(2) {
            let c = [1.0, -2.0, 1.0];
            for p in 0..3 {
                a0[r + p] += beta * c[p] * c[p];
                if p >= 1 {
                    a1[r + p] += beta * c[p] * c[p - 1];
                }
                if p >= 2 {
                    a2[r + p] += beta * c[p] * c[p - 2];
                }
            }
        }
        for (a, g) in a0.iter_mut().zip(gamma) {
            *a += g;
        }
        // LDLᵀ for a band of width 2 (a1[i] = A[i][i-1], a2[i] = A[i][i-2]).
        let (mut d, mut l1, mut l2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for i in 0..n {
            if i >= 2 {
                l2[i] = a2[i] / d[i - 2];
            }
            if i >= 1 {
                let mut v = a1[i];
                if i >= 2 {
                    v -= l2[i] * l1[i - 1] * d[i - 2];
                }
                l1[i] = v / d[i - 1];
            }
            let mut v = a0[i];
            if i >= 1 {
                v -= l1[i] * l1[i] * d[i - 1];
            }
            if i >= 2 {
                v -= l2[i] * l2[i] * d[i - 2];
            }
            d[i] = v;
        }
        Banded { d, l1, l2 }
    }

    /// Solves in place: `b` becomes `x`.
    pub fn solve(&self, b: &mut [f64]) {
        let n = b.len();
        for i in 0..n {
            if i >= 1 {
                b[i] -= self.l1[i] * b[i - 1];
            }
            if i >= 2 {
                b[i] -= self.l2[i] * b[i - 2];
            }
        }
        for (v, d) in b.iter_mut().zip(&self.d) {
            *v /= d;
        }
        for i in (0..n).rev() {
            if i + 1 < n {
                b[i] -= self.l1[i + 1] * b[i + 1];
            }
            if i + 2 < n {
                b[i] -= self.l2[i + 2] * b[i + 2];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_the_pentadiagonal_system_like_a_dense_elimination() {
        let n = 9;
        let gamma: Vec<f64> = (0..n).map(|i| 0.5 + i as f64 * 0.1).collect();
        let m = Banded::bending(n, 0.7, &gamma);
        // Dense matrix of the same system.
        let mut a = vec![vec![0.0; n]; n];
        for r in 0..n - 2 {
            let c = [1.0, -2.0, 1.0];
            for p in 0..3 {
                for q in 0..3 {
                    a[r + p][r + q] += 0.7 * c[p] * c[q];
                }
            }
        }
        for i in 0..n {
            a[i][i] += gamma[i];
        }
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() * 3.0).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| (0..n).map(|j| a[i][j] * x_true[j]).sum())
            .collect();
        m.solve(&mut b);
        for (x, t) in b.iter().zip(&x_true) {
            assert!((x - t).abs() < 1e-10, "{x} vs {t}");
        }
    }
}
