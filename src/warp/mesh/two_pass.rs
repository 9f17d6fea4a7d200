//! Smythe's two-pass mesh warp (Wolberg, `meshWarp`), for any channel count
//! and float data, in parallel.
//!
//! The intermediate mesh takes its x from the destination and its y from the
//! source, so node `(x_s, y_s)` goes to `(x_d, y_s)` in the first pass (rows)
//! and on to `(x_d, y_d)` in the second (columns): every node lands exactly
//! where it should, and a mesh moved by one affine map warps affinely.

use std::ops::Range;

use rayon::prelude::*;

use super::spline::{self, Beyond};
use super::{fant, Mesh};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::{EdgeMode, Plane, Sample, Sampler};

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
    let (m, ho) = (window.width(), window.height());
    plane.channels = src.channels();
    plane.pixels.resize(m * ho, [0.0; 4]);
    if m == 0 || ho == 0 || b.width() == 0 || b.height() == 0 {
        plane.pixels.fill([0.0; 4]);
        return;
    }
    let maps = Maps::new(src, from, to, scale, window);

    // Strips of output columns, each made start to finish by one worker:
    // the strip's column maps, the first pass for just the intermediate
    // pixels it reads (strips partition the intermediate's columns, so none
    // is made twice), then its second pass. Everything a strip touches stays
    // in cache, and the whole intermediate image never exists.
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
            let (k0, w) = (index * STRIP, out[0].len());
            maps.column_maps(strip, k0, w);
            let rows = rows_read(&strip.pre, maps.h, maps.edge);
            maps.first_pass(src, strip, k0, w, rows.clone());
            maps.second_pass(strip, &mut out, w, rows);
        });
}

/// Output columns one worker makes start to finish.
const STRIP: usize = 96;

/// Both passes' maps, in pixel units (the source's, then the output's).
struct Maps {
    /// The source's pixels.
    b: RectI,
    /// Source width and height.
    n: usize,
    h: usize,
    /// Output height.
    ho: usize,
    edge: EdgeMode,
    premultiply: bool,
    /// Mesh columns and rows.
    cols: usize,
    rows: usize,
    /// First pass: where the columns of the source and intermediate meshes
    /// cross each source row; each row is stretched so the first move to
    /// the second.
    cross_src: Vec<f64>,
    cross_mid: Vec<f64>,
    out_x_edges: Vec<f64>,
    /// Second pass: where the rows of the intermediate and destination
    /// meshes cross each output column; each column is stretched likewise.
    cross_mid_rows: Vec<f64>,
    cross_dst: Vec<f64>,
    out_y_edges: Vec<f64>,
}

impl Maps {
    fn new<S: Sample>(
        src: &Sampler<'_, S>,
        from: &Mesh,
        to: &Mesh,
        scale: PixelScale,
        window: RectI,
    ) -> Maps {
        let b = src.bounds();
        let (n, h) = (b.width(), b.height());
        let (m, ho) = (window.width(), window.height());
        let ss = src.scale();
        let from_px = from.map_nodes(|_, _, p| ss.to_pixel(p));
        let to_px = to.map_nodes(|_, _, p| scale.to_pixel(p));
        let mid = to_px.map_nodes(|r, c, p| Vec2::new(p.x, from_px.node(r, c).y));
        let row_centres: Vec<f64> = (0..h).map(|j| b.y1 as f64 + j as f64 + 0.5).collect();
        let col_centres: Vec<f64> = (0..m).map(|k| window.x1 as f64 + k as f64 + 0.5).collect();
        Maps {
            b,
            n,
            h,
            ho,
            edge: src.edge(),
            premultiply: src.alpha_weighted(),
            cols: from.cols(),
            rows: from.rows(),
            cross_src: column_crossings(&from_px, &row_centres),
            cross_mid: column_crossings(&mid, &row_centres),
            out_x_edges: (0..=m).map(|k| window.x1 as f64 + k as f64).collect(),
            cross_mid_rows: row_crossings(&mid, &col_centres),
            cross_dst: row_crossings(&to_px, &col_centres),
            out_y_edges: (0..=ho).map(|l| window.y1 as f64 + l as f64).collect(),
        }
    }

