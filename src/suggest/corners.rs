//! Where an artist would put a point: corners, the places a patch fixes in
//! both directions. Shi and Tomasi's measure (the smaller eigenvalue of the
//! structure tensor over a window), kept where it is a local maximum, then
//! spread over the frame cell by cell so suggestions cover the picture
//! rather than crowd its busiest part.

use crate::geom::Vec2;
use crate::track::Grey;

/// One corner: where, and how firmly its window fixes both directions (the
/// structure tensor's smaller eigenvalue, mean per pixel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Where (pixel centre).
    pub at: Vec2,
    /// The structure tensor's smaller eigenvalue, mean per pixel.
    pub strength: f64,
}

/// Half the side of the window the structure tensor is summed over.
const WINDOW: i32 = 3;

/// The smallest mean eigenvalue counted as structure: a gradient of about
/// one 8-bit code value per pixel in both directions. A blank plate has
/// none; grain alone is smoothed away by the halving the corners are
/// found on.
pub const MIN_STRENGTH: f64 = 2e-5;

/// The corners of `grey`, strongest first: local maxima of the measure at
/// least [`MIN_STRENGTH`], at most one per `cell` × `cell` pixels, and
/// `margin` pixels clear of the edges.
pub fn corners(grey: &Grey, cell: f64, margin: f64) -> Vec<Corner> {
    let b = grey.bounds;
    let (w, h) = (b.width(), b.height());
    if w < 2 * WINDOW as usize + 3 || h < 2 * WINDOW as usize + 3 {
        return Vec::new();
    }
    let measure = min_eigenvalues(grey);
    let at = |i: i32, j: i32| measure[j as usize * w + i as usize];
    let mut found = Vec::new();
    let reach = WINDOW + 1;
    for j in reach..h as i32 - reach {
        for i in reach..w as i32 - reach {
            let m = at(i, j);
            if m < MIN_STRENGTH {
                continue;
            }
            let peak = (-1..=1)
                .flat_map(|dj| (-1..=1).map(move |di| (di, dj)))
                .filter(|&d| d != (0, 0))
                .all(|(di, dj)| at(i + di, j + dj) <= m);
            let p = Vec2::new((b.x1 + i) as f64 + 0.5, (b.y1 + j) as f64 + 0.5);
            let inside = p.x - b.x1 as f64 >= margin
                && b.x2 as f64 - p.x >= margin
                && p.y - b.y1 as f64 >= margin
                && b.y2 as f64 - p.y >= margin;
            if peak && inside {
                found.push(Corner { at: p, strength: m });
            }
        }
    }
    spread(found, cell)
}

/// The strongest corner of each `cell` × `cell` square, strongest first.
fn spread(mut corners: Vec<Corner>, cell: f64) -> Vec<Corner> {
    corners.sort_by(|p, q| q.strength.total_cmp(&p.strength));
    let mut taken = std::collections::HashSet::new();
    corners
        .into_iter()
        .filter(|c| {
            let key = (
                (c.at.x / cell).floor() as i64,
                (c.at.y / cell).floor() as i64,
            );
            taken.insert(key)
        })
        .collect()
}

/// The structure tensor's smaller eigenvalue at every pixel, mean over the
/// window: gradients by central differences, summed over the window with
/// running sums.
fn min_eigenvalues(grey: &Grey) -> Vec<f64> {
    let b = grey.bounds;
    let (w, h) = (b.width(), b.height());
    let value = |i: i32, j: i32| {
        let p = Vec2::new((b.x1 + i) as f64 + 0.5, (b.y1 + j) as f64 + 0.5);
        grey.sample(p) as f64
    };
    // xx, xy, yy per pixel.
    let mut tensor = vec![[0f64; 3]; w * h];
    for j in 0..h as i32 {
        for i in 0..w as i32 {
            let gx = 0.5 * (value(i + 1, j) - value(i - 1, j));
            let gy = 0.5 * (value(i, j + 1) - value(i, j - 1));
            tensor[j as usize * w + i as usize] = [gx * gx, gx * gy, gy * gy];
        }
    }
    let summed = box_sum(&box_sum(&tensor, w, h, true), w, h, false);
    let n = ((2 * WINDOW + 1) * (2 * WINDOW + 1)) as f64;
    summed
        .iter()
        .map(|[a, b, c]| {
            let (a, b, c) = (a / n, b / n, c / n);
            0.5 * (a + c) - (0.25 * (a - c) * (a - c) + b * b).sqrt()
        })
        .collect()
}

/// Sums over `2 WINDOW + 1` neighbours along rows (`across`) or columns,
/// edge values held.
fn box_sum(values: &[[f64; 3]], w: usize, h: usize, across: bool) -> Vec<[f64; 3]> {
    let mut out = vec![[0f64; 3]; w * h];
    let (lines, len) = if across { (h, w) } else { (w, h) };
    let index = |line: usize, k: usize| if across { line * w + k } else { k * w + line };
    for line in 0..lines {
        let at = |k: i32| values[index(line, k.clamp(0, len as i32 - 1) as usize)];
        let mut sum = [0f64; 3];
        for k in -WINDOW..=WINDOW {
            add(&mut sum, at(k), 1.0);
        }
        for k in 0..len as i32 {
            out[index(line, k as usize)] = sum;
            add(&mut sum, at(k + WINDOW + 1), 1.0);
            add(&mut sum, at(k - WINDOW), -1.0);
        }
    }
    out
}

fn add(sum: &mut [f64; 3], v: [f64; 3], sign: f64) {
    for (s, v) in sum.iter_mut().zip(v) {
        *s += sign * v;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::RectI;

    /// A white square on black: its four corners, and nothing on its
    /// straight edges or in the flat.
    #[test]
    fn a_squares_four_corners_are_found_and_its_edges_are_not() {
        let grey = Grey::from_fn(RectI::from_size(64, 64), |i, j| {
            ((16..48).contains(&i) && (16..48).contains(&j)) as u8 as f32
        });
        let found = corners(&grey, 8.0, 4.0);
        assert_eq!(found.len(), 4, "{found:?}");
        for c in &found {
            let near = [16.0, 48.0].iter().any(|&x| (c.at.x - x).abs() <= 3.0)
                && [16.0, 48.0].iter().any(|&y| (c.at.y - y).abs() <= 3.0);
            assert!(near, "{c:?} is not at a corner");
        }
    }

    #[test]
    fn a_blank_plate_has_no_corners() {
        let grey = Grey::from_fn(RectI::from_size(64, 48), |_, _| 0.5);
        assert!(corners(&grey, 8.0, 4.0).is_empty());
    }
}
