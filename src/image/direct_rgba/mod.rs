//! Bilinear and bicubic float RGBA, premultiplied: the plate a host usually
//! sends, and nearly the whole cost of a morph frame once its warps are
//! cached.
//!
//! The general sampler row ([`super::Sampler::sample_row`]) finds each pixel's
//! row through the view and checks slices per tap; here each tap pair is
//! addressed from the buffer's origin and stride, so a pixel is a few integer
//! operations and two eight-wide loads (bilinear), or eight (bicubic: each
//! row's four taps are two loads, summed down the rows, then weighted by
//! pairs of columns at once).
//! With FMA, bilinear pixels go two at a time, their horizontal steps in one
//! vector. The dissolve samples both sources of a pixel in the same
//! iteration ([`blend_row`]): four independent loads close together keep
//! more of them in flight, and no second row is written and read back.
//!
//! A warp walks each output row across many source rows, so the taps of
//! pixels a little ahead are asked of the cache early ([`Taps::prefetch`]);
//! each group of four is placed once, then ([`Ahead`]), and waits in a
//! small ring for its turn: placing each group twice (once to prefetch,
//! once to sample) cost a quarter of the time. The positions themselves
//! are asked for a few groups before they are placed. Past that, on a
//! Xeon both are bound by the instructions a pixel takes, and so is the
//! dissolve on a Zen 5 EPYC. On a Zen 3 EPYC a dissolve's pixel takes
//! nearly as long with every byte in cache as at 1080p (a warp's taps
//! add 15–30 %), and a quarter fewer instructions did not make it faster
//! (docs/PERFORMANCE.md).
//!
//! Bilinear values are bit for bit those of the general path for other
//! sample types and of the separate blend (the same fused multiply-adds in
//! the same order); bicubic ones sum the same sixteen products in another
//! order (within a few float ulps). Positions it does not take (taps
//! outside the image, on or near a pixel centre, NaN) go one by one to
//! [`off_path`], bit for bit the general sampler, or for bicubic to the
//! caller's one-pixel fallback. A row's last one to three pixels go as a
//! group of four too (the last position repeated), so a row split anywhere
//! (a host's tile) gives every pixel the same bits as the whole row.

use wide::bytemuck::cast;
use wide::{f32x8, i32x8, u32x8, u64x4};

use super::edge::EdgeMode;
use super::kernel::SNAP;
use super::{Layout, Sample};
use crate::geom::{PixelScale, RectI};
use crate::prefetch;

mod off_path;

/// How many groups of four pixels ahead [`Taps::prefetch`] asks for taps:
/// 64 pixels, a few hundred nanoseconds at this kernel's pace, about one
/// memory latency. Measured against 8 and 32 in docs/PERFORMANCE.md (8
/// was best while each group was located twice, and slower since).
const AHEAD: usize = 16;

/// How many groups past the one [`Ahead::pass`] places it asks the cache for
/// positions: the map streams, yet on a Zen 5 EPYC a dissolve spent a fifth
/// of its time waiting on the map's lines until they were asked for a few
/// groups early (1 to 12 groups all did as well; docs/PERFORMANCE.md).
const POSITIONS_AHEAD: usize = 4;

const _: () = assert!(
    cfg!(target_endian = "little"),
    "Taps::first_taps reads 64-bit lanes' low halves as even lanes"
);

/// `Place::fast` when all four pixels take the direct path on both axes.
const ALL_FAST: u32 = 0xff;

/// Whether bilinear pixels go two at a time ([`Taps::pixel_pair`]): only
/// where eight-wide `mul_add` is the fused operation scalar `f32::mul_add`
/// is, so both give the same bits.
const PAIRS: bool = cfg!(target_feature = "fma");

