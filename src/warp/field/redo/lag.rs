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

/// A change at each sample, `[Δ Σ w·Δx, Δ Σ w·Δy, Δ Σ w]`, component by
/// component (as the kernel writes it).
pub(super) type Change = [[f32; PADDED]; 3];

/// Share of the adaptive evaluation's check-point allowance that what the
/// redos since a block was made have left out of its pixels may take, on
/// top of the far field's own error checked then.
pub(super) const SHARE: f32 = 0.5;

/// A block's lag and where it is sampled: the samples are the block's for
/// as long as the map is (same window, same scale), so they are found once,
/// when the map is made, not at every redo.
#[derive(Debug, Clone, Default)]
pub(super) struct Tracked {
    pub lag: Lag,
    pub samples: Samples,
}

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
/// points, as canonical positions.
///
/// Bilinear interpolation errs most at the centres of a cell's edges or at
/// its centre: along an edge by `h²/8` times the second derivative along
/// it, at the centre by the sum of both (so for a term near harmonic, as a
/// far line's is, the centre alone would see almost nothing). The check
/// points are all three kinds: the cells' centres, then the centres of
/// their edges across, then those up, each row by row.
#[derive(Debug, Clone)]
pub(super) struct Samples {
    /// Positions, padded to whole lanes.
    pub xs: [f32; PADDED],
    pub ys: [f32; PADDED],
    /// Samples in all, and of them nodes.
    pub len: usize,
    nodes: usize,
    /// Nodes across and up.
    nx: usize,
    ny: usize,
    /// The block's first pixel and its last.
    first: (i32, i32),
    last: (i32, i32),
}

/// Per kind of check point: its offset from a node (pixels) and its place
/// in the cell, and whether it needs a next node across and up.
const KINDS: [((i32, i32), (f32, f32)); 3] = [
    ((SPACING / 2, SPACING / 2), (0.5, 0.5)),
    ((SPACING / 2, 0), (0.5, 0.0)),
    ((0, SPACING / 2), (0.0, 0.5)),
];

impl Default for Samples {
    fn default() -> Self {
        Samples {
            xs: [0.0; PADDED],
            ys: [0.0; PADDED],
            len: 0,
            nodes: 0,
            nx: 0,
            ny: 0,
            first: (0, 0),
            last: (0, 0),
        }
    }
}

impl Samples {
    /// The samples of `block` at `scale`.
    pub fn of(block: RectI, scale: PixelScale) -> Self {
        let (nodes, nx) = grid::node_count(block, SPACING);
        let mut s = Samples {
            xs: [0.0; PADDED],
            ys: [0.0; PADDED],
            len: 0,
            nodes,
            nx,
            ny: nodes / nx,
            first: (block.x1, block.y1),
            last: (block.x2 - 1, block.y2 - 1),
        };
        // Every sample lies on a half-spacing lattice: its coordinates,
        // once per column and row.
        let half = SPACING / 2;
        let (mut columns, mut rows) = ([0f32; 2 * NODES_ACROSS], [0f32; 2 * NODES_ACROSS]);
        for (k, c) in columns[..2 * nx].iter_mut().enumerate() {
            *c = scale.pixel_centre(block.x1 + k as i32 * half, 0).x as f32;
        }
        for (k, r) in rows[..2 * s.ny].iter_mut().enumerate() {
            *r = scale.pixel_centre(0, block.y1 + k as i32 * half).y as f32;
        }
        let mut len = 0;
        for ((a2, c2), _) in s.points() {
            (s.xs[len], s.ys[len]) = (columns[a2], rows[c2]);
            len += 1;
        }
        s.len = len;
        s
    }

    /// The pixel a sample at `(a2, c2)` on the half-spacing lattice reads
    /// its sums from (samples past the block's far edges read its last row
    /// or column).
    fn pixel(&self, (a2, c2): (usize, usize)) -> (i32, i32) {
        let half = SPACING / 2;
        let (i, j) = (
            self.first.0 + a2 as i32 * half,
            self.first.1 + c2 as i32 * half,
        );
        (i.min(self.last.0), j.min(self.last.1))
    }

