//! The discrete plate of Lee et al. §2 on one grid: the linear system
//! `A f = b` whose solution minimises
//!
//! ```text
//! E(f) = ½ [ Σ_nodes (f_xx² + 2 f_xy² + f_yy²) h²  +  β Σ_nodes f² h²
//!            + α Σ_k (f(p_k) − z_k)² ]
//! ```
//!
//! with second differences over the nodes where their stencil fits (so the
//! edges are free, the natural boundary of a plate) and `f(p_k)` the bilinear
//! interpolant at a spring's attachment `p_k`. `A` is the gradient of `E`:
//! symmetric positive semi-definite, definite once `β > 0` or three springs
//! are not collinear. Scaled so a coarser grid's `A` is (nearly) the Galerkin
//! product of the finer one's, which is what multigrid wants.

/// A spring: the four nodes of its cell with their bilinear weights, and
/// the height it pulls toward.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spring {
    /// The four nodes of the spring's cell.
    pub nodes: [usize; 4],
    /// Their bilinear weights at the attachment.
    pub weights: [f64; 4],
    /// The height the spring pulls toward.
    pub z: f64,
}

/// A thin plate on a node grid: its bending, glue and springs.
#[derive(Debug, Clone)]
pub struct Plate {
    /// Nodes in x.
    pub nx: usize,
    /// Nodes in y.
    pub ny: usize,
    /// Node spacing (canonical px).
    pub h: f64,
    /// Spring constant `α`.
    pub alpha: f64,
    /// Glue `β`.
    pub beta: f64,
    /// Attachments (positions) of the springs; heights vary per surface.
    pub springs: Vec<Spring>,
    /// For each node, the springs pulling it (CSR: `spring_start[n]..[n+1]`).
    spring_start: Vec<usize>,
    spring_index: Vec<(u32, u8)>,
}

impl Plate {
    /// A plate of `nx × ny` nodes with springs at grid positions `(gx, gy)`
    /// (in node units: node `(i, j)` at `(i, j)`), heights zero.
    pub fn new(nx: usize, ny: usize, h: f64, alpha: f64, beta: f64, at: &[(f64, f64)]) -> Plate {
        let springs: Vec<Spring> = at
            .iter()
            .map(|&(gx, gy)| {
                let i = (gx.floor().max(0.0) as usize).min(nx - 2);
                let j = (gy.floor().max(0.0) as usize).min(ny - 2);
                let (fx, fy) = (
                    (gx - i as f64).clamp(0.0, 1.0),
                    (gy - j as f64).clamp(0.0, 1.0),
                );
                let n = j * nx + i;
                Spring {
                    nodes: [n, n + 1, n + nx, n + nx + 1],
                    weights: [
                        (1.0 - fx) * (1.0 - fy),
                        fx * (1.0 - fy),
                        (1.0 - fx) * fy,
                        fx * fy,
                    ],
                    z: 0.0,
                }
            })
            .collect();
        let mut count = vec![0usize; nx * ny + 1];
        for s in &springs {
            for &n in &s.nodes {
                count[n + 1] += 1;
            }
        }
        for n in 0..nx * ny {
            count[n + 1] += count[n];
        }
        let mut fill = count.clone();
        let mut spring_index = vec![(0u32, 0u8); count[nx * ny]];
        for (k, s) in springs.iter().enumerate() {
            for (c, &n) in s.nodes.iter().enumerate() {
                spring_index[fill[n]] = (k as u32, c as u8);
                fill[n] += 1;
            }
        }
        Plate {
            nx,
            ny,
            h,
            alpha,
            beta,
            springs,
            spring_start: count,
            spring_index,
        }
    }

    fn bend(&self) -> f64 {
        1.0 / (self.h * self.h)
    }

