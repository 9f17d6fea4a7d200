//! The Track Forward and Track Backward push-buttons: every enabled line
//! slot, every shape of Scene Text and Scene Text's mesh followed through
//! its source from the current frame, one frame at a time, to the next key
//! in that direction (or the end of the clip), keyed at each frame: A's
//! points on Source A, B's on Source B (Morph). Slots are keyed in their
//! params; shapes and the mesh in Scene Text, written once at the end (one
//! undo step with the slots'). A mesh's nodes on flat ground move with
//! their neighbours; a grid that would fold is keyed no further.
//!
//! The core's tracker does the work (docs/tracking.md): each frame is
//! matched against the current frame's picture, so nothing drifts. A line
//! that loses track is keyed no further, and named in a message at the end.
//! The host's progress bar shows the frames; cancel keeps the keys made.

use std::sync::Arc;

use morphfx::features::{FeatureKind, Side};
use morphfx::geom::{PixelScale, Vec2};
use morphfx::track::{Grey, GridTracker, Pyramid, SideTracker, TrackSettings};
use morphfx::warp::mesh::Mesh;

use morphfx::scene::edit::Document;

use super::kind::NodeKind;
use super::lines::{end_id, slot_lines, SlotLine};
use super::overlay::shapes;
use super::params::{Reader, Settings};
use super::state::NodeState;
use ofx_layer::clips::{Depth, EffectHandle};
use ofx_layer::params::Params;
use ofx_layer::plugin::Context;
use ofx_layer::{Failure, Outcome};

/// Frames tracked at most when neither keys nor the clip say where to stop.
const MAX_FRAMES: i64 = 10_000;

/// What a follower keys.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    /// Line slot `k`: its end params.
    Slot(usize),
    /// Scene Text's feature `i`.
    Shape(usize),
}

/// One side of Scene Text's mesh being tracked.
struct GridFollower {
    side: Side,
    rows: usize,
    cols: usize,
    tracker: GridTracker,
    /// The frame it was lost or would have folded at, after which it is
    /// keyed no more, and why.
    stopped: Option<(f64, &'static str)>,
}

/// One side of one slot or shape being tracked.
struct Follower {
    target: Target,
    side: Side,
    tracker: SideTracker,
    /// The first frame it lost track at, after which it is keyed no more.
    lost_at: Option<f64>,
}

/// A source clip and its frame offset, with the pixel scale of its images.
struct Source<'e> {
    effect: &'e EffectHandle,
    clip: &'static str,
    offset: f64,
}

impl Source<'_> {
    /// The pyramid of the source at node time `time`, and the scale its
    /// pixels are at; `None` when the clip has no image there.
    fn pyramid(&self, time: f64, levels: usize) -> Outcome<Option<(Arc<Pyramid>, PixelScale)>> {
        let Some(image) = self.effect.clip(self.clip)?.image(time + self.offset)? else {
            return Ok(None);
        };
        let info = image.info();
        let scale = PixelScale::new(info.render_scale.0, info.render_scale.1, info.par);
        let grey = match info.depth {
            Depth::U8 => Grey::from_view(&image.view::<u8>()?),
            Depth::U16 => Grey::from_view(&image.view::<u16>()?),
            Depth::F32 => Grey::from_view(&image.view::<f32>()?),
        };
        Ok(Some((Arc::new(Pyramid::new(grey, levels, 16)), scale)))
    }
}

