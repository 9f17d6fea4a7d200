//! `auto`: automatic morphing by work minimisation (Gao & Sederberg 1998,
//! Gao-Sederberg). The correspondence is a hierarchical bilinear B-spline warp
//! `F` from A's unit square onto B's, found by greedy search of the work
//! (re-colouring + stretching + angle change + anchor penalties); the morph
//! then blends A's lattice with `F`'s control points ([`QuadWarp`]).
//!
//! Flow: plates → [`WorkImage`]s → [`solve`] (level by level, `optimise`)
//! → [`Correspondence`] (the grid placed on the two frames) → per-side
//! reverse maps toward `t` like every other method.

pub mod grid;
mod optimise;
mod quad_warp;
#[cfg(test)]
mod tests;
mod work;

use std::hash::{Hash, Hasher};

pub use grid::Grid;
pub use quad_warp::QuadWarp;
pub use work::{Anchor, Coefficients, Pricer, Work, WorkImage, ANCHOR_FLOOR_PX};

use crate::error::{Error, Result};
use crate::features::{Feature, Side, Tween};
use crate::geom::{RectD, Vec2};

/// Scene key `auto`.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoSettings {
    /// Deepest level `i_max` (`2^i` patches per side); `None`: quads of
    /// about 4 pixels on the plate's longer side (6 at 256², 8 at 1080p).
    pub levels: Option<u32>,
    /// The work's weights.
    pub coefficients: Coefficients,
    /// Start each frame of a sequence from the previous frame's warp:
    /// faster, but a frame then depends on where its sequence started (a
    /// farm's chunks differ from one run at their first frames), so off by
    /// default.
    pub warm_start: bool,
    /// Refinements per point at the finest level when warm-starting.
    pub warm_iterations: usize,
    /// The user's initial warp (§6.2): where A's lattice points lie on B,
    /// canonical pixels of B, `(2^i + 1)^2` points, bottom row first.
    pub initial: Option<Vec<Vec2>>,
}

impl Default for AutoSettings {
    fn default() -> Self {
        AutoSettings {
            levels: None,
            coefficients: Coefficients::default(),
            warm_start: false,
            warm_iterations: 3,
            initial: None,
        }
    }
}

/// The default deepest level for a plate: quads about 4 pixels wide.
pub fn default_levels(width: usize, height: usize) -> u32 {
    let r = width.max(height).max(8) as f64;
    ((r / 4.0).log2().floor() as u32).clamp(1, grid::MAX_LEVEL)
}

/// Pixels a quad spans, at least, in the plate its work is priced on.
const QUAD_SAMPLES: f64 = 32.0;

/// The plate level `level`'s search prices on: the full plate, or the
/// halving at which a quad still spans `QUAD_SAMPLES` pixels.
fn pick<'i>(full: &'i WorkImage, halvings: &'i [WorkImage], level: u32) -> &'i WorkImage {
    let quad = full.width.min(full.height) as f64 / (1u64 << level) as f64;
    let k = (quad / QUAD_SAMPLES).log2().floor().max(0.0) as usize;
    match k.min(halvings.len()) {
        0 => full,
        k => &halvings[k - 1],
    }
}

/// Where the search starts.
#[derive(Debug, Clone)]
pub enum Start<'a> {
    /// `F̂_1` the identity, as the paper.
    Identity,
    /// A user's initial warp at its own level (§6.2).
    Initial(Grid),
    /// The previous frame's final warp: only the finest level is refined.
    Warm(&'a Grid),
}

/// The work at the end of one level (level 0: the start), as the paper's table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelWork {
    /// The level (quads per side `2^level`).
    pub level: u32,
    /// The work there.
    pub work: Work,
}

/// A solved warp grid and the work at each level.
#[derive(Debug, Clone)]
pub struct Solution {
    /// The finest grid: A's lattice points on B (unit square).
    pub grid: Grid,
    /// The work at the end of each level.
    pub table: Vec<LevelWork>,
}

/// Seed 004's search from `start`, with `anchors` (unit squares of A and B).
pub fn solve(
    a: &WorkImage,
    b: &WorkImage,
    anchors: &[Anchor],
    settings: &AutoSettings,
    start: Start<'_>,
) -> Result<Solution> {
    for (name, im) in [("A", a), ("B", b)] {
        if im.width < 2 || im.height < 2 {
            return Err(Error::Invalid(format!(
                "auto: image {name} is {}x{}; it needs at least 2x2 pixels",
                im.width, im.height
            )));
        }
    }
    if let Some(i) = anchors
        .iter()
        .position(|an| !an.a.is_finite() || !an.b.is_finite())
    {
        return Err(Error::Invalid(format!("auto: anchor {i} is not finite")));
    }
    let top = settings
        .levels
        .unwrap_or_else(|| default_levels(a.width, a.height))
        .clamp(1, grid::MAX_LEVEL);
    let (mut grid, warm) = match start {
        Start::Identity => (Grid::identity(1), false),
        Start::Initial(g) => (g, false),
        Start::Warm(g) => (g.clone(), g.level() == top),
    };
    let top = top.max(grid.level());
    let c = &settings.coefficients;
    let first = grid.level().max(1);
    // The search at coarse levels prices quads on halved plates, so that a
    // quad spans about `QUAD_SAMPLES` pixels or more (a coarse-to-fine
    // pyramid: big quads need no per-pixel detail, and blur smooths the
    // work's landscape). The table reports full-resolution work.
    let (ha, hb) = (a.halvings(8), b.halvings(8));
    let mut table = vec![LevelWork {
        level: 0,
        work: Pricer::new(a, b, first, anchors, c)
            .all(&grid)
            .into_iter()
            .sum(),
    }];
    // Onto from level 3 on (§6.2), or at the last level of a shallower search.
    let onto_from = 3.min(top);
    for level in first..=top {
        while grid.level() < level {
            grid = grid.refined();
        }
        if level >= onto_from && !grid.is_onto() && !grid.make_onto() {
            return Err(Error::Invalid(
                "auto: the initial warp cannot be pulled onto the frame without folding".into(),
            ));
        }
        let search = Pricer::new(pick(a, &ha, level), pick(b, &hb, level), level, anchors, c);
        let mut works = search.all(&grid);
        let iterations = if warm {
            settings.warm_iterations
        } else if level == top {
            // The paper's single pass at the finest level steps 0.4 of a
            // quad; two more halvings reach a tenth of one (sub-pixel).
            optimise::iterations(level).max(3)
        } else {
            optimise::iterations(level)
        };
        optimise::refine_level(&mut grid, &search, &mut works, iterations);
        table.push(LevelWork {
            level,
            work: Pricer::new(a, b, level, anchors, c)
                .all(&grid)
                .into_iter()
                .sum(),
        });
    }
    Ok(Solution { grid, table })
}

