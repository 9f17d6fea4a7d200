//! Sums that vary slowly over a block, from a coarse grid: evaluated at
//! grid nodes every `spacing` pixels and interpolated bilinearly, in loops
//! over whole rows that vectorise. The adaptive evaluation's far field
//! ([`split`](super::split), every [`GRID`] pixels) and a redo's far
//! change ([`redo`](super::redo)) both lie on one.

use crate::geom::{PixelScale, RectI};

/// Spacing of the far field's grid, pixels.
pub(super) const GRID: i32 = 4;

/// `M` sums on a grid of `nx` nodes per row, `spacing` pixels apart, over
/// a block.
pub(super) struct Grid<const M: usize> {
    pub nx: usize,
    pub spacing: i32,
    pub sums: Vec<[f32; M]>,
}

/// How many nodes `spacing` pixels apart a block has, and how many of them
/// across: nodes `(x1 + a·spacing, y1 + c·spacing)` reach up to one cell
/// past its far edges.
pub(super) fn node_count(block: RectI, spacing: i32) -> (usize, usize) {
    let nx = (block.width() as i32 + spacing - 1) / spacing + 1;
    let ny = (block.height() as i32 + spacing - 1) / spacing + 1;
    ((nx * ny) as usize, nx as usize)
}

/// The pixel at node `n` of a block's grid with `nx` nodes across.
pub(super) fn node_pixel(block: RectI, n: usize, nx: usize, spacing: i32) -> (i32, i32) {
    let (a, c) = ((n % nx) as i32, (n / nx) as i32);
    (block.x1 + a * spacing, block.y1 + c * spacing)
}

/// The canonical positions of a block's grid nodes, row by row, and how
/// many there are across.
pub(super) fn nodes(block: RectI, scale: PixelScale, spacing: i32) -> (Vec<f32>, Vec<f32>, usize) {
    let (count, nx) = node_count(block, spacing);
    let centres = (0..count).map(|n| {
        let (i, j) = node_pixel(block, n, nx, spacing);
        let c = scale.pixel_centre(i, j);
        (c.x as f32, c.y as f32)
    });
    let (xs, ys) = centres.unzip();
    (xs, ys, nx)
}

impl<const M: usize> Grid<M> {
    /// The bilinear value at `(fx, fy)` (fractions of a cell) in the cell
    /// whose lower-left node is `(a, c)`.
    pub fn at(&self, (a, c): (usize, usize), (fx, fy): (f32, f32)) -> [f32; M] {
        let node = |a: usize, c: usize| self.sums[c * self.nx + a];
        let (n00, n10, n01, n11) = (
            node(a, c),
            node(a + 1, c),
            node(a, c + 1),
            node(a + 1, c + 1),
        );
        std::array::from_fn(|m| {
            let lo = n00[m] + (n10[m] - n00[m]) * fx;
            let hi = n01[m] + (n11[m] - n01[m]) * fx;
            lo + (hi - lo) * fy
        })
    }
}

/// Sums along a pixel row: `lo + (hi − lo)·f` per component, between two
/// rows of a grid (or known exactly: `lo` = `hi`, `f` = 0).
pub(super) struct Between<'a, const M: usize> {
    pub lo: [&'a [f32]; M],
    pub hi: [&'a [f32]; M],
    pub f: f32,
}

impl<'a, const M: usize> Between<'a, M> {
    /// Sums known exactly at each pixel.
    pub fn exact(sums: [&'a [f32]; M]) -> Self {
        Between {
            lo: sums,
            hi: sums,
            f: 0.0,
        }
    }

    /// Component `m` at pixel `i`.
    #[inline]
    pub fn at(&self, m: usize, i: usize) -> f32 {
        self.lo[m][i] + (self.hi[m][i] - self.lo[m][i]) * self.f
    }
}

/// A grid's sums interpolated over a block: along each grid row once per
/// block, then between two grid rows per pixel row.
pub(super) struct Rows<const M: usize> {
    /// Sums along each grid row: `[(row * M + m) * stride + k]`.
    across: Vec<f32>,
    stride: usize,
    /// The grid's spacing, pixels.
    spacing: usize,
    /// One pixel row's sums, one vector per component, padded to whole lanes.
    row: [Vec<f32>; M],
}

impl<const M: usize> Default for Rows<M> {
    fn default() -> Self {
        Rows {
            across: Vec::new(),
            stride: 0,
            spacing: GRID as usize,
            row: std::array::from_fn(|_| Vec::new()),
        }
    }
}

impl<const M: usize> Rows<M> {
    /// Interpolates `grid` along its rows for a block `n` pixels wide.
    pub fn across(&mut self, grid: &Grid<M>, n: usize) {
        self.zero(n);
        self.spacing = grid.spacing as usize;
        let ny = grid.sums.len() / grid.nx;
        self.across.clear();
        self.across.resize(ny * M * self.stride, 0.0);
        let fractions: Vec<f32> = (0..self.spacing)
            .map(|i| i as f32 / self.spacing as f32)
            .collect();
        for (c, nodes) in grid.sums.chunks_exact(grid.nx).enumerate() {
            for m in 0..M {
                let at = (c * M + m) * self.stride;
                let row = &mut self.across[at..at + self.stride];
                for (cell, w) in row.chunks_exact_mut(self.spacing).zip(nodes.windows(2)) {
                    let (a, d) = (w[0][m], w[1][m] - w[0][m]);
                    for (o, f) in cell.iter_mut().zip(&fractions) {
                        *o = a + d * f;
                    }
                }
            }
        }
    }

    /// Rows of zeros for a block `n` pixels wide (nothing to interpolate).
    pub fn zero(&mut self, n: usize) {
        self.stride = n + 8;
        for v in &mut self.row {
            v.clear();
            v.resize(self.stride, 0.0);
        }
    }

    /// The last row made (zeros after [`Rows::zero`]).
    pub fn last(&self) -> &[Vec<f32>; M] {
        &self.row
    }

    /// The grid rows around pixel row `dy` of the block, interpolated
    /// along, and how far between them it lies.
    pub fn between(&self, dy: usize) -> Between<'_, M> {
        let (c, f) = (
            dy / self.spacing,
            (dy % self.spacing) as f32 / self.spacing as f32,
        );
        let stride = self.stride;
        let row = |c: usize, m: usize| &self.across[(c * M + m) * stride..][..stride];
        Between {
            lo: std::array::from_fn(|m| row(c, m)),
            hi: std::array::from_fn(|m| row(c + 1, m)),
            f,
        }
    }

    /// The sums along pixel row `dy` of the block.
    pub fn row(&mut self, dy: usize) -> &[Vec<f32>; M] {
        let (c, f) = (
            dy / self.spacing,
            (dy % self.spacing) as f32 / self.spacing as f32,
        );
        let stride = self.stride;
        for (m, out) in self.row.iter_mut().enumerate() {
            let lo = &self.across[(c * M + m) * stride..][..stride];
            let hi = &self.across[((c + 1) * M + m) * stride..][..stride];
            for ((o, a), b) in out.iter_mut().zip(lo).zip(hi) {
                *o = a + (b - a) * f;
            }
        }
        &self.row
    }
}
