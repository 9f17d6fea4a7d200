//! Multilevel free-form deformation (Lee, Wolberg et al. §5): one-to-one warps from
//! scattered point pairs.
//!
//! Each step is a cubic B-spline FFD whose control displacements come from the
//! least-squares rule (eq. 4–5) and are truncated to `0.48 h` per coordinate,
//! which by Theorem 1 makes the step one-to-one with a positive Jacobian. The
//! warp is the composition of the steps, so it is one-to-one whatever the
//! constraints ask (swapped or crossing points end as close as folding-free
//! allows, seed Fig. 14). Steps start on a coarse lattice and move to the next
//! finer one when a step gains less than `α (0.48 h)²` in squared error (§5.4).

use super::node_grid::NodeGrid;
use super::Warp;
use crate::bspline::{basis, Approximation, Lattice};
use crate::geom::{PixelScale, RectD, RectI, Vec2};
use crate::image::WarpMap;
use wide::f64x4;

/// Theorem 1's bound on a control displacement, in lattice spacings.
pub const ONE_TO_ONE_BOUND: f64 = 0.48;

/// Multilevel free-form deformation settings (scene key `mffd`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MffdSettings {
    /// Cells of the coarsest lattice across the longer side of the frame
    /// (seed: a 5 × 5 lattice, two cells).
    pub coarsest: usize,
    /// `α` of §5.4: a step that gains less than `α (0.48 h)²` moves to the
    /// next finer lattice. Small values favour coarse, smooth deformation.
    pub alpha: f64,
    /// Stop once every constraint is within this distance (canonical px).
    pub tolerance: f64,
    /// The finest lattice spacing (canonical px).
    pub finest: f64,
    /// Spacing (output pixels) of the nodes where the composition is
    /// evaluated exactly for a dense map; bilinear between them.
    pub grid: f64,
    /// Theorem 1's truncation. Off only to show what it prevents.
    pub truncate: bool,
}

impl Default for MffdSettings {
    fn default() -> Self {
        MffdSettings {
            coarsest: 2,
            alpha: 0.5,
            tolerance: 0.01,
            finest: 1.0,
            grid: 2.0,
            truncate: true,
        }
    }
}

/// Most steps one solve takes (foldover-prone constraints may never meet
/// the tolerance; each step is then still one-to-one).
const MAX_STEPS: usize = 96;

/// One FFD: `p ↦ p + (dx(p), dy(p))`.
#[derive(Debug, Clone, PartialEq)]
pub struct Deformation {
    /// Displacement in x.
    pub dx: Lattice,
    /// Displacement in y.
    pub dy: Lattice,
    /// The layout [`Deformation::apply`] reads; `None` when `dx` and `dy`
    /// differ in geometry (then both lattices are evaluated separately).
    packed: Option<Packed>,
}

/// Both lattices' controls interleaved and padded with `PAD` zeros on every
/// side, so a point in any cell a control reaches reads its 16 `(dx, dy)`
/// pairs without bounds checks and with one set of basis weights. Cells whose
/// 16 controls are all zero are marked, so the rest of the plane costs one
/// lookup: a fine lattice's step touches only the pixels near its features.
#[derive(Debug, Clone, PartialEq)]
struct Packed {
    controls: Vec<f64>,
    /// Controls per row of `controls` (two values each): `nx + 2 PAD`.
    stride: usize,
    /// Per cell `c ∈ −2..=nx` (stored at `c + 2`): whether any control it
    /// reads is non-zero. Row length `nx + 3` (`stride − PAD`).
    active: Vec<bool>,
    /// Stored cells per row and column (`nx + 3`, `ny + 3`).
    cells: (f64, f64),
    origin: Vec2,
    inverse_h: f64,
}

/// Zeros around the stored controls: cell `−2` reads control `−3`.
const PAD: usize = 3;

impl Packed {
    fn new(dx: &Lattice, dy: &Lattice) -> Packed {
        let (nx, ny) = (dx.nx, dx.ny);
        let stride = nx + 2 * PAD;
        let mut controls = vec![0.0; 2 * stride * (ny + 2 * PAD)];
        let (cx, cy) = (nx + 3, ny + 3);
        let mut active = vec![false; cx * cy];
        for j in 0..ny {
            for i in 0..nx {
                let k = j * nx + i;
                let at = 2 * ((j + PAD) * stride + i + PAD);
                controls[at] = dx.phi[k];
                controls[at + 1] = dy.phi[k];
                if dx.phi[k] != 0.0 || dy.phi[k] != 0.0 {
                    // Control i is read by cells i−2 ..= i+1, stored at +2.
                    for row in active[j * cx..(j + 4) * cx].chunks_mut(cx) {
                        row[i..i + 4].fill(true);
                    }
                }
            }
        }
        Packed {
            controls,
            stride,
            active,
            cells: (cx as f64, cy as f64),
            origin: dx.origin,
            inverse_h: 1.0 / dx.h,
        }
    }
}

