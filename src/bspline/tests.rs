use super::mba::{interpolate, MbaSettings};
use super::*;
use crate::geom::{PixelScale, RectI, Vec2};
use crate::testing::Lcg;

fn random_lattice(seed: u64, nx: usize, ny: usize, h: f64) -> Lattice {
    let mut r = Lcg::new(seed);
    let mut l = Lattice::zero(Vec2::new(-13.0, 7.0), h, nx, ny);
    for v in l.phi.iter_mut() {
        *v = r.range(-5.0, 5.0);
    }
    l
}

#[test]
fn basis_is_a_partition_of_unity_with_linear_precision() {
    for k in 0..=20 {
        let s = k as f64 / 20.0;
        let b = basis(s);
        assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        // Controls at −1, 0, 1, 2 reproduce the line s.
        let line: f64 = b
            .iter()
            .enumerate()
            .map(|(k, w)| w * (k as f64 - 1.0))
            .sum();
        assert!((line - s).abs() < 1e-15);
        let d = basis_derivative(s);
        assert!(d.iter().sum::<f64>().abs() < 1e-15);
        // Derivative by central differences.
        let e = 1e-6;
        let (bp, bm) = (basis((s + e).min(1.0)), basis((s - e).max(0.0)));
        let span = (s + e).min(1.0) - (s - e).max(0.0);
        for k in 0..4 {
            assert!(((bp[k] - bm[k]) / span - d[k]).abs() < 1e-6);
        }
    }
}

#[test]
fn refinement_keeps_the_function_exactly() {
    let coarse = random_lattice(3, 7, 6, 16.0);
    let fine = coarse.refined();
    assert_eq!(fine.h, 8.0);
    let mut r = Lcg::new(9);
    // Everywhere, including beyond the stored controls (both vanish there).
    for _ in 0..500 {
        let p = Vec2::new(r.range(-80.0, 150.0), r.range(-60.0, 150.0));
        let (a, b) = (coarse.eval(p), fine.eval(p));
        assert!((a - b).abs() < 1e-12, "{p:?}: {a} vs {b}");
    }
}

#[test]
fn gradient_matches_finite_differences() {
    let l = random_lattice(5, 8, 8, 10.0);
    let mut r = Lcg::new(2);
    for _ in 0..100 {
        let p = Vec2::new(r.range(0.0, 60.0), r.range(0.0, 60.0));
        let e = 1e-5;
        let fd = Vec2::new(
            (l.eval(p + Vec2::new(e, 0.0)) - l.eval(p - Vec2::new(e, 0.0))) / (2.0 * e),
            (l.eval(p + Vec2::new(0.0, e)) - l.eval(p - Vec2::new(0.0, e))) / (2.0 * e),
        );
        assert!(fd.distance(l.gradient(p)) < 1e-6);
    }
}

#[test]
fn dense_evaluation_equals_pointwise() {
    let l = random_lattice(8, 9, 7, 12.0);
    let window = RectI::new(-3, 2, 41, 30);
    let scale = PixelScale::new(0.5, 0.5, 1.0);
    let dense = l.eval_window(window, scale);
    for j in window.y1..window.y2 {
        for i in window.x1..window.x2 {
            let k = (j - window.y1) as usize * window.width() + (i - window.x1) as usize;
            let exact = l.eval(scale.pixel_centre(i, j));
            assert!((dense[k] as f64 - exact).abs() < 1e-4);
        }
    }
}

#[test]
fn one_point_is_met_exactly_by_the_least_squares_rule() {
    // Eq. (4): with one point, the 16 controls move it by exactly Δq.
    let mut l = Lattice::covering(Vec2::ZERO, Vec2::new(50.0, 50.0), 10.0);
    let p = Vec2::new(23.4, 31.7);
    let mut fit = Approximation::new(&l);
    fit.add(p, Vec2::new(2.5, -1.5));
    let (x, y) = fit.finish(None);
    assert!((x.eval(p) - 2.5).abs() < 1e-12);
    assert!((y.eval(p) + 1.5).abs() < 1e-12);
    l.add(&x);
    assert!((l.eval(p) - 2.5).abs() < 1e-12);
}

/// Scattered heights at points at least `gap` apart.
fn scattered(seed: u64, n: usize, size: f64) -> Vec<(Vec2, f64)> {
    let mut r = Lcg::new(seed);
    crate::testing::smooth_pairs(seed, n, size, size, 1.0, 12.0)
        .into_iter()
        .map(|(p, _)| (p, r.range(-1.0, 1.0)))
        .collect()
}

#[test]
fn multilevel_interpolation_reaches_its_threshold() {
    for seed in 0..4 {
        let points = scattered(seed, 60, 256.0);
        let s = MbaSettings {
            threshold: 1e-4,
            ..MbaSettings::default()
        };
        let surface = interpolate(&points, Vec2::ZERO, Vec2::new(256.0, 256.0), &s);
        assert!(surface.error <= 1e-4, "seed {seed}: {}", surface.error);
        for (p, v) in &points {
            assert!((surface.eval(*p) - v).abs() <= 1e-4);
        }
        // Coarse first: more than one lattice was needed and used.
        assert!(surface.levels > 2, "{}", surface.levels);
    }
}

#[test]
fn multilevel_interpolation_is_c2() {
    // Second derivatives by finite differences on both sides of every knot
    // line crossed agree to O(η); a C¹-only surface would jump there.
    let points = scattered(7, 40, 128.0);
    let surface = interpolate(
        &points,
        Vec2::ZERO,
        Vec2::new(128.0, 128.0),
        &MbaSettings::default(),
    );
    let l = &surface.lattice;
    let second = |p: Vec2, d: f64| {
        (l.eval(p + Vec2::new(d, 0.0)) - 2.0 * l.eval(p) + l.eval(p - Vec2::new(d, 0.0))) / (d * d)
    };
    let (eta, d) = (1e-3 * l.h, 1e-4 * l.h);
    let mut scale: f64 = 0.0;
    let mut worst: f64 = 0.0;
    let mut r = Lcg::new(1);
    for _ in 0..200 {
        // A knot line x = origin + k h, at a random y.
        let k = (r.range(2.0, 2.0 + 128.0 / l.h)).floor();
        let x = l.origin.x + k * l.h;
        let p = Vec2::new(x, r.range(0.0, 128.0));
        let (left, right) = (
            second(p - Vec2::new(eta, 0.0), d),
            second(p + Vec2::new(eta, 0.0), d),
        );
        scale = scale.max(left.abs());
        worst = worst.max((left - right).abs());
    }
    assert!(scale > 1e-4, "the surface bends ({scale})");
    assert!(
        worst < 0.02 * scale,
        "jump in f_xx: {worst} (scale {scale})"
    );
}

#[test]
fn no_points_give_the_zero_surface() {
    let s = interpolate(
        &[],
        Vec2::ZERO,
        Vec2::new(10.0, 10.0),
        &MbaSettings::default(),
    );
    assert!(s.lattice.is_zero());
    assert_eq!(s.levels, 0);
}