/// The paper's table: work by kind at the end of each level.
pub fn table_text(table: &[LevelWork]) -> String {
    let mut s = format!(
        "{:>5} {:>12} {:>12} {:>12} {:>12} {:>12}\n",
        "level", "stretch", "angle", "colour", "anchors", "total"
    );
    for row in table {
        let w = row.work;
        s += &format!(
            "{:>5} {:>12.1} {:>12.1} {:>12.1} {:>12.1} {:>12.1}\n",
            row.level,
            w.stretch,
            w.angle,
            w.colour,
            w.anchor,
            w.total()
        );
    }
    s
}

/// A solved grid placed on the two frames (canonical coordinates): A's
/// lattice corresponds to the grid's points on B.
#[derive(Clone)]
pub struct Correspondence {
    /// A's lattice points' places on B (unit square).
    pub grid: Grid,
    /// A's frame (canonical).
    pub a_frame: RectD,
    /// B's frame (canonical).
    pub b_frame: RectD,
    /// A digest of all of the above, so caches can key on it cheaply.
    id: u64,
}

impl Correspondence {
    /// A solved grid placed on the two frames.
    pub fn new(grid: Grid, a_frame: RectD, b_frame: RectD) -> Self {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for p in grid.points() {
            p.x.to_bits().hash(&mut h);
            p.y.to_bits().hash(&mut h);
        }
        for f in [a_frame, b_frame] {
            for v in [f.x1, f.y1, f.x2, f.y2] {
                v.to_bits().hash(&mut h);
            }
        }
        Correspondence {
            grid,
            a_frame,
            b_frame,
            id: h.finish(),
        }
    }

    /// The warp of `side` toward the in-between at `t`.
    pub fn toward<'a>(&self, side: Side, t: impl Into<Tween<'a>>) -> QuadWarp {
        QuadWarp::toward(&self.grid, self.a_frame, self.b_frame, side, t.into())
    }

    /// `F` on canonical points of A.
    pub fn map_a_to_b(&self, p: Vec2) -> Vec2 {
        let (fa, fb) = (self.a_frame, self.b_frame);
        let u = Vec2::new((p.x - fa.x1) / fa.width(), (p.y - fa.y1) / fa.height());
        let q = self.grid.eval(u);
        Vec2::new(fb.x1 + q.x * fb.width(), fb.y1 + q.y * fb.height())
    }
}

impl std::fmt::Debug for Correspondence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Correspondence#{:016x}", self.id)
    }
}

impl PartialEq for Correspondence {
    fn eq(&self, o: &Self) -> bool {
        self.id == o.id && self.grid == o.grid
    }
}

/// Canonical position `p` of `frame` in the unit square.
pub fn to_unit(frame: RectD, p: Vec2) -> Vec2 {
    Vec2::new(
        (p.x - frame.x1) / frame.width(),
        (p.y - frame.y1) / frame.height(),
    )
}

/// The features as anchors (every point, polylines and curves sampled).
pub fn anchors(
    features: &[Feature],
    per_segment: usize,
    a_frame: RectD,
    b_frame: RectD,
) -> Vec<Anchor> {
    features
        .iter()
        .flat_map(|f| f.point_pairs(per_segment))
        .map(|pp| Anchor {
            a: to_unit(a_frame, pp.a),
            b: to_unit(b_frame, pp.b),
        })
        .collect()
}

/// One frame's correspondence: the features as anchors, started from the
/// previous frame's grid (`warm`, when the settings allow), else the user's
/// initial warp, else the identity.
#[allow(clippy::too_many_arguments)]
pub fn correspond(
    a: &WorkImage,
    a_frame: RectD,
    b: &WorkImage,
    b_frame: RectD,
    features: &[Feature],
    per_segment: usize,
    settings: &AutoSettings,
    warm: Option<&Grid>,
) -> Result<(Correspondence, Vec<LevelWork>)> {
    if !a_frame.is_valid() || !b_frame.is_valid() {
        return Err(Error::Invalid(
            "auto: the frames of A and B must not be empty".into(),
        ));
    }
    let anchors = anchors(features, per_segment, a_frame, b_frame);
    let start = match (warm.filter(|_| settings.warm_start), &settings.initial) {
        (Some(g), _) => Start::Warm(g),
        (None, Some(pts)) => Start::Initial(
            Grid::from_points(pts.iter().map(|&p| to_unit(b_frame, p)).collect())
                .map_err(|e| Error::Invalid(format!("auto.initial: {e}")))?,
        ),
        (None, None) => Start::Identity,
    };
    let solution = solve(a, b, &anchors, settings, start)?;
    Ok((
        Correspondence::new(solution.grid, a_frame, b_frame),
        solution.table,
    ))
}
