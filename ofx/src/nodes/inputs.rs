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

/// The scene named by the params, parsed once per content.
pub(in crate::nodes) fn load_scene(
    instance: &NodeState,
    settings: &Settings,
) -> Outcome<Option<Arc<Scene>>> {
    let path = settings.scene_file.trim();
    let (key, source) = if !path.is_empty() {
        let meta = std::fs::metadata(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?;
        (
            format!("file:{path}:{:?}:{}", meta.modified().ok(), meta.len()),
            Some(path),
        )
    } else if !settings.scene_text.trim().is_empty() {
        (format!("text:{}", settings.scene_text), None)
    } else {
        return Ok(None);
    };
    let mut cached = instance.scene.locked();
    if let Some((k, scene)) = cached.as_ref() {
        if *k == key {
            return Ok(Some(scene.clone()));
        }
    }
    let text = match source {
        Some(path) => std::fs::read_to_string(path)
            .map_err(|e| Failure::BadInput(format!("scene file {path}: {e}")))?,
        None => settings.scene_text.clone(),
    };
    let scene = Scene::read(&text).map_err(|e| match source {
        Some(path) => Failure::BadInput(format!("scene file {path}: {e}")),
        None => Failure::BadInput(format!("scene text: {e}")),
    })?;
    let scene = Arc::new(scene);
    *cached = Some((key, scene.clone()));
    Ok(Some(scene))
}

/// Everything the warps at one time depend on.
#[derive(Debug)]
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
    let scene = load_scene(instance, settings)?;
    // The scene's features first, so transition curves attached by index
    // name the scene's own features.
    let mut features = Vec::new();
    let mut warp = WarpSettings::new(settings.warp.clone());
    let mut t = settings.progress;
    if let Some(scene) = &scene {
        features.extend(scene.features_at(time));
        if settings.settings_from_scene {
            let node_transition = warp.settings.transition.clone();
            warp = scene.warp_settings_at(time);
            // A scene without a transition leaves the node's in place.
            if warp.settings.transition == Default::default() {
                warp.settings.transition = node_transition;
            }
        } else {
            warp.meshes = scene.mesh_at(time);
        }
        if settings.use_scene_progress {
            t = scene.progress_at(time).unwrap_or(t);
        }
    }
    features.extend(settings.lines.iter().cloned());
    // Only nodes with two sources have the transition context, and its
    // mandated param drives them there.
    if instance.context == Context::Transition {
        t = instance
            .params()
            .double(&TRANSITION_PARAM, time)?
            .clamp(0.0, 1.0);
    }
    Ok(WarpInputs { features, warp, t })
}
