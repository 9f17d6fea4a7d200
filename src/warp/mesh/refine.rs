//! Rows and columns added to a mesh pair or taken out, as a grid tool
//! does. A new row goes through a point at a fractional row index `r` of
//! the surfaces (the one-pass map's Catmull-Rom surfaces, [`super::patch`]):
//! each of its nodes is where A's surface, and B's, pass at that index, so
//! the new mesh lies on the old surfaces and the warp barely moves. (A
//! Catmull-Rom surface through the new nodes is not exactly the old one:
//! the spans each side of the new row are reparametrised, so the map moves
//! by a few per cent of how far the mesh bends there: 1.8 % of a smooth
//! bend (the tests below), 6 % beside a single moved node (the harness's
//! `an_added_row_or_column_keeps_the_rendered_map`). Moving the new row's
//! B nodes by least squares to hold the old warp gained under 3 % of
//! that, so they stay on B's surface.)

use super::patch::Surface;
use super::{Mesh, MeshPair};
use crate::error::{Error, Result};
use crate::features::Side;
use crate::geom::Vec2;

/// Which way a grid line runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Line {
    /// A row: nodes side by side, left to right.
    Row,
    /// A column: nodes one above another.
    Column,
}

impl MeshPair {
    /// The surface parameters `(column, row)`, fractional, of `p` on
    /// `side`'s mesh; `None` outside it.
    pub fn locate(&self, side: Side, p: Vec2) -> Option<(f64, f64)> {
        let surface = Surface::new(self.side(side));
        let (s, r) = surface.start(p)?;
        let (s, r) = surface.solve(p, s, r)?;
        surface.inside_domain(s, r).then_some((s, r))
    }

    /// A row (or column) added at fractional index `at` of the surfaces,
    /// strictly between two rows (columns): on A and B each node where that
    /// side's surface passes there.
    pub fn with_line(&self, line: Line, at: f64) -> Result<MeshPair> {
        let (rows, cols) = (self.a.rows(), self.a.cols());
        let count = match line {
            Line::Row => rows,
            Line::Column => cols,
        };
        let before = at.floor();
        let inside =
            at > 0.0 && at < (count - 1) as f64 && at - before > 1e-6 && before + 1.0 - at > 1e-6;
        if !inside || count >= super::MAX_SIZE {
            return Err(Error::Invalid(format!(
                "a {} goes strictly between two (at {at:.3} of 0 to {}), and a mesh has at most {} \
                 of them",
                line.name(),
                count - 1,
                super::MAX_SIZE
            )));
        }
        let k = before as usize + 1;
        let added = |mesh: &Mesh| {
            let surface = Surface::new(mesh);
            match line {
                Line::Row => {
                    let mut nodes = mesh.nodes()[..k * cols].to_vec();
                    nodes.extend((0..cols).map(|c| surface.position(c as f64, at)));
                    nodes.extend_from_slice(&mesh.nodes()[k * cols..]);
                    Mesh::new(rows + 1, cols, nodes)
                }
                Line::Column => {
                    let nodes = (0..rows)
                        .flat_map(|r| {
                            let row = &mesh.nodes()[r * cols..(r + 1) * cols];
                            let new = surface.position(at, r as f64);
                            row[..k]
                                .iter()
                                .copied()
                                .chain([new])
                                .chain(row[k..].iter().copied())
                        })
                        .collect();
                    Mesh::new(rows, cols + 1, nodes)
                }
            }
        };
        let a = added(&self.a)?;
        // The new line's border nodes lie on the border's curves, the same
        // on both sides: B takes A's, not its own rounding of them.
        let b = added(&self.b)?.map_nodes(|r, c, p| {
            let new = match line {
                Line::Row => r == k && (c == 0 || c + 1 == cols),
                Line::Column => c == k && (r == 0 || r + 1 == rows),
            };
            if new {
                a.node(r, c)
            } else {
                p
            }
        });
        MeshPair::new(a, b)
    }

