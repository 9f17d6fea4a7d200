//! A warp evaluated at pixel centres: what resampling and the ST-map view consume,
//! and what the plugin caches between tiles and threads.

use crate::geom::{PixelScale, RectI, Vec2};

/// A reverse map: for each output pixel, the canonical source position it samples.
#[derive(Debug, Clone, PartialEq)]
pub struct WarpMap {
    /// Output pixels covered, at `scale`.
    pub window: RectI,
    /// The render scale of the output pixels.
    pub scale: PixelScale,
    /// Canonical source position per output pixel, rows bottom-up. Empty when
    /// `identity` (then every pixel samples its own centre).
    positions: Vec<[f32; 2]>,
    identity: bool,
}

impl WarpMap {
    /// A map from one position per pixel of `window`, rows bottom-up.
    pub fn new(window: RectI, scale: PixelScale, positions: Vec<[f32; 2]>) -> Self {
        assert_eq!(positions.len(), window.area(), "one position per pixel");
        WarpMap {
            window,
            scale,
            positions,
            identity: false,
        }
    }

    /// The map of every pixel to its own centre.
    pub fn identity(window: RectI, scale: PixelScale) -> Self {
        WarpMap {
            window,
            scale,
            positions: Vec::new(),
            identity: true,
        }
    }

    /// True when every pixel samples its own centre.
    #[inline]
    pub fn is_identity(&self) -> bool {
        self.identity
    }

    /// Canonical source position for output pixel `(i, j)` (inside `window`).
    #[inline]
    pub fn get(&self, i: i32, j: i32) -> Vec2 {
        if self.identity {
            return self.scale.pixel_centre(i, j);
        }
        let k = (j - self.window.y1) as usize * self.window.width() + (i - self.window.x1) as usize;
        let [x, y] = self.positions[k];
        Vec2::new(x as f64, y as f64)
    }

    /// One row of positions (`None` for the identity map).
    #[inline]
    pub fn row(&self, j: i32) -> Option<&[[f32; 2]]> {
        if self.identity {
            return None;
        }
        let w = self.window.width();
        let start = (j - self.window.y1) as usize * w;
        Some(&self.positions[start..start + w])
    }

    /// Every position, rows bottom-up (empty for the identity map).
    pub fn positions(&self) -> &[[f32; 2]] {
        &self.positions
    }

    /// The positions, to be edited into another map of the same window.
    pub fn into_positions(self) -> Vec<[f32; 2]> {
        self.positions
    }

    /// Heap bytes held (for cache budgets).
    pub fn memory_bytes(&self) -> usize {
        self.positions.len() * std::mem::size_of::<[f32; 2]>()
    }
}
