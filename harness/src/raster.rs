//! Draws a plugin overlay's recorded Draw-suite calls onto a plate, with
//! anti-aliased strokes: what `morphfx overlay` shows instead of a viewer.

use morphfx::geom::Vec2;
use morphfx::image::Image;
use morphfx::strokes;
use openfx::sys::image_effect_v1::draw_suite::*;
use tiny_skia::{Color, LineCap, Paint, PathBuilder, Pixmap, Stroke, StrokeDash, Transform};

use crate::host::overlay::DrawCall;

/// Label cap height, screen pixels (the host's font size, for us).
const LABEL_PX: f64 = 10.0;

/// Paints `calls` over `image`, whose pixels are `pixel` canonical units
/// each. Colours are composited straight onto the image's values.
pub fn paint(image: &mut Image, calls: &[DrawCall], pixel: (f64, f64)) {
    let (w, h) = (image.width(), image.height());
    let Some(mut pixmap) = Pixmap::new(w as u32, h as u32) else {
        return;
    };
    let b = image.bounds;
    // Canonical to pixmap pixels: scale, offset by the bounds, flip y.
    let to_px = |p: [f64; 2]| {
        let x = p[0] / pixel.0 - b.x1 as f64;
        let y = h as f64 - (p[1] / pixel.1 - b.y1 as f64);
        (x as f32, y as f32)
    };
    let mut state = State::default();
    for call in calls {
        match call {
            DrawCall::Colour(c) => state.colour = *c,
            DrawCall::Width(px) => state.width = *px,
            DrawCall::Stipple(s) => state.dashed = *s != kOfxDrawLineStipplePatternSolid,
            DrawCall::Draw { primitive, points } => {
                let pts: Vec<(f32, f32)> = points.iter().map(|p| to_px(*p)).collect();
                for path in shapes(*primitive, &pts) {
                    state.stroke(&mut pixmap, &path, false);
                }
            }
            DrawCall::Text { text, at, .. } => {
                let origin = Vec2::new(at[0], at[1]);
                let strokes = strokes::text(text, origin, LABEL_PX * pixel.1, pixel.0 / pixel.1);
                for s in strokes {
                    let pts: Vec<(f32, f32)> = s.iter().map(|p| to_px([p.x, p.y])).collect();
                    state.stroke(&mut pixmap, &pts, true);
                }
            }
        }
    }
    composite(image, &pixmap);
}

#[derive(Debug)]
struct State {
    colour: [f32; 4],
    width: f32,
    dashed: bool,
}

impl Default for State {
    fn default() -> Self {
        State {
            colour: [1.0; 4],
            width: 1.0,
            dashed: false,
        }
    }
}

impl State {
    /// Strokes the polyline `pts` (text: always solid, one pixel).
    fn stroke(&self, pixmap: &mut Pixmap, pts: &[(f32, f32)], text: bool) {
        let mut pb = PathBuilder::new();
        let Some((first, rest)) = pts.split_first() else {
            return;
        };
        pb.move_to(first.0, first.1);
        for p in rest {
            pb.line_to(p.0, p.1);
        }
        let Some(path) = pb.finish() else { return };
        let [r, g, b, a] = self.colour.map(|v| v.clamp(0.0, 1.0));
        let mut paint = Paint::default();
        paint.set_color(Color::from_rgba(r, g, b, a).unwrap_or(Color::WHITE));
        paint.anti_alias = true;
        let stroke = Stroke {
            width: if text { 1.0 } else { self.width.max(1.0) },
            line_cap: LineCap::Round,
            dash: (self.dashed && !text)
                .then(|| StrokeDash::new(vec![6.0, 4.0], 0.0))
                .flatten(),
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }
}

/// The polylines a primitive's points make (outlines for filled shapes).
fn shapes(primitive: OfxDrawPrimitive, pts: &[(f32, f32)]) -> Vec<Vec<(f32, f32)>> {
    if primitive == kOfxDrawPrimitiveLines {
        pts.chunks_exact(2).map(|p| p.to_vec()).collect()
    } else if primitive == kOfxDrawPrimitiveLineStrip {
        vec![pts.to_vec()]
    } else if primitive == kOfxDrawPrimitiveRectangle && pts.len() == 2 {
        let ((x0, y0), (x1, y1)) = (pts[0], pts[1]);
        vec![vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]]
    } else {
        // Loops, polygons and ellipses (as their bounding polygon): closed.
        let mut closed = pts.to_vec();
        closed.extend(pts.first());
        vec![closed]
    }
}

/// `pixmap` (premultiplied RGBA8, top row first) over `image` (bottom row
/// first), on its colour channels and alpha.
fn composite(image: &mut Image, pixmap: &Pixmap) {
    let (w, h, ch) = (image.width(), image.height(), image.channels);
    for (r, row) in pixmap.data().chunks_exact(w * 4).enumerate() {
        let j = h - 1 - r;
        for (i, px) in row.chunks_exact(4).enumerate() {
            let a = px[3] as f32 / 255.0;
            if a == 0.0 {
                continue;
            }
            let o = (j * w + i) * ch;
            let dst = &mut image.data[o..o + ch];
            for c in 0..ch.min(3) {
                dst[c] = px[c] as f32 / 255.0 + dst[c] * (1.0 - a);
            }
            if ch == 4 {
                dst[3] = a + dst[3] * (1.0 - a);
            } else if ch == 1 {
                dst[0] = a + dst[0] * (1.0 - a);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use morphfx::geom::RectI;

    #[test]
    fn a_white_line_lands_on_its_pixels_and_nowhere_else() {
        let mut image = Image::new(RectI::new(0, 0, 40, 20), 4);
        let calls = [
            DrawCall::Colour([1.0, 1.0, 1.0, 1.0]),
            DrawCall::Width(1.0),
            DrawCall::Draw {
                primitive: kOfxDrawPrimitiveLines,
                points: vec![[5.0, 10.5], [35.0, 10.5]],
            },
        ];
        paint(&mut image, &calls, (1.0, 1.0));
        // Row j = 10 (centre y 10.5) is covered along x 5..35; rows 3 away are not.
        assert!(image.pixel(20, 10)[0] > 0.9, "{:?}", image.pixel(20, 10));
        assert_eq!(image.pixel(20, 13), [0.0; 4]);
        assert_eq!(image.pixel(38, 10), [0.0; 4]);
    }
}
