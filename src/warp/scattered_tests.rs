//! Thin plate, MFFD and hybrid against what they promise: constraints met,
//! one-to-one (Jacobian signs), the multigrid solving the discrete plate.

use super::hybrid::{self, HybridSettings};
use super::mffd::{Deformation, Mffd, MffdSettings, MffdWarp};
use super::thin_plate::multigrid::{Hierarchy, Stencil};
use super::thin_plate::plate::Plate;
use super::thin_plate::{ThinPlate, ThinPlateSettings, ThinPlateWarp};
use super::Warp;
use crate::bspline::Lattice;
use crate::geom::{PixelScale, RectD, RectI, Vec2};
use crate::testing::{smooth_pairs, Lcg};

const FRAME: RectD = RectD {
    x1: 0.0,
    y1: 0.0,
    x2: 256.0,
    y2: 192.0,
};

fn worst_miss(map: impl Fn(Vec2) -> Vec2, pairs: &[(Vec2, Vec2)]) -> f64 {
    pairs
        .iter()
        .fold(0.0f64, |m, (p, q)| m.max(map(*p).distance(*q)))
}

/// The smallest Jacobian determinant of a dense map, by finite differences
/// of neighbouring pixels (independent of the method's own derivatives).
fn smallest_jacobian(warp: &dyn Warp, window: RectI) -> f64 {
    let map = warp.map_window(window, PixelScale::new(1.0, 1.0, 1.0));
    let mut worst = f64::INFINITY;
    for j in window.y1..window.y2 - 1 {
        for i in window.x1..window.x2 - 1 {
            let (p, px, py) = (map.get(i, j), map.get(i + 1, j), map.get(i, j + 1));
            let (a, b) = (px - p, py - p);
            worst = worst.min(a.x * b.y - a.y * b.x);
        }
    }
    worst
}

#[test]
fn mffd_meets_non_crossing_constraints() {
    for seed in 0..5 {
        let pairs = smooth_pairs(seed, 40, 256.0, 192.0, 12.0, 16.0);
        let m = Mffd::solve(&pairs, FRAME, &MffdSettings::default());
        let miss = worst_miss(|p| m.apply(p), &pairs);
        assert!(
            miss <= 0.05,
            "seed {seed}: {miss} px after {} steps",
            m.steps.len()
        );
        assert!((m.error - miss).abs() < 1e-9);
    }
}

#[test]
fn mffd_dense_map_stays_close_to_the_exact_composition() {
    let pairs = smooth_pairs(4, 40, 256.0, 192.0, 12.0, 16.0);
    let warp = MffdWarp {
        mffd: Mffd::solve(&pairs, FRAME, &MffdSettings::default()),
    };
    let window = RectI::new(0, 0, 256, 192);
    let map = warp.map_window(window, PixelScale::new(1.0, 1.0, 1.0));
    let mut worst: f64 = 0.0;
    for j in 0..192 {
        for i in 0..256 {
            let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
            worst = worst.max(map.get(i, j).distance(warp.map(p)));
        }
    }
    // Nodes every 2 px, exact there; bilinear between (f32 positions).
    assert!(worst < 0.05, "dense map off by {worst} px");
}

/// A host renders in tiles: each tile's map must be exactly the whole
/// frame's there, whatever rows and columns the tile starts on, at any
/// render scale (the nodes lie on a lattice fixed in the image).
#[test]
fn mffd_tiles_are_the_whole_frame_bit_for_bit() {
    let pairs = smooth_pairs(4, 40, 256.0, 192.0, 12.0, 16.0);
    let warp = MffdWarp {
        mffd: Mffd::solve(&pairs, FRAME, &MffdSettings::default()),
    };
    for s in [1.0, 0.5, 0.25] {
        let scale = PixelScale::new(s, s, 1.0);
        let (w, h) = ((256.0 * s) as i32, (192.0 * s) as i32);
        let whole = warp.map_window(RectI::new(0, 0, w, h), scale);
        for tile in [
            RectI::new(0, 3, w, 9),
            RectI::new(5, 7, w - 3, h),
            RectI::new(1, 1, 2, 2),
        ] {
            let part = warp.map_window(tile, scale);
            for j in tile.y1..tile.y2 {
                for i in tile.x1..tile.x2 {
                    assert_eq!(
                        part.get(i, j),
                        whole.get(i, j),
                        "scale {s}, {tile:?}, ({i}, {j})"
                    );
                }
            }
        }
    }
}

