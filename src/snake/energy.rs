//! The image force a snake follows: `F = −∇E_image = ∇ P`, where
//! `P = |G_σ ∗ ∇I|²` (Sobel gradient of the Gaussian-smoothed luminance,
//! squared) normalised so the strongest edge has `P = 1`. Smoothing lets a
//! feature attract a snake placed up to about 2σ away (seed §4.1).

use rayon::prelude::*;

use crate::geom::{RectI, Vec2};
use crate::image::{ImageView, Sample};

/// Force field over an image's pixels (canonical coordinates at full
/// resolution: pixel `(i, j)` centred at `(i + 0.5, j + 0.5)`).
#[derive(Debug, Clone)]
pub struct EdgeEnergy {
    bounds: RectI,
    fx: Vec<f32>,
    fy: Vec<f32>,
}

impl EdgeEnergy {
    /// From any image view: luminance of RGB(A), the one channel otherwise.
    pub fn new<T: Sample>(view: ImageView<'_, T>, sigma: f64) -> EdgeEnergy {
        let b = view.bounds();
        let (w, h) = (b.width(), b.height());
        let c = view.channels();
        let mut lum = vec![0f32; w * h];
        lum.par_chunks_mut(w.max(1))
            .enumerate()
            .for_each(|(r, out)| {
                let row = view.row(b.y1 + r as i32);
                for (o, px) in out.iter_mut().zip(row.chunks_exact(c)) {
                    let v = if c >= 3 {
                        0.2126 * px[0].to_f32() + 0.7152 * px[1].to_f32() + 0.0722 * px[2].to_f32()
                    } else {
                        px[0].to_f32()
                    };
                    // NaN or infinite pixels (HDR renders have them) count as black,
                    // so every force stays finite.
                    *o = if v.is_finite() { v } else { 0.0 };
                }
            });
        let smooth = gaussian(&lum, w, h, sigma);
        // Sobel on the smoothed image, squared magnitude (edges held).
        let mut p = vec![0f32; w * h];
        p.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
            let line = |y: usize| &smooth[y * w..(y + 1) * w];
            let (lo, mid, hi) = (line(y.saturating_sub(1)), line(y), line((y + 1).min(h - 1)));
            for (x, o) in out.iter_mut().enumerate() {
                let (xl, xr) = (x.saturating_sub(1), (x + 1).min(w - 1));
                let gx = (lo[xr] + 2.0 * mid[xr] + hi[xr]) - (lo[xl] + 2.0 * mid[xl] + hi[xl]);
                let gy = (hi[xl] + 2.0 * hi[x] + hi[xr]) - (lo[xl] + 2.0 * lo[x] + lo[xr]);
                *o = (gx * gx + gy * gy) / 64.0;
            }
        });
        let max = p.iter().cloned().fold(0f32, f32::max);
        if max > 0.0 {
            p.iter_mut().for_each(|v| *v /= max);
        }
        // F = ∇P by central differences (one-sided at the border).
        let (mut fx, mut fy) = (vec![0f32; w * h], vec![0f32; w * h]);
        fx.par_chunks_mut(w)
            .zip(fy.par_chunks_mut(w))
            .enumerate()
            .for_each(|(y, (ox, oy))| {
                let row = &p[y * w..(y + 1) * w];
                let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
                let (below, above) = (&p[y0 * w..(y0 + 1) * w], &p[y1 * w..(y1 + 1) * w]);
                let dy = (y1 - y0).max(1) as f32;
                for x in 0..w {
                    let (x0, x1) = (x.saturating_sub(1), (x + 1).min(w - 1));
                    ox[x] = (row[x1] - row[x0]) / (x1 - x0).max(1) as f32;
                    oy[x] = (above[x] - below[x]) / dy;
                }
            });
        EdgeEnergy { bounds: b, fx, fy }
    }

    /// The force at canonical position `p`, interpolated bilinearly between
    /// pixel centres (held at the border).
    pub fn force(&self, p: Vec2) -> Vec2 {
        let b = self.bounds;
        let (w, h) = (b.width(), b.height());
        if w == 0 || h == 0 || !p.is_finite() {
            return Vec2::default();
        }
        let fx = (p.x - b.x1 as f64 - 0.5).clamp(0.0, (w - 1) as f64);
        let fy = (p.y - b.y1 as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
        let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
        let lerp = |v: &[f32]| {
            let g = |x: usize, y: usize| v[y * w + x] as f64;
            let bottom = g(x0, y0) + (g(x1, y0) - g(x0, y0)) * tx;
            let top = g(x0, y1) + (g(x1, y1) - g(x0, y1)) * tx;
            bottom + (top - bottom) * ty
        };
        Vec2::new(lerp(&self.fx), lerp(&self.fy))
    }
}

/// Separable Gaussian blur, radius 3σ, edges held.
fn gaussian(src: &[f32], w: usize, h: usize, sigma: f64) -> Vec<f32> {
    if sigma <= 0.0 || w == 0 || h == 0 {
        return src.to_vec();
    }
    let r = (3.0 * sigma).ceil() as usize;
    let mut k: Vec<f32> = (0..=2 * r)
        .map(|i| {
            let d = i as f64 - r as f64;
            (-(d * d) / (2.0 * sigma * sigma)).exp() as f32
        })
        .collect();
    let sum: f32 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= sum);
    // Along rows: each row padded with its end values, then a dot product
    // per pixel.
    let mut tmp = vec![0f32; w * h];
    tmp.par_chunks_mut(w)
        .enumerate()
        .for_each_init(Vec::new, |padded, (y, out)| {
            let row = &src[y * w..(y + 1) * w];
            padded.clear();
            padded.extend(std::iter::repeat_n(row[0], r));
            padded.extend_from_slice(row);
            padded.extend(std::iter::repeat_n(row[w - 1], r));
            for (x, o) in out.iter_mut().enumerate() {
                *o = padded[x..x + 2 * r + 1]
                    .iter()
                    .zip(&k)
                    .map(|(v, kv)| v * kv)
                    .sum();
            }
        });
    // Down columns: whole rows weighted and summed, edges held.
    let mut out = vec![0f32; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, o)| {
        for (q, kv) in k.iter().enumerate() {
            let yy = (y as isize + q as isize - r as isize).clamp(0, h as isize - 1) as usize;
            for (v, t) in o.iter_mut().zip(&tmp[yy * w..(yy + 1) * w]) {
                *v += kv * t;
            }
        }
    });
    out
}
