//! Adaptive evaluation of a smooth warp: evaluate on a coarse grid of pixel
//! centres, check each cell's bilinear interpolant against the exact map at
//! its centre and edge midpoints, and split cells that err by more than the
//! tolerance (or that touch a crease, such as a field line) down to single
//! pixels, which are evaluated exactly.
//!
//! Work is batched level by level so the warp's vector kernel sees long runs
//! of points, and bands of cells are independent, so they run in parallel.

use rayon::prelude::*;

use super::{Warp, WarpMap};
use crate::geom::{PixelScale, RectI, Vec2};

/// Side of the coarsest cells, in pixels (a power of two).
const COARSE: i32 = 16;
/// Interpolation errors are checked at a few points only; demand this share of
/// the tolerance there so the unchecked points stay within the whole of it.
const SAFETY: f64 = 0.25;

#[derive(Clone, Copy)]
struct Cell {
    x0: i32,
    y0: i32,
    size: i32,
    /// Map at the corners: (x0,y0), (x0+s,y0), (x0,y0+s), (x0+s,y0+s).
    corners: [[f32; 2]; 4],
}

/// The map over `window` within `tolerance` pixels (at `scale`) of the exact
/// map; `creases` are segments (canonical) near which cells always refine.
pub fn map_window(
    warp: &dyn Warp,
    window: RectI,
    scale: PixelScale,
    tolerance: f64,
    creases: &[(Vec2, Vec2)],
) -> WarpMap {
    let (w, h) = (window.width(), window.height());
    let mut pos = vec![[0f32; 2]; w * h];
    if w == 0 || h == 0 {
        return WarpMap::new(window, scale, pos);
    }
    // Creases in this window's pixel space.
    let creases: Vec<(Vec2, Vec2)> = creases
        .iter()
        .map(|(p, q)| (scale.to_pixel(*p), scale.to_pixel(*q)))
        .collect();
    let tol_px = [
        tolerance * SAFETY / scale.x.max(1e-9),
        tolerance * SAFETY / scale.y.max(1e-9),
    ];
    let band_rows = COARSE as usize * w;
    pos.par_chunks_mut(band_rows)
        .enumerate()
        .for_each(|(band, out)| {
            let y0 = window.y1 + band as i32 * COARSE;
            Band {
                warp,
                window,
                scale,
                tol: tol_px,
                creases: &creases,
                out,
                y0,
            }
            .fill();
        });
    WarpMap::new(window, scale, pos)
}

struct Band<'a> {
    warp: &'a dyn Warp,
    window: RectI,
    scale: PixelScale,
    /// Allowed error at check points, canonical units per axis.
    tol: [f64; 2],
    creases: &'a [(Vec2, Vec2)],
    out: &'a mut [[f32; 2]],
    y0: i32,
}

