//! What the overlay shows at a time, and drawing it.

use morphfx::geom::Vec2;

use super::outline::{self, Outline};
use super::paint::{self, Frame};
use super::state::Owner;
use crate::nodes::inputs::{load_scene, warp_inputs};
use crate::nodes::lines::slot_lines;
use crate::nodes::params::{Reader, Settings, Show, OVERLAY_SHOW};
use crate::nodes::state::NodeState;
use ofx_layer::paint::Painter;
use ofx_layer::plugin::DrawArgs;
use ofx_layer::sync::Locked;
use ofx_layer::Outcome;
use ofx_layer::Reply;

/// Every feature of the node at `time`, with the progress and the frames
/// Scene Text's shapes are keyed at. A scene that does not parse is drawn
/// as nothing (the slots still are).
pub(super) struct View {
    pub(super) outlines: Vec<Outline>,
    t: f64,
    keys: Vec<f64>,
    settings: Settings,
}

pub(super) fn view(instance: &NodeState, time: f64) -> View {
    let settings = Settings::read(instance.params(), time, instance.kind);
    let slots = slot_lines(&Reader::new(instance.params(), instance.kind, time));
    let from_file = !settings.scene_file.trim().is_empty();
    let mut outlines = Vec::new();
    let mut t = settings.progress;
    if let Ok(inputs) = warp_inputs(instance, &settings, time) {
        let n = inputs.features.len() - settings.lines.len();
        let owner = |i| {
            if from_file {
                Owner::File(i)
            } else {
                Owner::Shape(i)
            }
        };
        outlines.extend(
            inputs.features[..n]
                .iter()
                .enumerate()
                .map(|(i, f)| Outline {
                    owner: owner(i),
                    feature: f.clone(),
                }),
        );
        t = inputs.t;
    }
    let keys = match load_scene(instance, &settings) {
        Ok(Some(scene)) if !from_file => scene.keyframes.iter().map(|k| k.frame).collect(),
        _ => Vec::new(),
    };
    outlines.extend(slots.iter().map(Outline::slot));
    View {
        outlines,
        t,
        keys,
        settings,
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
    let show: Show = Reader::new(instance.params(), kind, time).choice(&OVERLAY_SHOW);
    if show == Show::Off {
        return Ok(Reply::Done);
    }
    let v = view(instance, time);
    let field = &v.settings.warp.field;
    let between: Vec<Vec<Vec2>> = v
        .outlines
        .iter()
        .map(|o| outline::in_between(o, v.t, field))
        .collect();
    let (hover, building) = {
        let state = instance.overlay.locked();
        let building = state
            .building
            .as_ref()
            .map(|b| (b.points.clone(), b.cursor));
        (state.hover, building.unwrap_or_default())
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
        },
    );
    Ok(Reply::Done)
}