    /// Row (or column) `index` taken out; a border one cannot be (the
    /// border is frozen).
    pub fn without_line(&self, line: Line, index: usize) -> Result<MeshPair> {
        let (rows, cols) = (self.a.rows(), self.a.cols());
        let count = match line {
            Line::Row => rows,
            Line::Column => cols,
        };
        if index == 0 || index + 1 >= count {
            return Err(Error::Invalid(format!(
                "{} {index} is on the border or not in the mesh: the border stays (a mesh \
                 keeps 2 {}s at least)",
                line.name(),
                line.name()
            )));
        }
        let removed = |mesh: &Mesh| {
            let nodes: Vec<Vec2> = (0..rows * cols)
                .filter(|i| match line {
                    Line::Row => i / cols != index,
                    Line::Column => i % cols != index,
                })
                .map(|i| mesh.nodes()[i])
                .collect();
            match line {
                Line::Row => Mesh::new(rows - 1, cols, nodes),
                Line::Column => Mesh::new(rows, cols - 1, nodes),
            }
        };
        MeshPair::new(removed(&self.a)?, removed(&self.b)?)
    }
}

impl Line {
    /// "row" or "column".
    pub fn name(self) -> &'static str {
        match self {
            Line::Row => "row",
            Line::Column => "column",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::warp::mesh::MeshWarp;
    use crate::warp::Warp;

    /// A 5 × 5 mesh over 400 × 400, B's interior nodes moved by a smooth
    /// field of up to 10 px.
    fn pair() -> MeshPair {
        let a = Mesh::regular(5, 5, 0.0, 0.0, 400.0, 400.0).unwrap();
        let b = a.map_nodes(|r, c, p| {
            let inner = r > 0 && c > 0 && r < 4 && c < 4;
            let d = Vec2::new((p.y / 130.0).sin() * 10.0, (p.x / 170.0).cos() * 6.0);
            if inner {
                p + d
            } else {
                p
            }
        });
        MeshPair::new(a, b).unwrap()
    }

    /// The largest distance between two pairs' maps of A and of B toward
    /// t = 0.5, over the mesh on a 5 px grid.
    fn map_change(x: &MeshPair, y: &MeshPair) -> f64 {
        let mut worst: f64 = 0.0;
        for side in [Side::A, Side::B] {
            let (wx, wy) = (
                MeshWarp::toward(x, side, 0.5),
                MeshWarp::toward(y, side, 0.5),
            );
            for j in 1..80 {
                for i in 1..80 {
                    let p = Vec2::new(5.0 * i as f64, 5.0 * j as f64);
                    worst = worst.max(wx.map(p).distance(wy.map(p)));
                }
            }
        }
        worst
    }

    /// A row added through a point lands there, on both sides where the
    /// surfaces pass; the warp moves by under 0.2 px (1.8 % of the 10 px
    /// the mesh bends: the spans beside the new row are reparametrised),
    /// under 0.35 px with a column as well; taken out again, the mesh is
    /// what it was.
    #[test]
    fn a_row_or_column_added_keeps_the_warp_and_one_taken_out_restores_it() {
        let pair = pair();
        let through = Vec2::new(150.0, 130.0);
        let (s, r) = pair.locate(Side::A, through).unwrap();
        assert!((r - 1.3).abs() < 1e-9 && (s - 1.5).abs() < 1e-9, "{s}, {r}");
        let rows = pair.with_line(Line::Row, r).unwrap();
        assert_eq!((rows.a.rows(), rows.a.cols()), (6, 5));
        assert!(rows.a.node(2, 0).distance(Vec2::new(0.0, 130.0)) < 1e-9);
        let change = map_change(&pair, &rows);
        eprintln!("a row moved the map by {change:.4} px");
        assert!(change < 0.2, "a row moved the map by {change} px");
        let both = rows.with_line(Line::Column, 2.6).unwrap();
        assert_eq!((both.a.rows(), both.a.cols()), (6, 6));
        let change = map_change(&pair, &both);
        eprintln!("a row and a column moved the map by {change:.4} px");
        assert!(
            change < 0.35,
            "a row and a column moved the map by {change} px"
        );
        assert_eq!(rows.without_line(Line::Row, 2).unwrap(), pair);
        assert!(pair.without_line(Line::Row, 0).is_err());
        assert!(pair.with_line(Line::Column, 2.0).is_err());
    }
}
