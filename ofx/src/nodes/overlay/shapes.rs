//! The shapes of Scene Text as the viewer edits them: the text read as a
//! scene document, edited, and written back whole (one string param, one
//! write per pen event); and the buttons that act on it.

use morphfx::scene::edit::Document;

use crate::nodes::inputs::remember_scene_text;
use crate::nodes::params::{Reader, SCENE_FILE, SCENE_TEXT};
use crate::nodes::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::sync::Locked;
use ofx_layer::{Failure, Outcome};

/// The id of the message shown while the viewer refuses to edit.
const REFUSED: &std::ffi::CStr = c"net.morphfx.overlay.refused";

/// Scene Text as a document, when the viewer may edit it: refused while
/// Scene File is in use (its shapes are what renders) or while the text
/// is not a valid scene (it is never overwritten then).
pub fn document(instance: &NodeState, time: f64) -> Outcome<Document> {
    let r = Reader::new(instance.params(), instance.kind, time);
    if !r.text(&SCENE_FILE).trim().is_empty() {
        return Err(Failure::BadInput(
            "Scene File is in use, so its shapes are read-only: press \
                Copy Scene Into Node to edit them"
                .into(),
        ));
    }
    Document::parse(&r.text(&SCENE_TEXT)).map_err(|e| {
        Failure::BadInput(format!(
            "Scene Text is not a valid scene, so the viewer edits nothing until it is fixed: {e}"
        ))
    })
}

/// Writes `doc` into Scene Text.
pub fn write(instance: &NodeState, doc: &Document) -> Outcome {
    let text = doc.text();
    instance.params().set_string(&SCENE_TEXT, &text)?;
    remember_scene_text(instance, &text, doc.scene().clone());
    Ok(())
}

/// Shows why an edit was refused on the node until the next edit that
/// works (a transient warning where the host keeps no persistent message).
/// A warning, not an error: the node still renders, and an error would
/// mark it failed (Natron's ERROR badge) for a click the viewer ignored.
pub fn refuse(effect: &EffectHandle, why: &Failure) {
    if !effect.persistent_warning(REFUSED, why.message()) {
        effect.warning(REFUSED, why.message());
    }
}

/// Turns a core edit's error into the node's.
pub fn refused(e: morphfx::Error) -> Failure {
    Failure::BadInput(format!(
        "the edit would break the scene, so it was not made: {e}"
    ))
}

/// The Key Shapes Here button: Scene Text's shapes keyed at `time`.
pub fn key_here(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let result = document(instance, time).and_then(|mut doc| {
        doc.key_here(time).map_err(refused)?;
        instance
            .params()
            .edit_block("Key Shapes Here", || write(instance, &doc))
    });
    settle(instance, effect, result)
}

/// The Copy Scene Into Node button: Scene File's text into Scene Text, and
/// Scene File emptied so the text is what renders (one undo step).
pub fn copy_scene(instance: &NodeState, effect: &EffectHandle, time: f64) -> Outcome {
    let params = instance.params();
    let path = Reader::new(params, instance.kind, time).text(&SCENE_FILE);
    let path = path.trim();
    if path.is_empty() {
        return Ok(());
    }
    let result = std::fs::read_to_string(path)
        .map_err(|e| Failure::BadInput(format!("Copy Scene Into Node: scene file {path}: {e}")))
        .and_then(|text| {
            // A file that is not a scene is not copied: the node keeps
            // rendering what it did.
            Document::parse(&text).map_err(|e| {
                Failure::BadInput(format!("Copy Scene Into Node: scene file {path}: {e}"))
            })?;
            params.edit_block("Copy Scene Into Node", || {
                params.set_string(&SCENE_TEXT, &text)?;
                params.set_string(&SCENE_FILE, "")
            })
        });
    settle(instance, effect, result)
}

/// An edit's outcome on the node: a refusal shown, a success clearing the
/// refusal an earlier edit showed.
pub fn settle(instance: &NodeState, effect: &EffectHandle, result: Outcome) -> Outcome {
    let shown = &mut instance.overlay.locked().refused;
    match result {
        Ok(()) => {
            if std::mem::take(shown) {
                effect.clear_persistent();
            }
            Ok(())
        }
        Err(f @ Failure::BadInput(_)) => {
            *shown = true;
            refuse(effect, &f);
            Ok(())
        }
        Err(f) => Err(f),
    }
}
