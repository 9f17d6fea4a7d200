//! Displacements on a regular grid of nodes, bilinear between them: how the
//! thin plate is discretised, and how MFFD's composed deformations reach every
//! pixel without composing at every pixel (Lee, Wolberg et al. §5.6).

use rayon::prelude::*;

use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;

/// Displacements at the nodes of a regular grid, bilinear between them.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeGrid {
    /// Canonical position of node (0, 0).
    pub origin: Vec2,
    /// Canonical spacing of the nodes in x and y.
    pub step: Vec2,
    /// Nodes in x.
    pub nx: usize,
    /// Nodes in y.
    pub ny: usize,
    /// Displacement (source − position) per node, row-major.
    pub disp: Vec<Vec2>,
}

impl NodeGrid {
    /// Nodes over `[min, max]` (at least 2 × 2), displacements zero.
    pub fn covering(min: Vec2, max: Vec2, step: Vec2) -> NodeGrid {
        let n = |a: f64, b: f64, s: f64| ((b - a) / s).ceil().max(1.0) as usize + 1;
        let (nx, ny) = (n(min.x, max.x, step.x), n(min.y, max.y, step.y));
        NodeGrid {
            origin: min,
            step,
            nx,
            ny,
            disp: vec![Vec2::ZERO; nx * ny],
        }
    }

    /// Canonical position of node `(i, j)`.
    #[inline]
    pub fn node(&self, i: usize, j: usize) -> Vec2 {
        Vec2::new(
            self.origin.x + i as f64 * self.step.x,
            self.origin.y + j as f64 * self.step.y,
        )
    }

    /// Fills every node's displacement from `f`, which maps a row of node
    /// positions in place (a row at a time, so a map made of stages can run
    /// each stage over the whole row); rows in parallel.
    pub fn fill_rows(&mut self, f: impl Fn(&mut [Vec2]) + Sync) {
        let (nx, origin, step) = (self.nx, self.origin, self.step);
        self.disp
            .par_chunks_mut(nx)
            .enumerate()
            .for_each(|(j, row)| {
                let node = |i: usize| {
                    Vec2::new(origin.x + i as f64 * step.x, origin.y + j as f64 * step.y)
                };
                for (i, d) in row.iter_mut().enumerate() {
                    *d = node(i);
                }
                f(row);
                for (i, d) in row.iter_mut().enumerate() {
                    *d = *d - node(i);
                }
            });
    }

    /// Cell and weights of `p`, clamped to the grid (beyond it the edge
    /// displacement holds).
    #[inline]
    fn locate(&self, p: Vec2) -> (usize, usize, f64, f64) {
        let axis = |v: f64, o: f64, s: f64, n: usize| {
            let u = ((v - o) / s).clamp(0.0, (n - 1) as f64);
            let c = (u.floor() as usize).min(n - 2);
            (c, u - c as f64)
        };
        let (i, fx) = axis(p.x, self.origin.x, self.step.x, self.nx);
        let (j, fy) = axis(p.y, self.origin.y, self.step.y, self.ny);
        (i, j, fx, fy)
    }

    /// The bilinear displacement at `p`.
    pub fn displacement(&self, p: Vec2) -> Vec2 {
        let (i, j, fx, fy) = self.locate(p);
        let d = |i: usize, j: usize| self.disp[j * self.nx + i];
        let bottom = d(i, j) * (1.0 - fx) + d(i + 1, j) * fx;
        let top = d(i, j + 1) * (1.0 - fx) + d(i + 1, j + 1) * fx;
        bottom * (1.0 - fy) + top * fy
    }

    /// `p` plus its displacement: the source position a reverse map reads.
    pub fn map(&self, p: Vec2) -> Vec2 {
        p + self.displacement(p)
    }

    /// The map at the pixel centres of `window` (the x weights of each column
    /// and the y weights of each row computed once).
    pub fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        let w = window.width();
        let columns: Vec<(f64, usize, f64)> = (0..w)
            .map(|k| {
                let p = scale.pixel_centre(window.x1 + k as i32, window.y1);
                let (i, _, fx, _) = self.locate(p);
                (p.x, i, fx)
            })
            .collect();
        let mut pos = vec![[0f32; 2]; window.area()];
        if w > 0 {
            pos.par_chunks_mut(w).enumerate().for_each(|(row, out)| {
                let y = scale.pixel_centre(window.x1, window.y1 + row as i32).y;
                let (_, j, _, fy) = self.locate(Vec2::new(self.origin.x, y));
                let (lo, hi) = (
                    &self.disp[j * self.nx..(j + 1) * self.nx],
                    &self.disp[(j + 1) * self.nx..(j + 2) * self.nx],
                );
                for (o, &(x, i, fx)) in out.iter_mut().zip(&columns) {
                    let b = lo[i] * (1.0 - fx) + lo[i + 1] * fx;
                    let t = hi[i] * (1.0 - fx) + hi[i + 1] * fx;
                    let d = b * (1.0 - fy) + t * fy;
                    *o = [(x + d.x) as f32, (y + d.y) as f32];
                }
            });
        }
        WarpMap::new(window, scale, pos)
    }
}
