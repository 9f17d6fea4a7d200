//! Smythe's two-pass mesh warp (seed 001, `meshWarp`), for any channel count
//! and float data, in parallel.
//!
//! The intermediate mesh takes its x from the destination and its y from the
//! source, so node `(x_s, y_s)` goes to `(x_d, y_s)` in the first pass (rows)
//! and on to `(x_d, y_d)` in the second (columns): every node lands exactly
//! where it should, and a mesh moved by one affine map warps affinely.

use rayon::prelude::*;

use super::spline::{self, Beyond};
use super::{fant, Mesh};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::{Plane, Sample, Sampler};

/// `src` warped so that the nodes of `from` (on the source) land on the nodes
/// of `to`, over the output pixels of `window` at `scale`. The result has the
/// sampler's channel layout; straight-alpha RGBA is filtered premultiplied.
pub fn two_pass<S: Sample>(
    src: &Sampler<'_, S>,
    from: &Mesh,
    to: &Mesh,
    window: RectI,
    scale: PixelScale,
) -> Plane {
    let b = src.bounds();
    let (n, h) = (b.width(), b.height());
    let (m, ho) = (window.width(), window.height());
    let mut plane = Plane {
        window,
        channels: src.channels(),
        pixels: vec![[0.0; 4]; m * ho],
    };
    if m == 0 || ho == 0 || n == 0 || h == 0 {
        return plane;
    }
    // Everything below works in pixel units: the source's, then the output's.
    let ss = src.scale();
    let from_px = from.map_nodes(|_, _, p| ss.to_pixel(p));
    let to_px = to.map_nodes(|_, _, p| scale.to_pixel(p));
    let mid = to_px.map_nodes(|r, c, p| Vec2::new(p.x, from_px.node(r, c).y));
    let edge = src.edge();
    let premultiply = src.alpha_weighted();

    // First pass: each source row is stretched so the source mesh's columns
    // (their x where they cross the row) move to the intermediate mesh's.
    let row_centres: Vec<f64> = (0..h).map(|j| b.y1 as f64 + j as f64 + 0.5).collect();
    let cross_src = column_crossings(&from_px, &row_centres);
    let cross_mid = column_crossings(&mid, &row_centres);
    let cols = from.cols();
    let src_edges: Vec<f64> = (0..=n).map(|i| b.x1 as f64 + i as f64).collect();
    let mut inter = vec![[0f32; 4]; h * m];
    inter
        .par_chunks_mut(m)
        .enumerate()
        .for_each_init(Buffers::default, |buf, (j, out)| {
            let y = b.y1 + j as i32;
            buf.line.clear();
            buf.line.extend((b.x1..b.x2).map(|i| {
                let mut px = [0f32; 4];
                src.pixel(i, y, &mut px);
                if premultiply {
                    px = [px[0] * px[3], px[1] * px[3], px[2] * px[3], px[3]];
                }
                px
            }));
            let knots = j * cols..(j + 1) * cols;
            buf.stretch(
                &cross_src[knots.clone()],
                &cross_mid[knots],
                &src_edges,
                window.x1,
                m,
            );
            let line = &buf.line;
            for (k, o) in out.iter_mut().enumerate() {
                *o = fant::sample(buf.pre[k], buf.pre[k + 1], n, edge, |i| line[i]);
            }
        });

    // Second pass: each output column is stretched so the intermediate
    // mesh's rows (their y where they cross the column) move to the
    // destination mesh's.
    let col_centres: Vec<f64> = (0..m).map(|k| window.x1 as f64 + k as f64 + 0.5).collect();
    let rows = from.rows();
    let cross_mid = row_crossings(&mid, &col_centres);
    let cross_dst = row_crossings(&to_px, &col_centres);
    let mid_edges: Vec<f64> = (0..=h).map(|i| b.y1 as f64 + i as f64).collect();
    let mut preimages = vec![0f64; m * (ho + 1)];
    preimages.par_chunks_mut(ho + 1).enumerate().for_each_init(
        Buffers::default,
        |buf, (k, out)| {
            let knots = k * rows..(k + 1) * rows;
            buf.stretch(
                &cross_mid[knots.clone()],
                &cross_dst[knots],
                &mid_edges,
                window.y1,
                ho,
            );
            out.copy_from_slice(&buf.pre);
        },
    );
    plane
        .pixels
        .par_chunks_mut(m)
        .enumerate()
        .for_each(|(l, out)| {
            for (k, o) in out.iter_mut().enumerate() {
                let at = k * (ho + 1) + l;
                let px = fant::sample(preimages[at], preimages[at + 1], h, edge, |i| {
                    inter[i * m + k]
                });
                *o = if premultiply && px[3] != 0.0 {
                    let inv = 1.0 / px[3];
                    [px[0] * inv, px[1] * inv, px[2] * inv, px[3]]
                } else {
                    px
                };
            }
        });
    plane
}

