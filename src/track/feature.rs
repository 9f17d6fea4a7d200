//! One side (A or B) of one feature followed through a sweep of frames.
//!
//! Points, polylines and curves: each control point is tracked on its own.
//! A line's ends follow their own matches where those can be trusted (a
//! corner, matched well): a motion that bends along the line moves each end
//! its own way. Elsewhere the line is tracked along its whole length:
//! patches spaced along it are tracked, and one affine motion is fitted to
//! all of them, each patch weighted by how firmly its texture fixes each
//! direction (a patch on the line's edge fixes only the across-edge
//! position; one on a corner fixes both) and pulled towards its own local
//! affine motion; the line's ends move by that motion. A line is then
//! carried by the picture along it, not by the two pixels under its ends,
//! which often lie where there is little to see.

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
    /// Lines: whether each end's own patch was found in some frame so far.
    ends_seen: [bool; 2],
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
            ends_seen: [false; 2],
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
        let mut side = SideEstimate {
            points: Vec::new(),
            confidence: Vec::new(),
            lost: Vec::new(),
        };
        // The ends are the first and last samples.
        let last = self.samples.len() - 1;
        for (n, (key, k)) in self.key_points.iter().zip([0, last]).enumerate() {
            let end = End {
                own: &found[k],
                information: self.samples[k].1.information(),
                seen: self.ends_seen[n],
                fit: motion(*key),
                line_confidence: confidence,
            }
            .decide();
            self.ends_seen[n] |= !found[k].lost;
            side.points.push(end.at);
            side.confidence.push(end.confidence);
            side.lost.push(lost || end.doubtful);
        }
        side
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

/// One end of a line in one frame: its own match, and where the line's
/// fit puts it.
struct End<'a> {
    own: &'a Estimate,
    /// How firmly the end's own patch fixes each direction, `[xx, xy, yy]`.
    information: [f64; 3],
    /// Whether the end's own match has found it in an earlier frame of the
    /// sweep: lost now, it is hidden or changed, and the fit there is a
    /// guess. (An end on flat ground is never found: the fit is all there is.)
    seen: bool,
    fit: Vec2,
    line_confidence: f64,
}

/// Where an end is reported, how surely, and whether it is in doubt.
struct EndEstimate {
    at: Vec2,
    confidence: f64,
    doubtful: bool,
}

/// The smaller and larger eigenvalues of a patch's information `[xx, xy, yy]`.
fn eigen([xx, xy, yy]: [f64; 3]) -> (f64, f64) {
    let (mean, spread) = (0.5 * (xx + yy), (0.25 * (xx - yy).powi(2) + xy * xy).sqrt());
    (mean - spread, mean + spread)
}

/// An end's own match is taken over the line's fit when its patch fixes
/// both directions (the smaller eigenvalue of its information at least
/// this share of the larger: a corner, not an edge)...
const CORNER_RATIO: f64 = 0.1;
/// ...and it matches the key at least this well.
const OWN_CONFIDENCE: f64 = 0.9;
/// An end reported from the fit is in doubt when its own match disagrees by
/// more than this, pixels, in the directions its patch fixes.
const DISAGREEMENT_PX: f64 = 0.75;

impl End<'_> {
    /// Each end follows its own local motion where its patch can say
    /// (under a motion that bends along the line, a whole-line fit slides
    /// the ends off their corners); elsewhere the fit, the only evidence on
    /// flat ground. The fit's answer is in doubt where the end's own match
    /// contradicts it in a direction its texture fixes, or where an end
    /// found before is lost (hidden): reported, never passed off as found.
    fn decide(&self) -> EndEstimate {
        let [xx, xy, yy] = self.information;
        let (small, large) = eigen(self.information);
        let own = self.own;
        let corner = large > 0.0 && small >= CORNER_RATIO * large;
        if corner && !own.lost && own.confidence >= OWN_CONFIDENCE {
            return EndEstimate {
                at: own.at,
                confidence: own.confidence,
                doubtful: false,
            };
        }
        // The gap along the directions the patch fixes: an edge's across
        // it, a corner's both, a flat patch's none.
        let d = own.at - self.fit;
        let fixed = if large > 0.0 {
            ((xx * d.x * d.x + 2.0 * xy * d.x * d.y + yy * d.y * d.y) / large).sqrt()
        } else {
            0.0
        };
        let doubtful = if own.lost {
            self.seen
        } else {
            fixed > DISAGREEMENT_PX
        };
        EndEstimate {
            at: self.fit,
            confidence: if doubtful {
                self.line_confidence.min(own.confidence) * 0.5
            } else {
                self.line_confidence
            },
            doubtful,
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
