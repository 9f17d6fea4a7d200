//! Snakes for feature placement (Lee, Wolberg et al. §4.1–4.2): a polyline or curve is
//! sampled into points that slither toward nearby edges under image forces
//! while a thin-plate bending energy keeps them smooth.
//!
//! `E = ∫ β |v''|² + E_image`, with `E_image = −|G_σ ∗ ∇I|²` (Gaussian-smoothed
//! Sobel gradient magnitude, squared). Discretised by finite differences and
//! iterated semi-implicitly (Kass et al.): `(A + Γ) x_t = Γ x_{t−1} + κ F(x_{t−1})`
//! where `A` is the bending matrix, `Γ` the per-point step weights (clamped
//! points get a huge one, seed §4.2) and `F = −∇E_image`.

mod energy;
mod solve;

pub use energy::EdgeEnergy;

use crate::features::{sample_points, FeatureKind};
use crate::geom::Vec2;

/// How a snake moves (defaults suit edges a few pixels away at 1080p).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SnakeSettings {
    /// Bending stiffness β of the thin-plate term.
    pub beta: f64,
    /// Image force weight κ, pixels per unit of normalised force.
    pub kappa: f64,
    /// Step weight γ (viscosity): larger moves less per iteration.
    pub gamma: f64,
    /// Iterations of the energy minimisation loop.
    pub iterations: usize,
    /// Points sampled per polyline segment or curve span (seed: 20).
    pub samples_per_segment: usize,
    /// Keep the samples on the primitive's control points still.
    pub clamp_controls: bool,
}

impl Default for SnakeSettings {
    fn default() -> Self {
        SnakeSettings {
            beta: 0.5,
            kappa: 4.0,
            gamma: 1.0,
            iterations: 200,
            samples_per_segment: crate::features::DEFAULT_SAMPLES_PER_SEGMENT,
            clamp_controls: false,
        }
    }
}

/// The step weight of a clamped point: it cannot move.
const CLAMPED: f64 = 1e12;

/// A snake made from a primitive: its sampled points, which of them are the
/// primitive's control points, and which are held still.
#[derive(Debug, Clone, PartialEq)]
pub struct Snake {
    /// The sampled points, in order along the primitive.
    pub points: Vec<Vec2>,
    /// Index in `points` of each control point of the primitive.
    pub controls: Vec<usize>,
    /// Points held still (seed §4.2: "the user may clamp any of the sampled
    /// points"); set any of them before [`Snake::run`].
    pub clamped: Vec<bool>,
}

impl Snake {
    /// Samples a polyline or curve `per_segment` times per span (seed §4.2).
    pub fn from_primitive(kind: FeatureKind, controls: &[Vec2], settings: &SnakeSettings) -> Snake {
        let per = settings.samples_per_segment.max(1);
        let points = sample_points(kind, false, controls, per);
        let controls: Vec<usize> = match kind {
            FeatureKind::Polyline | FeatureKind::Curve => {
                (0..controls.len()).map(|k| k * per).collect()
            }
            FeatureKind::Point | FeatureKind::Line => (0..controls.len()).collect(),
        };
        let mut clamped = vec![false; points.len()];
        if settings.clamp_controls {
            for &k in &controls {
                clamped[k] = true;
            }
        }
        Snake {
            points,
            controls,
            clamped,
        }
    }

    /// `settings.iterations` steps of the minimisation loop on `energy`.
    pub fn run(&mut self, energy: &EdgeEnergy, settings: &SnakeSettings) {
        let n = self.points.len();
        if n == 0 {
            return;
        }
        let gamma: Vec<f64> = self
            .clamped
            .iter()
            .map(|&c| if c { CLAMPED } else { settings.gamma })
            .collect();
        let system = solve::Banded::bending(n, settings.beta, &gamma);
        let (mut bx, mut by) = (vec![0.0; n], vec![0.0; n]);
        for _ in 0..settings.iterations {
            for (k, p) in self.points.iter().enumerate() {
                let f = if self.clamped[k] {
                    Vec2::default()
                } else {
                    energy.force(*p)
                };
                bx[k] = gamma[k] * p.x + settings.kappa * f.x;
                by[k] = gamma[k] * p.y + settings.kappa * f.y;
            }
            system.solve(&mut bx);
            system.solve(&mut by);
            for (k, p) in self.points.iter_mut().enumerate() {
                if !self.clamped[k] {
                    *p = Vec2::new(bx[k], by[k]);
                }
            }
        }
    }

    /// Unsnake (seed §4.2): the primitive's control points taken back from
    /// the snake points that correspond to them.
    pub fn unsnake(&self) -> Vec<Vec2> {
        self.controls.iter().map(|&k| self.points[k]).collect()
    }
}

#[cfg(test)]
mod tests;
