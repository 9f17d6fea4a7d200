//! Galerkin coarse levels: node classes whose rows are alike, springs
//! restricted to the coarse grid, and the B-spline subdivision weights.

use wide::f64x4;

/// Nodes whose operator rows can differ only by how near they are to the
/// edges: on each axis, the `margin` nodes at either end are classes of
/// their own and the rest one interior class (every node its own class on
/// an axis too short for that).
#[derive(Debug, Clone, Copy)]
pub(super) struct Classes {
    pub(super) nx: usize,
    pub(super) ny: usize,
    pub(super) margin: usize,
}

impl Classes {
    pub(super) fn new(nx: usize, ny: usize, margin: usize) -> Classes {
        Classes { nx, ny, margin }
    }

    pub(super) fn count(&self, n: usize) -> usize {
        let m = self.margin;
        if n < 2 * m + 1 {
            n
        } else {
            2 * m + 1
        }
    }

    /// Class of node `i` of `n`: `0..m` from the low end, `m` inside,
    /// `m + 1..=2m` toward the high end.
    pub(super) fn of(&self, i: usize, n: usize) -> usize {
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
    pub(super) fn representative(&self, c: usize, n: usize) -> usize {
        let m = self.margin;
        if n < 2 * m + 1 || c <= m {
            c
        } else {
            n + c - 2 * m - 1
        }
    }
}

/// `Pᵀ u` for a spring's weights `u` on a fine grid `nx` wide, onto the
/// `cx × cy` coarse grid.
pub(super) fn restrict_spring(
    u: &[(usize, f64)],
    nx: usize,
    cx: usize,
    cy: usize,
) -> Vec<(usize, f64)> {
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
pub(super) fn window_sum<const S: usize>(
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
pub(super) fn parents(x: usize, cn: usize) -> impl Iterator<Item = (usize, f64)> {
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
pub(super) fn children(c: usize, n: usize) -> impl Iterator<Item = (usize, f64)> {
    let cn = (n - 1) / 2 + 1;
    ((2 * c).saturating_sub(2)..=(2 * c + 2).min(n - 1)).flat_map(move |x| {
        parents(x, cn)
            .filter(move |(p, _)| *p == c)
            .map(move |(_, w)| (x, w))
    })
}
