//! What a node can show besides the morph: ST maps, a warped grid with the
//! features drawn on it, and the transition rate as grey. All are consumers of
//! the same warp maps as the morph itself.

use crate::choice::Choice;
use crate::features::{sample_points, Feature, FeatureKind};
use crate::geom::Vec2;
use crate::image::WarpMap;
use crate::image::{resample::fill, RowsMut, Sample};
use crate::transition::Rates;

/// The output view a node renders (the command line's `--view`, docs/command-line.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum View {
    /// The morph: warped A and B dissolved.
    #[default]
    Morph,
    /// A warped toward the in-between features.
    WarpedA,
    /// B warped toward the in-between features.
    WarpedB,
    /// A's reverse map as an ST map (normalised source positions in red and green).
    StmapA,
    /// B's reverse map as an ST map.
    StmapB,
    /// The colour transition rates, grey.
    Transition,
    /// A grid warped like A, to show the warp's shape.
    Grid,
}

impl Choice for View {
    const ALL: &'static [View] = &[
        View::Morph,
        View::WarpedA,
        View::WarpedB,
        View::StmapA,
        View::StmapB,
        View::Transition,
        View::Grid,
    ];
    fn name(self) -> &'static str {
        match self {
            View::Morph => "morph",
            View::WarpedA => "warped-a",
            View::WarpedB => "warped-b",
            View::StmapA => "stmap-a",
            View::StmapB => "stmap-b",
            View::Transition => "transition",
            View::Grid => "grid",
        }
    }
}

/// ST map (Nuke STMap convention, docs/coordinates.md): red and green hold the source
/// position normalised by the source image's extent (`origin`, `size`:
/// canonical, full resolution), blue 0, alpha 1. Not clamped.
pub fn stmap<D: Sample>(map: &WarpMap, origin: Vec2, size: Vec2, dst: RowsMut<'_, D>) {
    let (w, h) = (size.x, size.y);
    let (ox, oy) = (origin.x, origin.y);
    fill(dst, 4, |i, j, px| {
        let win = map.window;
        if i < win.x1 || i >= win.x2 || j < win.y1 || j >= win.y2 {
            *px = [0.0; 4];
            return;
        }
        let p = map.get(i, j);
        *px = [((p.x - ox) / w) as f32, ((p.y - oy) / h) as f32, 0.0, 1.0];
    });
}

/// The geometry transition rate as grey: at each output pixel, the rate of
/// the point of A it shows (`map_a`); pixels outside the map take `t`.
pub fn transition_grey<D: Sample>(rates: &Rates, map_a: &WarpMap, dst: RowsMut<'_, D>) {
    let win = map_a.window;
    let uniform = rates.uniform();
    let t = rates.t() as f32;
    fill(dst, 4, |i, j, px| {
        let r = match uniform {
            Some(u) => u as f32,
            None if i >= win.x1 && i < win.x2 && j >= win.y1 && j < win.y2 => {
                rates.at(map_a.get(i, j)) as f32
            }
            None => t,
        };
        *px = [r, r, r, 1.0];
    });
}

/// Grid spacing of the grid view, canonical pixels.
pub const GRID_SPACING: f64 = 32.0;

/// A grid drawn in source space, seen through `map`, with `features` (at the
/// output's positions) drawn on top in orange: shows where each region of the
/// source lands and why (Beier-Neely §4's "ghostbusting" aid).
pub fn grid<D: Sample>(map: &WarpMap, features: &[Feature], t: f64, dst: RowsMut<'_, D>) {
    let segments: Vec<(Vec2, Vec2)> = features
        .iter()
        .flat_map(|f| {
            let pts = f.points_at(t);
            let pts = match f.kind {
                FeatureKind::Curve => sample_points(FeatureKind::Curve, &pts, 8),
                _ => pts,
            };
            if pts.len() == 1 {
                let p = pts[0];
                vec![
                    (p - Vec2::new(3.0, 0.0), p + Vec2::new(3.0, 0.0)),
                    (p - Vec2::new(0.0, 3.0), p + Vec2::new(0.0, 3.0)),
                ]
            } else {
                pts.windows(2).map(|w| (w[0], w[1])).collect()
            }
        })
        .collect();
    let scale = map.scale;
    fill(dst, 4, |i, j, px| {
        let win = map.window;
        if i < win.x1 || i >= win.x2 || j < win.y1 || j >= win.y2 {
            *px = [0.0; 4];
            return;
        }
        let s = map.get(i, j);
        let near = |v: f64| {
            let d = (v / GRID_SPACING - (v / GRID_SPACING).round()).abs() * GRID_SPACING;
            (1.0 - d).max(0.0)
        };
        let g = near(s.x).max(near(s.y)) as f32;
        let base = 0.12 + 0.88 * g;
        *px = [base, base, base, 1.0];
        let c = scale.pixel_centre(i, j);
        let on_feature = segments
            .iter()
            .any(|&(p, q)| c.distance_to_segment(p, q) <= 1.0 / scale.y.min(scale.x));
        if on_feature {
            *px = [1.0, 0.55, 0.1, 1.0];
        }
    });
}
