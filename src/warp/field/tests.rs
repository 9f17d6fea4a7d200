use super::*;
use crate::features::{Feature, FeatureKind, Side};
use crate::warp::Warp;
use proptest::prelude::*;

pub(super) fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

pub(super) fn exact(a: f64) -> FieldSettings {
    FieldSettings {
        a,
        evaluation: Evaluation::Exact,
        ..FieldSettings::default()
    }
}

fn one_pair(dst: (Vec2, Vec2), src: (Vec2, Vec2)) -> FieldWarp {
    FieldWarp::new(vec![LinePair { dst, src }], &exact(0.001))
}

#[test]
fn single_pair_of_equal_lines_translates() {
    let w = one_pair((v(10.0, 10.0), v(30.0, 10.0)), (v(15.0, 7.0), v(35.0, 7.0)));
    for x in [v(0.0, 0.0), v(20.0, 40.0), v(-50.0, 3.0)] {
        let m = w.map_reference(x);
        assert!(m.distance(x + v(5.0, -3.0)) < 1e-9, "{x:?} -> {m:?}");
    }
}

#[test]
fn single_pair_rotated_line_rotates_about_the_lines() {
    // dst along +x from the origin, src along +y: X' = R(90°) X.
    let w = one_pair((v(0.0, 0.0), v(10.0, 0.0)), (v(0.0, 0.0), v(0.0, 10.0)));
    for x in [v(3.0, 4.0), v(-2.0, 7.0), v(12.0, -1.0)] {
        let m = w.map_reference(x);
        assert!(m.distance(v(-x.y, x.x)) < 1e-9, "{x:?} -> {m:?}");
    }
}

#[test]
fn single_pair_scales_along_the_line_only() {
    // src twice as long: u scales by 2 along x, v (pixels) unchanged in y.
    let w = one_pair((v(0.0, 0.0), v(10.0, 0.0)), (v(0.0, 0.0), v(20.0, 0.0)));
    for x in [v(3.0, 4.0), v(-2.0, -7.0)] {
        let m = w.map_reference(x);
        assert!(m.distance(v(2.0 * x.x, x.y)) < 1e-9, "{x:?} -> {m:?}");
    }
}

#[test]
fn identical_features_give_the_identity() {
    let f = Feature::new(
        FeatureKind::Polyline,
        vec![v(1.0, 2.0), v(40.0, 9.0), v(60.0, 50.0)],
        vec![v(1.0, 2.0), v(40.0, 9.0), v(60.0, 50.0)],
    );
    let w = FieldWarp::toward(&[f], Side::A, 0.37, &FieldSettings::default());
    assert!(w.is_identity());
    assert_eq!(w.map(v(5.5, 7.25)), v(5.5, 7.25));
}

#[test]
fn end_frames_are_identity_warps_of_their_image() {
    let f = Feature::line(
        [v(10.0, 10.0), v(50.0, 20.0)],
        [v(12.0, 30.0), v(40.0, 60.0)],
    );
    for mode in [LineInterpolation::Endpoints, LineInterpolation::CenterAngle] {
        let s = FieldSettings {
            interpolation: mode,
            ..FieldSettings::default()
        };
        assert!(FieldWarp::toward(std::slice::from_ref(&f), Side::A, 0.0, &s).is_identity());
        assert!(FieldWarp::toward(std::slice::from_ref(&f), Side::B, 1.0, &s).is_identity());
        assert!(!FieldWarp::toward(std::slice::from_ref(&f), Side::A, 0.5, &s).is_identity());
    }
}

#[test]
fn point_features_translate_their_neighbourhood() {
    let f = Feature::point(v(50.0, 50.0), v(58.0, 44.0));
    let w = FieldWarp::toward(&[f], Side::A, 1.0, &exact(0.001));
    // Output at B's position samples A's position: a pure translation.
    let m = w.map_reference(v(58.0, 44.0));
    assert!(m.distance(v(50.0, 50.0)) < 1e-9);
    assert!(w.map_reference(v(0.0, 0.0)).distance(v(-8.0, 6.0)) < 1e-9);
}

#[test]
fn center_angle_interpolation_keeps_length_of_a_rotating_line() {
    let a = (v(-10.0, 0.0), v(10.0, 0.0));
    let b = (v(0.0, -10.0), v(0.0, 10.0));
    let (p, q) = interpolate_line(a, b, 0.5, LineInterpolation::CenterAngle);
    assert!((p.distance(q) - 20.0).abs() < 1e-9);
    let (p, q) = interpolate_line(a, b, 0.5, LineInterpolation::Endpoints);
    assert!((p.distance(q) - 20.0 * 0.5f64.sqrt()).abs() < 1e-9);
}

