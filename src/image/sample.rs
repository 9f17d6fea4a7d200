//! Reading a source image at any canonical position: filters, edge modes and
//! the pixel-centre convention (pixel `(i, j)` is centred at `(i+0.5, j+0.5)`).

use wide::f32x8;

use super::direct_rgba::{self, Taps};
use super::edge::EdgeMode;
use super::kernel::{catmull_rom_weights, catmull_rom_weights8, split, SNAP};
use super::{ImageView, Sample};
use crate::choice::Choice;
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
    /// The one pixel the position falls in, unblended: for IDs and mattes,
    /// whose values must stay values the source holds.
    Nearest,
}

impl Choice for Filter {
    const ALL: &'static [Self] = &[Filter::Bilinear, Filter::Bicubic, Filter::Nearest];
    fn name(self) -> &'static str {
        match self {
            Filter::Bilinear => "bilinear",
            Filter::Bicubic => "bicubic",
            Filter::Nearest => "nearest",
        }
    }
}

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
    /// A sampler of `view` at render scale `scale`; `premultiplied` says whether an RGBA
    /// source's colour is already times alpha (else colour is weighted by alpha while
    /// filtering).
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

    /// Components per pixel.
    #[inline]
    pub fn channels(&self) -> usize {
        self.view.channels()
    }

    /// The reconstruction filter.
    #[inline]
    pub fn filter(&self) -> Filter {
        self.filter
    }

    /// The source's pixels.
    #[inline]
    pub fn bounds(&self) -> RectI {
        self.view.bounds()
    }

    /// The render scale the source is at.
    #[inline]
    pub fn scale(&self) -> PixelScale {
        self.scale
    }

    /// What lies outside the source's pixels.
    #[inline]
    pub fn edge(&self) -> EdgeMode {
        self.edge
    }

    /// Direct taps for the bilinear or bicubic kernel of premultiplied
    /// RGBA of any sample type ([`direct_rgba`]); `None` for any other
    /// layout, which takes the general path.
    pub(crate) fn direct_taps(&self) -> Option<Taps<'a, T>> {
        if self.view.channels() != 4 || self.alpha_weighted || self.filter == Filter::Nearest {
            return None;
        }
        let cubic = self.filter == Filter::Bicubic;
        let (data, layout) = (self.view.data, self.view.layout);
        Taps::new(data, layout, self.scale(), self.edge, cubic)
    }

    /// Whether colour is weighted by alpha while filtering (straight RGBA).
    #[inline]
    pub fn alpha_weighted(&self) -> bool {
        self.alpha_weighted
    }

    /// Row `j` as it lies in memory when that already is what
    /// [`Sampler::load_span`] would make (float RGBA, premultiplied): no copy.
    pub fn float_rgba_row(&self, j: i32) -> Option<&'a [[f32; 4]]> {
        if self.view.channels() != 4 || self.alpha_weighted {
            return None;
        }
        T::as_f32(self.view.row(j)).map(|f| f.as_chunks::<4>().0)
    }

    /// The `len` pixels of row `j` from column `i` (inside the bounds) as
    /// floats in `out`, one pixel per entry in the sampler's layout; colour
    /// multiplied by alpha when the sampler weights by alpha (straight RGBA),
    /// so the pixels can be filtered linearly and divided back afterwards.
    pub fn load_span(&self, j: i32, i: i32, len: usize, out: &mut Vec<[f32; 4]>) {
        let c = self.view.channels();
        let start = (i - self.view.bounds().x1) as usize * c;
        let row = &self.view.row(j)[start..start + len * c];
        match (self.view.channels(), self.alpha_weighted) {
            (4, true) => load::<T, 4, true>(row, out),
            (4, false) => load::<T, 4, false>(row, out),
            (3, _) => load::<T, 3, false>(row, out),
            (2, _) => load::<T, 2, false>(row, out),
            _ => load::<T, 1, false>(row, out),
        }
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
            Filter::Nearest => {
                // The pixel whose square holds the position: [i, i + 1) in x.
                let (i, j) = ((fx + 0.5).floor() as i32, (fy + 0.5).floor() as i32);
                if !self.pixel(i, j, out) {
                    self.accumulate(&[(i, j, 1.0)], out);
                }
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

    /// Samples at each canonical position of `positions` into `out` (the
    /// sampler's channel layout in the first [`Sampler::channels`] entries).
    /// Same values as [`Sampler::sample`] per pixel; the common case (all taps
    /// inside the image, off centre lines) runs eight positions at a time
    /// without edge handling, specialised per layout and filter.
    pub fn sample_row(&self, positions: &[[f32; 2]], out: &mut [[f32; 4]]) {
        if self.filter == Filter::Nearest {
            for (&[x, y], o) in positions.iter().zip(out) {
                self.sample(x, y, o);
            }
            return;
        }
        let cubic = self.filter == Filter::Bicubic;
        match (self.view.channels(), self.alpha_weighted, cubic) {
            (4, true, false) => self.row::<4, true, false>(positions, out),
            (4, true, true) => self.row::<4, true, true>(positions, out),
            (4, false, false) => match self.direct_taps() {
                Some(taps) => direct_rgba::row(&taps, positions, out, |n, o| {
                    self.sample(positions[n][0], positions[n][1], o)
                }),
                None => self.row::<4, false, false>(positions, out),
            },
            (4, false, true) => match self.direct_taps() {
                Some(taps) => direct_rgba::row(&taps, positions, out, |n, o| {
                    self.sample(positions[n][0], positions[n][1], o)
                }),
                None => self.row::<4, false, true>(positions, out),
            },
            (3, _, false) => self.row::<3, false, false>(positions, out),
            (3, _, true) => self.row::<3, false, true>(positions, out),
            (2, _, false) => self.row::<2, false, false>(positions, out),
            (2, _, true) => self.row::<2, false, true>(positions, out),
            (_, _, false) => self.row::<1, false, false>(positions, out),
            (_, _, true) => self.row::<1, false, true>(positions, out),
        }
    }

    #[inline(always)]
    fn row<const C: usize, const AW: bool, const CUBIC: bool>(
        &self,
        positions: &[[f32; 2]],
        out: &mut [[f32; 4]],
    ) {
        let b = self.view.bounds();
        // Taps reach `lo` pixels below the integer part and `hi` above.
        let (lo, hi) = if CUBIC { (1, 2) } else { (0, 1) };
        let s = f32x8::splat;
        let (sx, sy) = (s(self.scale.x as f32), s(self.scale.y as f32));
        let (x_min, x_max) = (s((b.x1 + lo) as f32), s((b.x2 - hi) as f32));
        let (y_min, y_max) = (s((b.y1 + lo) as f32), s((b.y2 - hi) as f32));
        let (snap_lo, snap_hi) = (s(SNAP), s(1.0 - SNAP));
        for (pos, outs) in positions.chunks(8).zip(out.chunks_mut(8)) {
            if pos.len() < 8 {
                for (&[x, y], o) in pos.iter().zip(outs) {
                    self.sample(x, y, o);
                }
                continue;
            }
            let x = f32x8::new(std::array::from_fn(|k| pos[k][0]));
            let y = f32x8::new(std::array::from_fn(|k| pos[k][1]));
            // Continuous pixel index: integers are pixel centres.
            let (fx, fy) = (x * sx - s(0.5), y * sy - s(0.5));
            let (ix, iy) = (fx.floor(), fy.floor());
            let (tx, ty) = (fx - ix, fy - iy);
            // NaN fails every comparison, so it takes the general path too;
            // so do positions near a centre line (fewer taps, snapping).
            let fast = fx.simd_ge(x_min)
                & fx.simd_lt(x_max)
                & fy.simd_ge(y_min)
                & fy.simd_lt(y_max)
                & tx.simd_gt(snap_lo)
                & tx.simd_lt(snap_hi)
                & ty.simd_gt(snap_lo)
                & ty.simd_lt(snap_hi);
            let fast = fast.to_bitmask();
            let (i0, j0) = (
                ix.fast_trunc_int().to_array(),
                iy.fast_trunc_int().to_array(),
            );
            let (wx, wy) = if CUBIC {
                (catmull_rom_weights8(tx), catmull_rom_weights8(ty))
            } else {
                let z = f32x8::ZERO;
                ([f32x8::ONE - tx, tx, z, z], [f32x8::ONE - ty, ty, z, z])
            };
            let (wx, wy) = (wx.map(|w| w.to_array()), wy.map(|w| w.to_array()));
            for (lane, o) in outs.iter_mut().enumerate() {
                if fast & (1 << lane) == 0 {
                    self.sample(pos[lane][0], pos[lane][1], o);
                    continue;
                }
                if C == 4 && !CUBIC {
                    *o = self.bilinear_rgba::<AW>(i0[lane], j0[lane], wx[1][lane], wy[1][lane]);
                    continue;
                }
                let taps = if CUBIC { 4 } else { 2 };
                let k = (i0[lane] - b.x1 - lo) as usize * C;
                let mut acc = [0f32; 4];
                for (r, wyr) in wy.iter().take(taps).enumerate() {
                    let row = &self.view.row(j0[lane] - lo + r as i32)[k..k + taps * C];
                    for (px, wxc) in row.chunks_exact(C).zip(&wx) {
                        add::<T, C, AW>(&mut acc, px, wxc[lane] * wyr[lane]);
                    }
                }
                *o = if AW { unweight(acc) } else { acc };
            }
        }
    }

    /// Bilinear RGBA with all four taps inside: each pair of horizontal
    /// neighbours is one eight-wide load, blended vertically, then the two
    /// halves horizontally (`tx`, `ty`: weights of the right and upper taps).
    #[inline(always)]
    fn bilinear_rgba<const AW: bool>(&self, i0: i32, j0: i32, tx: f32, ty: f32) -> [f32; 4] {
        let k = (i0 - self.view.bounds().x1) as usize * 4;
        let load = |j: i32| {
            let v = T::load8(&self.view.row(j)[k..k + 8]);
            if AW {
                // Colour weighted by its own alpha; alpha itself stays.
                let a = v.to_array();
                v * f32x8::new([a[3], a[3], a[3], 1.0, a[7], a[7], a[7], 1.0])
            } else {
                v
            }
        };
        let (below, above) = (load(j0), load(j0 + 1));
        let v = (above - below).mul_add(f32x8::splat(ty), below).to_array();
        let acc: [f32; 4] = std::array::from_fn(|c| (v[4 + c] - v[c]).mul_add(tx, v[c]));
        if AW {
            unweight(acc)
        } else {
            acc
        }
    }

    /// `Σ w · pixel` over `taps` in their order, each resolved by the
    /// edge mode (a tap it drops, or of weight zero, adds nothing): the
    /// one-pixel sum every path falls back on, where the direct path
    /// leaves the border strip a warp pulls in from outside. One instance
    /// per channel layout, so a tap's channels are an unrolled loop.
    #[inline]
    fn accumulate(&self, taps: &[(i32, i32, f32)], out: &mut [f32; 4]) {
        match (self.view.channels(), self.alpha_weighted) {
            (_, true) => self.accumulate_in::<4, true>(taps, out),
            (4, false) => self.accumulate_in::<4, false>(taps, out),
            (3, _) => self.accumulate_in::<3, false>(taps, out),
            (2, _) => self.accumulate_in::<2, false>(taps, out),
            _ => self.accumulate_in::<1, false>(taps, out),
        }
    }

    #[inline(always)]
    fn accumulate_in<const C: usize, const AW: bool>(
        &self,
        taps: &[(i32, i32, f32)],
        out: &mut [f32; 4],
    ) {
        let b = self.view.bounds();
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
            add::<T, C, AW>(&mut acc, &self.view.pixel(i, j)[..C], w);
        }
        *out = if AW { unweight(acc) } else { acc };
    }
}

