//! Drawing the output rows from the prepared job, per source and output depth.

use std::sync::{Arc, Mutex};

use morphfx::features::{Feature, Side};
use morphfx::geom::{PixelScale, Vec2};
use morphfx::image::{Image, Plane, RowsMut, Sample, Sampler, WarpMap};
use morphfx::morph::{dissolve, dissolve_weighted, show, Warped};
use morphfx::transition::{Rates, Weights};
use morphfx::views::{self, View};
use morphfx::warp::mesh::{self, MeshPair};

use crate::nodes::state::PLANES_KEPT;
use ofx_layer::sync::Locked;

pub(super) struct Job<'a> {
    pub(super) view: View,
    /// Per-pixel dissolve weights (non-uniform colour transition).
    pub(super) weights: Option<Arc<Weights>>,
    /// Geometry rates (the transition view).
    pub(super) rates: Option<Rates>,
    pub(super) t: f64,
    pub(super) features: &'a [Feature],
    pub(super) map_a: Option<Arc<WarpMap>>,
    pub(super) map_b: Option<Arc<WarpMap>>,
    /// The mesh pair when pictures come from the two-pass mesh warp.
    pub(super) meshes: Option<&'a MeshPair>,
    /// Output planes reused between two-pass renders.
    pub(super) planes: &'a Mutex<Vec<Plane>>,
    /// Straight sources (A, B) to bring to premultiplied colour.
    pub(super) premultiply: [bool; 2],
    pub(super) scale: PixelScale,
    pub(super) origin: Vec2,
    pub(super) size: Vec2,
}

