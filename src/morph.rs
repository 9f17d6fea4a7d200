//! The in-between image: both sources warped toward the same feature positions
//! and dissolved (Beier-Neely §3.4).

use crate::image::direct_rgba::blend_row;
use crate::image::resample::{adapt_channels, fill_rows, map_span, row_through};
use crate::image::WarpMap;
use crate::image::{Plane, RowsMut, Sample, Sampler};
use crate::transition::Weights;

pub mod mix;

/// A warped source as the dissolve reads it: resampled through a reverse
/// map, or pixels a warp made directly (the two-pass mesh warp).
#[derive(Clone, Copy)]
pub enum Warped<'a, S> {
    /// A source sampled through a reverse map.
    Map(&'a Sampler<'a, S>, &'a WarpMap),
    /// Pixels a warp made directly.
    Pixels(&'a Plane),
    /// A straight-alpha source's warped pixels with colour times alpha, to
    /// meet premultiplied pixels in a dissolve or a premultiplied output.
    /// Exactly filtering the premultiplied source: straight sampling already
    /// weights colour by alpha, and this undoes its division.
    Premultiplied(&'a Warped<'a, S>),
}

impl<S: Sample> Warped<'_, S> {
    /// Components per pixel.
    pub fn channels(&self) -> usize {
        match self {
            Warped::Map(s, _) => s.channels(),
            Warped::Pixels(p) => p.channels,
            Warped::Premultiplied(w) => w.channels(),
        }
    }

    /// Pixels `x1..` of row `j` into `out`, in [`Warped::channels`] layout;
    /// transparent black outside what the warp covers.
    pub fn row(&self, j: i32, x1: i32, out: &mut [[f32; 4]]) {
        match self {
            Warped::Map(sampler, map) => row_through(sampler, map, j, x1, out),
            Warped::Pixels(plane) => {
                let w = plane.window;
                let x2 = x1 + out.len() as i32;
                let (lo, hi) = (x1.max(w.x1), x2.min(w.x2));
                out.fill([0.0; 4]);
                if j >= w.y1 && j < w.y2 && lo < hi {
                    let src = &plane.row(j)[(lo - w.x1) as usize..(hi - w.x1) as usize];
                    out[(lo - x1) as usize..(hi - x1) as usize].copy_from_slice(src);
                }
            }
            Warped::Premultiplied(w) => {
                w.row(j, x1, out);
                if w.channels() == 4 {
                    for px in out.iter_mut() {
                        for c in 0..3 {
                            px[c] *= px[3];
                        }
                    }
                }
            }
        }
    }
}

impl<S: Sample> Warped<'_, S> {
    /// [`Warped::row`] in `channels` layout.
    pub fn row_as(&self, j: i32, x1: i32, channels: usize, out: &mut [[f32; 4]]) {
        self.row(j, x1, out);
        let own = self.channels();
        if own != channels {
            for px in out.iter_mut() {
                *px = adapt_channels(own, channels, *px);
            }
        }
    }
}

/// One warped source written into `dst`'s layout.
pub fn show<S: Sample, D: Sample>(src: Warped<'_, S>, dst: RowsMut<'_, D>) {
    fill_rows(dst, src.channels(), |j, x1, row, _| src.row(j, x1, row));
}

/// `dst = (1 − t) · A + t · B` of the warped sources, in `dst`'s channel layout.
/// At `t = 0` B is not read at all (and A not at `t = 1`), so the end frames are
/// exactly the warped source, whatever the other holds (even NaN).
pub fn dissolve<S: Sample, D: Sample>(
    a: Warped<'_, S>,
    b: Warped<'_, S>,
    t: f64,
    dst: RowsMut<'_, D>,
) {
    let dc = dst.channels;
    let (wa, wb) = ((1.0 - t) as f32, t as f32);
    // Both sources float RGBA through maps (the usual host plates), both
    // read: sampled and blended pixel by pixel in one pass.
    let direct = match (a, b) {
        (Warped::Map(sa, ma), Warped::Map(sb, mb)) if dc == 4 && wa != 0.0 && wb != 0.0 => sa
            .direct_taps()
            .zip(sb.direct_taps())
            .map(|(ta, tb)| [(ta, sa, ma), (tb, sb, mb)]),
        _ => None,
    };
    fill_rows(dst, dc, |j, x1, row, other| {
        let warped = |src: &Warped<'_, S>, out: &mut [[f32; 4]]| src.row_as(j, x1, dc, out);
        if let Some([(ta, sa, ma), (tb, sb, mb)]) = &direct {
            let len = row.len();
            if let Some((pa, pb)) = map_span(ma, j, x1, len).zip(map_span(mb, j, x1, len)) {
                let slow = |s: &Sampler<'_, S>, p: &[[f32; 2]], n: usize| {
                    let mut v = [0f32; 4];
                    s.sample(p[n][0], p[n][1], &mut v);
                    v
                };
                blend_row(
                    (ta, pa, wa, |n| slow(sa, pa, n)),
                    (tb, pb, wb, |n| slow(sb, pb, n)),
                    row,
                );
                return;
            }
        }
        if wb == 0.0 {
            warped(&a, row);
        } else if wa == 0.0 {
            warped(&b, row);
        } else {
            // Every pixel is written, so the spare needs no clearing.
            other.resize(row.len(), [0.0; 4]);
            warped(&a, row);
            warped(&b, other);
            for (pa, pb) in row.iter_mut().zip(other.iter()) {
                for c in 0..4 {
                    pa[c] = wb.mul_add(pb[c], wa * pa[c]);
                }
            }
        }
    });
}

/// The dissolve with a weight per pixel and side (Lee, Wolberg et al. §3: `I = W0 •
/// ((1 − T0) I0) + W1 • (T1 I1)`): `dst = w_a · A + w_b · B`, weights from
/// [`crate::transition::colour_weights`] over a window that covers `dst`
/// (pixels outside it take the plain `1 − t`, `t`).
pub fn dissolve_weighted<S: Sample, D: Sample>(
    a: Warped<'_, S>,
    b: Warped<'_, S>,
    t: f64,
    weights: &Weights,
    dst: RowsMut<'_, D>,
) {
    let dc = dst.channels;
    let win = weights.window;
    let (ua, ub) = ((1.0 - t) as f32, t as f32);
    fill_rows(dst, dc, |j, x1, row, other| {
        let warped = |src: &Warped<'_, S>, out: &mut [[f32; 4]]| src.row_as(j, x1, dc, out);
        other.resize(row.len(), [0.0; 4]);
        warped(&a, row);
        warped(&b, other);
        for (k, (pa, pb)) in row.iter_mut().zip(other.iter()).enumerate() {
            let i = x1 + k as i32;
            let (wa, wb) = if i >= win.x1 && i < win.x2 && j >= win.y1 && j < win.y2 {
                let n = (j - win.y1) as usize * win.width() + (i - win.x1) as usize;
                (weights.a[n], weights.b[n])
            } else {
                (ua, ub)
            };
            for c in 0..4 {
                pa[c] = wa * pa[c] + wb * pb[c];
            }
        }
    });
}

#[cfg(test)]
mod tests;
