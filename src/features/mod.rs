//! Feature primitives: points, directed lines, polylines and Catmull-Rom curves,
//! each with a position on image A and one on image B (Lee, Wolberg et al. §4.2).

mod catmull_rom;
mod sampling;

pub use catmull_rom::{catmull_rom, catmull_rom_closed};
pub use sampling::{outline, sample_points, PointPair, DEFAULT_SAMPLES_PER_SEGMENT};

use crate::geom::Vec2;

/// The shape of a feature: what its points mean.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FeatureKind {
    /// A single point.
    Point,
    /// A directed segment P → Q.
    Line,
    /// Straight segments through its points, in order.
    Polyline,
    /// Catmull-Rom spline through its control points.
    Curve,
}

impl FeatureKind {
    /// Every kind, in the order the scene format lists them.
    pub const ALL: [FeatureKind; 4] = [
        FeatureKind::Point,
        FeatureKind::Line,
        FeatureKind::Polyline,
        FeatureKind::Curve,
    ];

    /// The kind's name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            FeatureKind::Point => "point",
            FeatureKind::Line => "line",
            FeatureKind::Polyline => "polyline",
            FeatureKind::Curve => "curve",
        }
    }

    /// The kind named `s` in a scene file, if any.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }

    /// The point counts this kind accepts: `(min, max)`.
    pub fn point_count(self) -> (usize, usize) {
        match self {
            FeatureKind::Point => (1, 1),
            FeatureKind::Line => (2, 2),
            FeatureKind::Polyline | FeatureKind::Curve => (2, usize::MAX),
        }
    }
}

/// A feature with corresponding positions on image A and image B.
/// `a.len() == b.len()` is an invariant (the scene parser enforces it).
#[derive(Debug, Clone, PartialEq)]
pub struct Feature {
    /// The user's name for it, used in messages and transition attachments.
    pub name: Option<String>,
    /// What the points describe.
    pub kind: FeatureKind,
    /// Control points on image A (canonical).
    pub a: Vec<Vec2>,
    /// Control points on image B, one per point on A.
    pub b: Vec<Vec2>,
    /// A polyline or curve that runs on from its last point back to its
    /// first (scene key `closed`); always false for points and lines.
    pub closed: bool,
    /// How sure `morphfx suggest` was of the pair, `[0, 1]` (scene key
    /// `confidence`): shown to the artist, never used by a warp. `None`
    /// for features the artist placed or moved.
    pub confidence: Option<f64>,
}

/// Where a feature sits on one image, or in between.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Image A, the start of the morph.
    A,
    /// Image B, the end of the morph.
    B,
}

impl Feature {
    /// An unnamed feature of `kind` with points `a` on A and `b` on B.
    pub fn new(kind: FeatureKind, a: Vec<Vec2>, b: Vec<Vec2>) -> Self {
        Feature {
            name: None,
            kind,
            a,
            b,
            closed: false,
            confidence: None,
        }
    }

    /// The same feature closed (a loop) or open; points and lines stay open.
    pub fn closed(mut self, closed: bool) -> Self {
        self.closed = closed && matches!(self.kind, FeatureKind::Polyline | FeatureKind::Curve);
        self
    }

    /// A directed line: `a[0] → a[1]` on A, `b[0] → b[1]` on B.
    pub fn line(a: [Vec2; 2], b: [Vec2; 2]) -> Self {
        Feature::new(FeatureKind::Line, a.to_vec(), b.to_vec())
    }

    /// A point at `a` on A and `b` on B.
    pub fn point(a: Vec2, b: Vec2) -> Self {
        Feature::new(FeatureKind::Point, vec![a], vec![b])
    }

    /// The same feature with a name.
    pub fn named(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// The control points on `side`.
    pub fn points(&self, side: Side) -> &[Vec2] {
        match side {
            Side::A => &self.a,
            Side::B => &self.b,
        }
    }

    /// Control points interpolated linearly from A (t = 0) to B (t = 1).
    pub fn points_at(&self, t: f64) -> Vec<Vec2> {
        self.a
            .iter()
            .zip(&self.b)
            .map(|(a, b)| a.lerp(*b, t))
            .collect()
    }

    /// How the feature is called in messages: its name, or its index.
    pub fn label(&self, index: usize) -> String {
        match &self.name {
            Some(n) => format!("features[{index}] \"{n}\""),
            None => format!("features[{index}]"),
        }
    }
}

/// Where each feature point is along its way from A to B at one instant:
/// one progress `t` for every point, or a rate per point taken from its
/// position on A (transition control, Lee, Wolberg et al. §3: `T0(p; t)`).
#[derive(Clone, Copy)]
pub struct Tween<'a> {
    /// The progress, `0` (A) to `1` (B).
    pub t: f64,
    rate: Option<&'a (dyn Fn(Vec2) -> f64 + Sync)>,
}

impl<'a> Tween<'a> {
    /// Every point at progress `t`.
    pub fn uniform(t: f64) -> Self {
        Tween { t, rate: None }
    }

    /// Rates from `rate(p_A)`, each in `[0, 1]`.
    pub fn with_rates(t: f64, rate: &'a (dyn Fn(Vec2) -> f64 + Sync)) -> Self {
        Tween {
            t,
            rate: Some(rate),
        }
    }

    /// True when every point moves at the same rate `t`.
    pub fn is_uniform(&self) -> bool {
        self.rate.is_none()
    }

    /// The rate of the point at `a` on image A.
    #[inline]
    pub fn rate(&self, a: Vec2) -> f64 {
        self.rate.map_or(self.t, |f| f(a))
    }

    /// The in-between position of a point at `a` on A and `b` on B; the end
    /// rates return `a` and `b` bit for bit.
    #[inline]
    pub fn between(&self, a: Vec2, b: Vec2) -> Vec2 {
        let r = self.rate(a);
        if r == 0.0 {
            a
        } else if r == 1.0 {
            b
        } else {
            a.lerp(b, r)
        }
    }
}

impl From<f64> for Tween<'static> {
    fn from(t: f64) -> Self {
        Tween::uniform(t)
    }
}

impl std::fmt::Debug for Tween<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.rate {
            None => write!(f, "Tween({})", self.t),
            Some(_) => write!(f, "Tween({}, per point)", self.t),
        }
    }
}
