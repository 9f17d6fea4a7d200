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

use super::kernel::{Lines, Sums};
use super::FieldWarp;
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;

/// Side of a block, pixels.
const BLOCK: i32 = 48;
/// Spacing of the far-field grid, pixels.
const GRID: i32 = 4;
/// Pixel offsets within a grid cell, as fractions of it.
const FRACTIONS: [f32; GRID as usize] = [0.0, 0.25, 0.5, 0.75];
/// Lines closer than this to a block (pixels) are evaluated exactly there.
/// At this distance a far line's relative curvature over a grid cell is
/// about `0.75·(GRID/NEAR)² ≈ 7e-4`.
const NEAR: f64 = 128.0;
/// Share of the tolerance the check points must meet, so the unchecked
/// pixels (whose error is smaller than at cell centres) stay within it.
const SAFETY: f64 = 0.5;

pub(super) fn map_window(
    warp: &FieldWarp,
    window: RectI,
    scale: PixelScale,
    tolerance: f64,
) -> WarpMap {
    let (w, h) = (window.width(), window.height());
    let mut pos = vec![[0f32; 2]; w * h];
    if w == 0 || h == 0 {
        return WarpMap::new(window, scale, pos);
    }
    // Destination segments in this window's pixel space (centres at k + 0.5).
    let segments: Vec<(Vec2, Vec2)> = warp
        .pairs
        .iter()
        .map(|l| (scale.to_pixel(l.dst.0), scale.to_pixel(l.dst.1)))
        .collect();
    let tol = [
        (tolerance * SAFETY / scale.x.max(1e-9)) as f32,
        (tolerance * SAFETY / scale.y.max(1e-9)) as f32,
    ];
    pos.par_chunks_mut(BLOCK as usize * w)
        .enumerate()
        .for_each(|(band, out)| {
            let y1 = window.y1 + band as i32 * BLOCK;
            let y2 = (y1 + BLOCK).min(window.y2);
            let mut scratch = Scratch::default();
            let mut x1 = window.x1;
            while x1 < window.x2 {
                let block = RectI::new(x1, y1, (x1 + BLOCK).min(window.x2), y2);
                let mut b = Block {
                    warp,
                    window,
                    scale,
                    block,
                    out: &mut *out,
                    scratch: &mut scratch,
                };
                b.fill(&segments, tol);
                x1 += BLOCK;
            }
        });
    WarpMap::new(window, scale, pos)
}

struct Block<'a> {
    warp: &'a FieldWarp,
    window: RectI,
    scale: PixelScale,
    block: RectI,
    /// The band of the map this block lies in (rows from the block's `y1`).
    out: &'a mut [[f32; 2]],
    scratch: &'a mut Scratch,
}

/// Buffers reused from block to block of a band.
#[derive(Default)]
struct Scratch {
    xs: Vec<f32>,
    ys: Vec<f32>,
    ox: Vec<f32>,
    oy: Vec<f32>,
    /// Far sums along a row, one vector per component, padded to whole lanes.
    far: [Vec<f32>; 3],
    /// Far sums interpolated along each grid row: `[(row * 3 + m) * stride + k]`.
    across: Vec<f32>,
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
    fn fill(&mut self, segments: &[(Vec2, Vec2)], tol: [f32; 2]) {
        let b = self.block;
        let (lo, hi) = (
            Vec2::new(b.x1 as f64 + 0.5, b.y1 as f64 + 0.5),
            Vec2::new(b.x2 as f64 - 0.5, b.y2 as f64 - 0.5),
        );
        let mut sets = std::mem::take(&mut self.scratch.sets);
        sets.near_idx.clear();
        sets.far_idx.clear();
        for (k, &(p, q)) in segments.iter().enumerate() {
            if is_near(p, q, lo, hi) {
                sets.near_idx.push(k);
            } else {
                sets.far_idx.push(k);
            }
        }
        if sets.far_idx.is_empty() {
            self.scratch.sets = sets;
            self.exact();
            return;
        }
        let all = &self.warp.kernel;
        all.select_into(&sets.far_idx, &mut sets.far);
        all.select_into(&sets.near_idx, &mut sets.near);
        let grid = self.far_grid(&sets.far);
        self.interpolated(&sets.near, &grid);
        self.scratch.sets = sets;
        if !self.checks_pass(tol) {
            self.exact();
        }
    }

    /// Canonical position of the centre of pixel `(i, j)`.
    fn centre(&self, i: i32, j: i32) -> (f32, f32) {
        let c = self.scale.pixel_centre(i, j);
        (c.x as f32, c.y as f32)
    }

    fn row_mut(&mut self, j: i32) -> &mut [[f32; 2]] {
        let w = self.window.width();
        let start = (j - self.block.y1) as usize * w + (self.block.x1 - self.window.x1) as usize;
        &mut self.out[start..start + self.block.width()]
    }

    /// Every pixel of the block with all lines.
    fn exact(&mut self) {
        self.rows(&self.warp.kernel, None);
    }

    /// The far lines' sums on grid nodes `(x1 + a·GRID, y1 + c·GRID)`, which
    /// reach up to one cell past the block's far edges.
    fn far_grid(&self, far: &Lines) -> Grid {
        let b = self.block;
        let nx = (b.width() as i32 + GRID - 1) / GRID + 1;
        let ny = (b.height() as i32 + GRID - 1) / GRID + 1;
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for c in 0..ny {
            for a in 0..nx {
                let (x, y) = self.centre(b.x1 + a * GRID, b.y1 + c * GRID);
                xs.push(x);
                ys.push(y);
            }
        }
        let mut sums = vec![[0f32; 3]; xs.len()];
        far.sums(&xs, &ys, &mut sums);
        Grid {
            nx: nx as usize,
            sums,
        }
    }

