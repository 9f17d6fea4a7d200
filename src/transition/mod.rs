//! Transition control (Lee, Wolberg et al. §3 and §6, Lee et al. §3.3): how fast each
//! point of A travels toward its place on B (geometry) and how fast its colour
//! gives way to B's (colour), as a rate `T0(p; t) ∈ [0, 1]` per point of A.
//!
//! A rate comes from transition curves attached to features or points of A,
//! propagated over the image by multilevel B-spline interpolation (or by the
//! thin plate), or from a procedural pattern. On B the rate is `T1(q; t) =
//! T0(W1(q); t)`, `W1` the warp that carries B onto A, so both images agree
//! on every pair of corresponding points.

pub mod curve;
pub mod matte;
pub mod pace;
pub mod procedural;

use std::sync::Arc;

use rayon::prelude::*;

use crate::bspline::mba::{self, MbaSettings};
use crate::bspline::Lattice;
use crate::error::{Error, Result};
use crate::features::{Feature, Side};
use crate::geom::{RectD, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::node_grid::NodeGrid;
use crate::warp::thin_plate::{ThinPlate, ThinPlateSettings};
use crate::warp::Warp;
pub use curve::Curve;
pub use matte::Matte;
pub use procedural::{Pattern, Procedural};

/// Where a transition curve is attached on A.
#[derive(Debug, Clone, PartialEq)]
pub enum Attach {
    /// Every point of the feature with this name shares the curve.
    Name(String),
    /// Every point of the feature at this index of the feature list.
    Index(usize),
    /// One point (canonical, on A).
    At(Vec2),
}

/// A transition curve and the feature points it applies to.
#[derive(Debug, Clone, PartialEq)]
pub struct Attached {
    /// Which points.
    pub attach: Attach,
    /// Their rate over progress.
    pub curve: Curve,
}

/// How the curves' rates spread over the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Propagation {
    /// Multilevel B-spline interpolation (Lee, Wolberg et al. §6.2): C².
    BSpline(MbaSettings),
    /// The thin plate (Lee et al. §3.3): C¹.
    ThinPlate(ThinPlateSettings),
}

impl Default for Propagation {
    fn default() -> Self {
        Propagation::BSpline(MbaSettings::default())
    }
}

/// How each point's rate of transition depends on the progress `t` (Lee et al. §4).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Transition {
    /// Every point at rate `t`.
    #[default]
    Uniform,
    /// Curves at feature points, spread over the image (Lee et al. §4.1).
    Curves {
        /// The curves and the points they are attached to.
        curves: Vec<Attached>,
        /// How the rates spread between the points.
        propagation: Propagation,
    },
    /// A pattern over the image, no features needed (Lee et al. §4.2).
    Procedural(Procedural),
    /// A timing matte: each point's turn is the matte's alpha there, paced
    /// as a pattern is.
    Matte {
        /// The matte, over A.
        matte: Arc<Matte>,
        /// The share of the progress over which the turns spread, `[0, 0.99]`.
        spread: f64,
    },
}

/// The geometry transition, and the colour one (`None`: the same as the
/// geometry, as Lee, Wolberg et al. §3 treats them).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TransitionSettings {
    /// The rates at which feature points move.
    pub geometry: Transition,
    /// The dissolve's rates; `None`: the geometry's.
    pub colour: Option<Transition>,
}

impl TransitionSettings {
    /// The colour transition in effect.
    pub fn colour(&self) -> &Transition {
        self.colour.as_ref().unwrap_or(&self.geometry)
    }
}

