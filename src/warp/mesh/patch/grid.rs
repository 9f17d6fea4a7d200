//! The one-pass map on an error-checked coarse grid, as the field's adaptive
//! evaluation does: Newton at the nodes of a grid a few pixels apart,
//! bilinear in between where the nodes' second differences bound the
//! interpolation error within the tolerance, and Newton at every pixel of a
//! cell where they do not. Inside a mesh the map is smooth (C1 patches,
//! inverted exactly) and the grid is finer than the mesh's cells, so the
//! nodes see its curvature and nearly every cell interpolates; cells the
//! mesh's edge crosses are solved pixel by pixel.

use rayon::prelude::*;

use super::{MeshWarp, Params, LANES};
use crate::geom::{PixelScale, RectI, Vec2};

/// Most pixels between grid nodes.
const GRID: usize = 4;
/// Least nodes along a side of the mesh's smallest cell, so that curvature
/// within a cell shows in the nodes' differences.
const NODES_PER_CELL: f64 = 2.0;
/// Share of the tolerance the estimated error must meet: second differences
/// estimate the curvature, they do not bound it.
const SAFETY: f64 = 0.5;

/// The map at a grid node: where its pixel samples, its parameters on the
/// output mesh (`None` off it, where the map is the identity), and the
/// largest second derivative of the map across and along the grid there
/// (canonical px per px², infinite where a neighbour lies off the mesh).
#[derive(Clone, Copy)]
struct Node {
    q: Vec2,
    at: Option<Params>,
    bend: [f64; 2],
}

/// Pixel offsets of the grid's nodes along a side of `n` pixels: every
/// `step`-th, and the last pixel.
fn knots(n: usize, step: usize) -> Vec<usize> {
    let mut k: Vec<usize> = (0..n).step_by(step).collect();
    if k.last() != Some(&(n - 1)) {
        k.push(n - 1);
    }
    k
}

/// Pixels `k[c]..` of cell `c` of `k`'s cells: up to the next knot, and the
/// last knot with the last cell.
fn span(k: &[usize], c: usize) -> std::ops::Range<usize> {
    let end = if c + 2 == k.len() {
        k[c + 1] + 1
    } else {
        k[c + 1]
    };
    k[c]..end
}

/// Weights of the second divided difference about each middle knot `m`
/// of `k` (index `m - 1`): `2 / (x₊ − x₋)` times the slopes' difference,
/// each slope a difference over its span.
fn second_weights(k: &[usize]) -> Vec<[f64; 3]> {
    k.windows(3)
        .map(|x| {
            let [a, b, c] = [x[0], x[1], x[2]].map(|x| x as f64);
            [1.0 / (b - a), 1.0 / (c - b), 2.0 / (c - a)]
        })
        .collect()
}

/// The largest component of the second divided difference of values `q`
/// at three knots with `weights` ([`second_weights`]); infinite where one
/// is off the mesh.
fn second_difference(weights: [f64; 3], q: [Option<Vec2>; 3]) -> f64 {
    let (Some(a), Some(b), Some(c)) = (q[0], q[1], q[2]) else {
        return f64::INFINITY;
    };
    let [below, above, across] = weights;
    let d = ((c - b) * above - (b - a) * below) * across;
    d.x.abs().max(d.y.abs())
}

/// A window's pixels in canonical positions.
struct Pixels {
    window: RectI,
    scale: PixelScale,
}

impl Pixels {
    fn centre(&self, i: usize, j: usize) -> Vec2 {
        self.scale
            .pixel_centre(self.window.x1 + i as i32, self.window.y1 + j as i32)
    }
}

impl MeshWarp {
    /// The map over `window` within `tolerance` (the render's px) of the
    /// exact one, into `pos` (rows bottom-up); returns how many cells were
    /// solved pixel by pixel, of how many, or `None` (and writes nothing)
    /// where the mesh's cells are too small for a grid.
    pub(super) fn map_grid(
        &self,
        window: RectI,
        scale: PixelScale,
        tolerance: f64,
        pos: &mut [[f32; 2]],
    ) -> Option<(usize, usize)> {
        let (w, h) = (window.width(), window.height());
        let smallest = self.to.smallest_cell() * scale.x.min(scale.y);
        let step = GRID.min((smallest / NODES_PER_CELL) as usize);
        if step < 2 || w < 2 || h < 2 {
            return None;
        }
        let px = Pixels { window, scale };
        // Positions are canonical: a render pixel spans 1 / scale of them.
        let tol = tolerance * SAFETY / scale.x.max(scale.y);
        let (xs, ys) = (knots(w, step), knots(h, step));
        let nodes = self.nodes(&px, &xs, &ys);
        // Bands of cells, each with its rows of `pos`.
        let mut bands = Vec::with_capacity(ys.len() - 1);
        let mut rest = pos;
        for b in 0..ys.len() - 1 {
            let (band, tail) = rest.split_at_mut(span(&ys, b).len() * w);
            bands.push((b, band));
            rest = tail;
        }
        let solved = bands.into_par_iter().map(|(b, band)| {
            let cells: Vec<Cell> = (0..xs.len() - 1)
                .map(|c| Cell {
                    columns: span(&xs, c),
                    rows: span(&ys, b),
                    knots: [(xs[c], xs[c + 1]), (ys[b], ys[b + 1])],
                    corners: [
                        &nodes[b][c],
                        &nodes[b][c + 1],
                        &nodes[b + 1][c],
                        &nodes[b + 1][c + 1],
                    ],
                })
                .collect();
            let fills: Vec<Fill> = cells.iter().map(|c| self.fill(&px, c, tol)).collect();
            fill_rows(&px, &cells, &fills, [&nodes[b], &nodes[b + 1]], band, w);
            let solve = cells.iter().zip(&fills).filter(|(_, f)| **f == Fill::Solve);
            solve
                .map(|(cell, _)| self.solve_cell(&px, cell, band, w))
                .count()
        });
        Some((solved.sum(), (xs.len() - 1) * (ys.len() - 1)))
    }

