//! The template tracker: a patch of the keyed frame found again in another
//! frame under an affine warp and a gain and offset of brightness.
//!
//! Inverse compositional alignment (Baker & Matthews, "Lucas-Kanade 20 Years
//! On", §3.2): the template's gradients and Hessian are computed once, at the
//! key, so each iteration only samples the frame. Brightness is fitted in
//! closed form each iteration (`I ≈ αT + β`), which makes the match blind to
//! flicker; the geometric step is then the usual one for the model `αT`.
//! Coarse levels solve translation only (a wide patch there spans more than
//! an affine map describes well); the two finest solve the full affine.

use crate::geom::Vec2;

use super::grey::Pyramid;
use super::linear::solve;

/// How the tracker looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackSettings {
    /// Half the patch side, in pixels of every level (the patch is
    /// `2r + 1` square).
    pub radius: usize,
    /// Pyramid levels used at most.
    pub levels: usize,
    /// Iterations per level at most.
    pub iterations: usize,
    /// The smallest normalised correlation with the key's patch still
    /// counted as found.
    pub min_correlation: f64,
}

impl Default for TrackSettings {
    fn default() -> Self {
        TrackSettings {
            radius: 12,
            levels: 3,
            iterations: 30,
            min_correlation: 0.75,
        }
    }
}

/// Where a template lies in a frame: offset `d` from its centre (pixels of
/// any level) lands at `c + M d` (`c` in level-0 canonical coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// The centre.
    pub c: Vec2,
    /// The linear part, row-major `[m00, m01, m10, m11]`.
    pub m: [f64; 4],
}

impl Affine {
    /// The identity at `c`.
    pub fn at(c: Vec2) -> Affine {
        Affine {
            c,
            m: [1.0, 0.0, 0.0, 1.0],
        }
    }

    fn apply(&self, c: Vec2, d: Vec2) -> Vec2 {
        Vec2::new(
            c.x + self.m[0] * d.x + self.m[1] * d.y,
            c.y + self.m[2] * d.x + self.m[3] * d.y,
        )
    }

    /// `M d`.
    pub fn linear(&self, d: Vec2) -> Vec2 {
        self.apply(Vec2::ZERO, d)
    }

    fn det(&self) -> f64 {
        self.m[0] * self.m[3] - self.m[1] * self.m[2]
    }

    /// Still a plausible patch motion: neither folded, nor squashed or
    /// grown more than threefold.
    fn plausible(&self) -> bool {
        let det = self.det();
        det.is_finite() && (1.0 / 3.0..=3.0).contains(&det) && self.m.iter().all(|v| v.abs() < 3.0)
    }
}

/// One level of a template.
struct Level {
    values: Vec<f32>,
    weights: Vec<f32>,
    /// Steepest-descent images: the template gradient times the warp's
    /// Jacobian at identity, for (cx, cy, m00 - 1, m01, m10, m11 - 1).
    descent: Vec<[f64; 6]>,
    /// `Σ w SDᵀ SD`, lightly damped so a patch on a straight edge still
    /// gives a step (its along-edge motion then simply stays put).
    hessian: [[f64; 6]; 6],
    mean: f64,
    variance: f64,
}

/// A patch of the keyed frame at every pyramid level.
pub struct Template {
    levels: Vec<Level>,
    radius: i32,
    /// `Σ w ∇T ∇Tᵀ` at level 0, `[xx, xy, yy]`: how firmly the patch fixes
    /// each direction of translation (a line fit weighs samples by it).
    pub information: [f64; 3],
}

/// A template found in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// Where.
    pub warp: Affine,
    /// Weighted normalised correlation with the key's patch, `[-1, 1]`.
    pub correlation: f64,
    /// Whether it counts as found: correlated enough, a plausible warp, the
    /// patch inside the frame and not flat.
    pub ok: bool,
}

fn offsets(r: i32) -> impl Iterator<Item = Vec2> {
    (-r..=r).flat_map(move |y| (-r..=r).map(move |x| Vec2::new(x as f64, y as f64)))
}

