//! The one-pass mesh map: each mesh is a tensor-product Catmull-Rom surface
//! `S(s, r)` over its node indices (uniform parameters, end tangents from
//! linearly extrapolated phantom nodes, so straight rows stay straight). An
//! output point `p` is located on the in-between surface by Newton's method,
//! `S_to(s, r) = p`, and sampled at `S_from(s, r)`. Row neighbours start from
//! each other's solution, so most pixels converge in one or two steps.

mod grid;
mod lanes;
mod quads;

use rayon::prelude::*;

use super::{Mesh, MeshPair};
use crate::features::{Side, Tween};
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;
use crate::warp::Warp;

/// Catmull-Rom basis in powers of the local parameter (times 2).
const M: [[f64; 4]; 4] = [
    [0.0, 2.0, 0.0, 0.0],
    [-1.0, 0.0, 1.0, 0.0],
    [2.0, -5.0, 4.0, -1.0],
    [-1.0, 3.0, -3.0, 1.0],
];

/// Rows of the map computed together, one per lane of `f64x4` ([`lanes`]).
const LANES: usize = 4;
/// Columns at which the Newton chains along a row of pixels start cold,
/// fixed in the image so that any window of a map has the whole frame's
/// bits (a multiple of every grid step: 2, 3 and 4).
const RUN: i32 = 48;

/// Newton stops when the located point is this close (canonical pixels).
const TOLERANCE: f64 = 1e-7;
const MAX_STEPS: usize = 16;
/// Newton also stops after a step shorter than this (cells); see
/// [`Surface::solve`].
const EARLY_EXIT: f64 = 1e-4;

/// Surface parameters `(s, r)`: column and row index, fractional.
type Params = (f64, f64);

/// One mesh as bicubic patches in power form, one per cell.
#[derive(Debug, Clone)]
pub(super) struct Surface {
    rows: usize,
    cols: usize,
    /// Per cell: x then y coefficients, `c[i * 4 + j]` for `u^i v^j`.
    coef: Vec<[[f64; 16]; 2]>,
    /// The node quads, for finding a starting cell, and their bounds.
    quads: quads::Quads,
    bounds: (Vec2, Vec2),
}