    /// The grid's nodes, row by row, with their second differences.
    fn nodes(&self, px: &Pixels, xs: &[usize], ys: &[usize]) -> Vec<Vec<Node>> {
        let mut nodes: Vec<Vec<Node>> = ys
            .par_chunks(LANES)
            .flat_map_iter(|js| self.node_rows(px, xs, js))
            .collect();
        let on = |n: &Node| n.at.map(|_| n.q);
        // Along each row and each column about the nearest node with
        // neighbours on both sides (none where a side has two nodes).
        let (wx, wy) = (second_weights(xs), second_weights(ys));
        let middle = |k: usize, n: usize| (n >= 3).then(|| k.clamp(1, n - 2));
        let bends: Vec<Vec<[f64; 2]>> = (0..ys.len())
            .into_par_iter()
            .map(|b| {
                let mb = middle(b, ys.len());
                let (row, rows) = (&nodes[b], mb.map(|m| &nodes[m - 1..=m + 1]));
                (0..xs.len())
                    .map(|i| {
                        let x = middle(i, xs.len()).map_or(f64::INFINITY, |m| {
                            second_difference(wx[m - 1], [m - 1, m, m + 1].map(|k| on(&row[k])))
                        });
                        let y = mb.zip(rows).map_or(f64::INFINITY, |(m, rows)| {
                            second_difference(wy[m - 1], [0, 1, 2].map(|r| on(&rows[r][i])))
                        });
                        [x, y]
                    })
                    .collect()
            })
            .collect();
        for (row, bends) in nodes.iter_mut().zip(bends) {
            for (node, bend) in row.iter_mut().zip(bends) {
                node.bend = bend;
            }
        }
        nodes
    }

    /// The nodes of pixel rows `js`, each starting Newton from those before
    /// it in its row: four rows in the lanes, fewer one by one.
    fn node_rows(&self, px: &Pixels, xs: &[usize], js: &[usize]) -> Vec<Vec<Node>> {
        let node = |q: Vec2, at| Node {
            q,
            at,
            bend: [f64::INFINITY; 2],
        };
        if let Ok(js) = <[usize; LANES]>::try_from(js) {
            let mut rows: Vec<Vec<Node>> =
                (0..LANES).map(|_| Vec::with_capacity(xs.len())).collect();
            let ys = js.map(|j| px.centre(0, j).y);
            let x = xs.iter().map(|&i| px.centre(i, 0).x);
            self.rows4(x, ys, [None; LANES], |_, q, found| {
                let (qx, qy) = (q.x.to_array(), q.y.to_array());
                for (l, row) in rows.iter_mut().enumerate() {
                    row.push(node(Vec2::new(qx[l], qy[l]), found.get(l)));
                }
            });
            return rows;
        }
        js.iter()
            .map(|&j| {
                let mut row = Vec::with_capacity(xs.len());
                let points = xs.iter().map(|&i| px.centre(i, j));
                self.locate_run(points, None, |_, q, at| row.push(node(q, at)));
                row
            })
            .collect()
    }

    /// How a cell is filled: bilinearly where its nodes bound the error
    /// within `tol`, the identity where it lies wholly off the mesh, else
    /// by Newton at every pixel.
    fn fill(&self, px: &Pixels, cell: &Cell, tol: f64) -> Fill {
        let on = cell.corners.map(|n| n.at.is_some());
        if on.iter().all(|&o| o) && cell.error() <= tol {
            Fill::Bilinear
        } else if !on.iter().any(|&o| o) && !self.touches(px, cell) {
            Fill::Identity
        } else {
            Fill::Solve
        }
    }

