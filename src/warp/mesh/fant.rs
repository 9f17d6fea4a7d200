//! Fant's 1-D resampling (seed 001, `resample`): linear interpolation where a
//! line is magnified, box filtering (unweighted averaging) where it is
//! minified, so squeezed regions average instead of aliasing.
//!
//! Our formulation: output pixel `k` has the preimage `[u0, u1]` in input
//! pixel units (input pixel `i` covers `[i, i + 1]`). Its value is the mean of
//! the piecewise-constant input over a box of width `max(u1 − u0, 1)` centred
//! on the preimage. A box of width one is exactly linear interpolation between
//! pixel centres, and a wider box is the area average, so one rule covers
//! both cases, is continuous between them, leaves the identity map exact (no
//! blur) and conserves a row's mean under minification. The listing's
//! per-segment accumulation approximates the same integral and is 8-bit only.

use crate::image::EdgeMode;

/// Inverts a forward map sampled at the input pixel edges (`forward[i]` is
/// where input edge `i` lands) at the output edges `x0 + k`, `k = 0..out.len()`.
/// Folds (decreasing stretches) are skipped, as the listing's walk does; past
/// both ends the map continues with slope one.
pub fn invert(forward: &[f64], x0: f64, out: &mut [f64]) {
    let n = forward.len() - 1;
    let (first, last) = (forward[0], forward[n]);
    let mut i = 0;
    for (k, u) in out.iter_mut().enumerate() {
        let x = x0 + k as f64;
        if x <= first {
            *u = x - first;
            continue;
        }
        if x >= last {
            *u = n as f64 + (x - last);
            continue;
        }
        // `x` grows with k, so the segment holding it only moves right.
        while i < n && forward[i + 1] <= x {
            i += 1;
        }
        // forward[i] <= x < forward[i + 1] unless an earlier fold overshot.
        let (a, b) = (forward[i], forward[i + 1]);
        *u = if b > a {
            i as f64 + ((x - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            i as f64
        };
    }
}

/// The value of the output pixel whose preimage is `[u0, u1]` (in either
/// order), reading input pixel `i` of `n` through `read` and the edge mode
/// beyond them.
#[inline]
pub fn sample(
    u0: f64,
    u1: f64,
    n: usize,
    edge: EdgeMode,
    read: impl Fn(usize) -> [f32; 4],
) -> [f32; 4] {
    let (lo, hi) = if u0 <= u1 { (u0, u1) } else { (u1, u0) };
    let centre = 0.5 * (lo + hi);
    let half = (0.5 * (hi - lo)).max(0.5);
    let (a, b) = (centre - half, centre + half);
    let mut acc = [0f32; 4];
    if !(a.is_finite() && b.is_finite()) {
        return acc;
    }
    // A preimage longer than the whole line repeats it (mirror) or its end
    // (clamp); clip the loop to a bounded number of taps.
    let first = a.floor();
    let count = ((b - first).ceil() as i64).clamp(1, 4 * n as i64 + 4);
    for k in 0..count {
        let i = first + k as f64;
        let w = (b.min(i + 1.0) - a.max(i)) as f32;
        if w <= 0.0 {
            continue;
        }
        let Ok(idx) = i32::try_from(i as i64) else {
            continue;
        };
        if let Some(idx) = edge.resolve(idx, 0, n as i32) {
            let px = read(idx as usize);
            for c in 0..4 {
                acc[c] += w * px[c];
            }
        }
    }
    let inv = (1.0 / (b - a)) as f32;
    acc.map(|v| v * inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(n: usize) -> Vec<[f32; 4]> {
        (0..n)
            .map(|i| {
                let v = ((i * 37 % 11) as f32) * 0.25 - 0.7;
                [v, 2.0 * v, (i as f32).sin(), 1.0]
            })
            .collect()
    }

    fn resample(src: &[[f32; 4]], forward: &[f64], m: usize, edge: EdgeMode) -> Vec<[f32; 4]> {
        let mut u = vec![0.0; m + 1];
        invert(forward, 0.0, &mut u);
        (0..m)
            .map(|k| sample(u[k], u[k + 1], src.len(), edge, |i| src[i]))
            .collect()
    }

    #[test]
    fn identity_copies_exactly() {
        let src = line(50);
        let forward: Vec<f64> = (0..=50).map(|i| i as f64).collect();
        assert_eq!(resample(&src, &forward, 50, EdgeMode::Clamp), src);
    }

    #[test]
    fn minification_conserves_the_mean() {
        // 90 input pixels squeezed into 36 output pixels (factor 2.5), and a
        // non-uniform squeeze: the sums (means times lengths) must agree.
        let src = line(90);
        let total: f64 = src.iter().map(|p| p[0] as f64).sum();
        let uniform: Vec<f64> = (0..=90).map(|i| i as f64 / 2.5).collect();
        let out = resample(&src, &uniform, 36, EdgeMode::Clamp);
        let sum: f64 = out.iter().map(|p| p[0] as f64 * 2.5).sum();
        assert!((sum - total).abs() < 1e-4, "{sum} vs {total}");

        let curved: Vec<f64> = (0..=90)
            .map(|i| {
                let u = i as f64 / 90.0;
                30.0 * (u + 0.3 * u * (1.0 - u))
            })
            .collect();
        let out = resample(&src, &curved, 30, EdgeMode::Clamp);
        let mut u = vec![0.0; 31];
        invert(&curved, 0.0, &mut u);
        let sum: f64 = out
            .iter()
            .enumerate()
            .map(|(k, p)| p[0] as f64 * (u[k + 1] - u[k]))
            .sum();
        assert!((sum - total).abs() < 1e-3, "{sum} vs {total}");
    }

    #[test]
    fn magnification_interpolates_linearly_between_centres() {
        let src = line(20);
        // Magnify by 4: output pixel k's preimage centre is (k + 0.5) / 4.
        let forward: Vec<f64> = (0..=20).map(|i| i as f64 * 4.0).collect();
        let out = resample(&src, &forward, 80, EdgeMode::Clamp);
        for (k, px) in out.iter().enumerate() {
            let c = (k as f64 + 0.5) / 4.0 - 0.5; // continuous index, centres at integers
            let i0 = c.floor().clamp(0.0, 19.0) as usize;
            let i1 = (i0 + 1).min(19);
            let f = (c - c.floor()) as f32;
            let want = if c < 0.0 {
                src[0][0]
            } else {
                src[i0][0] * (1.0 - f) + src[i1][0] * f
            };
            assert!((px[0] - want).abs() < 1e-5, "{k}: {} vs {want}", px[0]);
        }
    }

    #[test]
    fn edge_modes_beyond_the_line() {
        let src = vec![[1.0f32, 2.0, 3.0, 1.0]; 4];
        // Shift right by 2: the first two output pixels read before the line.
        let forward: Vec<f64> = (0..=4).map(|i| i as f64 + 2.0).collect();
        let clamp = resample(&src, &forward, 4, EdgeMode::Clamp);
        let black = resample(&src, &forward, 4, EdgeMode::Black);
        assert_eq!(clamp[0], [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(black[0], [0.0; 4]);
        assert_eq!(black[3], [1.0, 2.0, 3.0, 1.0]);
    }
}
