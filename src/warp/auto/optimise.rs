//! The hierarchical search of Gao-Sederberg §5: level by level, every control
//! point tries offset positions `F̂_i(P + s δ)` and keeps the best one that
//! lowers the work and keeps every quad convex and counter-clockwise.
//!
//! Points are visited in four colour classes by the parity of `(j, k)`: two
//! points of one class share no quad, so a class is searched in parallel and
//! the result is the same whatever the thread count (the paper visits points
//! one by one; the order differs, the rule does not).

use rayon::prelude::*;

use super::grid::{lattice, Freedom, Grid};
use super::work::{Pricer, Work};
use crate::geom::Vec2;

/// Adaptive refinements per point at level `i` (the paper's `n_1 = 5`,
/// `n_2 = 3`, `n_3 = 2`, then 1).
pub fn iterations(level: u32) -> usize {
    match level {
        0 | 1 => 5,
        2 => 3,
        3 => 2,
        _ => 1,
    }
}

/// The step of refinement `n` at level `i`, in the unit square: 0.4 of a
/// patch, halved at each refinement, so each level starts where the one
/// before left off (0.2, 0.1, 0.05, ... at level 1, as the paper's 0.5, 0.1,
/// 0.05 shrink).
pub fn step(level: u32, n: usize) -> f64 {
    0.4 / (1u64 << level) as f64 / (1u64 << n) as f64
}

/// The 8 neighbours of a square (the paper's Figure 5 offsets).
const RING: [(f64, f64); 8] = [
    (1.0, 0.0),
    (1.0, 1.0),
    (0.0, 1.0),
    (-1.0, 1.0),
    (-1.0, 0.0),
    (-1.0, -1.0),
    (0.0, -1.0),
    (1.0, -1.0),
];

/// The wider first look at levels 2 and 3 (the paper's Figure 4): the ring
/// at once and twice the step.
fn wide() -> impl Iterator<Item = (f64, f64)> {
    RING.iter()
        .copied()
        .chain(RING.iter().map(|&(x, y)| (2.0 * x, 2.0 * y)))
}

/// Offsets for refinement `n` at `level`, restricted to the point's freedom
/// (an edge point keeps only the part along its edge, without repeats).
fn offsets(level: u32, n: usize, freedom: Freedom) -> Vec<(f64, f64)> {
    let all: Vec<(f64, f64)> = if n == 0 && (level == 2 || level == 3) {
        wide().collect()
    } else {
        RING.to_vec()
    };
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(all.len());
    for (x, y) in all {
        let o = match freedom {
            Freedom::Fixed => return Vec::new(),
            Freedom::AlongX => (x, 0.0),
            Freedom::AlongY => (0.0, y),
            Freedom::Free => (x, y),
        };
        if o != (0.0, 0.0) && !out.contains(&o) {
            out.push(o);
        }
    }
    out
}

/// The quads around point `(j, k)`: `(quad index, which corner the point is)`.
fn star(n: usize, j: usize, k: usize) -> impl Iterator<Item = (usize, usize, usize)> {
    // Corner order of `Grid::quad`: (0,0) (1,0) (1,1) (0,1).
    [(0usize, 0usize, 0usize), (1, 0, 1), (1, 1, 2), (0, 1, 3)]
        .into_iter()
        .filter_map(move |(dj, dk, corner)| {
            let (qj, qk) = (j.checked_sub(dj)?, k.checked_sub(dk)?);
            (qj < n && qk < n).then_some((qj, qk, corner))
        })
}

/// An accepted move: the point, its new position, its quads' new work.
type Move = (usize, usize, Vec2, Vec<(usize, Work)>);

/// Refines every point of `grid` at `pricer`'s level, updating `works`
/// (one per quad) as moves are accepted.
pub fn refine_level(grid: &mut Grid, pricer: &Pricer<'_>, works: &mut [Work], iterations: usize) {
    let n = grid.n();
    let level = grid.level();
    for class in 0..4 {
        let points: Vec<(usize, usize)> = (0..=n)
            .flat_map(|k| (0..=n).map(move |j| (j, k)))
            .filter(|&(j, k)| (j % 2) + 2 * (k % 2) == class)
            .filter(|&(j, k)| grid.freedom(j, k) != Freedom::Fixed)
            .collect();
        let g: &Grid = grid;
        let w: &[Work] = works;
        let moves: Vec<Move> = points
            .par_iter()
            .filter_map(|&(j, k)| {
                let (p, new) = search_point(g, pricer, w, j, k, level, iterations)?;
                Some((j, k, p, new))
            })
            .collect();
        for (j, k, p, new) in moves {
            grid.set(j, k, p);
            for (q, work) in new {
                works[q] = work;
            }
        }
    }
}

