//! Deformable-surface warps (Lee et al.): the x and y displacements are two
//! thin plates pulled by springs toward the constraint displacements and held
//! by glue, each solved by multigrid on a node grid over the frame. The
//! warp between nodes is bilinear, the same interpolant the springs attach
//! to, so the map is exactly the discrete model that was solved.

pub mod multigrid;
mod pinning;
pub mod plate;

use super::node_grid::NodeGrid;
use super::Warp;
use crate::geom::{PixelScale, RectD, RectI, Vec2};
use crate::image::WarpMap;
use multigrid::{Hierarchy, Report};

/// Thin-plate settings (scene key `thin-plate`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinPlateSettings {
    /// Spring constant `α` (px⁻²): how tightly the plate meets the constraints.
    pub alpha: f64,
    /// Glue `β` (px⁻⁴): how soon a constraint's pull dies away, over about
    /// `β^(−1/4)` px. Zero: no glue, displacements spread over the frame.
    pub beta: f64,
    /// Node spacing (canonical px).
    pub cell: f64,
    /// Stop when an iteration moves no node by more than this (px).
    pub tolerance: f64,
    /// Most multigrid cycles per solve.
    pub max_cycles: usize,
}

impl Default for ThinPlateSettings {
    fn default() -> Self {
        ThinPlateSettings {
            alpha: 100.0,
            beta: 0.0,
            cell: 4.0,
            tolerance: 0.01,
            max_cycles: 60,
        }
    }
}

/// Both displacement surfaces on their node grid, and how the solve went.
#[derive(Debug, Clone, PartialEq)]
pub struct ThinPlate {
    /// The nodes and their displacements.
    pub nodes: NodeGrid,
    /// How the x solve went.
    pub report_x: Report,
    /// How the y solve went.
    pub report_y: Report,
}

impl ThinPlate {
    /// The plates whose displacements carry each `from` to its `to`, over
    /// `frame`. `warm`: a previous solution on the same grid to start from
    /// (a sequence's previous frame), else the plates start flat. Features
    /// on one point or one line are completed by `pinning` so that the
    /// plates are unique, whatever the start.
    pub fn solve(
        pairs: &[(Vec2, Vec2)],
        frame: RectD,
        s: &ThinPlateSettings,
        warm: Option<&ThinPlate>,
    ) -> ThinPlate {
        let pinned = pinning::pin_free_modes(pairs, frame, s.cell);
        let pairs = pinned.as_slice();
        let (origin, nx, ny, levels) = layout(frame, pairs, s.cell);
        let mut nodes = NodeGrid {
            origin,
            step: Vec2::new(s.cell, s.cell),
            nx,
            ny,
            disp: vec![Vec2::ZERO; nx * ny],
        };
        let at: Vec<(f64, f64)> = pairs
            .iter()
            .map(|(p, _)| ((p.x - origin.x) / s.cell, (p.y - origin.y) / s.cell))
            .collect();
        let hierarchy = Hierarchy::new(nx, ny, s.cell, s.alpha, s.beta, &at, levels);
        let start = |pick: fn(Vec2) -> f64| -> Vec<f64> {
            match warm {
                Some(w) if w.nodes.origin == origin && w.nodes.nx == nx && w.nodes.ny == ny => {
                    w.nodes.disp.iter().map(|d| pick(*d)).collect()
                }
                _ => vec![0.0; nx * ny],
            }
        };
        let rhs = |pick: fn(Vec2) -> f64| {
            let z: Vec<f64> = pairs.iter().map(|(p, q)| pick(*q - *p)).collect();
            hierarchy.plate.rhs_for(&z)
        };
        let solve = |pick: fn(Vec2) -> f64| {
            let mut f = start(pick);
            let report = hierarchy.solve(&mut f, &rhs(pick), s.tolerance, s.max_cycles);
            (f, report)
        };
        let ((fx, report_x), (fy, report_y)) = rayon::join(|| solve(|v| v.x), || solve(|v| v.y));
        for (d, (x, y)) in nodes.disp.iter_mut().zip(fx.iter().zip(&fy)) {
            *d = Vec2::new(*x, *y);
        }
        ThinPlate {
            nodes,
            report_x,
            report_y,
        }
    }
}

/// The node grid over `frame` and every constraint: cell counts padded to a
/// multiple of `2^(levels − 1)` (evenly on both sides) so each coarser grid's
/// nodes are every other node of the finer one, down to a grid of 16 to 31
/// cells along its longer side for the (banded) direct solve.
fn layout(frame: RectD, pairs: &[(Vec2, Vec2)], cell: f64) -> (Vec2, usize, usize, usize) {
    let area = frame.including(pairs.iter().map(|(p, _)| *p));
    let (min, max) = (Vec2::new(area.x1, area.y1), Vec2::new(area.x2, area.y2));
    let cx = ((max.x - min.x) / cell).ceil().max(1.0) as usize;
    let cy = ((max.y - min.y) / cell).ceil().max(1.0) as usize;
    let (short, long) = (cx.min(cy), cx.max(cy));
    let mut k = 0;
    while long >> (k + 1) >= 16 && short >> (k + 1) >= 1 {
        k += 1;
    }
    let unit = 1usize << k;
    let (px, py) = (cx.div_ceil(unit) * unit, cy.div_ceil(unit) * unit);
    let origin = Vec2::new(
        min.x - (px - cx) as f64 * cell / 2.0,
        min.y - (py - cy) as f64 * cell / 2.0,
    );
    (origin, px + 1, py + 1, k + 1)
}

/// The reverse map of a solved plate pair.
#[derive(Debug, Clone)]
pub struct ThinPlateWarp {
    /// The solved plates.
    pub plate: ThinPlate,
    identity: bool,
}

impl ThinPlateWarp {
    /// The reverse map of `plate`.
    pub fn new(plate: ThinPlate) -> Self {
        let identity = plate.nodes.disp.iter().all(|d| *d == Vec2::ZERO);
        ThinPlateWarp { plate, identity }
    }
}

impl Warp for ThinPlateWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        self.plate.nodes.map(p)
    }

    fn is_identity(&self) -> bool {
        self.identity
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.identity {
            return WarpMap::identity(window, scale);
        }
        self.plate.nodes.map_window(window, scale)
    }
}