/// `T0(·; t)` at one instant: the rate of every point of A.
#[derive(Debug, Clone, PartialEq)]
pub enum Rates {
    /// Every point at rate `t`.
    Uniform(f64),
    /// A timing matte's turns at progress `t`.
    Matte {
        /// The matte, over A.
        matte: Arc<Matte>,
        /// The share of the progress the turns spread over.
        spread: f64,
        /// The progress.
        t: f64,
    },
    /// A procedural pattern over `frame` at progress `t`.
    Procedural {
        /// The pattern and its spread.
        procedural: Procedural,
        /// The frame the pattern covers (canonical).
        frame: RectD,
        /// The progress.
        t: f64,
    },
    /// `t + ΔT(p)`, `ΔT` a B-spline surface.
    Surface {
        /// The progress.
        t: f64,
        /// The offset surface `ΔT`.
        delta: Lattice,
    },
    /// `t + ΔT(p)`, `ΔT` a thin plate.
    Plate {
        /// The progress.
        t: f64,
        /// The offset `ΔT` at the plate's nodes (in `disp.x`).
        delta: NodeGrid,
    },
}

impl Rates {
    /// The rate of the point at `p` on A, in `[0, 1]`.
    #[inline]
    pub fn at(&self, p: Vec2) -> f64 {
        let r = match self {
            Rates::Uniform(t) => return *t,
            Rates::Procedural {
                procedural,
                frame,
                t,
            } => return procedural.rate(p, *frame, *t),
            Rates::Matte { matte, spread, t } => return pace::paced(matte.order(p), *t, *spread),
            Rates::Surface { t, delta } => t + delta.eval(p),
            Rates::Plate { t, delta } => t + delta.displacement(p).x,
        };
        r.clamp(0.0, 1.0)
    }

    /// The progress these rates are for.
    pub fn t(&self) -> f64 {
        match self {
            Rates::Uniform(t)
            | Rates::Matte { t, .. }
            | Rates::Procedural { t, .. }
            | Rates::Surface { t, .. }
            | Rates::Plate { t, .. } => *t,
        }
    }

    /// `Some(t)` when every point has rate `t`.
    pub fn uniform(&self) -> Option<f64> {
        match self {
            Rates::Uniform(t) => Some(*t),
            _ => None,
        }
    }
}

impl Transition {
    /// Whether every point is at rate `t` at progress `t`, known without
    /// computing any rate: uniform, the end frames, or a pattern of no spread.
    pub fn is_uniform_at(&self, t: f64) -> bool {
        t <= 0.0
            || t >= 1.0
            || match self {
                Transition::Uniform => true,
                Transition::Procedural(p) => p.spread == 0.0,
                Transition::Matte { spread, .. } => *spread == 0.0,
                Transition::Curves { .. } => false,
            }
    }

    /// The rates at progress `t` for the features of this frame (curves
    /// attached to features follow them; polylines and curves sampled
    /// `per_segment` times per span) over `frame` (canonical, A).
    pub fn rates(
        &self,
        features: &[Feature],
        per_segment: usize,
        frame: RectD,
        t: f64,
    ) -> Result<Rates> {
        if self.is_uniform_at(t) {
            return Ok(Rates::Uniform(t.clamp(0.0, 1.0)));
        }
        match self {
            Transition::Uniform => Ok(Rates::Uniform(t)),
            Transition::Procedural(procedural) => Ok(Rates::Procedural {
                procedural: *procedural,
                frame,
                t,
            }),
            Transition::Matte { matte, spread } => Ok(Rates::Matte {
                matte: matte.clone(),
                spread: *spread,
                t,
            }),
            Transition::Curves {
                curves,
                propagation,
            } => {
                let points = constraints(curves, features, per_segment, t)?;
                if points.iter().all(|(_, d)| *d == 0.0) {
                    return Ok(Rates::Uniform(t));
                }
                let area = frame.including(points.iter().map(|(p, _)| *p));
                let (min, max) = (Vec2::new(area.x1, area.y1), Vec2::new(area.x2, area.y2));
                Ok(match propagation {
                    Propagation::BSpline(s) => Rates::Surface {
                        t,
                        delta: mba::interpolate(&points, min, max, s).lattice,
                    },
                    Propagation::ThinPlate(s) => {
                        let pairs: Vec<(Vec2, Vec2)> = points
                            .iter()
                            .map(|(p, d)| (*p, *p + Vec2::new(*d, 0.0)))
                            .collect();
                        Rates::Plate {
                            t,
                            delta: ThinPlate::solve(&pairs, area, s, None).nodes,
                        }
                    }
                })
            }
        }
    }
}

