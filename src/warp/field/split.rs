//! The field warp within a tolerance, fast: the adaptive evaluation.
//!
//! Every line pulls every pixel (eq. 4 has no cut-off), but a line's pull
//! varies slowly far from it. So per block of pixels the lines split in two:
//! lines near the block are evaluated exactly at every pixel; the far lines'
//! weighted sums `Σ w·(X′ − X)` and `Σ w` are evaluated on a coarse grid and
//! interpolated bilinearly. Creases of the field (on and around lines, where
//! the distance rule switches) stay in the exact part. Each block is then
//! checked against the exact map at grid-cell centres, where bilinear error
//! peaks, and evaluated exactly when any check misses the tolerance.

use rayon::prelude::*;
use wide::f32x8;

use super::grid::{self, Grid, Rows, GRID};
use super::kernel::{Lines, Sums};
use super::warp::FieldWarp;
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;
use crate::prefetch;

/// Side of a block, pixels.
pub(super) const BLOCK: i32 = 48;
/// Lines closer than this to a block (pixels) are evaluated exactly there.
/// At this distance a far line's relative curvature over a grid cell is
/// about `0.75·(GRID/NEAR)² ≈ 7e-4`.
pub(super) const NEAR: f64 = 128.0;
/// Share of the tolerance the check points must meet, so the unchecked
/// pixels (whose error is smaller than at cell centres) stay within it.
const SAFETY: f64 = 0.5;

pub(super) fn map_window(
    warp: &FieldWarp,
    window: RectI,
    scale: PixelScale,
    tolerance: f64,
) -> WarpMap {
    let mut pos = vec![[0f32; 2]; window.area()];
    let setup = Setup::new(warp, window, scale, Some(tolerance));
    let mut blocks = vec![(); setup.block_count()];
    setup.each_band(&mut pos, None, &mut blocks, fill_band);
    WarpMap::new(window, scale, pos)
}

/// What every block of one evaluation shares.
pub(super) struct Setup<'a> {
    pub warp: &'a FieldWarp,
    pub window: RectI,
    pub scale: PixelScale,
    /// Destination segments in this window's pixel space (centres at k + 0.5).
    segments: Vec<(Vec2, Vec2)>,
    /// What the check points must meet per axis (pixels); `None` evaluates
    /// every block exactly.
    tol: Option<[f32; 2]>,
}

impl<'a> Setup<'a> {
    /// `warp` over `window`: adaptive within `tolerance`, or exact without one.
    pub fn new(
        warp: &'a FieldWarp,
        window: RectI,
        scale: PixelScale,
        tolerance: Option<f64>,
    ) -> Self {
        let segments = warp
            .pairs
            .iter()
            .map(|l| (scale.to_pixel(l.dst.0), scale.to_pixel(l.dst.1)))
            .collect();
        let tol = tolerance.map(|t| {
            [
                (t * SAFETY / scale.x.max(1e-9)) as f32,
                (t * SAFETY / scale.y.max(1e-9)) as f32,
            ]
        });
        Setup {
            warp,
            window,
            scale,
            segments,
            tol,
        }
    }

    /// Blocks in a band.
    pub fn blocks_across(&self) -> usize {
        self.window.width().div_ceil(BLOCK as usize)
    }

    /// The columns of block `k` of a band, as offsets from the window's left.
    pub fn block_columns(&self, k: usize) -> std::ops::Range<usize> {
        let x1 = k * BLOCK as usize;
        x1..(x1 + BLOCK as usize).min(self.window.width())
    }

    /// Blocks in the window, numbered row of blocks by row from the bottom.
    pub fn block_count(&self) -> usize {
        self.blocks_across() * self.window.height().div_ceil(BLOCK as usize)
    }

