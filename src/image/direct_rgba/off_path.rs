//! Bilinear pixels the direct path's four-at-a-time loop leaves: taps past
//! an edge, positions on or near a centre line, positions not finite.
//! Under 1 % of a warp's pixels, nearly all at the frame's edges; computed
//! here with the general sampler's arithmetic, bit for bit, without its
//! per-tap branches.

use wide::{f32x4, u32x4};

use super::Taps;
use crate::image::kernel::split;
use crate::image::Sample;

impl<T: Sample> Taps<'_, T> {
    /// A pixel off the fast path: bicubic by the caller's `slow`, bilinear
    /// by [`Self::bilinear_at`].
    #[inline(always)]
    pub(super) fn off_path(&self, xy: [f32; 2], slow: impl FnOnce() -> [f32; 4]) -> [f32; 4] {
        match self.cubic {
            true => slow(),
            false => self.bilinear_at(xy),
        }
    }

    /// The bilinear value at canonical position `[x, y]` wherever the fast
    /// path does not take it (taps past an edge, on or near a centre line,
    /// not finite): bit for bit [`crate::image::Sampler::sample`], whose
    /// steps it takes (the same split and weights, each tap's product added
    /// in turn to a sum from zero, a tap the edge drops or of weight zero
    /// skipped), four channels at once, each axis's two taps resolved
    /// once, and a select where that takes a branch: an edge pixel's taps
    /// fall either side of the edge, so those branches went either way.
    /// Out of line: under 1 % of a warp's pixels come here, and the fast
    /// loop stays small.
    #[inline(never)]
    fn bilinear_at(&self, [x, y]: [f32; 2]) -> [f32; 4] {
        if !(x.is_finite() && y.is_finite()) {
            return [0.0; 4];
        }
        let [sx, sy, ..] = self.scale.to_array();
        let (i0, tx) = split(x * sx - 0.5);
        let (j0, ty) = split(y * sy - 0.5);
        if tx == 0.0 && ty == 0.0 {
            return self.centre(i0, j0);
        }
        let (below, above) = (self.row(j0), self.row(j0 + 1));
        let (left, right) = (self.column(i0), self.column(i0 + 1));
        let taps = [
            (left, below, (1.0 - tx) * (1.0 - ty)),
            (right, below, tx * (1.0 - ty)),
            (left, above, (1.0 - tx) * ty),
            (right, above, tx * ty),
        ];
        let mut sum = f32x4::ZERO;
        for ((i, in_x), (row, in_y), w) in taps {
            let counts = in_x && in_y && w != 0.0;
            let keep = u32x4::splat(u32::from(counts).wrapping_neg());
            sum = keep.select(sum + f32x4::splat(w) * self.pixel_at(row + i), sum);
        }
        sum.to_array()
    }

    /// On a pixel centre: the pixel itself where it lies inside, else the
    /// one tap the general sampler sums (`0 + 1 · px`, which differs from
    /// `px` in the sign of a zero).
    #[cold]
    fn centre(&self, i: i32, j: i32) -> [f32; 4] {
        let ((row, in_y), (column, in_x)) = (self.row(j), self.column(i));
        let px = self.pixel_at(row + column);
        let b = self.bounds;
        if (b.x1..b.x2).contains(&i) && (b.y1..b.y2).contains(&j) {
            px.to_array()
        } else if in_x && in_y {
            (f32x4::ZERO + f32x4::ONE * px).to_array()
        } else {
            [0.0; 4]
        }
    }

    /// Column `i`, anywhere, as the edge mode reads it: the offset of its
    /// pixels in a row, and whether it counts at all (not where the edge
    /// is black).
    #[inline(always)]
    fn column(&self, i: i32) -> (i64, bool) {
        let (i, inside) = self.edge.read(i, self.bounds.x1, self.bounds.x2);
        (i64::from(i - self.bounds.x1) * 4, inside)
    }

    /// Row `j` likewise: the index its pixels count from.
    #[inline(always)]
    fn row(&self, j: i32) -> (i64, bool) {
        let (j, inside) = self.edge.read(j, self.bounds.y1, self.bounds.y2);
        let start = i64::from(self.corner) + i64::from(j - self.bounds.y1) * i64::from(self.stride);
        (start, inside)
    }

    /// The pixel at index `at` (a [`Self::row`] plus a [`Self::column`]):
    /// inside the buffer, which fits `i32`.
    #[inline(always)]
    fn pixel_at(&self, at: i64) -> f32x4 {
        let at = at as usize;
        let px = &self.data[at..at + 4];
        f32x4::new(std::array::from_fn(|c| px[c].to_f32()))
    }
}

