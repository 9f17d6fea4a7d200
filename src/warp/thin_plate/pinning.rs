//! Constraints that leave a thin plate free to tilt. Bending energy does
//! not see affine displacements, and springs on one point (or on points
//! along one line) pin only some of them: the plate may then tilt about the
//! point or the line at no cost, the system is singular, and the solution
//! depends on where the solver starts (a warm start, a render at another
//! scale) rather than on the features.
//!
//! The missing affine modes are pinned by virtual springs that move as the
//! features' best similarity transform moves them: one point translates the
//! frame, one line carries it as Beier and Neely's single line pair does
//! (rotation and scale about the line). Placed inside the frame, they never
//! grow the node grid.

use crate::geom::{RectD, Vec2};

/// `pairs` (from, to), with virtual pairs appended when their `from` points
/// lie within `cell` of one point or of one line.
pub fn pin_free_modes(pairs: &[(Vec2, Vec2)], frame: RectD, cell: f64) -> Vec<(Vec2, Vec2)> {
    let mut out = pairs.to_vec();
    if pairs.is_empty() {
        return out;
    }
    let n = pairs.len() as f64;
    let c = pairs.iter().fold(Vec2::ZERO, |s, (p, _)| s + *p) / n;
    let c_to = pairs.iter().fold(Vec2::ZERO, |s, (_, q)| s + *q) / n;
    let spread = |dir: Vec2| {
        pairs
            .iter()
            .map(|(p, _)| (*p - c).dot(dir).abs())
            .fold(0.0, f64::max)
    };
    let u = principal_direction(pairs, c);
    if spread(u) < cell {
        // One point: every virtual point translates with it.
        let d = c_to - c;
        for axis in [Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)] {
            let p = c + axis * reach(c, axis, frame, cell);
            out.push((p, p + d));
        }
    } else if spread(u.perp()) < cell {
        // One line: one virtual point off it, carried by the similarity.
        let a = similarity(pairs, c, c_to);
        let normal = u.perp();
        let p = c + normal * reach(c, normal, frame, cell);
        out.push((p, c_to + rotate_scale(a, p - c)));
    }
    out
}