/// Adds tap `px` with weight `w`; straight-alpha RGBA (`AW`) weights colour by alpha.
#[inline(always)]
fn add<T: Sample, const C: usize, const AW: bool>(acc: &mut [f32; 4], px: &[T], w: f32) {
    if AW {
        let wa = w * px[3].to_f32();
        for c in 0..3 {
            acc[c] += wa * px[c].to_f32();
        }
        acc[3] += wa;
    } else {
        for c in 0..C {
            acc[c] += w * px[c].to_f32();
        }
    }
}

/// Converts a row of `C`-channel samples to float pixels (alpha-weighted
/// colour when `AW`), one layout per instance so the loop vectorises.
fn load<T: Sample, const C: usize, const AW: bool>(row: &[T], out: &mut Vec<[f32; 4]>) {
    // Sized first and written in place: `extend` through a mapping iterator
    // does not vectorise.
    out.clear();
    out.resize(row.len() / C, [0.0; 4]);
    for (o, px) in out.iter_mut().zip(row.chunks_exact(C)) {
        let mut v = [0f32; 4];
        for c in 0..C {
            v[c] = px[c].to_f32();
        }
        *o = if AW {
            [v[0] * v[3], v[1] * v[3], v[2] * v[3], v[3]]
        } else {
            v
        };
    }
}

