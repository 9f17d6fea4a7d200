//! One warp abstraction for every method: a reverse map from output positions
//! to source positions (canonical coordinates), plus dense evaluation over a
//! window of pixels (docs/architecture.md, "Layers").

pub mod auto;
pub mod field;
pub mod hybrid;
mod invert;

pub use invert::invert;
pub mod mesh;
pub mod mffd;
pub mod node_grid;
pub mod thin_plate;
pub mod triangles;

#[cfg(test)]
mod scattered_tests;

use rayon::prelude::*;

use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;

/// A reverse map: where each output point samples its source.
pub trait Warp: Send + Sync {
    /// Where output position `p` samples the source (canonical coordinates).
    fn map(&self, p: Vec2) -> Vec2;

    /// Map many points at once. The default calls [`Warp::map`]; generators
    /// with a vector kernel override it.
    fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        for i in 0..xs.len() {
            let q = self.map(Vec2::new(xs[i] as f64, ys[i] as f64));
            out_x[i] = q.x as f32;
            out_y[i] = q.y as f32;
        }
    }

    /// True when the warp maps every point to itself, so resampling can be
    /// skipped and the source copied bit for bit.
    fn is_identity(&self) -> bool {
        false
    }

    /// The map at the centres of the pixels of `window` (pixels at `scale`),
    /// evaluated exactly, in parallel over rows.
    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.is_identity() {
            return WarpMap::identity(window, scale);
        }
        let w = window.width();
        let mut pos = vec![[0f32; 2]; window.area()];
        if w > 0 {
            pos.par_chunks_mut(w).enumerate().for_each_init(
                || (vec![0f32; w], vec![0f32; w], vec![0f32; w], vec![0f32; w]),
                |(xs, ys, ox, oy), (row, out)| {
                    let j = window.y1 + row as i32;
                    for (k, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
                        let c = scale.pixel_centre(window.x1 + k as i32, j);
                        *x = c.x as f32;
                        *y = c.y as f32;
                    }
                    self.map_points(xs, ys, ox, oy);
                    for (o, (x, y)) in out.iter_mut().zip(ox.iter().zip(oy.iter())) {
                        *o = [*x, *y];
                    }
                },
            );
        }
        WarpMap::new(window, scale, pos)
    }
}

/// The warp that maps every point to itself.
#[derive(Debug, Clone, Copy, Default)]
pub struct Identity;

impl Warp for Identity {
    fn map(&self, p: Vec2) -> Vec2 {
        p
    }
    fn is_identity(&self) -> bool {
        true
    }
}
