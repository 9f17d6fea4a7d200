//! The field map again after a few lines move, as while a compositor drags
//! one: eq. (4)'s multiple-line algorithm divides two sums over lines
//! (Beier-Neely §3.3), so a moved line changes each pixel by its own old
//! and new terms, whatever the other lines do. A pixel's new position is
//! `X + (S − s_old + s_new) / (W − w_old + w_new)`, with `S = (X′ − X)·W`
//! read back from the map before and `W` kept beside it.
//!
//! Only the moved lines are evaluated, exactly, at every pixel; a block with
//! a pixel where they carry a tenth of the weight or more is evaluated
//! afresh. Blocks they come near need nothing more: whether a fresh block
//! would count them among its near lines or its far grid, exact terms
//! swapped in leave the sums' error as it was.

use std::sync::Arc;

use super::kernel::Lines;
use super::lines::LinePair;
use super::settings::Evaluation;
use super::split::{fill_band, Band, Setup};
use super::warp::FieldWarp;
use super::weight::Weight;
use crate::geom::{PixelScale, RectI};
use crate::image::WarpMap;

/// Redos in a row before a full evaluation again: each rounds the kept
/// sums once more (about 1e-4 px at 8K), so a long drag stays bounded.
const MAX_REDOS: u32 = 64;

/// A field warp's map over a window with what it takes to redo it cheaply
/// after a few lines move ([`FieldWarp::field_map_after`]).
#[derive(Debug)]
pub struct FieldMap {
    map: Arc<WarpMap>,
    /// `Σ w` per pixel (empty for an identity map).
    weights: Vec<f32>,
    /// Per block: whether its far field was interpolated.
    interpolated: Vec<bool>,
    pairs: Vec<LinePair>,
    weight: Weight,
    evaluation: Evaluation,
    redos: u32,
}

impl FieldMap {
    /// The map.
    pub fn map(&self) -> &Arc<WarpMap> {
        &self.map
    }

    /// Heap bytes held (for cache budgets).
    pub fn memory_bytes(&self) -> usize {
        self.map.memory_bytes()
            + self.weights.len() * std::mem::size_of::<f32>()
            + self.interpolated.len()
    }

    /// How many redos this map is from a full evaluation (0: it is one).
    pub fn redos(&self) -> u32 {
        self.redos
    }
}

impl FieldWarp {
    /// The map over `window` (pixels at `scale`) as [`crate::warp::Warp::map_window`]
    /// makes it, with the sums kept for [`FieldWarp::field_map_after`].
    pub fn field_map(&self, window: RectI, scale: PixelScale) -> FieldMap {
        self.field_map_after(window, scale, None)
    }

    /// The map over `window`, redone from `before` when that is this warp's
    /// map with a few lines moved (same window, scale and settings, at most
    /// a quarter of the lines changed), else evaluated in full. Either way
    /// within the evaluation's tolerance of the exact map (exact: within
    /// float rounding of it).
    pub fn field_map_after(
        &self,
        window: RectI,
        scale: PixelScale,
        before: Option<&FieldMap>,
    ) -> FieldMap {
        let kept = |map: WarpMap, weights, interpolated, redos| FieldMap {
            map: Arc::new(map),
            weights,
            interpolated,
            pairs: self.pairs.clone(),
            weight: self.weight,
            evaluation: self.evaluation,
            redos,
        };
        if self.identity {
            return kept(WarpMap::identity(window, scale), Vec::new(), Vec::new(), 0);
        }
        let tolerance = match self.evaluation {
            Evaluation::Exact => None,
            Evaluation::Adaptive { tolerance } => Some(tolerance),
        };
        let setup = Setup::new(self, window, scale, tolerance);
        let mut pos = vec![[0f32; 2]; window.area()];
        let mut weights = vec![0f32; window.area()];
        let mut made = vec![false; setup.block_count()];
        let redos = match before.and_then(|b| Moved::between(b, &setup)) {
            Some(moved) => {
                setup.each_band(
                    &mut pos,
                    Some(&mut weights),
                    &mut made,
                    |band, first, made| moved.redo(band, first, made),
                );
                moved.before.redos + 1
            }
            None => {
                setup.each_band(&mut pos, Some(&mut weights), &mut made, |band, _, made| {
                    fill_band(band, made)
                });
                0
            }
        };
        kept(WarpMap::new(window, scale, pos), weights, made, redos)
    }
}

/// The lines that moved since a map was made: their terms before and after.
struct Moved<'a> {
    before: &'a FieldMap,
    old: Lines,
    new: Lines,
}

impl<'a> Moved<'a> {
    /// What moved between `before` and `setup`'s warp, when a redo applies.
    fn between(before: &'a FieldMap, setup: &Setup) -> Option<Self> {
        let warp = setup.warp;
        let same = before.map.window == setup.window
            && before.map.scale == setup.scale
            && before.weight == warp.weight
            && before.evaluation == warp.evaluation
            && before.pairs.len() == warp.pairs.len()
            && !before.weights.is_empty()
            && before.redos < MAX_REDOS;
        if !same {
            return None;
        }
        let moved: Vec<usize> = (0..warp.pairs.len())
            .filter(|&k| before.pairs[k] != warp.pairs[k])
            .collect();
        if moved.len() * 4 > warp.pairs.len() {
            return None;
        }
        let pick = |pairs: &[LinePair]| moved.iter().map(|&k| pairs[k]).collect::<Vec<_>>();
        Some(Moved {
            before,
            old: Lines::new(&pick(&before.pairs), &warp.weight),
            new: Lines::new(&pick(&warp.pairs), &warp.weight),
        })
    }

