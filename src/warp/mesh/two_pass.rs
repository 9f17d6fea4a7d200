//! Smythe's two-pass mesh warp (Wolberg, `meshWarp`), for any channel count
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
    let mut plane = Plane {
        window,
        channels: src.channels(),
        pixels: Vec::new(),
    };
    two_pass_into(src, from, to, scale, &mut plane);
    plane
}

/// [`two_pass`] into `plane` (its window says which output pixels), reusing
/// its allocation: a sequence render that keeps its planes skips the cost of
/// fresh memory, which is a fifth of the work at 1080p.
pub fn two_pass_into<S: Sample>(
    src: &Sampler<'_, S>,
    from: &Mesh,
    to: &Mesh,
    scale: PixelScale,
    plane: &mut Plane,
) {
    let window = plane.window;
    let b = src.bounds();
    let (n, h) = (b.width(), b.height());
    let (m, ho) = (window.width(), window.height());
    plane.channels = src.channels();
    plane.pixels.resize(m * ho, [0.0; 4]);
    if m == 0 || ho == 0 || n == 0 || h == 0 {
        plane.pixels.fill([0.0; 4]);
        return;
    }
    // Everything below works in pixel units: the source's, then the output's.
    let ss = src.scale();
    let from_px = from.map_nodes(|_, _, p| ss.to_pixel(p));
    let to_px = to.map_nodes(|_, _, p| scale.to_pixel(p));
    let mid = to_px.map_nodes(|r, c, p| Vec2::new(p.x, from_px.node(r, c).y));
    let edge = src.edge();
    let premultiply = src.alpha_weighted();

    // First pass's maps: where the columns of the source and intermediate
    // meshes cross each source row. Each source row is stretched so the
    // first move to the second.
    let row_centres: Vec<f64> = (0..h).map(|j| b.y1 as f64 + j as f64 + 0.5).collect();
    let cross_src = column_crossings(&from_px, &row_centres);
    let cross_mid = column_crossings(&mid, &row_centres);
    let cols = from.cols();
    let out_x_edges: Vec<f64> = (0..=m).map(|k| window.x1 as f64 + k as f64).collect();

    // Second pass's maps: where the rows of the intermediate and destination
    // meshes cross each output column. Each column is stretched so the
    // first move to the second.
    let col_centres: Vec<f64> = (0..m).map(|k| window.x1 as f64 + k as f64 + 0.5).collect();
    let rows = from.rows();
    let cross_mid_rows = row_crossings(&mid, &col_centres);
    let cross_dst = row_crossings(&to_px, &col_centres);
    let out_y_edges: Vec<f64> = (0..=ho).map(|l| window.y1 as f64 + l as f64).collect();

    // Strips of output columns, each made start to finish by one worker:
    // the strip's column maps, the first pass for just the intermediate
    // pixels it reads (strips partition the intermediate's columns, so none
    // is made twice), then its second pass. Everything a strip touches stays
    // in cache, and the whole intermediate image never exists.
    const STRIP: usize = 96;
    let strips = m.div_ceil(STRIP);
    let mut pieces: Vec<Vec<&mut [[f32; 4]]>> =
        (0..strips).map(|_| Vec::with_capacity(ho)).collect();
    for row in plane.pixels.chunks_exact_mut(m) {
        for (s, piece) in row.chunks_mut(STRIP).enumerate() {
            pieces[s].push(piece);
        }
    }
    pieces
        .into_par_iter()
        .enumerate()
        .for_each_init(Strip::default, |strip, (index, mut out)| {
            let k0 = index * STRIP;
            let w = out[0].len();
            // The strip's column maps: preimages of the output row edges in
            // intermediate rows, stored row by row for the second pass.
            strip.pre.clear();
            strip.pre.resize(w * (ho + 1), 0.0);
            for c in 0..w {
                let knots = (k0 + c) * rows..(k0 + c + 1) * rows;
                let buf = &mut strip.buf;
                buf.stretch(
                    &cross_mid_rows[knots.clone()],
                    &cross_dst[knots],
                    &out_y_edges,
                    b.y1 as f64,
                );
                for (l, v) in buf.pre.iter().enumerate() {
                    strip.pre[l * w + c] = *v as f32;
                }
            }
            let (r0, r1) = rows_read(&strip.pre, h, edge);

            // First pass: the strip's columns of intermediate rows r0..r1.
            let edges = &out_x_edges[k0..=k0 + w];
            strip.inter.resize((r1 - r0) * w, [0.0; 4]);
            for (r, dst) in (r0..r1).zip(strip.inter.chunks_exact_mut(w)) {
                let buf = &mut strip.buf;
                let knots = r * cols..(r + 1) * cols;
                buf.stretch(
                    &cross_src[knots.clone()],
                    &cross_mid[knots],
                    edges,
                    b.x1 as f64,
                );
                if let Some(row) = src.float_rgba_row(b.y1 + r as i32) {
                    // Float RGBA: read the source row where it lies.
                    let pre = &buf.pre;
                    for (k, o) in dst.iter_mut().enumerate() {
                        *o = fant::sample(pre[k], pre[k + 1], n, edge, |i| row[i]);
                    }
                    continue;
                }
                // Only the source pixels these preimages reach are converted.
                let (lo, hi) = span(&buf.pre);
                let (s0, s1) =
                    if edge == crate::image::EdgeMode::Mirror && (lo < 0.0 || hi > n as f64) {
                        (0, n)
                    } else {
                        let s0 = (lo.floor() as i64 - 1).clamp(0, n as i64 - 1) as usize;
                        (
                            s0,
                            (hi.ceil() as i64 + 3).clamp(s0 as i64 + 1, n as i64) as usize,
                        )
                    };
                src.load_span(b.y1 + r as i32, b.x1 + s0 as i32, s1 - s0, &mut buf.line);
                let (line, pre) = (&buf.line, &buf.pre);
                let top = s1 - s0 - 1;
                for (k, o) in dst.iter_mut().enumerate() {
                    *o = fant::sample(pre[k], pre[k + 1], n, edge, |i| {
                        line[i.saturating_sub(s0).min(top)]
                    });
                }
            }

            // Second pass, row by row of the strip.
            let (inter, pre) = (&strip.inter, &strip.pre);
            let last = r1 - r0 - 1;
            for (l, row) in out.iter_mut().enumerate() {
                let (top, bottom) = (&pre[l * w..(l + 1) * w], &pre[(l + 1) * w..(l + 2) * w]);
                for (c, o) in row.iter_mut().enumerate() {
                    let px = fant::sample(top[c] as f64, bottom[c] as f64, h, edge, |i| {
                        inter[i.saturating_sub(r0).min(last) * w + c]
                    });
                    *o = if premultiply && px[3] != 0.0 {
                        let inv = 1.0 / px[3];
                        [px[0] * inv, px[1] * inv, px[2] * inv, px[3]]
                    } else {
                        px
                    };
                }
            }
        });
}