#[test]
fn multi_line_pixels_on_a_line_follow_that_line() {
    // With a tiny `a`, a pixel on a destination line maps onto its source line.
    let pairs = vec![
        LinePair {
            dst: (v(10.0, 10.0), v(90.0, 10.0)),
            src: (v(12.0, 20.0), v(95.0, 15.0)),
        },
        LinePair {
            dst: (v(10.0, 90.0), v(10.0, 30.0)),
            src: (v(5.0, 80.0), v(20.0, 35.0)),
        },
    ];
    let w = FieldWarp::new(pairs.clone(), &exact(1e-6));
    for (pair, u) in [(&pairs[0], 0.3), (&pairs[1], 0.8)] {
        let x = pair.dst.0.lerp(pair.dst.1, u);
        let expected = pair.src.0.lerp(pair.src.1, u);
        assert!(w.map_reference(x).distance(expected) < 1e-3);
    }
}

/// Deterministic uniform numbers in [0, 1) (a 64-bit LCG's high bits).
fn uniform(mut s: u64) -> impl FnMut() -> f64 {
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn random_pairs(seed: u64, n: usize, size: f64) -> Vec<LinePair> {
    let mut r = uniform(
        seed.wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407),
    );
    (0..n)
        .map(|_| {
            let p = v(r() * size, r() * size);
            let q = p + v(r() * 60.0 - 30.0 + 5.0, r() * 60.0 - 30.0 + 5.0);
            let jitter = v(r() * 20.0 - 10.0, r() * 20.0 - 10.0);
            let jitter2 = v(r() * 20.0 - 10.0, r() * 20.0 - 10.0);
            LinePair {
                dst: (p, q),
                src: (p + jitter, q + jitter2),
            }
        })
        .collect()
}

#[test]
fn vector_kernel_matches_the_f64_reference() {
    let w = FieldWarp::new(random_pairs(7, 25, 400.0), &exact(0.001));
    let pts: Vec<(f32, f32)> = (0..997)
        .map(|k| ((k * 37 % 400) as f32 + 0.5, (k * 91 % 400) as f32 + 0.5))
        .collect();
    let (xs, ys): (Vec<f32>, Vec<f32>) = pts.iter().copied().unzip();
    let (mut ox, mut oy) = (vec![0.0; xs.len()], vec![0.0; xs.len()]);
    w.map_points(&xs, &ys, &mut ox, &mut oy);
    let mut worst = 0.0f64;
    for k in 0..xs.len() {
        let r = w.map_reference(v(xs[k] as f64, ys[k] as f64));
        worst = worst.max(r.distance(v(ox[k] as f64, oy[k] as f64)));
    }
    assert!(
        worst < 2e-3,
        "f32 kernel strays {worst} px from the reference"
    );
}

#[test]
fn general_exponents_match_the_reference() {
    for b in [0.0, 0.5, 1.0, 1.3] {
        let s = FieldSettings {
            b,
            p: 0.7,
            ..exact(0.5)
        };
        let w = FieldWarp::new(random_pairs(3, 6, 200.0), &s);
        let (xs, ys) = (vec![17.5f32, 150.5, 88.5], vec![3.5f32, 190.5, 100.5]);
        let (mut ox, mut oy) = (vec![0.0; 3], vec![0.0; 3]);
        w.map_points(&xs, &ys, &mut ox, &mut oy);
        for k in 0..3 {
            let r = w.map_reference(v(xs[k] as f64, ys[k] as f64));
            assert!(r.distance(v(ox[k] as f64, oy[k] as f64)) < 2e-3, "b = {b}");
        }
    }
}

#[test]
fn adaptive_mode_stays_within_its_tolerance_on_random_line_sets() {
    let window = RectI::from_size(320, 240);
    for seed in 0..6 {
        let pairs = random_pairs(seed, 12, 300.0);
        let exact_warp = FieldWarp::new(pairs.clone(), &exact(0.001));
        let tolerance = Evaluation::DEFAULT_TOLERANCE;
        let adaptive = FieldWarp::new(
            pairs,
            &FieldSettings {
                evaluation: Evaluation::Adaptive { tolerance },
                ..exact(0.001)
            },
        );
        let e = exact_warp.map_window(window, PixelScale::UNIT);
        let a = adaptive.map_window(window, PixelScale::UNIT);
        let mut worst = 0.0f64;
        for j in 0..240 {
            for i in 0..320 {
                worst = worst.max(e.get(i, j).distance(a.get(i, j)));
            }
        }
        assert!(
            worst <= tolerance,
            "seed {seed}: adaptive error {worst} px > {tolerance}"
        );
    }
}