    /// Runs `f(band, blocks)` on every row of blocks (a band), in parallel,
    /// into `pos` and, when kept, `weights` (`Σ w` per pixel): `blocks` is
    /// the band's share of `per_block`, one entry per block from the left.
    pub fn each_band<T: Send>(
        &self,
        pos: &mut [[f32; 2]],
        weights: Option<&mut [f32]>,
        per_block: &mut [T],
        f: impl Fn(&mut Band, &mut [T]) + Sync,
    ) {
        let (w, across) = (self.window.width(), self.blocks_across());
        if w == 0 || self.window.height() == 0 {
            return;
        }
        let rows = BLOCK as usize * w;
        let weight_bands: Vec<Option<&mut [f32]>> = match weights {
            Some(ws) => ws.chunks_mut(rows).map(Some).collect(),
            None => (0..pos.len().div_ceil(rows)).map(|_| None).collect(),
        };
        pos.par_chunks_mut(rows)
            .zip(weight_bands)
            .zip(per_block.par_chunks_mut(across))
            .enumerate()
            .for_each(|(row, ((out, weights), blocks))| {
                let y1 = self.window.y1 + row as i32 * BLOCK;
                let mut band = Band {
                    setup: self,
                    y1,
                    y2: (y1 + BLOCK).min(self.window.y2),
                    out,
                    weights,
                    scratch: Scratch::default(),
                };
                f(&mut band, blocks);
            });
    }

    /// What the check points must meet per axis (canonical units), when
    /// the evaluation is adaptive.
    pub fn tolerance(&self) -> Option<[f32; 2]> {
        self.tol
    }
}

/// Evaluates every block of `band` afresh ([`Block::fill`]).
fn fill_band(band: &mut Band, blocks: &mut [()]) {
    for k in 0..blocks.len() {
        band.block(k).fill();
    }
}

/// A row of blocks of the map being made.
pub(super) struct Band<'a> {
    pub setup: &'a Setup<'a>,
    pub y1: i32,
    pub y2: i32,
    /// The band's rows of the map.
    out: &'a mut [[f32; 2]],
    /// The same rows of `Σ w` per pixel, when kept.
    weights: Option<&'a mut [f32]>,
    scratch: Scratch,
}

impl Band<'_> {
    /// Where block `k` of the band comes among the window's blocks, row
    /// by row.
    pub fn index(&self, k: usize) -> usize {
        let row = ((self.y1 - self.setup.window.y1) / BLOCK) as usize;
        row * self.setup.blocks_across() + k
    }

    /// The pixels of block `k` of the band, from the left.
    pub fn rect(&self, k: usize) -> RectI {
        let (x1, cols) = (self.setup.window.x1, self.setup.block_columns(k));
        RectI::new(
            x1 + cols.start as i32,
            self.y1,
            x1 + cols.end as i32,
            self.y2,
        )
    }

    /// Block `k` of the band, from the left.
    pub fn block(&mut self, k: usize) -> Block<'_> {
        Block {
            setup: self.setup,
            rect: self.rect(k),
            out: &mut *self.out,
            weights: self.weights.as_deref_mut(),
            scratch: &mut self.scratch,
        }
    }

    /// Pixel `(i, j)`'s position and `Σ w` (0 when not kept).
    pub fn at(&self, i: i32, j: i32) -> ([f32; 2], f32) {
        let k = self.row_start(j) + (i - self.setup.window.x1) as usize;
        (self.out[k], self.weights.as_ref().map_or(0.0, |ws| ws[k]))
    }

    /// Asks the cache for row `j`'s pixels at columns `cols` of the window
    /// (positions and `Σ w`), when the band holds that row.
    pub fn prefetch_row(&self, j: i32, cols: std::ops::Range<usize>) {
        if !(self.y1..self.y2).contains(&j) {
            return;
        }
        let start = self.row_start(j);
        let at = start + cols.start..start + cols.end;
        prefetch::lines(&self.out[at.clone()]);
        if let Some(ws) = &self.weights {
            prefetch::lines(&ws[at]);
        }
    }

    /// Row `j` across the window: positions and `Σ w` (when kept).
    pub fn row_mut(&mut self, j: i32) -> (&mut [[f32; 2]], Option<&mut [f32]>) {
        let start = self.row_start(j);
        let at = start..start + self.setup.window.width();
        row_slices(self.out, self.weights.as_deref_mut(), at)
    }

    /// Where row `j` starts in the band's buffers.
    fn row_start(&self, j: i32) -> usize {
        (j - self.y1) as usize * self.setup.window.width()
    }
}

