//! Four rows of the one-pass map at once, one per lane of `f64x4`: a
//! pixel's Newton steps and its source position cost about what one row's
//! do, for four pixels. The lanes run the one-row path's operations
//! ([`Surface::solve`], [`Surface::position`]) in the same order, without
//! fused multiply-adds, so they give its bits. A lane takes the one-row path
//! ([`MeshWarp::locate`]) instead where the lanes cannot follow it: no guess
//! yet (a row's start, or off the mesh), or a point Newton does not settle
//! from its guess. Lanes in different cells gather their patches'
//! coefficients; in one cell (nearly always) they share them.

use wide::f64x4;

use super::{extrapolate, MeshWarp, Params, Surface, EARLY_EXIT, LANES, MAX_STEPS, TOLERANCE};
use crate::geom::{PixelScale, Vec2};

/// Four points, one per lane.
#[derive(Clone, Copy)]
pub(super) struct Points {
    pub(super) x: f64x4,
    pub(super) y: f64x4,
}

impl Points {
    pub(super) fn new(p: [Vec2; LANES]) -> Points {
        Points {
            x: f64x4::new(p.map(|p| p.x)),
            y: f64x4::new(p.map(|p| p.y)),
        }
    }
}

/// The patches four lanes evaluate, and their cells' corners.
struct Cells<'s> {
    patches: [&'s [[f64; 16]; 2]; LANES],
    column: f64x4,
    row: f64x4,
    /// One patch for all lanes, the usual case: coefficients are splat
    /// rather than gathered.
    shared: bool,
}

impl Cells<'_> {
    /// Coefficient `n` of `axis`, per lane.
    #[inline(always)]
    fn coef<const SHARED: bool>(&self, axis: usize, n: usize) -> f64x4 {
        if SHARED {
            f64x4::splat(self.patches[0][axis][n])
        } else {
            f64x4::new(self.patches.map(|p| p[axis][n]))
        }
    }
}

impl Surface {
    /// The cells [`Surface::eval`] uses for four parameter pairs
    /// ([`Surface::cell`] in the lanes).
    #[inline(always)]
    fn cells4(&self, s: f64x4, r: f64x4) -> Cells<'_> {
        let f = f64x4::splat;
        let column = s.floor().max(f(0.0)).min(f((self.cols - 2) as f64));
        let row = r.floor().max(f(0.0)).min(f((self.rows - 2) as f64));
        let (c, k) = (column.to_array(), row.to_array());
        let patch = |l: usize| &self.coef[k[l] as usize * (self.cols - 1) + c[l] as usize];
        let shared = c.iter().all(|&x| x == c[0]) && k.iter().all(|&x| x == k[0]);
        Cells {
            patches: if shared {
                [patch(0); LANES]
            } else {
                std::array::from_fn(patch)
            },
            column,
            row,
            shared,
        }
    }

    /// [`Surface::eval`] at four parameter pairs.
    fn eval4(&self, s: f64x4, r: f64x4) -> (Points, Points, Points) {
        let cells = self.cells4(s, r);
        if cells.shared {
            eval4::<true>(&cells, s, r)
        } else {
            eval4::<false>(&cells, s, r)
        }
    }

    /// [`Surface::position`] at four parameter pairs.
    fn position4(&self, s: f64x4, r: f64x4) -> Points {
        let cells = self.cells4(s, r);
        if cells.shared {
            position4::<true>(&cells, s, r)
        } else {
            position4::<false>(&cells, s, r)
        }
    }

    /// [`Surface::solve`] from four guesses `at`: the parameters each lane
    /// settles on, and a bit per lane (of [`Lanes::found`]) set where it
    /// did and they lie inside the domain.
    pub(super) fn solve4(&self, p: Points, at: Lanes) -> Lanes {
        let f = f64x4::splat;
        let (mut s, mut r) = (at.s, at.r);
        let mut out = Lanes { found: 0, ..at };
        let mut going = f64x4::new([f64::from_bits(u64::MAX); LANES]);
        let mut found = f64x4::ZERO;
        for _ in 0..MAX_STEPS {
            let (q, du, dv) = self.eval4(s, r);
            let (ex, ey) = (p.x - q.x, p.y - q.y);
            let converged = (ex * ex + ey * ey).simd_le(f(TOLERANCE * TOLERANCE)) & going;
            let det = du.x * dv.y - du.y * dv.x;
            let inverse = f(1.0) / det;
            let (ds, dr) = (
                (ex * dv.y - ey * dv.x) * inverse,
                (du.x * ey - du.y * ex) * inverse,
            );
            let m = ds.abs().max(dr.abs());
            let long = m.simd_gt(f(1.0));
            // Divisions are dear; steps over a cell are rare.
            let (ds, dr) = match long.any() {
                true => (long.bitselect(ds / m, ds), long.bitselect(dr / m, dr)),
                false => (ds, dr),
            };
            let stepped_s = (s + ds).max(f(-1.0)).min(f(self.cols as f64));
            let stepped_r = (r + dr).max(f(-1.0)).min(f(self.rows as f64));
            // The one-row path gives up at a degenerate Jacobian (and then
            // starts afresh, which the fallback repeats).
            let sound = det.abs().simd_ge(f(1e-12)) & det.is_finite();
            let settled = sound & m.simd_lt(f(EARLY_EXIT)) & going & !converged;
            out.s = converged.bitselect(s, settled.bitselect(stepped_s, out.s));
            out.r = converged.bitselect(r, settled.bitselect(stepped_r, out.r));
            found = found | converged | settled;
            going = going & sound & !(converged | settled);
            if going.to_bitmask() == 0 {
                break;
            }
            (s, r) = (stepped_s, stepped_r);
        }
        let eps = 1e-9;
        let inside = out.s.simd_ge(f(-eps))
            & out.s.simd_le(f((self.cols - 1) as f64 + eps))
            & out.r.simd_ge(f(-eps))
            & out.r.simd_le(f((self.rows - 1) as f64 + eps));
        out.found = (found & inside).to_bitmask();
        out
    }
}