impl Deformation {
    /// The deformation by `dx` and `dy`.
    pub fn new(dx: Lattice, dy: Lattice) -> Self {
        let same = (dx.origin, dx.h, dx.nx, dx.ny) == (dy.origin, dy.h, dy.nx, dy.ny);
        let packed = same.then(|| Packed::new(&dx, &dy));
        Deformation { dx, dy, packed }
    }

    /// `p` moved by the deformation.
    #[inline]
    pub fn apply(&self, p: Vec2) -> Vec2 {
        let Some(packed) = &self.packed else {
            return p + Vec2::new(self.dx.eval(p), self.dy.eval(p));
        };
        // Lattice coordinates shifted by 2, so the stored cell is the integer
        // part (cells −2 ..= nx are stored; beyond them the step is identity).
        let u = (p.x - packed.origin.x) * packed.inverse_h + 2.0;
        let v = (p.y - packed.origin.y) * packed.inverse_h + 2.0;
        if !(u >= 0.0 && v >= 0.0 && u < packed.cells.0 && v < packed.cells.1) {
            return p;
        }
        let (c, r) = (u as usize, v as usize);
        let (s, t) = (u - c as f64, v - r as f64);
        if !packed.active[r * (packed.stride - PAD) + c] {
            return p;
        }
        // Cell c reads controls c−1 ..= c+2, stored from c on (PAD = 3).
        // A row of 4 (dx, dy) pairs is two 4-lane vectors: the rows are mixed
        // by the y weights, then the columns by the x weights.
        let (bs, bt) = (basis(s), basis(t));
        let (mut lo, mut hi) = (f64x4::ZERO, f64x4::ZERO);
        for (l, &wt) in bt.iter().enumerate() {
            let start = 2 * ((r + l) * packed.stride + c);
            let row: &[f64; 8] = packed.controls[start..start + 8].try_into().unwrap();
            let wt = f64x4::splat(wt);
            lo = f64x4::from([row[0], row[1], row[2], row[3]]).mul_add(wt, lo);
            hi = f64x4::from([row[4], row[5], row[6], row[7]]).mul_add(wt, hi);
        }
        let sum = (lo * f64x4::from([bs[0], bs[0], bs[1], bs[1]])
            + hi * f64x4::from([bs[2], bs[2], bs[3], bs[3]]))
        .to_array();
        p + Vec2::new(sum[0] + sum[2], sum[1] + sum[3])
    }

    /// The Jacobian `[[∂x/∂u, ∂x/∂v], [∂y/∂u, ∂y/∂v]]` at `p`.
    pub fn jacobian(&self, p: Vec2) -> [[f64; 2]; 2] {
        let (gx, gy) = (self.dx.gradient(p), self.dy.gradient(p));
        [[1.0 + gx.x, gx.y], [gy.x, 1.0 + gy.y]]
    }

    /// The largest control displacement in lattice spacings (`|Δφ|∞ / h`).
    pub fn largest_step(&self) -> f64 {
        let m = self
            .dx
            .phi
            .iter()
            .chain(&self.dy.phi)
            .fold(0.0f64, |m, v| m.max(v.abs()));
        m / self.dx.h
    }
}

/// A solved MFFD: its steps (applied first to last) and what it reached.
#[derive(Debug, Clone, PartialEq)]
pub struct Mffd {
    /// The deformations, applied first to last.
    pub steps: Vec<Deformation>,
    /// Largest distance from a constraint's target after the last step.
    pub error: f64,
    grid: f64,
}

impl Mffd {
    /// Moves every `from` onto its `to` (`pairs`), over `frame`.
    pub fn solve(pairs: &[(Vec2, Vec2)], frame: RectD, s: &MffdSettings) -> Mffd {
        let extent = frame.width().max(frame.height()).max(1.0);
        Mffd::solve_from(
            Vec::new(),
            pairs,
            frame,
            extent / s.coarsest.max(1) as f64,
            s,
        )
    }

