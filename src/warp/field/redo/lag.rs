//! What a redo has not written into a block's pixels yet.
//!
//! Far from a block, a moved line's change varies as slowly as the far
//! lines of the adaptive evaluation do, so it is known from the block's
//! grid nodes. A redo adds it there and at the check points; the pixels
//! take it (interpolated from the nodes) only once leaving it out would
//! move some node or check point by more than the share of the tolerance
//! that redos may use. A one-pixel nudge of one line among many then
//! touches the pixels near it and nothing else.

use super::super::grid::{self, Grid};
use super::super::split::{Band, BLOCK};
use crate::geom::{PixelScale, RectI};

/// Spacing of the grid a far change is known on, pixels. Its cells are
/// as wide as a quarter of [`NEAR`](super::super::split::NEAR) at most
/// (relative curvature of a far term over one: `0.75·(8/128)² ≈ 3e-3`),
/// and the pixels take a change only once it is about the share
/// allowed, so what interpolating it misses is a small part of that.
pub(super) const SPACING: i32 = 8;
/// Grid nodes of a whole block, across or up.
const NODES_ACROSS: usize = (BLOCK / SPACING) as usize + 1;
/// Grid nodes of a whole block.
const NODES: usize = NODES_ACROSS * NODES_ACROSS;
/// Cells of a whole block, across.
const CELLS_ACROSS: usize = NODES_ACROSS - 1;
/// Check points of a whole block: the centres of the grid's cells and of
/// their edges (see [`Samples::of`]).
const CHECKS: usize = CELLS_ACROSS * CELLS_ACROSS + 2 * CELLS_ACROSS * NODES_ACROSS;
/// Samples of a whole block: its nodes, then its check points.
const SAMPLES: usize = NODES + CHECKS;
/// Room for the samples in whole SIMD lanes.
pub(super) const PADDED: usize = SAMPLES.div_ceil(8) * 8;

/// Share of the adaptive evaluation's check-point allowance that what the
/// redos since a block was made have left out of its pixels may take, on
/// top of the far field's own error checked then.
pub(super) const SHARE: f32 = 0.5;

/// One block's lag.
#[derive(Debug, Clone, Default)]
pub(super) struct Lag {
    due: Due,
    /// What the block's pixels hold at each sample (position, `Σ w`), as
    /// they were last written: read while they are in cache, not from a
    /// map far larger than it at every redo.
    seen: Seen,
}

/// What a block's pixels have not taken.
#[derive(Debug, Clone, Copy)]
struct Due {
    /// At each grid node: the moved lines' changes `[Δ Σ w·Δx, Δ Σ w·Δy,
    /// Δ Σ w]` summed over the redos since the pixels last took them.
    pending: [[f32; 3]; NODES],
    /// Whether `pending` holds anything.
    waiting: bool,
    /// At each check point: the exact changes since the block was made
    /// less what its pixels took (interpolation is linear, so this is the
    /// error of everything interpolated or left out since then).
    owed: [[f32; 3]; CHECKS],
}

impl Default for Due {
    fn default() -> Self {
        Due {
            pending: [[0.0; 3]; NODES],
            waiting: false,
            owed: [[0.0; 3]; CHECKS],
        }
    }
}

#[derive(Debug, Clone)]
struct Seen([[f32; 3]; SAMPLES]);

impl Default for Seen {
    fn default() -> Self {
        Seen([[0.0; 3]; SAMPLES])
    }
}

/// Where a check point lies: the grid cell (its lower-left node, across
/// and up) and the place in it (fractions of a cell across and up).
type Place = ((usize, usize), (f32, f32));

/// Where a block's changes are sampled: its grid nodes then its check
/// points, as canonical positions and the pixels whose sums they read.
pub(super) struct Samples {
    /// Positions, padded to whole lanes.
    pub xs: [f32; PADDED],
    pub ys: [f32; PADDED],
    /// Samples in all, and of them nodes.
    pub len: usize,
    nodes: usize,
    /// Nodes across.
    nx: usize,
    /// The pixel each sample reads (nodes past the block's far edges read
    /// its last row or column).
    pixels: [(i32, i32); SAMPLES],
    /// Per check point: the cell it lies in (its lower-left node) and
    /// where in it (fractions across and up).
    checks: [Place; CHECKS],
}