impl Job<'_> {
    pub(super) fn draw<S: Sample, D: Sample>(
        &self,
        a: &Sampler<'_, S>,
        b: Option<&Sampler<'_, S>>,
        rows: RowsMut<'_, D>,
    ) {
        // The folds view draws its picture below, over the maps' measure.
        if let Some(pair) = self.meshes.filter(|_| self.view != View::Folds) {
            return self.draw_two_pass(self.view, pair, a, b, rows);
        }
        let (ma, mb) = (self.map_a.as_deref(), self.map_b.as_deref());
        match (self.view, b) {
            (View::StmapA, _) => views::stmap(ma.expect("map A"), self.origin, self.size, rows),
            (View::StmapB, _) => {
                views::stmap(mb.or(ma).expect("map"), self.origin, self.size, rows)
            }
            (View::Transition, _) => match &self.rates {
                Some(r) => views::transition_grey(r, ma.expect("map A"), rows),
                None => views::transition_grey(&Rates::Uniform(self.t), ma.expect("map A"), rows),
            },
            (View::Grid, _) => views::grid(ma.expect("map A"), self.features, self.t, rows),
            (View::Ghost, Some(b)) => {
                let wa = Warped::Map(a, ma.expect("map A"));
                let wb = Warped::Map(b, mb.expect("map B"));
                views::ghost(
                    self.in_output_state(&wa, Side::A),
                    self.in_output_state(&wb, Side::B),
                    rows,
                )
            }
            (View::Folds, _) => {
                let mut morph = Image::new(rows.bounds, 4);
                match self.meshes {
                    Some(pair) => {
                        self.draw_two_pass(View::Morph, pair, a, b, morph.view_mut().rows())
                    }
                    None => self.picture(View::Morph, a, b, morph.view_mut().rows()),
                }
                let maps: Vec<&WarpMap> = [ma, mb].into_iter().flatten().collect();
                views::folds(&morph, &maps, rows)
            }
            (view, _) => self.picture(view, a, b, rows),
        }
    }

    /// A picture view: the morph, or one warped source (A where there is
    /// no B).
    fn picture<S: Sample, D: Sample>(
        &self,
        view: View,
        a: &Sampler<'_, S>,
        b: Option<&Sampler<'_, S>>,
        rows: RowsMut<'_, D>,
    ) {
        let (ma, mb) = (self.map_a.as_deref(), self.map_b.as_deref());
        let wa = ma.map(|m| Warped::Map(a, m));
        let wb = b.zip(mb).map(|(b, m)| Warped::Map(b, m));
        macro_rules! picture {
            ($w:expr, $side:expr) => {
                self.in_output_state($w.as_ref().expect("a map for the side drawn"), $side)
            };
        }
        match (view, b) {
            (View::Morph, Some(_)) => match &self.weights {
                Some(w) => dissolve_weighted(
                    picture!(wa, Side::A),
                    picture!(wb, Side::B),
                    self.t,
                    w,
                    rows,
                ),
                None => dissolve(picture!(wa, Side::A), picture!(wb, Side::B), self.t, rows),
            },
            (View::WarpedB, Some(_)) => show(picture!(wb, Side::B), rows),
            _ => show(picture!(wa, Side::A), rows),
        }
    }

    /// `w` as the output holds colour: premultiplied when `side` is straight
    /// and the output is not.
    fn in_output_state<'w, S: Sample>(&self, w: &'w Warped<'w, S>, side: Side) -> Warped<'w, S> {
        let k = if side == Side::A { 0 } else { 1 };
        if self.premultiply[k] {
            Warped::Premultiplied(w)
        } else {
            *w
        }
    }

    /// Pictures through the two-pass mesh warp, made for this render window
    /// only (its cost follows the window, so tiles stay cheap; nothing that
    /// depends on the host's pixels is cached). A side whose mesh does not
    /// move is copied, not filtered.
    fn draw_two_pass<S: Sample, D: Sample>(
        &self,
        view: View,
        pair: &MeshPair,
        a: &Sampler<'_, S>,
        b: Option<&Sampler<'_, S>>,
        rows: RowsMut<'_, D>,
    ) {
        let window = rows.bounds;
        let to = pair.at(self.t);
        let identity = WarpMap::identity(window, self.scale);
        let pool = || self.planes.locked();
        let plane = |side: Side, s: &Sampler<'_, S>| {
            let from = pair.side(side);
            (*from != to).then(|| {
                let mut p = pool().pop().unwrap_or(Plane {
                    window,
                    channels: 0,
                    pixels: Vec::new(),
                });
                p.window = window;
                mesh::two_pass_into(s, from, &to, self.scale, &mut p);
                p
            })
        };
        let used = match (view, b) {
            (View::Morph, Some(b)) => {
                let (pa, pb) = (
                    (self.t < 1.0).then(|| plane(Side::A, a)).flatten(),
                    (self.t > 0.0).then(|| plane(Side::B, b)).flatten(),
                );
                let (wa, wb) = (warped(a, &pa, &identity), warped(b, &pb, &identity));
                dissolve(
                    self.in_output_state(&wa, Side::A),
                    self.in_output_state(&wb, Side::B),
                    self.t,
                    rows,
                );
                [pa, pb]
            }
            (View::WarpedB, Some(b)) => {
                let p = plane(Side::B, b);
                show(
                    self.in_output_state(&warped(b, &p, &identity), Side::B),
                    rows,
                );
                [p, None]
            }
            _ => {
                let p = plane(Side::A, a);
                show(
                    self.in_output_state(&warped(a, &p, &identity), Side::A),
                    rows,
                );
                [p, None]
            }
        };
        let mut kept = pool();
        for p in used.into_iter().flatten() {
            if kept.len() < PLANES_KEPT {
                kept.push(p);
            }
        }
    }
}

/// A two-pass side: its pixels, or the source itself when its mesh stays put.
fn warped<'a, S: Sample>(
    source: &'a Sampler<'a, S>,
    plane: &'a Option<Plane>,
    identity: &'a WarpMap,
) -> Warped<'a, S> {
    match plane {
        Some(p) => Warped::Pixels(p),
        None => Warped::Map(source, identity),
    }
}
