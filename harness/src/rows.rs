//! Pictures as rows of float samples, the top row first: how image files,
//! numpy and the Python module hold them. Plates hold their rows bottom-up
//! in canonical coordinates; these convert between the two over a plate's
//! display window.

use morphfx::geom::RectI;
use morphfx::image::Image;

use crate::plate::{rgba, Plate};

/// A picture as rows of float samples, the top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    pub data: Vec<f32>,
}

impl Rows {
    /// The display window `size` of `image` as RGBA rows (fewer channels
    /// widened as files store them), black where `image` has no pixels.
    pub fn of_window(image: &Image, (width, height): (usize, usize)) -> Rows {
        let b = image.bounds;
        let mut data = vec![0.0f32; width * height * 4];
        let rows = data.chunks_exact_mut((width * 4).max(1));
        for (row, j) in rows.zip((0..height as i32).rev()) {
            if !(b.y1..b.y2).contains(&j) {
                continue;
            }
            for (px, i) in row.chunks_exact_mut(4).zip(0..width as i32) {
                if (b.x1..b.x2).contains(&i) {
                    px.copy_from_slice(&rgba(image.pixel(i, j)));
                }
            }
        }
        Rows {
            width,
            height,
            channels: 4,
            data,
        }
    }

    /// A plate's display window as RGBA rows.
    pub fn of_plate(plate: &Plate) -> Rows {
        Rows::of_window(&plate.image, plate.size)
    }

    /// The rows as a plate whose display window they fill.
    pub fn to_plate(&self) -> Plate {
        let (w, h) = (self.width, self.height);
        let bounds = RectI::new(0, 0, w as i32, h as i32);
        let row_len = w * self.channels;
        let mut data = Vec::with_capacity(self.data.len());
        for row in self.data.chunks_exact(row_len.max(1)).rev() {
            data.extend_from_slice(row);
        }
        let image = Image {
            bounds,
            channels: self.channels,
            data,
        };
        Plate::new(image, (w, h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Canonical row 0 is the bottom one; the top row comes first in rows.
    #[test]
    fn the_top_row_comes_first_and_round_trips() {
        let image = Image::from_fn(RectI::new(0, 0, 3, 2), 4, |i, j, c| {
            (10 * j + i) as f32 + c as f32 / 10.0
        });
        let rows = Rows::of_window(&image, (3, 2));
        assert_eq!(&rows.data[..4], &[10.0, 10.1, 10.2, 10.3]);
        assert_eq!(&rows.data[12..16], &[0.0, 0.1, 0.2, 0.3]);
        assert_eq!(rows.to_plate().image, image);
    }

    /// Pixels outside the data window are black; RGB is made opaque.
    #[test]
    fn a_smaller_data_window_is_padded_with_black() {
        let image = Image::from_fn(RectI::new(1, 0, 2, 1), 3, |_, _, _| 0.5);
        let rows = Rows::of_window(&image, (2, 2));
        let px = |k: usize| &rows.data[4 * k..4 * k + 4];
        assert_eq!(px(0), &[0.0; 4]);
        assert_eq!(px(1), &[0.0; 4]);
        assert_eq!(px(2), &[0.0; 4]);
        assert_eq!(px(3), &[0.5, 0.5, 0.5, 1.0]);
    }
}
