//! Generated content with known properties, shared by this project's tests
//! and benchmarks (the core's, the harness's and the bundle's).

use crate::geom::{RectI, Vec2};
use crate::image::{Image, Layout, Sample};

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

/// The pixels of `packed` (rows of `bounds`, `channels` samples a pixel,
/// bottom row first) laid out as a host may lend them: top row first, `pad`
/// samples after each row and `lead` before the first, every gap holding
/// `gap` (NaN shows a read that strays into one).
pub fn top_down<T: Sample>(
    packed: &[T],
    bounds: RectI,
    channels: usize,
    (pad, lead): (usize, usize),
    gap: T,
) -> (Vec<T>, Layout) {
    let (w, h) = (bounds.width() * channels, bounds.height());
    let stride = w + pad;
    let mut data = vec![gap; lead + h * stride];
    for (r, row) in packed.chunks_exact(w).enumerate() {
        let at = lead + (h - 1 - r) * stride;
        data[at..at + w].copy_from_slice(row);
    }
    let layout = Layout {
        bounds,
        channels,
        base: lead + (h - 1) * stride,
        row_stride: -(stride as isize),
    };
    (data, layout)
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

/// A known smooth non-rigid motion over a shot, for trackers: frame `f` of
/// `frames` rotates by up to `rotate_deg` and zooms by up to `zoom` about
/// `centre`, drifts by up to `drift`, and bends the picture near `bend_at`
/// by up to `bend` px (a Gaussian bump of radius `bend_radius`); each grows
/// linearly from nothing at frame 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShotMotion {
    /// The last frame (the first is 0).
    pub frames: usize,
    /// The centre of rotation and zoom.
    pub centre: Vec2,
    /// Rotation at the last frame, degrees.
    pub rotate_deg: f64,
    /// Scale at the last frame.
    pub zoom: f64,
    /// Translation at the last frame.
    pub drift: Vec2,
    /// Peak displacement of the local bend at the last frame.
    pub bend: Vec2,
    /// Where the bend peaks.
    pub bend_at: Vec2,
    /// The bend's Gaussian radius.
    pub bend_radius: f64,
    /// Peak displacement, at the last frame, of a wave across the frame:
    /// a bend that varies along any long feature.
    pub wave: Vec2,
    /// The wave's length, pixels, along the diagonal (x + y); keep
    /// `|wave| · 2π / wavelength` well under 1 so the motion stays one-to-one.
    pub wavelength: f64,
}

impl ShotMotion {
    /// Where the point at `p` in frame 0 lies in frame `frame`.
    pub fn at(&self, frame: usize, p: Vec2) -> Vec2 {
        let s = frame as f64 / self.frames.max(1) as f64;
        let (sin, cos) = (self.rotate_deg * s).to_radians().sin_cos();
        let zoom = 1.0 + (self.zoom - 1.0) * s;
        let d = p - self.centre;
        let turned = Vec2::new(cos * d.x - sin * d.y, sin * d.x + cos * d.y) * zoom;
        let r2 = (p - self.bend_at).length_squared() / (2.0 * self.bend_radius.powi(2));
        let phase = std::f64::consts::TAU * (p.x + p.y)
            / std::f64::consts::SQRT_2
            / self.wavelength.max(1e-9);
        self.centre
            + turned
            + self.drift * s
            + self.bend * (s * (-r2).exp())
            + self.wave * (s * phase.sin())
    }

    /// The point of frame 0 that lands at `x` in frame `frame` (Newton's
    /// method on [`ShotMotion::at`], which is smooth and one-to-one).
    pub fn source_of(&self, frame: usize, x: Vec2) -> Vec2 {
        let mut p = x;
        for _ in 0..20 {
            let r = self.at(frame, p) - x;
            if r.length() < 1e-9 {
                break;
            }
            let h = 1e-4;
            let jx = (self.at(frame, p + Vec2::new(h, 0.0)) - self.at(frame, p)) * (1.0 / h);
            let jy = (self.at(frame, p + Vec2::new(0.0, h)) - self.at(frame, p)) * (1.0 / h);
            let det = jx.x * jy.y - jy.x * jx.y;
            p = p - Vec2::new(jy.y * r.x - jy.x * r.y, -jx.y * r.x + jx.x * r.y) * (1.0 / det);
        }
        p
    }
}

