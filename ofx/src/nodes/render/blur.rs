//! Motion blur's mean: the samples of a blurred frame, each rendered in
//! float over the window, summed, and written once at the output's depth
//! (rounded once, not per sample).

use morphfx::geom::RectI;
use morphfx::image::resample::fill;
use morphfx::image::{Image, RowsMut, Sample};

/// The running sum of a frame's samples.
pub(super) struct Mean {
    sum: Image,
    samples: usize,
}

impl Mean {
    /// An empty sum over `window`, `channels` deep.
    pub(super) fn new(window: RectI, channels: usize) -> Mean {
        Mean {
            sum: Image::new(window, channels),
            samples: 0,
        }
    }

    /// A new image to render one sample into.
    pub(super) fn sample(&self) -> Image {
        Image::new(self.sum.bounds, self.sum.channels)
    }

    /// Adds one sample.
    pub(super) fn add(&mut self, one: &Image) {
        for (s, v) in self.sum.data.iter_mut().zip(&one.data) {
            *s += v;
        }
        self.samples += 1;
    }

    /// The mean into `rows`.
    pub(super) fn write<D: Sample>(&self, rows: RowsMut<'_, D>) {
        let k = 1.0 / self.samples.max(1) as f32;
        fill(rows, self.sum.channels, |i, j, px| {
            for (p, v) in px.iter_mut().zip(self.sum.pixel(i, j)) {
                *p = v * k;
            }
        });
    }
}
