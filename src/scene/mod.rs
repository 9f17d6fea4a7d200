//! The scene: a `*.morph.json` document (docs/scene-format.md), parsed, validated and
//! queried for the features and the progress at any frame.

pub mod edit;
#[cfg(test)]
mod edit_tests;
#[cfg(test)]
mod mesh_edit_tests;
mod parse;
mod range;
mod scattered;
#[cfg(test)]
mod tests;

use crate::features::Feature;
use crate::make_warp::{MethodSettings, WarpSettings};
use crate::warp::mesh::MeshPair;

pub use parse::FORMAT;

/// A feature set at one frame of an image sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct Keyframe {
    /// The frame of the image sequence the features are keyed at.
    pub frame: f64,
    /// The features at that frame.
    pub features: Vec<Feature>,
}

/// A morph as a scene file describes it: the features, their keyframes, the meshes and
/// every setting.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The method and its settings (scene keys `method`, `field`, `mesh`,
    /// `auto`, `thin-plate`, `mffd`, `hybrid`, `transition`, `sampling`).
    pub settings: MethodSettings,
    /// The mesh pair: one static pair, or pairs keyed at frames (sorted,
    /// strictly increasing), interpolated like feature keyframes.
    pub meshes: Vec<(f64, MeshPair)>,
    /// The features when there are no keyframes.
    pub features: Vec<Feature>,
    /// Sorted by frame, strictly increasing; when non-empty it replaces `features`.
    pub keyframes: Vec<Keyframe>,
    /// `(frame, t)` keys sorted by frame.
    pub progress: Vec<(f64, f64)>,
    /// Settings of other methods (`mesh`, `thin-plate`, `transition`, ...) kept
    /// verbatim so a scene round-trips through tools that do not know them.
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            settings: MethodSettings::default(),
            meshes: Vec::new(),
            features: Vec::new(),
            keyframes: Vec::new(),
            progress: Vec::new(),
            extra: serde_json::Map::new(),
        }
    }
}

impl Scene {
    /// The features at `frame`: keyframes interpolated linearly in frame and
    /// held outside the keyed range; the static features without keyframes.
    pub fn features_at(&self, frame: f64) -> Vec<Feature> {
        let keys = &self.keyframes;
        if keys.is_empty() {
            return self.features.clone();
        }
        let (lo, hi, w) = bracket(keys.len(), |i| keys[i].frame, frame);
        if w == 0.0 {
            return keys[lo].features.clone();
        }
        keys[lo]
            .features
            .iter()
            .zip(&keys[hi].features)
            .map(|(f0, f1)| Feature {
                name: f0.name.clone(),
                kind: f0.kind,
                a: lerp_points(&f0.a, &f1.a, w),
                b: lerp_points(&f0.b, &f1.b, w),
                closed: f0.closed,
                // Between two keys the pair is as sure as the less sure
                // end; one the artist keyed is theirs.
                confidence: f0.confidence.zip(f1.confidence).map(|(c0, c1)| c0.min(c1)),
            })
            .collect()
    }

    /// The mesh pair at `frame`: keys interpolated linearly in frame and held
    /// outside the keyed range (a static mesh is one key).
    pub fn mesh_at(&self, frame: f64) -> Option<MeshPair> {
        let keys = &self.meshes;
        if keys.is_empty() {
            return None;
        }
        let (lo, hi, w) = bracket(keys.len(), |i| keys[i].0, frame);
        Some(if w == 0.0 {
            keys[lo].1.clone()
        } else {
            keys[lo].1.lerp(&keys[hi].1, w)
        })
    }

    /// The scene's settings with its mesh pair at `frame`.
    pub fn warp_settings_at(&self, frame: f64) -> WarpSettings {
        WarpSettings {
            meshes: self.mesh_at(frame),
            ..WarpSettings::new(self.settings.clone())
        }
    }

    /// Progress `t` at `frame`, if the scene keys it (linear between keys, held outside).
    pub fn progress_at(&self, frame: f64) -> Option<f64> {
        let keys = &self.progress;
        if keys.is_empty() {
            return None;
        }
        let (lo, hi, w) = bracket(keys.len(), |i| keys[i].0, frame);
        Some(keys[lo].1 + (keys[hi].1 - keys[lo].1) * w)
    }

    /// Whether the scene has any feature at all (static or keyed).
    pub fn has_features(&self) -> bool {
        self.keyframes
            .first()
            .map_or(!self.features.is_empty(), |k| !k.features.is_empty())
    }
}

/// For sorted keys, the pair of indices around `x` and the weight of the upper one.
fn bracket(n: usize, key: impl Fn(usize) -> f64, x: f64) -> (usize, usize, f64) {
    if x <= key(0) {
        return (0, 0, 0.0);
    }
    if x >= key(n - 1) {
        return (n - 1, n - 1, 0.0);
    }
    let hi = (1..n).find(|&i| key(i) > x).unwrap_or(n - 1);
    let lo = hi - 1;
    let w = (x - key(lo)) / (key(hi) - key(lo));
    (lo, hi, w)
}

fn lerp_points(p0: &[crate::Vec2], p1: &[crate::Vec2], w: f64) -> Vec<crate::Vec2> {
    p0.iter().zip(p1).map(|(a, b)| a.lerp(*b, w)).collect()
}