#[inline(always)]
fn eval4<const SHARED: bool>(cells: &Cells, s: f64x4, r: f64x4) -> (Points, Points, Points) {
    let f = f64x4::splat;
    let (u, v) = (s - cells.column, r - cells.row);
    let pu = [f(1.0), u, u * u, u * u * u];
    let du = [f(0.0), f(1.0), f(2.0) * u, f(3.0) * u * u];
    let pv = [f(1.0), v, v * v, v * v * v];
    let dv = [f(0.0), f(1.0), f(2.0) * v, f(3.0) * v * v];
    let mut out = [[f64x4::ZERO; 3]; 2];
    for (axis, o) in out.iter_mut().enumerate() {
        for i in 0..4 {
            let row = |j: usize| cells.coef::<SHARED>(axis, i * 4 + j);
            let cv = row(0) * pv[0] + row(1) * pv[1] + row(2) * pv[2] + row(3) * pv[3];
            let cdv = row(1) * dv[1] + row(2) * dv[2] + row(3) * dv[3];
            o[0] += pu[i] * cv;
            o[1] += du[i] * cv;
            o[2] += pu[i] * cdv;
        }
    }
    let point = |d: usize| Points {
        x: out[0][d],
        y: out[1][d],
    };
    (point(0), point(1), point(2))
}

#[inline(always)]
fn position4<const SHARED: bool>(cells: &Cells, s: f64x4, r: f64x4) -> Points {
    let f = f64x4::splat;
    let (u, v) = (s - cells.column, r - cells.row);
    let pu = [f(1.0), u, u * u, u * u * u];
    let pv = [f(1.0), v, v * v, v * v * v];
    let mut out = [f64x4::ZERO; 2];
    for (axis, o) in out.iter_mut().enumerate() {
        for (i, pu) in pu.iter().enumerate() {
            let row = |j: usize| cells.coef::<SHARED>(axis, i * 4 + j);
            *o += *pu * (row(0) * pv[0] + row(1) * pv[1] + row(2) * pv[2] + row(3) * pv[3]);
        }
    }
    Points {
        x: out[0],
        y: out[1],
    }
}

/// Surface parameters in four lanes.
#[derive(Clone, Copy)]
pub(super) struct Lanes {
    pub(super) s: f64x4,
    pub(super) r: f64x4,
    /// A bit per lane: whether its parameters were found.
    pub(super) found: u32,
}