impl Surface {
    pub(super) fn new(mesh: &Mesh) -> Surface {
        let (rows, cols) = (mesh.rows(), mesh.cols());
        // Phantom nodes one step outside continue the border linearly.
        let node = |r: isize, c: isize| -> Vec2 {
            let along_c = |r: usize, c: isize| -> Vec2 {
                let last = cols as isize - 1;
                if c < 0 {
                    mesh.node(r, 0) * 2.0 - mesh.node(r, 1)
                } else if c > last {
                    mesh.node(r, cols - 1) * 2.0 - mesh.node(r, cols - 2)
                } else {
                    mesh.node(r, c as usize)
                }
            };
            let last = rows as isize - 1;
            if r < 0 {
                along_c(0, c) * 2.0 - along_c(1, c)
            } else if r > last {
                along_c(rows - 1, c) * 2.0 - along_c(rows - 2, c)
            } else {
                along_c(r as usize, c)
            }
        };
        let mut coef = Vec::with_capacity((rows - 1) * (cols - 1));
        let mut quads = Vec::with_capacity(coef.capacity());
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let p = |b: usize, a: usize| {
                    node(r as isize - 1 + b as isize, c as isize - 1 + a as isize)
                };
                let mut cell = [[0.0; 16]; 2];
                for i in 0..4 {
                    for j in 0..4 {
                        let mut acc = Vec2::default();
                        for (a, mia) in M[i].iter().enumerate() {
                            for (b, mjb) in M[j].iter().enumerate() {
                                let w = mia * mjb;
                                if w != 0.0 {
                                    acc += p(b, a) * w;
                                }
                            }
                        }
                        cell[0][i * 4 + j] = 0.25 * acc.x;
                        cell[1][i * 4 + j] = 0.25 * acc.y;
                    }
                }
                coef.push(cell);
                quads.push([
                    mesh.node(r, c),
                    mesh.node(r, c + 1),
                    mesh.node(r + 1, c + 1),
                    mesh.node(r + 1, c),
                ]);
            }
        }
        let lo = mesh
            .nodes()
            .iter()
            .fold(Vec2::new(f64::MAX, f64::MAX), |m, p| {
                Vec2::new(m.x.min(p.x), m.y.min(p.y))
            });
        let hi = mesh
            .nodes()
            .iter()
            .fold(Vec2::new(f64::MIN, f64::MIN), |m, p| {
                Vec2::new(m.x.max(p.x), m.y.max(p.y))
            });
        Surface {
            rows,
            cols,
            coef,
            quads: quads::Quads::new(quads, lo, hi),
            bounds: (lo, hi),
        }
    }

    /// The cell (column, row) whose patch evaluates `(s, r)`: the one
    /// holding it, or the nearest border cell for parameters outside.
    #[inline]
    fn cell(&self, s: f64, r: f64) -> (usize, usize) {
        let c = (s.floor() as isize).clamp(0, self.cols as isize - 2) as usize;
        let k = (r.floor() as isize).clamp(0, self.rows as isize - 2) as usize;
        (c, k)
    }

    /// `S(s, r)` and its partial derivatives.
    #[inline]
    fn eval(&self, s: f64, r: f64) -> (Vec2, Vec2, Vec2) {
        let (c, k) = self.cell(s, r);
        let (u, v) = (s - c as f64, r - k as f64);
        let cell = &self.coef[k * (self.cols - 1) + c];
        let pu = [1.0, u, u * u, u * u * u];
        let du = [0.0, 1.0, 2.0 * u, 3.0 * u * u];
        let pv = [1.0, v, v * v, v * v * v];
        let dv = [0.0, 1.0, 2.0 * v, 3.0 * v * v];
        let mut out = [[0.0; 3]; 2];
        for (axis, o) in cell.iter().zip(out.iter_mut()) {
            for i in 0..4 {
                let row = &axis[i * 4..i * 4 + 4];
                let cv = row[0] * pv[0] + row[1] * pv[1] + row[2] * pv[2] + row[3] * pv[3];
                let cdv = row[1] * dv[1] + row[2] * dv[2] + row[3] * dv[3];
                o[0] += pu[i] * cv;
                o[1] += du[i] * cv;
                o[2] += pu[i] * cdv;
            }
        }
        (
            Vec2::new(out[0][0], out[1][0]),
            Vec2::new(out[0][1], out[1][1]),
            Vec2::new(out[0][2], out[1][2]),
        )
    }

    /// `S(s, r)` alone (no derivatives): where a located point samples.
    #[inline]
    pub(super) fn position(&self, s: f64, r: f64) -> Vec2 {
        let (c, k) = self.cell(s, r);
        let (u, v) = (s - c as f64, r - k as f64);
        let cell = &self.coef[k * (self.cols - 1) + c];
        let pu = [1.0, u, u * u, u * u * u];
        let pv = [1.0, v, v * v, v * v * v];
        let mut out = [0.0; 2];
        for (axis, o) in cell.iter().zip(out.iter_mut()) {
            for i in 0..4 {
                let row = &axis[i * 4..i * 4 + 4];
                let cv = row[0] * pv[0] + row[1] * pv[1] + row[2] * pv[2] + row[3] * pv[3];
                *o += pu[i] * cv;
            }
        }
        Vec2::new(out[0], out[1])
    }

    /// The shortest side of any cell's node quad (canonical px).
    fn smallest_cell(&self) -> f64 {
        self.quads
            .all()
            .iter()
            .flat_map(|q| (0..4).map(move |k| q[k].distance(q[(k + 1) % 4])))
            .fold(f64::INFINITY, f64::min)
    }

    pub(super) fn inside_domain(&self, s: f64, r: f64) -> bool {
        let eps = 1e-9;
        s >= -eps
            && s <= (self.cols - 1) as f64 + eps
            && r >= -eps
            && r <= (self.rows - 1) as f64 + eps
    }

    /// Newton from `(s, r)`; the parameters where `S = p`, if found.
    pub(super) fn solve(&self, p: Vec2, mut s: f64, mut r: f64) -> Option<(f64, f64)> {
        let (hi_s, hi_r) = (self.cols as f64, self.rows as f64);
        for _ in 0..MAX_STEPS {
            let (q, du, dv) = self.eval(s, r);
            let e = p - q;
            if e.length_squared() <= TOLERANCE * TOLERANCE {
                return Some((s, r));
            }
            let det = du.x * dv.y - du.y * dv.x;
            if det.abs() < 1e-12 || !det.is_finite() {
                return None;
            }
            let mut ds = (e.x * dv.y - e.y * dv.x) / det;
            let mut dr = (du.x * e.y - du.y * e.x) / det;
            // At most one cell per step: the patches are only locally cubic.
            let m = ds.abs().max(dr.abs());
            if m > 1.0 {
                ds /= m;
                dr /= m;
            }
            s = (s + ds).clamp(-1.0, hi_s);
            r = (r + dr).clamp(-1.0, hi_r);
            // Newton converges quadratically: a step of `m` cells leaves an
            // error of about m² cells (the patches bend by about their
            // slope per cell), so after one this small the point lies within
            // ~1e-6 px on a 100 px cell, under the f32 map's rounding: no
            // need to evaluate again.
            if m < EARLY_EXIT {
                return Some((s, r));
            }
        }
        None
    }

    /// A starting point: where `p` lies in the bilinear quad of the
    /// cell's nodes that holds it (the patch passes through those nodes,
    /// so Newton starts a fraction of a cell off at most).
    pub(super) fn start(&self, p: Vec2) -> Option<(f64, f64)> {
        let (lo, hi) = self.bounds;
        if p.x < lo.x || p.y < lo.y || p.x > hi.x || p.y > hi.y {
            return None;
        }
        let k = self.quads.holding(p)?;
        let (u, v) = quads::within(&self.quads.all()[k], p);
        let cells = self.cols - 1;
        Some(((k % cells) as f64 + u, (k / cells) as f64 + v))
    }
}