/// The curves' points on A and what each asks of the surface, `C(t) − t`
/// (Lee et al. §3.3: `ΔT = C − t`, so `T0 = t + ΔT`).
pub fn constraints(
    curves: &[Attached],
    features: &[Feature],
    per_segment: usize,
    t: f64,
) -> Result<Vec<(Vec2, f64)>> {
    let mut points = Vec::new();
    for (k, c) in curves.iter().enumerate() {
        let delta = c.curve.at(t) - t;
        let feature = match &c.attach {
            Attach::At(p) => {
                points.push((*p, delta));
                continue;
            }
            Attach::Name(name) => features.iter().find(|f| f.name.as_deref() == Some(name)),
            Attach::Index(i) => features.get(*i),
        };
        let f = feature.ok_or_else(|| {
            Error::scene(
                format!("transition curves[{k}]"),
                format!("{:?}: no such feature in this frame", c.attach),
            )
        })?;
        points.extend(
            f.sampled(Side::A, per_segment)
                .into_iter()
                .map(|p| (p, delta)),
        );
    }
    Ok(points)
}

/// Per-pixel weights of the dissolve (Lee, Wolberg et al. §3): A's colour attenuated by
/// `1 − T0` at the point it comes from, B's by `T1 = T0 ∘ W1` at its point,
/// then scaled to sum to 1. The two points agree only where `W1` inverts the
/// warps exactly; elsewhere (any field warp) the paper's weights sum to a
/// little more or less than 1, which made opaque plates come out with
/// alpha 0.98 and bright seams where the rate changes fast.
#[derive(Debug, Clone, PartialEq)]
pub struct Weights {
    /// Output pixels covered.
    pub window: RectI,
    /// A's weight per pixel, rows bottom-up.
    pub a: Vec<f32>,
    /// B's weight per pixel, rows bottom-up.
    pub b: Vec<f32>,
}

impl Weights {
    /// Heap bytes held (for cache budgets).
    pub fn memory_bytes(&self) -> usize {
        (self.a.len() + self.b.len()) * 4
    }
}

/// The weights over the window of `map_a` (which `map_b` shares). `w1`
/// carries points of B to their correspondents on A.
pub fn colour_weights(rates: &Rates, map_a: &WarpMap, map_b: &WarpMap, w1: &dyn Warp) -> Weights {
    let window = map_a.window;
    let w = window.width();
    let mut a = vec![0f32; window.area()];
    let mut b = vec![0f32; window.area()];
    if w > 0 {
        a.par_chunks_mut(w)
            .zip(b.par_chunks_mut(w))
            .enumerate()
            .for_each_init(
                || (vec![0f32; w], vec![0f32; w], vec![0f32; w], vec![0f32; w]),
                |(xs, ys, ox, oy), (row, (wa, wb))| {
                    let j = window.y1 + row as i32;
                    for (k, o) in wa.iter_mut().enumerate() {
                        let i = window.x1 + k as i32;
                        *o = (1.0 - rates.at(map_a.get(i, j))) as f32;
                        let q = map_b.get(i, j);
                        xs[k] = q.x as f32;
                        ys[k] = q.y as f32;
                    }
                    w1.map_points(xs, ys, ox, oy);
                    for (k, (a, b)) in wa.iter_mut().zip(wb.iter_mut()).enumerate() {
                        let tb = rates.at(Vec2::new(ox[k] as f64, oy[k] as f64)) as f32;
                        (*a, *b) = normalised(*a, tb);
                    }
                },
            );
    }
    Weights { window, a, b }
}

/// A's and B's weights scaled to sum to 1; where both are 0 (A's point
/// has turned, B's not yet), an even mix.
fn normalised(a: f32, b: f32) -> (f32, f32) {
    let sum = a + b;
    if sum > 0.0 {
        (a / sum, b / sum)
    } else {
        (0.5, 0.5)
    }
}

#[cfg(test)]
mod tests;
