//! What a redo has not written into a block's pixels yet.
//!
//! Far from a block, a moved line's change varies as slowly as the far
//! lines of the adaptive evaluation do, so it is known from the block's
//! grid nodes. A redo adds it there and at the check points; the pixels
//! take it (interpolated from the nodes) only once leaving it out would
//! move some node or check point by more than the share of the tolerance
//! that redos may use. A one-pixel nudge of one line among many then
//! touches the pixels near it and nothing else.

use std::ops::Range;

use super::super::grid::{self, Grid};
use super::super::split::{Band, BLOCK};
use crate::geom::{PixelScale, RectI};

/// Spacing of the grid a far change is known on, pixels. Its cells are
/// an eighth of [`NEAR`](super::super::split::NEAR) wide (relative
/// curvature of a far term over one: `0.75·(16/128)² ≈ 0.012`), and the
/// check points at their centres and their edges' centres find what
/// interpolating it misses, so a block takes the change once
/// that would be too much. A third of the samples of an 8 px grid: the
/// lags are most of what a redo reads for the blocks it leaves alone.
pub(super) const SPACING: i32 = 16;
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

/// A value per sample, component by component and padded to whole lanes,
/// so the loops over a block's samples vectorise.
pub(super) type PerSample = [[f32; PADDED]; 3];

/// A change at each sample, `[Δ Σ w·Δx, Δ Σ w·Δy, Δ Σ w]` (as the kernel
/// writes it).
pub(super) type Change = PerSample;

/// Share of what the block's own far-field error, found at its check
/// points when it was made, left of the adaptive evaluation's check-point
/// allowance, that what the redos since have left out of its pixels may
/// take. The two errors then meet the allowance together as the far field
/// alone did, with a fifth of it to spare. (A far block's own error is
/// mostly far below the allowance; half of the whole allowance, as before,
/// made the redo of a 1080p drag at proxy scale rewrite 1.7 times as many
/// far pixels, at full scale 1.3 times.)
pub(super) const SHARE: f32 = 0.8;

/// A block's lag and where it is sampled: the samples are the block's for
/// as long as the map is (same window, same scale), so they are found once,
/// when the map is made, not at every redo.
#[derive(Debug, Clone, Default)]
pub(super) struct Tracked {
    pub lag: Lag,
    pub samples: Samples,
    /// The largest error the block's check points found per axis when it
    /// was last evaluated afresh (canonical units).
    pub made: [f32; 2],
    /// Redos that wrote its pixels since then.
    pub swaps: u32,
}

/// One block's lag: read and written at every redo for every block, so
/// kept as small as the checks allow and laid out for SIMD.
#[derive(Debug, Clone)]
pub(super) struct Lag {
    /// What the block's pixels have not taken, `[Δ Σ w·Δx, Δ Σ w·Δy,
    /// Δ Σ w]`. At each grid node: the moved lines' changes summed over
    /// the redos since the pixels last took them (what is pending). At
    /// each check point: the exact changes since the block was made less
    /// what its pixels took (interpolation is linear, so this is the error
    /// of everything interpolated or left out since then: what is owed).
    due: PerSample,
    /// Whether the nodes hold anything pending.
    waiting: bool,
    /// What the block's pixels hold at each sample, as they were last
    /// written: the position less the sample's own, and `Σ w`. Read while
    /// they are in cache, not from a map far larger than it at every redo.
    seen: PerSample,
}

impl Default for Lag {
    fn default() -> Self {
        Lag {
            due: [[0.0; PADDED]; 3],
            waiting: false,
            seen: [[0.0; PADDED]; 3],
        }
    }
}

/// Where a check point lies: the grid cell (its lower-left node, across
/// and up) and the place in it (fractions of a cell across and up).
type Place = ((usize, usize), (f32, f32));

/// Where a block's changes are sampled: its grid nodes then its check
/// points.
///
/// Bilinear interpolation errs most at the centres of a cell's edges or at
/// its centre: along an edge by `h²/8` times the second derivative along
/// it, at the centre by the sum of both (so for a term near harmonic, as a
/// far line's is, the centre alone would see almost nothing). The check
/// points are all three kinds: the cells' centres, then the centres of
/// their edges across, then those up, each row by row.
#[derive(Debug, Clone, Default)]
pub(super) struct Samples {
    /// Every sample lies on a half-spacing lattice: the canonical
    /// coordinates of its columns and rows (kept instead of each sample's
    /// position, which a redo rebuilds from them on the stack).
    columns: [f32; 2 * NODES_ACROSS],
    rows: [f32; 2 * NODES_ACROSS],
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

/// Per kind of check point, whether it lies half a cell across and half
/// a cell up from a node: cells' centres, then the centres of their edges
/// across, then those up.
const KINDS: [(usize, usize); 3] = [(1, 1), (1, 0), (0, 1)];

impl Samples {
    /// The samples of `block` at `scale`.
    pub fn of(block: RectI, scale: PixelScale) -> Self {
        let (nodes, nx) = grid::node_count(block, SPACING);
        let mut s = Samples {
            columns: [0.0; 2 * NODES_ACROSS],
            rows: [0.0; 2 * NODES_ACROSS],
            len: 0,
            nodes,
            nx,
            ny: nodes / nx,
            first: (block.x1, block.y1),
            last: (block.x2 - 1, block.y2 - 1),
        };
        let half = SPACING / 2;
        for (k, c) in s.columns[..2 * nx].iter_mut().enumerate() {
            *c = scale.pixel_centre(block.x1 + k as i32 * half, 0).x as f32;
        }
        for (k, r) in s.rows[..2 * s.ny].iter_mut().enumerate() {
            *r = scale.pixel_centre(0, block.y1 + k as i32 * half).y as f32;
        }
        let mut len = 0;
        s.each(|n, _| len = n + 1);
        s.len = len;
        s
    }

