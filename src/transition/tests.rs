use super::procedural::MAX_SPREAD;
use super::*;
use crate::features::{Feature, Side};
use crate::geom::{PixelScale, RectD, RectI, Vec2};
use crate::make_warp::{self, Method, MethodSettings, WarpSettings};

const FRAME: RectD = RectD {
    x1: 0.0,
    y1: 0.0,
    x2: 320.0,
    y2: 240.0,
};

fn features() -> Vec<Feature> {
    vec![
        Feature::new(
            crate::features::FeatureKind::Polyline,
            vec![
                Vec2::new(40.0, 40.0),
                Vec2::new(90.0, 60.0),
                Vec2::new(120.0, 40.0),
            ],
            vec![
                Vec2::new(50.0, 45.0),
                Vec2::new(95.0, 70.0),
                Vec2::new(130.0, 42.0),
            ],
        )
        .named("mouth"),
        Feature::point(Vec2::new(250.0, 180.0), Vec2::new(240.0, 170.0)).named("eye"),
        Feature::point(Vec2::new(160.0, 120.0), Vec2::new(165.0, 118.0)),
    ]
}

fn curves(propagation: Propagation) -> Transition {
    let curve = |keys: &[(f64, f64)]| Curve::new(keys, "test").unwrap();
    Transition::Curves {
        curves: vec![
            Attached {
                attach: Attach::Name("mouth".into()),
                curve: curve(&[(0.3, 0.8), (0.6, 0.9)]),
            },
            Attached {
                attach: Attach::Name("eye".into()),
                curve: curve(&[(0.5, 0.1)]),
            },
            Attached {
                attach: Attach::At(Vec2::new(300.0, 20.0)),
                curve: curve(&[(0.2, 0.0), (0.7, 0.05)]),
            },
        ],
        propagation,
    }
}

#[test]
fn rates_at_curve_points_equal_their_curves_at_every_t() {
    let fs = features();
    for (propagation, tolerance) in [
        (Propagation::BSpline(MbaSettings::default()), 1e-3),
        (
            Propagation::ThinPlate(ThinPlateSettings {
                cell: 8.0,
                ..ThinPlateSettings::default()
            }),
            0.01,
        ),
    ] {
        let transition = curves(propagation);
        let Transition::Curves { curves: list, .. } = &transition else {
            unreachable!()
        };
        for k in 0..=20 {
            let t = k as f64 / 20.0;
            let rates = transition.rates(&fs, 20, FRAME, t).unwrap();
            for c in list {
                let points = match &c.attach {
                    Attach::At(p) => vec![*p],
                    Attach::Name(n) => fs
                        .iter()
                        .find(|f| f.name.as_deref() == Some(n))
                        .unwrap()
                        .sampled(Side::A, 20),
                    Attach::Index(i) => fs[*i].sampled(Side::A, 20),
                };
                for p in points {
                    let (got, want) = (rates.at(p), c.curve.at(t));
                    assert!(
                        (got - want).abs() <= tolerance,
                        "{propagation:?} t {t}: {got} vs {want} at {p:?}"
                    );
                }
            }
            // Exactly A and B at the ends, everywhere.
            if t == 0.0 || t == 1.0 {
                assert_eq!(rates, Rates::Uniform(t));
            }
        }
    }
}

#[test]
fn propagated_rates_are_smooth_between_curves() {
    // Between the fast mouth (0.8 at t = 0.3) and the slow eye (≈ 0.06),
    // the rate along the segment joining them passes through the values
    // in between without leaving [0, 1].
    let rates = curves(Propagation::default())
        .rates(&features(), 20, FRAME, 0.3)
        .unwrap();
    let (from, to) = (Vec2::new(90.0, 60.0), Vec2::new(250.0, 180.0));
    let samples: Vec<f64> = (0..=50)
        .map(|k| rates.at(from.lerp(to, k as f64 / 50.0)))
        .collect();
    assert!((samples[0] - 0.8).abs() < 1e-3);
    assert!(samples.iter().all(|r| (0.0..=1.0).contains(r)));
    let steps = samples
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    assert!(steps < 0.1, "no jumps: largest step {steps}");
}

#[test]
fn procedural_rates_are_a_at_zero_and_b_at_one() {
    let patterns = [
        Pattern::Ramp { angle: 0.0 },
        Pattern::Ramp { angle: 135.0 },
        Pattern::SineRows { cycles: 2.0 },
        Pattern::SineColumns { cycles: 3.5 },
        Pattern::Radial {
            cycles: 0.0,
            centre: None,
        },
        Pattern::Radial {
            cycles: 2.0,
            centre: Some(Vec2::new(10.0, 200.0)),
        },
    ];
    let mut r = crate::testing::Lcg::new(3);
    for pattern in patterns {
        for spread in [0.0, 0.3, 0.9, MAX_SPREAD] {
            let p = Procedural { pattern, spread };
            for _ in 0..200 {
                let x = Vec2::new(r.range(-10.0, 330.0), r.range(-10.0, 250.0));
                assert_eq!(p.rate(x, FRAME, 0.0), 0.0);
                assert_eq!(p.rate(x, FRAME, 1.0), 1.0);
                let mut last = 0.0;
                for k in 0..=40 {
                    let rate = p.rate(x, FRAME, k as f64 / 40.0);
                    assert!(
                        (0.0..=1.0).contains(&rate) && rate >= last,
                        "{pattern:?} {spread}"
                    );
                    last = rate;
                }
            }
        }
    }
    // A left-to-right ramp: the left edge is further along than the right.
    let ramp = Procedural {
        pattern: Pattern::Ramp { angle: 0.0 },
        spread: 0.5,
    };
    let (left, right) = (Vec2::new(0.0, 100.0), Vec2::new(320.0, 100.0));
    assert_eq!(ramp.rate(left, FRAME, 0.5), 1.0);
    assert_eq!(ramp.rate(right, FRAME, 0.5), 0.0);
    assert!((ramp.rate(Vec2::new(160.0, 7.0), FRAME, 0.5) - 0.5).abs() < 1e-12);
}

