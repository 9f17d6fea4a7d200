//! Per-instance state: the warp cache, the parsed scene, messages said once.

use std::collections::HashSet;
use std::sync::{Arc, Mutex, Weak};

use morphfx::features::Side;
use morphfx::image::Plane;
use morphfx::scene::Scene;
use morphfx::transition::Weights;
use morphfx::warp::auto::{Correspondence, Grid};
use morphfx::warp::field::FieldMap;
use morphfx::warp::thin_plate::ThinPlate;

use super::kind::NodeKind;
use super::overlay::State as OverlayState;
use crate::cache::{Cache, Key, WarpCache};
use ofx_layer::params::Params;
use ofx_layer::plugin::Context;
use ofx_layer::sync::Locked;

/// A side's last field map, by its cache key.
type LastField = (Key, Weak<FieldMap>);

pub struct NodeState {
    pub kind: &'static NodeKind,
    /// The context the host made the instance in.
    pub context: Context,
    /// The instance's params, their handles fetched once at creation.
    params: Params,
    pub warps: WarpCache,
    /// Viewer renders' `field` maps with the sums that redo them after a
    /// line moves, keyed like the warps.
    pub field_maps: Cache<FieldMap>,
    /// Each side's last field map and its key, while the cache holds it:
    /// what the next viewer render redoes.
    last_field: Mutex<[Option<LastField>; 2]>,
    /// The last scene parsed, keyed by where it came from (text, or path + mtime + size).
    pub scene: Mutex<Option<(String, Arc<Scene>)>>,
    /// Warnings already posted (minimal hosts: report each fallback once).
    pub said: Mutex<HashSet<String>>,
    /// Two-pass output planes kept between renders (at most [`PLANES_KEPT`]):
    /// fresh frame-sized memory costs more than a tenth of a two-pass warp.
    pub planes: Mutex<Vec<Plane>>,
    /// `auto` correspondences, keyed by the images' content and the settings.
    pub correspondences: Cache<Correspondence>,
    /// The last solved `auto` grids by frame, for warm starts: `(time,
    /// settings key, grid)`, at most [`GRIDS_KEPT`].
    pub grids: Mutex<Vec<(f64, Key, Grid)>>,
    /// The last solved thin plates, for warm starts: `(time, settings and
    /// side key, plates)`, at most [`PLATES_KEPT`].
    pub plates: Mutex<Vec<(f64, Key, Arc<ThinPlate>)>>,
    /// Per-pixel dissolve weights of non-uniform colour transitions, keyed
    /// like the warps they come from.
    pub weights: Cache<Weights>,
    /// The viewer overlay's hover, drag and held keys.
    pub overlay: Mutex<OverlayState>,
}

/// Solved grids kept for warm starts.
pub const GRIDS_KEPT: usize = 8;

/// Solved plates kept for warm starts (a morph solves two per frame).
pub const PLATES_KEPT: usize = 4;

/// A morph needs two planes.
pub const PLANES_KEPT: usize = 2;

impl NodeState {
    /// A new instance's state over its params.
    pub fn create(kind: &'static NodeKind, context: Context, params: Params) -> NodeState {
        NodeState {
            kind,
            context,
            params,
            warps: Default::default(),
            field_maps: Default::default(),
            last_field: Default::default(),
            scene: Default::default(),
            said: Default::default(),
            planes: Default::default(),
            correspondences: Default::default(),
            grids: Default::default(),
            plates: Default::default(),
            weights: Default::default(),
            overlay: Default::default(),
        }
    }

    /// The instance's params.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Frees what the instance caches: warps, weights, correspondences,
    /// planes and the parsed scene. The warm starts of `thin-plate` and
    /// `auto` stay: a few small grids (at most [`GRIDS_KEPT`] and
    /// [`PLATES_KEPT`]), and what makes the next frame's solve fast when a
    /// host purges between the frames of a sequence (our harness does, to
    /// keep memory flat).
    pub fn purge(&self) {
        self.warps.clear();
        self.field_maps.clear();
        *self.scene.locked() = None;
        self.planes.locked().clear();
        self.correspondences.clear();
        self.weights.clear();
    }

    /// `side`'s last field map and its key, if the cache still holds it.
    pub fn last_field(&self, side: Side) -> Option<(Key, Arc<FieldMap>)> {
        let last = self.last_field.locked();
        let (key, map) = last[side_index(side)].as_ref()?;
        Some((key.clone(), map.upgrade()?))
    }

    /// Makes `map`, cached under `key`, the one the next viewer render of
    /// `side` redoes.
    pub fn set_last_field(&self, side: Side, key: Key, map: &Arc<FieldMap>) {
        let mut last = self.last_field.locked();
        last[side_index(side)] = Some((key, Arc::downgrade(map)));
    }

    /// True the first time `what` is asked about.
    pub fn first_time(&self, what: &str) -> bool {
        self.said.locked().insert(what.to_owned())
    }
}

fn side_index(side: Side) -> usize {
    match side {
        Side::A => 0,
        Side::B => 1,
    }
}