    /// The strip's column maps: preimages of the output row edges in
    /// intermediate rows, stored row by row for the second pass.
    fn column_maps(&self, strip: &mut Strip, k0: usize, w: usize) {
        strip.pre.clear();
        strip.pre.resize(w * (self.ho + 1), 0.0);
        for c in 0..w {
            let knots = (k0 + c) * self.rows..(k0 + c + 1) * self.rows;
            let buf = &mut strip.buf;
            buf.stretch(
                &self.cross_mid_rows[knots.clone()],
                &self.cross_dst[knots],
                &self.out_y_edges,
                self.b.y1 as f64,
            );
            for (l, v) in buf.pre.iter().enumerate() {
                strip.pre[l * w + c] = *v as f32;
            }
        }
    }

    /// First pass: the strip's columns `k0..k0 + w` of intermediate `rows`.
    fn first_pass<S: Sample>(
        &self,
        src: &Sampler<'_, S>,
        strip: &mut Strip,
        k0: usize,
        w: usize,
        rows: Range<usize>,
    ) {
        let (b, n, edge) = (self.b, self.n, self.edge);
        let edges = &self.out_x_edges[k0..=k0 + w];
        strip.inter.resize(rows.len() * w, [0.0; 4]);
        for (r, dst) in rows.zip(strip.inter.chunks_exact_mut(w)) {
            let buf = &mut strip.buf;
            let knots = r * self.cols..(r + 1) * self.cols;
            buf.stretch(
                &self.cross_src[knots.clone()],
                &self.cross_mid[knots],
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
            let (s0, s1) = self.columns_read(span(&buf.pre));
            src.load_span(b.y1 + r as i32, b.x1 + s0 as i32, s1 - s0, &mut buf.line);
            let (line, pre) = (&buf.line, &buf.pre);
            let top = s1 - s0 - 1;
            for (k, o) in dst.iter_mut().enumerate() {
                *o = fant::sample(pre[k], pre[k + 1], n, edge, |i| {
                    line[i.saturating_sub(s0).min(top)]
                });
            }
        }
    }

    /// The source columns `s0..s1` preimages spanning `lo..hi` read: one
    /// pixel of margin before, three after for the filter (mirroring can
    /// reach anywhere once it leaves the image, so then every column).
    fn columns_read(&self, (lo, hi): (f64, f64)) -> (usize, usize) {
        let n = self.n;
        if self.edge == EdgeMode::Mirror && (lo < 0.0 || hi > n as f64) {
            return (0, n);
        }
        let s0 = (lo.floor() as i64 - 1).clamp(0, n as i64 - 1) as usize;
        let s1 = (hi.ceil() as i64 + 3).clamp(s0 as i64 + 1, n as i64) as usize;
        (s0, s1)
    }

    /// Second pass, row by row of the strip, from intermediate `rows`.
    fn second_pass(
        &self,
        strip: &Strip,
        out: &mut [&mut [[f32; 4]]],
        w: usize,
        rows: Range<usize>,
    ) {
        let (inter, pre) = (&strip.inter, &strip.pre);
        let (r0, last) = (rows.start, rows.len() - 1);
        for (l, row) in out.iter_mut().enumerate() {
            let (top, bottom) = (&pre[l * w..(l + 1) * w], &pre[(l + 1) * w..(l + 2) * w]);
            for (c, o) in row.iter_mut().enumerate() {
                let px = fant::sample(top[c] as f64, bottom[c] as f64, self.h, self.edge, |i| {
                    inter[i.saturating_sub(r0).min(last) * w + c]
                });
                *o = if self.premultiply && px[3] != 0.0 {
                    let inv = 1.0 / px[3];
                    [px[0] * inv, px[1] * inv, px[2] * inv, px[3]]
                } else {
                    px
                };
            }
        }
    }
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
fn rows_read(preimages: &[f32], h: usize, edge: EdgeMode) -> Range<usize> {
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
    if !(lo.is_finite() && hi.is_finite()) || (reaches_out && edge == EdgeMode::Mirror) {
        return 0..h;
    }
    let r0 = (lo.floor() as i64 - 1).clamp(0, h as i64 - 1) as usize;
    let r1 = (hi.ceil() as i64 + 1).clamp(r0 as i64 + 1, h as i64) as usize;
    r0..r1
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
