//! Plain 2-D geometry in canonical coordinates (f64: feature math wants the headroom).

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
#[serde(from = "[f64; 2]", into = "[f64; 2]")]
/// A point or a vector; in scene files, `[x, y]`.
pub struct Vec2 {
    /// Rightwards.
    pub x: f64,
    /// Upwards.
    pub y: f64,
}

impl From<[f64; 2]> for Vec2 {
    #[inline]
    fn from([x, y]: [f64; 2]) -> Self {
        Vec2 { x, y }
    }
}

impl From<Vec2> for [f64; 2] {
    #[inline]
    fn from(v: Vec2) -> Self {
        [v.x, v.y]
    }
}

impl Vec2 {
    /// The origin, and the zero vector.
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };

    /// `(x, y)`.
    pub const fn new(x: f64, y: f64) -> Self {
        Vec2 { x, y }
    }
    /// The dot product.
    #[inline]
    pub fn dot(self, o: Vec2) -> f64 {
        self.x * o.x + self.y * o.y
    }
    /// The left perpendicular, same length (Beier-Neely's `Perpendicular()`; any
    /// consistent choice works, we take the counter-clockwise one).
    #[inline]
    pub fn perp(self) -> Vec2 {
        Vec2::new(-self.y, self.x)
    }
    /// The squared length (no square root).
    #[inline]
    pub fn length_squared(self) -> f64 {
        self.dot(self)
    }
    /// The Euclidean length.
    #[inline]
    pub fn length(self) -> f64 {
        self.length_squared().sqrt()
    }
    /// `self` at `t = 0`, `o` at `t = 1`, on the line between elsewhere.
    #[inline]
    pub fn lerp(self, o: Vec2, t: f64) -> Vec2 {
        Vec2::new(self.x + (o.x - self.x) * t, self.y + (o.y - self.y) * t)
    }
    /// Neither coordinate is infinite or NaN.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
    /// The Euclidean distance to `o`.
    #[inline]
    pub fn distance(self, o: Vec2) -> f64 {
        (self - o).length()
    }
    /// Distance to the segment `p`–`q` (to `p` when it has no length).
    #[inline]
    pub fn distance_to_segment(self, p: Vec2, q: Vec2) -> f64 {
        let d = q - p;
        let len2 = d.length_squared();
        let u = if len2 > 0.0 {
            ((self - p).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.distance(p + d * u)
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    #[inline]
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}
impl AddAssign for Vec2 {
    #[inline]
    fn add_assign(&mut self, o: Vec2) {
        self.x += o.x;
        self.y += o.y;
    }
}
impl Sub for Vec2 {
    type Output = Vec2;
    #[inline]
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}
impl Mul<f64> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn mul(self, s: f64) -> Vec2 {
        Vec2::new(self.x * s, self.y * s)
    }
}
impl Div<f64> for Vec2 {
    type Output = Vec2;
    #[inline]
    fn div(self, s: f64) -> Vec2 {
        Vec2::new(self.x / s, self.y / s)
    }
}
impl Neg for Vec2 {
    type Output = Vec2;
    #[inline]
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}

/// An integer pixel rectangle `[x1, x2) × [y1, y2)` (OFX `OfxRectI` semantics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct RectI {
    /// The first column.
    pub x1: i32,
    /// The first row (from the bottom).
    pub y1: i32,
    /// One past the last column.
    pub x2: i32,
    /// One past the last row.
    pub y2: i32,
}

impl RectI {
    /// `[x1, x2) × [y1, y2)`.
    pub const fn new(x1: i32, y1: i32, x2: i32, y2: i32) -> Self {
        RectI { x1, y1, x2, y2 }
    }
    /// `width × height` pixels from the origin.
    pub const fn from_size(width: usize, height: usize) -> Self {
        RectI::new(0, 0, width as i32, height as i32)
    }
    /// Columns (0 when inverted).
    #[inline]
    pub fn width(&self) -> usize {
        // In i64: a rectangle from i32::MIN to i32::MAX (a host's
        // "infinite" region) is wider than an i32 holds.
        (self.x2 as i64 - self.x1 as i64).max(0) as usize
    }
    /// Rows (0 when inverted).
    #[inline]
    pub fn height(&self) -> usize {
        (self.y2 as i64 - self.y1 as i64).max(0) as usize
    }
    /// No pixel inside.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.width() == 0 || self.height() == 0
    }
    /// Pixels inside.
    #[inline]
    pub fn area(&self) -> usize {
        self.width().saturating_mul(self.height())
    }
    /// Every pixel of `other` is inside (an empty `other` always is).
    #[inline]
    pub fn contains(&self, other: &RectI) -> bool {
        other.is_empty()
            || (self.x1 <= other.x1
                && self.y1 <= other.y1
                && other.x2 <= self.x2
                && other.y2 <= self.y2)
    }
    /// The pixels inside both; the default (empty) rectangle when none are.
    #[inline]
    pub fn intersect(&self, o: &RectI) -> RectI {
        let r = RectI::new(
            self.x1.max(o.x1),
            self.y1.max(o.y1),
            self.x2.min(o.x2),
            self.y2.min(o.y2),
        );
        if r.x2 <= r.x1 || r.y2 <= r.y1 {
            RectI::default()
        } else {
            r
        }
    }
}

