//! What the pen is over: a control point of a feature, or its body (with
//! where along it), measured in screen pixels so a handle is as easy to
//! grab at any zoom.

use morphfx::features::{FeatureKind, Side};
use morphfx::geom::Vec2;

use super::grid::{self, Grid};
use super::outline::{per_span, Outline};
use super::state::{Handle, Part};

/// How close (screen pixels) the pen must come to grab.
pub const RADIUS_PX: f64 = 8.0;

/// The handle nearest `pen` within [`RADIUS_PX`] among `sides` of the
/// editable `outlines` and the grid's nodes: points and nodes before
/// bodies (a point sits on its body), nearer before farther, and on a tie
/// the first side listed.
pub fn hit(
    outlines: &[Outline],
    grid: Option<&Grid>,
    pen: Vec2,
    pixel: (f64, f64),
    sides: &[Side],
) -> Option<Handle> {
    let screen = |p: Vec2| Vec2::new(p.x / pixel.0, p.y / pixel.1);
    let pen_at = pen;
    let pen = screen(pen);
    let mut best: Option<(u8, f64, Handle)> = None;
    let mut consider = |rank: u8, dist: f64, handle: Handle| {
        let better = best.is_none_or(|(r, d, _)| (rank, dist) < (r, d));
        if dist <= RADIUS_PX && better {
            best = Some((rank, dist, handle));
        }
    };
    for &side in sides {
        for o in outlines.iter().filter(|o| o.editable()) {
            let handle = |part| Handle {
                owner: o.owner,
                side,
                part,
            };
            for (i, p) in o.feature.points(side).iter().enumerate() {
                consider(0, pen.distance(screen(*p)), handle(Part::Point(i)));
            }
            if o.feature.kind == FeatureKind::Point {
                continue;
            }
            if let Some((dist, span, s)) = nearest_on_chain(o, side, pen, screen) {
                consider(1, dist, handle(Part::Body { span, s }));
            }
        }
    }
    if let Some((dist, handle)) = grid.and_then(|g| grid::nearest(g, pen_at, pixel, sides)) {
        consider(0, dist, handle);
    }
    best.map(|(_, _, h)| h)
}

/// The distance (screen pixels) from `pen` to the outline's chain on
/// `side`, and the span and parameter there.
fn nearest_on_chain(
    o: &Outline,
    side: Side,
    pen: Vec2,
    screen: impl Fn(Vec2) -> Vec2,
) -> Option<(f64, usize, f64)> {
    let per = per_span(o.feature.kind);
    let chain: Vec<Vec2> = o.chain(side).into_iter().map(screen).collect();
    let mut best: Option<(f64, usize, f64)> = None;
    for (k, w) in chain.windows(2).enumerate() {
        let d = w[1] - w[0];
        let len2 = d.dot(d);
        let u = if len2 > 0.0 {
            ((pen - w[0]).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = pen.distance(w[0] + d * u);
        if best.is_none_or(|(b, _, _)| dist < b) {
            best = Some((dist, k / per, ((k % per) as f64 + u) / per as f64));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::super::state::Owner;
    use super::*;
    use morphfx::features::Feature;

    fn slot() -> Outline {
        Outline {
            owner: Owner::Slot(3),
            feature: Feature::line(
                [Vec2::new(100.0, 100.0), Vec2::new(200.0, 100.0)],
                [Vec2::new(100.0, 300.0), Vec2::new(200.0, 300.0)],
            ),
        }
    }

    #[test]
    fn points_win_over_bodies_and_sides_are_kept_apart() {
        let s = [slot()];
        let both = [Side::A, Side::B];
        let h = hit(&s, None, Vec2::new(103.0, 101.0), (1.0, 1.0), &both).unwrap();
        assert_eq!(
            (h.owner, h.side, h.part),
            (Owner::Slot(3), Side::A, Part::Point(0))
        );
        let h = hit(&s, None, Vec2::new(150.0, 296.0), (1.0, 1.0), &both).unwrap();
        assert_eq!((h.side, h.part), (Side::B, Part::Body { span: 0, s: 0.5 }));
        assert_eq!(
            hit(&s, None, Vec2::new(150.0, 296.0), (1.0, 1.0), &[Side::A]),
            None
        );
        assert_eq!(
            hit(&s, None, Vec2::new(150.0, 200.0), (1.0, 1.0), &both),
            None
        );
    }

    #[test]
    fn the_radius_is_in_screen_pixels() {
        let s = [slot()];
        // 20 canonical units right of A's end: 20 screen pixels at (1, 1),
        // 5 at (4, 4) (zoomed out: one screen pixel covers four).
        let pen = Vec2::new(220.0, 100.0);
        assert_eq!(hit(&s, None, pen, (1.0, 1.0), &[Side::A]), None);
        let h = hit(&s, None, pen, (4.0, 4.0), &[Side::A]).unwrap();
        assert_eq!(h.part, Part::Point(1));
        // Anamorphic (2, 1): x distances halve, y ones do not.
        assert!(hit(&s, None, Vec2::new(212.0, 100.0), (2.0, 1.0), &[Side::A]).is_some());
        assert!(hit(&s, None, Vec2::new(200.0, 112.0), (2.0, 1.0), &[Side::A]).is_none());
    }

    #[test]
    fn a_closed_shapes_last_span_and_a_curves_parameter_are_found() {
        let sq = [(0.0, 0.0), (100.0, 0.0), (100.0, 100.0), (0.0, 100.0)]
            .map(|(x, y)| Vec2::new(x, y))
            .to_vec();
        let mut o = Outline {
            owner: Owner::Shape(0),
            feature: Feature::new(FeatureKind::Polyline, sq.clone(), sq).closed(true),
        };
        // On the closing side x = 0, a quarter of the way from (0, 100) down.
        let h = hit(
            &[o.clone()],
            None,
            Vec2::new(1.0, 75.0),
            (1.0, 1.0),
            &[Side::A],
        )
        .unwrap();
        assert_eq!(h.part, Part::Body { span: 3, s: 0.25 });
        // File features are never grabbed.
        o.owner = Owner::File(0);
        assert_eq!(
            hit(&[o], None, Vec2::new(0.0, 0.0), (1.0, 1.0), &[Side::A]),
            None
        );
    }
}
