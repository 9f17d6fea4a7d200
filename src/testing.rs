//! Generated content with known properties, shared by this project's tests
//! and benchmarks (the core's, the harness's and the bundle's).

use crate::geom::{RectI, Vec2};
use crate::image::Image;

/// An RGBA plate of `bounds` with a vertical step edge at canonical x =
/// `edge` (0.1 left of it, 0.9 right, opaque), for snakes to find.
pub fn step_plate(bounds: RectI, edge: f64) -> Image {
    Image::from_fn(bounds, 4, |i, _, c| {
        if c == 3 {
            1.0
        } else if (i as f64 + 0.5) < edge {
            0.1
        } else {
            0.9
        }
    })
}

/// Positions that exercise every path of a sampler row: inside (most), on and
/// near pixel centres, across each edge, outside and NaN; canonical
/// positions over `bounds` at scale 1, deterministic in `seed`.
pub fn awkward_positions(bounds: RectI, n: usize, seed: u64) -> Vec<[f32; 2]> {
    let mut lcg = Lcg::new(seed);
    let mut r = move || lcg.unit() as f32;
    let (x1, y1) = (bounds.x1 as f32, bounds.y1 as f32);
    let (w, h) = (bounds.width() as f32, bounds.height() as f32);
    (0..n)
        .map(|k| match k % 11 {
            0 => [x1 + 3.5, y1 + 2.5],
            1 => [x1 + 4.5 + 3e-5, y1 + 1.5],
            2 => [x1 - 3.0 + (w + 6.0) * r(), y1 - 3.0 + (h + 6.0) * r()],
            3 => [f32::NAN, y1 + 1.0],
            4 => [x1 + w - 0.7 * r(), y1 + h * r()],
            _ => [x1 + w * r(), y1 + h * r()],
        })
        .collect()
}

/// A smooth colour field with texture everywhere (no flat region), values in
/// [0, 1]: what `auto` needs to find a warp, and what 8-bit plates can hold.
/// Canonical pixel position in, RGB out.
pub fn texture(p: Vec2) -> [f32; 3] {
    let (x, y) = (p.x, p.y);
    [
        (0.5 + 0.25 * (x / 7.0).sin() * (y / 9.0).cos() + 0.2 * ((x + y) / 13.0).sin()) as f32,
        (0.5 + 0.3 * ((x - 0.5 * y) / 11.0).cos() + 0.15 * (y / 5.0).sin()) as f32,
        (0.4 + 0.3 * ((x * x + y * y).sqrt() / 8.0).sin()) as f32,
    ]
}

/// A small deterministic generator (PCG-style LCG) for generated tests and
/// benchmarks: the same seed gives the same case on every machine.
pub struct Lcg(u64);

impl Lcg {
    /// A generator started from `seed`.
    pub fn new(seed: u64) -> Self {
        Lcg(seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407))
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// `n` points at least `gap` apart inside `[margin, w − margin] × [margin,
/// h − margin]`, each paired with its place under a smooth displacement of
/// amplitude up to `shift` px whose gradient stays below 1/2: a
/// non-crossing constraint set (no two paths can cross, the map it samples
/// is one-to-one).
pub fn smooth_pairs(
    seed: u64,
    n: usize,
    w: f64,
    h: f64,
    shift: f64,
    gap: f64,
) -> Vec<(Vec2, Vec2)> {
    let mut r = Lcg::new(seed);
    let margin = 2.0 * shift + 4.0;
    let length = 4.0 * shift.max(1.0);
    let phase: [f64; 4] = std::array::from_fn(|_| r.range(0.0, std::f64::consts::TAU));
    let field = |p: Vec2| {
        Vec2::new(
            shift * (p.x / length + phase[0]).sin() * (p.y / length + phase[1]).cos(),
            shift * (p.x / length + phase[2]).cos() * (p.y / length + phase[3]).sin(),
        )
    };
    let mut points: Vec<Vec2> = Vec::with_capacity(n);
    let mut tries = 0;
    while points.len() < n && tries < 100 * n {
        tries += 1;
        let p = Vec2::new(r.range(margin, w - margin), r.range(margin, h - margin));
        if points.iter().all(|q| q.distance(p) >= gap) {
            points.push(p);
        }
    }
    points.into_iter().map(|p| (p, p + field(p))).collect()
}
