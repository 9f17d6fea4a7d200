//! The scene's mesh as the viewer shows it (method mesh): A's and B's
//! grids and the in-between one, each row and column the Catmull-Rom
//! spline through its nodes as the mesh warp's splines pass through them;
//! and which node the pen is over. Pure: nothing here reads the host.

use morphfx::features::{catmull_rom, Side};
use morphfx::geom::Vec2;
use morphfx::warp::mesh::{Mesh, MeshPair, Node};

use super::state::{Handle, Owner, Part};

/// The mesh at a draw's time.
#[derive(Debug, Clone)]
pub struct Grid {
    /// A's and B's meshes.
    pub pair: MeshPair,
    /// The in-between mesh at the progress.
    pub between: Mesh,
    /// Scene Text's (edited with the pen), not Scene File's (drawn dimmer,
    /// never edited).
    pub editable: bool,
}

/// Samples per span of a drawn grid line, as for curves.
pub const PER_SPAN: usize = 8;

impl Grid {
    /// The mesh on `side`.
    pub fn side(&self, side: Side) -> &Mesh {
        self.pair.side(side)
    }
}

/// Node `index` (row-major from the bottom row) of a mesh of `cols`
/// columns.
pub fn node_at(index: usize, cols: usize) -> Node {
    Node {
        row: index / cols,
        col: index % cols,
    }
}

/// Every row, then every column, of `mesh` as the Catmull-Rom spline
/// through its nodes, [`PER_SPAN`] samples a span and the last node.
pub fn lines(mesh: &Mesh) -> Vec<Vec<Vec2>> {
    let (rows, cols) = (mesh.rows(), mesh.cols());
    let row = |r: usize| (0..cols).map(|c| mesh.node(r, c)).collect::<Vec<_>>();
    let col = |c: usize| (0..rows).map(|r| mesh.node(r, c)).collect::<Vec<_>>();
    (0..rows)
        .map(row)
        .chain((0..cols).map(col))
        .map(|nodes| spline(&nodes))
        .collect()
}

fn spline(nodes: &[Vec2]) -> Vec<Vec2> {
    let spans = nodes.len() - 1;
    let mut out: Vec<Vec2> = (0..spans * PER_SPAN)
        .map(|k| catmull_rom(nodes, k / PER_SPAN, (k % PER_SPAN) as f64 / PER_SPAN as f64))
        .collect();
    out.extend(nodes.last());
    out
}

/// The grid node nearest `pen` (screen pixels, at `pixel` canonical units
/// each) among `sides`, with its distance, when the grid is editable.
pub fn nearest(grid: &Grid, pen: Vec2, pixel: (f64, f64), sides: &[Side]) -> Option<(f64, Handle)> {
    if !grid.editable {
        return None;
    }
    let screen = |p: Vec2| Vec2::new(p.x / pixel.0, p.y / pixel.1);
    let pen = screen(pen);
    let mut best: Option<(f64, Handle)> = None;
    for &side in sides {
        for (i, p) in grid.side(side).nodes().iter().enumerate() {
            let d = pen.distance(screen(*p));
            if best.is_none_or(|(b, _)| d < b) {
                let handle = Handle {
                    owner: Owner::Grid,
                    side,
                    part: Part::Point(i),
                };
                best = Some((d, handle));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> Grid {
        let a = Mesh::regular(3, 3, 0.0, 0.0, 200.0, 200.0).unwrap();
        let b = a.map_nodes(|r, c, p| {
            if (r, c) == (1, 1) {
                p + Vec2::new(10.0, -5.0)
            } else {
                p
            }
        });
        Grid {
            between: a.lerp(&b, 0.5),
            pair: MeshPair { a, b },
            editable: true,
        }
    }

    #[test]
    fn rows_then_columns_run_through_every_node() {
        let g = grid();
        let l = lines(g.side(Side::B));
        assert_eq!(l.len(), 6);
        // Row 1 passes through B's moved middle node at its second span's start.
        assert_eq!(l[1].len(), 2 * PER_SPAN + 1);
        assert_eq!(l[1][PER_SPAN], Vec2::new(110.0, 95.0));
        assert_eq!(l[4][PER_SPAN], Vec2::new(110.0, 95.0));
        assert_eq!(l[0][0], Vec2::new(0.0, 0.0));
        assert_eq!(l[5][2 * PER_SPAN], Vec2::new(200.0, 200.0));
    }

    #[test]
    fn the_nearest_node_is_found_on_the_sides_asked_and_never_on_a_files_grid() {
        let mut g = grid();
        let (d, h) = nearest(&g, Vec2::new(108.0, 96.0), (1.0, 1.0), &[Side::B]).unwrap();
        assert_eq!((h.side, h.part), (Side::B, Part::Point(4)));
        assert!((d - 5.0f64.sqrt()).abs() < 1e-9);
        let (_, h) = nearest(&g, Vec2::new(108.0, 96.0), (1.0, 1.0), &[Side::A]).unwrap();
        assert_eq!((h.side, h.part), (Side::A, Part::Point(4)));
        assert_eq!(node_at(4, 3), Node { row: 1, col: 1 });
        g.editable = false;
        assert!(nearest(&g, Vec2::new(108.0, 96.0), (1.0, 1.0), &[Side::B]).is_none());
    }
}
