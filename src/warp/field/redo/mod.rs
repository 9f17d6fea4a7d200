//! The field map again after a few lines move, as while a compositor drags
//! one: eq. (4)'s multiple-line algorithm divides two sums over lines
//! (Beier-Neely §3.3), so a moved line changes each pixel by its own old
//! and new terms, whatever the other lines do. A pixel's new position is
//! `X + (S − s_old + s_new) / (W − w_old + w_new)`, with `S = (X′ − X)·W`
//! read back from the map before and `W` kept beside it.
//!
//! Only the moved lines are evaluated, and only where they matter:
//! - Blocks near them (as near as the adaptive evaluation's near lines)
//!   take their terms exactly at every pixel. Whether a fresh block would
//!   count them among its near lines or its far grid, exact terms swapped
//!   in leave the sums' error as it was.
//! - Farther away their change is as smooth as a far line's term, so it is
//!   evaluated on a grid and waits in the block's [`lag`] until leaving it
//!   out would cost a share of the tolerance; then the pixels take it,
//!   interpolated. A nudge touches the pixels near the line and few more.
//! - A pixel whose weight changes by a tenth or more (the moved line
//!   dominates it, and the division would magnify the map's rounding) is
//!   evaluated exactly with every line; its block afresh when such pixels
//!   are a quarter of it.
//! - What a block owes is kept as sums, so it moves the positions by more
//!   where a write lowered the block's weights (a line dragged close past
//!   it): a block that owes more than its allowance once written is
//!   evaluated afresh.
//!
//! A redo edits the map before in place when it is handed over
//! ([`FieldWarp::field_map_from`]), so the pixels it leaves alone cost
//! nothing: no copy, no fresh memory.

use std::sync::Arc;

use super::grid::{Grid, Rows};
use super::kernel::Lines;
use super::lines::LinePair;
use super::settings::Evaluation;
use super::split::{corners, is_within, Band, Setup};
use super::warp::FieldWarp;
use super::weight::Weight;
use crate::geom::{PixelScale, RectI, Vec2};
use crate::image::WarpMap;

mod lag;
mod swap;

use lag::{Lag, Samples, Take, Tracked};
use swap::{swap_terms, RowChange};

/// Blocks closer than this (pixels) to a moved line, before or after,
/// take its change exactly: its term has a kink on the line itself, which
/// no grid follows, and bends sharply near it. Farther away each block
/// checks the grid's error at its cells' centres and edges (see [`lag`]).
/// At half this distance a sweep of long drags came to 98 % of the
/// tolerance; at this one (the adaptive evaluation's own), to 78 %.
const CLOSE: f64 = super::split::NEAR;

/// Redos that may write a block before it is evaluated afresh: each
/// rounds its kept sums once more (about 1e-4 px at 8K), so a long drag
/// stays bounded. The last [`STAGGER`] of them are staggered over the
/// blocks, so no redo makes many afresh at once: making the whole map
/// afresh after 64 redos, as before, made one redo in 65 of a 1080p drag
/// at proxy scale take 21 ms against 1.2 ms for the others.
const MAX_SWAPS: u32 = 64;
/// How many redos the blocks' renewals are spread over.
const STAGGER: usize = 16;

/// A field warp's map over a window with what it takes to redo it cheaply
/// after a few lines move ([`FieldWarp::field_map_after`]).
#[derive(Debug)]
pub struct FieldMap {
    map: Arc<WarpMap>,
    /// `Σ w` per pixel (empty for an identity map).
    weights: Vec<f32>,
    /// Per block of the evaluation, what redos have not written yet.
    lags: Vec<Tracked>,
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

    /// Per block, how many redos wrote its pixels since it was made.
    #[cfg(test)]
    pub(super) fn swaps(&self) -> Vec<u32> {
        self.lags.iter().map(|t| t.swaps).collect()
    }

    /// Whether what every block's pixels have not taken moves none of its
    /// check points by more than its allowance: what a redo holds, as
    /// `warp` (this map's) would check it.
    #[cfg(test)]
    pub(super) fn owes_within_allowance(&self, warp: &FieldWarp) -> bool {
        let setup = warp.setup(self.map.window, self.map.scale);
        self.lags.iter().all(|t| {
            let owes = |a| t.lag.owes_within(&t.samples, a);
            allowed(&setup, t).is_none_or(owes)
        })
    }