/// Smallest and largest value.
fn span(values: &[f64]) -> (f64, f64) {
    values
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)))
}

/// Per-worker scratch for one strip of output columns.
#[derive(Default)]
struct Strip {
    /// First-pass pixels the strip reads, row by row.
    inter: Vec<[f32; 4]>,
    /// The strip's column maps, row by row of the output.
    pre: Vec<f32>,
    buf: Buffers,
}

/// The intermediate rows `r0..r1` a strip reads, from its preimages: their
/// span, one row of margin for the filter, through the edge mode (mirroring
/// can reach anywhere, so it takes every row).
fn rows_read(preimages: &[f32], h: usize, edge: crate::image::EdgeMode) -> (usize, usize) {
    // Eight lanes at a time: this scans every preimage of the strip.
    let (mut lo8, mut hi8) = (wide::f32x8::splat(f32::MAX), wide::f32x8::splat(f32::MIN));
    let (chunks, rest) = preimages.as_chunks::<8>();
    for c in chunks {
        let v = wide::f32x8::new(*c);
        lo8 = lo8.min(v);
        hi8 = hi8.max(v);
    }
    let lo = lo8
        .to_array()
        .into_iter()
        .chain(rest.iter().copied())
        .fold(f32::MAX, f32::min);
    let hi = hi8
        .to_array()
        .into_iter()
        .chain(rest.iter().copied())
        .fold(f32::MIN, f32::max);
    let reaches_out = lo < 0.0 || hi > h as f32;
    if !(lo.is_finite() && hi.is_finite())
        || (reaches_out && edge == crate::image::EdgeMode::Mirror)
    {
        return (0, h);
    }
    let r0 = (lo.floor() as i64 - 1).clamp(0, h as i64 - 1) as usize;
    let r1 = (hi.ceil() as i64 + 1).clamp(r0 as i64 + 1, h as i64) as usize;
    (r0, r1)
}

