//! Reading a source image at any canonical position: filters, edge modes and
//! the pixel-centre convention (pixel `(i, j)` is centred at `(i+0.5, j+0.5)`).

use super::{ImageView, Sample};
use crate::geom::{PixelScale, RectI};

/// Reconstruction filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Filter {
    /// 2×2 taps. Interpolating: a pixel centre returns that pixel exactly.
    #[default]
    Bilinear,
    /// 4×4 taps, Catmull-Rom (Keys cubic, a = −0.5). Interpolating like
    /// bilinear, sharper; may overshoot at edges (never clamped: HDR data).
    Bicubic,
}

impl Filter {
    pub fn name(self) -> &'static str {
        match self {
            Filter::Bilinear => "bilinear",
            Filter::Bicubic => "bicubic",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        [Filter::Bilinear, Filter::Bicubic]
            .into_iter()
            .find(|f| f.name() == s)
    }
}

/// What lies outside the source image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum EdgeMode {
    /// Transparent black.
    Black,
    /// The nearest edge pixel (no black borders: the default).
    #[default]
    Clamp,
    /// The image reflected about its edges.
    Mirror,
}

impl EdgeMode {
    pub fn name(self) -> &'static str {
        match self {
            EdgeMode::Black => "black",
            EdgeMode::Clamp => "clamp",
            EdgeMode::Mirror => "mirror",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror]
            .into_iter()
            .find(|m| m.name() == s)
    }

    /// The in-bounds index `k` reads from, for an axis `[lo, hi)`.
    #[inline]
    fn resolve(self, k: i32, lo: i32, hi: i32) -> Option<i32> {
        if k >= lo && k < hi {
            return Some(k);
        }
        match self {
            EdgeMode::Black => None,
            EdgeMode::Clamp => Some(k.clamp(lo, hi - 1)),
            EdgeMode::Mirror => {
                let n = hi - lo;
                let m = (k - lo).rem_euclid(2 * n);
                Some(lo + if m < n { m } else { 2 * n - 1 - m })
            }
        }
    }
}

/// Fractions this close to a pixel centre snap to it, so warps that land on
/// centres up to float round-off copy pixels exactly instead of blurring.
const SNAP: f32 = 1e-4;

/// Samples one image; at most 4 channels.
#[derive(Debug, Clone, Copy)]
pub struct Sampler<'a, T> {
    view: ImageView<'a, T>,
    scale: PixelScale,
    filter: Filter,
    edge: EdgeMode,
    /// Weight colour by alpha while filtering (straight-alpha RGBA), so
    /// transparent pixels do not bleed their colour.
    alpha_weighted: bool,
}

impl<'a, T: Sample> Sampler<'a, T> {
    pub fn new(
        view: ImageView<'a, T>,
        scale: PixelScale,
        filter: Filter,
        edge: EdgeMode,
        premultiplied: bool,
    ) -> Self {
        assert!(view.channels() <= 4, "at most 4 channels");
        Sampler {
            view,
            scale,
            filter,
            edge,
            alpha_weighted: !premultiplied && view.channels() == 4,
        }
    }

    pub fn channels(&self) -> usize {
        self.view.channels()
    }

    pub fn bounds(&self) -> RectI {
        self.view.bounds()
    }

    /// The source pixel `(i, j)` itself, if inside the bounds.
    #[inline]
    pub fn pixel(&self, i: i32, j: i32, out: &mut [f32; 4]) -> bool {
        let b = self.view.bounds();
        if i < b.x1 || i >= b.x2 || j < b.y1 || j >= b.y2 {
            return false;
        }
        for (o, v) in out.iter_mut().zip(self.view.pixel(i, j)) {
            *o = v.to_f32();
        }
        true
    }