/// A source sampled by direct addressing; see [`Taps::new`].
#[derive(Clone, Copy)]
pub(crate) struct Taps<'a, T> {
    data: &'a [T],
    /// Index of the first sample of the bounds' corner pixel, for
    /// bilinear on a buffer stored top row first that of the pixel a row
    /// up: where [`Place::at`] counts from.
    origin: i32,
    /// From [`Place::at`] to the taps' top row, which [`Self::prefetch`]
    /// asks for.
    top: i32,
    /// Samples from one row to the next row up.
    stride: i32,
    /// `stride`'s size, and whether the row up lies lower in the buffer
    /// (a host's image stored top row first): see [`Self::rows_at`].
    span: u32,
    flipped: bool,
    /// Samples per pixel and per row, interleaved: a pixel's offset from
    /// `origin` is the sum of a pair of its index (relative to the corner)
    /// times these. All `i32`: buffers this path takes are shorter than
    /// `i32::MAX`, and inside pixels' offsets lie within them.
    step: i32x8,
    /// Canonical position to pixel index, x and y interleaved as positions are.
    scale: f32x8,
    /// Every tap inside: `lo ≤ index < hi` per axis, interleaved likewise;
    /// `lo` is also the first tap's offset from the integer part.
    lo: f32x8,
    hi: f32x8,
    /// Catmull-Rom's four taps per axis, else bilinear's two.
    cubic: bool,
    /// What [`off_path`] needs besides: the source's bounds, the index of
    /// its corner pixel, and what lies outside.
    bounds: RectI,
    corner: i32,
    edge: EdgeMode,
}

/// Where four positions (one eight-wide vector of x, y pairs) fall in a
/// source: all a bilinear pixel needs.
#[derive(Clone, Copy, Default)]
struct Place {
    /// Two bits per pixel (x, y): set where that axis takes the fast path.
    fast: u32,
    /// Index in the buffer of each pixel's first tap ([`Self::at`]), pixel
    /// `k`'s in lane `2k` (where its x fraction lies); odd lanes unused.
    first: [i32; 8],
    /// Fractions (weights of the right and upper taps), interleaved.
    t: [f32; 8],
}

impl Place {
    /// Index in the buffer of pixel `k`'s first tap: bilinear, the left
    /// tap of whichever of its two rows lies lower in the buffer
    /// ([`Taps::rows_at`]); bicubic, the lowest row's leftmost tap.
    /// Nonsense, and not read, for a pixel off the fast path.
    #[inline(always)]
    fn at(&self, k: usize) -> i32 {
        self.first[2 * k]
    }
}

/// Four positions located for either filter.
struct Located {
    place: Place,
    /// Bicubic only: the Catmull-Rom weights of taps −1, 0, 1, 2 for each
    /// fraction, computed for all eight at once.
    w: [[f32; 8]; 4],
}

impl<'a, T: Sample> Taps<'a, T> {
    /// Direct taps into premultiplied RGBA floats `data` laid out as
    /// `layout`, at `scale`, with `edge` outside (see
    /// [`super::Sampler::direct_taps`]); `None` for a buffer too large to
    /// address in `i32`, or no pixels.
    pub(crate) fn new(
        data: &'a [T],
        layout: Layout,
        scale: PixelScale,
        edge: EdgeMode,
        cubic: bool,
    ) -> Option<Self> {
        let b = layout.bounds;
        if data.len() > i32::MAX as usize
            || layout.row_stride.unsigned_abs() > i32::MAX as usize
            || b.is_empty()
        {
            return None;
        }
        let stride = layout.row_stride as i32;
        let pairs = |x: f32, y: f32| f32x8::new([x, y, x, y, x, y, x, y]);
        // Taps reach `below` pixels under the integer part and `above` over it.
        let (below, above) = if cubic { (1, 2) } else { (0, 1) };
        let base = layout.base as i32;
        let (origin, top) = match (cubic, stride < 0) {
            (true, _) => (base, stride.wrapping_mul(3)),
            // The row up is the lower one: the place is the top row.
            (false, true) => (base + stride, 0),
            (false, false) => (base, stride),
        };
        Some(Taps {
            data,
            origin,
            top,
            stride,
            span: stride.unsigned_abs(),
            flipped: stride < 0,
            step: i32x8::new([4, stride, 4, stride, 4, stride, 4, stride]),
            scale: pairs(scale.x as f32, scale.y as f32),
            lo: pairs((b.x1 + below) as f32, (b.y1 + below) as f32),
            hi: pairs((b.x2 - above) as f32, (b.y2 - above) as f32),
            cubic,
            bounds: b,
            corner: base,
            edge,
        })
    }