/// The reverse map of a mesh pair's warp: output positions on mesh `to`,
/// source positions on mesh `from`. Outside the meshes (whose borders are
/// frozen, so the two agree there) every point maps to itself.
#[derive(Debug, Clone)]
pub struct MeshWarp {
    to: Surface,
    from: Surface,
    identity: bool,
    /// How far a dense map may stray from Newton at every pixel (the
    /// render's px); `None`: not at all.
    tolerance: Option<f64>,
}

impl MeshWarp {
    /// How far the dense maps of renders stray from the exact map at most
    /// (the render's px): under half the field's default, far under what a
    /// resampled image shows, and under a seventh of how far the two-pass
    /// warp differs from the one-pass map.
    pub const TOLERANCE: f64 = 0.02;

    /// The reverse map from mesh `to` (output) to mesh `from` (source),
    /// solved at every pixel of a dense map.
    pub fn new(from: &Mesh, to: &Mesh) -> MeshWarp {
        MeshWarp {
            to: Surface::new(to),
            from: Surface::new(from),
            identity: from == to,
            tolerance: None,
        }
    }

    /// This warp with dense maps solved on a coarse grid and interpolated
    /// where that stays within `tolerance` of the exact map (in the render's
    /// pixels: a proxy render's map is held to its own coarser pixels).
    pub fn within(self, tolerance: f64) -> MeshWarp {
        MeshWarp {
            tolerance: Some(tolerance),
            ..self
        }
    }

    /// The warp of the image on `side` toward the in-between mesh at `t`,
    /// dense maps within [`MeshWarp::TOLERANCE`].
    pub fn toward<'a>(pair: &MeshPair, side: Side, t: impl Into<Tween<'a>>) -> MeshWarp {
        MeshWarp::new(pair.side(side), &pair.tween(t.into())).within(MeshWarp::TOLERANCE)
    }

    /// `p` mapped, starting Newton at `guess`; returns the parameters used so
    /// the next pixel can start there.
    #[inline]
    fn locate(&self, p: Vec2, guess: Option<(f64, f64)>) -> (Vec2, Option<(f64, f64)>) {
        let found = guess
            .and_then(|(s, r)| self.to.solve(p, s, r))
            .filter(|&(s, r)| self.to.inside_domain(s, r))
            .or_else(|| {
                let (s, r) = self.to.start(p)?;
                self.to.solve(p, s, r)
            });
        match found {
            Some((s, r)) if self.to.inside_domain(s, r) => (self.from.position(s, r), Some((s, r))),
            _ => (p, None),
        }
    }

    fn map_run(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        let mut guess = None;
        for i in 0..xs.len() {
            let (q, g) = self.locate(Vec2::new(xs[i] as f64, ys[i] as f64), guess);
            guess = g.or(guess);
            out_x[i] = q.x as f32;
            out_y[i] = q.y as f32;
        }
    }
}

