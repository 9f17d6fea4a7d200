//! Dialling an effect back where a compositor asks, as every Nuke node and
//! openfx-misc plugin does with its mask input and Mix:
//! `out = src + (effect − src) · mix · m`, `m` the mask's alpha at the pixel
//! (`1 − alpha` inverted; 1 with no mask).

use super::Warped;
use crate::geom::RectI;
use crate::image::resample::fill_rows;
use crate::image::{Image, RowsMut, Sample};

/// What the effect is mixed back toward, and by how much.
pub struct Mix<'a, S> {
    /// The unaltered picture (the node's main source, unwarped).
    pub source: Warped<'a, S>,
    /// The mask's alpha, one channel covering the output ([`mask_plane`]);
    /// `None`: no mask, 1 everywhere (inverting a mask that is not there
    /// changes nothing, as in Nuke).
    pub mask: Option<&'a Image>,
    /// How much of the effect, `[0, 1]`.
    pub amount: f32,
    /// Use `1 − alpha` as the mask.
    pub invert: bool,
}

impl<S: Sample> Mix<'_, S> {
    /// Whether the output is the effect unaltered everywhere.
    pub fn is_full(&self) -> bool {
        self.amount >= 1.0 && self.mask.is_none()
    }

    /// The weight of the effect at pixel `k` of a mask row.
    #[inline]
    fn weight(&self, mask_row: Option<&[f32]>, k: usize) -> f32 {
        match mask_row {
            None => self.amount,
            Some(row) => {
                let a = row[k].clamp(0.0, 1.0);
                self.amount * if self.invert { 1.0 - a } else { a }
            }
        }
    }
}

/// A mask's alpha at every pixel of `window` (`mask` seen through the
/// identity map, so a mask of another size or region lines up by canonical
/// position; transparent outside its region): alpha of RGBA and alpha-only
/// masks, the mean of an RGB one.
pub fn mask_plane<M: Sample>(mask: Warped<'_, M>, window: RectI) -> Image {
    let mut plane = Image::new(window, 1);
    fill_rows(plane.view_mut().rows(), 1, |j, x1, row, _| {
        mask.row_as(j, x1, 1, row);
    });
    plane
}

/// `dst = src + (effect − src) · amount · m` per pixel, `effect` an image
/// covering `dst`'s bounds in `dst`'s channel layout. Computed in float and
/// stored once, so integer outputs are rounded once.
pub fn mix<S: Sample, D: Sample>(effect: &Image, how: &Mix<'_, S>, dst: RowsMut<'_, D>) {
    let dc = dst.channels;
    debug_assert_eq!(effect.channels, dc);
    debug_assert_eq!(effect.bounds, dst.bounds);
    let (fx, mask) = (effect.view(), how.mask.map(Image::view));
    let x0 = dst.bounds.x1;
    fill_rows(dst, dc, |j, x1, row, spare| {
        let n = row.len();
        let (e, k0) = (fx.row(j), (x1 - x0) as usize);
        spare.resize(n, [0.0; 4]);
        how.source.row_as(j, x1, dc, spare);
        let m = mask
            .as_ref()
            .map(|m| &m.row(j)[(x1 - m.bounds().x1) as usize..]);
        for (k, (out, src)) in row.iter_mut().zip(spare.iter()).enumerate() {
            let w = how.weight(m, k);
            for c in 0..dc {
                out[c] = src[c] + (e[(k0 + k) * dc + c] - src[c]) * w;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{PixelScale, RectI};
    use crate::image::{EdgeMode, Filter, ImageView, Layout, Sampler, WarpMap};

    /// Source 0.2, effect 0.8 everywhere; the mask an alpha ramp over a
    /// smaller region than the output (0 outside it).
    #[test]
    fn the_closed_form_with_a_mask_of_another_region() {
        let out = RectI::new(0, 0, 6, 2);
        let src = Image::from_fn(out, 4, |_, _, _| 0.2);
        let effect = Image::from_fn(out, 4, |_, _, _| 0.8);
        let mask_bounds = RectI::new(1, 0, 4, 2);
        let mask = Image::from_fn(mask_bounds, 1, |i, _, _| 0.25 * i as f32);
        fn sampler(img: &Image) -> Sampler<'_, f32> {
            Sampler::new(
                ImageView::new(&img.data, Layout::packed(img.bounds, img.channels)).unwrap(),
                PixelScale::UNIT,
                Filter::Bilinear,
                EdgeMode::Black,
                true,
            )
        }
        let (s, m) = (sampler(&src), sampler(&mask));
        let identity = WarpMap::identity(out, PixelScale::UNIT);
        let plane = mask_plane(Warped::Map(&m, &identity), out);
        for invert in [false, true] {
            let how = Mix {
                source: Warped::Map(&s, &identity),
                mask: Some(&plane),
                amount: 0.5,
                invert,
            };
            let mut dst = Image::new(out, 4);
            mix(&effect, &how, dst.view_mut().rows());
            for i in 0..6 {
                let alpha = if (1..4).contains(&i) {
                    0.25 * i as f32
                } else {
                    0.0
                };
                let m = if invert { 1.0 - alpha } else { alpha };
                let want = 0.2 + (0.8 - 0.2) * 0.5 * m;
                for c in 0..4 {
                    let got = dst.pixel(i, 1)[c];
                    assert!(
                        (got - want).abs() < 1e-6,
                        "i {i} invert {invert}: {got} vs {want}"
                    );
                }
            }
        }
        // No mask: the amount alone, inverted or not.
        for invert in [false, true] {
            let how = Mix {
                source: Warped::Map(&s, &identity),
                mask: None,
                amount: 0.25,
                invert,
            };
            let mut dst = Image::new(out, 4);
            mix(&effect, &how, dst.view_mut().rows());
            assert!((dst.pixel(3, 0)[0] - 0.35).abs() < 1e-6);
        }
    }
}
