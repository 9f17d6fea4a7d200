//! The field warp's hot loop: eight points per step across SIMD lanes, each
//! line's constants together in one cache line, so every constant is one
//! broadcast from a single base pointer.
//! f32 keeps 8 lanes; positions up to 8K stay within ~0.001 px of the f64
//! reference (tested in `tests.rs`).

use wide::f32x8;

use super::lines::LinePair;
use super::weight::{Exponent, Weight};

/// The lines, each one's constants together in one cache line: the kernel
/// broadcasts them from one base pointer, where fifteen separate arrays
/// left too few registers for their pointers (reloaded from the stack at
/// every line).
#[derive(Debug, Clone, Default)]
pub(super) struct Lines {
    lines: Vec<Line>,
    a: f32,
    exponent: Option<Exponent>,
}

/// One line's constants.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(64))]
struct Line {
    // Destination line P→Q, its direction d and 1/|d|², 1/|d|.
    px: f32,
    py: f32,
    qx: f32,
    qy: f32,
    dx: f32,
    dy: f32,
    inv_len2: f32,
    inv_len: f32,
    // Source line P' and its direction e' and unit normal n'.
    spx: f32,
    spy: f32,
    ex: f32,
    ey: f32,
    nx: f32,
    ny: f32,
    /// `length^p` of the destination line.
    len_p: f32,
}

impl Line {
    fn new(pair: &LinePair, weight: &Weight) -> Self {
        let (p, q) = pair.dst;
        let (ps, qs) = pair.src;
        let d = q - p;
        let e = qs - ps;
        let n = e.perp() / e.length();
        Line {
            px: p.x as f32,
            py: p.y as f32,
            qx: q.x as f32,
            qy: q.y as f32,
            dx: d.x as f32,
            dy: d.y as f32,
            inv_len2: (1.0 / d.length_squared()) as f32,
            inv_len: (1.0 / d.length()) as f32,
            spx: ps.x as f32,
            spy: ps.y as f32,
            ex: e.x as f32,
            ey: e.y as f32,
            nx: n.x as f32,
            ny: n.y as f32,
            len_p: d.length().powf(weight.p) as f32,
        }
    }
}

impl Lines {
    pub fn new(pairs: &[LinePair], weight: &Weight) -> Self {
        Lines {
            lines: pairs.iter().map(|pair| Line::new(pair, weight)).collect(),
            a: weight.a as f32,
            exponent: Some(weight.exponent()),
        }
    }

    /// The lines at `indices` of `self`, into `out` (reusing its buffer):
    /// a block's near or far set without recomputing lengths and powers.
    pub fn select_into(&self, indices: &[usize], out: &mut Lines) {
        out.lines.clear();
        out.lines.extend(indices.iter().map(|&i| self.lines[i]));
        out.a = self.a;
        out.exponent = self.exponent;
    }