/// Each pixel starts Newton where the last two solutions of its row point:
/// one step usually lands within tolerance.
fn extrapolate(prev: Option<Params>, before: Option<Params>) -> Option<Params> {
    match (prev, before) {
        (Some(a), Some(b)) => Some((2.0 * a.0 - b.0, 2.0 * a.1 - b.1)),
        _ => prev,
    }
}

/// A row's last two solutions, the pixel just mapped's first; a pixel off
/// the mesh forgets both.
#[derive(Clone, Copy, Default)]
struct Trail {
    prev: Option<Params>,
    before: Option<Params>,
}

impl Trail {
    fn guess(&self) -> Option<Params> {
        extrapolate(self.prev, self.before)
    }

    fn push(&mut self, found: Option<Params>) {
        *self = match found {
            Some(_) => Trail {
                prev: found,
                before: self.prev,
            },
            None => Trail::default(),
        };
    }
}

impl MeshWarp {
    /// Rows `j..` of the map (as many as `out` holds, up to [`LANES`]),
    /// pixels `x1..`, into `out`: each row in runs that start Newton cold
    /// at multiples of [`RUN`] in the image, solved from the start of
    /// the first, so that any window has the bits of the whole frame.
    fn map_band(&self, (x1, w): (i32, usize), j: i32, scale: PixelScale, out: &mut [[f32; 2]]) {
        let rows = out.len() / w;
        let x2 = x1 + w as i32;
        let mut start = x1.div_euclid(RUN) * RUN;
        let mut run = Vec::new();
        while start < x2 {
            let n = ((start + RUN).min(x2) - start) as usize;
            run.clear();
            run.resize(rows * n, [0f32; 2]);
            if rows == LANES {
                self.map_rows4(start, j, scale, &mut run);
            } else {
                for (r, row) in run.chunks_mut(n).enumerate() {
                    self.map_row(start, j + r as i32, scale, row);
                }
            }
            // The first run may start left of the window.
            let skip = (x1 - start).max(0) as usize;
            let at = (start + skip as i32 - x1) as usize;
            for r in 0..rows {
                out[r * w + at..][..n - skip].copy_from_slice(&run[r * n + skip..][..n - skip]);
            }
            start += RUN;
        }
    }

    /// Row `j` of the map, pixels `x1..`, into `out`.
    fn map_row(&self, x1: i32, j: i32, scale: PixelScale, out: &mut [[f32; 2]]) {
        let points = (0..out.len()).map(|k| scale.pixel_centre(x1 + k as i32, j));
        self.locate_run(points, None, |k, q, _| out[k] = [q.x as f32, q.y as f32]);
    }

    /// `points` of one row mapped in turn, each starting Newton where the
    /// row's last two solutions point (the first from `seed`): `emit(k,
    /// where it maps, its parameters)` for the `k`th. [`MeshWarp::rows4`]
    /// does this for four rows at once.
    fn locate_run(
        &self,
        points: impl Iterator<Item = Vec2>,
        seed: Option<Params>,
        mut emit: impl FnMut(usize, Vec2, Option<Params>),
    ) {
        let mut trail = Trail::default();
        trail.push(seed);
        for (k, p) in points.enumerate() {
            let (q, at) = self.locate(p, trail.guess());
            trail.push(at);
            emit(k, q, at);
        }
    }
}

impl Warp for MeshWarp {
    fn map(&self, p: Vec2) -> Vec2 {
        if self.identity {
            return p;
        }
        self.locate(p, None).0
    }

    fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        if self.identity {
            out_x.copy_from_slice(xs);
            out_y.copy_from_slice(ys);
            return;
        }
        self.map_run(xs, ys, out_x, out_y);
    }

    fn is_identity(&self) -> bool {
        self.identity
    }

    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.identity {
            return WarpMap::identity(window, scale);
        }
        let w = window.width();
        let mut pos = vec![[0f32; 2]; window.area()];
        let grid = self
            .tolerance
            .and_then(|tolerance| self.map_grid(window, scale, tolerance, &mut pos));
        if grid.is_none() && w > 0 {
            pos.par_chunks_mut(LANES * w)
                .enumerate()
                .for_each(|(band, out)| {
                    let j = window.y1 + (LANES * band) as i32;
                    self.map_band((window.x1, w), j, scale, out);
                });
        }
        WarpMap::new(window, scale, pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(s, r)` with `S(s, r) = p` to 1e-10 px, by plain Newton from the
    /// cell the point lies in: no warm start, no early exit.
    fn strict(surface: &Surface, p: Vec2) -> Option<(f64, f64)> {
        let (mut s, mut r) = surface.start(p)?;
        for _ in 0..50 {
            let (q, du, dv) = surface.eval(s, r);
            let e = p - q;
            if e.length() < 1e-10 {
                return Some((s, r));
            }
            let det = du.x * dv.y - du.y * dv.x;
            s += (e.x * dv.y - e.y * dv.x) / det;
            r += (du.x * e.y - du.y * e.x) / det;
        }
        None
    }

    /// A 240 × 160 mesh pair whose interior bends by up to 9 px.
    fn curved() -> MeshWarp {
        let src = Mesh::regular(7, 9, 0.0, 0.0, 240.0, 160.0).unwrap();
        let dst = src.map_nodes(|r, c, p| {
            if r == 0 || c == 0 || r == 6 || c == 8 {
                return p;
            }
            p + Vec2::new(9.0 * (p.y * 0.05).sin(), 7.0 * (p.x * 0.04).cos())
        });
        MeshWarp::new(&src, &dst)
    }

    #[test]
    fn four_rows_at_once_give_the_one_row_paths_bits() {
        let warp = curved();
        // Past the mesh on every side, and a height no multiple of four.
        let window = RectI::new(-12, -7, 251, 170);
        let map = warp.map_window(window, PixelScale::UNIT);
        let w = window.width();
        for j in window.y1..window.y2 {
            let mut row = vec![[0f32; 2]; w];
            warp.map_band((window.x1, w), j, PixelScale::UNIT, &mut row);
            let got = map.row(j).unwrap();
            for (i, (a, b)) in got.iter().zip(&row).enumerate() {
                assert_eq!(
                    a.map(f32::to_bits),
                    b.map(f32::to_bits),
                    "pixel ({}, {j})",
                    window.x1 + i as i32
                );
            }
        }
    }

    /// Tiles, chunks of rows and single scanlines of a map have the bits
    /// of the whole frame's map there, on the grid and solved at every
    /// pixel, at full and half scale: the grid and the Newton chains are
    /// fixed in the image, not in the window.
    #[test]
    fn any_window_of_the_map_has_the_whole_frames_bits() {
        let frame = RectI::new(-12, -7, 251, 170);
        for (exact, scale) in [(false, 1.0), (false, 0.5), (true, 1.0), (true, 0.5)] {
            let warp = match exact {
                true => curved(),
                false => curved().within(MeshWarp::TOLERANCE),
            };
            let scale = PixelScale::new(scale, scale, 1.0);
            let frame = RectI::new(frame.x1, frame.y1, frame.x2, frame.y2);
            let whole = warp.map_window(frame, scale);
            let windows = [
                RectI::new(0, 0, 64, 64),
                RectI::new(37, 21, 101, 83),
                RectI::new(-12, 55, 251, 56),
                RectI::new(130, -7, 131, 170),
                RectI::new(61, 150, 250, 169),
            ];
            for window in windows {
                let part = warp.map_window(window, scale);
                for j in window.y1..window.y2 {
                    let (got, want) = (part.row(j).unwrap(), whole.row(j).unwrap());
                    let want = &want[(window.x1 - frame.x1) as usize..][..got.len()];
                    for (i, (a, b)) in got.iter().zip(want).enumerate() {
                        assert_eq!(
                            a.map(f32::to_bits),
                            b.map(f32::to_bits),
                            "exact {exact}, scale {scale:?}, {window:?}: pixel ({}, {j})",
                            window.x1 + i as i32
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn the_lanes_settle_nearly_every_pixel_of_a_curved_mesh() {
        let warp = curved();
        // Bands of four rows as the map goes, guesses from the one-row path:
        // on this mesh most pixels take two Newton steps.
        let (mut lanes, mut settled) = (0, 0);
        for j in (4..150).step_by(4) {
            let mut trails = [Trail::default(); LANES];
            for i in 4..236 {
                let p: [Vec2; LANES] =
                    std::array::from_fn(|l| PixelScale::UNIT.pixel_centre(i, j + l as i32));
                let guesses = trails.map(|t| t.guess());
                if guesses.iter().all(Option::is_some) {
                    let g = guesses.map(Option::unwrap);
                    let s = wide::f64x4::new(g.map(|g| g.0));
                    let r = wide::f64x4::new(g.map(|g| g.1));
                    let at = lanes::Lanes {
                        s,
                        r,
                        found: 0b1111,
                    };
                    let found = warp.to.solve4(lanes::Points::new(p), at);
                    lanes += LANES;
                    settled += found.found.count_ones() as usize;
                }
                for (l, t) in trails.iter_mut().enumerate() {
                    t.push(warp.locate(p[l], t.guess()).1);
                }
            }
        }
        assert!(lanes > 25_000, "{lanes} lanes tried");
        assert!(
            settled * 100 > lanes * 95,
            "{settled} of {lanes} lanes settled"
        );
    }

    /// A 240 × 160 mesh pair whose interior swells by up to 4 px, fading
    /// to nothing at the border: gently enough for a bilinear grid.
    fn gentle() -> MeshWarp {
        let src = Mesh::regular(7, 9, 0.0, 0.0, 240.0, 160.0).unwrap();
        let dst = src.map_nodes(|_, _, p| {
            use std::f64::consts::PI;
            let bump = (PI * p.x / 240.0).sin() * (PI * p.y / 160.0).sin();
            p + Vec2::new(4.0, -3.0) * bump
        });
        MeshWarp::new(&src, &dst)
    }

    #[test]
    fn the_grid_map_stays_within_its_tolerance_of_the_exact_map() {
        // Past the mesh on every side, sides no multiple of the grid; full
        // and half scale (where a pixel is two canonical units).
        let cases = [
            (gentle(), PixelScale::UNIT, RectI::new(-12, -7, 251, 170)),
            (curved(), PixelScale::UNIT, RectI::new(-12, -7, 251, 170)),
            (
                gentle(),
                PixelScale::new(0.5, 0.5, 1.0),
                RectI::new(-5, -3, 123, 84),
            ),
        ];
        for (n, (warp, scale, window)) in cases.into_iter().enumerate() {
            let exact = warp.map_window(window, scale);
            let mut pos = vec![[0f32; 2]; window.area()];
            let (solved, cells) = warp
                .map_grid(window, scale, MeshWarp::TOLERANCE, &mut pos)
                .unwrap();
            let grid = WarpMap::new(window, scale, pos);
            let rendered = warp.clone().within(MeshWarp::TOLERANCE);
            let rendered = rendered.map_window(window, scale);
            for j in window.y1..window.y2 {
                assert_eq!(rendered.row(j), grid.row(j), "case {n}: row {j}");
            }
            let mut worst = 0.0f64;
            for j in window.y1..window.y2 {
                for i in window.x1..window.x2 {
                    worst = worst.max(grid.get(i, j).distance(exact.get(i, j)));
                }
            }
            // Rounding to f32 adds up to 1e-5 px.
            assert!(
                worst * scale.x <= MeshWarp::TOLERANCE + 2e-5,
                "case {n}: {worst} px from the exact map"
            );
            // The gentle mesh must interpolate all but the cells along the
            // mesh's and the window's edges (a quarter of them at half
            // scale), or this test would pass by solving every pixel; the
            // curved one bends too fast for the grid in most cells.
            let share = solved as f64 / cells as f64;
            let (lo, hi) = [(0.0, 0.2), (0.5, 1.0), (0.0, 0.3)][n];
            assert!(
                (lo..hi).contains(&share),
                "case {n}: {solved} of {cells} solved"
            );
        }
    }

    #[test]
    fn the_dense_map_matches_a_strict_solve_on_a_curved_mesh() {
        let (w, h) = (240.0, 160.0);
        let warp = curved();
        let window = RectI::from_size(w as usize, h as usize);
        let map = warp.map_window(window, PixelScale::UNIT);
        let mut worst = 0.0f64;
        let mut solved = 0;
        for j in 0..h as i32 {
            for i in 0..w as i32 {
                let p = PixelScale::UNIT.pixel_centre(i, j);
                let Some((s, r)) = strict(&warp.to, p) else {
                    continue;
                };
                if !warp.to.inside_domain(s, r) {
                    continue;
                }
                solved += 1;
                worst = worst.max(map.get(i, j).distance(warp.from.position(s, r)));
            }
        }
        assert!(solved > 30_000, "{solved} pixels solved");
        // f32 positions near 240 px round by up to 1e-5 px.
        assert!(
            worst < 5e-5,
            "dense map strays {worst} px from the strict solve"
        );
    }
}