    /// Heap bytes held (for cache budgets).
    pub fn memory_bytes(&self) -> usize {
        self.map.memory_bytes()
            + self.weights.len() * std::mem::size_of::<f32>()
            + self.lags.len() * std::mem::size_of::<Tracked>()
    }

    /// How many redos this map is from a full evaluation (0: it is one).
    /// No block has been written by more than 64 redos since it was made
    /// afresh.
    pub fn redos(&self) -> u32 {
        self.redos
    }
}

/// A map's buffers, to be redone in place.
struct Buffers {
    pos: Vec<[f32; 2]>,
    weights: Vec<f32>,
    lags: Vec<Tracked>,
    redos: u32,
}

impl FieldWarp {
    /// The map over `window` (pixels at `scale`) as [`crate::warp::Warp::map_window`]
    /// makes it, with the sums kept for [`FieldWarp::field_map_after`].
    pub fn field_map(&self, window: RectI, scale: PixelScale) -> FieldMap {
        self.field_map_after(window, scale, None)
    }

    /// The map over `window`, redone from a copy of `before` when that is
    /// this warp's map with a few lines moved ([`FieldWarp::redoes`]), else
    /// evaluated in full. Either way within the evaluation's tolerance of
    /// the exact map (exact: within float rounding of it).
    pub fn field_map_after(
        &self,
        window: RectI,
        scale: PixelScale,
        before: Option<&FieldMap>,
    ) -> FieldMap {
        let setup = self.setup(window, scale);
        match before.and_then(|b| Moved::between(b, &setup).map(|m| (b, m))) {
            Some((before, moved)) => {
                let buffers = Buffers {
                    pos: before.map.positions().to_vec(),
                    weights: before.weights.clone(),
                    lags: before.lags.clone(),
                    redos: before.redos,
                };
                self.redone(&setup, &moved, buffers)
            }
            None => self.made(&setup),
        }
    }

    /// [`FieldWarp::field_map_after`] taking `before` over: a redo edits
    /// its buffers in place (when nothing else holds its map) instead of
    /// copying them, so it touches only the pixels the moved lines change.
    pub fn field_map_from(&self, window: RectI, scale: PixelScale, before: FieldMap) -> FieldMap {
        let setup = self.setup(window, scale);
        let Some(moved) = Moved::between(&before, &setup) else {
            return self.made(&setup);
        };
        let pos = match Arc::try_unwrap(before.map) {
            Ok(map) => map.into_positions(),
            Err(shared) => shared.positions().to_vec(),
        };
        let buffers = Buffers {
            pos,
            weights: before.weights,
            lags: before.lags,
            redos: before.redos,
        };
        self.redone(&setup, &moved, buffers)
    }

    /// Whether [`FieldWarp::field_map_after`] would redo `before` over
    /// `window` rather than evaluate afresh: it is this warp's map over the
    /// same window, scale and settings, and at most a quarter of the lines
    /// moved. However long a drag, it is never made in full again: a
    /// block that redos wrote 64 times is made afresh in its turn.
    pub fn redoes(&self, window: RectI, scale: PixelScale, before: &FieldMap) -> bool {
        Moved::between(before, &self.setup(window, scale)).is_some()
    }

    fn setup(&self, window: RectI, scale: PixelScale) -> Setup<'_> {
        let tolerance = match self.evaluation {
            Evaluation::Exact => None,
            Evaluation::Adaptive { tolerance } => Some(tolerance),
        };
        Setup::new(self, window, scale, tolerance)
    }

    fn kept(
        &self,
        setup: &Setup,
        pos: Vec<[f32; 2]>,
        b: (Vec<f32>, Vec<Tracked>, u32),
    ) -> FieldMap {
        let map = match self.identity {
            true => WarpMap::identity(setup.window, setup.scale),
            false => WarpMap::new(setup.window, setup.scale, pos),
        };
        FieldMap {
            map: Arc::new(map),
            weights: b.0,
            lags: b.1,
            pairs: self.pairs.clone(),
            weight: self.weight,
            evaluation: self.evaluation,
            redos: b.2,
        }
    }

    /// The map evaluated in full.
    fn made(&self, setup: &Setup) -> FieldMap {
        if self.identity {
            return self.kept(setup, Vec::new(), (Vec::new(), Vec::new(), 0));
        }
        let area = setup.window.area();
        let mut pos = vec![[0f32; 2]; area];
        let mut weights = vec![0f32; area];
        let mut lags = vec![Tracked::default(); setup.block_count()];
        setup.each_band(&mut pos, Some(&mut weights), &mut lags, |band, lags| {
            for (k, tracked) in lags.iter_mut().enumerate() {
                tracked.made = band.block(k).fill();
                tracked.samples = Samples::of(band.rect(k), band.setup.scale);
                tracked.lag.look(band, &tracked.samples);
            }
        });
        self.kept(setup, pos, (weights, lags, 0))
    }

    /// `buffers` redone in place for `moved`.
    fn redone(&self, setup: &Setup, moved: &Moved, buffers: Buffers) -> FieldMap {
        let Buffers {
            mut pos,
            mut weights,
            mut lags,
            redos,
        } = buffers;
        setup.each_band(&mut pos, Some(&mut weights), &mut lags, |band, lags| {
            moved.redo(band, lags)
        });
        self.kept(setup, pos, (weights, lags, redos.saturating_add(1)))
    }
}

