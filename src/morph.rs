//! The in-between image: both sources warped toward the same feature positions
//! and dissolved (seed 002 §3.4).

use crate::image::{resample::adapt_channels, resample::fill, RowsMut, Sample, Sampler};
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
    fill(dst, dc, |i, j, px| {
        let mut sa = [0f32; 4];
        let mut sb = [0f32; 4];
        if wa != 0.0 {
            crate::image::resample::sample_through(a, map_a, i, j, &mut sa);
            sa = adapt_channels(ca, dc, sa);
        }
        if wb != 0.0 {
            crate::image::resample::sample_through(b, map_b, i, j, &mut sb);
            sb = adapt_channels(cb, dc, sb);
        }
        for c in 0..4 {
            px[c] = match (wa != 0.0, wb != 0.0) {
                (true, false) => sa[c],
                (false, true) => sb[c],
                _ => wa * sa[c] + wb * sb[c],
            };
        }
    });
}

#[cfg(test)]
mod tests;