/// Alpha-weighted sums back to straight colour: `acc[3] = Σ w a`,
/// colour = `Σ w a c / Σ w a`, alpha = `Σ w a`.
#[inline(always)]
fn unweight(acc: [f32; 4]) -> [f32; 4] {
    let sum_wa = acc[3];
    let inv = if sum_wa != 0.0 { 1.0 / sum_wa } else { 0.0 };
    [acc[0] * inv, acc[1] * inv, acc[2] * inv, sum_wa]
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

    /// The row path (eight positions at a time, per-layout fast paths) must
    /// give what the one-position path gives, for every layout, alpha mode,
    /// filter and sample type, inside, at the edges, outside and on centres.
    #[test]
    fn row_sampling_matches_single_samples_everywhere() {
        use crate::image::{ImageView, Layout};
        let bounds = RectI::new(3, -2, 40, 27);
        let mut seed = 0x2545f4914f6cdd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f32 / (1u64 << 53) as f32
        };
        let positions: Vec<[f32; 2]> = (0..203)
            .map(|k| match k % 7 {
                // On a pixel centre, near one, and beyond the bounds.
                0 => [10.5, 4.5],
                1 => [20.5 + 1e-6, 7.5],
                2 => [-5.0 + 60.0 * next(), -10.0 + 50.0 * next()],
                _ => [3.0 + 37.0 * next(), -2.0 + 29.0 * next()],
            })
            .collect();
        fn check<T: Sample>(bounds: RectI, positions: &[[f32; 2]], value: impl Fn(usize) -> T) {
            for channels in [1, 2, 3, 4] {
                let layout = Layout::packed(bounds, channels);
                let data: Vec<T> = (0..bounds.area() * channels).map(&value).collect();
                let view = ImageView::new(&data, layout).unwrap();
                for &filter in Filter::ALL {
                    for edge in [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror] {
                        for premultiplied in [true, false] {
                            let s = Sampler::new(
                                view,
                                PixelScale::new(1.0, 1.0, 1.0),
                                filter,
                                edge,
                                premultiplied,
                            );
                            let mut row = vec![[0f32; 4]; positions.len()];
                            s.sample_row(positions, &mut row);
                            for (p, got) in positions.iter().zip(&row) {
                                let mut want = [0f32; 4];
                                s.sample(p[0], p[1], &mut want);
                                for c in 0..channels {
                                    assert!(
                                        (got[c] - want[c]).abs() <= 1e-5 * (1.0 + want[c].abs()),
                                        "{channels} ch {filter:?} {edge:?} premult {premultiplied} at \
                                            {p:?}: {got:?} vs {want:?}"
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
        check::<f32>(bounds, &positions, |i| ((i * 7919) % 1013) as f32 / 1013.0);
        check::<u8>(bounds, &positions, |i| ((i * 7919) % 251) as u8);
        check::<u16>(bounds, &positions, |i| ((i * 7919) % 65521) as u16);
    }

    /// Nearest sampling returns the value of the pixel whose square holds
    /// the position (x in [i, i + 1) is pixel i at scale 1, [i/2, (i+1)/2)
    /// at scale 2), and so only values the source holds: IDs stay IDs.
    #[test]
    fn nearest_reads_the_pixel_the_position_falls_in() {
        use crate::image::{ImageView, Layout};
        let bounds = RectI::new(0, 0, 4, 3);
        let ids: Vec<f32> = (0..12).map(|k| (k * 10 + 7) as f32).collect();
        let view = ImageView::new(&ids, Layout::packed(bounds, 1)).unwrap();
        let at = |scale: f64, edge: EdgeMode, x: f32, y: f32| {
            let s = Sampler::new(
                view,
                PixelScale::new(scale, scale, 1.0),
                Filter::Nearest,
                edge,
                true,
            );
            let mut out = [0f32; 4];
            s.sample(x, y, &mut out);
            out[0]
        };
        let id = |i: usize, j: usize| (10 * (j * 4 + i) + 7) as f32;
        assert_eq!(at(1.0, EdgeMode::Clamp, 2.0, 1.0), id(2, 1));
        assert_eq!(at(1.0, EdgeMode::Clamp, 2.999, 1.5), id(2, 1));
        assert_eq!(at(1.0, EdgeMode::Clamp, 1.7, 0.2), id(1, 0));
        assert_eq!(at(2.0, EdgeMode::Clamp, 1.2, 0.6), id(2, 1));
        assert_eq!(at(1.0, EdgeMode::Clamp, 9.0, 1.5), id(3, 1));
        assert_eq!(at(1.0, EdgeMode::Black, 9.0, 1.5), 0.0);
        for k in 0..200 {
            let (x, y) = (k as f32 * 0.0213, (k * 7 % 31) as f32 * 0.097);
            let v = at(1.0, EdgeMode::Mirror, x, y);
            assert!(ids.contains(&v), "{v} at ({x}, {y}) is no source value");
        }
    }
}