/// Per-worker scratch for one line.
#[derive(Default)]
struct Buffers {
    line: Vec<[f32; 4]>,
    knots: Vec<f64>,
    values: Vec<f64>,
    forward: Vec<f64>,
    /// Preimage of each output edge, in input pixels from the line's start.
    pre: Vec<f64>,
}

impl Buffers {
    /// The 1-D map of one line: the spline through `from[i] → to[i]`, taken
    /// at the input pixel edges `edges` and inverted at output edges
    /// `out_start + 0..=out_len`, into `self.pre`.
    fn stretch(&mut self, from: &[f64], to: &[f64], edges: &[f64], out_start: i32, out_len: usize) {
        self.knots.clear();
        self.knots.extend_from_slice(from);
        self.values.clear();
        self.values.extend_from_slice(to);
        spline::increasing(&mut self.knots, &mut self.values);
        self.forward.resize(edges.len(), 0.0);
        if self.knots.len() >= 2 {
            spline::eval_sorted(
                &self.knots,
                &self.values,
                Beyond::Shift,
                edges,
                &mut self.forward,
            );
        } else {
            self.forward.copy_from_slice(edges);
        }
        self.pre.resize(out_len + 1, 0.0);
        fant::invert(&self.forward, out_start as f64, &mut self.pre);
    }
}

/// Where each column spline of `mesh` (x as a function of y) crosses each
/// height of `at`: `[j * cols + c]`.
fn column_crossings(mesh: &Mesh, at: &[f64]) -> Vec<f64> {
    let (rows, cols) = (mesh.rows(), mesh.cols());
    let mut table = vec![0.0; at.len() * cols];
    let mut out = vec![0.0; at.len()];
    for c in 0..cols {
        let mut ys: Vec<f64> = (0..rows).map(|r| mesh.node(r, c).y).collect();
        let mut xs: Vec<f64> = (0..rows).map(|r| mesh.node(r, c).x).collect();
        spline::increasing(&mut ys, &mut xs);
        if ys.len() >= 2 {
            spline::eval_sorted(&ys, &xs, Beyond::Hold, at, &mut out);
        } else {
            out.fill(xs[0]);
        }
        for (j, v) in out.iter().enumerate() {
            table[j * cols + c] = *v;
        }
    }
    table
}

/// Where each row spline of `mesh` (y as a function of x) crosses each
/// abscissa of `at`: `[k * rows + r]`.
fn row_crossings(mesh: &Mesh, at: &[f64]) -> Vec<f64> {
    let (rows, cols) = (mesh.rows(), mesh.cols());
    let mut table = vec![0.0; at.len() * rows];
    let mut out = vec![0.0; at.len()];
    for r in 0..rows {
        let mut xs: Vec<f64> = (0..cols).map(|c| mesh.node(r, c).x).collect();
        let mut ys: Vec<f64> = (0..cols).map(|c| mesh.node(r, c).y).collect();
        spline::increasing(&mut xs, &mut ys);
        if xs.len() >= 2 {
            spline::eval_sorted(&xs, &ys, Beyond::Hold, at, &mut out);
        } else {
            out.fill(ys[0]);
        }
        for (k, v) in out.iter().enumerate() {
            table[k * rows + r] = *v;
        }
    }
    table
}