/// The refinements of one point; `None` when it stays put.
fn search_point(
    grid: &Grid,
    pricer: &Pricer<'_>,
    works: &[Work],
    j: usize,
    k: usize,
    level: u32,
    iterations: usize,
) -> Option<(Vec2, Vec<(usize, Work)>)> {
    let n = grid.n();
    let freedom = grid.freedom(j, k);
    let home = lattice(n, j, k);
    let quads: Vec<(usize, usize, usize)> = star(n, j, k).collect();
    let mut corners: Vec<[Vec2; 4]> = quads.iter().map(|&(qj, qk, _)| grid.quad(qj, qk)).collect();
    let mut current: Vec<Work> = quads
        .iter()
        .map(|&(qj, qk, _)| works[qk * n + qj])
        .collect();
    let mut cost: f64 = current.iter().map(Work::total).sum();
    let mut moved = false;
    let mut at = grid.at(j, k);
    for it in 0..iterations {
        let s = step(level, it);
        let mut best: Option<(f64, Vec2, Vec<Work>)> = None;
        for (dx, dy) in offsets(level, it, freedom) {
            let u = Vec2::new(
                (home.x + s * dx).clamp(0.0, 1.0),
                (home.y + s * dy).clamp(0.0, 1.0),
            );
            // F̂_i(P + s δ) on the current warp, whose quads around P are `corners`.
            let candidate = eval_star(n, j, k, &quads, &corners, u);
            let mut trial = corners.clone();
            for (c, &(_, _, corner)) in trial.iter_mut().zip(&quads) {
                c[corner] = candidate;
            }
            if !trial.iter().all(super::grid::is_convex_ccw) {
                continue;
            }
            let bound = best.as_ref().map_or(cost, |b| b.0.min(cost));
            if let Some((total, priced)) = price(pricer, &quads, &trial, bound) {
                best = Some((total, candidate, priced));
            }
        }
        if let Some((total, p, priced)) = best {
            cost = total;
            at = p;
            current = priced;
            moved = true;
            for (c, &(_, _, corner)) in corners.iter_mut().zip(&quads) {
                c[corner] = p;
            }
        }
    }
    moved.then(|| {
        let updates = quads
            .iter()
            .zip(current)
            .map(|(&(qj, qk, _), w)| (qk * n + qj, w))
            .collect();
        (at, updates)
    })
}

/// The work of the quads `trial` if it is below `bound`; `None` as soon as
/// it cannot be (colour, the costly part, is priced last and quad by quad,
/// and work is never negative).
fn price(
    pricer: &Pricer<'_>,
    quads: &[(usize, usize, usize)],
    trial: &[[Vec2; 4]],
    bound: f64,
) -> Option<(f64, Vec<Work>)> {
    let mut priced: Vec<Work> = quads
        .iter()
        .zip(trial)
        .map(|(&(qj, qk, _), q)| pricer.shape_work(qj, qk, q))
        .collect();
    let mut total: f64 = priced.iter().map(Work::total).sum();
    if total >= bound {
        return None;
    }
    for (w, (&(qj, qk, _), q)) in priced.iter_mut().zip(quads.iter().zip(trial)) {
        w.colour = pricer.colour_work(qj, qk, q);
        total += w.colour;
        if total >= bound {
            return None;
        }
    }
    Some((total, priced))
}

/// The current warp at unit position `u`, which lies in one of the quads
/// around the point being moved.
fn eval_star(
    n: usize,
    j: usize,
    k: usize,
    quads: &[(usize, usize, usize)],
    corners: &[[Vec2; 4]],
    u: Vec2,
) -> Vec2 {
    let (x, y) = (u.x * n as f64, u.y * n as f64);
    // The quad left/below of the point when u is left/below of its lattice position.
    let qj = if x < j as f64 {
        j.saturating_sub(1)
    } else {
        j.min(n - 1)
    };
    let qk = if y < k as f64 {
        k.saturating_sub(1)
    } else {
        k.min(n - 1)
    };
    let i = quads
        .iter()
        .position(|&(a, b, _)| a == qj && b == qk)
        .unwrap_or(0);
    let (qj, qk, _) = quads[i];
    super::grid::bilinear(
        &corners[i],
        (x - qj as f64).clamp(0.0, 1.0),
        (y - qk as f64).clamp(0.0, 1.0),
    )
}