    /// As [`Mffd::solve`], after the deformations `first` (hybrid: the thin
    /// plate's warp) and starting on lattices of spacing `h0`.
    pub fn solve_from(
        first: Vec<Deformation>,
        pairs: &[(Vec2, Vec2)],
        frame: RectD,
        h0: f64,
        s: &MffdSettings,
    ) -> Mffd {
        let targets: Vec<Vec2> = pairs.iter().map(|(_, q)| *q).collect();
        let mut at: Vec<Vec2> = pairs
            .iter()
            .map(|(p, _)| first.iter().fold(*p, |p, d| d.apply(p)))
            .collect();
        let sq_error = |at: &[Vec2]| {
            at.iter()
                .zip(&targets)
                .fold(0.0f64, |m, (p, q)| m.max((*q - *p).length_squared()))
        };
        let mut steps = first;
        let mut h = h0.max(s.finest);
        let mut error = sq_error(&at);
        let tolerance = s.tolerance * s.tolerance;
        while error > tolerance && steps.len() < MAX_STEPS {
            let step = ffd_step(&at, &targets, frame, h, s.truncate);
            for p in at.iter_mut() {
                *p = step.apply(*p);
            }
            steps.push(step);
            let old = error;
            error = sq_error(&at);
            let gain = old - error;
            let bound = ONE_TO_ONE_BOUND * h;
            if gain < s.alpha * bound * bound {
                if h / 2.0 >= s.finest {
                    h /= 2.0;
                } else if gain <= 1e-6 * old {
                    break; // finest lattice and no progress: as close as one-to-one allows
                }
            }
        }
        Mffd {
            steps,
            error: error.sqrt(),
            grid: s.grid,
        }
    }

    /// The composed warp at `p`, exactly.
    pub fn apply(&self, p: Vec2) -> Vec2 {
        self.steps.iter().fold(p, |p, d| d.apply(p))
    }

    /// The composed warp at every point of `points`, in place: step by step
    /// over all of them, so the evaluations of one step are independent and
    /// overlap in the CPU, and each step's controls stay in cache.
    pub fn apply_all(&self, points: &mut [Vec2]) {
        for d in &self.steps {
            for p in points.iter_mut() {
                *p = d.apply(*p);
            }
        }
    }

    /// The Jacobian determinant of the composition at `p` (chain rule).
    pub fn jacobian_det(&self, p: Vec2) -> f64 {
        let mut det = 1.0;
        let mut q = p;
        for d in &self.steps {
            let j = d.jacobian(q);
            det *= j[0][0] * j[1][1] - j[0][1] * j[1][0];
            q = d.apply(q);
        }
        det
    }
}

/// One FFD manipulation (Lee, Wolberg et al. §5.3's algorithm) on a lattice of spacing `h`
/// that covers the frame and every point.
fn ffd_step(at: &[Vec2], targets: &[Vec2], frame: RectD, h: f64, truncate: bool) -> Deformation {
    let area = frame.including(at.iter().chain(targets).copied());
    let lattice = Lattice::covering(Vec2::new(area.x1, area.y1), Vec2::new(area.x2, area.y2), h);
    let mut fit = Approximation::new(&lattice);
    for (p, q) in at.iter().zip(targets) {
        fit.add(*p, *q - *p);
    }
    let (dx, dy) = fit.finish(truncate.then_some(ONE_TO_ONE_BOUND * h));
    Deformation::new(dx, dy)
}

/// The reverse map of an MFFD. Pointwise it is the exact composition; a
/// dense map composes exactly at nodes `grid` output pixels apart and is
/// bilinear between them.
#[derive(Debug, Clone)]
pub struct MffdWarp {
    /// The solved deformation.
    pub mffd: Mffd,
}

impl Warp for MffdWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        self.mffd.apply(p)
    }

    fn is_identity(&self) -> bool {
        self.mffd.steps.is_empty()
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.is_identity() {
            return WarpMap::identity(window, scale);
        }
        // Nodes on a lattice fixed in the image (every `grid` pixels from
        // pixel 0), not started at the window: a tile then gets exactly the
        // pixels the whole frame has there (hosts render in tiles).
        let grid = self.mffd.grid.max(1.0);
        let snap = |p: i32| (p as f64 / grid).floor() * grid;
        let lo = Vec2::new(
            (snap(window.x1) + 0.5) / scale.x,
            (snap(window.y1) + 0.5) / scale.y,
        );
        let hi = scale.pixel_centre(window.x2 - 1, window.y2 - 1);
        let unit = scale.pixel_centre(1, 1) - scale.pixel_centre(0, 0);
        let mut nodes = NodeGrid::covering(lo, hi, unit * grid);
        nodes.fill_rows(|row| self.mffd.apply_all(row));
        nodes.map_window(window, scale)
    }
}