/// The pixels `at` of a band's positions and, when kept, `Σ w`.
fn row_slices<'a>(
    out: &'a mut [[f32; 2]],
    weights: Option<&'a mut [f32]>,
    at: std::ops::Range<usize>,
) -> (&'a mut [[f32; 2]], Option<&'a mut [f32]>) {
    (&mut out[at.clone()], weights.map(|w| &mut w[at]))
}

/// One block of the map being made.
pub(super) struct Block<'a> {
    setup: &'a Setup<'a>,
    /// The block's pixels.
    rect: RectI,
    /// The band of the map this block lies in (rows from the block's `y1`).
    out: &'a mut [[f32; 2]],
    /// The same band of `Σ w` per pixel, when kept.
    weights: Option<&'a mut [f32]>,
    scratch: &'a mut Scratch,
}

/// Buffers reused from block to block of a band.
#[derive(Default)]
struct Scratch {
    xs: Vec<f32>,
    ys: Vec<f32>,
    ox: Vec<f32>,
    oy: Vec<f32>,
    ow: Vec<f32>,
    far: Rows<3>,
    sets: Sets,
}

/// A block's near and far lines (indices into the warp's lines, and the
/// lines themselves), reused from block to block.
#[derive(Default)]
struct Sets {
    near_idx: Vec<usize>,
    far_idx: Vec<usize>,
    near: Lines,
    far: Lines,
}

