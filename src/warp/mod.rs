//! One warp abstraction for every method: a reverse map from output positions
//! to source positions (canonical coordinates), plus dense evaluation over a
//! window of pixels (DESIGN rule 2).

pub mod auto;
pub mod field;
pub mod hybrid;
mod map;
pub mod mesh;
pub mod mffd;
pub mod node_grid;
pub mod thin_plate;
pub mod triangles;

#[cfg(test)]
mod scattered_tests;

pub use map::WarpMap;

use rayon::prelude::*;

use crate::geom::{PixelScale, RectI, Vec2};

pub trait Warp: Send + Sync {
    /// Where output position `p` samples the source (canonical coordinates).
    fn map(&self, p: Vec2) -> Vec2;

    /// Map many points at once. The default calls [`Warp::map`]; generators
    /// with a vector kernel override it.
    fn map_points(&self, xs: &[f32], ys: &[f32], out_x: &mut [f32], out_y: &mut [f32]) {
        for i in 0..xs.len() {
            let q = self.map(Vec2::new(xs[i] as f64, ys[i] as f64));
            out_x[i] = q.x as f32;
            out_y[i] = q.y as f32;
        }
    }

    /// True when the warp maps every point to itself, so resampling can be
    /// skipped and the source copied bit for bit.
    fn is_identity(&self) -> bool {
        false
    }

    /// The map at the centres of the pixels of `window` (pixels at `scale`),
    /// evaluated exactly, in parallel over rows.
    fn map_window(&self, window: RectI, scale: PixelScale) -> WarpMap {
        if self.is_identity() {
            return WarpMap::identity(window, scale);
        }
        let w = window.width();
        let mut pos = vec![[0f32; 2]; window.area()];
        if w > 0 {
            pos.par_chunks_mut(w).enumerate().for_each_init(
                || (vec![0f32; w], vec![0f32; w], vec![0f32; w], vec![0f32; w]),
                |(xs, ys, ox, oy), (row, out)| {
                    let j = window.y1 + row as i32;
                    for (k, (x, y)) in xs.iter_mut().zip(ys.iter_mut()).enumerate() {
                        let c = scale.pixel_centre(window.x1 + k as i32, j);
                        *x = c.x as f32;
                        *y = c.y as f32;
                    }
                    self.map_points(xs, ys, ox, oy);
                    for (o, (x, y)) in out.iter_mut().zip(ox.iter().zip(oy.iter())) {
                        *o = [*x, *y];
                    }
                },
            );
        }
        WarpMap::new(window, scale, pos)
    }
}

/// The warp that maps every point to itself.
#[derive(Debug, Clone, Copy, Default)]
pub struct Identity;

impl Warp for Identity {
    fn map(&self, p: Vec2) -> Vec2 {
        p
    }
    fn is_identity(&self) -> bool {
        true
    }
}

use std::sync::Arc;

use crate::error::{Error, Result};
use crate::features::{Feature, Side, Tween, DEFAULT_SAMPLES_PER_SEGMENT};
use crate::geom::RectD;
use crate::scene::{Method, Scene};
use crate::transition::{Rates, TransitionSettings};
use auto::{AutoSettings, Correspondence};
use field::{FieldSettings, FieldWarp};
use hybrid::HybridSettings;
use mesh::{MeshPair, MeshSettings, MeshWarp};
use mffd::{Mffd, MffdSettings, MffdWarp};
use thin_plate::{ThinPlate, ThinPlateSettings, ThinPlateWarp};
use triangles::TriangleWarp;

/// Everything a warp generator depends on besides the features: the method,
/// its settings, and the per-frame inputs some methods need (the mesh pair at
/// this frame, the frame the warp must cover).
#[derive(Debug, Clone, PartialEq)]
pub struct WarpSettings {
    pub method: Method,
    pub field: FieldSettings,
    pub mesh: MeshSettings,
    pub samples_per_segment: usize,
    /// The mesh pair at this frame (method `mesh`).
    pub meshes: Option<MeshPair>,
    /// The frame (canonical) whose border `triangles` pins; without it, the
    /// features' bounds grown by half their size on each side.
    pub frame: Option<RectD>,
    pub auto: AutoSettings,
    pub thin_plate: ThinPlateSettings,
    pub mffd: MffdSettings,
    pub hybrid: HybridSettings,
    /// Transition control: the geometry rates move each feature point at its
    /// own pace; the colour rates are the dissolve's (see [`crate::transition`]).
    pub transition: TransitionSettings,
    /// The correspondence `auto` solved for this frame from both images
    /// ([`auto::correspond`]); the warps only read it.
    pub correspondence: Option<Arc<Correspondence>>,
}

