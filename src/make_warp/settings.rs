//! What a warp is made from besides the features.

use std::sync::Arc;

use super::Method;
use crate::error::{Error, Result};
use crate::features::DEFAULT_SAMPLES_PER_SEGMENT;
use crate::geom::RectD;
use crate::transition::TransitionSettings;
use crate::warp::auto::{AutoSettings, Correspondence};
use crate::warp::field::FieldSettings;
use crate::warp::hybrid::HybridSettings;
use crate::warp::mesh::{MeshPair, MeshSettings};
use crate::warp::mffd::MffdSettings;
use crate::warp::thin_plate::ThinPlateSettings;

/// The method a morph warps with and every method's settings: what a scene
/// says and what a node's params set, one struct for both.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodSettings {
    /// Which warp generator.
    pub method: Method,
    /// Field-warp settings (scene key `field`).
    pub field: FieldSettings,
    /// Mesh method settings (scene key `mesh`).
    pub mesh: MeshSettings,
    /// Settings of `auto` (scene key `auto`).
    pub auto: AutoSettings,
    /// Settings of `thin-plate` (and of the hybrid's plate).
    pub thin_plate: ThinPlateSettings,
    /// Settings of `mffd` (and of the hybrid's MFFD steps).
    pub mffd: MffdSettings,
    /// Settings of `hybrid` (scene key `hybrid`).
    pub hybrid: HybridSettings,
    /// Transition control: the geometry rates move each feature point at its
    /// own pace; the colour rates are the dissolve's (see [`crate::transition`]).
    pub transition: TransitionSettings,
    /// Samples per polyline/curve span for point-based methods (Lee,
    /// Wolberg et al. §4.2).
    pub samples_per_segment: usize,
}

impl Default for MethodSettings {
    fn default() -> Self {
        MethodSettings {
            method: Method::Field,
            field: FieldSettings::default(),
            mesh: MeshSettings::default(),
            auto: AutoSettings::default(),
            thin_plate: ThinPlateSettings::default(),
            mffd: MffdSettings::default(),
            hybrid: HybridSettings::default(),
            transition: TransitionSettings::default(),
            samples_per_segment: DEFAULT_SAMPLES_PER_SEGMENT,
        }
    }
}

/// Everything a warp generator depends on besides the features: the
/// method's settings and the inputs of one frame some methods need.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WarpSettings {
    /// The method and every method's settings.
    pub settings: MethodSettings,
    /// The mesh pair at this frame (method `mesh`).
    pub meshes: Option<MeshPair>,
    /// The canonical region the warp must cover (the frame), whose border
    /// `triangles` pins; without it, the features' bounds grown by half
    /// their size on each side.
    pub region: Option<RectD>,
    /// The correspondence `auto` solved for this frame from both images
    /// ([`crate::warp::auto::correspond`]); the warps only read it.
    pub correspondence: Option<Arc<Correspondence>>,
}

impl WarpSettings {
    /// `settings` with no per-frame inputs yet.
    pub fn new(settings: MethodSettings) -> Self {
        WarpSettings {
            settings,
            ..WarpSettings::default()
        }
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.settings.method
    }

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
