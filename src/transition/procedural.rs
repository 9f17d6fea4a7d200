//! Procedural transitions (Lee et al. §4.2, Lee, Wolberg et al. Figs. 17–18): the rate of
//! a point follows from where it is. A spatial pattern `g(p) ∈ [0, 1]` says
//! when a point's turn comes; each point crosses from A to B over a window
//! of `1 − spread` of the progress, starting at `spread · g(p)`:
//!
//! ```text
//! T(p, t) = clamp((t − spread · g(p)) / (1 − spread), 0, 1)
//! ```
//!
//! so every point is exactly A at `t = 0` and exactly B at `t = 1`, and
//! `spread = 0` is the uniform dissolve.

use std::f64::consts::TAU;

use crate::choice::Choice;
use crate::geom::{RectD, Vec2};

/// A procedural transition's shape: which points go first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    /// A linear wipe along `angle` (degrees; 0: left to right, 90: bottom to top).
    Ramp {
        /// Degrees.
        angle: f64,
    },
    /// A sinusoid along the rows (varies with x), `cycles` across the frame.
    SineRows {
        /// Periods across the frame.
        cycles: f64,
    },
    /// A sinusoid along the columns (varies with y).
    SineColumns {
        /// Periods up the frame.
        cycles: f64,
    },
    /// Rings around `centre` (canonical; `None`: the frame's centre): the
    /// centre first when `cycles` is 0, else a sinusoid of the radius.
    Radial {
        /// Periods from the centre to the farthest corner; 0: a plain radial wipe.
        cycles: f64,
        /// The rings' centre (canonical); `None`: the frame's centre.
        centre: Option<Vec2>,
    },
}

/// Which pattern, without its numbers: what a scene's `pattern` and the
/// nodes' Transition param name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PatternKind {
    /// A linear wipe.
    Ramp,
    /// A sinusoid varying with x.
    SineRows,
    /// A sinusoid varying with y.
    SineColumns,
    /// Rings around a centre.
    Radial,
}

impl Choice for PatternKind {
    const ALL: &'static [Self] = &[
        PatternKind::Ramp,
        PatternKind::SineRows,
        PatternKind::SineColumns,
        PatternKind::Radial,
    ];
    fn name(self) -> &'static str {
        match self {
            PatternKind::Ramp => "ramp",
            PatternKind::SineRows => "sine-rows",
            PatternKind::SineColumns => "sine-columns",
            PatternKind::Radial => "radial",
        }
    }
}

/// A procedural transition: a pattern, swept over part of the progress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Procedural {
    /// Which points go first.
    pub pattern: Pattern,
    /// The share of the progress over which the pattern sweeps, `[0, 0.99]`.
    pub spread: f64,
}

pub use super::pace::MAX_SPREAD;

impl Procedural {
    /// `g(p)`: when the point at `p` (canonical, on A) has its turn.
    pub fn order(&self, p: Vec2, frame: RectD) -> f64 {
        let (w, h) = (frame.width().max(1e-9), frame.height().max(1e-9));
        let (u, v) = ((p.x - frame.x1) / w, (p.y - frame.y1) / h);
        let sine = |phase: f64| 0.5 - 0.5 * (TAU * phase).cos();
        let g = match self.pattern {
            Pattern::Ramp { angle } => {
                let (c, s) = (angle.to_radians().cos(), angle.to_radians().sin());
                // Projections of the frame's corners bound the ramp.
                let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)].map(|(x, y)| x * c + y * s);
                let lo = corners.iter().cloned().fold(f64::INFINITY, f64::min);
                let hi = corners.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                let d = (p.x - frame.x1) * c + (p.y - frame.y1) * s;
                (d - lo) / (hi - lo).max(1e-9)
            }
            Pattern::SineRows { cycles } => sine(cycles * u),
            Pattern::SineColumns { cycles } => sine(cycles * v),
            Pattern::Radial { cycles, centre } => {
                let c = centre.unwrap_or(Vec2::new(
                    frame.x1 + 0.5 * frame.width(),
                    frame.y1 + 0.5 * frame.height(),
                ));
                let reach = [
                    Vec2::new(frame.x1, frame.y1),
                    Vec2::new(frame.x2, frame.y1),
                    Vec2::new(frame.x1, frame.y2),
                    Vec2::new(frame.x2, frame.y2),
                ]
                .iter()
                .fold(0.0f64, |m, q| m.max(q.distance(c)))
                .max(1e-9);
                let r = p.distance(c) / reach;
                if cycles == 0.0 {
                    r
                } else {
                    sine(cycles * r)
                }
            }
        };
        g.clamp(0.0, 1.0)
    }

    /// `T(p, t)`.
    pub fn rate(&self, p: Vec2, frame: RectD, t: f64) -> f64 {
        if t <= 0.0 || t >= 1.0 {
            return t.clamp(0.0, 1.0);
        }
        super::pace::paced(self.order(p, frame), t, self.spread)
    }
}
