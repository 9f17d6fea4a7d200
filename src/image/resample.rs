//! Writing an output image pixel by pixel in parallel (row bands), and
//! resampling a source through a warp map.

use rayon::prelude::*;

use super::WarpMap;
use super::{EdgeMode, Filter, ImageView, RowsMut, Sample, Sampler};
use crate::geom::PixelScale;

/// How a warped source is sampled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ResampleSettings {
    /// The reconstruction filter.
    pub filter: Filter,
    /// What lies outside the source's pixels.
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
    fill_rows(dst, src_channels, |j, x1, row, _| {
        for (k, px) in row.iter_mut().enumerate() {
            f(x1 + k as i32, j, px);
        }
    });
}

/// Row-at-a-time [`fill`]: `f(j, x1, row, spare)` computes the pixels `x1..`
/// of row `j` into `row` (in `src_channels` layout), which is then stored into
/// `dst`. `spare` is a buffer kept per worker for callers that need a second
/// row (the dissolve), so no row allocates.
pub fn fill_rows<D: Sample>(
    dst: RowsMut<'_, D>,
    src_channels: usize,
    f: impl Fn(i32, i32, &mut [[f32; 4]], &mut Vec<[f32; 4]>) + Sync,
) {
    type Buffers = (Vec<[f32; 4]>, Vec<[f32; 4]>);
    let b = dst.bounds;
    let dc = dst.channels;
    let work = |(scratch, spare): &mut Buffers, (j, row): (i32, &mut [D])| {
        // Float RGBA in and out: compute straight into the output row.
        if src_channels == 4 && dc == 4 {
            if let Some(floats) = D::as_f32_mut(row) {
                let (pixels, _) = floats.as_chunks_mut::<4>();
                f(j, b.x1, pixels, spare);
                return;
            }
        }
        scratch.clear();
        scratch.resize(b.width(), [0.0; 4]);
        f(j, b.x1, scratch, spare);
        store(src_channels, dc, scratch, row);
    };
    let rows = dst.rows;
    if b.area() >= PARALLEL_MIN_PIXELS {
        rows.into_par_iter().for_each_init(Buffers::default, work);
    } else {
        let mut buffers = Buffers::default();
        rows.into_iter().for_each(|r| work(&mut buffers, r));
    }
}

/// Converts a row of `from`-channel pixels into `to`-channel samples.
fn store<D: Sample>(from: usize, to: usize, px: &[[f32; 4]], row: &mut [D]) {
    let pixels = row.chunks_exact_mut(to).zip(px);
    if from == to {
        // The common case: no layout change, one branch-free loop.
        for (out, v) in pixels {
            for (o, v) in out.iter_mut().zip(v) {
                *o = D::from_f32(*v);
            }
        }
    } else {
        for (out, v) in pixels {
            for (o, v) in out.iter_mut().zip(adapt_channels(from, to, *v)) {
                *o = D::from_f32(v);
            }
        }
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
    fill_rows(dst, sampler.channels(), |j, x1, row, _| {
        row_through(sampler, map, j, x1, row);
    });
}

/// The map's positions for pixels `x1..x1 + len` of row `j`, when it holds
/// them all (not for the identity map, nor a span its window cuts).
pub(crate) fn map_span(map: &WarpMap, j: i32, x1: i32, len: usize) -> Option<&[[f32; 2]]> {
    let w = map.window;
    let x2 = x1 + len as i32;
    if j < w.y1 || j >= w.y2 || x1 < w.x1 || x2 > w.x2 {
        return None;
    }
    let positions = map.row(j)?;
    Some(&positions[(x1 - w.x1) as usize..(x2 - w.x1) as usize])
}

/// Row `j` of `sampler` seen through `map`, pixels `x1..x1 + row.len()`;
/// pixels outside the map's window are transparent black.
pub(crate) fn row_through<S: Sample>(
    sampler: &Sampler<'_, S>,
    map: &WarpMap,
    j: i32,
    x1: i32,
    row: &mut [[f32; 4]],
) {
    let w = map.window;
    let x2 = x1 + row.len() as i32;
    let (lo, hi) = (x1.max(w.x1), x2.min(w.x2));
    if j < w.y1 || j >= w.y2 || lo >= hi {
        row.fill([0.0; 4]);
        return;
    }
    let (before, rest) = row.split_at_mut((lo - x1) as usize);
    let (inside, after) = rest.split_at_mut((hi - lo) as usize);
    before.fill([0.0; 4]);
    after.fill([0.0; 4]);
    match map.row(j) {
        Some(positions) => {
            let span = &positions[(lo - w.x1) as usize..(hi - w.x1) as usize];
            sampler.sample_row(span, inside);
        }
        None => {
            let s = map.scale;
            let centres: Vec<[f32; 2]> = (lo..hi)
                .map(|i| {
                    let c = s.pixel_centre(i, j);
                    [c.x as f32, c.y as f32]
                })
                .collect();
            sampler.sample_row(&centres, inside);
        }
    }
}