/// The lines that moved since a map was made: their terms before and after.
struct Moved {
    old: Lines,
    new: Lines,
    /// Their destination segments before and after, in pixel space.
    segments: Vec<(Vec2, Vec2)>,
}

/// How a block takes the moved lines' change in this redo.
enum Plan {
    /// Its pixels take nothing now (the change waits in its lag).
    Skip,
    /// Exactly at every pixel, with what was pending, interpolated.
    Exact(Option<Grid<3>>),
    /// Interpolated from the grid, far from the moved lines.
    Interpolated(Grid<3>),
}

impl Moved {
    /// What moved between `before` and `setup`'s warp, when a redo applies.
    fn between(before: &FieldMap, setup: &Setup) -> Option<Self> {
        let warp = setup.warp;
        let same = before.map.window == setup.window
            && before.map.scale == setup.scale
            && before.weight == warp.weight
            && before.evaluation == warp.evaluation
            && before.pairs.len() == warp.pairs.len()
            && !before.weights.is_empty()
            && !warp.identity;
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
        let (old, new) = (pick(&before.pairs), pick(&warp.pairs));
        let to_pixel =
            |l: &LinePair| (setup.scale.to_pixel(l.dst.0), setup.scale.to_pixel(l.dst.1));
        Some(Moved {
            old: Lines::new(&old, &warp.weight),
            new: Lines::new(&new, &warp.weight),
            segments: old.iter().chain(&new).map(to_pixel).collect(),
        })
    }

    /// A band of the new map, holding the map before: the moved lines'
    /// terms swapped in each block as [`Self::plan`] says, the pixels whose
    /// sums cannot take the swap evaluated exactly, and a block with many
    /// of them evaluated afresh.
    fn redo(&self, band: &mut Band, lags: &mut [Tracked]) {
        let steps = lags.iter_mut().enumerate().map(|(k, t)| {
            let step = Step::of(self.plan(band, k, t), band.rect(k).width());
            let worn = MAX_SWAPS - (band.index(k) % STAGGER) as u32;
            match step {
                Step::Swap { .. } if t.swaps >= worn => Step::Fresh,
                step => step,
            }
        });
        let steps = self.shift(band, steps.collect());
        for (k, (tracked, step)) in lags.iter_mut().zip(steps).enumerate() {
            match step {
                Step::Untouched => continue,
                Step::Fresh => renew(band, k, tracked),
                Step::Swap { .. } => {
                    tracked.swaps += 1;
                    tracked.lag.look(band, &tracked.samples);
                    // What the check points owe was checked in sums
                    // against the pixels' weights before this write. The
                    // write changed them (a line passing close changes
                    // them most), and where `Σ w` fell the same sums now
                    // move the positions by more.
                    let owes = |a| tracked.lag.owes_within(&tracked.samples, a);
                    if !allowed(band.setup, tracked).is_none_or(owes) {
                        renew(band, k, tracked);
                    }
                }
            }
        }
    }

