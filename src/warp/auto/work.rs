//! The work of a warp (Gao-Sederberg §4, eq. 5): re-colouring (6), stretching (7),
//! angle change (8) and the anchor penalty (9), per quad, so a move of one
//! control point is re-priced from its four quads only.
//!
//! Units, as the paper's constants intend: geometry lives in the unit square
//! (the paper's domain) and the constants make the work independent of the
//! resolution. Two readings are ours, both needed for the paper's table to
//! make sense: colours are in [0, 1] (its identity work, 3384.5 units over
//! 256² pixels, is 0.05 a pixel), and angle changes are in degrees (in
//! radians its 600/256² would make the angle work of its table — 98.4 at
//! level 2 — a rotation of 26 radians a corner).

use crate::geom::Vec2;
use crate::image::{ImageView, Sample};

use super::grid::bilinear;

/// An RGB picture for the work: colours as `[r, g, b, 0]`, rows bottom-up.
#[derive(Clone)]
pub struct WorkImage {
    /// Pixels across.
    pub width: usize,
    /// Pixels up.
    pub height: usize,
    pixels: Vec<[f32; 4]>,
}

impl WorkImage {
    /// A picture whose pixel `(i, j)` is `f(i, j)`.
    pub fn from_fn(width: usize, height: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> Self {
        let mut pixels = Vec::with_capacity(width * height);
        for j in 0..height {
            for i in 0..width {
                let [r, g, b] = f(i, j);
                pixels.push([r, g, b, 0.0]);
            }
        }
        WorkImage {
            width,
            height,
            pixels,
        }
    }

    /// The colour channels of a view (grey for one or two channels; alpha is
    /// not colour). Non-finite samples count as black.
    pub fn from_view<S: Sample>(view: &ImageView<'_, S>) -> Self {
        let b = view.bounds();
        let c = view.channels();
        let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
        let mut pixels = Vec::with_capacity(b.area());
        for j in b.y1..b.y2 {
            for px in view.row(j).chunks_exact(c) {
                let v = |q: usize| finite(px[q.min(c - 1)].to_f32());
                pixels.push(if c >= 3 {
                    [v(0), v(1), v(2), 0.0]
                } else {
                    [v(0), v(0), v(0), 0.0]
                });
            }
        }
        WorkImage {
            width: b.width(),
            height: b.height(),
            pixels,
        }
    }

    /// Half the size, each pixel the mean of the (up to) four it covers.
    pub fn half(&self) -> WorkImage {
        let (w, h) = (self.width.div_ceil(2), self.height.div_ceil(2));
        let mut pixels = Vec::with_capacity(w * h);
        for j in 0..h {
            let (j0, j1) = (2 * j, (2 * j + 1).min(self.height - 1));
            for i in 0..w {
                let (i0, i1) = (2 * i, (2 * i + 1).min(self.width - 1));
                let p = |i: usize, j: usize| wide::f32x4::new(self.pixels[j * self.width + i]);
                let mean = (p(i0, j0) + p(i1, j0) + p(i0, j1) + p(i1, j1)) * 0.25;
                pixels.push(mean.to_array());
            }
        }
        WorkImage {
            width: w,
            height: h,
            pixels,
        }
    }

    /// Successive halvings of this image while the smaller side keeps at
    /// least `min_side` pixels (the image itself not included).
    pub fn halvings(&self, min_side: usize) -> Vec<WorkImage> {
        let mut levels: Vec<WorkImage> = Vec::new();
        loop {
            let last = levels.last().unwrap_or(self);
            if last.width.min(last.height) / 2 < min_side {
                return levels;
            }
            let next = last.half();
            levels.push(next);
        }
    }

    fn row(&self, j: usize) -> &[[f32; 4]] {
        &self.pixels[j * self.width..(j + 1) * self.width]
    }

    /// Bilinear colour at unit-square position `(u, v)`, clamped to the edge.
    #[inline]
    fn at_unit(&self, u: f32, v: f32) -> wide::f32x4 {
        let x = (u * self.width as f32 - 0.5).clamp(0.0, (self.width - 1) as f32);
        let y = (v * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let (i, j) = (x as usize, y as usize);
        let (fx, fy) = (x - i as f32, y - j as f32);
        let i1 = (i + 1).min(self.width - 1);
        let j1 = (j + 1).min(self.height - 1);
        let p = |i: usize, j: usize| wide::f32x4::new(self.pixels[j * self.width + i]);
        let bottom = p(i, j) + (p(i1, j) - p(i, j)) * fx;
        let top = p(i, j1) + (p(i1, j1) - p(i, j1)) * fx;
        bottom + (top - bottom) * fy
    }

    /// A stable digest of the pixels, for caches keyed by image content.
    pub fn digest(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ (self.width as u64) << 32 ^ self.height as u64;
        for p in &self.pixels {
            for v in &p[..3] {
                h = (h ^ v.to_bits() as u64).wrapping_mul(0x100_0000_01b3);
                h ^= h >> 29;
            }
        }
        h
    }
}

/// Work coefficients `c_c`, `c_s`, `c_a` of eq. (5) and the anchor weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// `c_c`: weight of colour difference.
    pub colour: f64,
    /// `c_s`: weight of stretching.
    pub stretch: f64,
    /// `c_a`: weight of angle change.
    pub angle: f64,
    /// Weight of the anchor penalty.
    pub anchor: f64,
}

impl Default for Coefficients {
    /// The paper's advice for `c_c`, `c_s`, `c_a`: all one. Anchors weigh
    /// ten times eq. (9): at one, a single anchor on a textured plate was
    /// left 2.9 px from its target by the colour work; at three, 0.13 px.
    fn default() -> Self {
        Coefficients {
            colour: 1.0,
            stretch: 1.0,
            angle: 1.0,
            anchor: 10.0,
        }
    }
}

/// The weighted work of one quad (or, summed, of a warp), by kind.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    /// Colour difference.
    pub colour: f64,
    /// Stretching.
    pub stretch: f64,
    /// Angle change.
    pub angle: f64,
    /// Anchor penalty.
    pub anchor: f64,
}

