//! Images as views over rows with any stride (negative too, as hosts send), so
//! the plugin can wrap host buffers without copying, and owned float images for
//! the harness and tests.
//!
//! A view's rows are addressed bottom-up in canonical pixel indices: pixel
//! `(i, j)` of `bounds` starts at `base + (j - y1) * row_stride + (i - x1) * channels`.

pub(crate) mod direct_rgba;
mod edge;
mod kernel;
mod layer_names;
pub mod resample;
mod sample;
mod warp_map;

pub use edge::EdgeMode;
pub use layer_names::holds_ids;
pub use resample::{resample, ResampleSettings};
pub use sample::{Filter, Sampler};
pub use warp_map::WarpMap;

use crate::error::{Error, Result};
use crate::geom::RectI;

/// A pixel component type a host may send: 8-bit, 16-bit or 32-bit float.
pub trait Sample: Copy + Send + Sync + Default + PartialEq + std::fmt::Debug + 'static {
    /// The sample as a float (8- and 16-bit scaled to `[0, 1]`).
    fn to_f32(self) -> f32;
    /// The nearest sample to `v` (clamped for integer types).
    fn from_f32(v: f32) -> Self;

    /// The first eight samples of `s` as floats.
    #[inline(always)]
    fn load8(s: &[Self]) -> wide::f32x8 {
        wide::f32x8::new(std::array::from_fn(|q| s[q].to_f32()))
    }

    /// The samples themselves when they already are floats, so float images
    /// can be written without a conversion pass.
    #[inline(always)]
    fn as_f32_mut(_s: &mut [Self]) -> Option<&mut [f32]> {
        None
    }

    /// Read-only [`Sample::as_f32_mut`]: float rows copied, not converted.
    #[inline(always)]
    fn as_f32(_s: &[Self]) -> Option<&[f32]> {
        None
    }
}

impl Sample for f32 {
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn load8(s: &[f32]) -> wide::f32x8 {
        wide::f32x8::new(*s.first_chunk::<8>().expect("eight samples"))
    }
    #[inline(always)]
    fn as_f32_mut(s: &mut [f32]) -> Option<&mut [f32]> {
        Some(s)
    }
    #[inline(always)]
    fn as_f32(s: &[f32]) -> Option<&[f32]> {
        Some(s)
    }
}

impl Sample for u8 {
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as f32 * (1.0 / 255.0)
    }
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        (v * 255.0 + 0.5).clamp(0.0, 255.0) as u8
    }
}

impl Sample for u16 {
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self as f32 * (1.0 / 65535.0)
    }
    #[inline(always)]
    fn from_f32(v: f32) -> Self {
        (v * 65535.0 + 0.5).clamp(0.0, 65535.0) as u16
    }
}

/// Where each row of a view lives in its slice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Pixels covered (at the image's own scale).
    pub bounds: RectI,
    /// Components per pixel, 1 to 4.
    pub channels: usize,
    /// Index of pixel `(x1, y1)`.
    pub base: usize,
    /// Elements from one row to the next row up (negative for top-down memory).
    pub row_stride: isize,
}

impl Layout {
    /// Tightly packed rows, bottom row first.
    pub fn packed(bounds: RectI, channels: usize) -> Self {
        Layout {
            bounds,
            channels,
            base: 0,
            row_stride: (bounds.width() * channels) as isize,
        }
    }

    #[inline]
    fn row_start(&self, j: i32) -> usize {
        (self.base as isize + (j - self.bounds.y1) as isize * self.row_stride) as usize
    }

    #[inline]
    fn row_len(&self) -> usize {
        self.bounds.width() * self.channels
    }

    /// Checks that every row lies inside a slice of `len` elements and that rows do not overlap.
    fn check(&self, len: usize) -> Result<()> {
        if self.channels == 0 {
            return Err(Error::Invalid("image has no channels".into()));
        }
        if self.bounds.is_empty() {
            return Ok(());
        }
        if (self.row_stride.unsigned_abs()) < self.row_len() && self.bounds.height() > 1 {
            return Err(Error::Invalid(format!(
                "image rows overlap: stride {} elements for rows of {}",
                self.row_stride,
                self.row_len()
            )));
        }
        let first = self.base as isize;
        let last = first + (self.bounds.height() as isize - 1) * self.row_stride;
        let (lo, hi) = (first.min(last), first.max(last) + self.row_len() as isize);
        if lo < 0 || hi as usize > len {
            return Err(Error::Invalid(format!(
                "image rows reach outside their buffer ({lo}..{hi} of {len} elements)"
            )));
        }
        Ok(())
    }
}

/// A read-only image borrowed from someone else's buffer (a host's, or an [`Image`]).
#[derive(Debug, Clone, Copy)]
pub struct ImageView<'a, T> {
    data: &'a [T],
    layout: Layout,
}

impl<'a, T: Sample> ImageView<'a, T> {
    /// A view of `data` laid out as `layout`; refused when the layout reaches outside
    /// `data`.
    pub fn new(data: &'a [T], layout: Layout) -> Result<Self> {
        layout.check(data.len())?;
        Ok(ImageView { data, layout })
    }
    /// Pixels covered.
    #[inline]
    pub fn bounds(&self) -> RectI {
        self.layout.bounds
    }
    /// Components per pixel.
    #[inline]
    pub fn channels(&self) -> usize {
        self.layout.channels
    }
    /// Row `j` (must be inside the bounds), `width * channels` elements.
    #[inline]
    pub fn row(&self, j: i32) -> &'a [T] {
        let s = self.layout.row_start(j);
        &self.data[s..s + self.layout.row_len()]
    }
    /// Pixel `(i, j)` (must be inside the bounds).
    #[inline]
    pub fn pixel(&self, i: i32, j: i32) -> &'a [T] {
        let c = self.layout.channels;
        let k = self.layout.row_start(j) + (i - self.layout.bounds.x1) as usize * c;
        &self.data[k..k + c]
    }
}

