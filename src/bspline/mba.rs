//! Multilevel B-spline interpolation (Lee, Wolberg et al. §6.2): a coarse lattice
//! catches the overall shape, each finer one the deviations the coarser left.
//! Unlike MFFD nothing is truncated, so each lattice is fitted once.
//!
//! The levels are summed by refining the running sum onto the next lattice
//! (B-spline subdivision is exact), so the result is one lattice and costs
//! 16 taps per evaluation however many levels it took.

use super::{Approximation, Lattice};
use crate::geom::Vec2;

/// Multilevel B-spline approximation settings (Lee, Wolberg et al. §6.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MbaSettings {
    /// Cells of the coarsest lattice across the longer side of the domain
    /// (seed: a 5 × 5 control lattice, two cells). Fewer cells, broader hills.
    pub coarsest: usize,
    /// Stop once every point is within this of its value.
    pub threshold: f64,
    /// The finest lattice spacing allowed (canonical pixels).
    pub finest: f64,
}

impl Default for MbaSettings {
    fn default() -> Self {
        MbaSettings {
            coarsest: 2,
            threshold: 1e-3,
            finest: 2.0,
        }
    }
}

/// An interpolating surface and how well it met its points.
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    /// The sum of every level's lattice, refined into one.
    pub lattice: Lattice,
    /// Largest `|f(p) − value|` over the points.
    pub error: f64,
    /// Lattices fitted (coarsest first).
    pub levels: usize,
}

impl Surface {
    /// The surface's value at `p`.
    pub fn eval(&self, p: Vec2) -> f64 {
        self.lattice.eval(p)
    }
}

/// The C² surface through `points` (`(position, value)`) over `[min, max]`.
pub fn interpolate(points: &[(Vec2, f64)], min: Vec2, max: Vec2, s: &MbaSettings) -> Surface {
    let extent = (max.x - min.x).max(max.y - min.y).max(1.0);
    let h0 = extent / s.coarsest.max(1) as f64;
    let mut total = Lattice::covering(min, max, h0);
    let mut residual: Vec<f64> = points.iter().map(|(_, v)| *v).collect();
    let worst = |r: &[f64]| r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut levels = 0;
    loop {
        if worst(&residual) <= s.threshold {
            break;
        }
        if levels > 0 {
            if total.h / 2.0 < s.finest {
                break;
            }
            total = total.refined();
        }
        let mut fit = Approximation::new(&total);
        for ((p, _), r) in points.iter().zip(&residual) {
            fit.add(*p, Vec2::new(*r, 0.0));
        }
        let (level, _) = fit.finish(None);
        for ((p, _), r) in points.iter().zip(residual.iter_mut()) {
            *r -= level.eval(*p);
        }
        total.add(&level);
        levels += 1;
    }
    Surface {
        error: worst(&residual),
        lattice: total,
        levels,
    }
}