/// The direction along which the `from` points spread most (x when they
/// all coincide).
fn principal_direction(pairs: &[(Vec2, Vec2)], c: Vec2) -> Vec2 {
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (p, _) in pairs {
        let v = *p - c;
        sxx += v.x * v.x;
        sxy += v.x * v.y;
        syy += v.y * v.y;
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    Vec2::new(angle.cos(), angle.sin())
}

/// The least-squares rotation-and-scale `a` (as a complex number) with
/// `to − c_to ≈ a (from − c)`.
fn similarity(pairs: &[(Vec2, Vec2)], c: Vec2, c_to: Vec2) -> Vec2 {
    let (mut re, mut im, mut norm) = (0.0, 0.0, 0.0);
    for (p, q) in pairs {
        let (v, w) = (*p - c, *q - c_to);
        re += w.x * v.x + w.y * v.y;
        im += w.y * v.x - w.x * v.y;
        norm += v.length_squared();
    }
    Vec2::new(re / norm, im / norm)
}

fn rotate_scale(a: Vec2, v: Vec2) -> Vec2 {
    Vec2::new(a.x * v.x - a.y * v.y, a.x * v.y + a.y * v.x)
}

/// A signed distance from `c` along `dir` (or against it) that stays inside
/// `frame` and is as long as the frame allows, at least four cells.
fn reach(c: Vec2, dir: Vec2, frame: RectD, cell: f64) -> f64 {
    let room = |d: Vec2| {
        let along = |lo: f64, hi: f64, x: f64, dx: f64| {
            if dx > 1e-12 {
                (hi - x) / dx
            } else if dx < -1e-12 {
                (lo - x) / dx
            } else {
                f64::INFINITY
            }
        };
        along(frame.x1, frame.x2, c.x, d.x).min(along(frame.y1, frame.y2, c.y, d.y))
    };
    let (ahead, behind) = (room(dir), room(dir * -1.0));
    let (len, sign) = if ahead >= behind {
        (ahead, 1.0)
    } else {
        (behind, -1.0)
    };
    sign * len.clamp(4.0 * cell, f64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> RectD {
        RectD::new(0.0, 0.0, 96.0, 64.0)
    }

    #[test]
    fn spread_features_get_no_virtual_springs() {
        let pairs = [
            (Vec2::new(10.0, 10.0), Vec2::new(12.0, 10.0)),
            (Vec2::new(50.0, 12.0), Vec2::new(50.0, 14.0)),
            (Vec2::new(30.0, 40.0), Vec2::new(31.0, 41.0)),
        ];
        assert_eq!(pin_free_modes(&pairs, frame(), 4.0), pairs.to_vec());
    }

    #[test]
    fn one_point_translates_two_virtual_points_inside_the_frame() {
        let pairs = [(Vec2::new(20.0, 50.0), Vec2::new(23.0, 46.0))];
        let out = pin_free_modes(&pairs, frame(), 4.0);
        assert_eq!(out.len(), 3);
        for (p, q) in &out[1..] {
            assert!(frame().contains_point(*p), "{p:?} inside the frame");
            assert_eq!(*q - *p, Vec2::new(3.0, -4.0));
        }
        // Along x and along y, toward the farther border.
        assert_eq!(out[1].0, Vec2::new(96.0, 50.0));
        assert_eq!(out[2].0, Vec2::new(20.0, 0.0));
    }

    #[test]
    fn one_line_carries_a_point_off_it_by_its_rotation_and_scale() {
        // A horizontal line turned by 90° and doubled about its centre
        // (40, 20): a point 44 above the centre lands 88 to its left.
        let pairs: Vec<_> = (0..=4)
            .map(|k| {
                let x = 30.0 + 5.0 * k as f64;
                let v = Vec2::new(x - 40.0, 0.0);
                (
                    Vec2::new(x, 20.0),
                    Vec2::new(40.0, 20.0) + Vec2::new(0.0, 2.0 * v.x),
                )
            })
            .collect();
        let out = pin_free_modes(&pairs, frame(), 4.0);
        assert_eq!(out.len(), pairs.len() + 1);
        let (p, q) = out[pairs.len()];
        assert!((p - Vec2::new(40.0, 64.0)).length() < 1e-9, "{p:?}");
        assert!((q - Vec2::new(40.0 - 88.0, 20.0)).length() < 1e-9, "{q:?}");
    }

    #[test]
    fn a_plate_on_one_line_is_the_same_from_any_start() {
        use crate::warp::thin_plate::{ThinPlate, ThinPlateSettings};
        // A horizontal line whose ends move apart vertically: without the
        // virtual spring the plate's tilt about the line was free, and a
        // warm start from another plate kept whatever tilt it had.
        let pairs: Vec<_> = (0..=8)
            .map(|k| {
                let x = 60.0 + 2.5 * k as f64;
                (
                    Vec2::new(x, 50.0),
                    Vec2::new(x + 1.0, 49.0 + 0.3 * k as f64),
                )
            })
            .collect();
        let s = ThinPlateSettings::default();
        let cold = ThinPlate::solve(&pairs, frame(), &s, None);
        // Another plate on the same grid, tilted about the line.
        let mut other = cold.clone();
        let nx = other.nodes.nx;
        for (i, d) in other.nodes.disp.iter_mut().enumerate() {
            *d = Vec2::new(0.0, 0.5 * ((i / nx) as f64 - 12.5));
        }
        let warm = ThinPlate::solve(&pairs, frame(), &s, Some(&other));
        let worst = cold
            .nodes
            .disp
            .iter()
            .zip(&warm.nodes.disp)
            .map(|(a, b)| (*a - *b).length())
            .fold(0.0, f64::max);
        assert!(worst < 0.05, "cold and warm plates differ by {worst} px");
    }
}