/// A writable image borrowed from someone else's buffer.
#[derive(Debug)]
pub struct ImageViewMut<'a, T> {
    data: &'a mut [T],
    layout: Layout,
}

impl<'a, T: Sample> ImageViewMut<'a, T> {
    /// A writable view of `data` laid out as `layout`; refused when the layout reaches
    /// outside `data`.
    pub fn new(data: &'a mut [T], layout: Layout) -> Result<Self> {
        layout.check(data.len())?;
        Ok(ImageViewMut { data, layout })
    }
    /// Pixels covered.
    #[inline]
    pub fn bounds(&self) -> RectI {
        self.layout.bounds
    }
    /// Components per pixel.
    #[inline]
    pub fn channels(&self) -> usize {
        self.layout.channels
    }
    /// The same pixels, read-only.
    pub fn as_view(&self) -> ImageView<'_, T> {
        ImageView {
            data: self.data,
            layout: self.layout,
        }
    }
    /// The view as disjoint rows, ready to be written in parallel.
    pub fn rows(&mut self) -> RowsMut<'_, T> {
        RowsMut {
            bounds: self.layout.bounds,
            channels: self.layout.channels,
            rows: self.rows_mut(),
        }
    }

    /// Every row as its own mutable slice, `(j, row)`, so rows can be written
    /// in parallel whatever the stride's sign.
    pub fn rows_mut(&mut self) -> Vec<(i32, &mut [T])> {
        let l = self.layout;
        let mut starts: Vec<(usize, i32)> = (l.bounds.y1..l.bounds.y2)
            .map(|j| (l.row_start(j), j))
            .collect();
        starts.sort_unstable();
        let mut rows = Vec::with_capacity(starts.len());
        let mut rest: &mut [T] = self.data;
        let mut consumed = 0;
        for (start, j) in starts {
            let tail = std::mem::take(&mut rest);
            let (_, tail) = tail.split_at_mut(start - consumed);
            let (row, tail) = tail.split_at_mut(l.row_len());
            consumed = start + l.row_len();
            rest = tail;
            rows.push((j, row));
        }
        rows
    }
}

/// Output pixels as disjoint rows: row `j` holds pixels `x1..x2` of `bounds`.
/// Hosts may render tiles of one buffer on several threads, so writers get
/// only the rows (and columns) of their own window, never the whole buffer.
#[derive(Debug)]
pub struct RowsMut<'a, T> {
    /// Pixels covered, the union of the rows.
    pub bounds: RectI,
    /// Components per pixel.
    pub channels: usize,
    /// `(j, pixels x1..x2 of row j)`, bottom row first.
    pub rows: Vec<(i32, &'a mut [T])>,
}

/// An owned float image: packed rows, bottom row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Pixels covered.
    pub bounds: RectI,
    /// Components per pixel.
    pub channels: usize,
    /// `bounds.area() × channels` samples, bottom row first.
    pub data: Vec<f32>,
}

impl Image {
    /// A black (all zero) image.
    pub fn new(bounds: RectI, channels: usize) -> Self {
        Image {
            bounds,
            channels,
            data: vec![0.0; bounds.area() * channels],
        }
    }
    /// An image whose sample `(i, j, c)` is `f(i, j, c)`.
    pub fn from_fn(bounds: RectI, channels: usize, f: impl Fn(i32, i32, usize) -> f32) -> Self {
        let mut img = Image::new(bounds, channels);
        let mut k = 0;
        for j in bounds.y1..bounds.y2 {
            for i in bounds.x1..bounds.x2 {
                for c in 0..channels {
                    img.data[k] = f(i, j, c);
                    k += 1;
                }
            }
        }
        img
    }
    /// Pixels across.
    #[inline]
    pub fn width(&self) -> usize {
        self.bounds.width()
    }
    /// Pixels up.
    #[inline]
    pub fn height(&self) -> usize {
        self.bounds.height()
    }
    /// The layout of [`Image::data`].
    pub fn layout(&self) -> Layout {
        Layout::packed(self.bounds, self.channels)
    }
    /// The image as a read-only view.
    pub fn view(&self) -> ImageView<'_, f32> {
        ImageView::new(&self.data, self.layout()).expect("packed layout fits its buffer")
    }
    /// The image as a writable view.
    pub fn view_mut(&mut self) -> ImageViewMut<'_, f32> {
        let layout = self.layout();
        ImageViewMut::new(&mut self.data, layout).expect("packed layout fits its buffer")
    }
    /// The samples of pixel `(i, j)`, which must lie inside `bounds`.
    #[inline]
    pub fn pixel(&self, i: i32, j: i32) -> &[f32] {
        let k = ((j - self.bounds.y1) as usize * self.width() + (i - self.bounds.x1) as usize)
            * self.channels;
        &self.data[k..k + self.channels]
    }
}

#[cfg(test)]
mod tests;

/// Float pixels over a window, `[f32; 4]` each in some channel layout (1, 3
/// or 4 channels used), rows bottom-up: what a warp that makes pixels rather
/// than a map (the two-pass mesh warp) hands to the dissolve.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Pixels covered.
    pub window: RectI,
    /// Channels in use in each pixel.
    pub channels: usize,
    /// One pixel per element, bottom row first.
    pub pixels: Vec<[f32; 4]>,
}

impl Plane {
    /// Row `j` (inside the window).
    #[inline]
    pub fn row(&self, j: i32) -> &[[f32; 4]] {
        let w = self.window.width();
        let start = (j - self.window.y1) as usize * w;
        &self.pixels[start..start + w]
    }
}
