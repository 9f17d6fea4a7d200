//! One side (A or B) of one feature followed through a sweep of frames.
//!
//! Points, polylines and curves: each control point is tracked on its own.
//! A line is tracked along its whole length: patches spaced along it are
//! tracked, and one affine motion is fitted to all of them, each patch
//! weighted by how firmly its texture fixes each direction (a patch on the
//! line's edge fixes only the across-edge position; one on a corner fixes
//! both) and pulled towards its own local affine motion; the line's ends
//! move by that motion. A line is then carried by the picture along it, not
//! by the two pixels under its ends, which often lie where there is little
//! to see.

use crate::features::FeatureKind;
use crate::geom::Vec2;

use super::grey::Pyramid;
use super::linear::solve;
use super::point::{Estimate, PointTracker};
use super::template::TrackSettings;

/// One side of a feature in one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SideEstimate {
    /// Its control points (the best guess where lost).
    pub points: Vec<Vec2>,
    /// Per point, `[0, 1]`.
    pub confidence: Vec<f64>,
    /// Per point: not found in this frame.
    pub lost: Vec<bool>,
}

/// One side of a feature followed away from its key.
pub struct SideTracker {
    kind: FeatureKind,
    key_points: Vec<Vec2>,
    /// Key positions of the tracked patches and their trackers.
    samples: Vec<(Vec2, PointTracker)>,
}

/// Patches along a line: about one per patch radius, ends included.
const MAX_LINE_SAMPLES: usize = 9;

impl SideTracker {
    /// Starts from `points` (the side's control points) in the key frame.
    pub fn new(
        kind: FeatureKind,
        points: &[Vec2],
        key: &Pyramid,
        settings: &TrackSettings,
    ) -> SideTracker {
        let radius = settings.radius as f64;
        let at: Vec<Vec2> = match (kind, points) {
            (FeatureKind::Line, &[p, q]) => {
                let n = ((p.distance(q) / radius).ceil() as usize + 1).clamp(2, MAX_LINE_SAMPLES);
                (0..n)
                    .map(|i| p.lerp(q, i as f64 / (n - 1) as f64))
                    .collect()
            }
            _ => points.to_vec(),
        };
        SideTracker {
            kind,
            key_points: points.to_vec(),
            samples: at
                .into_iter()
                .map(|p| (p, PointTracker::new(key, p, settings)))
                .collect(),
        }
    }

    /// The side in the next frame of the sweep.
    pub fn step(&mut self, frame: &Pyramid, settings: &TrackSettings) -> SideEstimate {
        let found: Vec<Estimate> = self
            .samples
            .iter_mut()
            .map(|(_, t)| t.step(frame, settings))
            .collect();
        if self.kind != FeatureKind::Line {
            return SideEstimate {
                points: found.iter().map(|e| e.at).collect(),
                confidence: found.iter().map(|e| e.confidence).collect(),
                lost: found.iter().map(|e| e.lost).collect(),
            };
        }
        let good = found.iter().filter(|e| !e.lost).count();
        let lost = 2 * good < found.len() || good < 2.min(found.len());
        let used: Vec<bool> = found.iter().map(|e| lost || !e.lost).collect();
        let motion = self.fit(&found, &used);
        let confidence = {
            let c: Vec<f64> = found
                .iter()
                .zip(&used)
                .filter(|(_, u)| **u)
                .map(|(e, _)| e.confidence)
                .collect();
            c.iter().sum::<f64>() / c.len().max(1) as f64
        };
        SideEstimate {
            points: self.key_points.iter().map(|&k| motion(k)).collect(),
            confidence: vec![confidence; 2],
            lost: vec![lost; 2],
        }
    }

    /// The affine motion `k ↦ t + G (k - k̄)` that best explains the used
    /// samples (see the module's comment). Only `G` along the line reaches
    /// the ends, so the samples' positions decide it; a faint pull towards
    /// their own affine motions only keeps the system regular. Samples that
    /// disagree with the rest (a patch half on texture can lock onto a
    /// wrong stretch and still correlate) are down-weighted by iterating
    /// with Cauchy weights on their misfit.
    fn fit(&self, found: &[Estimate], used: &[bool]) -> impl Fn(Vec2) -> Vec2 {
        let picked: Vec<(Vec2, &Estimate, [f64; 3])> = self
            .samples
            .iter()
            .zip(found)
            .zip(used)
            .filter(|(_, u)| **u)
            .map(|(((k, t), e), _)| (*k, e, t.information()))
            .collect();
        let n = picked.len().max(1) as f64;
        let centre = picked.iter().fold(Vec2::ZERO, |s, (k, _, _)| s + *k) * (1.0 / n);
        let mean_shift = picked
            .iter()
            .fold(Vec2::ZERO, |s, (k, e, _)| s + (e.at - *k))
            * (1.0 / n);
        let apply = move |q: &[f64; 6], k: Vec2| {
            let d = k - centre;
            Vec2::new(
                q[0] + q[2] * d.x + q[3] * d.y,
                q[1] + q[4] * d.x + q[5] * d.y,
            )
        };
        let mut robust = vec![1.0; picked.len()];
        let mut q = None;
        for _ in 0..6 {
            q = solve_motion(&picked, &robust, centre);
            let Some(fit) = &q else { break };
            for ((k, e, _), r) in picked.iter().zip(robust.iter_mut()) {
                let misfit = apply(fit, *k).distance(e.at) / MISFIT_PX;
                *r = 1.0 / (1.0 + misfit * misfit);
            }
        }
        move |k: Vec2| match &q {
            Some(q) => apply(q, k),
            None => k + mean_shift,
        }
    }
}

/// The scale of the Cauchy weights on a sample's misfit, pixels.
const MISFIT_PX: f64 = 0.5;

/// The weighted least-squares motion `(t, G)` of the samples.
fn solve_motion(
    picked: &[(Vec2, &Estimate, [f64; 3])],
    robust: &[f64],
    centre: Vec2,
) -> Option<[f64; 6]> {
    let mut a = [[0.0; 6]; 6];
    let mut b = [0.0; 6];
    for ((k, e, info), r) in picked.iter().zip(robust) {
        let w = e.confidence.max(0.05) * r;
        // A little isotropic information, so motion along a plain edge
        // defaults to that of the rest rather than to anything.
        let iso = 1e-3 * (info[0] + info[2]);
        let s = [
            [w * (info[0] + iso), w * info[1]],
            [w * info[1], w * (info[2] + iso)],
        ];
        let d = *k - centre;
        let rows = [
            [1.0, 0.0, d.x, d.y, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0, d.x, d.y],
        ];
        let target = [e.at.x, e.at.y];
        for i in 0..6 {
            for r in 0..2 {
                for c in 0..2 {
                    let sj = rows[r][i] * s[r][c];
                    b[i] += sj * target[c];
                    for (j, aij) in a[i].iter_mut().enumerate() {
                        *aij += sj * rows[c][j];
                    }
                }
            }
        }
        let lambda = 1e-3 * w * (info[0] + info[2]);
        for (j, m) in e.warp.m.iter().enumerate() {
            a[2 + j][2 + j] += lambda;
            b[2 + j] += lambda * m;
        }
    }
    solve(a, b)
}
