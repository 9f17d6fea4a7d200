//! A stroke font for viewer labels: each glyph a few polylines, so labels
//! can be drawn by anything that draws lines (OpenGL 1.1, a software
//! rasteriser) without a font file.
//!
//! Glyphs sit in a box 0.6 wide and 1 high (the cap height), y up, with the
//! baseline at 0; each advances by [`ADVANCE`].

use crate::geom::Vec2;

/// Horizontal distance from one glyph's origin to the next, in cap heights.
pub const ADVANCE: f64 = 0.8;

type Glyph = &'static [&'static [(f64, f64)]];

/// The polylines of `c`: digits, `A`, `B`, `-` and space; anything else is a
/// box, so a missing glyph shows rather than vanishes.
pub fn glyph(c: char) -> Glyph {
    match c {
        '0' => &[&[
            (0.0, 0.0),
            (0.6, 0.0),
            (0.6, 1.0),
            (0.0, 1.0),
            (0.0, 0.0),
            (0.6, 1.0),
        ]],
        '1' => &[
            &[(0.1, 0.8), (0.3, 1.0), (0.3, 0.0)],
            &[(0.1, 0.0), (0.5, 0.0)],
        ],
        '2' => &[&[
            (0.0, 1.0),
            (0.6, 1.0),
            (0.6, 0.5),
            (0.0, 0.5),
            (0.0, 0.0),
            (0.6, 0.0),
        ]],
        '3' => &[
            &[(0.0, 1.0), (0.6, 1.0), (0.6, 0.0), (0.0, 0.0)],
            &[(0.1, 0.5), (0.6, 0.5)],
        ],
        '4' => &[
            &[(0.0, 1.0), (0.0, 0.5), (0.6, 0.5)],
            &[(0.45, 1.0), (0.45, 0.0)],
        ],
        '5' => &[&[
            (0.6, 1.0),
            (0.0, 1.0),
            (0.0, 0.5),
            (0.6, 0.5),
            (0.6, 0.0),
            (0.0, 0.0),
        ]],
        '6' => &[&[
            (0.6, 1.0),
            (0.0, 1.0),
            (0.0, 0.0),
            (0.6, 0.0),
            (0.6, 0.5),
            (0.0, 0.5),
        ]],
        '7' => &[&[(0.0, 1.0), (0.6, 1.0), (0.2, 0.0)]],
        '8' => &[
            &[(0.0, 0.0), (0.6, 0.0), (0.6, 1.0), (0.0, 1.0), (0.0, 0.0)],
            &[(0.0, 0.5), (0.6, 0.5)],
        ],
        '9' => &[&[
            (0.6, 0.5),
            (0.0, 0.5),
            (0.0, 1.0),
            (0.6, 1.0),
            (0.6, 0.0),
            (0.0, 0.0),
        ]],
        'A' => &[
            &[(0.0, 0.0), (0.3, 1.0), (0.6, 0.0)],
            &[(0.1, 0.35), (0.5, 0.35)],
        ],
        'B' => &[
            &[
                (0.0, 0.0),
                (0.0, 1.0),
                (0.45, 1.0),
                (0.55, 0.9),
                (0.55, 0.6),
                (0.45, 0.5),
            ],
            &[
                (0.0, 0.5),
                (0.5, 0.5),
                (0.6, 0.4),
                (0.6, 0.1),
                (0.5, 0.0),
                (0.0, 0.0),
            ],
        ],
        '-' => &[&[(0.1, 0.5), (0.5, 0.5)]],
        ' ' => &[],
        _ => &[&[(0.0, 0.0), (0.6, 0.0), (0.6, 1.0), (0.0, 1.0), (0.0, 0.0)]],
    }
}

/// `text` as polylines: its baseline starts at `origin`, capitals are
/// `height` high, and `aspect` stretches x (screen pixels are not always
/// square in canonical coordinates).
pub fn text(text: &str, origin: Vec2, height: f64, aspect: f64) -> Vec<Vec<Vec2>> {
    let mut lines = Vec::new();
    for (k, c) in text.chars().enumerate() {
        let x0 = origin.x + k as f64 * ADVANCE * height * aspect;
        for stroke in glyph(c) {
            lines.push(
                stroke
                    .iter()
                    .map(|&(x, y)| Vec2::new(x0 + x * height * aspect, origin.y + y * height))
                    .collect(),
            );
        }
    }
    lines
}

/// The width `text` takes at `height` (and `aspect`).
pub fn width(text: &str, height: f64, aspect: f64) -> f64 {
    let n = text.chars().count();
    if n == 0 {
        0.0
    } else {
        ((n - 1) as f64 * ADVANCE + 0.6) * height * aspect
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_label_glyph_stays_in_its_box() {
        for c in "0123456789AB- ?".chars() {
            for stroke in glyph(c) {
                assert!(stroke.len() >= 2, "{c:?}: a stroke is at least a segment");
                for &(x, y) in *stroke {
                    assert!(
                        (0.0..=0.6).contains(&x) && (0.0..=1.0).contains(&y),
                        "{c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn text_is_placed_scaled_and_advanced() {
        let lines = text("17", Vec2::new(10.0, 20.0), 10.0, 1.0);
        // '1' has two strokes, '7' one; the 7 starts one advance (8) right.
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0][0], Vec2::new(11.0, 28.0));
        assert_eq!(lines[2][0], Vec2::new(18.0, 30.0));
        assert_eq!(width("17", 10.0, 1.0), 14.0);
    }
}