impl Block<'_> {
    /// Evaluates the block: near lines exactly, far ones from a grid when
    /// that passes the checks, else all exactly. Returns the largest error
    /// its check points found per axis (canonical units; zero where every
    /// pixel is exact).
    pub fn fill(&mut self) -> [f32; 2] {
        if self.setup.tol.is_none() {
            self.exact();
            return [0.0; 2];
        }
        let (lo, hi) = corners(self.rect);
        let mut sets = std::mem::take(&mut self.scratch.sets);
        sets.near_idx.clear();
        sets.far_idx.clear();
        for (k, &(p, q)) in self.setup.segments.iter().enumerate() {
            if is_near(p, q, lo, hi) {
                sets.near_idx.push(k);
            } else {
                sets.far_idx.push(k);
            }
        }
        if sets.far_idx.is_empty() {
            self.scratch.sets = sets;
            self.exact();
            return [0.0; 2];
        }
        let all = &self.setup.warp.kernel;
        all.select_into(&sets.far_idx, &mut sets.far);
        all.select_into(&sets.near_idx, &mut sets.near);
        let grid = self.far_grid(&sets.far);
        self.rows(&sets.near, Some(&grid));
        self.scratch.sets = sets;
        self.checked().unwrap_or_else(|| {
            self.exact();
            [0.0; 2]
        })
    }

    /// Canonical position of the centre of pixel `(i, j)`.
    fn centre(&self, i: i32, j: i32) -> (f32, f32) {
        let c = self.setup.scale.pixel_centre(i, j);
        (c.x as f32, c.y as f32)
    }

    /// Where row `j` of the block starts in its band.
    fn row_start(&self, j: i32) -> usize {
        let w = self.setup.window.width();
        (j - self.rect.y1) as usize * w + (self.rect.x1 - self.setup.window.x1) as usize
    }

    fn row_mut(&mut self, j: i32) -> &mut [[f32; 2]] {
        let start = self.row_start(j);
        &mut self.out[start..start + self.rect.width()]
    }

    /// Row `j`'s positions and, when kept, its `Σ w`.
    fn rows_mut(&mut self, j: i32) -> (&mut [[f32; 2]], Option<&mut [f32]>) {
        let start = self.row_start(j);
        let at = start..start + self.rect.width();
        row_slices(self.out, self.weights.as_deref_mut(), at)
    }

    /// Every pixel of the block with all lines.
    fn exact(&mut self) {
        self.rows(&self.setup.warp.kernel, None);
    }

    /// `lines`' sums on the block's grid nodes ([`grid::nodes`]).
    fn far_grid(&self, lines: &Lines) -> Grid<3> {
        let (xs, ys, nx) = grid::nodes(self.rect, self.setup.scale, GRID);
        let mut sums = vec![[0f32; 3]; xs.len()];
        lines.sums(&xs, &ys, &mut sums);
        Grid {
            nx,
            spacing: GRID,
            sums,
        }
    }

    /// Each row of the block through `lines`, plus the far field from `grid`
    /// when there is one.
    fn rows(&mut self, lines: &Lines, grid: Option<&Grid<3>>) {
        let b = self.rect;
        let n = b.width();
        let mut sc = std::mem::take(self.scratch);
        sc.xs.clear();
        sc.xs.extend((b.x1..b.x2).map(|i| self.centre(i, b.y1).0));
        for v in [&mut sc.ys, &mut sc.ox, &mut sc.oy, &mut sc.ow] {
            v.resize(n, 0.0);
        }
        match grid {
            Some(grid) => sc.far.across(grid, n),
            None => sc.far.zero(n),
        }
        let keep_weights = self.weights.is_some();
        for j in b.y1..b.y2 {
            sc.ys.fill(self.centre(b.x1, j).1);
            let far = match grid {
                Some(_) => sc.far.row((j - b.y1) as usize),
                None => sc.far.last(),
            };
            let lanes = |k: usize| {
                let lane = |m: usize| f32x8::new(far[m][k..k + 8].try_into().expect("8 lanes"));
                Sums {
                    x: lane(0),
                    y: lane(1),
                    w: lane(2),
                }
            };
            let ow = keep_weights.then_some(&mut sc.ow[..]);
            lines.map_points_plus(&sc.xs, &sc.ys, lanes, (&mut sc.ox, &mut sc.oy), ow);
            let (out, weights) = self.rows_mut(j);
            for (o, (x, y)) in out.iter_mut().zip(sc.ox.iter().zip(&sc.oy)) {
                *o = [*x, *y];
            }
            if let Some(w) = weights {
                w.copy_from_slice(&sc.ow);
            }
        }
        *self.scratch = sc;
    }

    /// Compares the block with the exact map at the centres of every other
    /// grid cell (where bilinear interpolation errs most).
    /// The largest error per axis at the check points (canonical units),
    /// or `None` when one misses the tolerance.
    fn checked(&mut self) -> Option<[f32; 2]> {
        let Some(tol) = self.setup.tol else {
            return Some([0.0; 2]);
        };
        let b = self.rect;
        let pixels: Vec<(i32, i32)> = check_points(b).collect();
        let (xs, ys): (Vec<f32>, Vec<f32>) = pixels.iter().map(|&(i, j)| self.centre(i, j)).unzip();
        let (mut ox, mut oy) = (vec![0f32; xs.len()], vec![0f32; xs.len()]);
        self.setup
            .warp
            .kernel
            .map_points(&xs, &ys, &mut ox, &mut oy);
        let mut worst = [0f32; 2];
        for (k, &(i, j)) in pixels.iter().enumerate() {
            let got = self.row_mut(j)[(i - b.x1) as usize];
            let err = [(got[0] - ox[k]).abs(), (got[1] - oy[k]).abs()];
            // NaNs compare false: they fail here too.
            if !(err[0] <= tol[0] && err[1] <= tol[1]) {
                return None;
            }
            worst = [worst[0].max(err[0]), worst[1].max(err[1])];
        }
        Some(worst)
    }
}

