//! Fant's 1-D resampling (Wolberg, `resample`): linear interpolation where a
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

/// The value of the output pixel whose preimage is `[u0, u1]` (in either
/// order), reading input pixel `i` of `n` through `read` and the edge mode
/// beyond them.
#[inline(always)]
pub fn sample(
    u0: f64,
    u1: f64,
    n: usize,
    edge: EdgeMode,
    read: impl Fn(usize) -> [f32; 4],
) -> [f32; 4] {
    let (lo, hi) = if u0 <= u1 { (u0, u1) } else { (u1, u0) };
    if hi - lo <= 1.0 {
        // Magnifying or the identity (most pixels of most warps): the unit
        // box is linear interpolation between the two nearest centres.
        let c = 0.5 * (lo + hi) - 0.5;
        let i = c.floor();
        if i >= 0.0 && i + 2.0 <= n as f64 {
            let (i0, f) = (i as usize, (c - i) as f32);
            let (p, q) = (read(i0), read(i0 + 1));
            return std::array::from_fn(|k| p[k] + f * (q[k] - p[k]));
        }
    }
    let len = (hi - lo).max(1.0);
    let a = 0.5 * (lo + hi - len);
    let first = a.floor();
    if first >= 0.0 && first + 3.0 <= n as f64 && len <= 2.0 {
        // The common case, without branches: a box of width 1 to 2 inside
        // the line covers at most three pixels (the third may weigh 0).
        let i0 = first as usize;
        let (fa, l) = ((a - first) as f32, len as f32);
        let inv = 1.0 / l;
        // Weights of the second and third pixel over the box; the first takes
        // the rest, written as offsets from it so flat data stays exact.
        let (w1, w2) = ((l + fa - 1.0).min(1.0) * inv, (l + fa - 2.0).max(0.0) * inv);
        let (p, q) = (read(i0), read(i0 + 1));
        if w2 == 0.0 {
            // Magnifying or the identity: two taps, linear interpolation.
            return std::array::from_fn(|c| p[c] + w1 * (q[c] - p[c]));
        }
        let r = read(i0 + 2);
        return std::array::from_fn(|c| p[c] + w1 * (q[c] - p[c]) + w2 * (r[c] - p[c]));
    }
    let b = a + len;
    if !(a.is_finite() && b.is_finite()) {
        return [0.0; 4];
    }
    if first >= 0.0 && b.ceil() - 1.0 < n as f64 {
        box_inside(a, len, read)
    } else {
        box_across_edge(a, len, n, edge, read)
    }
}

/// The mean over `[a, a + len]` (`len` at least one pixel) inside the line:
/// partial end pixels, whole ones between.
#[inline(always)]
fn box_inside(a: f64, len: f64, read: impl Fn(usize) -> [f32; 4]) -> [f32; 4] {
    let b = a + len;
    let (first, last) = (a.floor(), b.ceil() - 1.0);
    let (i0, i1) = (first as usize, last as usize);
    if i0 == i1 {
        return read(i0);
    }
    let (w0, w1) = ((first + 1.0 - a) as f32, (b - last) as f32);
    let (p, q) = (read(i0), read(i1));
    let mut acc: [f32; 4] = std::array::from_fn(|c| w0 * p[c] + w1 * q[c]);
    for i in i0 + 1..i1 {
        let v = read(i);
        for c in 0..4 {
            acc[c] += v[c];
        }
    }
    let inv = (1.0 / len) as f32;
    acc.map(|v| v * inv)
}

/// The mean over `[a, a + len]` across an end of the line: each tap through the
/// edge mode. A preimage longer than the whole line repeats it (mirror) or
/// its end (clamp), so the loop is bounded.
#[inline(always)]
fn box_across_edge(
    a: f64,
    len: f64,
    n: usize,
    edge: EdgeMode,
    read: impl Fn(usize) -> [f32; 4],
) -> [f32; 4] {
    let (first, b) = (a.floor(), a + len);
    let mut acc = [0f32; 4];
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
    let inv = (1.0 / len) as f32;
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

    /// Output pixel `k` has the preimage `[pre(k), pre(k + 1)]`.
    fn resample(
        src: &[[f32; 4]],
        m: usize,
        edge: EdgeMode,
        pre: impl Fn(f64) -> f64,
    ) -> Vec<[f32; 4]> {
        (0..m)
            .map(|k| {
                sample(pre(k as f64), pre(k as f64 + 1.0), src.len(), edge, |i| {
                    src[i]
                })
            })
            .collect()
    }

    #[test]
    fn identity_copies_exactly() {
        let src = line(50);
        assert_eq!(resample(&src, 50, EdgeMode::Clamp, |x| x), src);
    }

    #[test]
    fn minification_conserves_the_mean() {
        // 90 input pixels squeezed into 36 output pixels (factor 2.5), and a
        // non-uniform squeeze: the sums (means times lengths) must agree.
        let src = line(90);
        let total: f64 = src.iter().map(|p| p[0] as f64).sum();
        let out = resample(&src, 36, EdgeMode::Clamp, |x| x * 2.5);
        let sum: f64 = out.iter().map(|p| p[0] as f64 * 2.5).sum();
        assert!((sum - total).abs() < 1e-4, "{sum} vs {total}");

        // Preimages from 2× to 4× long: every output pixel a box of 2+ pixels.
        let curved = |x: f64| 90.0 * (x / 30.0 + 0.5 * (x / 30.0) * (1.0 - x / 30.0));
        let out = resample(&src, 30, EdgeMode::Clamp, curved);
        let sum: f64 = out
            .iter()
            .enumerate()
            .map(|(k, p)| p[0] as f64 * (curved(k as f64 + 1.0) - curved(k as f64)))
            .sum();
        assert!((sum - total).abs() < 1e-3, "{sum} vs {total}");
    }

    #[test]
    fn magnification_interpolates_linearly_between_centres() {
        let src = line(20);
        // Magnify by 4: output pixel k's preimage centre is (k + 0.5) / 4.
        let out = resample(&src, 80, EdgeMode::Clamp, |x| x / 4.0);
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
        // Shifted right by 2: the first two output pixels read before the line.
        let clamp = resample(&src, 4, EdgeMode::Clamp, |x| x - 2.0);
        let black = resample(&src, 4, EdgeMode::Black, |x| x - 2.0);
        assert_eq!(clamp[0], [1.0, 2.0, 3.0, 1.0]);
        assert_eq!(black[0], [0.0; 4]);
        assert_eq!(black[3], [1.0, 2.0, 3.0, 1.0]);
        // Reversed preimages (a fold) read the same pixels.
        let folded = sample(3.0, 2.0, 4, EdgeMode::Clamp, |i| src[i]);
        assert_eq!(folded, [1.0, 2.0, 3.0, 1.0]);
    }
}
