//! Mesh warping (Wolberg: Smythe's algorithm at ILM as published by Wolberg).
//! Two meshes of control points, topologically equal, say where landmarks of
//! the source sit and where they go; Catmull-Rom splines through the mesh
//! columns and rows carry the motion to every pixel.
//!
//! Two evaluations of the same mesh pair:
//! - [`two_pass`]: the published algorithm, rows then columns, each resampled
//!   with Fant's filter ([`fant`]); it produces pixels, not a map.
//! - [`MeshWarp`]: bicubic patches through the nodes inverted per pixel, a
//!   reverse map like every other warp (ST maps, the grid view, any filter),
//!   free of the two-pass bottleneck under strong rotation.

pub mod fant;
mod patch;
mod refine;
pub mod spline;
mod two_pass;

pub use patch::MeshWarp;
pub use refine::Line;
pub use two_pass::{two_pass, two_pass_into};

use crate::choice::Choice;
use crate::error::{Error, Result};
use crate::features::{Side, Tween};
use crate::geom::Vec2;

/// A grid of control points, `rows × cols`, row by row from the bottom row
/// (smallest y) up, each row left to right.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    rows: usize,
    cols: usize,
    nodes: Vec<Vec2>,
}

/// Sizes beyond this are surely a mistake (a 256 × 256 mesh already holds
/// 65 536 hand-placed nodes, and its patch tables take 16 MB).
pub const MAX_SIZE: usize = 256;

impl Mesh {
    /// A mesh from its nodes; sizes are checked here, geometry by [`Mesh::check`].
    pub fn new(rows: usize, cols: usize, nodes: Vec<Vec2>) -> Result<Mesh> {
        if !(2..=MAX_SIZE).contains(&rows) || !(2..=MAX_SIZE).contains(&cols) {
            return Err(Error::Invalid(format!(
                "a mesh needs 2 to {MAX_SIZE} rows and columns, found {rows} × {cols}"
            )));
        }
        if nodes.len() != rows * cols {
            return Err(Error::Invalid(format!(
                "a {rows} × {cols} mesh has {} nodes, found {}",
                rows * cols,
                nodes.len()
            )));
        }
        Ok(Mesh { rows, cols, nodes })
    }

    /// The regular mesh over `[x1, x2] × [y1, y2]`.
    pub fn regular(rows: usize, cols: usize, x1: f64, y1: f64, x2: f64, y2: f64) -> Result<Mesh> {
        let nodes = (0..rows.max(2))
            .flat_map(|r| {
                (0..cols.max(2)).map(move |c| {
                    Vec2::new(
                        x1 + (x2 - x1) * c as f64 / (cols.max(2) - 1) as f64,
                        y1 + (y2 - y1) * r as f64 / (rows.max(2) - 1) as f64,
                    )
                })
            })
            .collect();
        Mesh::new(rows, cols, nodes)
    }

    /// Node rows.
    #[inline]
    pub fn rows(&self) -> usize {
        self.rows
    }
    /// Node columns.
    #[inline]
    pub fn cols(&self) -> usize {
        self.cols
    }
    /// Node at row `r`, column `c`.
    #[inline]
    pub fn node(&self, r: usize, c: usize) -> Vec2 {
        self.nodes[r * self.cols + c]
    }
    /// Every node, row-major, bottom row first.
    pub fn nodes(&self) -> &[Vec2] {
        &self.nodes
    }

    /// Every node moved by `f` (same topology).
    pub fn map_nodes(&self, f: impl Fn(usize, usize, Vec2) -> Vec2) -> Mesh {
        let nodes = (0..self.rows)
            .flat_map(|r| (0..self.cols).map(move |c| (r, c)))
            .map(|(r, c)| f(r, c, self.node(r, c)))
            .collect();
        Mesh {
            rows: self.rows,
            cols: self.cols,
            nodes,
        }
    }

    /// Node by node `self + (other − self)·t`; both meshes must be the same size.
    pub fn lerp(&self, other: &Mesh, t: f64) -> Mesh {
        self.map_nodes(|r, c, p| p.lerp(other.node(r, c), t))
    }

    /// The same mesh with its rows in the opposite order (for meshes listed
    /// top row first, as images are stored).
    fn flipped(&self) -> Mesh {
        self.map_nodes(|r, c, _| self.node(self.rows - 1 - r, c))
    }

