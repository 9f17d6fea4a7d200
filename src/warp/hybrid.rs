//! The hybrid method (Lee, Wolberg et al. §5.5): the thin plate solved on a coarse grid
//! gives the global shape cheaply; a cubic B-spline through its nodes carries
//! it to every point (C², their "B-spline propagation"); MFFD then starts
//! from that warp, on lattices no coarser than the plate's grid, to meet the
//! constraints exactly.

use super::mffd::{Deformation, Mffd, MffdSettings};
use super::thin_plate::{ThinPlate, ThinPlateSettings};
use crate::bspline::mba::{self, MbaSettings};
use crate::geom::{RectD, Vec2};

/// What the hybrid adds to the thin-plate and MFFD settings it uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HybridSettings {
    /// The plate's node spacing (canonical px; Lee, Wolberg et al. use a
    /// 128² grid for a 512² image).
    pub cell: f64,
}

impl Default for HybridSettings {
    fn default() -> Self {
        HybridSettings { cell: 16.0 }
    }
}

/// The hybrid warp: the propagated plate first, then the MFFD steps. The
/// plate and MFFD take the settings of the methods of those names (the
/// plate on the hybrid's own coarse grid).
pub fn solve(
    pairs: &[(Vec2, Vec2)],
    frame: RectD,
    s: &HybridSettings,
    thin_plate: &ThinPlateSettings,
    mffd: &MffdSettings,
) -> Mffd {
    let plate = ThinPlate::solve(
        pairs,
        frame,
        &ThinPlateSettings {
            cell: s.cell,
            ..*thin_plate
        },
        None,
    );
    let nodes = &plate.nodes;
    let mut positions = Vec::with_capacity(nodes.nx * nodes.ny);
    for j in 0..nodes.ny {
        for i in 0..nodes.nx {
            positions.push(nodes.node(i, j));
        }
    }
    let (min, max) = (positions[0], positions[positions.len() - 1]);
    // Threshold 0: both coordinates refine to the same finest lattice, so
    // the deformation's two lattices share one geometry.
    let settings = MbaSettings {
        coarsest: 2,
        threshold: 0.0,
        finest: s.cell / 2.0,
    };
    let surface = |pick: fn(Vec2) -> f64| {
        let points: Vec<(Vec2, f64)> = positions
            .iter()
            .zip(&nodes.disp)
            .map(|(p, d)| (*p, pick(*d)))
            .collect();
        mba::interpolate(&points, min, max, &settings).lattice
    };
    let (dx, dy) = rayon::join(|| surface(|d| d.x), || surface(|d| d.y));
    let first = if dx.is_zero() && dy.is_zero() {
        Vec::new()
    } else {
        vec![Deformation::new(dx, dy)]
    };
    Mffd::solve_from(first, pairs, frame, s.cell, mffd)
}
