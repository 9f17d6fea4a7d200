//! What the overlay draws, as calls on a [`Painter`]: pure, so it is tested
//! without a host, and the same for the Draw suite and OpenGL.

use morphfx::features::{Feature, Side};
use morphfx::geom::Vec2;

use super::hit::{Handle, Part};
use crate::nodes::lines::SlotLine;
use crate::nodes::params::Show;
use crate::wrapper::paint::{Painter, Stipple, LABEL_PX};

/// Everything one draw shows.
pub struct Frame<'a> {
    /// The slots' lines at the draw's time.
    pub slots: &'a [SlotLine],
    /// The slots' in-between lines at the progress, in the same order.
    pub between: &'a [[Vec2; 2]],
    /// Features of the scene file or text: drawn dimmer, not editable.
    pub scene: &'a [Feature],
    /// What to show.
    pub show: Show,
    /// The handle under the pen.
    pub hover: Option<Handle>,
    /// Canonical units per screen pixel, x and y.
    pub pixel: (f64, f64),
}

/// A's lines.
pub const A_COLOUR: [f32; 3] = [1.0, 0.55, 0.1];
/// B's lines.
pub const B_COLOUR: [f32; 3] = [0.25, 0.8, 1.0];
const BETWEEN_COLOUR: [f32; 3] = [0.95, 0.95, 0.95];
const CONNECTOR_COLOUR: [f32; 3] = [0.75, 0.75, 0.75];
const SHADOW: [f32; 4] = [0.0, 0.0, 0.0, 0.8];

/// Arrowhead and label sizes, in screen pixels.
const ARROW_PX: f64 = 10.0;
const LABEL_GAP_PX: f64 = 6.0;
const HANDLE_PX: f64 = 4.0;
/// Draws `frame`: everything twice, a dark shadow one pixel down and right,
/// then in colour, so it reads on any plate.
pub fn paint(p: &mut dyn Painter, frame: &Frame<'_>) {
    if frame.show == Show::Off {
        return;
    }
    let (px, py) = frame.pixel;
    for shadow in [true, false] {
        let offset = if shadow {
            Vec2::new(px, -py)
        } else {
            Vec2::ZERO
        };
        let mut pen = Pen {
            painter: p,
            offset,
            shadow,
            pixel: frame.pixel,
        };
        pen.scene(frame);
        pen.slots(frame);
    }
}

/// A painter with the pass's offset and colour rule.
struct Pen<'a> {
    painter: &'a mut dyn Painter,
    offset: Vec2,
    shadow: bool,
    pixel: (f64, f64),
}

