//! Catmull-Rom interpolation of `y = f(x)` through knots with any spacing,
//! as in Wolberg's `catmullRom` (his listing): the tangent at a knot is
//! the slope between its neighbours, the end tangents the slope of the end
//! interval. It passes through every knot and reproduces straight lines
//! exactly, which is why an affinely moved mesh warps affinely.

/// What the curve does beyond its first and last knot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Beyond {
    /// Keep the end value (a mesh column's x above its top node).
    Hold,
    /// Keep the end offset `y − x` (a row's mapping outside the mesh moves
    /// like its end node: the identity when the border is frozen).
    Shift,
}

/// Cubic coefficients of one interval, in powers of `x − x[j]`.
#[derive(Debug, Clone, Copy)]
struct Piece {
    x0: f64,
    a: [f64; 4],
}

impl Piece {
    fn new(x: &[f64], y: &[f64], j: usize) -> Piece {
        let n = x.len();
        let (j1, j2) = (j.saturating_sub(1), (j + 2).min(n - 1));
        let dx = 1.0 / (x[j + 1] - x[j]);
        let dx1 = 1.0 / (x[j + 1] - x[j1]);
        let dx2 = 1.0 / (x[j2] - x[j]);
        let dy = (y[j + 1] - y[j]) * dx;
        let yd1 = (y[j + 1] - y[j1]) * dx1;
        let yd2 = (y[j2] - y[j]) * dx2;
        Piece {
            x0: x[j],
            a: [
                y[j],
                yd1,
                dx * (3.0 * dy - 2.0 * yd1 - yd2),
                dx * dx * (-2.0 * dy + yd1 + yd2),
            ],
        }
    }

    #[inline]
    fn at(&self, x: f64) -> f64 {
        let u = x - self.x0;
        ((self.a[3] * u + self.a[2]) * u + self.a[1]) * u + self.a[0]
    }
}

/// The spline through `(x[i], y[i])`. Knots must increase strictly; callers
/// with knots that may not (columns squeezed together mid-morph) pass them
/// through [`increasing`] first.
pub fn eval(x: &[f64], y: &[f64], beyond: Beyond, at: f64) -> f64 {
    let n = x.len();
    debug_assert!(n >= 2 && y.len() == n);
    if at <= x[0] || at >= x[n - 1] {
        return outside(x, y, beyond, at);
    }
    let j = x.partition_point(|&k| k <= at) - 1;
    Piece::new(x, y, j.min(n - 2)).at(at)
}

/// The spline at ascending positions `at`, into `out` (one pass over the
/// knots; each interval's run of positions is a plain loop that vectorises).
pub fn eval_sorted(x: &[f64], y: &[f64], beyond: Beyond, at: &[f64], out: &mut [f64]) {
    let n = x.len();
    debug_assert!(n >= 2 && y.len() == n && out.len() == at.len());
    let m = at.len();
    let mut k = 0;
    while k < m && at[k] <= x[0] {
        out[k] = outside(x, y, beyond, at[k]);
        k += 1;
    }
    for j in 0..n - 1 {
        if k >= m {
            return;
        }
        let end = x[j + 1];
        let first = k;
        while k < m && at[k] < end {
            k += 1;
        }
        if k > first {
            let piece = Piece::new(x, y, j);
            for (o, p) in out[first..k].iter_mut().zip(&at[first..k]) {
                *o = piece.at(*p);
            }
        }
    }
    for (o, p) in out[k..].iter_mut().zip(&at[k..]) {
        *o = outside(x, y, beyond, *p);
    }
}

#[inline]
fn outside(x: &[f64], y: &[f64], beyond: Beyond, at: f64) -> f64 {
    let k = if at <= x[0] { 0 } else { x.len() - 1 };
    match beyond {
        Beyond::Hold => y[k],
        Beyond::Shift => at + (y[k] - x[k]),
    }
}

/// Keeps the knots that increase strictly (drops any knot not right of the
/// last kept one), so a spline can be fitted even through a pinched mesh.
pub fn increasing(x: &mut Vec<f64>, y: &mut Vec<f64>) {
    let mut keep = 0;
    for i in 0..x.len() {
        if keep == 0 || x[i] > x[keep - 1] {
            x[keep] = x[i];
            y[keep] = y[i];
            keep += 1;
        }
    }
    x.truncate(keep);
    y.truncate(keep);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_through_uneven_knots() {
        let x = [0.0, 1.0, 3.5, 4.0, 9.0];
        let y = [2.0, -1.0, 5.0, 4.0, 0.5];
        for (xi, yi) in x.iter().zip(&y) {
            assert!((eval(&x, &y, Beyond::Hold, *xi) - yi).abs() < 1e-12);
        }
    }

    #[test]
    fn reproduces_straight_lines_on_uneven_knots() {
        let x = [0.0, 0.7, 3.5, 4.0, 9.0, 9.1];
        let y: Vec<f64> = x.iter().map(|v| 3.0 * v - 2.0).collect();
        let at: Vec<f64> = (0..=91).map(|k| k as f64 * 0.1).collect();
        let mut out = vec![0.0; at.len()];
        eval_sorted(&x, &y, Beyond::Shift, &at, &mut out);
        for (p, v) in at.iter().zip(&out) {
            assert!((v - (3.0 * p - 2.0)).abs() < 1e-9, "{p}: {v}");
        }
    }

    #[test]
    fn sorted_and_single_evaluation_agree_and_extend_as_asked() {
        let x = [10.0, 20.0, 35.0, 50.0];
        let y = [12.0, 19.0, 40.0, 50.0];
        let at = [0.0, 10.0, 14.0, 20.0, 27.5, 49.0, 50.0, 60.0];
        let mut out = [0.0; 8];
        eval_sorted(&x, &y, Beyond::Shift, &at, &mut out);
        for (p, v) in at.iter().zip(&out) {
            assert_eq!(*v, eval(&x, &y, Beyond::Shift, *p));
        }
        assert_eq!(out[0], 2.0); // 0 + (12 − 10)
        assert_eq!(out[7], 60.0); // frozen end: identity beyond
        assert_eq!(eval(&x, &y, Beyond::Hold, -5.0), 12.0);
    }

    #[test]
    fn pinched_knots_are_dropped() {
        let (mut x, mut y) = (vec![0.0, 2.0, 1.5, 3.0], vec![0.0, 1.0, 2.0, 3.0]);
        increasing(&mut x, &mut y);
        assert_eq!(x, vec![0.0, 2.0, 3.0]);
        assert_eq!(y, vec![0.0, 1.0, 3.0]);
    }
}