    /// `A[n][n]`, from the count of stencil positions that touch the node.
    pub fn diagonal_at(&self, n: usize) -> f64 {
        let (i, j) = (n % self.nx, n / self.nx);
        let second = |i: usize, n: usize| -> f64 {
            // Stencil positions i−1, i, i+1 (coefficients 1, −2, 1) that fit.
            let fits = |s: i64| s >= 1 && s <= n as i64 - 2;
            let i = i as i64;
            [(i - 1, 1.0), (i, 4.0), (i + 1, 1.0)]
                .iter()
                .filter(|(s, _)| fits(*s))
                .map(|(_, c)| c)
                .sum()
        };
        let cells = |i: usize, n: usize| (i > 0) as usize + (i + 1 < n) as usize;
        let bending = second(i, self.nx)
            + second(j, self.ny)
            + 2.0 * (cells(i, self.nx) * cells(j, self.ny)) as f64;
        let mut d = bending * self.bend() + self.beta * self.h * self.h;
        for &(k, c) in &self.spring_index[self.spring_start[n]..self.spring_start[n + 1]] {
            let w = self.springs[k as usize].weights[c as usize];
            d += self.alpha * w * w;
        }
        d
    }

    /// `b`: the springs' pull, `α Σ w z`, with the springs' own heights.
    pub fn rhs(&self) -> Vec<f64> {
        let z: Vec<f64> = self.springs.iter().map(|s| s.z).collect();
        self.rhs_for(&z)
    }

    /// `b` for heights `z` (one per spring): one plate serves both surfaces.
    pub fn rhs_for(&self, z: &[f64]) -> Vec<f64> {
        let mut b = vec![0.0; self.nx * self.ny];
        for (s, z) in self.springs.iter().zip(z) {
            for c in 0..4 {
                b[s.nodes[c]] += self.alpha * s.weights[c] * z;
            }
        }
        b
    }

    /// `(A f)` at node `n`.
    #[inline]
    pub fn apply_at(&self, f: &[f64], n: usize) -> f64 {
        let (nx, ny) = (self.nx, self.ny);
        let (i, j) = (n % nx, n / nx);
        let bending = if i >= 2 && j >= 2 && i + 2 < nx && j + 2 < ny {
            // Interior: the 13-point biharmonic stencil.
            20.0 * f[n] - 8.0 * (f[n - 1] + f[n + 1] + f[n - nx] + f[n + nx])
                + 2.0 * (f[n - nx - 1] + f[n - nx + 1] + f[n + nx - 1] + f[n + nx + 1])
                + f[n - 2]
                + f[n + 2]
                + f[n - 2 * nx]
                + f[n + 2 * nx]
        } else {
            self.bending_near_edge(f, i, j)
        };
        let mut v = bending * self.bend() + self.beta * self.h * self.h * f[n];
        for &(k, c) in &self.spring_index[self.spring_start[n]..self.spring_start[n + 1]] {
            let s = &self.springs[k as usize];
            let at: f64 = (0..4).map(|m| s.weights[m] * f[s.nodes[m]]).sum();
            v += self.alpha * s.weights[c as usize] * at;
        }
        v
    }

    /// `(Dᵀ D f)` at `(i, j)` for the second differences that fit, written as
    /// the sum over the stencil positions that touch the node.
    fn bending_near_edge(&self, f: &[f64], i: usize, j: usize) -> f64 {
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        let (i, j) = (i as i64, j as i64);
        let at = |x: i64, y: i64| f[(y * nx + x) as usize];
        let mut v = 0.0;
        for (s, c) in [(i - 1, 1.0), (i, -2.0), (i + 1, 1.0)] {
            if s >= 1 && s <= nx - 2 {
                v += c * (at(s - 1, j) - 2.0 * at(s, j) + at(s + 1, j));
            }
        }
        for (s, c) in [(j - 1, 1.0), (j, -2.0), (j + 1, 1.0)] {
            if s >= 1 && s <= ny - 2 {
                v += c * (at(i, s - 1) - 2.0 * at(i, s) + at(i, s + 1));
            }
        }
        // Cells (cx, cy) with the node at corner (i − cx, j − cy) ∈ {0, 1}².
        for (cx, cy, c) in [
            (i - 1, j - 1, 1.0),
            (i - 1, j, -1.0),
            (i, j - 1, -1.0),
            (i, j, 1.0),
        ] {
            if cx >= 0 && cy >= 0 && cx <= nx - 2 && cy <= ny - 2 {
                let d = at(cx + 1, cy + 1) - at(cx + 1, cy) - at(cx, cy + 1) + at(cx, cy);
                v += 2.0 * c * d;
            }
        }
        v
    }
}