/// The centres of a block's corner pixels (pixel space).
pub(super) fn corners(block: RectI) -> (Vec2, Vec2) {
    let b = block;
    (
        Vec2::new(b.x1 as f64 + 0.5, b.y1 as f64 + 0.5),
        Vec2::new(b.x2 as f64 - 0.5, b.y2 as f64 - 0.5),
    )
}

/// The centres of every other grid cell of `block`, where bilinear
/// interpolation errs most.
pub(super) fn check_points(block: RectI) -> impl Iterator<Item = (i32, i32)> {
    let step = (2 * GRID) as usize;
    let ys = (block.y1 + GRID / 2..block.y2).step_by(step);
    ys.flat_map(move |j| {
        (block.x1 + GRID / 2..block.x2)
            .step_by(step)
            .map(move |i| (i, j))
    })
}

/// Whether segment `p→q` comes within [`NEAR`] of the box `[lo, hi]`. Most
/// lines are far from most blocks, and their bounding boxes say so without
/// the exact distance.
#[inline]
fn is_near(p: Vec2, q: Vec2, lo: Vec2, hi: Vec2) -> bool {
    is_within(p, q, lo, hi, NEAR)
}

/// Whether segment `p→q` comes within `distance` of the box `[lo, hi]`.
#[inline]
pub(super) fn is_within(p: Vec2, q: Vec2, lo: Vec2, hi: Vec2, distance: f64) -> bool {
    let gap_x = (lo.x - p.x.max(q.x)).max(p.x.min(q.x) - hi.x);
    let gap_y = (lo.y - p.y.max(q.y)).max(p.y.min(q.y) - hi.y);
    if gap_x >= distance || gap_y >= distance {
        return false;
    }
    segment_box_distance(p, q, lo, hi) < distance
}

/// Distance from segment `p→q` to the axis-aligned box `[lo, hi]` (0 when
/// they meet).
fn segment_box_distance(p: Vec2, q: Vec2, lo: Vec2, hi: Vec2) -> f64 {
    let inside = |v: Vec2| v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y;
    if inside(p) || inside(q) {
        return 0.0;
    }
    let corners = [lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)];
    let edges = [0, 1, 2, 3].map(|k| (corners[k], corners[(k + 1) % 4]));
    if edges.iter().any(|&(a, b)| segments_cross(p, q, a, b)) {
        return 0.0;
    }
    let to_box = |v: Vec2| {
        let dx = (lo.x - v.x).max(0.0).max(v.x - hi.x);
        let dy = (lo.y - v.y).max(0.0).max(v.y - hi.y);
        dx.hypot(dy)
    };
    let corner_to_segment = corners
        .iter()
        .map(|&c| c.distance_to_segment(p, q))
        .fold(f64::INFINITY, f64::min);
    to_box(p).min(to_box(q)).min(corner_to_segment)
}

fn segments_cross(p: Vec2, q: Vec2, a: Vec2, b: Vec2) -> bool {
    let cross = |o: Vec2, s: Vec2, t: Vec2| (s - o).x * (t - o).y - (s - o).y * (t - o).x;
    let (d1, d2) = (cross(a, b, p), cross(a, b, q));
    let (d3, d4) = (cross(p, q, a), cross(p, q, b));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn segment_box_distance_cases() {
        let (lo, hi) = (v(0.0, 0.0), v(10.0, 10.0));
        // Crossing the box with both ends outside.
        assert_eq!(
            segment_box_distance(v(-5.0, 5.0), v(15.0, 5.0), lo, hi),
            0.0
        );
        // One end inside.
        assert_eq!(
            segment_box_distance(v(5.0, 5.0), v(50.0, 50.0), lo, hi),
            0.0
        );
        // Parallel above the box.
        assert!((segment_box_distance(v(-5.0, 13.0), v(15.0, 13.0), lo, hi) - 3.0).abs() < 1e-12);
        // Diagonal off a corner: closest to corner (10, 10).
        let d = segment_box_distance(v(20.0, 10.0), v(10.0, 20.0), lo, hi);
        assert!((d - 50f64.sqrt()).abs() < 1e-12);
    }
}
