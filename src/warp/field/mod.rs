//! Beier-Neely field warping (Beier-Neely §3): every directed line pair pulls
//! nearby pixels along with it, weighted by eq. (4).

mod kernel;
mod lines;
mod redo;
pub mod split;
pub mod weight;

pub use lines::{interpolate_line, line_pairs_toward, LinePair};
pub use redo::FieldMap;

use crate::choice::Choice;
use crate::features::{Feature, Side, Tween};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::Warp;
use weight::Weight;

/// How lines move from their A to their B position over `t` (Beier-Neely §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LineInterpolation {
    /// Endpoints move on straight paths (a rotating line shrinks mid-way).
    #[default]
    Endpoints,
    /// Centre, orientation and length are interpolated (rotating lines keep length).
    CenterAngle,
}

impl Choice for LineInterpolation {
    const ALL: &'static [Self] = &[LineInterpolation::Endpoints, LineInterpolation::CenterAngle];
    fn name(self) -> &'static str {
        match self {
            LineInterpolation::Endpoints => "endpoints",
            LineInterpolation::CenterAngle => "center-angle",
        }
    }
}

/// How the field is evaluated over an image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Evaluation {
    /// Eq. (1)–(4) at every pixel.
    Exact,
    /// A coarse grid refined where bilinear interpolation would err by more
    /// than `tolerance` pixels ([`split`]).
    Adaptive {
        /// Largest interpolation error allowed (output px).
        tolerance: f64,
    },
}

impl Evaluation {
    /// The adaptive evaluation's default tolerance (px).
    pub const DEFAULT_TOLERANCE: f64 = 0.05;
}

impl Default for Evaluation {
    fn default() -> Self {
        Evaluation::Adaptive {
            tolerance: Self::DEFAULT_TOLERANCE,
        }
    }
}

/// Beier-Neely field warp settings (scene key `field`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldSettings {
    /// Eq. (4) `a`: barely above zero pins pixels on a line exactly to it.
    pub a: f64,
    /// Eq. (4) `b`: how fast a line's influence falls off with distance.
    pub b: f64,
    /// Eq. (4) `p`: how much longer lines outweigh shorter ones.
    pub p: f64,
    /// How the in-between lines are made from A's and B's.
    pub interpolation: LineInterpolation,
    /// Exact or adaptive evaluation.
    pub evaluation: Evaluation,
    /// Line segments per Catmull-Rom span when a curve feature becomes lines.
    pub curve_samples: usize,
}

impl Default for FieldSettings {
    fn default() -> Self {
        FieldSettings {
            a: 0.001,
            b: 2.0,
            p: 0.5,
            interpolation: LineInterpolation::Endpoints,
            evaluation: Evaluation::default(),
            curve_samples: 8,
        }
    }
}

/// A field warp: the reverse map defined by line pairs (destination lines in
/// the output, source lines in the image being warped).
#[derive(Debug, Clone)]
pub struct FieldWarp {
    pairs: Vec<LinePair>,
    weight: Weight,
    evaluation: Evaluation,
    kernel: kernel::Lines,
    identity: bool,
}

impl FieldWarp {
    /// The warp defined by `pairs` with `settings`' weights.
    pub fn new(pairs: Vec<LinePair>, settings: &FieldSettings) -> Self {
        let weight = Weight::new(settings.a, settings.b, settings.p);
        let identity = pairs.iter().all(|l| l.dst == l.src);
        let kernel = kernel::Lines::new(&pairs, &weight);
        FieldWarp {
            pairs,
            weight,
            evaluation: settings.evaluation,
            kernel,
            identity,
        }
    }

    /// The warp of the image on `side` toward the features' positions at `t`
    /// (output lines at `t`, source lines on that side).
    pub fn toward<'a>(
        features: &[Feature],
        side: Side,
        t: impl Into<Tween<'a>>,
        settings: &FieldSettings,
    ) -> Self {
        FieldWarp::new(
            line_pairs_toward(features, side, t.into(), settings),
            settings,
        )
    }

    /// The line pairs.
    pub fn pairs(&self) -> &[LinePair] {
        &self.pairs
    }

    /// Eq. (1)–(4) and the multiple-line algorithm exactly as written, in f64:
    /// the reference the vector kernel and the adaptive mode are held to.
    pub fn map_reference(&self, x: Vec2) -> Vec2 {
        let mut dsum = Vec2::ZERO;
        let mut weight_sum = 0.0;
        for pair in &self.pairs {
            let (p, q) = (pair.dst.0, pair.dst.1);
            let (ps, qs) = (pair.src.0, pair.src.1);
            let d = q - p;
            let u = (x - p).dot(d) / d.length_squared(); // (1)
            let v = (x - p).dot(d.perp()) / d.length(); // (2)
            let ds = qs - ps;
            let xs = ps + ds * u + ds.perp() * (v / ds.length()); // (3)
                                                                  // Distance to the directed segment (footnote to §3.3).
            let dist = if u < 0.0 {
                (x - p).length()
            } else if u > 1.0 {
                (x - q).length()
            } else {
                v.abs()
            };
            let w = self.weight.of(d.length(), dist); // (4)
            dsum += (xs - x) * w;
            weight_sum += w;
        }
        if weight_sum > 0.0 && weight_sum.is_finite() {
            x + dsum / weight_sum
        } else {
            x
        }
    }
}

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