impl Template {
    /// The patch around `at` (level-0 canonical) in `key`, at each of its
    /// levels up to `settings.levels`.
    pub fn new(key: &Pyramid, at: Vec2, settings: &TrackSettings) -> Template {
        let r = settings.radius as i32;
        let sigma = 0.6 * r as f64;
        let mut levels = Vec::new();
        let mut information = [0.0; 3];
        for (k, grey) in key.levels.iter().take(settings.levels).enumerate() {
            let c = at * (0.5f64).powi(k as i32);
            let v = |d: Vec2| grey.sample(c + d) as f64;
            let mut level = Level {
                values: Vec::new(),
                weights: Vec::new(),
                descent: Vec::new(),
                hessian: [[0.0; 6]; 6],
                mean: 0.0,
                variance: 0.0,
            };
            let mut wsum = 0.0;
            for d in offsets(r) {
                let w = (-(d.length_squared()) / (2.0 * sigma * sigma)).exp();
                let gx = 0.5 * (v(d + Vec2::new(1.0, 0.0)) - v(d - Vec2::new(1.0, 0.0)));
                let gy = 0.5 * (v(d + Vec2::new(0.0, 1.0)) - v(d - Vec2::new(0.0, 1.0)));
                let sd = [gx, gy, gx * d.x, gx * d.y, gy * d.x, gy * d.y];
                for (i, row) in level.hessian.iter_mut().enumerate() {
                    for (j, h) in row.iter_mut().enumerate() {
                        *h += w * sd[i] * sd[j];
                    }
                }
                if k == 0 {
                    information[0] += w * gx * gx;
                    information[1] += w * gx * gy;
                    information[2] += w * gy * gy;
                }
                let t = v(d);
                level.mean += w * t;
                wsum += w;
                level.values.push(t as f32);
                level.weights.push(w as f32);
                level.descent.push(sd);
            }
            level.mean /= wsum;
            level.variance = level
                .values
                .iter()
                .zip(&level.weights)
                .map(|(&t, &w)| w as f64 * (t as f64 - level.mean).powi(2))
                .sum::<f64>()
                / wsum;
            let trace: f64 = (0..6).map(|i| level.hessian[i][i]).sum();
            for i in 0..6 {
                level.hessian[i][i] += 1e-6 * trace + 1e-12;
            }
            levels.push(level);
        }
        Template {
            levels,
            radius: r,
            information,
        }
    }

    /// The template found in `frame`, starting from `guess`.
    pub fn find(&self, frame: &Pyramid, guess: Affine, settings: &TrackSettings) -> Found {
        let top = self.levels.len().min(frame.levels.len());
        let mut warp = guess;
        for k in (0..top).rev() {
            let affine = k < 2;
            let before = warp;
            if !self.align(frame, k, &mut warp, affine, settings.iterations) {
                if k > 0 {
                    // A coarse level can fail where a fine one does not (a
                    // patch wider than the structure, or hanging over the
                    // frame's edge): the finer levels start from before it.
                    warp = before;
                    continue;
                }
                return Found {
                    warp,
                    correlation: -1.0,
                    ok: false,
                };
            }
        }
        let correlation = self.correlation(frame, &warp);
        // A centre off the frame is a feature that left it: its patch there
        // is only the edge pixels repeated.
        let inside = frame.levels[0].contains(warp.c);
        let ok = correlation >= settings.min_correlation && warp.plausible() && inside;
        Found {
            warp,
            correlation,
            ok,
        }
    }