    /// The samples' canonical positions, across and up, padded with zeros.
    pub fn positions(&self) -> ([f32; PADDED], [f32; PADDED]) {
        let (mut xs, mut ys) = ([0f32; PADDED], [0f32; PADDED]);
        self.each(|n, (a2, c2)| (xs[n], ys[n]) = (self.columns[a2], self.rows[c2]));
        (xs, ys)
    }

    /// Calls `f(n, (a2, c2))` for each sample `n` in order, with where it
    /// lies on the half-spacing lattice (across, up): the nodes row by
    /// row (as a [`Grid`] holds them), then each kind of check point row
    /// by row. Plain loops, which cost nothing per sample, where a chained
    /// iterator cost a call (at every sample of every block of a redo).
    #[inline(always)]
    fn each(&self, mut f: impl FnMut(usize, (usize, usize))) {
        let (nx, ny) = (self.nx, self.ny);
        let mut n = 0;
        for (da, dc) in [(0, 0)].into_iter().chain(KINDS) {
            for c in 0..ny - dc {
                for a in 0..nx - da {
                    f(n, (2 * a + da, 2 * c + dc));
                    n += 1;
                }
            }
        }
    }

    /// Where the check point at `(a2, c2)` on the half-spacing lattice
    /// lies in the grid: one on the grid's last row or column lies on the
    /// far edge of the cell before it.
    fn place(&self, (a2, c2): (usize, usize)) -> Place {
        let (a, c) = (a2 / 2, c2 / 2);
        let cell = (a.min(self.nx - 2), c.min(self.ny - 2));
        let half = |odd: usize, whole: usize| 0.5 * (odd % 2) as f32 + whole as f32;
        (cell, (half(a2, a - cell.0), half(c2, c - cell.1)))
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
        let [dx, dy, ws] = &mut self.seen;
        samples.each(|n, at| {
            let (i, j) = samples.pixel(at);
            let (p, w) = band.at(i, j);
            dx[n] = p[0] - samples.columns[at.0];
            dy[n] = p[1] - samples.rows[at.1];
            ws[n] = w;
        });
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
        let (nodes, len) = (samples.nodes, samples.len);
        if !now && self.within(0..len, [&self.due, change], allowed) {
            for (due, change) in self.due.iter_mut().zip(change) {
                for (d, c) in due[..len].iter_mut().zip(&change[..len]) {
                    *d += c;
                }
            }
            self.waiting = true;
            return Some(Take::Nothing);
        }
        let mut left: PerSample =
            std::array::from_fn(|m| std::array::from_fn(|n| self.due[m][n] + change[m][n]));
        let grid = Grid {
            nx: samples.nx,
            spacing: SPACING,
            sums: (0..nodes)
                .map(|n| std::array::from_fn(|m| left[m][n]))
                .collect(),
        };
        // What the check points still owe once the pixels take the grid.
        samples.each(|n, at| {
            if n >= nodes {
                let (cell, at) = samples.place(at);
                for (left, taken) in left.iter_mut().zip(grid.at(cell, at)) {
                    left[n] -= taken;
                }
            }
        });
        if !self.within(nodes..len, [&left, &NONE], allowed) {
            return None;
        }
        for (due, left) in self.due.iter_mut().zip(&left) {
            due[..nodes].fill(0.0);
            due[nodes..len].copy_from_slice(&left[nodes..len]);
        }
        self.waiting = false;
        Some(Take::Pending(grid))
    }

    /// What the pixels must take before an exact change: the pending
    /// changes, if any, interpolated (`None` when that leaves too much
    /// owed, as in [`Lag::add`]).
    pub fn flush(&mut self, samples: &Samples, allowed: [f32; 2]) -> Option<Take> {
        if !self.waiting {
            return Some(Take::Nothing);
        }
        self.add(samples, &NONE, allowed, true)
    }