    /// The filtered value at canonical position `(x, y)`.
    #[inline]
    pub fn sample(&self, x: f32, y: f32, out: &mut [f32; 4]) {
        *out = [0.0; 4];
        if !(x.is_finite() && y.is_finite()) {
            return;
        }
        // Continuous pixel index: integers are pixel centres.
        let fx = x * self.scale.x as f32 - 0.5;
        let fy = y * self.scale.y as f32 - 0.5;
        let (i0, tx) = split(fx);
        let (j0, ty) = split(fy);
        if tx == 0.0 && ty == 0.0 {
            // On a centre: every interpolating filter returns the pixel.
            if !self.pixel(i0, j0, out) {
                self.accumulate(&[(i0, j0, 1.0)], out);
            }
            return;
        }
        match self.filter {
            Filter::Bilinear => {
                let taps = [
                    (i0, j0, (1.0 - tx) * (1.0 - ty)),
                    (i0 + 1, j0, tx * (1.0 - ty)),
                    (i0, j0 + 1, (1.0 - tx) * ty),
                    (i0 + 1, j0 + 1, tx * ty),
                ];
                self.accumulate(&taps, out);
            }
            Filter::Bicubic => {
                let wx = catmull_rom_weights(tx);
                let wy = catmull_rom_weights(ty);
                let mut taps = [(0, 0, 0.0f32); 16];
                for (r, wyr) in wy.iter().enumerate() {
                    for (c, wxc) in wx.iter().enumerate() {
                        taps[r * 4 + c] = (i0 - 1 + c as i32, j0 - 1 + r as i32, wxc * wyr);
                    }
                }
                self.accumulate(&taps, out);
            }
        }
    }

    #[inline]
    fn accumulate(&self, taps: &[(i32, i32, f32)], out: &mut [f32; 4]) {
        let b = self.view.bounds();
        let n = self.view.channels();
        let mut acc = [0f32; 4];
        for &(i, j, w) in taps {
            if w == 0.0 {
                continue;
            }
            let (Some(i), Some(j)) = (
                self.edge.resolve(i, b.x1, b.x2),
                self.edge.resolve(j, b.y1, b.y2),
            ) else {
                continue;
            };
            let px = self.view.pixel(i, j);
            if self.alpha_weighted {
                let a = px[3].to_f32();
                let wa = w * a;
                for c in 0..3 {
                    acc[c] += wa * px[c].to_f32();
                }
                acc[3] += wa;
            } else {
                for c in 0..n {
                    acc[c] += w * px[c].to_f32();
                }
            }
        }
        if self.alpha_weighted {
            // acc[3] = Σ w a; colour = Σ w a c / Σ w a; alpha = Σ w a.
            let sum_wa = acc[3];
            let inv = if sum_wa != 0.0 { 1.0 / sum_wa } else { 0.0 };
            *out = [acc[0] * inv, acc[1] * inv, acc[2] * inv, sum_wa];
        } else {
            *out = acc;
        }
    }
}

/// Integer part and fraction, with fractions within [`SNAP`] of a centre snapped.
#[inline]
fn split(f: f32) -> (i32, f32) {
    let i = f.floor();
    let t = f - i;
    if t < SNAP {
        (i as i32, 0.0)
    } else if t > 1.0 - SNAP {
        (i as i32 + 1, 0.0)
    } else {
        (i as i32, t)
    }
}

/// Catmull-Rom weights for taps at offsets −1, 0, 1, 2 from the fraction `t`.
#[inline]
fn catmull_rom_weights(t: f32) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_rom_weights_sum_to_one_and_interpolate() {
        for k in 0..=10 {
            let w = catmull_rom_weights(k as f32 / 10.0);
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        }
        assert_eq!(catmull_rom_weights(0.0), [0.0, 1.0, 0.0, 0.0]);
    }

    #[test]
    fn edge_modes_resolve_indices() {
        assert_eq!(EdgeMode::Black.resolve(-1, 0, 4), None);
        assert_eq!(EdgeMode::Clamp.resolve(-3, 0, 4), Some(0));
        assert_eq!(EdgeMode::Clamp.resolve(9, 0, 4), Some(3));
        // Mirror: ... 1 0 | 0 1 2 3 | 3 2 ...
        assert_eq!(EdgeMode::Mirror.resolve(-1, 0, 4), Some(0));
        assert_eq!(EdgeMode::Mirror.resolve(-2, 0, 4), Some(1));
        assert_eq!(EdgeMode::Mirror.resolve(4, 0, 4), Some(3));
        assert_eq!(EdgeMode::Mirror.resolve(5, 0, 4), Some(2));
        assert_eq!(EdgeMode::Mirror.resolve(5, 2, 6), Some(5));
    }
}