impl Samples {
    /// The samples of `block` at `scale`. Bilinear interpolation errs most
    /// at the centres of a cell's edges or at its centre: along an edge by
    /// `h²/8` times the second derivative along it, at the centre by the
    /// sum of both (so for a term near harmonic, as a far line's is, the
    /// centre alone would see almost nothing).
    pub fn of(block: RectI, scale: PixelScale) -> Self {
        let (nodes, nx) = grid::node_count(block, SPACING);
        let ny = nodes / nx;
        let mut s = Samples {
            xs: [0.0; PADDED],
            ys: [0.0; PADDED],
            len: 0,
            nodes,
            nx,
            pixels: [(0, 0); SAMPLES],
            checks: [((0, 0), (0.0, 0.0)); CHECKS],
        };
        let last = (block.x2 - 1, block.y2 - 1);
        let push = |s: &mut Samples, (i, j): (i32, i32)| {
            let (n, c) = (s.len, scale.pixel_centre(i, j));
            (s.xs[n], s.ys[n]) = (c.x as f32, c.y as f32);
            s.pixels[n] = (i.min(last.0), j.min(last.1));
            s.len += 1;
        };
        for n in 0..nodes {
            push(&mut s, grid::node_pixel(block, n, nx, SPACING));
        }
        let half = SPACING / 2;
        let kinds = [
            ((half, half), (0.5, 0.5)),
            ((half, 0), (0.5, 0.0)),
            ((0, half), (0.0, 0.5)),
        ];
        let mut k = 0;
        for ((di, dj), at) in kinds {
            let (across, up) = (nx - usize::from(di > 0), ny - usize::from(dj > 0));
            for c in 0..up {
                for a in 0..across {
                    let (i, j) = grid::node_pixel(block, c * nx + a, nx, SPACING);
                    push(&mut s, (i + di, j + dj));
                    // A point on the grid's last row or column lies on the
                    // far edge of the cell before it.
                    let cell = (a.min(nx - 2), c.min(ny - 2));
                    let at = (at.0 + (a - cell.0) as f32, at.1 + (c - cell.1) as f32);
                    s.checks[k] = (cell, at);
                    k += 1;
                }
            }
        }
        s
    }

    /// The check points' cells and places in them, in order.
    fn checks(&self) -> &[Place] {
        &self.checks[..self.len - self.nodes]
    }
}

/// What a block's pixels must take in this redo.
pub(super) enum Take {
    /// Nothing: the lag stays within its share.
    Nothing,
    /// The pending changes, interpolated from the nodes.
    Pending(Grid<3>),
}

impl Lag {
    /// Notes what the block's pixels in `band` hold at `samples`, after
    /// they were written.
    pub fn look(&mut self, band: &Band, samples: &Samples) {
        for (seen, &(i, j)) in self.seen.0.iter_mut().zip(&samples.pixels[..samples.len]) {
            let (p, w) = band.at(i, j);
            *seen = [p[0], p[1], w];
        }
    }

    /// This redo's `change` at `samples` (the moved lines' change at each),
    /// added to the lag: what the pixels must take now, if the lag would
    /// grow past its share (`allowed` per axis, canonical units) when they
    /// take nothing, or always when `now`. `None`, the lag left as it was,
    /// when even taking it would leave too much owed at the check points.
    pub fn add(
        &mut self,
        samples: &Samples,
        change: &[[f32; 3]],
        allowed: [f32; 2],
        now: bool,
    ) -> Option<Take> {
        let mut due = self.due;
        let (nodes, checks) = change[..samples.len].split_at(samples.nodes);
        for (p, c) in due.pending.iter_mut().zip(nodes) {
            for m in 0..3 {
                p[m] += c[m];
            }
        }
        due.waiting = true;
        for (owed, c) in due.owed.iter_mut().zip(checks) {
            for m in 0..3 {
                owed[m] += c[m];
            }
        }
        if !now && self.within(&due, samples, allowed, true) {
            self.due = due;
            return Some(Take::Nothing);
        }
        let grid = Grid {
            nx: samples.nx,
            spacing: SPACING,
            sums: due.pending[..samples.nodes].to_vec(),
        };
        for (owed, &(cell, at)) in due.owed.iter_mut().zip(samples.checks()) {
            let taken = grid.at(cell, at);
            for m in 0..3 {
                owed[m] -= taken[m];
            }
        }
        due.pending = [[0.0; 3]; NODES];
        due.waiting = false;
        if !self.within(&due, samples, allowed, false) {
            return None;
        }
        self.due = due;
        Some(Take::Pending(grid))
    }

    /// What the pixels must take before an exact change: the pending
    /// changes, if any, interpolated (`None` when that leaves too much
    /// owed, as in [`Lag::add`]).
    pub fn flush(&mut self, samples: &Samples, allowed: [f32; 2]) -> Option<Take> {
        if !self.due.waiting {
            return Some(Take::Nothing);
        }
        self.add(samples, &[[0.0; 3]; SAMPLES], allowed, true)
    }

    /// Whether leaving out what `due` owes at the check points and, with
    /// `at_nodes`, what is pending at the nodes, moves no sample's position
    /// by more than `allowed`.
    fn within(&self, due: &Due, samples: &Samples, allowed: [f32; 2], at_nodes: bool) -> bool {
        let off = |n: usize, lag: [f32; 3]| {
            let [px, py, w] = self.seen.0[n];
            let w1 = w + lag[2];
            let d = [px - samples.xs[n], py - samples.ys[n]];
            (0..2).all(|axis| {
                let off = (d[axis] * w + lag[axis]) / w1 - d[axis];
                // NaNs compare false: they fail here too.
                off.abs() <= allowed[axis]
            })
        };
        let nodes_ok = !at_nodes || (0..samples.nodes).all(|n| off(n, due.pending[n]));
        let checks = samples.len - samples.nodes;
        nodes_ok && (0..checks).all(|k| off(samples.nodes + k, due.owed[k]))
    }
}