    /// Whether what the check points owe (with what is pending, if
    /// anything) moves none of their positions by more than `allowed` per
    /// axis, with the pixels as [`Lag::look`] last saw them.
    pub fn owes_within(&self, samples: &Samples, allowed: [f32; 2]) -> bool {
        self.within(samples.nodes..samples.len, [&self.due, &NONE], allowed)
    }

    /// Whether leaving the sum of `lag`'s two parts out of the pixels of
    /// the samples in `range` moves none of their positions by more than
    /// `allowed` per axis. One pass with no early exit, which vectorises.
    fn within(&self, range: Range<usize>, lag: [&PerSample; 2], allowed: [f32; 2]) -> bool {
        let n = range.len();
        fn part(s: &PerSample, range: Range<usize>, n: usize) -> [&[f32]; 3] {
            s.each_ref().map(|s| &s[range.clone()][..n])
        }
        let ([dx, dy, w], [ax, ay, aw], [bx, by, bw]) = (
            part(&self.seen, range.clone(), n),
            part(lag[0], range.clone(), n),
            part(lag[1], range, n),
        );
        let mut ok = true;
        for k in 0..n {
            let w1 = w[k] + (aw[k] + bw[k]);
            let off_x = (dx[k] * w[k] + (ax[k] + bx[k])) / w1 - dx[k];
            let off_y = (dy[k] * w[k] + (ay[k] + by[k])) / w1 - dy[k];
            // NaNs compare false: they fail here too.
            ok &= (off_x.abs() <= allowed[0]) & (off_y.abs() <= allowed[1]);
        }
        ok
    }
}

/// No change at any sample.
const NONE: Change = [[0.0; PADDED]; 3];

#[cfg(test)]
mod tests {
    use super::*;

    /// A far change is known on a 16 px grid (docs/architecture.md): a
    /// whole block's nodes lie 16 pixels apart, across and up.
    #[test]
    fn a_whole_blocks_grid_has_its_nodes_16_px_apart() {
        let block = RectI::new(0, 0, BLOCK, BLOCK);
        let samples = Samples::of(block, PixelScale::UNIT);
        let (nodes, nx) = grid::node_count(block, SPACING);
        assert_eq!(
            (nx, nodes),
            (BLOCK as usize / 16 + 1, (BLOCK as usize / 16 + 1).pow(2))
        );
        let (xs, ys) = samples.positions();
        assert_eq!((xs[1] - xs[0], ys[1] - ys[0]), (16.0, 0.0));
        assert_eq!((xs[nx] - xs[0], ys[nx] - ys[0]), (0.0, 16.0));
    }

    /// The samples of a whole block and of blocks cut short by the
    /// window's edges: the nodes first, row by row as a grid holds them,
    /// then check points each placed in the cell whose centre or edge it
    /// is, every sample once, at its pixel centre.
    #[test]
    fn samples_are_the_grid_nodes_then_check_points_placed_in_their_cells() {
        let scale = PixelScale::new(0.5, 0.5, 1.0);
        for block in [
            RectI::new(0, 0, BLOCK, BLOCK),
            RectI::new(96, 48, 96 + 13, 48 + BLOCK),
            RectI::new(0, 0, 3, 1),
        ] {
            let samples = Samples::of(block, scale);
            let (nodes, nx) = grid::node_count(block, SPACING);
            let mut walked = Vec::new();
            samples.each(|n, at| walked.push((n, at)));
            assert_eq!(walked.len(), samples.len, "{block:?}");
            let (xs, ys) = samples.positions();
            let half = SPACING / 2;
            for &(n, (a2, c2)) in &walked {
                if n < nodes {
                    assert_eq!((a2, c2), (2 * (n % nx), 2 * (n / nx)), "{block:?} node {n}");
                } else {
                    assert!(a2 % 2 == 1 || c2 % 2 == 1, "{block:?} check {n} on a node");
                    let ((a, c), (fx, fy)) = samples.place((a2, c2));
                    assert!(a + 1 < nx && c + 1 < nodes / nx, "{block:?} check {n}");
                    assert!((0.0..=1.0).contains(&fx) && (0.0..=1.0).contains(&fy));
                    assert_eq!(
                        (2.0 * (a as f32 + fx), 2.0 * (c as f32 + fy)),
                        (a2 as f32, c2 as f32)
                    );
                }
                let (i, j) = (block.x1 + a2 as i32 * half, block.y1 + c2 as i32 * half);
                let centre = scale.pixel_centre(i, j);
                assert_eq!((xs[n], ys[n]), (centre.x as f32, centre.y as f32));
            }
            let mut at: Vec<_> = walked.iter().map(|&(_, at)| at).collect();
            at.sort_unstable();
            at.dedup();
            assert_eq!(at.len(), walked.len(), "{block:?}: a sample twice");
        }
    }
}