    #[inline(always)]
    fn locate(&self, positions: &[f32; 8]) -> Located {
        self.located(self.place(positions))
    }

    /// A placed four with the bicubic weights its fractions give.
    #[inline(always)]
    fn located(&self, place: Place) -> Located {
        Located {
            place,
            w: match self.cubic {
                true => {
                    super::kernel::catmull_rom_weights8(f32x8::new(place.t)).map(f32x8::to_array)
                }
                false => [[0.0; 8]; 4],
            },
        }
    }

    /// Where four positions' taps lie, and which pixels take the fast path.
    #[inline(always)]
    fn place(&self, positions: &[f32; 8]) -> Place {
        let s = f32x8::splat;
        let (f, whole) = self.index(positions);
        let t = f - whole;
        // NaN fails every comparison, so it takes the fallback too; so do
        // fractions near a centre line, which the fallback snaps.
        let fast =
            f.simd_ge(self.lo) & f.simd_lt(self.hi) & t.simd_gt(s(SNAP)) & t.simd_lt(s(1.0 - SNAP));
        Place {
            fast: fast.to_bitmask(),
            first: self.first_taps(whole).to_array(),
            t: t.to_array(),
        }
    }

    /// Four positions' continuous pixel index (integers are pixel centres)
    /// and its whole part.
    #[inline(always)]
    fn index(&self, positions: &[f32; 8]) -> (f32x8, f32x8) {
        let f = f32x8::new(*positions) * self.scale - f32x8::splat(0.5);
        (f, f.floor())
    }

    /// Each pixel's first tap's index in the buffer in the even lane of
    /// its pair: relative to the corner, the first tap, one below the
    /// integer part for bicubic (whose `lo` is one above the corner).
    ///
    /// A pixel's column and row offsets, side by side, are the two halves
    /// of one 64-bit lane, so one shift and one add sum all four pairs
    /// (in the low halves), where taking the lanes apart cost nine
    /// instructions. Wrapping, as the halves' low 32 bits: a pixel off
    /// the fast path (NaN, far outside) may have any offsets, and its
    /// index is never used. The low half is the even lane on a
    /// little-endian target, which every target this builds for is.
    #[inline(always)]
    fn first_taps(&self, whole: f32x8) -> i32x8 {
        let offsets = (whole - self.lo).fast_trunc_int() * self.step;
        let pairs: u64x4 = cast(offsets);
        cast::<u64x4, i32x8>(pairs + (pairs >> 32)) + i32x8::splat(self.origin)
    }

    /// Asks the cache for the top row of taps of each pixel of a placed
    /// four, some time before their turn ([`Ahead`]).
    ///
    /// Rows go up the output, so the top row is the one no earlier output
    /// row brought in. A warp's taps wander across source rows along an
    /// output row (a 100-line field warp's cross ~30 of them), which the
    /// hardware's stream prefetchers never lock onto: without this, each
    /// new cache line is a full memory latency with few others in flight.
    /// Pixels 0 and 2 alone (whose lines the others' taps mostly share)
    /// cost the dissolve, with two sources' taps in flight, a tenth of its
    /// time.
    #[inline(always)]
    fn prefetch(&self, place: &Place) {
        // Wrapping, then clamped into the buffer, all four at once: a
        // pixel off the fast path has a nonsense index, and the line it
        // then asks for is a harmless one.
        let last = u32x8::splat((self.data.len() as u32).wrapping_sub(1));
        let tops: u32x8 = cast(i32x8::new(place.first) + i32x8::splat(self.top));
        let tops = tops.min(last).to_array();
        for k in 0..4 {
            if let Some(v) = self.data.get(tops[2 * k] as usize) {
                prefetch::line(v);
            }
        }
    }