fn settings(method: Method, transition: TransitionSettings) -> WarpSettings {
    WarpSettings {
        region: Some(FRAME),
        ..WarpSettings::new(MethodSettings {
            method,
            transition,
            ..MethodSettings::default()
        })
    }
}

#[test]
fn geometry_rates_move_each_feature_point_at_its_own_pace() {
    // The eye's curve is at 0.1 when t = 0.5: the warps of A and of B both
    // take the eye's in-between position a + 0.1 (b − a) to its place.
    let fs = features();
    let transition = TransitionSettings {
        geometry: curves(Propagation::default()),
        colour: None,
    };
    for method in [Method::Triangles, Method::ThinPlate, Method::Mffd] {
        let s = settings(method, transition.clone());
        let eye = &fs[1];
        let mid = eye.a[0].lerp(eye.b[0], 0.1);
        let tolerance = if method == Method::Triangles {
            1e-9
        } else {
            0.05
        };
        let wa = make_warp::toward(&fs, Side::A, 0.5, &s).unwrap();
        let wb = make_warp::toward(&fs, Side::B, 0.5, &s).unwrap();
        assert!(
            wa.map(mid).distance(eye.a[0]) < tolerance,
            "{method:?} A: {:?}",
            wa.map(mid)
        );
        assert!(
            wb.map(mid).distance(eye.b[0]) < tolerance,
            "{method:?} B: {:?}",
            wb.map(mid)
        );
        // The unattached point follows the propagated rate, not t.
        let rates = s.geometry_rates(&fs, 0.5).unwrap();
        let free = &fs[2];
        let r = rates.at(free.a[0]);
        assert!((r - 0.5).abs() > 1e-3, "the curves reach the centre ({r})");
        let mid = free.a[0].lerp(free.b[0], r);
        assert!(wa.map(mid).distance(free.a[0]) < tolerance);
    }
}

/// The colour weights at t = 0.5 of pixels that see the given source
/// points on A and on B (one pixel per pair), the features' curves pacing
/// the colour: the eye at rate 0.1, the mouth by its own curve.
fn weights_of(pixels: &[(Vec2, Vec2)]) -> Weights {
    let fs = features();
    let transition = TransitionSettings {
        geometry: Transition::Uniform,
        colour: Some(curves(Propagation::default())),
    };
    let s = settings(Method::Triangles, transition);
    let rates = s.colour_rates(&fs, 0.5).unwrap();
    let w1 = make_warp::toward(&fs, Side::A, 1.0, &s).unwrap();
    let window = RectI::new(0, 0, pixels.len() as i32, 1);
    let scale = PixelScale::new(1.0, 1.0, 1.0);
    let map = |side: fn(&(Vec2, Vec2)) -> Vec2| {
        let at: Vec<[f32; 2]> = pixels
            .iter()
            .map(side)
            .map(|v| [v.x as f32, v.y as f32])
            .collect();
        crate::image::WarpMap::new(window, scale, at)
    };
    colour_weights(&rates, &map(|p| p.0), &map(|p| p.1), w1.as_ref())
}

#[test]
fn colour_weights_carry_t0_to_b_through_w1() {
    // A pixel showing the eye on both sides: A's weight is 1 − C(t) and
    // B's is T1(b) = T0(W1(b)) = C(t), so the two sum to one there.
    let fs = features();
    let (eye, mouth) = (&fs[1], Vec2::new(90.0, 60.0));
    let w = weights_of(&[(eye.a[0], eye.b[0]), (mouth, fs[0].b[1])]);
    let eye_rate = 0.1;
    assert!((w.a[0] as f64 - (1.0 - eye_rate)).abs() < 2e-3, "{:?}", w.a);
    assert!((w.b[0] as f64 - eye_rate).abs() < 2e-3, "{:?}", w.b);
    let mouth_rate = Curve::new(&[(0.3, 0.8), (0.6, 0.9)], "m").unwrap().at(0.5);
    assert!((w.a[1] as f64 - (1.0 - mouth_rate)).abs() < 2e-3);
    assert!((w.b[1] as f64 - mouth_rate).abs() < 2e-3);
}

#[test]
fn colour_weights_sum_to_one_where_the_two_points_disagree() {
    // A pixel whose A point is the eye (rate 0.1) but whose B point is
    // the mouth's (rate C(t) of the mouth curve): the paper's weights,
    // 1 − 0.1 and C(t), sum to more than 1; the dissolve keeps their ratio
    // and sums to 1, so opaque plates stay opaque.
    let fs = features();
    let w = weights_of(&[(fs[1].a[0], fs[0].b[1])]);
    let t = 0.5;
    let mouth_rate = Curve::new(&[(0.3, 0.8), (0.6, 0.9)], "m").unwrap().at(t);
    let (pa, pb) = (1.0 - 0.1, mouth_rate);
    assert!(pa + pb > 1.5, "the paper's weights sum to {}", pa + pb);
    assert!((w.a[0] + w.b[0] - 1.0).abs() < 1e-6, "{:?} {:?}", w.a, w.b);
    assert!((w.a[0] as f64 / w.b[0] as f64 - pa / pb).abs() < 1e-2);
}
