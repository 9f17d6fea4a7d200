use super::*;
use crate::geom::RectI;
use crate::image::Image;

/// A plate dark left of `edge` and bright right of it (a vertical step).
fn step(edge: f64) -> Image {
    crate::testing::step_plate(RectI::from_size(96, 64), edge)
}

fn polyline(x: f64) -> Vec<Vec2> {
    vec![
        Vec2::new(x, 12.0),
        Vec2::new(x + 1.0, 32.0),
        Vec2::new(x, 52.0),
    ]
}

#[test]
fn a_polyline_placed_off_an_edge_locks_onto_it() {
    // The step lies between pixel columns 39 and 40: at x = 40.
    let energy = EdgeEnergy::new(step(40.0).view(), 3.0);
    for start in [44.5, 35.5] {
        let settings = SnakeSettings::default();
        let mut snake = Snake::from_primitive(FeatureKind::Polyline, &polyline(start), &settings);
        assert_eq!(snake.points.len(), 41);
        snake.run(&energy, &settings);
        for p in &snake.points {
            assert!((p.x - 40.0).abs() < 0.5, "from x = {start}: point at {p:?}");
        }
        // It slid across the edge, not along it.
        assert!(
            (snake.points[20].y - 32.0).abs() < 1.5,
            "{:?}",
            snake.points[20]
        );
    }
}

#[test]
fn clamped_points_do_not_move_and_unsnake_restores_the_controls() {
    let energy = EdgeEnergy::new(step(40.0).view(), 3.0);
    let settings = SnakeSettings {
        clamp_controls: true,
        ..SnakeSettings::default()
    };
    let controls = polyline(43.0);
    let mut snake = Snake::from_primitive(FeatureKind::Polyline, &controls, &settings);
    snake.run(&energy, &settings);
    assert_eq!(snake.unsnake(), controls);
    // Between the held controls the snake still bends toward the edge.
    let mid = snake.points[10];
    assert!(mid.x < 42.0, "{mid:?}");

    // Unclamped, unsnake gives back the moved control samples.
    let free = SnakeSettings::default();
    let mut moved = Snake::from_primitive(FeatureKind::Curve, &controls, &free);
    moved.run(&energy, &free);
    let back = moved.unsnake();
    assert_eq!(back.len(), 3);
    for (k, p) in back.iter().enumerate() {
        assert_eq!(*p, moved.points[k * free.samples_per_segment]);
        assert!((p.x - 40.0).abs() < 0.5, "{p:?}");
    }
}

#[test]
fn without_edges_nothing_pulls_and_straight_snakes_stay_put() {
    let flat = Image::from_fn(RectI::from_size(64, 64), 1, |_, _, _| 0.5);
    let energy = EdgeEnergy::new(flat.view(), 2.0);
    let settings = SnakeSettings::default();
    let straight = vec![
        Vec2::new(10.0, 10.0),
        Vec2::new(30.0, 20.0),
        Vec2::new(50.0, 30.0),
    ];
    let mut snake = Snake::from_primitive(FeatureKind::Polyline, &straight, &settings);
    let before = snake.points.clone();
    snake.run(&energy, &settings);
    for (a, b) in before.iter().zip(&snake.points) {
        assert!(a.distance(*b) < 1e-9, "{a:?} → {b:?}");
    }
}

#[test]
fn non_finite_pixels_keep_the_snake_finite() {
    let mut img = step(40.0);
    for v in img.data.iter_mut().step_by(7) {
        *v = f32::NAN;
    }
    img.data[100] = f32::INFINITY;
    let energy = EdgeEnergy::new(img.view(), 3.0);
    let settings = SnakeSettings::default();
    let mut snake = Snake::from_primitive(FeatureKind::Polyline, &polyline(44.0), &settings);
    snake.run(&energy, &settings);
    assert!(snake.points.iter().all(|p| p.is_finite()));
}