    /// The eight samples (two pixels of a tap row) from index `lower` and
    /// the eight `span` after them, as the row below and the row above,
    /// from one slice of the samples between them: the offsets of both
    /// within it are known to the compiler (each 0 or `span`, and `span`
    /// a `u32`). `FLIP` is [`Self::flipped`], a constant in each row's
    /// loop ([`row`], [`blend_row`]): chosen per pixel, it cost a dozen
    /// instructions and the checks the offsets spare.
    ///
    /// `lower` is clamped to the last index such a slice may start at
    /// ([`Self::taps_from`]): a no-op for the pixels that come here (both
    /// rows inside), and what lets the compiler see the slice is in
    /// bounds. In place of the check (the slice's end computed, compared
    /// and branched on, for every pixel of each source) it took 7 % of
    /// the dissolve's instructions and 2–8 % of its time (median 5 %) on
    /// a Zen 5 EPYC (docs/PERFORMANCE.md).
    #[inline(always)]
    fn rows_at<const FLIP: bool>(&self, lower: i32) -> (f32x8, f32x8) {
        debug_assert_eq!(FLIP, self.flipped);
        let span = self.span as usize;
        // An index inside the buffer, which fits `i32`.
        let both = self.taps_from(lower as u32 as usize, span + 8);
        let (below, above) = if FLIP { (span, 0) } else { (0, span) };
        (T::load8(&both[below..]), T::load8(&both[above..]))
    }

    /// Bicubic's sixteen taps of a pixel whose first tap (that of its
    /// lowest row, [`Place::at`]) is at index `at`: the samples from the
    /// lowest to the highest of its four tap rows in the buffer, and where
    /// in them tap row `r` (0 the lowest, up) starts. Clamped
    /// ([`Self::taps_from`]), so the compiler sees every load in bounds:
    /// one compare and move a pixel instead of a check on each of its
    /// eight loads, which took a fifth of a bicubic dissolve's
    /// instructions and about a tenth of its time (docs/PERFORMANCE.md).
    #[inline(always)]
    fn tap_block<const FLIP: bool>(&self, at: i32) -> (&[T], impl Fn(usize) -> usize) {
        debug_assert_eq!(FLIP, self.flipped);
        let span = self.span as usize;
        let reach = 3 * span + 16;
        // Stored top row first, the row up lies lower in the buffer.
        let start = match FLIP {
            true => at.wrapping_add(self.stride.wrapping_mul(3)),
            false => at,
        };
        let row = move |r: usize| match FLIP {
            true => (3 - r) * span,
            false => r * span,
        };
        (self.taps_from(start as u32 as usize, reach), row)
    }

    /// The `reach` samples from index `start`, which a fast pixel's taps
    /// lie within: `start` clamped to the last index such a slice may
    /// begin at, a no-op for them, so that the compiler sees the slice in
    /// bounds and, inlined, every load from it at offsets it knows.
    #[inline(always)]
    fn taps_from(&self, start: usize, reach: usize) -> &[T] {
        let last = self
            .data
            .len()
            .checked_sub(reach)
            .expect("a fast pixel's taps lie in the buffer");
        debug_assert!(start <= last, "a fast pixel's taps lie in the buffer");
        let start = start.min(last);
        &self.data[start..start + reach]
    }

    /// Pixel `k` of a located four, both axes on the fast path.
    #[inline(always)]
    fn pixel<const FLIP: bool>(&self, l: &Located, k: usize) -> [f32; 4] {
        if self.cubic {
            return self.cubic_pixel::<FLIP>(l, k);
        }
        let l = &l.place;
        let (below, above) = self.rows_at::<FLIP>(l.at(k));
        // Each row's pair of horizontal neighbours blended vertically, then
        // the two halves horizontally.
        let v = (above - below)
            .mul_add(f32x8::splat(l.t[2 * k + 1]), below)
            .to_array();
        let tx = l.t[2 * k];
        std::array::from_fn(|c| (v[4 + c] - v[c]).mul_add(tx, v[c]))
    }