#[test]
fn a_deformation_is_its_two_lattices_everywhere() {
    // The packed evaluation (both lattices interleaved, zero cells skipped)
    // against the lattices' own, on the lattice, at its edges and far away.
    let mut r = Lcg::new(21);
    let lattice = |r: &mut Lcg| {
        let mut l = Lattice::zero(Vec2::new(-7.0, 3.0), 5.0, 9, 6);
        for v in l.phi.iter_mut() {
            // Sparse, as a fine step's controls are.
            *v = if r.unit() < 0.3 {
                r.range(-2.0, 2.0)
            } else {
                0.0
            };
        }
        l
    };
    let (dx, dy) = (lattice(&mut r), lattice(&mut r));
    let d = Deformation::new(dx.clone(), dy.clone());
    let points: Vec<Vec2> = (0..4000)
        .map(|_| Vec2::new(r.range(-40.0, 70.0), r.range(-30.0, 60.0)))
        .collect();
    for p in &points {
        let exact = *p + Vec2::new(dx.eval(*p), dy.eval(*p));
        assert!(d.apply(*p).distance(exact) < 1e-12, "{p:?}");
    }
    // A composition over a batch equals it point by point.
    let mffd = Mffd::solve(
        &smooth_pairs(2, 30, 256.0, 192.0, 10.0, 16.0),
        FRAME,
        &MffdSettings::default(),
    );
    let mut batch = points.clone();
    mffd.apply_all(&mut batch);
    for (p, q) in points.iter().zip(&batch) {
        assert_eq!(mffd.apply(*p), *q);
    }
}

/// Constraints that ask for folds: pairs that swap places, and a row of
/// points that must cross another row.
fn adversarial(seed: u64) -> Vec<(Vec2, Vec2)> {
    let mut r = Lcg::new(seed);
    let mut pairs = Vec::new();
    for _ in 0..6 {
        let p = Vec2::new(r.range(40.0, 216.0), r.range(40.0, 152.0));
        let q = p + Vec2::new(r.range(3.0, 30.0), r.range(-10.0, 10.0));
        pairs.push((p, q));
        pairs.push((q, p));
    }
    for k in 0..8 {
        let y = 30.0 + 16.0 * k as f64;
        pairs.push((Vec2::new(60.0, y), Vec2::new(190.0, y + 3.0)));
        pairs.push((Vec2::new(190.0, y + 8.0), Vec2::new(60.0, y + 5.0)));
    }
    pairs
}