const ALL: u32 = (1 << LANES) - 1;

impl Lanes {
    pub(super) fn get(&self, l: usize) -> Option<Params> {
        (self.found >> l & 1 == 1).then(|| (self.s.to_array()[l], self.r.to_array()[l]))
    }

    /// Lanes from one `Option` each.
    fn from_options(p: [Option<Params>; LANES]) -> Lanes {
        let mut found = 0;
        for (l, p) in p.iter().enumerate() {
            found |= u32::from(p.is_some()) << l;
        }
        Lanes {
            s: f64x4::new(std::array::from_fn(|l| p[l].map_or(0.0, |p| p.0))),
            r: f64x4::new(std::array::from_fn(|l| p[l].map_or(0.0, |p| p.1))),
            found,
        }
    }
}

impl MeshWarp {
    /// Rows `j..j + LANES` of the map, pixels `x1..`, into `out` (the rows
    /// one after another).
    pub(super) fn map_rows4(&self, x1: i32, j: i32, scale: PixelScale, out: &mut [[f32; 2]]) {
        let w = out.len() / LANES;
        let ys = std::array::from_fn(|l| scale.pixel_centre(0, j + l as i32).y);
        let xs = (0..w).map(|k| scale.pixel_centre(x1 + k as i32, 0).x);
        self.rows4(xs, ys, [None; LANES], |k, q, _| {
            let (qx, qy) = (q.x.to_array(), q.y.to_array());
            for l in 0..LANES {
                out[l * w + k] = [qx[l] as f32, qy[l] as f32];
            }
        });
    }

    /// The map at `(x, ys[l])` for each `x` of `xs` in turn, four rows at
    /// once, each point starting Newton where its row's last two solutions
    /// point (the first from `seed`): `emit(k, where they map, their
    /// parameters)` for the `k`th.
    pub(super) fn rows4(
        &self,
        xs: impl Iterator<Item = f64>,
        ys: [f64; LANES],
        seed: [Option<Params>; LANES],
        mut emit: impl FnMut(usize, Points, Lanes),
    ) {
        // Each row's last two solutions, as the one-row path keeps them.
        let (mut prev, mut before) = (
            Lanes::from_options(seed),
            Lanes::from_options([None; LANES]),
        );
        let ys = f64x4::new(ys);
        for (k, x) in xs.enumerate() {
            let p = Points {
                x: f64x4::splat(x),
                y: ys,
            };
            let (q, found) = if prev.found & before.found == ALL {
                // `extrapolate` in the lanes.
                let guess = Lanes {
                    s: f64x4::splat(2.0) * prev.s - before.s,
                    r: f64x4::splat(2.0) * prev.r - before.r,
                    found: ALL,
                };
                self.locate4(p, guess)
            } else {
                let guesses = std::array::from_fn(|l| extrapolate(prev.get(l), before.get(l)));
                self.locate4(p, Lanes::from_options(guesses))
            };
            // `Trail::push` in the lanes: a lane off the mesh forgets both.
            before = Lanes {
                found: prev.found & found.found,
                ..prev
            };
            prev = found;
            emit(k, q, found);
        }
    }

    /// [`MeshWarp::locate`] for four points from guesses `at` (lanes
    /// without one take the one-row path): where they map, and the
    /// parameters found.
    fn locate4(&self, p: Points, at: Lanes) -> (Points, Lanes) {
        let found = if at.found == ALL {
            self.to.solve4(p, at)
        } else {
            Lanes { found: 0, ..at }
        };
        if found.found == ALL {
            return (self.from.position4(found.s, found.r), found);
        }
        // Lanes the lanes did not settle, one by one.
        let (px, py) = (p.x.to_array(), p.y.to_array());
        let mapped: [(Vec2, Option<Params>); LANES] = std::array::from_fn(|l| match found.get(l) {
            Some((s, r)) => (self.from.position(s, r), Some((s, r))),
            None => self.locate(Vec2::new(px[l], py[l]), at.get(l)),
        });
        let q = Points::new(mapped.map(|m| m.0));
        (q, Lanes::from_options(mapped.map(|m| m.1)))
    }
}
