//! What the overlay shows at a time, and drawing it.

use std::sync::Arc;

use morphfx::geom::Vec2;
use morphfx::make_warp::Method;
use morphfx::scene::Scene;
use morphfx::warp::field::FieldSettings;

use super::grid::Grid;
use super::outline::{self, Outline};
use super::paint::{self, Frame};
use super::state::{Drag, Owner};
use crate::nodes::inputs::{load_scene, progress_at, scene_settings};
use crate::nodes::lines::slot_lines;
use crate::nodes::params::{
    field_settings, Reader, Show, METHOD, OVERLAY_SHOW, PROGRESS, SCENE_FILE, SCENE_TEXT,
    SETTINGS_FROM_SCENE, USE_SCENE_PROGRESS,
};
use crate::nodes::state::NodeState;
use ofx_layer::paint::Painter;
use ofx_layer::plugin::DrawArgs;
use ofx_layer::sync::Locked;
use ofx_layer::{Outcome, Reply};

/// What the pen can grab at `time`: every line slot and every feature of
/// the scene, at their A and B positions, and Scene Text's grid when the
/// method is mesh. It reads only the params that place them (Scene File,
/// Scene Text, Line Count and the used slots; the method only when the
/// scene has a mesh). A scene that does not parse gives no features (the
/// slots still count).
pub(super) fn grabbable(
    instance: &NodeState,
    r: &Reader<'_>,
    time: f64,
) -> (Vec<Outline>, Option<Grid>) {
    let (outlines, scene) = outlines_and_scene(instance, r, time);
    let grid = match &scene {
        Some((s, false)) => grid_of(instance, r, (s, false), 0.0, time),
        _ => None,
    };
    (outlines, grid)
}

/// The outlines, and the scene they came from with whether it is Scene
/// File's.
fn outlines_and_scene(
    instance: &NodeState,
    r: &Reader<'_>,
    time: f64,
) -> (Vec<Outline>, Option<(Arc<Scene>, bool)>) {
    let (file, text) = (r.text(&SCENE_FILE), r.text(&SCENE_TEXT));
    let from_file = !file.trim().is_empty();
    let scene = load_scene(instance, &file, &text).ok().flatten();
    let owner = |i| match from_file {
        true => Owner::File(i),
        false => Owner::Shape(i),
    };
    let scene_features = scene
        .as_ref()
        .map_or_else(Vec::new, |s| s.features_at(time));
    let mut outlines: Vec<Outline> = scene_features
        .into_iter()
        .enumerate()
        .map(|(i, feature)| Outline {
            owner: owner(i),
            feature,
        })
        .collect();
    outlines.extend(slot_lines(r).iter().map(Outline::slot));
    (outlines, scene.map(|s| (s, from_file)))
}

/// The scene's mesh at `time` as the overlay shows it, with the grid in
/// between at `t`, when the method (the scene's where the node takes its
/// settings from it, else the node's) is mesh.
fn grid_of(
    instance: &NodeState,
    r: &Reader<'_>,
    (scene, from_file): (&Scene, bool),
    t: f64,
    time: f64,
) -> Option<Grid> {
    let pair = scene.mesh_at(time)?;
    let from_scene = scene_settings(Some(scene), r.bool(&SETTINGS_FROM_SCENE), time);
    let method = from_scene.map_or_else(
        || r.pick(&METHOD, instance.kind.methods),
        |w| w.settings.method,
    );
    if method != Method::Mesh {
        return None;
    }
    Some(Grid {
        between: pair.at(t),
        pair,
        editable: !from_file,
    })
}

/// What the overlay draws at `time`: the outlines, the progress their
/// in-between shapes are drawn at, the line interpolation those follow,
/// the frames Scene Text's shapes are keyed at, and the mesh.
struct View {
    outlines: Vec<Outline>,
    t: f64,
    field: FieldSettings,
    keys: Vec<f64>,
    grid: Option<Grid>,
}

fn view(instance: &NodeState, r: &Reader<'_>, time: f64) -> View {
    let (outlines, scene) = outlines_and_scene(instance, r, time);
    let loaded = scene.as_ref().map(|(s, _)| &**s);
    let node = (r.double(&PROGRESS), r.bool(&USE_SCENE_PROGRESS));
    let t = progress_at(instance, loaded, node, time).unwrap_or(node.0);
    let from_scene = scene_settings(loaded, r.bool(&SETTINGS_FROM_SCENE), time);
    let field = from_scene.map_or_else(|| field_settings(r), |w| w.settings.field);
    let mut keys: Vec<f64> = match &scene {
        Some((s, false)) => s.keyframes.iter().map(|k| k.frame).collect(),
        _ => Vec::new(),
    };
    let grid = scene
        .as_ref()
        .and_then(|(s, file)| grid_of(instance, r, (s, *file), t, time));
    // A keyed mesh's keys are its own (a drag keys only the mesh); one
    // key alone is where Key Shapes Here keyed the features as well.
    if let (Some(_), Some((s, false))) = (&grid, &scene) {
        if s.meshes.len() > 1 {
            keys.extend(s.meshes.iter().map(|m| m.0));
            keys.sort_by(f64::total_cmp);
            keys.dedup_by(|x, y| (*x - *y).abs() < 1e-6);
        }
    }
    View {
        outlines,
        t,
        field,
        keys,
        grid,
    }
}

/// Draws the overlay (returns at once when Show Lines is off). A pixel
/// scale measured from the OpenGL projection is kept for the pen events
/// that follow (they carry only the host's figure).
pub fn draw(instance: &NodeState, args: &DrawArgs, painter: &mut dyn Painter) -> Outcome<Reply> {
    let (kind, time, pixel) = (instance.kind, args.time, args.pixel);
    if args.measured {
        instance.overlay.locked().measured_pixel = Some(pixel);
    }
    let r = Reader::new(instance.params(), kind, time);
    let show: Show = r.choice(&OVERLAY_SHOW);
    if show == Show::Off {
        return Ok(Reply::Done);
    }
    let v = view(instance, &r, time);
    let field = &v.field;
    let between: Vec<Vec<Vec2>> = v
        .outlines
        .iter()
        .map(|o| outline::in_between(o, v.t, field))
        .collect();
    let (hover, building, selection, band) = {
        let state = instance.overlay.locked();
        let building = state
            .building
            .as_ref()
            .map(|b| (b.points.clone(), b.cursor));
        let band = match &state.drag {
            Some(Drag::Band { from, to }) => Some([*from, *to]),
            _ => None,
        };
        let selection = state.grid_selection.clone();
        (state.hover, building.unwrap_or_default(), selection, band)
    };
    paint::paint(
        painter,
        &Frame {
            outlines: &v.outlines,
            between: &between,
            show,
            hover,
            pixel,
            keys: (&v.keys, time),
            building: (&building.0, building.1),
            grid: v.grid.as_ref(),
            grid_selection: selection.as_ref(),
            band,
        },
    );
    Ok(Reply::Done)
}