#[test]
fn mffd_is_one_to_one_whatever_the_constraints() {
    let window = RectI::new(-20, -20, 276, 212);
    for seed in 0..4 {
        for (pairs, crossing) in [
            (smooth_pairs(seed, 60, 256.0, 192.0, 20.0, 8.0), false),
            (adversarial(seed), true),
        ] {
            let m = Mffd::solve(&pairs, FRAME, &MffdSettings::default());
            // Every step within Theorem 1's bound...
            for d in &m.steps {
                assert!(d.largest_step() <= 0.48 + 1e-12);
            }
            // ...so the analytic Jacobian is positive on a fine grid...
            for j in -20..212 {
                for i in -20..276 {
                    let det = m.jacobian_det(Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
                    assert!(det > 0.0, "seed {seed}: det {det} at ({i}, {j})");
                }
            }
            // ...and so is the dense map's, by finite differences. (Where
            // crossing constraints squeeze a region to a sliver, the bilinear
            // dense map between exact nodes is not held to this.)
            if !crossing {
                let warp = MffdWarp { mffd: m };
                let worst = smallest_jacobian(&warp, window);
                assert!(worst > 0.0, "seed {seed}: dense map folds ({worst})");
            }
        }
    }
}

#[test]
fn swapped_points_end_as_close_as_folding_free_allows() {
    // Seed Fig. 14: two points that swap. The warp stays one-to-one, so
    // they cannot fully swap, but they move toward their targets.
    let (p, q) = (Vec2::new(100.0, 96.0), Vec2::new(140.0, 96.0));
    let pairs = [(p, q), (q, p)];
    let m = Mffd::solve(&pairs, FRAME, &MffdSettings::default());
    let (mp, mq) = (m.apply(p), m.apply(q));
    assert!(mp.x < mq.x, "order kept: {mp:?} {mq:?}");
    assert!(m.error < p.distance(q), "they moved toward each other");
}

#[test]
fn the_single_patch_counterexample_folds_without_truncation() {
    // Seed 000 §5.2: Δφ_kl = (0.49, −0.49) for k ≤ l, (−0.49, 0.49) for
    // k > l on one 4 × 4 patch folds at (0.75519, 0.24483).
    let lattice = |sign: f64| {
        let mut l = Lattice::zero(Vec2::new(-1.0, -1.0), 1.0, 4, 4);
        for lj in 0..4 {
            for k in 0..4 {
                l.phi[lj * 4 + k] = if k <= lj { sign * 0.49 } else { -sign * 0.49 };
            }
        }
        l
    };
    let d = Deformation::new(lattice(1.0), lattice(-1.0));
    let det = |d: &Deformation, p: Vec2| {
        let j = d.jacobian(p);
        j[0][0] * j[1][1] - j[0][1] * j[1][0]
    };
    let fold = Vec2::new(0.75519, 0.24483);
    assert!(det(&d, fold) < 0.0, "folds: {}", det(&d, fold));
    // Truncated to 0.48 (Theorem 1) the same patch is one-to-one.
    let clamp = |mut l: Lattice| {
        l.phi.iter_mut().for_each(|v| *v = v.clamp(-0.48, 0.48));
        l
    };
    let t = Deformation::new(clamp(lattice(1.0)), clamp(lattice(-1.0)));
    for j in 0..=100 {
        for i in 0..=100 {
            let p = Vec2::new(i as f64 / 100.0, j as f64 / 100.0);
            assert!(det(&t, p) > 0.0, "{p:?}");
        }
    }
}

#[test]
fn mffd_folds_when_truncation_is_off() {
    // The same swapping constraints with Theorem 1's truncation disabled:
    // the least-squares displacements exceed 0.48 h and the warp folds.
    let (p, q) = (Vec2::new(100.0, 96.0), Vec2::new(112.0, 96.0));
    let pairs = [(p, q), (q, p)];
    let off = MffdSettings {
        truncate: false,
        ..MffdSettings::default()
    };
    let m = Mffd::solve(&pairs, FRAME, &off);
    let worst = (0..200)
        .flat_map(|j| (0..256).map(move |i| Vec2::new(i as f64 + 0.5, j as f64 * 0.96 + 0.5)))
        .fold(f64::INFINITY, |w, x| w.min(m.jacobian_det(x)));
    assert!(worst < 0.0, "a foldover is detected ({worst})");
    let on = Mffd::solve(&pairs, FRAME, &MffdSettings::default());
    assert!(on.steps.iter().all(|d| d.largest_step() <= 0.48 + 1e-12));
}

#[test]
fn thin_plate_meets_non_crossing_constraints() {
    for seed in 0..4 {
        let pairs = smooth_pairs(seed, 40, 256.0, 192.0, 12.0, 16.0);
        let plate = ThinPlate::solve(&pairs, FRAME, &ThinPlateSettings::default(), None);
        let warp = ThinPlateWarp::new(plate);
        let miss = worst_miss(|p| warp.map(p), &pairs);
        assert!(miss <= 0.05, "seed {seed}: {miss} px");
    }
}

#[test]
fn thin_plate_stops_within_its_tolerance_of_the_solution() {
    // The free edges between the springs and the frame are the slowest
    // part to settle, and leave almost no residual while they are off.
    let pairs = smooth_pairs(6, 40, 256.0, 192.0, 12.0, 16.0);
    let converged = ThinPlateSettings {
        tolerance: 1e-7,
        max_cycles: 400,
        ..ThinPlateSettings::default()
    };
    let exact = ThinPlate::solve(&pairs, FRAME, &converged, None);
    assert!(*exact.report_x.moved.last().unwrap() <= 1e-7);
    for tolerance in [0.1, 0.01, 0.001] {
        let s = ThinPlateSettings {
            tolerance,
            ..ThinPlateSettings::default()
        };
        let plate = ThinPlate::solve(&pairs, FRAME, &s, None);
        let off = plate
            .nodes
            .disp
            .iter()
            .zip(&exact.nodes.disp)
            .fold(0.0f64, |m, (a, b)| m.max(a.distance(*b)));
        assert!(
            off <= 3.0 * tolerance,
            "tolerance {tolerance}: {off} px off"
        );
    }
}

#[test]
fn thin_plate_glue_localises_the_pull() {
    // One constraint: without glue the whole plate translates; with glue
    // the pull dies away within a few multiples of β^(−1/4).
    let pairs = [(Vec2::new(128.0, 96.0), Vec2::new(138.0, 96.0))];
    let free = ThinPlateWarp::new(ThinPlate::solve(
        &pairs,
        FRAME,
        &ThinPlateSettings::default(),
        None,
    ));
    let glued = ThinPlateWarp::new(ThinPlate::solve(
        &pairs,
        FRAME,
        &ThinPlateSettings {
            beta: 1.0 / 16f64.powi(4),
            ..ThinPlateSettings::default()
        },
        None,
    ));
    let far = Vec2::new(20.0, 20.0);
    // One spring leaves the plate's tilts about it free (zero energy), so the
    // free plate's far displacement is 10 px up to a slight tilt.
    assert!((free.map(far) - far).x > 9.5, "{:?}", free.map(far));
    assert!(
        (glued.map(far) - far).length() < 0.5,
        "{:?}",
        glued.map(far)
    );
    assert!(glued.map(pairs[0].0).distance(pairs[0].1) < 0.05);
}

/// `E(f)` of the plate, written out term by term from the energy (not from
/// the operator under test).
fn energy(plate: &Plate, f: &[f64]) -> f64 {
    let (nx, ny, h) = (plate.nx, plate.ny, plate.h);
    let at = |i: usize, j: usize| f[j * nx + i];
    let mut e = 0.0;
    for j in 0..ny {
        for i in 1..nx - 1 {
            let fxx = (at(i - 1, j) - 2.0 * at(i, j) + at(i + 1, j)) / (h * h);
            e += fxx * fxx * h * h;
        }
    }
    for j in 1..ny - 1 {
        for i in 0..nx {
            let fyy = (at(i, j - 1) - 2.0 * at(i, j) + at(i, j + 1)) / (h * h);
            e += fyy * fyy * h * h;
        }
    }
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let fxy = (at(i + 1, j + 1) - at(i + 1, j) - at(i, j + 1) + at(i, j)) / (h * h);
            e += 2.0 * fxy * fxy * h * h;
        }
    }
    e += plate.beta * f.iter().map(|v| v * v).sum::<f64>() * h * h;
    for s in &plate.springs {
        let v: f64 = (0..4).map(|m| s.weights[m] * f[s.nodes[m]]).sum();
        e += plate.alpha * (v - s.z) * (v - s.z);
    }
    0.5 * e
}

