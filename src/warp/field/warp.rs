//! The field warp itself: line pairs and their weights, and the reference
//! evaluation of eq. (1)–(4) that the vector kernel and the adaptive
//! evaluation are held to.

use super::kernel::Lines;
use super::lines::{line_pairs_toward, LinePair};
use super::settings::{Evaluation, FieldSettings};
use super::weight::Weight;
use crate::features::{Feature, Side, Tween};
use crate::geom::Vec2;

/// A field warp: the reverse map defined by line pairs (destination lines in
/// the output, source lines in the image being warped).
#[derive(Debug, Clone)]
pub struct FieldWarp {
    pub(super) pairs: Vec<LinePair>,
    pub(super) weight: Weight,
    pub(super) evaluation: Evaluation,
    pub(super) kernel: Lines,
    pub(super) identity: bool,
}

impl FieldWarp {
    /// The warp defined by `pairs` with `settings`' weights.
    pub fn new(pairs: Vec<LinePair>, settings: &FieldSettings) -> Self {
        let weight = Weight::new(settings.a, settings.b, settings.p);
        let identity = pairs.iter().all(|l| l.dst == l.src);
        let kernel = Lines::new(&pairs, &weight);
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