    /// Bilinear pixels `k` and `k + 1` of a located four, all four taps on
    /// the fast path: the same operations as two [`Self::pixel`]s, the
    /// horizontal step for both pixels in one eight-wide vector.
    #[inline(always)]
    fn pixel_pair<const FLIP: bool>(&self, l: &Place, k: usize) -> f32x8 {
        let vertical = |k: usize| {
            let (below, above) = self.rows_at::<FLIP>(l.at(k));
            (above - below)
                .mul_add(f32x8::splat(l.t[2 * k + 1]), below)
                .to_array()
        };
        let (p, q) = (vertical(k), vertical(k + 1));
        let left = f32x8::new([p[0], p[1], p[2], p[3], q[0], q[1], q[2], q[3]]);
        let right = f32x8::new([p[4], p[5], p[6], p[7], q[4], q[5], q[6], q[7]]);
        let (tp, tq) = (l.t[2 * k], l.t[2 * k + 2]);
        let t = f32x8::new([tp, tp, tp, tp, tq, tq, tq, tq]);
        (right - left).mul_add(t, left)
    }
}

impl<T: Sample> Taps<'_, T> {
    /// Pixel `k` of a located four by Catmull-Rom: each of the four rows'
    /// four taps (sixteen floats) is two eight-wide loads; the columns are
    /// summed down the rows by the rows' weights first (two independent
    /// chains), then weighted two columns at a time, and the two halves of
    /// the sum add up to the pixel. The weights come with the location,
    /// computed for four pixels at once.
    #[inline(always)]
    fn cubic_pixel<const FLIP: bool>(&self, l: &Located, k: usize) -> [f32; 4] {
        let (x, y) = (2 * k, 2 * k + 1);
        let (block, row) = self.tap_block::<FLIP>(l.place.at(k));
        let load = |at: usize| T::load8(&block[at..]);
        let w = &l.w;
        let pair = |a: f32, b: f32| f32x8::new([a, a, a, a, b, b, b, b]);
        let (left, right) = (pair(w[0][x], w[1][x]), pair(w[2][x], w[3][x]));
        // Columns −1, 0 (`near`) and 1, 2 (`far`) summed down the rows first.
        let wy = |r: usize| f32x8::splat(w[r][y]);
        let (mut near, mut far) = (load(row(0)) * wy(0), load(row(0) + 8) * wy(0));
        for r in 1..4 {
            near = load(row(r)).mul_add(wy(r), near);
            far = load(row(r) + 8).mul_add(wy(r), far);
        }
        let sum = far.mul_add(right, near * left);
        let v = sum.to_array();
        std::array::from_fn(|c| v[c] + v[4 + c])
    }
}

/// A row's groups of four positions placed [`AHEAD`] groups before their
/// turn, when their taps' top rows are asked of the cache
/// ([`Taps::prefetch`]): placing each group once serves both.
struct Ahead<'s, 'a, T> {
    taps: &'s Taps<'a, T>,
    groups: &'s [[f32; 8]],
    /// Group `g`'s place in slot `g % AHEAD` until its turn.
    ring: [Place; AHEAD],
}

impl<'s, 'a, T: Sample> Ahead<'s, 'a, T> {
    fn new(taps: &'s Taps<'a, T>, groups: &'s [[f32; 8]]) -> Self {
        let mut ring = [Place::default(); AHEAD];
        for (slot, p) in ring.iter_mut().zip(groups) {
            *slot = taps.place(p);
            taps.prefetch(slot);
        }
        Ahead { taps, groups, ring }
    }

    /// Group `g`'s place, until [`Self::pass`] of `g`.
    #[inline(always)]
    fn place(&self, g: usize) -> &Place {
        &self.ring[g % AHEAD]
    }