/// Twelve spring positions (grid units) and heights on an `nx × ny` grid.
fn small_springs(seed: u64, nx: usize, ny: usize) -> (Vec<(f64, f64)>, Vec<f64>) {
    let mut r = Lcg::new(seed);
    let at: Vec<(f64, f64)> = (0..12)
        .map(|_| (r.range(0.0, (nx - 1) as f64), r.range(0.0, (ny - 1) as f64)))
        .collect();
    let z = at.iter().map(|_| r.range(-4.0, 4.0)).collect();
    (at, z)
}

fn small_plate(seed: u64, nx: usize, ny: usize) -> Plate {
    let (at, z) = small_springs(seed, nx, ny);
    let mut plate = Plate::new(nx, ny, 3.0, 50.0, 1e-3, &at);
    for (s, z) in plate.springs.iter_mut().zip(z) {
        s.z = z;
    }
    plate
}

/// [`small_plate`]'s plate with its multigrid levels.
fn small_hierarchy(seed: u64, nx: usize, ny: usize, levels: usize) -> Hierarchy {
    let (at, z) = small_springs(seed, nx, ny);
    let mut h = Hierarchy::new(nx, ny, 3.0, 50.0, 1e-3, &at, levels);
    for (s, z) in h.plate.springs.iter_mut().zip(z) {
        s.z = z;
    }
    h
}

