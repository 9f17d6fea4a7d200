use super::{basis, basis_derivative};
use crate::geom::{PixelScale, RectI, Vec2};

/// A scalar function `f(x, y) = Σ_k Σ_l B_k(s) B_l(t) φ[c+k−1][r+l−1]` on a
/// uniform lattice: control `(i, j)` sits at `origin + (i h, j h)`; a point in
/// cell `(c, r)` (`c = ⌊(x − origin.x)/h⌋`) reads controls `c−1..=c+2`.
/// Controls outside the stored array are zero, so the function is C² on the
/// whole plane and vanishes far from the lattice: a deformation made of such
/// lattices is the identity away from its features and never tears at the
/// lattice's edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Lattice {
    /// Canonical position of control `(0, 0)`.
    pub origin: Vec2,
    /// Control spacing (canonical px).
    pub h: f64,
    /// Controls stored in x.
    pub nx: usize,
    /// Controls stored in y.
    pub ny: usize,
    /// Row-major, `j * nx + i`.
    pub phi: Vec<f64>,
}

impl Lattice {
    /// A lattice of `nx × ny` zero controls: the zero function.
    pub fn zero(origin: Vec2, h: f64, nx: usize, ny: usize) -> Self {
        Lattice {
            origin,
            h,
            nx,
            ny,
            phi: vec![0.0; nx * ny],
        }
    }

    /// The coarsest lattice whose cells (spacing `h`) cover `[min, max]` with
    /// every control a point there can read.
    pub fn covering(min: Vec2, max: Vec2, h: f64) -> Self {
        let cells = |a: f64, b: f64| ((b - a) / h).floor().max(0.0) as usize + 1;
        let origin = Vec2::new(min.x - h, min.y - h);
        Lattice::zero(origin, h, cells(min.x, max.x) + 3, cells(min.y, max.y) + 3)
    }

    /// Control `(i, j)`; zero outside the stored array.
    #[inline]
    pub fn get(&self, i: i64, j: i64) -> f64 {
        if i < 0 || j < 0 || i >= self.nx as i64 || j >= self.ny as i64 {
            0.0
        } else {
            self.phi[j as usize * self.nx + i as usize]
        }
    }

    /// The cell of `p` (first control read is `cell − 1`) and the local
    /// parameters `(s, t)`.
    #[inline]
    pub fn locate(&self, p: Vec2) -> (i64, i64, f64, f64) {
        let u = (p.x - self.origin.x) / self.h;
        let v = (p.y - self.origin.y) / self.h;
        let (c, r) = (u.floor(), v.floor());
        (c as i64, r as i64, u - c, v - r)
    }

    /// Whether every control `p` reads is stored (its weights can be set).
    pub fn reaches(&self, p: Vec2) -> bool {
        let (c, r, _, _) = self.locate(p);
        c >= 1 && r >= 1 && c + 2 < self.nx as i64 && r + 2 < self.ny as i64
    }

    /// The cubic B-spline function at `p` (canonical).
    pub fn eval(&self, p: Vec2) -> f64 {
        let (c, r, s, t) = self.locate(p);
        let (bs, bt) = (basis(s), basis(t));
        let mut sum = 0.0;
        for (l, wt) in bt.iter().enumerate() {
            let mut row = 0.0;
            for (k, ws) in bs.iter().enumerate() {
                row += ws * self.get(c - 1 + k as i64, r - 1 + l as i64);
            }
            sum += wt * row;
        }
        sum
    }

    /// `(∂f/∂x, ∂f/∂y)` at `p`.
    pub fn gradient(&self, p: Vec2) -> Vec2 {
        let (c, r, s, t) = self.locate(p);
        let (bs, bt) = (basis(s), basis(t));
        let (ds, dt) = (basis_derivative(s), basis_derivative(t));
        let (mut gx, mut gy) = (0.0, 0.0);
        for l in 0..4 {
            for k in 0..4 {
                let phi = self.get(c - 1 + k as i64, r - 1 + l as i64);
                gx += ds[k] * bt[l] * phi;
                gy += bs[k] * dt[l] * phi;
            }
        }
        Vec2::new(gx / self.h, gy / self.h)
    }