#[cfg(test)]
mod tests {
    use crate::geom::{PixelScale, RectI};
    use crate::image::{EdgeMode, Filter, ImageView, Layout, Sample, Sampler};

    /// Pixels off the fast path take [`Taps::bilinear_at`], which must give
    /// what the general sampler gives, bit for bit (NaN for NaN), for every
    /// edge mode, layout, sample type and scale: positions inside, past
    /// each edge, far out, on and near centres inside and out, not finite;
    /// values that make skipping a tap matter (−0, ∞, NaN).
    #[test]
    fn bilinear_off_the_fast_path_is_the_general_samplers_bit_for_bit() {
        let bounds = RectI::new(-3, 2, 17, 13);
        let value = |k: usize| match k % 23 {
            0 => -0.0,
            5 => f32::INFINITY,
            11 => f32::NAN,
            _ => ((k * 7919) % 1013) as f32 / 1013.0 - 0.2,
        };
        let n = bounds.area() * 4;
        check(bounds, &(0..n).map(value).collect::<Vec<f32>>());
        let bytes: Vec<u8> = (0..n).map(|k| (k * 7919 % 256) as u8).collect();
        check(bounds, &bytes);
        let shorts: Vec<u16> = (0..n).map(|k| (k * 7919 % 65536) as u16).collect();
        check(bounds, &shorts);
    }

    fn check<T: Sample>(bounds: RectI, packed: &[T]) {
        // Top row first, padded rows, a lead-in: as hosts lend buffers.
        let (flipped, top_down) =
            crate::testing::top_down(packed, bounds, 4, (12, 9), T::default());
        let views = [
            ImageView::new(packed, Layout::packed(bounds, 4)).unwrap(),
            ImageView::new(&flipped, top_down).unwrap(),
        ];
        for (view, scale) in views.into_iter().flat_map(|v| [(v, 1.0), (v, 0.5)]) {
            let canonical = |p: [f32; 2]| p.map(|v| v / scale as f32);
            let positions: Vec<[f32; 2]> = positions(bounds).into_iter().map(canonical).collect();
            for edge in [EdgeMode::Black, EdgeMode::Clamp, EdgeMode::Mirror] {
                let s = Sampler::new(
                    view,
                    PixelScale::new(scale, scale, 1.0),
                    Filter::Bilinear,
                    edge,
                    true,
                );
                let taps = s.direct_taps().expect("RGBA takes the direct path");
                for &[x, y] in &positions {
                    let mut want = [0f32; 4];
                    s.sample(x, y, &mut want);
                    let got = taps.bilinear_at([x, y]);
                    let same = got
                        .iter()
                        .zip(want)
                        .all(|(g, w)| g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()));
                    assert!(
                        same,
                        "{edge:?} at ({x}, {y}) scale {scale}: {got:?} vs {want:?}"
                    );
                }
            }
        }
    }

    /// Pixel-index positions (centres at integers + 0.5) of every kind.
    fn positions(b: RectI) -> Vec<[f32; 2]> {
        let mut p = crate::testing::awkward_positions(b, 600, 11);
        let (x1, y1, x2, y2) = (b.x1 as f32, b.y1 as f32, b.x2 as f32, b.y2 as f32);
        for k in 0..40 {
            let f = k as f32 * 0.173 % 1.0;
            p.extend([
                // Along each edge, the taps either side of it.
                [x1 + f - 0.5, y1 + 3.0 * f + 1.0],
                [x2 - f + 0.5, y1 + 5.0 * f + 2.0],
                [x1 + 7.0 * f + 1.0, y1 + f - 0.5],
                [x1 + 9.0 * f + 2.0, y2 - f + 0.5],
                // Corners and far out.
                [x1 - 0.5 * f, y2 + 0.5 * f],
                [x1 - 40.0 * f - 3.0, y1 - 100.0 * f],
            ]);
        }
        p.extend([
            [x1 - 2.5, y1 + 3.5],
            [x2 + 1.5, y2 + 0.5],
            [x1 + 2.5, y1 + 1.5],
            [x1 + 2.5 + 2e-5, y1 + 1.5 - 2e-5],
            [x1 - 0.5 + 3e-5, y1 + 4.25],
            [x2 - 0.5, y2 - 0.5],
            [1e30, 5.0],
            [-1e30, -1e30],
            [f32::INFINITY, y1 + 1.0],
            [x1 + 1.0, f32::NEG_INFINITY],
            [x1 + 1.0, f32::NAN],
        ]);
        p
    }
}