    /// How block `k` takes the change (`None`: it is to be made afresh).
    ///
    /// Near the moved lines, before or after, their terms are swapped
    /// exactly: whether a fresh block would have put them among its near
    /// lines or its far grid changes nothing but how exactly they are
    /// counted (see [`Self::shift`]), and there the swap's weight check
    /// picks the pixels to evaluate exactly. Far from them, as far as an adaptive
    /// evaluation's far lines, the change is known from the block's grid
    /// and waits in its [`Lag`] until it matters.
    fn plan(&self, band: &Band, k: usize, tracked: &mut Tracked) -> Option<Plan> {
        let Some(allowed) = allowed(band.setup, tracked) else {
            return Some(Plan::Exact(None));
        };
        let (lag, samples) = (&mut tracked.lag, &tracked.samples);
        let (lo, hi) = corners(band.rect(k));
        let close = |&(p, q): &(Vec2, Vec2)| is_within(p, q, lo, hi, CLOSE);
        if !self.segments.iter().any(close) {
            match lag.add(samples, &self.changes_at(samples), allowed, false) {
                Some(Take::Nothing) => return Some(Plan::Skip),
                Some(Take::Pending(grid)) => return Some(Plan::Interpolated(grid)),
                // The change bends too much between the nodes here.
                None => {}
            }
        }
        match lag.flush(samples, allowed)? {
            Take::Nothing => Some(Plan::Exact(None)),
            Take::Pending(grid) => Some(Plan::Exact(Some(grid))),
        }
    }

    /// The moved lines' change `[Δ Σ w·Δx, Δ Σ w·Δy, Δ Σ w]` at each
    /// sample.
    fn changes_at(&self, samples: &Samples) -> lag::Change {
        let mut change = [[0f32; lag::PADDED]; 3];
        let (xs, ys) = samples.positions();
        let (xs, ys) = (&xs[..samples.len], &ys[..samples.len]);
        (self.old).change_to(&self.new, xs, ys, change.each_mut().map(|v| &mut v[..]));
        change
    }

    /// Swaps the moved lines' old terms for their new ones in every pixel
    /// of the band's blocks as `steps` say, row by row across the band (the
    /// map is read and written in the order it lies in memory). A row's
    /// blocks are runs of 48 pixels with gaps where blocks are left alone,
    /// which the hardware's stream prefetchers do not follow, so each
    /// block asks for its next row's pixels a row of work ahead (without
    /// that, a 1080p redo after the draw had evicted the map took about
    /// 1.5 times as long). The pixels whose sums could not take it are
    /// evaluated exactly afterwards ([`Self::repair`]); a block
    /// where they reach a quarter of its pixels becomes [`Step::Fresh`],
    /// and from that row on is skipped.
    ///
    /// Exact terms leave each pixel's error what it was: the far field's
    /// interpolation error in the sums (checked when the block was made) is
    /// untouched, and it moves the position by about as much while the
    /// total weight changes by a tenth or less, which [`swap_terms`] holds.
    /// That holds as well where a moved line was one of a block's far lines:
    /// its old term's share of that error stays, as it was, and its new term
    /// is exact. What interpolated terms leave out is the blocks' lag.
    fn shift(&self, band: &mut Band, mut steps: Vec<Step>) -> Vec<Step> {
        let setup = band.setup;
        let (window, scale) = (setup.window, setup.scale);
        let xs: Vec<f32> = (window.x1..window.x2)
            .map(|i| scale.pixel_centre(i, band.y1).x as f32)
            .collect();
        let lanes = setup.block_columns(0).len().div_ceil(8) * 8;
        let mut ys = vec![0f32; lanes];
        let mut change: [Vec<f32>; 3] = std::array::from_fn(|_| vec![0f32; lanes]);
        let mut refused = vec![false; lanes];
        for j in band.y1..band.y2 {
            let y = scale.pixel_centre(window.x1, j).y as f32;
            ys.fill(y);
            let dy = (j - band.y1) as usize;
            for (k, step) in steps.iter_mut().enumerate() {
                let Step::Swap {
                    exact,
                    pending,
                    repair,
                } = step
                else {
                    continue;
                };
                let cols = setup.block_columns(k);
                band.prefetch_row(j + 1, cols.clone());
                let (xs, n) = (&xs[cols.clone()], cols.len());
                let pending = pending.as_ref().map(|rows| rows.between(dy));
                let by = match (*exact, pending) {
                    (false, Some(pending)) => pending,
                    (_, pending) => {
                        let out = change.each_mut().map(|v| &mut v[..]);
                        (self.old).change_to(&self.new, xs, &ys[..n], out);
                        if let Some(p) = pending {
                            for (m, c) in change.iter_mut().enumerate() {
                                c[..n]
                                    .iter_mut()
                                    .enumerate()
                                    .for_each(|(i, c)| *c += p.at(m, i));
                            }
                        }
                        RowChange::exact(change.each_ref().map(|v| &v[..]))
                    }
                };
                let (out, weights) = band.row_mut(j);
                let weights = weights.expect("a redo keeps weights");
                let (pos, ws) = (&mut out[cols.clone()], &mut weights[cols.clone()]);
                if swap_terms(xs, y, &by, pos, ws, &mut refused) {
                    continue;
                }
                let at = refused[..n].iter().enumerate().filter(|(_, r)| **r);
                repair.extend(at.map(|(i, _)| (cols.start + i, j)));
                if repair.len() > n * n / 4 {
                    *step = Step::Fresh;
                }
            }
        }
        for step in &mut steps {
            if let Step::Swap { repair, .. } = step {
                self.repair(band, repair);
            }
        }
        steps
    }