    /// Whether every control is zero (the function is 0 everywhere).
    pub fn is_zero(&self) -> bool {
        self.phi.iter().all(|&v| v == 0.0)
    }

    /// The same function on a lattice of half the spacing (B-spline
    /// subdivision, exact): lets a multilevel sum collapse into its finest
    /// lattice, so evaluation costs one lattice however many levels there were.
    /// The finer lattice's origin is `origin − h`, so coarse control `i` is
    /// fine control `2i + 2`.
    pub fn refined(&self) -> Lattice {
        let (nx, ny) = (2 * self.nx + 3, 2 * self.ny + 3);
        // Rows first (x), then columns (y): the tensor product of 1-D rules.
        let mut wide = vec![0.0; nx * self.ny];
        for j in 0..self.ny {
            for (fi, out) in wide[j * nx..(j + 1) * nx].iter_mut().enumerate() {
                *out = subdivide(fi, |i| self.get(i, j as i64));
            }
        }
        let get_wide = |i: usize, j: i64| {
            if j < 0 || j >= self.ny as i64 {
                0.0
            } else {
                wide[j as usize * nx + i]
            }
        };
        let mut phi = vec![0.0; nx * ny];
        for fj in 0..ny {
            for i in 0..nx {
                phi[fj * nx + i] = subdivide(fj, |j| get_wide(i, j));
            }
        }
        Lattice {
            origin: Vec2::new(self.origin.x - self.h, self.origin.y - self.h),
            h: self.h / 2.0,
            nx,
            ny,
            phi,
        }
    }

    /// `self += other` where `other` has the same geometry.
    pub fn add(&mut self, other: &Lattice) {
        debug_assert!(self.nx == other.nx && self.ny == other.ny && self.h == other.h);
        for (a, b) in self.phi.iter_mut().zip(&other.phi) {
            *a += b;
        }
    }

    /// The function at the centres of the pixels of `window` (pixels at
    /// `scale`), rows bottom-up. Separable: the x weights of each column and
    /// the y weights of each row are computed once.
    pub fn eval_window(&self, window: RectI, scale: PixelScale) -> Vec<f32> {
        use rayon::prelude::*;
        let w = window.width();
        let columns: Vec<(i64, [f64; 4])> = (0..w)
            .map(|k| {
                let p = scale.pixel_centre(window.x1 + k as i32, window.y1);
                let (c, _, s, _) = self.locate(p);
                (c, basis(s))
            })
            .collect();
        let mut out = vec![0f32; window.area()];
        if w == 0 {
            return out;
        }
        out.par_chunks_mut(w).enumerate().for_each_init(
            || vec![0f64; self.nx],
            |mixed, (row, out)| {
                let p = scale.pixel_centre(window.x1, window.y1 + row as i32);
                let (_, r, _, t) = self.locate(p);
                let bt = basis(t);
                // The four lattice rows mixed by the y weights, once per row.
                for (i, m) in mixed.iter_mut().enumerate() {
                    *m = (0..4)
                        .map(|l| bt[l] * self.get(i as i64, r - 1 + l as i64))
                        .sum();
                }
                let at = |i: i64| {
                    if i < 0 || i >= self.nx as i64 {
                        0.0
                    } else {
                        mixed[i as usize]
                    }
                };
                for (o, (c, bs)) in out.iter_mut().zip(&columns) {
                    let v: f64 = (0..4).map(|k| bs[k] * at(c - 1 + k as i64)).sum();
                    *o = v as f32;
                }
            },
        );
        out
    }
}

/// Fine control `fi` of a 1-D cubic B-spline subdivided once, from the coarse
/// controls `c(i)` (coarse `i` is fine `2i + 2`): vertex points
/// `(c[i−1] + 6c[i] + c[i+1]) / 8`, edge points `(c[i] + c[i+1]) / 2`.
fn subdivide(fi: usize, c: impl Fn(i64) -> f64) -> f64 {
    let f = fi as i64 - 2;
    if f.rem_euclid(2) == 0 {
        let i = f.div_euclid(2);
        (c(i - 1) + 6.0 * c(i) + c(i + 1)) / 8.0
    } else {
        let i = f.div_euclid(2);
        (c(i) + c(i + 1)) / 2.0
    }
}