/// Long lines spread over a wide frame, many of them: every block mixes
/// near and far lines, the case the adaptive split exists for.
pub(super) fn spread_pairs(seed: u64, n: usize, w: f64, h: f64) -> Vec<LinePair> {
    let mut r = uniform(seed.wrapping_add(0x9E37_79B9_7F4A_7C15));
    (0..n)
        .map(|_| {
            let p = v(r() * w, r() * h);
            let angle = r() * std::f64::consts::TAU;
            let len = 20.0 + r() * 150.0;
            let q = p + v(angle.cos(), angle.sin()) * len;
            let mut jitter = || v(r() * 30.0 - 15.0, r() * 30.0 - 15.0);
            let (jp, jq) = (jitter(), jitter());
            LinePair {
                dst: (p, q),
                src: (p + jp, q + jq),
            }
        })
        .collect()
}

#[test]
fn adaptive_mode_stays_within_its_tolerance_on_dense_line_sets_and_proxy_scale() {
    let tolerance = Evaluation::DEFAULT_TOLERANCE;
    for (seed, n, scale) in [(1, 40, 1.0), (2, 60, 1.0), (3, 40, 0.5)] {
        let pairs = spread_pairs(seed, n, 640.0, 360.0);
        let scale = PixelScale::new(scale, scale, 1.0);
        let window = RectI::new(0, 0, (640.0 * scale.x) as i32, (360.0 * scale.y) as i32);
        let exact_warp = FieldWarp::new(pairs.clone(), &exact(0.001));
        let adaptive = FieldWarp::new(
            pairs,
            &FieldSettings {
                evaluation: Evaluation::Adaptive { tolerance },
                ..exact(0.001)
            },
        );
        let e = exact_warp.map_window(window, scale);
        let a = adaptive.map_window(window, scale);
        let mut worst = 0.0f64;
        for j in window.y1..window.y2 {
            for i in window.x1..window.x2 {
                // Error in output pixels at this scale.
                let (pe, pa) = (scale.to_pixel(e.get(i, j)), scale.to_pixel(a.get(i, j)));
                worst = worst.max(pe.distance(pa));
            }
        }
        assert!(
            worst <= tolerance,
            "seed {seed}, {n} lines, scale {}: adaptive error {worst} px > {tolerance}",
            scale.x
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Warping A all the way (t = 1) brings A's line endpoints onto B's.
    #[test]
    fn warp_of_a_at_t1_sends_line_endpoints_onto_b(
        ax in 20.0..200.0f64, ay in 20.0..200.0f64, dx in 10.0..60.0f64, dy in -40.0..40.0f64,
        mx in -15.0..15.0f64, my in -15.0..15.0f64, rot in -0.5..0.5f64,
        ox in 250.0..400.0f64, oy in 20.0..300.0f64,
    ) {
        let a0 = v(ax, ay);
        let a1 = a0 + v(dx, dy);
        let d = a1 - a0;
        let b0 = a0 + v(mx, my);
        let b1 = b0 + v(d.x * rot.cos() - d.y * rot.sin(), d.x * rot.sin() + d.y * rot.cos());
        let other = Feature::line(
            [v(ox, oy), v(ox + 30.0, oy + 5.0)],
            [v(ox + 3.0, oy), v(ox + 33.0, oy + 8.0)],
        );
        let f = Feature::line([a0, a1], [b0, b1]);
        let s = FieldSettings { a: 1e-4, ..exact(1e-4) };
        let w = FieldWarp::toward(&[f, other], Side::A, 1.0, &s);
        prop_assert!(w.map_reference(b0).distance(a0) < 0.05);
        prop_assert!(w.map_reference(b1).distance(a1) < 0.05);
    }
}

#[test]
fn a_closed_polyline_adds_the_line_from_its_last_point_back_to_its_first() {
    let a = vec![v(0.0, 0.0), v(40.0, 0.0), v(20.0, 30.0)];
    let b = vec![v(2.0, 1.0), v(44.0, 0.0), v(21.0, 35.0)];
    let open = Feature::new(FeatureKind::Polyline, a.clone(), b.clone());
    let closed = open.clone().closed(true);
    let settings = FieldSettings::default();
    let pairs =
        |f: &Feature| line_pairs_toward(std::slice::from_ref(f), Side::A, 0.5.into(), &settings);
    let (p_open, p_closed) = (pairs(&open), pairs(&closed));
    assert_eq!(p_open.len(), 2);
    assert_eq!(p_closed.len(), 3);
    assert_eq!(p_closed[..2], p_open[..]);
    // The closing pair runs from the last point to the first: on A exactly,
    // halfway between A and B at t = 0.5.
    assert_eq!(p_closed[2].src, (a[2], a[0]));
    assert_eq!(
        p_closed[2].dst,
        (a[2].lerp(b[2], 0.5), a[0].lerp(b[0], 0.5))
    );
}
