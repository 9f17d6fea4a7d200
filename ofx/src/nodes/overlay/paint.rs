//! What the overlay draws, as calls on a [`Painter`]: pure, so it is tested
//! without a host, and the same for the Draw suite and OpenGL.

use morphfx::features::{FeatureKind, Side};
use morphfx::geom::Vec2;
use morphfx::warp::mesh::{Mesh, Node};

use super::grid::{self, Grid};
use super::outline::{per_span, Outline};
use super::state::{Handle, Owner, Part};
use crate::nodes::params::Show;
use ofx_layer::paint::{Painter, Stipple, LABEL_PX};

/// Everything one draw shows.
pub struct Frame<'a> {
    /// Every feature at the draw's time: slots, Scene Text's shapes, Scene
    /// File's features (drawn dimmer).
    pub outlines: &'a [Outline],
    /// Each outline's in-between chain at the progress, in the same order.
    pub between: &'a [Vec<Vec2>],
    /// What to show.
    pub show: Show,
    /// The handle under the pen.
    pub hover: Option<Handle>,
    /// Canonical units per screen pixel, x and y.
    pub pixel: (f64, f64),
    /// The frames the scene's shapes are keyed at, and the draw's time.
    pub keys: (&'a [f64], f64),
    /// The control points of a polyline or curve being drawn, and where
    /// the pen is (the next point's rubber band runs there).
    pub building: (&'a [Vec2], Option<Vec2>),
    /// The scene's mesh, when the method is mesh.
    pub grid: Option<&'a Grid>,
    /// The grid nodes selected, on one side.
    pub grid_selection: Option<&'a (Side, Vec<Node>)>,
    /// A rubber band being drawn, corner to corner.
    pub band: Option<[Vec2; 2]>,
}

/// A's features.
pub const A_COLOUR: [f32; 3] = [1.0, 0.55, 0.1];
/// B's features.
pub const B_COLOUR: [f32; 3] = [0.25, 0.8, 1.0];
const BETWEEN_COLOUR: [f32; 3] = [0.95, 0.95, 0.95];
/// Selected grid nodes and the rubber band that selects them.
const SELECTED_COLOUR: [f32; 3] = [1.0, 1.0, 0.3];

/// A suggested pair's colour by its confidence, on both sides until the
/// artist edits it: red when doubtful, through yellow, to green when sure.
pub fn confidence_colour(c: f64) -> [f32; 3] {
    let c = c.clamp(0.0, 1.0) as f32;
    if c < 0.5 {
        [1.0, 0.25 + 1.5 * c, 0.2]
    } else {
        [1.0 - 1.4 * (c - 0.5), 1.0, 0.2 + 0.2 * (c - 0.5)]
    }
}
const CONNECTOR_COLOUR: [f32; 3] = [0.75, 0.75, 0.75];
const SHADOW: [f32; 4] = [0.0, 0.0, 0.0, 0.8];
/// Scene File's features: read-only, so drawn fainter.
const FILE_ALPHA: f32 = 0.45;

/// Arrowhead and label sizes, in screen pixels.
const ARROW_PX: f64 = 10.0;
const LABEL_GAP_PX: f64 = 6.0;
const HANDLE_PX: f64 = 4.0;
/// Control point marks of shapes, half a side, screen pixels.
const POINT_PX: f64 = 2.5;

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
        pen.grid(frame);
        pen.connectors(frame);
        pen.between(frame);
        pen.features(frame);
        pen.building(frame.building);
        pen.keys(frame);
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
        self.head([p, q]);
    }

    /// An arrowhead at `q` pointing from `p`.
    fn head(&mut self, [p, q]: [Vec2; 2]) {
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

    /// The mesh: the in-between grid dashed, then each side's rows and
    /// columns (Scene File's fainter) with its nodes marked where the pen
    /// may grab them, the hovered node heavier.
    fn grid(&mut self, frame: &Frame<'_>) {
        let Some(g) = frame.grid else { return };
        if matches!(frame.show, Show::Both | Show::Between) {
            self.painter.stipple(Stipple::Dash);
            self.painter.width(1.0);
            self.colour(BETWEEN_COLOUR, 0.6);
            self.grid_lines(&g.between);
        }
        self.painter.stipple(Stipple::Solid);
        for (side, colour) in sides(frame.show) {
            self.painter.width(1.0);
            self.colour(colour, if g.editable { 0.8 } else { FILE_ALPHA });
            let mesh = g.side(side);
            self.grid_lines(mesh);
            if !g.editable {
                continue;
            }
            let marks: Vec<Vec2> = mesh
                .nodes()
                .iter()
                .flat_map(|p| self.square(*p, POINT_PX))
                .collect();
            self.painter.lines(&marks);
            let hovered = frame
                .hover
                .filter(|h| h.owner == Owner::Grid && h.side == side);
            if let Some(h) = hovered {
                self.painter.width(2.0);
                self.handle(mesh.nodes(), h.part);
            }
            if let Some((_, nodes)) = frame.grid_selection.filter(|(s, _)| *s == side) {
                self.painter.width(2.0);
                self.colour(SELECTED_COLOUR, 1.0);
                let marks: Vec<Vec2> = nodes
                    .iter()
                    .filter(|n| n.row < mesh.rows() && n.col < mesh.cols())
                    .flat_map(|n| self.square(mesh.node(n.row, n.col), HANDLE_PX))
                    .collect();
                self.painter.lines(&marks);
            }
        }
        if let Some([p, q]) = frame.band {
            self.painter.stipple(Stipple::Dash);
            self.painter.width(1.0);
            self.colour(SELECTED_COLOUR, 0.9);
            let corners = [p, Vec2::new(q.x, p.y), q, Vec2::new(p.x, q.y), p];
            let pts: Vec<Vec2> = corners.iter().map(|c| self.at(*c)).collect();
            self.painter.strip(&pts);
            self.painter.stipple(Stipple::Solid);
        }
    }

    fn grid_lines(&mut self, mesh: &Mesh) {
        for line in grid::lines(mesh) {
            let pts: Vec<Vec2> = line.iter().map(|p| self.at(*p)).collect();
            self.painter.strip(&pts);
        }
    }

    /// Thin connectors from A's control points to B's.
    fn connectors(&mut self, frame: &Frame<'_>) {
        if frame.show != Show::Both {
            return;
        }
        self.painter.stipple(Stipple::Solid);
        self.painter.width(1.0);
        self.colour(CONNECTOR_COLOUR, 0.5);
        let pts: Vec<Vec2> = frame
            .outlines
            .iter()
            .filter(|o| o.editable())
            .flat_map(|o| o.feature.a.iter().zip(&o.feature.b))
            .flat_map(|(a, b)| [*a, *b])
            .map(|p| self.at(p))
            .collect();
        if !pts.is_empty() {
            self.painter.lines(&pts);
        }
    }

    /// The in-between shapes at the progress, dashed.
    fn between(&mut self, frame: &Frame<'_>) {
        if !matches!(frame.show, Show::Both | Show::Between) {
            return;
        }
        self.painter.stipple(Stipple::Dash);
        self.painter.width(1.0);
        self.colour(BETWEEN_COLOUR, 0.9);
        for (o, chain) in frame.outlines.iter().zip(frame.between) {
            self.shape(o, chain);
        }
    }

    /// Every feature on each side shown: chain, direction mark, label, and
    /// for shapes their control points; the hovered one heavier.
    fn features(&mut self, frame: &Frame<'_>) {
        self.painter.stipple(Stipple::Solid);
        let mut marks = Vec::new();
        for (side, colour) in sides(frame.show) {
            for o in frame.outlines {
                let hovered = frame.hover.filter(|h| h.owner == o.owner && h.side == side);
                let width = match (o.editable(), hovered) {
                    (false, _) => 1.0,
                    (true, Some(_)) => 3.0,
                    (true, None) => 1.5,
                };
                self.painter.width(width);
                let colour = o.feature.confidence.map_or(colour, confidence_colour);
                self.colour(colour, if o.editable() { 1.0 } else { FILE_ALPHA });
                let chain = o.chain(side);
                self.shape(o, &chain);
                let points = o.feature.points(side);
                self.label(points[0], side, &o.label());
                if let Some(h) = hovered {
                    self.handle(points, h.part);
                }
                if o.editable() && o.feature.kind != FeatureKind::Line {
                    marks.extend(points.iter().flat_map(|p| self.square(*p, POINT_PX)));
                }
            }
            if !marks.is_empty() {
                self.painter.width(1.0);
                self.painter.lines(&marks);
                marks.clear();
            }
        }
    }

    /// One feature's chain with its direction mark: an arrowhead at the end
    /// of an open chain, at the end of the first span of a closed one; a
    /// point is a cross.
    fn shape(&mut self, o: &Outline, chain: &[Vec2]) {
        match chain {
            [] => {}
            [c] => {
                let (h, v) = (self.screen(HANDLE_PX, 0.0), self.screen(0.0, HANDLE_PX));
                let pts = [*c - h, *c + h, *c - v, *c + v].map(|p| self.at(p));
                self.painter.lines(&pts);
            }
            [p, q] => self.arrow([*p, *q]),
            _ => {
                let pts: Vec<Vec2> = chain.iter().map(|p| self.at(*p)).collect();
                self.painter.strip(&pts);
                let tip = if o.feature.closed {
                    per_span(o.feature.kind).min(chain.len() - 1)
                } else {
                    chain.len() - 1
                };
                self.head([chain[tip - 1], chain[tip]]);
            }
        }
    }

    /// The control points of a polyline or curve being drawn, joined, the
    /// first one marked larger (a click there closes the shape), and a
    /// dashed rubber band from the last one to the pen.
    fn building(&mut self, (points, cursor): (&[Vec2], Option<Vec2>)) {
        let (Some(first), Some(last)) = (points.first(), points.last()) else {
            return;
        };
        if let Some(c) = cursor {
            self.painter.stipple(Stipple::Dash);
            self.painter.width(1.0);
            self.colour(A_COLOUR, 0.8);
            self.segment([*last, c]);
        }
        self.painter.stipple(Stipple::Solid);
        self.painter.width(1.5);
        self.colour(A_COLOUR, 1.0);
        if points.len() > 1 {
            let pts: Vec<Vec2> = points.iter().map(|p| self.at(*p)).collect();
            self.painter.strip(&pts);
        }
        let mut marks = self.square(*first, HANDLE_PX * 1.5).to_vec();
        marks.extend(points.iter().flat_map(|p| self.square(*p, POINT_PX)));
        self.painter.lines(&marks);
    }

    /// "keys 10 15 [20]": the frames Scene Text's shapes are keyed at (the
    /// draw's frame bracketed when it is one), below the lowest shape.
    fn keys(&mut self, frame: &Frame<'_>) {
        let (keys, time) = frame.keys;
        if keys.is_empty() {
            return;
        }
        let shapes = frame
            .outlines
            .iter()
            .filter(|o| matches!(o.owner, Owner::Shape(_)));
        let nodes = frame
            .grid
            .filter(|g| g.editable)
            .map(|g| g.pair.a.nodes().iter().chain(g.pair.b.nodes()));
        let corner = shapes
            .flat_map(|o| o.feature.a.iter().chain(&o.feature.b))
            .chain(nodes.into_iter().flatten())
            .fold(None, |m: Option<Vec2>, p| {
                Some(m.map_or(*p, |m| Vec2::new(m.x.min(p.x), m.y.min(p.y))))
            });
        let Some(corner) = corner else { return };
        self.colour(BETWEEN_COLOUR, 1.0);
        let at = self.at(corner - self.screen(0.0, 3.0 * LABEL_PX));
        self.painter.text(at, &key_list(keys, time));
    }

    /// A square of half-side `half_px` screen pixels around `c`, as four
    /// segments (eight points), so many go in one draw call.
    fn square(&self, c: Vec2, half_px: f64) -> [Vec2; 8] {
        let (dx, dy) = (self.screen(half_px, 0.0), self.screen(0.0, half_px));
        let corners = [c - dx - dy, c + dx - dy, c + dx + dy, c - dx + dy];
        let k = corners.map(|p| self.at(p));
        [k[0], k[1], k[1], k[2], k[2], k[3], k[3], k[0]]
    }

    /// A square around the hovered control point (none for a body grab).
    fn handle(&mut self, points: &[Vec2], part: Part) {
        let Part::Point(i) = part else { return };
        if let Some(c) = points.get(i) {
            let marks = self.square(*c, HANDLE_PX);
            self.painter.lines(&marks);
        }
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

/// The most keys the key list names one by one: a tracked scene keyed at
/// every frame would otherwise run a line of hundreds of frames off the
/// plate.
const KEYS_LISTED: usize = 7;

/// "keys 10 15 [20]": the frames keyed (`time`'s bracketed when it is one).
/// Past [`KEYS_LISTED`], the first and last keys and those next to `time`,
/// gaps as "…", and how many there are.
pub(super) fn key_list(keys: &[f64], time: f64) -> String {
    let name = |k: f64| {
        if (k - time).abs() < 1e-6 {
            format!("[{k}]")
        } else {
            k.to_string()
        }
    };
    if keys.len() <= KEYS_LISTED {
        let list: Vec<String> = keys.iter().map(|k| name(*k)).collect();
        return format!("keys {}", list.join(" "));
    }
    // The keys around `time`: the last at or before it, and its neighbours.
    let at = keys
        .partition_point(|k| *k <= time + 1e-6)
        .saturating_sub(1);
    let near = at.saturating_sub(1)..=(at + 1).min(keys.len() - 1);
    let mut shown: Vec<usize> = vec![0];
    shown.extend(near);
    shown.push(keys.len() - 1);
    shown.dedup();
    let mut words = Vec::new();
    for (n, &k) in shown.iter().enumerate() {
        if n > 0 && k > shown[n - 1] + 1 {
            words.push("…".to_string());
        }
        words.push(name(keys[k]));
    }
    format!("keys {} ({} keys)", words.join(" "), keys.len())
}

#[cfg(test)]
mod key_list_tests {
    use super::key_list;

    #[test]
    fn few_keys_are_all_named_and_many_are_elided_around_the_time() {
        assert_eq!(key_list(&[10.0, 15.0, 20.0], 20.0), "keys 10 15 [20]");
        let every: Vec<f64> = (1001..=1048).map(f64::from).collect();
        assert_eq!(
            key_list(&every, 1020.0),
            "keys 1001 … 1019 [1020] 1021 … 1048 (48 keys)"
        );
        assert_eq!(
            key_list(&every, 1001.0),
            "keys [1001] 1002 … 1048 (48 keys)"
        );
        assert_eq!(
            key_list(&every, 1048.0),
            "keys 1001 … 1047 [1048] (48 keys)"
        );
        assert_eq!(key_list(&every, 900.0), "keys 1001 1002 … 1048 (48 keys)");
    }
}
