//! A reverse map run backwards: the output point where a warp shows a
//! given source point. Motion vectors need it (where a source point is
//! shown in the next frame), and no warp here has a closed-form inverse.

use super::Warp;
use crate::geom::Vec2;

/// Newton stops when the point maps this close to its target (canonical
/// pixels): far under what a vector's float holds at any sensible size.
const TOLERANCE: f64 = 1e-6;
const MAX_STEPS: usize = 30;
/// The step of the central differences the Jacobian is measured with.
const STEP: f64 = 0.25;

/// The output point `q` with `warp.map(q) = target`, searched from `start`
/// by Newton's method with the Jacobian measured at each step; `None`
/// where it does not converge (the target outside the warp's reach, or a
/// fold).
pub fn invert(warp: &dyn Warp, target: Vec2, start: Vec2) -> Option<Vec2> {
    let mut q = start;
    for _ in 0..MAX_STEPS {
        let e = target - warp.map(q);
        if e.length() <= TOLERANCE {
            return Some(q);
        }
        let dx = (warp.map(q + Vec2::new(STEP, 0.0)) - warp.map(q - Vec2::new(STEP, 0.0)))
            * (0.5 / STEP);
        let dy = (warp.map(q + Vec2::new(0.0, STEP)) - warp.map(q - Vec2::new(0.0, STEP)))
            * (0.5 / STEP);
        let det = dx.x * dy.y - dx.y * dy.x;
        if det.abs() < 1e-12 || !det.is_finite() {
            return None;
        }
        let step = Vec2::new(
            (e.x * dy.y - e.y * dy.x) / det,
            (dx.x * e.y - dx.y * e.x) / det,
        );
        q += step;
        if !q.is_finite() {
            return None;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Swirl;
    impl Warp for Swirl {
        fn map(&self, p: Vec2) -> Vec2 {
            let a = 0.002 * (p.x + p.y);
            Vec2::new(
                p.x * a.cos() - p.y * a.sin() + 3.0,
                p.x * a.sin() + p.y * a.cos() - 2.0,
            )
        }
    }

    /// A smooth non-linear warp run backwards: the point found maps onto
    /// the target within the tolerance.
    #[test]
    fn the_point_found_maps_onto_the_target() {
        for target in [Vec2::new(40.0, 60.0), Vec2::new(120.0, 10.0)] {
            let q = invert(&Swirl, target, target).expect("converges");
            assert!(Swirl.map(q).distance(target) <= TOLERANCE, "{q:?}");
        }
    }
}