impl Band<'_> {
    fn fill(&mut self) {
        let nx = (self.window.width() as i32 + COARSE - 1) / COARSE;
        // Coarse grid nodes on the band's bottom and top edges.
        let mut nodes = Vec::with_capacity(2 * (nx as usize + 1));
        for row in [0, COARSE] {
            for c in 0..=nx {
                nodes.push((self.window.x1 + c * COARSE, self.y0 + row));
            }
        }
        let values = self.eval(&nodes);
        let stride = nx as usize + 1;
        let mut cells: Vec<Cell> = (0..nx as usize)
            .map(|c| Cell {
                x0: self.window.x1 + c as i32 * COARSE,
                y0: self.y0,
                size: COARSE,
                corners: [
                    values[c],
                    values[c + 1],
                    values[stride + c],
                    values[stride + c + 1],
                ],
            })
            .collect();

        while !cells.is_empty() {
            // Check points: centre, bottom, top, left, right midpoints.
            let mut checks = Vec::with_capacity(cells.len() * 5);
            for c in &cells {
                let h = c.size / 2;
                checks.extend([
                    (c.x0 + h, c.y0 + h),
                    (c.x0 + h, c.y0),
                    (c.x0 + h, c.y0 + c.size),
                    (c.x0, c.y0 + h),
                    (c.x0 + c.size, c.y0 + h),
                ]);
            }
            let exact = self.eval(&checks);
            let mut next = Vec::new();
            let mut leaves = Vec::new();
            for (c, e) in cells.iter().zip(exact.chunks_exact(5)) {
                let [c00, c10, c01, c11] = c.corners;
                let mid = |p: [f32; 2], q: [f32; 2]| [(p[0] + q[0]) * 0.5, (p[1] + q[1]) * 0.5];
                let predicted = [
                    mid(mid(c00, c10), mid(c01, c11)),
                    mid(c00, c10),
                    mid(c01, c11),
                    mid(c00, c01),
                    mid(c10, c11),
                ];
                let smooth = predicted.iter().zip(e).all(|(p, q)| {
                    ((p[0] - q[0]) as f64).abs() <= self.tol[0]
                        && ((p[1] - q[1]) as f64).abs() <= self.tol[1]
                });
                if smooth && !self.touches_crease(c) {
                    self.interpolate(c);
                } else if c.size <= 2 {
                    leaves.push(*c);
                } else {
                    let h = c.size / 2;
                    let [m, b, t, l, r] = [e[0], e[1], e[2], e[3], e[4]];
                    for (dx, dy, corners) in [
                        (0, 0, [c00, b, l, m]),
                        (h, 0, [b, c10, m, r]),
                        (0, h, [l, m, c01, t]),
                        (h, h, [m, r, t, c11]),
                    ] {
                        next.push(Cell {
                            x0: c.x0 + dx,
                            y0: c.y0 + dy,
                            size: h,
                            corners,
                        });
                    }
                }
            }
            self.exact_leaves(&leaves);
            cells = next;
        }
    }

    /// The exact map at pixel centres `(i, j)`.
    fn eval(&self, pixels: &[(i32, i32)]) -> Vec<[f32; 2]> {
        let (mut xs, mut ys): (Vec<f32>, Vec<f32>) = pixels
            .iter()
            .map(|&(i, j)| {
                let c = self.scale.pixel_centre(i, j);
                (c.x as f32, c.y as f32)
            })
            .unzip();
        let (mut ox, mut oy) = (vec![0f32; xs.len()], vec![0f32; xs.len()]);
        self.warp.map_points(&xs, &ys, &mut ox, &mut oy);
        xs.clear();
        ys.clear();
        ox.into_iter().zip(oy).map(|(x, y)| [x, y]).collect()
    }

    fn set(&mut self, i: i32, j: i32, v: [f32; 2]) {
        let w = &self.window;
        if i >= w.x1 && i < w.x2 && j >= w.y1 && j < w.y2 && j >= self.y0 && j < self.y0 + COARSE {
            let k = (j - self.y0) as usize * w.width() + (i - w.x1) as usize;
            self.out[k] = v;
        }
    }

    fn interpolate(&mut self, c: &Cell) {
        let [c00, c10, c01, c11] = c.corners;
        let s = c.size as f32;
        for dy in 0..c.size {
            let fy = dy as f32 / s;
            for dx in 0..c.size {
                let fx = dx as f32 / s;
                let lerp = |k: usize| {
                    let bottom = c00[k] + (c10[k] - c00[k]) * fx;
                    let top = c01[k] + (c11[k] - c01[k]) * fx;
                    bottom + (top - bottom) * fy
                };
                self.set(c.x0 + dx, c.y0 + dy, [lerp(0), lerp(1)]);
            }
        }
    }

    fn exact_leaves(&mut self, leaves: &[Cell]) {
        let mut pixels = Vec::with_capacity(leaves.len() * 4);
        for c in leaves {
            for dy in 0..c.size {
                for dx in 0..c.size {
                    pixels.push((c.x0 + dx, c.y0 + dy));
                }
            }
        }
        let values = self.eval(&pixels);
        for (&(i, j), v) in pixels.iter().zip(values) {
            self.set(i, j, v);
        }
    }

    /// Whether a crease segment passes within a pixel of the cell (pixel-centre
    /// coordinates: the cell spans centres x0+0.5 ..= x0+size+0.5).
    fn touches_crease(&self, c: &Cell) -> bool {
        let (lo_x, lo_y) = (c.x0 as f64 - 0.5, c.y0 as f64 - 0.5);
        let (hi_x, hi_y) = (lo_x + c.size as f64 + 2.0, lo_y + c.size as f64 + 2.0);
        self.creases
            .iter()
            .any(|(p, q)| segment_hits_box(*p, *q, (lo_x, lo_y), (hi_x, hi_y)))
    }
}

/// Liang-Barsky clip of segment `p→q` against an axis-aligned box.
fn segment_hits_box(p: Vec2, q: Vec2, lo: (f64, f64), hi: (f64, f64)) -> bool {
    let d = q - p;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (pd, dd, l, h) in [(p.x, d.x, lo.0, hi.0), (p.y, d.y, lo.1, hi.1)] {
        if dd == 0.0 {
            if pd < l || pd > h {
                return false;
            }
            continue;
        }
        let (mut a, mut b) = ((l - pd) / dd, (h - pd) / dd);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
        if t0 > t1 {
            return false;
        }
    }
    true
}