#[test]
fn the_plate_operator_is_the_gradient_of_its_energy() {
    let plate = small_plate(1, 9, 7);
    let mut r = Lcg::new(4);
    let f: Vec<f64> = (0..63).map(|_| r.range(-2.0, 2.0)).collect();
    let b = plate.rhs();
    for n in 0..63 {
        let e = 1e-4;
        let (mut up, mut down) = (f.clone(), f.clone());
        up[n] += e;
        down[n] -= e;
        let grad = (energy(&plate, &up) - energy(&plate, &down)) / (2.0 * e);
        let op = plate.apply_at(&f, n) - b[n];
        assert!(
            (grad - op).abs() < 1e-5 * (1.0 + grad.abs()),
            "node {n}: {grad} vs {op}"
        );
        // The stored diagonal is A's.
        let mut unit = vec![0.0; 63];
        unit[n] = 1.0;
        assert!((plate.apply_at(&unit, n) - plate.diagonal_at(n)).abs() < 1e-12);
    }
}

/// The plate's minimiser by dense Gaussian elimination on the Hessian of
/// the energy (assembled from energies alone).
fn direct_solution(plate: &Plate) -> Vec<f64> {
    let n = plate.nx * plate.ny;
    let zero = vec![0.0; n];
    let e0 = energy(plate, &zero);
    let unit = |k: usize| {
        let mut v = vec![0.0; n];
        v[k] = 1.0;
        v
    };
    let mut a = vec![vec![0.0; n + 1]; n];
    for i in 0..n {
        for j in 0..n {
            let mut both = unit(i);
            both[j] += 1.0;
            // E is quadratic: its Hessian entry from four energies.
            let ei = energy(plate, &unit(i));
            let ej = energy(plate, &unit(j));
            a[i][j] = energy(plate, &both) - ei - ej + e0;
        }
        // Linear term: −∂E/∂f_i at 0 is b_i.
        let (ei, emi) = (energy(plate, &unit(i)), {
            let mut v = vec![0.0; n];
            v[i] = -1.0;
            energy(plate, &v)
        });
        a[i][n] = -(ei - emi) / 2.0;
    }
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
            .unwrap();
        a.swap(c, p);
        let pivot = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let k = row[c] / pivot[c];
                for (v, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                    *v -= k * p;
                }
            }
        }
    }
    (0..n).map(|i| a[i][n] / a[i][i]).collect()
}

#[test]
fn multigrid_matches_a_direct_solve_and_converges_per_cycle() {
    // 17 × 13 nodes: three levels down to 5 × 4 (direct there).
    let h = small_hierarchy(2, 17, 13, 3);
    let b = h.plate.rhs();
    let mut f = vec![0.0; 17 * 13];
    let report = h.solve(&mut f, &b, 1e-10, 60);
    let r = &report.residuals;
    // The stated rate: on average each cycle at least halves the residual.
    for (k, rk) in r.iter().enumerate() {
        assert!(
            *rk <= r[0] * 0.5f64.powi(k as i32),
            "cycle {k}: {rk} (from {})",
            r[0]
        );
    }
    assert!(*r.last().unwrap() <= 1e-10 * h.plate.rhs().iter().map(|v| v * v).sum::<f64>().sqrt());
    let direct = direct_solution(&h.plate);
    let scale = direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (m, d) in f.iter().zip(&direct) {
        assert!((m - d).abs() < 1e-6 * scale, "{m} vs {d}");
    }
}

#[test]
fn a_sweep_is_gauss_seidel_node_by_node() {
    // The sweeps carry fresh values in registers and share stencils; they
    // must still be plain Gauss-Seidel, on the plate and on a Galerkin level.
    let h = small_hierarchy(5, 23, 19, 2);
    let fine = &h.levels[0];
    assert!(fine.distinct() < 23 * 19, "interior stencils are shared");
    for stencil in &h.levels {
        let n = stencil.nx * stencil.ny;
        let mut r = Lcg::new(9);
        let b: Vec<f64> = (0..n).map(|_| r.range(-1.0, 1.0)).collect();
        let start: Vec<f64> = (0..n).map(|_| r.range(-1.0, 1.0)).collect();
        for forward in [true, false] {
            let mut reference = start.clone();
            let order: Vec<usize> = if forward {
                (0..n).collect()
            } else {
                (0..n).rev().collect()
            };
            for k in order {
                let d = stencil.apply_at(&unit(n, k), k);
                reference[k] += (b[k] - stencil.apply_at(&reference, k)) / d;
            }
            let mut swept = start.clone();
            stencil.relax(&mut swept, &b, forward);
            for (s, e) in swept.iter().zip(&reference) {
                assert!((s - e).abs() < 1e-12 * e.abs().max(1.0), "{s} vs {e}");
            }
        }
    }
}