    /// Near lines exactly plus the far field interpolated from `grid`.
    fn interpolated(&mut self, near: &Lines, grid: &Grid) {
        self.rows(near, Some(grid));
    }

    /// Each row of the block through `lines`, plus the far field from `grid`
    /// when there is one.
    fn rows(&mut self, lines: &Lines, grid: Option<&Grid>) {
        let b = self.block;
        let n = b.width();
        let mut sc = std::mem::take(self.scratch);
        sc.xs.clear();
        sc.xs.extend((b.x1..b.x2).map(|i| self.centre(i, b.y1).0));
        for v in [&mut sc.ys, &mut sc.ox, &mut sc.oy] {
            v.resize(n, 0.0);
        }
        for v in &mut sc.far {
            v.clear();
            v.resize(n + 8, 0.0);
        }
        // The far sums along each grid row, interpolated across once per
        // block; each pixel row then blends the two grid rows around it, a
        // loop over whole rows that vectorises.
        let stride = n + 8;
        if let Some(grid) = grid {
            let ny = grid.sums.len() / grid.nx;
            sc.across.clear();
            sc.across.resize(ny * 3 * stride, 0.0);
            for (c, nodes) in grid.sums.chunks_exact(grid.nx).enumerate() {
                for m in 0..3 {
                    let row = &mut sc.across[(c * 3 + m) * stride..(c * 3 + m + 1) * stride];
                    for (cell, w) in row.chunks_exact_mut(GRID as usize).zip(nodes.windows(2)) {
                        let (a, d) = (w[0][m], w[1][m] - w[0][m]);
                        for (o, f) in cell.iter_mut().zip(FRACTIONS) {
                            *o = a + d * f;
                        }
                    }
                }
            }
        }
        for j in b.y1..b.y2 {
            sc.ys.fill(self.centre(b.x1, j).1);
            if grid.is_some() {
                let dy = (j - b.y1) as usize;
                let (c, f) = (
                    dy / GRID as usize,
                    (dy % GRID as usize) as f32 / GRID as f32,
                );
                for (m, far) in sc.far.iter_mut().enumerate() {
                    let lo = &sc.across[(c * 3 + m) * stride..(c * 3 + m + 1) * stride];
                    let hi = &sc.across[((c + 1) * 3 + m) * stride..((c + 1) * 3 + m + 1) * stride];
                    for ((o, a), b) in far.iter_mut().zip(lo).zip(hi) {
                        *o = a + (b - a) * f;
                    }
                }
            }
            let far = &sc.far;
            let lanes = |k: usize| {
                let lane = |m: usize| f32x8::new(far[m][k..k + 8].try_into().expect("8 lanes"));
                Sums {
                    x: lane(0),
                    y: lane(1),
                    w: lane(2),
                }
            };
            lines.map_points_plus(&sc.xs, &sc.ys, lanes, &mut sc.ox, &mut sc.oy);
            for (o, (x, y)) in self.row_mut(j).iter_mut().zip(sc.ox.iter().zip(&sc.oy)) {
                *o = [*x, *y];
            }
        }
        *self.scratch = sc;
    }

    /// Compares the block with the exact map at the centres of every other
    /// grid cell (where bilinear interpolation errs most).
    fn checks_pass(&mut self, tol: [f32; 2]) -> bool {
        let b = self.block;
        let mut pixels = Vec::new();
        let mut j = b.y1 + GRID / 2;
        while j < b.y2 {
            let mut i = b.x1 + GRID / 2;
            while i < b.x2 {
                pixels.push((i, j));
                i += 2 * GRID;
            }
            j += 2 * GRID;
        }
        let (xs, ys): (Vec<f32>, Vec<f32>) = pixels.iter().map(|&(i, j)| self.centre(i, j)).unzip();
        let (mut ox, mut oy) = (vec![0f32; xs.len()], vec![0f32; xs.len()]);
        self.warp.kernel.map_points(&xs, &ys, &mut ox, &mut oy);
        pixels.iter().enumerate().all(|(k, &(i, j))| {
            let got = self.row_mut(j)[(i - b.x1) as usize];
            (got[0] - ox[k]).abs() <= tol[0] && (got[1] - oy[k]).abs() <= tol[1]
        })
    }
}

/// Far-field sums on a grid of `nx` nodes per row.
struct Grid {
    nx: usize,
    sums: Vec<[f32; 3]>,
}

/// Whether segment `p→q` comes within [`NEAR`] of the box `[lo, hi]`. Most
/// lines are far from most blocks, and their bounding boxes say so without
/// the exact distance.
#[inline]
fn is_near(p: Vec2, q: Vec2, lo: Vec2, hi: Vec2) -> bool {
    let gap_x = (lo.x - p.x.max(q.x)).max(p.x.min(q.x) - hi.x);
    let gap_y = (lo.y - p.y.max(q.y)).max(p.y.min(q.y) - hi.y);
    if gap_x >= NEAR || gap_y >= NEAR {
        return false;
    }
    segment_box_distance(p, q, lo, hi) < NEAR
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