/// Per-worker scratch for one line.
#[derive(Default)]
struct Buffers {
    line: Vec<[f32; 4]>,
    knots: Vec<f64>,
    values: Vec<f64>,
    /// Preimage of each output edge, in input pixels from the line's start.
    pre: Vec<f64>,
}

impl Buffers {
    /// The 1-D map of one line, fitted from output to input: the spline
    /// through `to[i] → from[i]` taken at the output edges `out_edges`, in
    /// input pixels from `in_start`, into `self.pre`. (The listing fits the
    /// forward spline and inverts it numerically; fitting the inverse
    /// directly interpolates the same node pairs, reproduces affine maps just
    /// the same, and costs one evaluation per output edge.)
    fn stretch(&mut self, from: &[f64], to: &[f64], out_edges: &[f64], in_start: f64) {
        self.knots.clear();
        self.knots.extend_from_slice(to);
        self.values.clear();
        self.values.extend_from_slice(from);
        spline::increasing(&mut self.knots, &mut self.values);
        self.pre.resize(out_edges.len(), 0.0);
        if self.knots.len() >= 2 {
            spline::eval_sorted(
                &self.knots,
                &self.values,
                Beyond::Shift,
                out_edges,
                &mut self.pre,
            );
        } else {
            self.pre.copy_from_slice(out_edges);
        }
        for p in &mut self.pre {
            *p -= in_start;
        }
    }
}

/// Where each column spline of `mesh` (x as a function of y) crosses each
/// height of `at`: `[j * cols + c]`.
fn column_crossings(mesh: &Mesh, at: &[f64]) -> Vec<f64> {
    let splines = (0..mesh.cols()).map(|c| {
        (0..mesh.rows())
            .map(move |r| mesh.node(r, c))
            .map(|p| (p.y, p.x))
    });
    crossings(splines, mesh.cols(), at)
}

/// Where each row spline of `mesh` (y as a function of x) crosses each
/// abscissa of `at`: `[k * rows + r]`.
fn row_crossings(mesh: &Mesh, at: &[f64]) -> Vec<f64> {
    let splines = (0..mesh.rows()).map(|r| {
        (0..mesh.cols())
            .map(move |c| mesh.node(r, c))
            .map(|p| (p.x, p.y))
    });
    crossings(splines, mesh.rows(), at)
}

/// Each spline (knot, value pairs) taken at every position of `at`, as a
/// table `[position * count + spline]`.
fn crossings<I, S>(splines: I, count: usize, at: &[f64]) -> Vec<f64>
where
    I: Iterator<Item = S>,
    S: Iterator<Item = (f64, f64)>,
{
    let mut table = vec![0.0; at.len() * count];
    let mut out = vec![0.0; at.len()];
    for (i, spline) in splines.enumerate() {
        let (mut knots, mut values): (Vec<f64>, Vec<f64>) = spline.unzip();
        spline::increasing(&mut knots, &mut values);
        if knots.len() >= 2 {
            spline::eval_sorted(&knots, &values, Beyond::Hold, at, &mut out);
        } else {
            out.fill(values[0]);
        }
        for (j, v) in out.iter().enumerate() {
            table[j * count + i] = *v;
        }
    }
    table
}
