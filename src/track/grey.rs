//! Grey frames and their pyramids: what the tracker looks at.
//!
//! A frame becomes one luminance plane (colour does not help a template
//! tracker much, and one plane is a third of the work), then a pyramid of
//! halvings so fast motion is found coarse and refined fine.

use rayon::prelude::*;

use crate::geom::{RectI, Vec2};
use crate::image::{ImageView, Sample};

/// One plane of luminance over a pixel rectangle, rows bottom-up.
#[derive(Debug, Clone)]
pub struct Grey {
    /// The pixel rectangle it covers, in this level's pixels.
    pub bounds: RectI,
    data: Vec<f32>,
}

impl Grey {
    /// Rec. 709 luminance of a view's colour (grey for one or two
    /// channels); NaN and infinite samples count as black.
    pub fn from_view<S: Sample>(view: &ImageView<'_, S>) -> Grey {
        let b = view.bounds();
        let c = view.channels();
        let mut data = vec![0f32; b.area()];
        data.par_chunks_mut(b.width().max(1))
            .enumerate()
            .for_each(|(r, out)| {
                for (o, px) in out
                    .iter_mut()
                    .zip(view.row(b.y1 + r as i32).chunks_exact(c))
                {
                    let v = if c >= 3 {
                        0.2126 * px[0].to_f32() + 0.7152 * px[1].to_f32() + 0.0722 * px[2].to_f32()
                    } else {
                        px[0].to_f32()
                    };
                    *o = if v.is_finite() { v } else { 0.0 };
                }
            });
        Grey { bounds: b, data }
    }

    /// A plane whose pixel `(i, j)` is `f(i, j)`.
    pub fn from_fn(bounds: RectI, f: impl Fn(i32, i32) -> f32 + Sync) -> Grey {
        let w = bounds.width().max(1);
        let mut data = vec![0f32; bounds.area()];
        data.par_chunks_mut(w).enumerate().for_each(|(r, out)| {
            let j = bounds.y1 + r as i32;
            for (k, o) in out.iter_mut().enumerate() {
                *o = f(bounds.x1 + k as i32, j);
            }
        });
        Grey { bounds, data }
    }

    fn at(&self, i: i32, j: i32) -> f32 {
        let b = &self.bounds;
        let i = i.clamp(b.x1, b.x2 - 1) - b.x1;
        let j = j.clamp(b.y1, b.y2 - 1) - b.y1;
        self.data[j as usize * b.width() + i as usize]
    }

    /// The plane at `p` (this level's canonical coordinates, pixel centres
    /// at half-integers), bilinear, the edge pixels held outside.
    pub fn sample(&self, p: Vec2) -> f32 {
        let (u, v) = (p.x - 0.5, p.y - 0.5);
        let (i, j) = (u.floor(), v.floor());
        let (fx, fy) = ((u - i) as f32, (v - j) as f32);
        let (i, j) = (i as i32, j as i32);
        let top = self.at(i, j) * (1.0 - fx) + self.at(i + 1, j) * fx;
        let bottom = self.at(i, j + 1) * (1.0 - fx) + self.at(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Whether `p` lies inside the plane's rectangle.
    pub fn contains(&self, p: Vec2) -> bool {
        let b = &self.bounds;
        p.x >= b.x1 as f64 && p.x <= b.x2 as f64 && p.y >= b.y1 as f64 && p.y <= b.y2 as f64
    }

    /// Half the resolution: pixel `i` of the result covers `[2i, 2i + 2]`
    /// here, filtered by `[1 3 3 1] / 8` across pixels `2i - 1 ..= 2i + 2`
    /// in each direction (centred on that span, so coordinates simply halve).
    pub fn half(&self) -> Grey {
        let b = &self.bounds;
        let h = RectI::new(
            b.x1.div_euclid(2),
            b.y1.div_euclid(2),
            (b.x2 + 1).div_euclid(2),
            (b.y2 + 1).div_euclid(2),
        );
        const TAPS: [f32; 4] = [0.125, 0.375, 0.375, 0.125];
        // Horizontal first, over this plane's rows, then vertical.
        let across = Grey::from_fn(RectI::new(h.x1, b.y1, h.x2, b.y2), |i, j| {
            (0..4)
                .map(|k| TAPS[k] * self.at(2 * i - 1 + k as i32, j))
                .sum()
        });
        Grey::from_fn(h, |i, j| {
            (0..4)
                .map(|k| TAPS[k] * across.at(i, 2 * j - 1 + k as i32))
                .sum()
        })
    }
}

/// A frame's grey plane and its halvings, finest first.
#[derive(Debug, Clone)]
pub struct Pyramid {
    /// Level `k` is `2^k` times coarser than level 0.
    pub levels: Vec<Grey>,
}

impl Pyramid {
    /// Halvings of `grey` while the smaller side stays at least `min_side`
    /// pixels, up to `max_levels` levels in all.
    pub fn new(grey: Grey, max_levels: usize, min_side: usize) -> Pyramid {
        let mut levels = vec![grey];
        while levels.len() < max_levels.max(1) {
            let last = levels.last().expect("one level at least");
            let next = last.half();
            if next.bounds.width().min(next.bounds.height()) < min_side {
                break;
            }
            levels.push(next);
        }
        Pyramid { levels }
    }

    /// The bytes it holds, for caches.
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|g| g.data.len() * 4).sum()
    }
}
