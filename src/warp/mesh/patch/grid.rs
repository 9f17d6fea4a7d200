//! The one-pass map on an error-checked coarse grid, as the field's adaptive
//! evaluation does: Newton at the nodes of a grid a few pixels apart,
//! bilinear in between where the nodes' second differences bound the
//! interpolation error within the tolerance, and Newton at every pixel of a
//! cell where they do not. Inside a mesh the map is smooth (C1 patches,
//! inverted exactly) and the grid is finer than the mesh's cells, so the
//! nodes see its curvature and nearly every cell interpolates; cells the
//! mesh's edge crosses are solved pixel by pixel.

use rayon::prelude::*;

use super::{MeshWarp, Params, LANES, RUN};
use crate::geom::{PixelScale, RectI, Vec2};

/// Most pixels between grid nodes.
const GRID: usize = 4;
/// Columns at which the Newton chains along a row of nodes start cold
/// ([`RUN`] for rows of pixels): a cold start costs a few Newton steps
/// more, a run's first nodes miss the lanes, and nodes left of a window
/// cost a sixteenth of pixels.
const NODE_RUN: i32 = 4 * RUN;
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
        let smallest = self.to.smallest_cell() * scale.x.min(scale.y);
        let step = GRID.min((smallest / NODES_PER_CELL) as usize);
        if step < 2 {
            return None;
        }
        // The grid is fixed in the image, so any window of the map (a tile,
        // a chunk) has the bits the whole frame has there: its knots are
        // multiples of `step`, every pixel of the window lies inside a cell
        // (never on a last cell's closing knot), and each node's bends see
        // its neighbours on both sides.
        let s = step as i32;
        debug_assert_eq!(RUN % s, 0);
        let first = |a: i32| a.div_euclid(s) * s;
        let (x1, y1) = (first(window.x1), first(window.y1));
        let (x2, y2) = (first(window.x2 - 1) + s, first(window.y2 - 1) + s);
        let region = RectI::new(x1, y1, x2 + 1, y2 + 1);
        let (rw, rh) = (region.width(), region.height());
        let px = Pixels {
            window: region,
            scale,
        };
        // Positions are canonical: a render pixel spans 1 / scale of them.
        let tol = tolerance * SAFETY / scale.x.max(scale.y);
        let (xs, ys) = (knots(rw, step), knots(rh, step));
        let nodes = self.nodes_around(region, step, scale);
        // Bands of cells, each with the window's rows it holds.
        let (dx, dy) = (
            (window.x1 - region.x1) as usize,
            (window.y1 - region.y1) as usize,
        );
        let w = window.width();
        let columns = dx..dx + w;
        let mut bands = Vec::with_capacity(ys.len() - 1);
        let mut rest = pos;
        for b in 0..ys.len() - 1 {
            let rows = clip(&span(&ys, b), &(dy..dy + window.height()));
            if rows.is_empty() {
                continue;
            }
            let (band, tail) = rest.split_at_mut(rows.len() * w);
            bands.push((
                b,
                Out {
                    data: band,
                    rows,
                    columns: columns.clone(),
                },
            ));
            rest = tail;
        }
        let solved = bands.into_par_iter().map(|(b, mut out)| {
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
                .filter(|cell| !clip(&cell.columns, &out.columns).is_empty())
                .collect();
            let fills: Vec<Fill> = cells.iter().map(|c| self.fill(&px, c, tol)).collect();
            fill_rows(&px, &cells, &fills, &mut out);
            let solve = cells.iter().zip(&fills).filter(|(_, f)| **f == Fill::Solve);
            let solved = solve.map(|(cell, _)| self.solve_cell(&px, cell, &mut out));
            (solved.count(), cells.len())
        });
        let counts = solved.reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        Some(counts)
    }

    /// The nodes of the grid of `step` over `region` (whose corners lie on
    /// it), row by row, with their second differences: solved over a grid
    /// one node wider each side, and further left to where the Newton
    /// chains along its rows start (at multiples of [`NODE_RUN`] in the image),
    /// so that every node in `region` comes out the same whatever the
    /// region.
    fn nodes_around(&self, region: RectI, step: usize, scale: PixelScale) -> Vec<Vec<Node>> {
        let s = step as i32;
        let x1 = (region.x1 - s).div_euclid(NODE_RUN) * NODE_RUN;
        let around = RectI::new(x1, region.y1 - s, region.x2 + s, region.y2 + s);
        let px = Pixels {
            window: around,
            scale,
        };
        let (xs, ys) = (knots(around.width(), step), knots(around.height(), step));
        let skip = ((region.x1 - x1) / s) as usize;
        let across = (region.width() - 1) / step + 1;
        let mut nodes = self.nodes(&px, &xs, &ys);
        nodes.pop();
        nodes.remove(0);
        for row in &mut nodes {
            row.drain(..skip);
            row.truncate(across);
        }
        nodes
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
    /// it in its row's run: four rows in the lanes, fewer one by one.
    fn node_rows(&self, px: &Pixels, xs: &[usize], js: &[usize]) -> Vec<Vec<Node>> {
        let node = |q: Vec2, at| Node {
            q,
            at,
            bend: [f64::INFINITY; 2],
        };
        let mut rows: Vec<Vec<Node>> = js.iter().map(|_| Vec::with_capacity(xs.len())).collect();
        // Each run of the row starts Newton cold.
        let run = |i: &usize| (px.window.x1 + *i as i32).div_euclid(NODE_RUN);
        for xs in xs.chunk_by(|a, b| run(a) == run(b)) {
            if let Ok(js) = <[usize; LANES]>::try_from(js) {
                let ys = js.map(|j| px.centre(0, j).y);
                let x = xs.iter().map(|&i| px.centre(i, 0).x);
                self.rows4(x, ys, [None; LANES], |_, q, found| {
                    let (qx, qy) = (q.x.to_array(), q.y.to_array());
                    for (l, row) in rows.iter_mut().enumerate() {
                        row.push(node(Vec2::new(qx[l], qy[l]), found.get(l)));
                    }
                });
                continue;
            }
            for (row, &j) in rows.iter_mut().zip(js) {
                let points = xs.iter().map(|&i| px.centre(i, j));
                self.locate_run(points, None, |_, q, at| row.push(node(q, at)));
            }
        }
        rows
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
    fn solve_cell(&self, px: &Pixels, cell: &Cell, out: &mut Out) {
        let i0 = cell.columns.start;
        if cell.rows.len() == LANES {
            // Four rows in the lanes, each from its left nodes' parameters.
            let rows: [usize; LANES] = std::array::from_fn(|l| cell.rows.start + l);
            let seed = rows.map(|j| cell.seed(j));
            let ys = rows.map(|j| px.centre(0, j).y);
            let xs = cell.columns.clone().map(|i| px.centre(i, 0).x);
            self.rows4(xs, ys, seed, |k, q, _| {
                let (qx, qy) = (q.x.to_array(), q.y.to_array());
                for l in 0..LANES {
                    out.put(i0 + k, rows[l], Vec2::new(qx[l], qy[l]));
                }
            });
            return;
        }
        for j in cell.rows.clone() {
            let points = cell.columns.clone().map(|i| px.centre(i, j));
            let put = |k: usize, q: Vec2, _| out.put(i0 + k, j, q);
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
/// band's two node rows (its cells' corners), then along the row.
fn fill_rows(px: &Pixels, cells: &[Cell], fills: &[Fill], out: &mut Out) {
    let Some(first) = cells.first() else {
        return;
    };
    let (y0, y1) = first.knots[1];
    let mix = |p: Vec2, q: Vec2, f: f64| p * (1.0 - f) + q * f;
    let columns = out.columns.clone();
    for j in out.rows.clone() {
        let fy = (j - y0) as f64 / (y1 - y0) as f64;
        let at = |n: [&Node; 2]| mix(n[0].q, n[1].q, fy);
        let row = out.row(j);
        for (cell, fill) in cells.iter().zip(fills) {
            let [bl, br, tl, tr] = cell.corners;
            let (x0, x1) = cell.knots[0];
            let part = clip(&cell.columns, &columns);
            let pixels = part
                .clone()
                .zip(&mut row[part.start - columns.start..][..part.len()]);
            match fill {
                Fill::Bilinear => {
                    let (left, right) = (at([bl, tl]), at([br, tr]));
                    let step = (right - left) * (1.0 / (x1 - x0) as f64);
                    for (i, o) in pixels {
                        let q = left + step * (i - x0) as f64;
                        *o = [q.x as f32, q.y as f32];
                    }
                }
                Fill::Identity => {
                    for (i, o) in pixels {
                        let p = px.centre(i, j);
                        *o = [p.x as f32, p.y as f32];
                    }
                }
                Fill::Solve => {}
            }
        }
    }
}

/// `a` within `b`.
fn clip(a: &std::ops::Range<usize>, b: &std::ops::Range<usize>) -> std::ops::Range<usize> {
    a.start.max(b.start)..a.end.min(b.end).max(a.start.max(b.start))
}

/// The window's rows of one band of the map: pixels (in the grid's
/// region) `columns` of each of `rows`.
struct Out<'a> {
    data: &'a mut [[f32; 2]],
    rows: std::ops::Range<usize>,
    columns: std::ops::Range<usize>,
}

impl Out<'_> {
    /// Pixel row `j` of the region, the window's part of it.
    fn row(&mut self, j: usize) -> &mut [[f32; 2]] {
        let w = self.columns.len();
        &mut self.data[(j - self.rows.start) * w..][..w]
    }

    /// The map at pixel `(i, j)` of the region, if the window holds it.
    #[inline]
    fn put(&mut self, i: usize, j: usize, q: Vec2) {
        if self.rows.contains(&j) && self.columns.contains(&i) {
            let w = self.columns.len();
            self.data[(j - self.rows.start) * w + i - self.columns.start] =
                [q.x as f32, q.y as f32];
        }
    }
}