/// Frame `frame` of a shot of `photo` moved by `motion` (bilinear, edge
/// pixels held outside), with a flicker of gain `1 ± flicker` and a grain of
/// relative standard deviation `grain`, both random per frame from `seed`.
/// RGBA, alpha 1.
pub fn shot_frame(
    photo: &Image,
    motion: &ShotMotion,
    frame: usize,
    flicker: f64,
    grain: f64,
    seed: u64,
) -> Image {
    let mut r = Lcg::new(seed ^ (frame as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let gain = if frame == 0 {
        1.0
    } else {
        1.0 + r.range(-flicker, flicker)
    };
    let b = photo.bounds;
    let mut out = Image::new(b, 4);
    let c = photo.channels;
    let at = |i: i32, j: i32, k: usize| {
        let (i, j) = (i.clamp(b.x1, b.x2 - 1), j.clamp(b.y1, b.y2 - 1));
        photo.pixel(i, j)[k.min(c - 1)]
    };
    let mut k = 0;
    for j in b.y1..b.y2 {
        for i in b.x1..b.x2 {
            let p = motion.source_of(frame, Vec2::new(i as f64 + 0.5, j as f64 + 0.5));
            let (u, v) = (p.x - 0.5, p.y - 0.5);
            let (i0, j0) = (u.floor() as i32, v.floor() as i32);
            let (fx, fy) = ((u - u.floor()) as f32, (v - v.floor()) as f32);
            // One grain value for the pixel (luminance grain), Box-Muller.
            let g =
                (-2.0 * r.unit().max(1e-12).ln()).sqrt() * (std::f64::consts::TAU * r.unit()).cos();
            for ch in 0..3 {
                let top = at(i0, j0, ch) * (1.0 - fx) + at(i0 + 1, j0, ch) * fx;
                let bottom = at(i0, j0 + 1, ch) * (1.0 - fx) + at(i0 + 1, j0 + 1, ch) * fx;
                let value = (top * (1.0 - fy) + bottom * fy) as f64;
                out.data[k + ch] = (value * gain * (1.0 + grain * g)) as f32;
            }
            out.data[k + 3] = 1.0;
            k += 4;
        }
    }
    out
}

/// Up to `n` well-textured corners of `image` (largest smaller eigenvalue
/// of the 2×2 gradient structure tensor over 9×9 pixels), at pixel centres,
/// at least `gap` apart and `margin` inside the edges: features a user would
/// key, picked by a rule independent of any tracker.
pub fn corners(image: &Image, n: usize, gap: f64, margin: f64) -> Vec<Vec2> {
    let b = image.bounds;
    let c = image.channels;
    let lum = |i: i32, j: i32| {
        let p = image.pixel(i.clamp(b.x1, b.x2 - 1), j.clamp(b.y1, b.y2 - 1));
        if c >= 3 {
            0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
        } else {
            p[0]
        }
    };
    let m = margin.ceil() as i32;
    let mut scored = Vec::new();
    for j in (b.y1 + m..b.y2 - m).step_by(2) {
        for i in (b.x1 + m..b.x2 - m).step_by(2) {
            let (mut xx, mut xy, mut yy) = (0.0f64, 0.0f64, 0.0f64);
            for dj in -4..=4 {
                for di in -4..=4 {
                    let (x, y) = (i + di, j + dj);
                    let gx = 0.5 * (lum(x + 1, y) - lum(x - 1, y)) as f64;
                    let gy = 0.5 * (lum(x, y + 1) - lum(x, y - 1)) as f64;
                    xx += gx * gx;
                    xy += gx * gy;
                    yy += gy * gy;
                }
            }
            let min_eig = 0.5 * (xx + yy) - (0.25 * (xx - yy).powi(2) + xy * xy).sqrt();
            scored.push((min_eig, Vec2::new(i as f64 + 0.5, j as f64 + 0.5)));
        }
    }
    scored.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut picked: Vec<Vec2> = Vec::new();
    for (_, p) in scored {
        if picked.len() == n {
            break;
        }
        if picked.iter().all(|q| q.distance(p) >= gap) {
            picked.push(p);
        }
    }
    picked
}

/// The numbers of JSON document `after` that differ from `before`'s, with
/// their paths (`.features[1].b[1][0]`) and both values. Refuses two
/// documents whose numbers sit at different paths: an edit that was meant
/// to change values only must not move anything.
pub fn changed_numbers(before: &str, after: &str) -> Vec<(String, f64, f64)> {
    fn numbers(v: &serde_json::Value, path: String, out: &mut Vec<(String, f64)>) {
        match v {
            serde_json::Value::Number(n) => out.push((path, n.as_f64().unwrap_or(f64::NAN))),
            serde_json::Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    numbers(v, format!("{path}[{i}]"), out);
                }
            }
            serde_json::Value::Object(o) => {
                for (k, v) in o {
                    numbers(v, format!("{path}.{k}"), out);
                }
            }
            _ => {}
        }
    }
    let read = |text: &str| {
        let mut out = Vec::new();
        let v = serde_json::from_str(text).expect("both documents are JSON");
        numbers(&v, String::new(), &mut out);
        out
    };
    let (x, y) = (read(before), read(after));
    let paths = |v: &[(String, f64)]| v.iter().map(|p| p.0.clone()).collect::<Vec<_>>();
    assert_eq!(
        paths(&x),
        paths(&y),
        "the documents' numbers sit at the same paths"
    );
    x.into_iter()
        .zip(y)
        .filter(|(p, q)| p.1 != q.1)
        .map(|(p, q)| (q.0, p.1, q.1))
        .collect()
}
