//! Beier-Neely field warping (Beier-Neely §3): every directed line pair pulls
//! nearby pixels along with it, weighted by eq. (4).

mod grid;
mod kernel;
mod lines;
mod redo;
mod settings;
pub mod split;
mod warp;
pub mod weight;

pub use lines::{interpolate_line, line_pairs_toward, LinePair};
pub use redo::FieldMap;
pub use settings::{Evaluation, FieldSettings, LineInterpolation};
pub use warp::FieldWarp;

use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::Warp;

impl Warp for FieldWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        if self.identity {
            return p;
        }
        self.map_reference(p)
    }

    fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        if self.identity {
            out_x.copy_from_slice(xs);
            out_y.copy_from_slice(ys);
            return;
        }
        self.kernel.map_points(xs, ys, out_x, out_y);
    }

    fn is_identity(&self) -> bool {
        self.identity
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        match self.evaluation {
            _ if self.identity => WarpMap::identity(window, scale),
            Evaluation::Exact => exact_map_window(self, window, scale),
            Evaluation::Adaptive { tolerance } => split::map_window(self, window, scale, tolerance),
        }
    }
}

/// The trait's default dense evaluation, reachable from an override.
fn exact_map_window(warp: &FieldWarp, window: RectI, scale: PixelScale) -> WarpMap {
    struct Exact<'a>(&'a FieldWarp);
    impl Warp for Exact<'_> {
        fn map(&self, p: Vec2) -> Vec2 {
            self.0.map(p)
        }
        fn map_points(&self, xs: &[f32], ys: &[f32], ox: &mut [f32], oy: &mut [f32]) {
            self.0.map_points(xs, ys, ox, oy)
        }
    }
    Exact(warp).map_window(window, scale)
}

#[cfg(test)]
mod redo_tests;
#[cfg(test)]
mod tests;