/// A Track button pressed at `time`: `step` is 1 (forward) or -1.
pub fn track_lines(instance: &NodeState, effect: &EffectHandle, time: f64, step: i64) -> Outcome {
    let kind = instance.kind;
    let params = instance.params();
    let lines = slot_lines(&Reader::new(params, kind, time));
    // Scene Text's shapes when the viewer may edit them (a Scene File's
    // features are not the node's to key).
    let doc = shapes::document(instance, time).ok();
    let shape_list = doc
        .as_ref()
        .map(|d| d.scene().features_at(time))
        .unwrap_or_default();
    let mesh = doc.as_ref().and_then(|d| d.scene().mesh_at(time));
    if lines.is_empty() && shape_list.is_empty() && mesh.is_none() {
        return Ok(());
    }
    let sources = sources((kind, instance.context), effect, params, time)?;
    let mut shape_keys = doc.as_ref().map(Document::keyed_frames).unwrap_or_default();
    shape_keys.extend(
        doc.as_ref()
            .map(Document::mesh_keyed_frames)
            .unwrap_or_default(),
    );
    let stop = stop_frame(params, effect, &sources, (&lines, &shape_keys), time, step);
    let settings = TrackSettings::default();
    let mut followers = Vec::new();
    let mut grids = Vec::new();
    for (side, source) in &sources {
        let (key, scale) = source.pyramid(time, settings.levels)?.ok_or_else(|| {
            Failure::BadInput(format!(
                "Track: clip {} has no image at frame {time}",
                source.clip
            ))
        })?;
        let slots = lines.iter().map(|l| {
            let ends = l.side(*side);
            (Target::Slot(l.slot), FeatureKind::Line, ends.to_vec())
        });
        let shapes = shape_list
            .iter()
            .enumerate()
            .map(|(i, f)| (Target::Shape(i), f.kind, f.points(*side).to_vec()));
        for (target, kind, points) in slots.chain(shapes) {
            let px: Vec<Vec2> = points.iter().map(|p| scale.to_pixel(*p)).collect();
            followers.push(Follower {
                target,
                side: *side,
                tracker: SideTracker::new(kind, &px, &key, &settings),
                lost_at: None,
            });
        }
        if let Some(pair) = &mesh {
            let m = pair.side(*side);
            let px: Vec<Vec2> = m.nodes().iter().map(|p| scale.to_pixel(*p)).collect();
            grids.push(GridFollower {
                side: *side,
                rows: m.rows(),
                cols: m.cols(),
                tracker: GridTracker::new(m.rows(), m.cols(), &px, &key, &settings),
                stopped: None,
            });
        }
    }
    let label = if step > 0 {
        "Track Forward"
    } else {
        "Track Backward"
    };
    effect.progress_start(label);
    let result = params.edit_block(label, || {
        let mut keys = Keys::default();
        let swept = sweep(
            effect,
            params,
            &sources,
            (&mut followers, &mut grids),
            (time, stop, step),
            &settings,
            &mut keys,
        );
        // The shapes' keys made so far are written even after a failure or
        // a cancel, as the slots' are.
        let written = match doc {
            Some(mut doc) if !keys.is_empty() => key_shapes(instance, &mut doc, time, &keys),
            _ => Ok(()),
        };
        swept.and(written)
    });
    effect.progress_end();
    instance.purge();
    result?;
    report_lost(effect, &followers, &shape_list, &grids);
    Ok(())
}

/// Keys Scene Text's shapes and mesh: at the start frame as they are (so
/// a static scene keeps its shape there), then where the tracker found
/// them.
fn key_shapes(instance: &NodeState, doc: &mut Document, time: f64, keys: &Keys) -> Outcome {
    doc.key_here(time).map_err(shapes::refused)?;
    doc.set_points(&keys.shapes).map_err(shapes::refused)?;
    for (frame, side, nodes) in &keys.meshes {
        doc.set_mesh_side(*frame, *side, nodes)
            .map_err(shapes::refused)?;
    }
    shapes::write(instance, doc)
}

/// A shape's points found at a frame: `(frame, feature, side, points)`.
type ShapeKey = (f64, usize, Side, Vec<Vec2>);

/// What a sweep found for Scene Text: shapes' points, and a mesh side's
/// nodes `(frame, side, nodes)`, canonical.
#[derive(Default)]
struct Keys {
    shapes: Vec<ShapeKey>,
    meshes: Vec<(f64, Side, Vec<Vec2>)>,
}

impl Keys {
    fn is_empty(&self) -> bool {
        self.shapes.is_empty() && self.meshes.is_empty()
    }
}

/// The node's sources with their sides and frame offsets, each connected.
fn sources<'e>(
    (kind, context): (&'static NodeKind, Context),
    effect: &'e EffectHandle,
    params: &Params,
    time: f64,
) -> Outcome<Vec<(Side, Source<'e>)>> {
    let settings = Settings::read(params, time, kind);
    let (a, b) = kind.source_clips(context);
    let mut out = vec![(Side::A, a, settings.offset_a)];
    out.extend(b.map(|b| (Side::B, b, settings.offset_b)));
    out.into_iter()
        .map(|(side, clip, offset)| {
            if !effect.clip(clip)?.is_connected() {
                return Err(Failure::BadInput(format!(
                    "Track needs clip {clip} connected"
                )));
            }
            Ok((
                side,
                Source {
                    effect,
                    clip,
                    offset: offset as f64,
                },
            ))
        })
        .collect()
}

