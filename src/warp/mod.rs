//! One warp abstraction for every method: a reverse map from output positions
//! to source positions (canonical coordinates), plus dense evaluation over a
//! window of pixels (DESIGN rule 2).

pub mod auto;
pub mod field;
mod map;
pub mod mesh;
pub mod triangles;

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
use crate::features::{Feature, Side, DEFAULT_SAMPLES_PER_SEGMENT};
use crate::geom::RectD;
use crate::scene::{Method, Scene};
use auto::{AutoSettings, Correspondence};
use field::{FieldSettings, FieldWarp};
use mesh::{MeshPair, MeshSettings, MeshWarp};
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
/// (`t = 0`: A's positions, `t = 1`: B's), as a reverse map. For `mesh` this
/// is the one-pass map; the two-pass warp makes pixels ([`mesh::two_pass`]).
pub fn toward(
    features: &[Feature],
    side: Side,
    t: f64,
    settings: &WarpSettings,
) -> Result<Arc<dyn Warp>> {
    match settings.method {
        Method::Field => Ok(Arc::new(FieldWarp::toward(
            features,
            side,
            t,
            &settings.field,
        ))),
        Method::Mesh => Ok(Arc::new(MeshWarp::toward(settings.mesh_pair()?, side, t))),
        Method::Triangles => {
            let frame = match settings.frame {
                Some(f) => f,
                None => feature_bounds(features).ok_or_else(|| {
                    Error::Invalid("method \"triangles\" needs at least one feature point".into())
                })?,
            };
            Ok(Arc::new(TriangleWarp::toward(
                features,
                side,
                t,
                settings.samples_per_segment,
                frame,
            )?))
        }
        Method::Auto => {
            let c = settings.correspondence.as_ref().ok_or_else(|| {
                Error::Invalid(
                    "method \"auto\" needs both images: its correspondence is solved from A and B (the Morph node, morphfx morph)".into(),
                )
            })?;
            Ok(Arc::new(c.toward(side, t)))
        }
        m => Err(Error::Unsupported(format!(
            "method \"{}\" is not available in this build yet (available: {})",
            m.name(),
            Method::available_names()
        ))),
    }
}

/// The bounds of every feature point on both sides, grown by half their size
/// on each side (at least 16 px).
fn feature_bounds(features: &[Feature]) -> Option<RectD> {
    let pts = features.iter().flat_map(|f| f.a.iter().chain(&f.b));
    let mut r: Option<RectD> = None;
    for p in pts {
        let b = r.get_or_insert(RectD::new(p.x, p.y, p.x, p.y));
        *b = RectD::new(b.x1.min(p.x), b.y1.min(p.y), b.x2.max(p.x), b.y2.max(p.y));
    }
    r.map(|b| {
        let (mx, my) = ((b.width() * 0.5).max(16.0), (b.height() * 0.5).max(16.0));
        RectD::new(b.x1 - mx, b.y1 - my, b.x2 + mx, b.y2 + my)
    })
}
