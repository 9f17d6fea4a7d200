//! The in-between image: both sources warped toward the same feature positions
//! and dissolved (seed 002 §3.4).

use crate::image::resample::{adapt_channels, fill_rows, row_through};
use crate::image::{RowsMut, Sample, Sampler};
use crate::warp::WarpMap;

/// `dst = (1 − t) · A(map_a) + t · B(map_b)`, in `dst`'s channel layout.
/// At `t = 0` B is not read at all (and A not at `t = 1`), so the end frames are
/// exactly the warped source, whatever the other holds (even NaN).
pub fn dissolve<S: Sample, D: Sample>(
    a: &Sampler<'_, S>,
    map_a: &WarpMap,
    b: &Sampler<'_, S>,
    map_b: &WarpMap,
    t: f64,
    dst: RowsMut<'_, D>,
) {
    let dc = dst.channels;
    let (wa, wb) = ((1.0 - t) as f32, t as f32);
    let (ca, cb) = (a.channels(), b.channels());
    fill_rows(dst, dc, |j, x1, row, other| {
        let warped =
            |sampler: &Sampler<'_, S>, map: &WarpMap, channels: usize, out: &mut [[f32; 4]]| {
                row_through(sampler, map, j, x1, out);
                if channels != dc {
                    for px in out.iter_mut() {
                        *px = adapt_channels(channels, dc, *px);
                    }
                }
            };
        if wb == 0.0 {
            warped(a, map_a, ca, row);
        } else if wa == 0.0 {
            warped(b, map_b, cb, row);
        } else {
            // row_through writes every pixel, so the spare needs no clearing.
            other.resize(row.len(), [0.0; 4]);
            warped(a, map_a, ca, row);
            warped(b, map_b, cb, other);
            for (pa, pb) in row.iter_mut().zip(other.iter()) {
                for c in 0..4 {
                    pa[c] = wa * pa[c] + wb * pb[c];
                }
            }
        }
    });
}

#[cfg(test)]
mod tests;