    /// Done with group `g`: group `g + AHEAD` is placed in its slot, and
    /// the positions of a group [`POSITIONS_AHEAD`] past it are asked of
    /// the cache.
    #[inline(always)]
    fn pass(&mut self, g: usize) {
        if let Some(p) = self.groups.get(g + AHEAD + POSITIONS_AHEAD) {
            prefetch::line(p);
        }
        if let Some(p) = self.groups.get(g + AHEAD) {
            let slot = &mut self.ring[g % AHEAD];
            *slot = self.taps.place(p);
            self.taps.prefetch(slot);
        }
    }
}

/// Two RGBA pixels from one eight-wide vector.
#[inline(always)]
fn put_pair(out: &mut [[f32; 4]; 2], v: f32x8) {
    *out.as_flattened_mut()
        .first_chunk_mut::<8>()
        .expect("two pixels") = v.to_array();
}

/// The eight floats of each group of four positions.
fn groups(positions: &[[f32; 2]]) -> &[[f32; 8]] {
    positions.as_flattened().as_chunks::<8>().0
}

/// Samples `taps` at each of `positions` into `out`; `slow(n, out)` computes
/// bicubic pixel `n` wherever the direct path does not apply (bilinear ones
/// it computes itself, [`off_path`]).
pub(crate) fn row<T: Sample>(
    taps: &Taps<'_, T>,
    positions: &[[f32; 2]],
    out: &mut [[f32; 4]],
    slow: impl Fn(usize, &mut [f32; 4]),
) {
    assert_eq!(positions.len(), out.len(), "one position per pixel");
    match taps.flipped {
        true => row_with::<T, true>(taps, positions, out, slow),
        false => row_with::<T, false>(taps, positions, out, slow),
    }
}

/// [`row`] for a buffer stored top row first (`FLIP`) or bottom row first.
#[inline(always)]
fn row_with<T: Sample, const FLIP: bool>(
    taps: &Taps<'_, T>,
    positions: &[[f32; 2]],
    out: &mut [[f32; 4]],
    slow: impl Fn(usize, &mut [f32; 4]),
) {
    // Pixels `first..` of a located group, one by one.
    let each = |l: &Located, first: usize, outs: &mut [[f32; 4]]| {
        for (k, o) in outs.iter_mut().enumerate() {
            let n = first + k;
            *o = if (l.place.fast >> (2 * k)) & 3 == 3 {
                taps.pixel::<FLIP>(l, k)
            } else {
                taps.off_path(positions[n], || {
                    let mut v = [0.0; 4];
                    slow(n, &mut v);
                    v
                })
            };
        }
    };
    let four = groups(positions);
    let mut ahead = Ahead::new(taps, four);
    for (g, outs) in out.chunks_exact_mut(4).enumerate() {
        let place = ahead.place(g);
        if PAIRS && place.fast == ALL_FAST && !taps.cubic {
            for (k, o) in [0, 2].into_iter().zip(outs.as_chunks_mut::<2>().0) {
                put_pair(o, taps.pixel_pair::<FLIP>(place, k));
            }
        } else {
            each(&taps.located(*place), 4 * g, outs);
        }
        ahead.pass(g);
    }
    let done = four.len() * 4;
    if done < out.len() {
        each(
            &taps.locate(&padded(&positions[done..])),
            done,
            &mut out[done..],
        );
    }
}

/// A row's last one to three positions as a group of four, the last
/// repeated: they take the same path as pixels inside a group, so a row
/// split anywhere (a host's tile) gives every pixel the same bits.
fn padded(rest: &[[f32; 2]]) -> [f32; 8] {
    let last = rest[rest.len() - 1];
    let mut group = [0f32; 8];
    for (k, xy) in group.chunks_exact_mut(2).enumerate() {
        xy.copy_from_slice(rest.get(k).unwrap_or(&last));
    }
    group
}