    /// Evaluates the pixels at `repair` (column in the window, row) with
    /// every line, exactly: where the moved lines dominate, a few pixels
    /// cost less than making their block afresh.
    fn repair(&self, band: &mut Band, repair: &[(usize, i32)]) {
        if repair.is_empty() {
            return;
        }
        let setup = band.setup;
        let x1 = setup.window.x1;
        let centre = |&(i, j): &(usize, i32)| setup.scale.pixel_centre(x1 + i as i32, j);
        let xs: Vec<f32> = repair.iter().map(|p| centre(p).x as f32).collect();
        let ys: Vec<f32> = repair.iter().map(|p| centre(p).y as f32).collect();
        let (mut ox, mut oy, mut ow) = (
            vec![0f32; xs.len()],
            vec![0f32; xs.len()],
            vec![0f32; xs.len()],
        );
        let zero = |_| Default::default();
        let out = (&mut ox[..], &mut oy[..]);
        (setup.warp.kernel).map_points_plus(&xs, &ys, zero, out, Some(&mut ow));
        for (k, &(i, j)) in repair.iter().enumerate() {
            let (pos, weights) = band.row_mut(j);
            pos[i] = [ox[k], oy[k]];
            weights.expect("a redo keeps weights")[i] = ow[k];
        }
    }
}

/// Block `k` of `band` evaluated afresh, its lag empty.
fn renew(band: &mut Band, k: usize, tracked: &mut Tracked) {
    tracked.made = band.block(k).fill();
    tracked.lag = Lag::default();
    tracked.swaps = 0;
    tracked.lag.look(band, &tracked.samples);
}

/// How far, per axis, what a block's pixels have not taken may move their
/// positions: the share of what its own error left of the tolerance
/// (`None` for an exact evaluation).
fn allowed(setup: &Setup, tracked: &Tracked) -> Option<[f32; 2]> {
    let tol = setup.tolerance()?;
    Some(std::array::from_fn(|a| {
        (tol[a] - tracked.made[a]).max(0.0) * lag::SHARE
    }))
}

/// What becomes of a block in a redo.
enum Step {
    /// Its pixels take nothing.
    Untouched,
    /// The moved lines' terms are swapped in its pixels: exactly, or (not
    /// `exact`) only what is pending; what is `pending` is interpolated.
    Swap {
        exact: bool,
        pending: Option<Box<Rows<3>>>,
        /// Pixels the swap refused, to be evaluated exactly (column in
        /// the window, row).
        repair: Vec<(usize, i32)>,
    },
    /// It is evaluated afresh.
    Fresh,
}

impl Step {
    /// The step for a block `width` pixels wide.
    fn of(plan: Option<Plan>, width: usize) -> Step {
        let rows = |grid: Grid<3>| {
            let mut rows = Box::<Rows<3>>::default();
            rows.across(&grid, width);
            rows
        };
        match plan {
            None => Step::Fresh,
            Some(Plan::Skip) => Step::Untouched,
            Some(Plan::Exact(pending)) => Step::Swap {
                exact: true,
                pending: pending.map(rows),
                repair: Vec::new(),
            },
            Some(Plan::Interpolated(grid)) => Step::Swap {
                exact: false,
                pending: Some(rows(grid)),
                repair: Vec::new(),
            },
        }
    }
}