/// A rectangle in canonical coordinates `[x1, x2] × [y1, y2]` (OFX `OfxRectD`),
/// e.g. the frame a warp must cover.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RectD {
    /// Left.
    pub x1: f64,
    /// Bottom.
    pub y1: f64,
    /// Right.
    pub x2: f64,
    /// Top.
    pub y2: f64,
}

impl RectD {
    /// `[x1, x2] × [y1, y2]`.
    pub const fn new(x1: f64, y1: f64, x2: f64, y2: f64) -> Self {
        RectD { x1, y1, x2, y2 }
    }
    /// `x2 - x1`.
    #[inline]
    pub fn width(&self) -> f64 {
        self.x2 - self.x1
    }
    /// `y2 - y1`.
    #[inline]
    pub fn height(&self) -> f64 {
        self.y2 - self.y1
    }
    /// Whether `p` lies inside or on the border (false for NaN).
    pub fn contains_point(&self, p: Vec2) -> bool {
        self.x1 <= p.x && p.x <= self.x2 && self.y1 <= p.y && p.y <= self.y2
    }

    /// The smallest rectangle holding this one and every point of `points`.
    pub fn including(self, points: impl IntoIterator<Item = Vec2>) -> RectD {
        points.into_iter().fold(self, |r, p| {
            RectD::new(r.x1.min(p.x), r.y1.min(p.y), r.x2.max(p.x), r.y2.max(p.y))
        })
    }

    /// Finite, with positive width and height.
    pub fn is_valid(&self) -> bool {
        [self.x1, self.y1, self.x2, self.y2]
            .iter()
            .all(|v| v.is_finite())
            && self.x2 > self.x1
            && self.y2 > self.y1
    }
}

/// How pixel indices of an image at some render scale relate to canonical
/// coordinates: `canonical = pixel / scale` per axis, where `scale.x` already
/// folds in the pixel aspect ratio (`render_scale.x / par`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelScale {
    /// Pixels per canonical unit along x (render scale over pixel aspect).
    pub x: f64,
    /// Pixels per canonical unit along y (the render scale).
    pub y: f64,
}

impl PixelScale {
    /// Full resolution, square pixels: pixels are canonical units.
    pub const UNIT: PixelScale = PixelScale { x: 1.0, y: 1.0 };

    /// From a host's render scale and pixel aspect ratio.
    #[inline]
    pub fn new(render_scale_x: f64, render_scale_y: f64, pixel_aspect: f64) -> Self {
        PixelScale {
            x: render_scale_x / pixel_aspect,
            y: render_scale_y,
        }
    }
    /// Canonical position of the centre of pixel `(i, j)`.
    #[inline]
    pub fn pixel_centre(&self, i: i32, j: i32) -> Vec2 {
        Vec2::new((i as f64 + 0.5) / self.x, (j as f64 + 0.5) / self.y)
    }
    /// A canonical position in this scale's pixel units.
    #[inline]
    pub fn to_pixel(&self, p: Vec2) -> Vec2 {
        Vec2::new(p.x * self.x, p.y * self.y)
    }
    /// A position in this scale's pixel units as a canonical one.
    #[inline]
    pub fn to_canonical(&self, p: Vec2) -> Vec2 {
        Vec2::new(p.x / self.x, p.y / self.y)
    }
    /// Full resolution with square pixels.
    #[inline]
    pub fn is_unit(&self) -> bool {
        *self == PixelScale::UNIT
    }
}