    /// Iterates at level `k`; false when the warp runs away or the frame's
    /// patch is flat (nothing to align).
    fn align(&self, frame: &Pyramid, k: usize, warp: &mut Affine, affine: bool, n: usize) -> bool {
        let level = &self.levels[k];
        let grey = &frame.levels[k];
        let scale = (0.5f64).powi(k as i32);
        for _ in 0..n {
            let c = warp.c * scale;
            let samples: Vec<f64> = offsets(self.radius)
                .map(|d| grey.sample(warp.apply(c, d)) as f64)
                .collect();
            let Some((gain, offset)) = brightness(level, &samples) else {
                return false;
            };
            let mut b = [0.0; 6];
            for ((sd, &t), (&w, &i)) in level
                .descent
                .iter()
                .zip(&level.values)
                .zip(level.weights.iter().zip(&samples))
            {
                let e = w as f64 * (i - gain * t as f64 - offset) / gain;
                for (bj, s) in b.iter_mut().zip(sd) {
                    *bj += s * e;
                }
            }
            let step = if affine {
                solve(level.hessian, b)
            } else {
                let h = [
                    [level.hessian[0][0], level.hessian[0][1]],
                    [level.hessian[1][0], level.hessian[1][1]],
                ];
                solve(h, [b[0], b[1]]).map(|[x, y]| [x, y, 0.0, 0.0, 0.0, 0.0])
            };
            let Some(p) = step else { return false };
            // W ← W ∘ W(Δp)⁻¹.
            let d = [1.0 + p[2], p[3], p[4], 1.0 + p[5]];
            let det = d[0] * d[3] - d[1] * d[2];
            if det.abs() < 1e-6 {
                return false;
            }
            let inv = [d[3] / det, -d[1] / det, -d[2] / det, d[0] / det];
            let m = warp.m;
            warp.m = [
                m[0] * inv[0] + m[1] * inv[2],
                m[0] * inv[1] + m[1] * inv[3],
                m[2] * inv[0] + m[3] * inv[2],
                m[2] * inv[1] + m[3] * inv[3],
            ];
            let shift = warp.linear(Vec2::new(p[0], p[1]));
            warp.c = (c - shift) * (1.0 / scale);
            if !(warp.c.is_finite() && warp.plausible()) {
                return false;
            }
            // Converged when the step moves no part of the patch by more
            // than a hundredth of a pixel (coarse levels: a tenth; the
            // finest level refines).
            let reach = p[2..].iter().fold(0.0f64, |m, v| m.max(v.abs())) * self.radius as f64;
            let tolerance = if k == 0 { 0.01 } else { 0.1 };
            let small = p[0].abs().max(p[1].abs()) + reach < tolerance;
            if small {
                break;
            }
        }
        true
    }

    /// Weighted normalised correlation of the frame's patch under `warp`
    /// with the key's, at level 0.
    pub fn correlation(&self, frame: &Pyramid, warp: &Affine) -> f64 {
        let level = &self.levels[0];
        let grey = &frame.levels[0];
        let samples: Vec<f64> = offsets(self.radius)
            .map(|d| grey.sample(warp.apply(warp.c, d)) as f64)
            .collect();
        let (wsum, mean) = weighted_mean(level, &samples);
        let (mut cov, mut var) = (0.0, 0.0);
        for ((&t, &w), &i) in level.values.iter().zip(&level.weights).zip(&samples) {
            cov += w as f64 * (t as f64 - level.mean) * (i - mean);
            var += w as f64 * (i - mean).powi(2);
        }
        let denom = (var / wsum * level.variance).sqrt();
        if denom > 1e-12 {
            cov / wsum / denom
        } else {
            0.0
        }
    }
}

fn weighted_mean(level: &Level, samples: &[f64]) -> (f64, f64) {
    let wsum: f64 = level.weights.iter().map(|&w| w as f64).sum();
    let mean = level
        .weights
        .iter()
        .zip(samples)
        .map(|(&w, &i)| w as f64 * i)
        .sum::<f64>()
        / wsum;
    (wsum, mean)
}

/// `(α, β)` of the weighted least-squares fit `I ≈ αT + β`; `None` when
/// either patch is flat or the fit inverts the contrast.
fn brightness(level: &Level, samples: &[f64]) -> Option<(f64, f64)> {
    let (wsum, mean) = weighted_mean(level, samples);
    let cov = level
        .values
        .iter()
        .zip(&level.weights)
        .zip(samples)
        .map(|((&t, &w), &i)| w as f64 * (t as f64 - level.mean) * (i - mean))
        .sum::<f64>()
        / wsum;
    if level.variance < 1e-10 {
        return None;
    }
    let gain = cov / level.variance;
    (gain > 0.05).then_some((gain, mean - gain * level.mean))
}