/// The last frame to key: before the nearest key of any tracked slot end
/// or of the shapes beyond `time`, else the clip's last (or first) frame.
fn stop_frame(
    params: &Params,
    effect: &EffectHandle,
    sources: &[(Side, Source<'_>)],
    (lines, shape_keys): (&[SlotLine], &[f64]),
    time: f64,
    step: i64,
) -> f64 {
    let dir = step as f64;
    let next_key = sources
        .iter()
        .flat_map(|(side, _)| lines.iter().map(move |l| (l.slot, *side)))
        .flat_map(|(slot, side)| (0..2).map(move |end| end_id(slot, side, end)))
        // A host that cannot list keys: the clip's end decides.
        .flat_map(|id| params.key_times(&id).unwrap_or_default())
        .chain(shape_keys.iter().copied())
        .filter(|t| (t - time) * dir > 0.5)
        .min_by(|x, y| ((x - time) * dir).total_cmp(&((y - time) * dir)));
    if let Some(key) = next_key {
        return key - dir;
    }
    let range = sources
        .iter()
        .filter_map(|(_, s)| {
            let (a, b) = effect.clip(s.clip).ok()?.frame_range()?;
            Some((a - s.offset, b - s.offset))
        })
        .reduce(|x, y| (x.0.max(y.0), x.1.min(y.1)));
    match range {
        Some((first, last)) => {
            if step > 0 {
                last
            } else {
                first
            }
        }
        None => time + dir * MAX_FRAMES as f64,
    }
}

/// Frames `time + step` to `stop`: track, key, report progress.
fn sweep(
    effect: &EffectHandle,
    params: &Params,
    sources: &[(Side, Source<'_>)],
    (followers, grids): (&mut [Follower], &mut [GridFollower]),
    (time, stop, step): (f64, f64, i64),
    settings: &TrackSettings,
    keys: &mut Keys,
) -> Outcome {
    let total = ((stop - time) * step as f64).round().max(0.0) as i64;
    for n in 1..=total {
        let frame = time + (n * step) as f64;
        for (side, source) in sources {
            // A clip that ends early (no image) ends the sweep.
            let Some((pyramid, scale)) = source.pyramid(frame, settings.levels)? else {
                return Ok(());
            };
            for f in followers
                .iter_mut()
                .filter(|f| f.side == *side && f.lost_at.is_none())
            {
                let e = f.tracker.step(&pyramid, settings);
                if e.lost.iter().any(|l| *l) {
                    f.lost_at = Some(frame);
                    continue;
                }
                let found = e
                    .points
                    .iter()
                    .map(|p| Vec2::new(p.x / scale.x, p.y / scale.y));
                match f.target {
                    Target::Slot(slot) => {
                        for (end, at) in found.enumerate() {
                            let id = end_id(slot, f.side, end);
                            params.set_point_at(&id, frame, (at.x, at.y))?;
                        }
                    }
                    Target::Shape(i) => keys.shapes.push((frame, i, f.side, found.collect())),
                }
            }
            for g in grids
                .iter_mut()
                .filter(|g| g.side == *side && g.stopped.is_none())
            {
                follow_grid(g, &pyramid, scale, frame, settings, keys);
            }
        }
        let all_stopped = followers.iter().all(|f| f.lost_at.is_some())
            && grids.iter().all(|g| g.stopped.is_some());
        if all_stopped || !effect.progress_update(n as f64 / total as f64) {
            break;
        }
    }
    Ok(())
}

/// One side of the mesh at `frame`: keyed where the tracker puts it,
/// unless it is lost or would fold (then it stops there).
fn follow_grid(
    g: &mut GridFollower,
    pyramid: &Pyramid,
    scale: PixelScale,
    frame: f64,
    settings: &TrackSettings,
    keys: &mut Keys,
) {
    let e = g.tracker.step(pyramid, settings);
    if e.is_lost() {
        g.stopped = Some((frame, "lost"));
        return;
    }
    let nodes: Vec<Vec2> = e.nodes.iter().map(|p| scale.to_canonical(*p)).collect();
    let unfolded = Mesh::new(g.rows, g.cols, nodes.clone()).is_ok_and(|m| m.check("mesh").is_ok());
    if !unfolded {
        g.stopped = Some((frame, "would fold"));
        return;
    }
    keys.meshes.push((frame, g.side, nodes));
}

/// Names each line, shape or grid that lost track, and where.
fn report_lost(
    effect: &EffectHandle,
    followers: &[Follower],
    shapes: &[morphfx::features::Feature],
    grids: &[GridFollower],
) {
    let grid_lost = grids.iter().filter_map(|g| {
        let side = if g.side == Side::A { "A" } else { "B" };
        g.stopped
            .map(|(t, why)| format!("the grid on {side} at frame {t} ({why})"))
    });
    let lost: Vec<String> = followers
        .iter()
        .filter_map(|f| {
            let side = if f.side == Side::A { "A" } else { "B" };
            let what = match f.target {
                Target::Slot(k) => format!("line {k}"),
                Target::Shape(i) => match shapes.get(i).and_then(|s| s.name.as_deref()) {
                    Some(name) => format!("shape \"{name}\""),
                    None => format!("shape #{}", i + 1),
                },
            };
            f.lost_at.map(|t| format!("{what} on {side} at frame {t}"))
        })
        .chain(grid_lost)
        .collect();
    if !lost.is_empty() {
        effect.warning(
            c"net.morphfx.track.lost",
            &format!(
                "Track lost {} (not keyed from there: key it by hand and track again): {}",
                if lost.len() == 1 {
                    "a feature"
                } else {
                    "features"
                },
                lost.join(", ")
            ),
        );
    }
}
