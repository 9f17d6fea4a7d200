//! Uniform Catmull-Rom splines through control points (curves pass through
//! every control point; the end tangents come from duplicated end points).

use crate::geom::Vec2;

/// Position on the Catmull-Rom spline through `points` at span `span`
/// (between `points[span]` and `points[span + 1]`), local parameter `s` in `[0, 1]`.
pub fn catmull_rom(points: &[Vec2], span: usize, s: f64) -> Vec2 {
    let n = points.len();
    debug_assert!(n >= 2 && span + 1 < n);
    let p = |i: isize| points[i.clamp(0, n as isize - 1) as usize];
    let i = span as isize;
    cubic([p(i - 1), p(i), p(i + 1), p(i + 2)], s)
}

/// Position on the closed Catmull-Rom loop through `points` at span `span`
/// (from `points[span]` to the next point, the last span back to the
/// first), local parameter `s` in `[0, 1]`: neighbours wrap around, so the
/// loop is C¹ at every control point, the first included.
pub fn catmull_rom_closed(points: &[Vec2], span: usize, s: f64) -> Vec2 {
    let n = points.len() as isize;
    debug_assert!(n >= 2 && (span as isize) < n);
    let p = |i: isize| points[i.rem_euclid(n) as usize];
    let i = span as isize;
    cubic([p(i - 1), p(i), p(i + 1), p(i + 2)], s)
}

/// The uniform Catmull-Rom cubic between `p1` and `p2`.
fn cubic([p0, p1, p2, p3]: [Vec2; 4], s: f64) -> Vec2 {
    let s2 = s * s;
    let s3 = s2 * s;
    // 0.5 * (2 P1 + (P2 - P0) s + (2 P0 - 5 P1 + 4 P2 - P3) s² + (3 P1 - P0 - 3 P2 + P3) s³)
    (p1 * 2.0
        + (p2 - p0) * s
        + (p0 * 2.0 - p1 * 5.0 + p2 * 4.0 - p3) * s2
        + (p1 * 3.0 - p0 - p2 * 3.0 + p3) * s3)
        * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_through_control_points() {
        let pts = [
            Vec2::new(0.0, 0.0),
            Vec2::new(10.0, 5.0),
            Vec2::new(20.0, -3.0),
            Vec2::new(31.0, 2.0),
        ];
        for span in 0..3 {
            assert_eq!(catmull_rom(&pts, span, 0.0), pts[span]);
            let end = catmull_rom(&pts, span, 1.0);
            assert!(end.distance(pts[span + 1]) < 1e-12);
        }
    }

    #[test]
    fn a_closed_loop_passes_through_every_point_and_is_smooth_at_the_first() {
        let pts = [
            Vec2::new(0.0, 0.0),
            Vec2::new(10.0, 0.0),
            Vec2::new(10.0, 10.0),
            Vec2::new(0.0, 10.0),
        ];
        for span in 0..4 {
            assert_eq!(catmull_rom_closed(&pts, span, 0.0), pts[span]);
            let end = catmull_rom_closed(&pts, span, 1.0);
            assert!(end.distance(pts[(span + 1) % 4]) < 1e-12);
        }
        // The tangent leaving the first point equals the one arriving at it
        // (both (P1 - P3) / 2 by symmetry of the wrap).
        let h = 1e-6;
        let leave = (catmull_rom_closed(&pts, 0, h) - pts[0]) * (1.0 / h);
        let arrive = (pts[0] - catmull_rom_closed(&pts, 3, 1.0 - h)) * (1.0 / h);
        assert!(leave.distance(arrive) < 1e-4, "{leave:?} {arrive:?}");
        assert!(leave.distance(Vec2::new(5.0, -5.0)) < 1e-4, "{leave:?}");
    }

    #[test]
    fn collinear_evenly_spaced_points_give_a_straight_uniform_line() {
        let pts: Vec<Vec2> = (0..4).map(|i| Vec2::new(i as f64 * 3.0, 1.0)).collect();
        // Interior span: the cubic reduces to linear motion.
        let m = catmull_rom(&pts, 1, 0.25);
        assert!(m.distance(Vec2::new(3.75, 1.0)) < 1e-12);
    }
}