impl Pen<'_> {
    fn colour(&mut self, rgb: [f32; 3], alpha: f32) {
        let c = if self.shadow {
            [SHADOW[0], SHADOW[1], SHADOW[2], SHADOW[3] * alpha]
        } else {
            [rgb[0], rgb[1], rgb[2], alpha]
        };
        self.painter.colour(c);
    }

    fn at(&self, p: Vec2) -> Vec2 {
        p + self.offset
    }

    /// A screen-pixel vector in canonical units.
    fn screen(&self, dx: f64, dy: f64) -> Vec2 {
        Vec2::new(dx * self.pixel.0, dy * self.pixel.1)
    }

    fn segment(&mut self, [p, q]: [Vec2; 2]) {
        let pts = [self.at(p), self.at(q)];
        self.painter.lines(&pts);
    }

    /// The line `p → q` with an arrowhead at `q`.
    fn arrow(&mut self, [p, q]: [Vec2; 2]) {
        self.segment([p, q]);
        // The head's direction in screen pixels, so it keeps its shape at
        // any zoom and pixel aspect.
        let d = Vec2::new((q.x - p.x) / self.pixel.0, (q.y - p.y) / self.pixel.1);
        let len = d.length();
        if len < 1e-9 {
            return;
        }
        let (ux, uy) = (d.x / len, d.y / len);
        let (c, s) = (0.93969, 0.34202); // ±20°
        let wing = |sign: f64| {
            let (wx, wy) = (ux * c - sign * uy * s, sign * ux * s + uy * c);
            q - self.screen(wx * ARROW_PX, wy * ARROW_PX)
        };
        let pts = [q, wing(1.0), q, wing(-1.0)].map(|v| self.at(v));
        self.painter.lines(&pts);
    }

    /// `text` beside `at`: above-left of it for A, below-left for B, so the
    /// two numbers stay apart when A's and B's starts coincide (a line just
    /// drawn has both on the same spot).
    fn label(&mut self, at: Vec2, side: Side, text: &str) {
        let dy = match side {
            Side::A => LABEL_GAP_PX,
            Side::B => -LABEL_GAP_PX - LABEL_PX,
        };
        let at = self.at(at + self.screen(-LABEL_GAP_PX * 2.0, dy));
        self.painter.text(at, text);
    }

    fn scene(&mut self, frame: &Frame<'_>) {
        self.painter.stipple(Stipple::Solid);
        self.painter.width(1.0);
        for (side, colour) in sides(frame.show) {
            self.colour(colour, 0.55);
            for f in frame.scene {
                let pts: Vec<Vec2> = f.sampled(side, 8).iter().map(|p| self.at(*p)).collect();
                match pts.len() {
                    0 => {}
                    1 => {
                        // A point feature: a small cross.
                        let (h, v) = (self.screen(HANDLE_PX, 0.0), self.screen(0.0, HANDLE_PX));
                        let c = pts[0];
                        self.painter.lines(&[c - h, c + h, c - v, c + v]);
                    }
                    _ => self.painter.strip(&pts),
                }
            }
        }
    }

    fn slots(&mut self, frame: &Frame<'_>) {
        if matches!(frame.show, Show::Both) {
            // Thin connectors from A's ends to B's.
            self.painter.stipple(Stipple::Solid);
            self.painter.width(1.0);
            self.colour(CONNECTOR_COLOUR, 0.5);
            let pts: Vec<Vec2> = frame
                .slots
                .iter()
                .flat_map(|l| [l.a[0], l.b[0], l.a[1], l.b[1]])
                .map(|p| self.at(p))
                .collect();
            if !pts.is_empty() {
                self.painter.lines(&pts);
            }
        }
        if matches!(frame.show, Show::Both | Show::Between) {
            self.painter.stipple(Stipple::Dash);
            self.painter.width(1.0);
            self.colour(BETWEEN_COLOUR, 0.9);
            for line in frame.between {
                self.arrow(*line);
            }
        }
        self.painter.stipple(Stipple::Solid);
        for (side, colour) in sides(frame.show) {
            for l in frame.slots {
                let hovered = frame.hover.filter(|h| h.slot == l.slot && h.side == side);
                self.painter
                    .width(if hovered.is_some() { 3.0 } else { 1.5 });
                self.colour(colour, 1.0);
                let line = l.side(side);
                self.arrow(line);
                self.label(line[0], side, &l.slot.to_string());
                if let Some(h) = hovered {
                    self.handle(line, h.part);
                }
            }
        }
    }

    /// A square around the hovered end (none for a whole-line grab).
    fn handle(&mut self, line: [Vec2; 2], part: Part) {
        let c = match part {
            Part::Start => line[0],
            Part::End => line[1],
            Part::Middle => return,
        };
        let (dx, dy) = (self.screen(HANDLE_PX, 0.0), self.screen(0.0, HANDLE_PX));
        let pts = [
            c - dx - dy,
            c + dx - dy,
            c + dx + dy,
            c - dx + dy,
            c - dx - dy,
        ];
        let pts = pts.map(|p| self.at(p));
        self.painter.strip(&pts);
    }
}

/// The sides `show` draws, with their colours.
fn sides(show: Show) -> Vec<(Side, [f32; 3])> {
    match show {
        Show::Both => vec![(Side::A, A_COLOUR), (Side::B, B_COLOUR)],
        Show::A => vec![(Side::A, A_COLOUR)],
        Show::B => vec![(Side::B, B_COLOUR)],
        Show::Between | Show::Off => vec![],
    }
}
