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

/// The polylines of `c`: digits, letters (either case, drawn as capitals:
/// names of shapes), `# [ ] . _ ' -` and space; anything else is a box, so
/// a missing glyph shows rather than vanishes.
pub fn glyph(c: char) -> Vec<Vec<(f64, f64)>> {
    if let Some(strokes) = letter(c) {
        return strokes
            .split(';')
            .map(|stroke| {
                stroke
                    .split(' ')
                    .filter_map(|xy| {
                        let (x, y) = xy.split_once(',')?;
                        Some((x.parse::<f64>().ok()? / 10.0, y.parse::<f64>().ok()? / 10.0))
                    })
                    .collect()
            })
            .collect();
    }
    fixed(c).iter().map(|s| s.to_vec()).collect()
}

/// Letters and signs on a 6 × 10 grid (x, y): strokes separated by `;`,
/// points by spaces.
fn letter(c: char) -> Option<&'static str> {
    Some(match c.to_ascii_uppercase() {
        'C' => "6,10 0,10 0,0 6,0",
        'D' => "0,0 0,10 4,10 6,8 6,2 4,0 0,0",
        'E' => "6,10 0,10 0,0 6,0;0,5 4,5",
        'F' => "6,10 0,10 0,0;0,5 4,5",
        'G' => "6,10 0,10 0,0 6,0 6,5 3,5",
        'H' => "0,0 0,10;6,0 6,10;0,5 6,5",
        'I' => "1,10 5,10;3,10 3,0;1,0 5,0",
        'J' => "6,10 6,0 0,0 0,3",
        'K' => "0,0 0,10;6,10 0,4;2,6 6,0",
        'L' => "0,10 0,0 6,0",
        'M' => "0,0 0,10 3,5 6,10 6,0",
        'N' => "0,0 0,10 6,0 6,10",
        'O' => "0,0 6,0 6,10 0,10 0,0",
        'P' => "0,0 0,10 6,10 6,5 0,5",
        'Q' => "0,0 6,0 6,10 0,10 0,0;3,3 6,0",
        'R' => "0,0 0,10 6,10 6,5 0,5;2,5 6,0",
        'S' => "6,10 0,10 0,5 6,5 6,0 0,0",
        'T' => "0,10 6,10;3,10 3,0",
        'U' => "0,10 0,0 6,0 6,10",
        'V' => "0,10 3,0 6,10",
        'W' => "0,10 1.5,0 3,6 4.5,0 6,10",
        'X' => "0,0 6,10;0,10 6,0",
        'Y' => "0,10 3,5 6,10;3,5 3,0",
        'Z' => "0,10 6,10 0,0 6,0",
        '#' => "2,0 2,10;4,0 4,10;0,3 6,3;0,7 6,7",
        '%' => "0,0 6,10;0,8 2,8 2,10 0,10 0,8;4,0 6,0 6,2 4,2 4,0",
        '[' => "4,10 1,10 1,0 4,0",
        ']' => "2,10 5,10 5,0 2,0",
        '.' => "2.5,0 3.5,0 3.5,1 2.5,1 2.5,0",
        '_' => "0,0 6,0",
        '\'' => "3,10 3,7",
        _ => return None,
    })
}

/// Digits, `A`, `B`, `-` and space, drawn point by point.
fn fixed(c: char) -> Glyph {
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
                    .into_iter()
                    .map(|(x, y)| Vec2::new(x0 + x * height * aspect, origin.y + y * height))
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
        let all = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcxyz#[]._'- ?";
        for c in all.chars() {
            for stroke in glyph(c) {
                assert!(stroke.len() >= 2, "{c:?}: a stroke is at least a segment");
                for &(x, y) in &stroke {
                    assert!(
                        (0.0..=0.6).contains(&x) && (0.0..=1.0).contains(&y),
                        "{c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn letters_of_either_case_are_drawn_and_unknown_ones_are_boxes() {
        assert_eq!(glyph('t'), glyph('T'));
        assert_eq!(
            glyph('T'),
            [vec![(0.0, 1.0), (0.6, 1.0)], vec![(0.3, 1.0), (0.3, 0.0)]]
        );
        let boxed = glyph('?');
        assert_eq!(boxed, glyph('€'));
        assert_ne!(glyph('e'), boxed);
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