    /// The rules that keep the two-pass splines and the patches one-to-one:
    /// finite nodes, columns rising and rows running right strictly
    /// (Wolberg: "It is important that the mesh not self-intersect"), every
    /// cell a convex counter-clockwise quad. `name` goes into the message.
    pub fn check(&self, name: &str) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(format!("{name}: {what}")));
        if let Some(i) = self.nodes.iter().position(|p| !p.is_finite()) {
            return bad(format!(
                "node (row {}, col {}) is not finite",
                i / self.cols,
                i % self.cols
            ));
        }
        for r in 0..self.rows {
            for c in 0..self.cols {
                let p = self.node(r, c);
                if r > 0 && p.y <= self.node(r - 1, c).y {
                    return bad(format!(
                        "column {c} does not rise monotonically: node (row {r}, col \
                            {c}) at y = {} is not above node (row {}, col {c}) at y = {}",
                        p.y,
                        r - 1,
                        self.node(r - 1, c).y
                    ));
                }
                if c > 0 && p.x <= self.node(r, c - 1).x {
                    return bad(format!(
                        "row {r} does not run monotonically to the right: node (row \
                            {r}, col {c}) at x = {} is not right of node (row {r}, col \
                            {}) at x = {}",
                        p.x,
                        c - 1,
                        self.node(r, c - 1).x
                    ));
                }
            }
        }
        for r in 0..self.rows - 1 {
            for c in 0..self.cols - 1 {
                let q = [
                    self.node(r, c),
                    self.node(r, c + 1),
                    self.node(r + 1, c + 1),
                    self.node(r + 1, c),
                ];
                let folded = (0..4).any(|k| {
                    let (a, b, d) = (q[k], q[(k + 1) % 4], q[(k + 3) % 4]);
                    let (e1, e2) = (b - a, d - a);
                    e1.x * e2.y - e1.y * e2.x <= 0.0
                });
                if folded {
                    return bad(format!(
                        "cell (row {r}, col {c}) is folded or self-intersecting (its \
                            corners do not run counter-clockwise around a convex quad)"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// A node of the mesh: its row (from the bottom) and column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Node {
    /// Row, 0 at the bottom.
    pub row: usize,
    /// Column, 0 at the left.
    pub col: usize,
}

/// How a mesh warp is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Pass {
    /// Rows then columns with Fant's filter (Smythe's algorithm as Wolberg lists it).
    #[default]
    TwoPass,
    /// Bicubic patches inverted per output pixel: a reverse map.
    OnePass,
}

impl Choice for Pass {
    const ALL: &'static [Self] = &[Pass::TwoPass, Pass::OnePass];
    fn name(self) -> &'static str {
        match self {
            Pass::TwoPass => "two-pass",
            Pass::OnePass => "one-pass",
        }
    }
}

/// Mesh method settings (scene key `mesh`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct MeshSettings {
    /// One pass or two.
    pub pass: Pass,
}

/// The mesh on A and the mesh on B, node for node.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshPair {
    /// The mesh on A.
    pub a: Mesh,
    /// The mesh on B, node for node.
    pub b: Mesh,
}

impl MeshPair {
    /// Checks both meshes and that their borders are frozen (Wolberg: "the
    /// first and last rows and columns all remain intact throughout the
    /// warp"). Meshes listed top row first are turned to bottom row first.
    pub fn new(a: Mesh, b: Mesh) -> Result<MeshPair> {
        if (a.rows, a.cols) != (b.rows, b.cols) {
            return Err(Error::Invalid(format!(
                "mesh a is {} × {} but mesh b is {} × {}; they must have the same topology",
                a.rows, a.cols, b.rows, b.cols
            )));
        }
        let (a, b) = if a.rows >= 2 && a.node(1, 0).y < a.node(0, 0).y {
            (a.flipped(), b.flipped())
        } else {
            (a, b)
        };
        a.check("mesh a")?;
        b.check("mesh b")?;
        for r in 0..a.rows {
            for c in 0..a.cols {
                let border = r == 0 || c == 0 || r + 1 == a.rows || c + 1 == a.cols;
                if border && a.node(r, c) != b.node(r, c) {
                    return Err(Error::Invalid(format!(
                        "mesh: border node (row {r}, col {c}) is at {:?} in a but \
                            {:?} in b; the border rows and columns must stay frozen",
                        <[f64; 2]>::from(a.node(r, c)),
                        <[f64; 2]>::from(b.node(r, c))
                    )));
                }
            }
        }
        Ok(MeshPair { a, b })
    }

    /// The mesh on `side`.
    pub fn side(&self, side: Side) -> &Mesh {
        match side {
            Side::A => &self.a,
            Side::B => &self.b,
        }
    }

    /// The in-between mesh at `t` (Wolberg `morph`: nodes interpolated linearly).
    pub fn at(&self, t: f64) -> Mesh {
        self.a.lerp(&self.b, t)
    }

    /// The in-between mesh with each node at its own rate (transition control:
    /// Smythe's per-node transition curves, Lee et al. §1).
    pub fn tween(&self, t: Tween<'_>) -> Mesh {
        if t.is_uniform() {
            return self.at(t.t);
        }
        self.a.map_nodes(|r, c, p| t.between(p, self.b.node(r, c)))
    }

    /// Node for node interpolation between two keyed pairs (sequence keyframes).
    pub fn lerp(&self, other: &MeshPair, w: f64) -> MeshPair {
        MeshPair {
            a: self.a.lerp(&other.a, w),
            b: self.b.lerp(&other.b, w),
        }
    }
}

#[cfg(test)]
mod tests;