/// The hierarchy builds each level as bending (one row per class of node
/// near the edges) plus springs restricted one by one; that must be exactly
/// the plate probed node by node and its Galerkin products `Pᵀ A P` built
/// row by row, on grids large enough for interior classes and small enough
/// for none, with springs in corners, on edges and clustered.
#[test]
fn split_levels_equal_the_direct_galerkin_products() {
    for (seed, nx, ny, levels) in [(2, 65, 49, 4), (7, 33, 17, 3), (4, 9, 9, 2)] {
        let mut r = Lcg::new(seed);
        let (w, h) = ((nx - 1) as f64, (ny - 1) as f64);
        let mut at: Vec<(f64, f64)> = vec![(0.0, 0.0), (w, h), (0.3, h * 0.5), (w - 0.2, 1.7)];
        at.extend((0..25).map(|_| (r.range(0.0, w), r.range(0.0, h))));
        at.extend((0..6).map(|_| (r.range(10.0, 11.0), r.range(4.0, 5.0))));
        let hierarchy = Hierarchy::new(nx, ny, 3.0, 50.0, 1e-3, &at, levels);
        let mut direct = Stencil::of(&hierarchy.plate);
        for (l, level) in hierarchy.levels.iter().enumerate() {
            if l > 0 {
                direct = direct.galerkin();
            }
            assert_eq!((level.nx, level.ny), (direct.nx, direct.ny));
            for n in 0..level.nx * level.ny {
                let (got, want) = (level.row(n), direct.row(n));
                let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (k, (g, d)) in got.iter().zip(want).enumerate() {
                    assert!(
                        (g - d).abs() <= 1e-12 * scale,
                        "{nx}x{ny} level {l} node {n} tap {k}: {g} vs {d}"
                    );
                }
            }
        }
    }
}

fn unit(n: usize, k: usize) -> Vec<f64> {
    let mut u = vec![0.0; n];
    u[k] = 1.0;
    u
}

#[test]
fn thin_plate_warm_start_needs_fewer_cycles() {
    let pairs = smooth_pairs(3, 40, 256.0, 192.0, 12.0, 16.0);
    let s = ThinPlateSettings::default();
    let cold = ThinPlate::solve(&pairs, FRAME, &s, None);
    // The next frame: constraints moved a little.
    let next: Vec<(Vec2, Vec2)> = pairs
        .iter()
        .map(|(p, q)| (*p, *q + Vec2::new(0.3, -0.2)))
        .collect();
    let warm = ThinPlate::solve(&next, FRAME, &s, Some(&cold));
    let again = ThinPlate::solve(&next, FRAME, &s, None);
    assert!(
        warm.report_x.residuals.len() < again.report_x.residuals.len(),
        "warm {} vs cold {} cycles",
        warm.report_x.residuals.len(),
        again.report_x.residuals.len()
    );
}

#[test]
fn hybrid_meets_constraints() {
    for seed in 0..3 {
        let pairs = smooth_pairs(seed, 40, 256.0, 192.0, 12.0, 16.0);
        let m = hybrid::solve(
            &pairs,
            FRAME,
            &HybridSettings::default(),
            &ThinPlateSettings::default(),
            &MffdSettings::default(),
        );
        let miss = worst_miss(|p| m.apply(p), &pairs);
        assert!(miss <= 0.05, "seed {seed}: {miss} px");
        // The plate's propagated warp did the bulk: the MFFD steps after
        // it are within Theorem 1's bound.
        for d in &m.steps[1..] {
            assert!(d.largest_step() <= 0.48 + 1e-12);
        }
    }
}
