//! Writing an output image pixel by pixel in parallel (row bands), and
//! resampling a source through a warp map.

use rayon::prelude::*;

use super::{EdgeMode, Filter, ImageView, RowsMut, Sample, Sampler};
use crate::geom::PixelScale;
use crate::warp::WarpMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ResampleSettings {
    pub filter: Filter,
    pub edge: EdgeMode,
    /// Whether RGBA sources hold premultiplied colour (OFX's usual state).
    pub premultiplied: bool,
}

/// Below this many pixels the thread hand-off costs more than it saves.
const PARALLEL_MIN_PIXELS: usize = 16 * 1024;

/// Calls `f(i, j, &mut px)` for every pixel of `dst` (in parallel over rows) and
/// stores `px` converted to `dst`'s channel layout and sample type. `px` holds
/// the value in `src_channels` layout (1 = alpha, 3 = RGB, 4 = RGBA).
pub fn fill<D: Sample>(
    dst: RowsMut<'_, D>,
    src_channels: usize,
    f: impl Fn(i32, i32, &mut [f32; 4]) + Sync,
) {
    let b = dst.bounds;
    let dc = dst.channels;
    let work = |(j, row): (i32, &mut [D])| {
        let mut px = [0f32; 4];
        for (k, out) in row.chunks_exact_mut(dc).enumerate() {
            f(b.x1 + k as i32, j, &mut px);
            let v = adapt_channels(src_channels, dc, px);
            for (o, v) in out.iter_mut().zip(v) {
                *o = D::from_f32(v);
            }
        }
    };
    let rows = dst.rows;
    if b.area() >= PARALLEL_MIN_PIXELS {
        rows.into_par_iter().for_each(work);
    } else {
        rows.into_iter().for_each(work);
    }
}

/// A pixel from one channel layout to another: RGB gains opaque alpha, alpha
/// alone becomes grey, RGBA to alpha keeps alpha.
#[inline]
pub fn adapt_channels(from: usize, to: usize, px: [f32; 4]) -> [f32; 4] {
    match (from, to) {
        (f, t) if f == t => px,
        (3, 4) => [px[0], px[1], px[2], 1.0],
        (4, 3) => px,
        (1, _) => [px[0]; 4],
        (4, 1) => [px[3], 0.0, 0.0, 0.0],
        (3, 1) => [(px[0] + px[1] + px[2]) / 3.0, 0.0, 0.0, 0.0],
        _ => px,
    }
}

/// `dst(i, j) = src(map(i, j))`. Output pixels outside `map.window` are left
/// as they are. An identity map copies pixels without filtering.
pub fn resample<S: Sample, D: Sample>(
    src: ImageView<'_, S>,
    src_scale: PixelScale,
    map: &WarpMap,
    dst: RowsMut<'_, D>,
    settings: ResampleSettings,
) {
    let sampler = Sampler::new(
        src,
        src_scale,
        settings.filter,
        settings.edge,
        settings.premultiplied,
    );
    through(&sampler, map, dst);
}

/// `dst(i, j) = sampler(map(i, j))`.
pub fn through<S: Sample, D: Sample>(sampler: &Sampler<'_, S>, map: &WarpMap, dst: RowsMut<'_, D>) {
    fill(dst, sampler.channels(), |i, j, px| {
        sample_through(sampler, map, i, j, px);
    });
}

/// One output pixel of `sampler` seen through `map`.
#[inline]
pub(crate) fn sample_through<S: Sample>(
    sampler: &Sampler<'_, S>,
    map: &WarpMap,
    i: i32,
    j: i32,
    px: &mut [f32; 4],
) {
    let w = map.window;
    if i < w.x1 || i >= w.x2 || j < w.y1 || j >= w.y2 {
        *px = [0.0; 4];
        return;
    }
    let p = map.get(i, j);
    sampler.sample(p.x as f32, p.y as f32, px);
}
