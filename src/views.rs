//! What a node can show besides the morph: ST maps, a warped grid with the
//! features drawn on it, and the transition rate as grey. All are consumers of
//! the same warp maps as the morph itself.

use crate::choice::Choice;
use crate::features::{outline, Feature, FeatureKind};
use crate::geom::{PixelScale, Vec2};
use crate::image::resample::fill_rows;
use crate::image::WarpMap;
use crate::image::{resample::fill, Image, RowsMut, Sample};
use crate::morph::Warped;
use crate::transition::Rates;
use crate::warp::{invert, Warp};

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
    /// Where the warped sources disagree (double edges): alpha the mean
    /// over R, G, B of |warped A − warped B|, colour a heat ramp of it.
    Ghost,
    /// Where a reverse map folds the image over itself: alpha 1 there, the
    /// morph tinted beneath.
    Folds,
    /// The warp's motion vectors ([`vectors`]): forward in red and green,
    /// backward in blue and alpha.
    Vectors,
}

impl View {
    /// Whether the view is a picture (the morph or a warped source), which
    /// a mask and mix dial back; the others are maps and diagnostics.
    pub fn is_picture(self) -> bool {
        matches!(self, View::Morph | View::WarpedA | View::WarpedB)
    }
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
        View::Ghost,
        View::Folds,
        View::Vectors,
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
            View::Ghost => "ghost",
            View::Folds => "folds",
            View::Vectors => "vectors",
        }
    }
}

