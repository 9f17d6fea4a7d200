//! The warp inputs at a time: the scene (parsed once per content), its
//! features and the line slots', the settings, and the progress.

use std::sync::Arc;

use morphfx::features::Feature;
use morphfx::make_warp::WarpSettings;
use morphfx::scene::Scene;

use crate::nodes::params::{Settings, TRANSITION_PARAM};
use crate::nodes::state::NodeState;
use ofx_layer::plugin::Context;
use ofx_layer::sync::Locked;
use ofx_layer::{Failure, Outcome};

/// The scene named by the params (Scene File, else Scene Text), parsed
/// once per content.
pub(in crate::nodes) fn load_scene(
    instance: &NodeState,
    file: &str,
    text: &str,
) -> Outcome<Option<Arc<Scene>>> {
    let path = file.trim();
    let (key, source) = if !path.is_empty() {
        let meta = std::fs::metadata(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?;
        (
            format!("file:{path}:{:?}:{}", meta.modified().ok(), meta.len()),
            Some(path),
        )
    } else if !text.trim().is_empty() {
        (text_key(text), None)
    } else {
        return Ok(None);
    };
    let mut cached = instance.scene.locked();
    if let Some((k, scene)) = cached.as_ref() {
        if *k == key {
            return Ok(Some(scene.clone()));
        }
    }
    let read = match source {
        Some(path) => std::fs::read_to_string(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?,
        None => text.to_owned(),
    };
    let scene = Scene::read(&read).map_err(|e| match source {
        Some(path) => Failure::BadInput(format!("scene file {path}: {e}")),
        None => Failure::BadInput(format!("scene text: {e}")),
    })?;
    let scene = Arc::new(scene);
    *cached = Some((key, scene.clone()));
    Ok(Some(scene))
}

/// Makes `scene` the parsed scene of Scene Text `text`: an edit that has
/// the scene already (the viewer's) spares the next render and draw a
/// parse of the text it wrote.
pub(in crate::nodes) fn remember_scene_text(instance: &NodeState, text: &str, scene: Scene) {
    *instance.scene.locked() = Some((text_key(text), Arc::new(scene)));
}

fn text_key(text: &str) -> String {
    format!("text:{text}")
}

/// The scene's warp settings at `time` where the node takes them from the
/// scene (Settings From Scene on, and a scene loaded).
pub(in crate::nodes) fn scene_settings(
    scene: Option<&Scene>,
    from_scene: bool,
    time: f64,
) -> Option<WarpSettings> {
    scene
        .filter(|_| from_scene)
        .map(|s| s.warp_settings_at(time))
}

/// The progress at `time`: the node's, or the scene's where it keys one
/// and the node follows it; in the transition context, the host's
/// Transition param (only nodes with two sources have that context).
pub(in crate::nodes) fn progress_at(
    instance: &NodeState,
    scene: Option<&Scene>,
    (node, follow_scene): (f64, bool),
    time: f64,
) -> Outcome<f64> {
    if instance.context == Context::Transition {
        let t = instance.params().double(&TRANSITION_PARAM, time)?;
        return Ok(t.clamp(0.0, 1.0));
    }
    Ok(match scene {
        Some(scene) if follow_scene => scene.progress_at(time).unwrap_or(node),
        _ => node,
    })
}

/// Everything the warps at one time depend on.
#[derive(Debug, Clone)]
pub struct WarpInputs {
    pub features: Vec<Feature>,
    pub warp: WarpSettings,
    pub t: f64,
}

pub(in crate::nodes) fn warp_inputs(
    instance: &NodeState,
    settings: &Settings,
    time: f64,
) -> Outcome<WarpInputs> {
    let scene = load_scene(instance, &settings.scene_file, &settings.scene_text)?;
    let scene = scene.as_deref();
    // The scene's features first, so transition curves attached by index
    // name the scene's own features.
    let mut features = scene.map_or_else(Vec::new, |s| s.features_at(time));
    let warp = match scene_settings(scene, settings.settings_from_scene, time) {
        Some(mut warp) => {
            // A scene without a transition leaves the node's in place.
            if warp.settings.transition == Default::default() {
                warp.settings.transition = settings.warp.transition.clone();
            }
            warp
        }
        None => {
            let mut warp = WarpSettings::new(settings.warp.clone());
            if let Some(scene) = scene {
                warp.meshes = scene.mesh_at(time);
            }
            warp
        }
    };
    let progress = (settings.progress, settings.use_scene_progress);
    let t = progress_at(instance, scene, progress, time)?;
    features.extend(settings.lines.iter().cloned());
    Ok(WarpInputs { features, warp, t })
}