    /// A band of the new map: `first` numbers its first block, and `made`
    /// gets whether each block's far field is interpolated (as it was).
    /// Blocks are shifted row by row across the whole band (the map is read
    /// and written in the order it lies in memory); those where some pixel's
    /// sums cannot take the shift are evaluated afresh.
    ///
    /// A block the moved lines come near needs no more than that: their
    /// terms are swapped exactly wherever they lie, so whether a fresh block
    /// would have put them among its near lines or its far grid changes
    /// nothing but how exactly they are counted (see [`Self::shift`]).
    /// Near them the swap's weight check is what refuses a block.
    fn redo(&self, band: &mut Band, first: usize, made: &mut [bool]) {
        let fresh = self.shift(band, made.len());
        for (k, made) in made.iter_mut().enumerate() {
            *made = match fresh[k] {
                true => band.block(k).fill(),
                false => self.before.interpolated[first + k],
            };
        }
    }

    /// Swaps the moved lines' old terms for their new ones, evaluated
    /// exactly, in every pixel of the band's `blocks`, row by row, and says
    /// which blocks some pixel's sums could not take it in (from that row
    /// on they are skipped, to be evaluated afresh).
    ///
    /// Exact terms leave each pixel's error what it was: the far field's
    /// interpolation error in the sums (checked when the block was made) is
    /// untouched, and it moves the position by about as much while the
    /// total weight changes by a tenth or less, which [`swap_terms`] holds.
    /// That holds as well where a moved line was one of a block's far lines:
    /// its old term's share of that error stays, as it was, and its new term
    /// is exact.
    fn shift(&self, band: &mut Band, blocks: usize) -> Vec<bool> {
        let setup = band.setup;
        let (window, scale) = (setup.window, setup.scale);
        let mut fresh = vec![false; blocks];
        let xs: Vec<f32> = (window.x1..window.x2)
            .map(|i| scale.pixel_centre(i, band.y1).x as f32)
            .collect();
        let padded = xs.len().div_ceil(8) * 8 + 8;
        let mut ys = vec![0f32; xs.len()];
        let mut change: [Vec<f32>; 4] = std::array::from_fn(|_| vec![0f32; padded]);
        for j in band.y1..band.y2 {
            let y = scale.pixel_centre(window.x1, j).y as f32;
            ys.fill(y);
            let was = self.before.map.row(j).expect("a kept map has rows");
            let at = (j - window.y1) as usize * window.width();
            let was_w = &self.before.weights[at..at + window.width()];
            let (out, weights) = band.row_mut(j);
            let weights = weights.expect("a redo keeps weights");
            for (k, fresh) in fresh.iter_mut().enumerate() {
                if *fresh {
                    continue;
                }
                let cols = setup.block_columns(k);
                let (xs, ys) = (&xs[cols.clone()], &ys[cols.clone()]);
                let change_out = change.each_mut().map(|v| &mut v[..]);
                (self.old).change_to(&self.new, xs, ys, change_out);
                let was = (&was[cols.clone()], &was_w[cols.clone()]);
                let out = (&mut out[cols.clone()], &mut weights[cols.clone()]);
                if !swap_terms(xs, y, was, change.each_ref().map(|v| &v[..]), out) {
                    *fresh = true;
                }
            }
        }
        fresh
    }
}

/// A row's positions and `Σ w` (`out`) from those before (`was`) with the
/// moved lines' terms changed by `[Δ Σ w·Δx, Δ Σ w·Δy, Δ Σ w]` and their old
/// `Σ w`, for pixels at `xs` on row `y`; false when the old terms carried a
/// tenth of a pixel's weight or more (taking them away would cancel digits
/// of its sums), or the weight changes by a tenth or more. One pass with no
/// early exit, so it vectorises.
fn swap_terms(
    xs: &[f32],
    y: f32,
    (was, was_w): (&[[f32; 2]], &[f32]),
    [dx, dy, dw, old_w]: [&[f32]; 4],
    (out, out_w): (&mut [[f32; 2]], &mut [f32]),
) -> bool {
    let n = out.len();
    let (xs, was, was_w, out_w) = (&xs[..n], &was[..n], &was_w[..n], &mut out_w[..n]);
    let (dx, dy, dw, old_w) = (&dx[..n], &dy[..n], &dw[..n], &old_w[..n]);
    let mut good = true;
    for k in 0..n {
        let (w, p) = (was_w[k], was[k]);
        let w1 = w + dw[k];
        let tenth = 0.1 * w;
        // NaNs compare false: they fail here too.
        good &= (w > 0.0) & (w < f32::INFINITY) & (old_w[k] <= tenth) & (dw[k].abs() <= tenth);
        let sx = (p[0] - xs[k]) * w + dx[k];
        let sy = (p[1] - y) * w + dy[k];
        out[k] = [xs[k] + sx / w1, y + sy / w1];
        out_w[k] = w1;
    }
    good
}