    /// Newton at every pixel of `cell`, into `band` (its band's rows, `w`
    /// pixels each).
    fn solve_cell(&self, px: &Pixels, cell: &Cell, band: &mut [[f32; 2]], w: usize) {
        let j0 = cell.rows.start;
        if cell.rows.len() == LANES {
            // Four rows in the lanes, each from its left nodes' parameters.
            let rows: [usize; LANES] = std::array::from_fn(|l| j0 + l);
            let seed = rows.map(|j| cell.seed(j));
            let ys = rows.map(|j| px.centre(0, j).y);
            let xs = cell.columns.clone().map(|i| px.centre(i, 0).x);
            let i0 = cell.columns.start;
            self.rows4(xs, ys, seed, |k, q, _| {
                let (qx, qy) = (q.x.to_array(), q.y.to_array());
                for l in 0..LANES {
                    band[(rows[l] - j0) * w + i0 + k] = [qx[l] as f32, qy[l] as f32];
                }
            });
            return;
        }
        for j in cell.rows.clone() {
            let row = &mut band[(j - j0) * w..][cell.columns.clone()];
            let points = cell.columns.clone().map(|i| px.centre(i, j));
            let put = |k: usize, q: Vec2, _| row[k] = [q.x as f32, q.y as f32];
            self.locate_run(points, cell.seed(j), put);
        }
    }

    /// Whether the cell's pixel centres reach the output mesh's node
    /// bounds, past which [`MeshWarp::locate`] finds no start.
    fn touches(&self, px: &Pixels, cell: &Cell) -> bool {
        let lo = px.centre(cell.columns.start, cell.rows.start);
        let hi = px.centre(cell.columns.end - 1, cell.rows.end - 1);
        let (b_lo, b_hi) = self.to.bounds;
        hi.x >= b_lo.x && lo.x <= b_hi.x && hi.y >= b_lo.y && lo.y <= b_hi.y
    }
}

/// A grid cell: its pixels, its nodes' pixel offsets, and its four nodes
/// (bottom left, bottom right, top left, top right).
struct Cell<'n> {
    columns: std::ops::Range<usize>,
    rows: std::ops::Range<usize>,
    knots: [(usize, usize); 2],
    corners: [&'n Node; 4],
}

impl Cell<'_> {
    /// Bilinear interpolation's error bound, `(hx²·|f_xx| + hy²·|f_yy|) / 8`,
    /// with the corners' largest second differences for the derivatives
    /// (the cross term `f_xy` it reproduces exactly).
    fn error(&self) -> f64 {
        let [(x0, x1), (y0, y1)] = self.knots;
        let (hx, hy) = ((x1 - x0) as f64, (y1 - y0) as f64);
        let bend = |a: usize| self.corners.iter().map(|n| n.bend[a]).fold(0.0, f64::max);
        (hx * hx * bend(0) + hy * hy * bend(1)) / 8.0
    }

    /// A start for Newton at the left end of pixel row `j`: its left nodes'
    /// parameters, interpolated, or any node's on the mesh.
    fn seed(&self, j: usize) -> Option<Params> {
        let [_, (y0, y1)] = self.knots;
        let f = (j - y0) as f64 / (y1 - y0) as f64;
        match (self.corners[0].at, self.corners[2].at) {
            (Some(a), Some(b)) => Some((a.0 + (b.0 - a.0) * f, a.1 + (b.1 - a.1) * f)),
            _ => self.corners.iter().find_map(|n| n.at),
        }
    }
}

/// How a cell is filled ([`MeshWarp::fill`]).
#[derive(Clone, Copy, PartialEq)]
enum Fill {
    Bilinear,
    Identity,
    Solve,
}

/// The bilinear and identity cells of a band, pixel row by pixel row: each
/// row's values at the node columns are interpolated once between the
/// band's two node rows (`nodes`), then along the row.
fn fill_rows(
    px: &Pixels,
    cells: &[Cell],
    fills: &[Fill],
    nodes: [&[Node]; 2],
    band: &mut [[f32; 2]],
    w: usize,
) {
    let Some(first) = cells.first() else {
        return;
    };
    let (rows, (y0, y1)) = (first.rows.clone(), first.knots[1]);
    let mix = |p: Vec2, q: Vec2, f: f64| p * (1.0 - f) + q * f;
    for j in rows.clone() {
        let row = &mut band[(j - rows.start) * w..][..w];
        let fy = (j - y0) as f64 / (y1 - y0) as f64;
        let at = |c: usize| mix(nodes[0][c].q, nodes[1][c].q, fy);
        let mut left = at(0);
        for (c, (cell, fill)) in cells.iter().zip(fills).enumerate() {
            let right = at(c + 1);
            let out = &mut row[cell.columns.clone()];
            match fill {
                Fill::Bilinear => {
                    let (x0, x1) = cell.knots[0];
                    let step = (right - left) * (1.0 / (x1 - x0) as f64);
                    for (k, o) in out.iter_mut().enumerate() {
                        let q = left + step * k as f64;
                        *o = [q.x as f32, q.y as f32];
                    }
                }
                Fill::Identity => {
                    for (i, o) in cell.columns.clone().zip(out) {
                        let p = px.centre(i, j);
                        *o = [p.x as f32, p.y as f32];
                    }
                }
                Fill::Solve => {}
            }
            left = right;
        }
    }
}