    /// Positions `(x, y) + Σ w·(X′ − X) / Σ w` over these lines.
    pub fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        let zero = Sums::default();
        self.map_points_plus(xs, ys, |_| zero, (out_x, out_y), None);
    }

    /// Like [`Lines::map_points`], with `base(k)` (sums of other lines,
    /// eight points from `k` on) added before dividing; `out_w`, when
    /// given, gets each point's `Σ w`.
    pub fn map_points_plus(
        &self,
        xs: &[f32],
        ys: &[f32],
        base: impl Fn(usize) -> Sums,
        (out_x, out_y): (&mut [f32], &mut [f32]),
        mut out_w: Option<&mut [f32]>,
    ) {
        self.each8(xs, ys, base, |k, take, x, y, s| {
            // Far from every line a steep falloff can underflow all weights: hold still there.
            let ok = s.w.simd_gt(f32x8::ZERO);
            let inv = ok.select(f32x8::ONE / s.w, f32x8::ZERO);
            store(&mut out_x[k..k + take], x + s.x * inv);
            store(&mut out_y[k..k + take], y + s.y * inv);
            if let Some(w) = out_w.as_deref_mut() {
                store(&mut w[k..k + take], s.w);
            }
        });
    }

    /// The weighted sums themselves, `[Σ w·Δx, Σ w·Δy, Σ w]` per point (for
    /// interpolating the far field).
    pub fn sums(&self, xs: &[f32], ys: &[f32], out: &mut [[f32; 3]]) {
        let zero = Sums::default();
        self.each8(
            xs,
            ys,
            |_| zero,
            |k, take, _, _, s| {
                let (x, y, w) = (s.x.to_array(), s.y.to_array(), s.w.to_array());
                for l in 0..take {
                    out[k + l] = [x[l], y[l], w[l]];
                }
            },
        );
    }

    /// At each point, `after`'s sums less these lines' (`[Σ w·Δx, Σ w·Δy,
    /// Σ w]`), into three slices padded to whole lanes (at least
    /// `xs.len()` rounded up to 8 long). Both sets share one pass, so their
    /// dependency chains overlap.
    pub fn change_to(&self, after: &Lines, xs: &[f32], ys: &[f32], out: [&mut [f32]; 3]) {
        match self.exponent.unwrap_or(Exponent::One) {
            Exponent::Zero => self.change_with(|_| f32x8::ONE, after, xs, ys, out),
            Exponent::Half => self.change_with(|r| r.sqrt(), after, xs, ys, out),
            Exponent::One => self.change_with(|r| r, after, xs, ys, out),
            Exponent::Two => self.change_with(|r| r * r, after, xs, ys, out),
            Exponent::General(b) => {
                let b = f32x8::splat(b);
                self.change_with(move |r| (r.ln() * b).exp(), after, xs, ys, out)
            }
        }
    }

    #[inline(always)]
    fn change_with<F: Fn(f32x8) -> f32x8>(
        &self,
        pow: F,
        after: &Lines,
        xs: &[f32],
        ys: &[f32],
        [dx, dy, dw]: [&mut [f32]; 3],
    ) {
        let mut k = 0;
        while k < xs.len() {
            let take = (xs.len() - k).min(8);
            let (x, y) = (lanes(xs, k), lanes(ys, k));
            let old = self.sums8(&pow, x, y, Sums::default());
            let less = Sums {
                x: -old.x,
                y: -old.y,
                w: -old.w,
            };
            let change = after.sums8(&pow, x, y, less);
            dx[k..k + 8].copy_from_slice(&change.x.to_array());
            dy[k..k + 8].copy_from_slice(&change.y.to_array());
            dw[k..k + 8].copy_from_slice(&change.w.to_array());
            k += take;
        }
    }

    /// Runs the kernel over points eight at a time: `sink(k, take, x, y, sums)`.
    fn each8(
        &self,
        xs: &[f32],
        ys: &[f32],
        base: impl Fn(usize) -> Sums,
        mut sink: impl FnMut(usize, usize, f32x8, f32x8, Sums),
    ) {
        // Dispatch once on the exponent so the inner loop has no branch on it.
        match self.exponent.unwrap_or(Exponent::One) {
            Exponent::Zero => self.run(|_| f32x8::ONE, xs, ys, base, &mut sink),
            Exponent::Half => self.run(|r| r.sqrt(), xs, ys, base, &mut sink),
            Exponent::One => self.run(|r| r, xs, ys, base, &mut sink),
            Exponent::Two => self.run(|r| r * r, xs, ys, base, &mut sink),
            Exponent::General(b) => {
                let b = f32x8::splat(b);
                self.run(move |r| (r.ln() * b).exp(), xs, ys, base, &mut sink)
            }
        }
    }

    #[inline(always)]
    fn run<F: Fn(f32x8) -> f32x8>(
        &self,
        pow: F,
        xs: &[f32],
        ys: &[f32],
        base: impl Fn(usize) -> Sums,
        sink: &mut impl FnMut(usize, usize, f32x8, f32x8, Sums),
    ) {
        let n = xs.len();
        let mut k = 0;
        while k < n {
            let take = (n - k).min(8);
            let (x, y) = (lanes(xs, k), lanes(ys, k));
            let sums = self.sums8(&pow, x, y, base(k));
            sink(k, take, x, y, sums);
            k += take;
        }
    }

    #[inline(always)]
    fn sums8<F: Fn(f32x8) -> f32x8>(&self, pow: &F, x: f32x8, y: f32x8, init: Sums) -> Sums {
        let zero = f32x8::ZERO;
        let one = f32x8::ONE;
        let a = f32x8::splat(self.a);
        let Sums {
            x: mut sx,
            y: mut sy,
            w: mut ws,
        } = init;
        let s = f32x8::splat;
        for l in &self.lines {
            let rx = x - s(l.px);
            let ry = y - s(l.py);
            let (dx, dy) = (s(l.dx), s(l.dy));
            let u = rx.mul_add(dx, ry * dy) * s(l.inv_len2);
            let v = ry.mul_sub(dx, rx * dy) * s(l.inv_len);
            let tx = u.mul_add(s(l.ex), v.mul_add(s(l.nx), s(l.spx)));
            let ty = u.mul_add(s(l.ey), v.mul_add(s(l.ny), s(l.spy)));
            let (qx, qy) = (x - s(l.qx), y - s(l.qy));
            let d2 = u.simd_lt(zero).select(
                rx.mul_add(rx, ry * ry),
                u.simd_gt(one).select(qx.mul_add(qx, qy * qy), v * v),
            );
            let w = pow(s(l.len_p) / (a + d2.sqrt()));
            sx = (tx - x).mul_add(w, sx);
            sy = (ty - y).mul_add(w, sy);
            ws += w;
        }
        Sums {
            x: sx,
            y: sy,
            w: ws,
        }
    }
}

/// Eight values of `s` from `k` on, lanes past its end zero. Whole lanes
/// are loaded as they are: copying a slice of a length the compiler cannot
/// see calls `memcpy`, which at two calls per eight points cost as much as
/// a line's arithmetic.
#[inline(always)]
fn lanes(s: &[f32], k: usize) -> f32x8 {
    match s.get(k..k + 8) {
        Some(whole) => f32x8::new(whole.try_into().expect("8 lanes")),
        None => {
            let mut b = [0f32; 8];
            b[..s.len() - k].copy_from_slice(&s[k..]);
            f32x8::new(b)
        }
    }
}

/// The first `out.len()` (at most 8) lanes of `v` into `out`.
#[inline(always)]
fn store(out: &mut [f32], v: f32x8) {
    let v = v.to_array();
    match <&mut [f32; 8]>::try_from(&mut *out) {
        Ok(whole) => *whole = v,
        Err(_) => out.copy_from_slice(&v[..out.len()]),
    }
}

/// `Σ w·(X′ − X)` per axis and `Σ w` for eight points (or one, in lane 0).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Sums {
    pub x: f32x8,
    pub y: f32x8,
    pub w: f32x8,
}