impl Default for WarpSettings {
    fn default() -> Self {
        WarpSettings {
            method: Method::Field,
            field: FieldSettings::default(),
            mesh: MeshSettings::default(),
            samples_per_segment: DEFAULT_SAMPLES_PER_SEGMENT,
            meshes: None,
            frame: None,
            auto: AutoSettings::default(),
            thin_plate: ThinPlateSettings::default(),
            mffd: MffdSettings::default(),
            hybrid: HybridSettings::default(),
            transition: TransitionSettings::default(),
            correspondence: None,
        }
    }
}

impl WarpSettings {
    /// The scene's settings and its mesh pair at `frame`.
    pub fn from_scene(s: &Scene, frame: f64) -> Self {
        WarpSettings {
            method: s.method,
            field: s.field,
            mesh: s.mesh,
            samples_per_segment: s.samples_per_segment,
            meshes: s.mesh_at(frame),
            frame: None,
            auto: s.auto.clone(),
            thin_plate: s.thin_plate,
            mffd: s.mffd,
            hybrid: s.hybrid,
            transition: s.transition.clone(),
            correspondence: None,
        }
    }
}

impl WarpSettings {
    /// The mesh pair method `mesh` warps with, or the error that says it is missing.
    pub fn mesh_pair(&self) -> Result<&MeshPair> {
        self.meshes.as_ref().ok_or_else(|| {
            Error::Invalid(
                "method \"mesh\" needs a mesh: put a \"mesh\" key (rows, cols, a, b) in the scene"
                    .into(),
            )
        })
    }
}

/// The warp of the image on `side` toward the features' positions at `t`
/// (`t = 0`: A's positions, `t = 1`: B's), as a reverse map. With a geometry
/// transition each feature point travels at its own rate. For `mesh` this is
/// the one-pass map; the two-pass warp makes pixels ([`mesh::two_pass`]).
pub fn toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
) -> Result<Arc<dyn Warp>> {
    with_tween(features, t, settings, |tween| {
        let pairs = || point_pairs_toward(features, side, tween, settings.samples_per_segment);
        match settings.method {
            Method::Field => Ok(
                Arc::new(FieldWarp::toward(features, side, tween, &settings.field))
                    as Arc<dyn Warp>,
            ),
            Method::Mesh => Ok(Arc::new(MeshWarp::toward(
                settings.mesh_pair()?,
                side,
                tween,
            ))),
            Method::Triangles => Ok(Arc::new(TriangleWarp::toward(
                features,
                side,
                tween,
                settings.samples_per_segment,
                settings.scattered_frame(features)?,
            )?)),
            Method::ThinPlate => Ok(Arc::new(thin_plate_with(
                features, side, tween, settings, None,
            )?)),
            Method::Mffd => Ok(Arc::new(MffdWarp {
                mffd: Mffd::solve(
                    &pairs(),
                    settings.scattered_frame(features)?,
                    &settings.mffd,
                ),
            })),
            Method::Hybrid => Ok(Arc::new(MffdWarp {
                mffd: hybrid::solve(
                    &pairs(),
                    settings.scattered_frame(features)?,
                    &settings.hybrid,
                ),
            })),
            Method::Auto => {
                let c = settings.correspondence.as_ref().ok_or_else(|| {
                    Error::Invalid(
                        "method \"auto\" needs both images: its correspondence is solved from A and B (the Morph node, morphfx morph)".into(),
                    )
                })?;
                Ok(Arc::new(c.toward(side, tween)))
            }
        }
    })
}

/// The `thin-plate` warp as [`toward`] makes it, its plates solved from
/// `warm` (the same side's plates at a sequence's previous frame; a plate on
/// another grid is ignored): a host rendering frame after frame keeps each
/// frame's plates to start the next from.
pub fn thin_plate_toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
    warm: Option<&ThinPlate>,
) -> Result<ThinPlateWarp> {
    with_tween(features, t, settings, |tween| {
        thin_plate_with(features, side, tween, settings, warm)
    })
}

fn thin_plate_with(
    features: &[Feature],
    side: Side,
    tween: Tween<'_>,
    settings: &WarpSettings,
    warm: Option<&ThinPlate>,
) -> Result<ThinPlateWarp> {
    let pairs = point_pairs_toward(features, side, tween, settings.samples_per_segment);
    let frame = settings.scattered_frame(features)?;
    Ok(ThinPlateWarp::new(ThinPlate::solve(
        &pairs,
        frame,
        &settings.thin_plate,
        warm,
    )))
}