/// The vectors view, for Nuke's VectorBlur: red and green the forward
/// motion, in pixels at `scale` (x right, y up), of what each output pixel
/// shows, from this frame to the next: `v(p) = next⁻¹(now(p)) − p`, where
/// the next frame shows the source point `now` samples here (the source
/// held still: the warp's own motion); blue and alpha the backward motion,
/// to the previous frame (`prev`). Where the point is not found (it
/// leaves the warp's reach) the motion is 0.
pub fn vectors<D: Sample>(
    now: &dyn Warp,
    next: &dyn Warp,
    prev: &dyn Warp,
    scale: PixelScale,
    dst: RowsMut<'_, D>,
) {
    fill(dst, 4, |i, j, px| {
        let p = scale.pixel_centre(i, j);
        let source = now.map(p);
        let motion = |other: &dyn Warp| match invert(other, source, p) {
            Some(q) => scale.to_pixel(q - p),
            None => Vec2::ZERO,
        };
        let (f, b) = (motion(next), motion(prev));
        *px = [f.x as f32, f.y as f32, b.x as f32, b.y as f32];
    });
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
                FeatureKind::Curve => outline(FeatureKind::Curve, f.closed, &pts, 8),
                FeatureKind::Polyline => outline(FeatureKind::Polyline, f.closed, &pts, 1),
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

/// The ghost view's full scale: a mean difference of this much or more
/// shows white.
pub const GHOST_FULL_SCALE: f32 = 0.5;

/// A heat ramp for `v` in `[0, GHOST_FULL_SCALE]`: black, red, yellow,
/// white, so small residuals already read as dark red.
pub fn heat(v: f32) -> [f32; 3] {
    let x = 3.0 * (v / GHOST_FULL_SCALE).clamp(0.0, 1.0);
    [
        x.min(1.0),
        (x - 1.0).clamp(0.0, 1.0),
        (x - 2.0).clamp(0.0, 1.0),
    ]
}

/// The ghost view (Beier-Neely §4's ghosting made measurable): at each pixel
/// `g` = the mean over R, G, B of |A − B| of the two warped sources, as the
/// dissolve would add them (premultiplied); written as RGB = [`heat`] of
/// `g`, alpha = `g`.
pub fn ghost<S: Sample, D: Sample>(a: Warped<'_, S>, b: Warped<'_, S>, dst: RowsMut<'_, D>) {
    fill_rows(dst, 4, |j, x1, row, other| {
        other.resize(row.len(), [0.0; 4]);
        a.row_as(j, x1, 4, row);
        b.row_as(j, x1, 4, other);
        for (pa, pb) in row.iter_mut().zip(other.iter()) {
            let g = ((pa[0] - pb[0]).abs() + (pa[1] - pb[1]).abs() + (pa[2] - pb[2]).abs()) / 3.0;
            let [r, gr, bl] = heat(g);
            *pa = [r, gr, bl, g];
        }
    });
}

/// The Jacobian determinant of a reverse map at pixel `(i, j)`, by central
/// differences of its positions (one-sided where a neighbour lies outside
/// its window), in canonical units per pixel squared: ≤ 0 where the map
/// folds the image over itself or collapses it.
pub fn jacobian(map: &WarpMap, i: i32, j: i32) -> f64 {
    let w = map.window;
    let inside = |i: i32, j: i32| i >= w.x1 && i < w.x2 && j >= w.y1 && j < w.y2;
    let diff = |(i0, j0): (i32, i32), (i1, j1): (i32, i32)| {
        let (p0, p1) = match (inside(i0, j0), inside(i1, j1)) {
            (true, true) => ((i0, j0), (i1, j1)),
            (false, true) => ((i, j), (i1, j1)),
            (true, false) => ((i0, j0), (i, j)),
            (false, false) => return None,
        };
        let steps = ((p1.0 - p0.0) + (p1.1 - p0.1)) as f64;
        Some((map.get(p1.0, p1.1) - map.get(p0.0, p0.1)) * (1.0 / steps))
    };
    match (diff((i - 1, j), (i + 1, j)), diff((i, j - 1), (i, j + 1))) {
        (Some(dx), Some(dy)) => dx.x * dy.y - dx.y * dy.x,
        _ => 1.0, // a one-pixel map: nothing to measure, nothing folded
    }
}

/// Tint of folded pixels over the picture, and how much of it.
const FOLD_TINT: [f32; 3] = [1.0, 0.0, 1.0];
const FOLD_TINT_AMOUNT: f32 = 0.6;

/// The folds view: alpha 1 where any of `maps` folds (its Jacobian
/// determinant ≤ 0), else 0; colour the `picture` (4 channels, covering
/// `dst`), folded pixels tinted magenta.
pub fn folds<D: Sample>(picture: &Image, maps: &[&WarpMap], dst: RowsMut<'_, D>) {
    debug_assert_eq!(picture.channels, 4);
    fill(dst, 4, |i, j, px| {
        let p = picture.pixel(i, j);
        let folded = maps.iter().any(|m| jacobian(m, i, j) <= 0.0);
        *px = if folded {
            let k = FOLD_TINT_AMOUNT;
            [
                p[0] + (FOLD_TINT[0] - p[0]) * k,
                p[1] + (FOLD_TINT[1] - p[1]) * k,
                p[2] + (FOLD_TINT[2] - p[2]) * k,
                1.0,
            ]
        } else {
            [p[0], p[1], p[2], 0.0]
        };
    });
}

#[cfg(test)]
mod vector_tests {
    use super::*;
    use crate::geom::RectI;

    /// A reverse map that samples `shift` away: the picture moves by
    /// `-shift`.
    struct Shift(Vec2);
    impl Warp for Shift {
        fn map(&self, p: Vec2) -> Vec2 {
            p + self.0
        }
    }

    /// The warp's sampling shift grows by (2, 1) canonical px a frame, so
    /// the picture moves by (-2, -1) a frame: forward (-2, -1), backward
    /// (2, 1), in pixels at render scale 0.5 half that.
    #[test]
    fn vectors_are_the_pictures_motion_to_the_next_and_previous_frames() {
        let s = |f: f64| Shift(Vec2::new(2.0, 1.0) * f);
        let scale = PixelScale::new(0.5, 0.5, 1.0);
        let mut out = Image::new(RectI::new(0, 0, 6, 4), 4);
        vectors(&s(5.0), &s(6.0), &s(4.0), scale, out.view_mut().rows());
        for px in out.data.chunks(4) {
            let want = [-1.0, -0.5, 1.0, 0.5];
            for (v, w) in px.iter().zip(want) {
                assert!((v - w).abs() < 1e-5, "{px:?}");
            }
        }
    }
}
