//! The field warp's settings: the weight constants of Beier-Neely eq. (4),
//! how lines interpolate (§3.4) and how the field is evaluated.

use crate::choice::Choice;

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
    /// than `tolerance` pixels ([`split`](super::split)).
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