/// `out = wa · A + wb · B`, A sampled at `pa` and B at `pb`, both sources of
/// a pixel in one iteration; each source's `slow(n)` gives its bicubic pixel
/// `n` wherever the direct path does not apply to it.
pub(crate) fn blend_row<S: Sample>(
    (a, pa, wa, slow_a): (&Taps<'_, S>, &[[f32; 2]], f32, impl Fn(usize) -> [f32; 4]),
    (b, pb, wb, slow_b): (&Taps<'_, S>, &[[f32; 2]], f32, impl Fn(usize) -> [f32; 4]),
    out: &mut [[f32; 4]],
) {
    assert!(
        pa.len() == out.len() && pb.len() == out.len(),
        "one position per pixel and source"
    );
    let (a, b) = ((a, pa, wa, slow_a), (b, pb, wb, slow_b));
    match (a.0.flipped, b.0.flipped) {
        (true, true) => blend_row_with::<S, true, true>(a, b, out),
        (true, false) => blend_row_with::<S, true, false>(a, b, out),
        (false, true) => blend_row_with::<S, false, true>(a, b, out),
        (false, false) => blend_row_with::<S, false, false>(a, b, out),
    }
}

/// [`blend_row`] for buffers stored top row first (`FA`, `FB`) or bottom
/// row first.
#[inline(always)]
fn blend_row_with<S: Sample, const FA: bool, const FB: bool>(
    (a, pa, wa, slow_a): (&Taps<'_, S>, &[[f32; 2]], f32, impl Fn(usize) -> [f32; 4]),
    (b, pb, wb, slow_b): (&Taps<'_, S>, &[[f32; 2]], f32, impl Fn(usize) -> [f32; 4]),
    out: &mut [[f32; 4]],
) {
    let blend = |va: [f32; 4], vb: [f32; 4]| std::array::from_fn(|c| wb.mul_add(vb[c], wa * va[c]));
    // Pixels `first..` of a located group of each source, one by one.
    let each = |(la, lb): (&Located, &Located), first: usize, outs: &mut [[f32; 4]]| {
        for (k, o) in outs.iter_mut().enumerate() {
            let fast = |l: &Located| (l.place.fast >> (2 * k)) & 3 == 3;
            let (fast_a, fast_b) = (fast(la), fast(lb));
            *o = if fast_a && fast_b {
                blend(a.pixel::<FA>(la, k), b.pixel::<FB>(lb, k))
            } else {
                let n = first + k;
                let va = if fast_a {
                    a.pixel::<FA>(la, k)
                } else {
                    a.off_path(pa[n], || slow_a(n))
                };
                let vb = if fast_b {
                    b.pixel::<FB>(lb, k)
                } else {
                    b.off_path(pb[n], || slow_b(n))
                };
                blend(va, vb)
            };
        }
    };
    let (four_a, four_b) = (groups(pa), groups(pb));
    let (mut ahead_a, mut ahead_b) = (Ahead::new(a, four_a), Ahead::new(b, four_b));
    for (g, outs) in out.chunks_exact_mut(4).enumerate() {
        let (la, lb) = (ahead_a.place(g), ahead_b.place(g));
        if PAIRS && la.fast & lb.fast == ALL_FAST && !a.cubic && !b.cubic {
            let (wa8, wb8) = (f32x8::splat(wa), f32x8::splat(wb));
            for (k, o) in [0, 2].into_iter().zip(outs.as_chunks_mut::<2>().0) {
                let v = b
                    .pixel_pair::<FB>(lb, k)
                    .mul_add(wb8, a.pixel_pair::<FA>(la, k) * wa8);
                put_pair(o, v);
            }
        } else {
            each((&a.located(*la), &b.located(*lb)), 4 * g, outs);
        }
        ahead_a.pass(g);
        ahead_b.pass(g);
    }
    let done = four_a.len() * 4;
    if done < out.len() {
        let (la, lb) = (
            a.locate(&padded(&pa[done..])),
            b.locate(&padded(&pb[done..])),
        );
        each((&la, &lb), done, &mut out[done..]);
    }
}