/// `f` with the in-between positions at `t`: one `t` for every point, or
/// each point's own rate under a geometry transition.
fn with_tween<R>(
    features: &[Feature],
    t: f64,
    settings: &WarpSettings,
    f: impl FnOnce(Tween<'_>) -> Result<R>,
) -> Result<R> {
    let rates = settings.geometry_rates(features, t)?;
    let rate = |p: Vec2| rates.at(p);
    match rates.uniform() {
        Some(t) => f(Tween::uniform(t)),
        None => f(Tween::with_rates(t, &rate)),
    }
}

/// How far outside the frame a feature point may lie, in frame extents, for
/// the methods that solve on a grid or triangulation covering every point
/// (thin-plate, mffd, hybrid, triangles): their work and memory grow with the
/// area the points span, so a point beyond this is refused rather than
/// allowed to ask for a grid of any size.
pub const REACH: f64 = 1.0;

/// The largest area (canonical px along either side) the features may span
/// when no frame is given.
pub const MAX_FEATURE_SPAN: f64 = 65536.0;

impl WarpSettings {
    /// The frame a scattered-data or triangulated warp covers: the host's
    /// frame, else the features' bounds. Every feature point must lie within
    /// [`REACH`] frame extents of it, so the work stays bounded by the frame.
    fn scattered_frame(&self, features: &[Feature]) -> Result<RectD> {
        let frame = match self.frame {
            Some(f) => f,
            None => {
                let f = feature_bounds(features).ok_or_else(|| {
                    Error::Invalid(format!(
                        "method \"{}\" needs at least one feature point",
                        self.method.name()
                    ))
                })?;
                if !(f.width() <= MAX_FEATURE_SPAN && f.height() <= MAX_FEATURE_SPAN) {
                    return Err(Error::Invalid(format!(
                        "method \"{}\": the features span {:.3e} x {:.3e} px, more than {MAX_FEATURE_SPAN} px",
                        self.method.name(),
                        f.width(),
                        f.height()
                    )));
                }
                return Ok(f);
            }
        };
        let extent = frame.width().max(frame.height()).max(1.0);
        let reach = RectD::new(
            frame.x1 - REACH * extent,
            frame.y1 - REACH * extent,
            frame.x2 + REACH * extent,
            frame.y2 + REACH * extent,
        );
        for (i, f) in features.iter().enumerate() {
            for (side, points) in [("A", &f.a), ("B", &f.b)] {
                if let Some(p) = points.iter().find(|p| !reach.contains_point(**p)) {
                    let name = f
                        .name
                        .as_deref()
                        .map(|n| format!(" \"{n}\""))
                        .unwrap_or_default();
                    return Err(Error::Invalid(format!(
                        "feature {}{name}: its {side} point ({}, {}) lies more than {REACH} frame width{} outside the frame ({}, {}) - ({}, {}); method \"{}\" cannot reach it",
                        i + 1,
                        p.x,
                        p.y,
                        if REACH == 1.0 { "" } else { "s" },
                        frame.x1,
                        frame.y1,
                        frame.x2,
                        frame.y2,
                        self.method.name()
                    )));
                }
            }
        }
        Ok(frame)
    }
}

impl WarpSettings {
    /// The geometry transition's rates at `t` (uniform unless the scene
    /// asks otherwise), over the frame or the features' bounds.
    pub fn geometry_rates(&self, features: &[Feature], t: f64) -> Result<Rates> {
        self.rates(&self.transition.geometry, features, t)
    }

    /// The colour transition's rates at `t`.
    pub fn colour_rates(&self, features: &[Feature], t: f64) -> Result<Rates> {
        self.rates(self.transition.colour(), features, t)
    }

    fn rates(
        &self,
        transition: &crate::transition::Transition,
        features: &[Feature],
        t: f64,
    ) -> Result<Rates> {
        if transition.is_uniform_at(t) {
            return Ok(Rates::Uniform(t.clamp(0.0, 1.0)));
        }
        let frame = self
            .frame
            .or_else(|| feature_bounds(features))
            .unwrap_or(RectD::new(0.0, 0.0, 1.0, 1.0));
        transition.rates(features, self.samples_per_segment, frame, t)
    }
}

/// Every feature's corresponding points (polylines and curves sampled
/// `per_segment` times per span, Lee, Wolberg et al. §4.2) as `(in-between, source)`
/// pairs for the scattered-data methods: the reverse map carries each
/// in-between position to its place on `side`.
pub fn point_pairs_toward(
    features: &[Feature],
    side: Side,
    t: Tween<'_>,
    per_segment: usize,
) -> Vec<(Vec2, Vec2)> {
    features
        .iter()
        .flat_map(|f| f.point_pairs(per_segment))
        .map(|pair| {
            let source = match side {
                Side::A => pair.a,
                Side::B => pair.b,
            };
            (t.between(pair.a, pair.b), source)
        })
        .collect()
}

/// The bounds of every feature point on both sides, grown by half their size
/// on each side (at least 16 px).
fn feature_bounds(features: &[Feature]) -> Option<RectD> {
    let mut pts = features
        .iter()
        .flat_map(|f| f.a.iter().chain(&f.b))
        .copied();
    let first = pts.next()?;
    let b = RectD::new(first.x, first.y, first.x, first.y).including(pts);
    let (mx, my) = ((b.width() * 0.5).max(16.0), (b.height() * 0.5).max(16.0));
    Some(RectD::new(b.x1 - mx, b.y1 - my, b.x2 + mx, b.y2 + my))
}