impl Work {
    /// The sum of all four kinds.
    #[inline]
    pub fn total(&self) -> f64 {
        self.colour + self.stretch + self.angle + self.anchor
    }
}

impl std::ops::Add for Work {
    type Output = Work;
    fn add(self, o: Work) -> Work {
        Work {
            colour: self.colour + o.colour,
            stretch: self.stretch + o.stretch,
            angle: self.angle + o.angle,
            anchor: self.anchor + o.anchor,
        }
    }
}

impl std::iter::Sum for Work {
    fn sum<I: Iterator<Item = Work>>(iter: I) -> Work {
        iter.fold(Work::default(), |a, b| a + b)
    }
}

/// A pair of corresponding positions in the unit square: `a` on A must map
/// to `b` on B.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// Position on A.
    pub a: Vec2,
    /// Position on B.
    pub b: Vec2,
}

/// An anchor inside a quad: its local patch coordinates and its target.
#[derive(Debug, Clone, Copy)]
struct Pinned {
    s: f64,
    t: f64,
    b: Vec2,
}

/// Prices quads of one level.
pub struct Pricer<'a> {
    a: &'a WorkImage,
    b: &'a WorkImage,
    n: usize,
    colour: f64,
    stretch: f64,
    angle: f64,
    anchor: f64,
    /// Anchor tolerance `δ` of eq. (9), in 256ths of the unit square.
    delta: f64,
    /// Pixel columns of A whose centres lie in quad column `j`: `cols[j]..cols[j + 1]`.
    cols: Vec<usize>,
    rows: Vec<usize>,
    pinned: Vec<Vec<Pinned>>,
}

/// Anchor tolerance floor: at fine levels eq. (9)'s `δ = R / 2^(2i)` would
/// shrink below a pixel and the penalty with it; it stops at two pixels of B
/// (anchors met within one pixel).
pub const ANCHOR_FLOOR_PX: f64 = 2.0;

impl<'a> Pricer<'a> {
    /// A pricer of level `level`'s quads between `a` and `b`, with `anchors` and weights
    /// `c`.
    pub fn new(
        a: &'a WorkImage,
        b: &'a WorkImage,
        level: u32,
        anchors: &[Anchor],
        c: &Coefficients,
    ) -> Self {
        let n = 1usize << level;
        // Pixel i's centre (i + 0.5) / W lies in [j/n, (j+1)/n) for i in cols[j]..cols[j+1].
        let bounds = |size: usize| -> Vec<usize> {
            (0..=n)
                .map(|j| {
                    let edge = j as f64 / n as f64 * size as f64 - 0.5;
                    (edge.ceil().max(0.0) as usize).min(size)
                })
                .collect()
        };
        let mut pinned = vec![Vec::new(); n * n];
        for an in anchors {
            let (x, y) = (
                an.a.x.clamp(0.0, 1.0) * n as f64,
                an.a.y.clamp(0.0, 1.0) * n as f64,
            );
            let (j, k) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
            pinned[k * n + j].push(Pinned {
                s: x - j as f64,
                t: y - k as f64,
                b: an.b,
            });
        }
        let r_b = b.width.max(b.height) as f64;
        let floor = 256.0 * ANCHOR_FLOOR_PX / r_b;
        Pricer {
            a,
            b,
            n,
            colour: c.colour * 256.0 * 256.0 / (a.width * a.height) as f64,
            stretch: c.stretch * 400.0,
            angle: c.angle * 600.0 / (256.0 * 256.0) / n as f64,
            anchor: c.anchor,
            delta: (256.0 / (1u64 << (2 * level).min(62)) as f64).max(floor),
            cols: bounds(a.width),
            rows: bounds(a.height),
            pinned,
        }
    }

