//! What the pen is over: an end of a slot's line, or its middle, measured
//! in screen pixels so a handle is as easy to grab at any zoom.

use morphfx::features::Side;
use morphfx::geom::Vec2;

use crate::nodes::lines::SlotLine;

/// How close (screen pixels) the pen must come to grab.
pub const RADIUS_PX: f64 = 8.0;

/// Which part of a line the pen holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The start (the arrow's tail).
    Start,
    /// The end (the arrowhead).
    End,
    /// The body: dragging moves the whole line.
    Middle,
}

/// A grabbable part of one slot's line on one side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Handle {
    /// Slot number, from 1.
    pub slot: usize,
    /// A's line or B's.
    pub side: Side,
    /// Which part.
    pub part: Part,
}

/// The handle nearest `pen` within [`RADIUS_PX`] among `sides` of `slots`:
/// ends before bodies (an end sits on its body), nearer before farther,
/// and on a tie the first side listed.
pub fn hit(slots: &[SlotLine], pen: Vec2, pixel: (f64, f64), sides: &[Side]) -> Option<Handle> {
    let screen = |p: Vec2| Vec2::new(p.x / pixel.0, p.y / pixel.1);
    let pen = screen(pen);
    let mut best: Option<(u8, f64, Handle)> = None;
    let mut consider = |rank: u8, dist: f64, handle: Handle| {
        let better = match best {
            None => true,
            Some((r, d, _)) => (rank, dist) < (r, d),
        };
        if dist <= RADIUS_PX && better {
            best = Some((rank, dist, handle));
        }
    };
    for &side in sides {
        for l in slots {
            let [p, q] = l.side(side).map(screen);
            let handle = |part| Handle {
                slot: l.slot,
                side,
                part,
            };
            consider(0, pen.distance(p), handle(Part::Start));
            consider(0, pen.distance(q), handle(Part::End));
            consider(1, pen.distance_to_segment(p, q), handle(Part::Middle));
        }
    }
    best.map(|(_, _, h)| h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slot() -> SlotLine {
        SlotLine {
            slot: 3,
            a: [Vec2::new(100.0, 100.0), Vec2::new(200.0, 100.0)],
            b: [Vec2::new(100.0, 300.0), Vec2::new(200.0, 300.0)],
        }
    }

    #[test]
    fn ends_win_over_bodies_and_sides_are_kept_apart() {
        let s = [slot()];
        let both = [Side::A, Side::B];
        let h = hit(&s, Vec2::new(103.0, 101.0), (1.0, 1.0), &both).unwrap();
        assert_eq!((h.slot, h.side, h.part), (3, Side::A, Part::Start));
        let h = hit(&s, Vec2::new(150.0, 296.0), (1.0, 1.0), &both).unwrap();
        assert_eq!((h.side, h.part), (Side::B, Part::Middle));
        assert_eq!(
            hit(&s, Vec2::new(150.0, 296.0), (1.0, 1.0), &[Side::A]),
            None
        );
        assert_eq!(hit(&s, Vec2::new(150.0, 200.0), (1.0, 1.0), &both), None);
    }

    #[test]
    fn the_radius_is_in_screen_pixels() {
        let s = [slot()];
        // 20 canonical units right of A's end: 20 screen pixels at (1, 1),
        // 5 at (4, 4) (zoomed out: one screen pixel covers four).
        let pen = Vec2::new(220.0, 100.0);
        assert_eq!(hit(&s, pen, (1.0, 1.0), &[Side::A]), None);
        let h = hit(&s, pen, (4.0, 4.0), &[Side::A]).unwrap();
        assert_eq!(h.part, Part::End);
        // Anamorphic (2, 1): x distances halve, y ones do not.
        assert!(hit(&s, Vec2::new(212.0, 100.0), (2.0, 1.0), &[Side::A]).is_some());
        assert!(hit(&s, Vec2::new(200.0, 112.0), (2.0, 1.0), &[Side::A]).is_none());
    }
}
