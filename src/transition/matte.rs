//! A timing matte: an image whose alpha says when each point of A has its
//! turn. It plays the part of a procedural pattern's `g(p)` (Lee et al.
//! §4.2), painted or rotoscoped by the user instead of computed, and is
//! paced the same way ([`super::pace::paced`]).

use std::fmt;
use std::hash::Hasher;

use crate::error::{Error, Result};
use crate::geom::{PixelScale, RectI, Vec2};

/// A matte's alpha over a pixel window, read as `g(p)` at canonical points.
#[derive(Clone)]
pub struct Matte {
    /// The pixels it covers, at `scale`.
    window: RectI,
    /// Its pixels per canonical unit.
    scale: PixelScale,
    /// Alpha per pixel, rows bottom-up, each in `[0, 1]`.
    alpha: Vec<f32>,
    /// A digest of everything above: what cache keys see of the matte.
    digest: u64,
}

impl Matte {
    /// A matte from `alpha`, one value per pixel of `window` (rows bottom-up).
    /// Values are clamped to `[0, 1]`; NaN counts as 0, the turn of the first.
    pub fn new(window: RectI, scale: PixelScale, mut alpha: Vec<f32>) -> Result<Matte> {
        if alpha.len() != window.area() {
            return Err(Error::Invalid(format!(
                "timing matte: {} values for a {}x{} window",
                alpha.len(),
                window.width(),
                window.height()
            )));
        }
        for a in &mut alpha {
            *a = if a.is_nan() { 0.0 } else { a.clamp(0.0, 1.0) };
        }
        let mut h = std::hash::DefaultHasher::new();
        for v in [window.x1, window.y1, window.x2, window.y2] {
            h.write_i32(v);
        }
        h.write_u64(scale.x.to_bits());
        h.write_u64(scale.y.to_bits());
        for a in &alpha {
            h.write_u32(a.to_bits());
        }
        let digest = h.finish();
        Ok(Matte {
            window,
            scale,
            alpha,
            digest,
        })
    }

    /// `g(p)`: the alpha at canonical `p`, bilinear between pixel centres,
    /// held at the edge pixels' values beyond them. Held, not 0, outside
    /// the window: a warp near the frame's edge reads A from just outside
    /// it, and a 0 there gave those pixels B's turn, a sliver of B along
    /// an edge the matte holds on A. (A matte cropped to its bounding box
    /// has edges of 0, and holds them.)
    pub fn order(&self, p: Vec2) -> f64 {
        let w = self.window;
        if w.is_empty() {
            return 0.0;
        }
        let q = self.scale.to_pixel(p);
        if !(q.x.is_finite() && q.y.is_finite()) {
            return 0.0;
        }
        // Continuous pixel coordinates from the first pixel's centre.
        let fx = (q.x - 0.5 - w.x1 as f64).clamp(0.0, (w.width() - 1) as f64);
        let fy = (q.y - 0.5 - w.y1 as f64).clamp(0.0, (w.height() - 1) as f64);
        let (i0, j0) = (fx.floor() as usize, fy.floor() as usize);
        let (i1, j1) = ((i0 + 1).min(w.width() - 1), (j0 + 1).min(w.height() - 1));
        let (u, v) = (fx - i0 as f64, fy - j0 as f64);
        let at = |i: usize, j: usize| self.alpha[j * w.width() + i] as f64;
        let bottom = at(i0, j0) + (at(i1, j0) - at(i0, j0)) * u;
        let top = at(i0, j1) + (at(i1, j1) - at(i0, j1)) * u;
        bottom + (top - bottom) * v
    }
}

impl PartialEq for Matte {
    fn eq(&self, o: &Matte) -> bool {
        self.digest == o.digest
            && self.window == o.window
            && self.scale == o.scale
            && self.alpha == o.alpha
    }
}

/// The window, scale and digest, never the pixels: warps are cached by
/// their settings' debug text.
impl fmt::Debug for Matte {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Matte {{ window: {:?}, scale: {:?}, digest: {:016x} }}",
            self.window, self.scale, self.digest
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4x2 matte at render scale 0.5: pixel (i, j) covers canonical
    /// [2i, 2i + 2] x [2j, 2j + 2].
    fn matte() -> Matte {
        let window = RectI::new(10, 5, 14, 7);
        let alpha = vec![0.0, 0.25, 0.5, 1.0, 0.1, 0.2, 0.3, 0.4];
        Matte::new(window, PixelScale::new(0.5, 0.5, 1.0), alpha).unwrap()
    }

    #[test]
    fn pixel_centres_read_their_own_alpha_and_between_is_bilinear() {
        let m = matte();
        // Pixel (11, 5)'s centre: canonical (23, 11).
        assert_eq!(m.order(Vec2::new(23.0, 11.0)), 0.25);
        assert_eq!(m.order(Vec2::new(27.0, 13.0)), 0.4f32 as f64);
        // Half way between columns 10 and 11, and between rows 5 and 6.
        let g = m.order(Vec2::new(22.0, 12.0));
        let want = 0.5 * (0.0 + 0.25) / 2.0 + 0.5 * (0.1f32 as f64 + 0.2f32 as f64) / 2.0;
        assert!((g - want).abs() < 1e-12, "{g} vs {want}");
        // Held at the edge pixels, up to the window's edge and past it.
        assert_eq!(m.order(Vec2::new(20.2, 10.1)), 0.0);
        assert_eq!(m.order(Vec2::new(27.9, 11.0)), 1.0);
        assert_eq!(m.order(Vec2::new(28.1, 11.0)), 1.0);
        assert_eq!(m.order(Vec2::new(500.0, 11.0)), 1.0);
        assert_eq!(m.order(Vec2::new(23.0, 9.9)), 0.25);
        assert_eq!(m.order(Vec2::new(-1e9, 1e9)), 0.1f32 as f64);
    }

    #[test]
    fn values_are_clamped_and_the_debug_text_follows_content() {
        let w = RectI::new(0, 0, 2, 1);
        let m = Matte::new(w, PixelScale::UNIT, vec![f32::NAN, 7.0]).unwrap();
        assert_eq!(m.order(Vec2::new(0.5, 0.5)), 0.0);
        assert_eq!(m.order(Vec2::new(1.5, 0.5)), 1.0);
        let same = Matte::new(w, PixelScale::UNIT, vec![0.0, 1.0]).unwrap();
        let other = Matte::new(w, PixelScale::UNIT, vec![0.0, 0.5]).unwrap();
        assert_eq!(format!("{m:?}"), format!("{same:?}"));
        assert_ne!(format!("{m:?}"), format!("{other:?}"));
        assert!(Matte::new(w, PixelScale::UNIT, vec![0.0]).is_err());
    }
}