    /// The work of quad `(j, k)` when its corners are `q`.
    pub fn quad(&self, j: usize, k: usize, q: &[Vec2; 4]) -> Work {
        Work {
            colour: self.colour_work(j, k, q),
            ..self.shape_work(j, k, q)
        }
    }

    /// The cheap part of [`Pricer::quad`]: all but the colour.
    pub fn shape_work(&self, j: usize, k: usize, q: &[Vec2; 4]) -> Work {
        Work {
            colour: 0.0,
            stretch: self.stretch * stretch(q, 1.0 / self.n as f64),
            angle: self.angle * angle(q),
            anchor: self.anchor * self.anchors(j, k, q),
        }
    }

    /// The colour part of [`Pricer::quad`] (the cost of the search).
    pub fn colour_work(&self, j: usize, k: usize, q: &[Vec2; 4]) -> f64 {
        if self.colour == 0.0 {
            return 0.0;
        }
        self.colour * self.recolour(j, k, q)
    }

    /// Eq. (6): every A pixel whose centre lies in the quad, against B's
    /// colour where the warp sends it (bilinear: sub-pixel moves still count).
    fn recolour(&self, j: usize, k: usize, q: &[Vec2; 4]) -> f64 {
        let n = self.n as f32;
        let (w, h) = (self.a.width as f32, self.a.height as f32);
        let q32 = q.map(|p| [p.x as f32, p.y as f32]);
        let lerp =
            |p: [f32; 2], r: [f32; 2], s: f32| [p[0] + (r[0] - p[0]) * s, p[1] + (r[1] - p[1]) * s];
        let (c0, c1) = (self.cols[j], self.cols[j + 1]);
        let mut sum = 0.0f64;
        for r in self.rows[k]..self.rows[k + 1] {
            let t = (r as f32 + 0.5) / h * n - k as f32;
            let left = lerp(q32[0], q32[3], t);
            let right = lerp(q32[1], q32[2], t);
            let d = [right[0] - left[0], right[1] - left[1]];
            let row = &self.a.row(r)[c0..c1];
            let mut acc = 0.0f32;
            for (i, c) in row.iter().enumerate() {
                let s = ((c0 + i) as f32 + 0.5) / w * n - j as f32;
                let diff =
                    self.b.at_unit(left[0] + d[0] * s, left[1] + d[1] * s) - wide::f32x4::new(*c);
                acc += (diff * diff).reduce_add().sqrt();
            }
            sum += acc as f64;
        }
        sum
    }

    /// Eq. (9) for the anchors in quad `(j, k)`, distances in 256ths.
    fn anchors(&self, j: usize, k: usize, q: &[Vec2; 4]) -> f64 {
        let delta = self.delta;
        let c2 = 3.0 * delta * delta;
        let c1 = c2 / 8.0;
        self.pinned[k * self.n + j]
            .iter()
            .map(|p| {
                let d = (bilinear(q, p.s, p.t) - p.b).length() * 256.0;
                if d <= delta / 2.0 {
                    c1 * 2.0 * d / delta
                } else {
                    (c1 * (delta - d) + c2 * (d - delta / 2.0)) / (delta / 2.0)
                }
            })
            .sum()
    }

    /// Every quad's work, in parallel.
    pub fn all(&self, grid: &super::grid::Grid) -> Vec<Work> {
        use rayon::prelude::*;
        let n = self.n;
        (0..n * n)
            .into_par_iter()
            .map(|i| {
                let (j, k) = (i % n, i / n);
                self.quad(j, k, &grid.quad(j, k))
            })
            .collect()
    }
}

/// Eq. (7): squared length changes of the four edges (rest length `h`).
fn stretch(q: &[Vec2; 4], h: f64) -> f64 {
    (0..4)
        .map(|c| {
            let d = (q[(c + 1) % 4] - q[c]).length() - h;
            d * d
        })
        .sum()
}

/// Eq. (8) without its `1/2^i` (folded into the weight): squared changes of
/// the four corner angles from a right angle, in degrees.
fn angle(q: &[Vec2; 4]) -> f64 {
    (0..4)
        .map(|c| {
            let (p, a, b) = (q[c], q[(c + 1) % 4], q[(c + 3) % 4]);
            let (u, v) = (a - p, b - p);
            let theta = (u.x * v.y - u.y * v.x).atan2(u.dot(v)).to_degrees() - 90.0;
            theta * theta
        })
        .sum()
}