    /// Each sample in order: where it lies on the half-spacing lattice
    /// (across, up), and for a check point its place in a grid cell. In
    /// order, not sample by sample: finding one sample's place on its own
    /// takes two divisions, at every sample of every block of a redo.
    fn points(&self) -> impl Iterator<Item = ((usize, usize), Option<Place>)> {
        let (nx, ny) = (self.nx, self.ny);
        let nodes = (0..ny).flat_map(move |c| (0..nx).map(move |a| ((2 * a, 2 * c), None)));
        let checks = KINDS.into_iter().flat_map(move |((di, dj), at)| {
            let (da, dc) = (usize::from(di > 0), usize::from(dj > 0));
            (0..ny - dc).flat_map(move |c| {
                (0..nx - da).map(move |a| {
                    // A point on the grid's last row or column lies on the
                    // far edge of the cell before it.
                    let cell = (a.min(nx - 2), c.min(ny - 2));
                    let at = (at.0 + (a - cell.0) as f32, at.1 + (c - cell.1) as f32);
                    ((2 * a + da, 2 * c + dc), Some((cell, at)))
                })
            })
        });
        nodes.chain(checks)
    }

    /// The check points' places, in order.
    fn checks(&self) -> impl Iterator<Item = Place> {
        self.points().filter_map(|(_, place)| place)
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
        for (seen, (at, _)) in self.seen.0[..samples.len].iter_mut().zip(samples.points()) {
            let (i, j) = samples.pixel(at);
            let (p, w) = band.at(i, j);
            *seen = [p[0], p[1], w];
        }
    }

    /// This redo's `change` at `samples` (the moved lines' change at each),
    /// added to the lag: what the pixels must take now, if the lag would
    /// grow past its share (`allowed` per axis, canonical units) when they
    /// take nothing, or always when `now`. `None`, the lag left as it was,
    /// when even taking it would leave too much owed at the check points.
    ///
    /// Checked before written, so the lag is not copied to be kept: most
    /// far blocks take nothing, at every redo.
    pub fn add(
        &mut self,
        samples: &Samples,
        change: &Change,
        allowed: [f32; 2],
        now: bool,
    ) -> Option<Take> {
        let nodes = samples.nodes;
        let checks = samples.len - nodes;
        let plus = |lag: [f32; 3], n: usize| std::array::from_fn(|m| lag[m] + change[m][n]);
        let pending = |n: usize| plus(self.due.pending[n], n);
        let owed = |k: usize| plus(self.due.owed[k], nodes + k);
        if !now
            && (0..nodes).all(|n| self.within(samples, n, pending(n), allowed))
            && (0..checks).all(|k| self.within(samples, nodes + k, owed(k), allowed))
        {
            let due = &mut self.due;
            for n in 0..nodes {
                due.pending[n] = plus(due.pending[n], n);
            }
            for k in 0..checks {
                due.owed[k] = plus(due.owed[k], nodes + k);
            }
            due.waiting = true;
            return Some(Take::Nothing);
        }
        let grid = Grid {
            nx: samples.nx,
            spacing: SPACING,
            sums: (0..nodes).map(pending).collect(),
        };
        // What the check points still owe once the pixels take the grid.
        let mut left = [[0f32; 3]; CHECKS];
        for (k, (left, (cell, at))) in left.iter_mut().zip(samples.checks()).enumerate() {
            let (owed, taken) = (owed(k), grid.at(cell, at));
            *left = std::array::from_fn(|m| owed[m] - taken[m]);
        }
        if !(0..checks).all(|k| self.within(samples, nodes + k, left[k], allowed)) {
            return None;
        }
        self.due.pending = [[0.0; 3]; NODES];
        self.due.owed[..checks].copy_from_slice(&left[..checks]);
        self.due.waiting = false;
        Some(Take::Pending(grid))
    }

    /// What the pixels must take before an exact change: the pending
    /// changes, if any, interpolated (`None` when that leaves too much
    /// owed, as in [`Lag::add`]).
    pub fn flush(&mut self, samples: &Samples, allowed: [f32; 2]) -> Option<Take> {
        if !self.due.waiting {
            return Some(Take::Nothing);
        }
        self.add(samples, &[[0.0; PADDED]; 3], allowed, true)
    }

    /// Whether leaving `lag` out of sample `n`'s pixel moves its position
    /// by no more than `allowed` per axis.
    fn within(&self, samples: &Samples, n: usize, lag: [f32; 3], allowed: [f32; 2]) -> bool {
        let [px, py, w] = self.seen.0[n];
        let w1 = w + lag[2];
        let d = [px - samples.xs[n], py - samples.ys[n]];
        (0..2).all(|axis| {
            let off = (d[axis] * w + lag[axis]) / w1 - d[axis];
            // NaNs compare false: they fail here too.
            off.abs() <= allowed[axis]
        })
    }
}
