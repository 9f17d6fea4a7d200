//! The actions that say what a render needs and makes: regions of
//! definition and interest, frames needed, clip preferences, identity.

use morphfx::features::Side;
use morphfx::geom::{RectD, Vec2};
use morphfx::views::View;

use crate::nodes::inputs::{warp_inputs, WarpInputs};
use crate::nodes::kind::{NodeKind, MASK_CLIP, TIMING_CLIP};
use crate::nodes::params::{Reader, Settings, OFFSET_A, OFFSET_B, VIEW};
use crate::nodes::state::NodeState;
use ofx_layer::clips::EffectHandle;
use ofx_layer::plugin::{ClipPreferences, FramesNeeded, Identity, RenderArgs, Rois};
use ofx_layer::{Outcome, Reply};

/// Each source clip and the time it is read at for output time `time`
/// (its frame offset added).
fn source_times(node: &NodeState, time: f64) -> impl Iterator<Item = (&'static str, f64)> {
    let (a, b) = node.kind.source_clips(node.context);
    let (oa, ob) = offsets(node, time);
    std::iter::once((a, time + oa)).chain(b.map(|b| (b, time + ob)))
}

/// The frame offsets of the sources (params read without a settings pass).
fn offsets(node: &NodeState, time: f64) -> (f64, f64) {
    let r = Reader::new(node.params(), node.kind, time);
    let a = r.int(&OFFSET_A) as f64;
    let b = if node.kind.has_b() {
        r.int(&OFFSET_B) as f64
    } else {
        0.0
    };
    (a, b)
}

/// The output's region of definition at `time`: the union of the connected
/// sources' regions, each at the time (offset included) it is read - what
/// hosts' own dissolves do with inputs of different data windows. The
/// region of definition action and the render use this one answer: `None`
/// while no source is connected (the spec's interface actions may come
/// then; a render may not).
pub(super) fn output_region(
    node: &NodeState,
    effect: &EffectHandle,
    time: f64,
) -> Outcome<Option<RectD>> {
    let mut union: Option<RectD> = None;
    for (name, at) in source_times(node, time) {
        let clip = effect.clip(name)?;
        if !clip.is_connected() {
            continue;
        }
        // A connected clip with no region at this time adds none (its
        // image is transparent black, like a failed fetch).
        let Ok(r) = clip.rod(at) else {
            continue;
        };
        union = Some(match union {
            None => r,
            Some(u) => RectD::new(
                u.x1.min(r.x1),
                u.y1.min(r.y1),
                u.x2.max(r.x2),
                u.y2.max(r.y2),
            ),
        });
    }
    Ok(union)
}

/// The region of definition; left to the host (its default, which the spec
/// defines per context) while no source is connected: a node just made is
/// not in error, and hosts ask before anything is connected (Natron at
/// once, showing a failure as an ERROR badge on the new node).
pub fn region_of_definition(
    node: &NodeState,
    effect: &EffectHandle,
    time: f64,
) -> Outcome<Option<RectD>> {
    output_region(node, effect, time)
}

/// Clip preferences: the output changes from frame to frame (line slots,
/// scene keyframes and progress all animate), so a host must not cache one
/// frame for every time; it is premultiplied, as the dissolve is, unless
/// every connected source is straight (then the samplers keep it straight).
pub fn clip_preferences(
    node: &NodeState,
    effect: &EffectHandle,
    out: &mut ClipPreferences,
) -> Outcome<Reply> {
    out.set_frame_varying(true);
    let (a, b) = node.kind.source_clips(node.context);
    let mut straight = Vec::new();
    for name in std::iter::once(a).chain(b) {
        let clip = effect.clip(name)?;
        if clip.is_connected() {
            straight.push(clip.is_straight());
        }
    }
    out.set_premultiplied_output(straight.is_empty() || !straight.iter().all(|s| *s));
    // The ghost and folds views put their measure in alpha, the vectors
    // view its backward motion: an RGB output (what hosts give RGB
    // sources) would drop it.
    let view = Reader::new(node.params(), node.kind, 0.0).pick(&VIEW, node.kind.views);
    if matches!(view, View::Ghost | View::Folds | View::Vectors) {
        out.set_rgba_output();
    }
    Ok(Reply::Done)
}

/// A warp can pull from anywhere: ask for each source's whole region, at the
/// frame (offset included) that source is read for this render.
pub fn regions_of_interest(
    node: &NodeState,
    effect: &EffectHandle,
    time: f64,
    out: &mut Rois,
) -> Outcome<Reply> {
    for (name, at) in source_times(node, time).chain(matte_times(node, time)) {
        let clip = effect.clip(name)?;
        if !clip.is_connected() {
            continue;
        }
        if let Ok(rod) = clip.rod(at) {
            out.set(name, rod);
        }
    }
    Ok(Reply::Done)
}

/// The mattes (Mask; Timing on the Morph node), read at the output's time:
/// the timing matte anywhere on A, so both whole.
fn matte_times(node: &NodeState, time: f64) -> impl Iterator<Item = (&'static str, f64)> {
    let timing = node.kind.timing_matte.then_some((TIMING_CLIP, time));
    timing.into_iter().chain([(MASK_CLIP, time)])
}

pub fn frames_needed(
    node: &NodeState,
    _: &EffectHandle,
    time: f64,
    out: &mut FramesNeeded,
) -> Outcome<Reply> {
    for (name, at) in source_times(node, time).chain(matte_times(node, time)) {
        out.set(name, (at, at));
    }
    Ok(Reply::Done)
}

/// The source a node's output equals bit for bit at this time, if any:
/// progress 0 shows A and 1 shows B unchanged (through the views that pass a
/// picture through), unless a transition paces pixels differently.
pub fn is_identity(
    node: &NodeState,
    effect: &EffectHandle,
    args: &RenderArgs,
) -> Outcome<Option<Identity>> {
    let time = args.time;
    let (side, settings) = side_at(node, effect, time)?;
    let Some(side) = side else {
        return Ok(None);
    };
    // Motion blur: the frame is one source only if every sample is.
    if settings.view.is_picture() {
        for t in settings.shutter.times(time) {
            if t != time && side_at(node, effect, t)?.0 != Some(side) {
                return Ok(None);
            }
        }
    }
    let (a, b) = node.kind.source_clips(node.context);
    let (clip, offset) = match (side, b) {
        (Side::B, Some(b)) => (b, settings.offset_b),
        _ => (a, settings.offset_a),
    };
    if !effect.clip(clip)?.is_connected() {
        return Ok(None); // rendered as transparent black
    }
    Ok(Some(Identity {
        clip,
        time: time + offset as f64,
    }))
}

/// Which source the output is at `time`, when it is one unchanged, with
/// the params there.
fn side_at(
    node: &NodeState,
    effect: &EffectHandle,
    time: f64,
) -> Outcome<(Option<Side>, Settings)> {
    let settings = Settings::read(node.params(), time, node.kind);
    let inputs = warp_inputs(node, &settings, time)?;
    // A mask or a mix below 1 dials a picture back toward source A: the
    // output is A where the effect is, or where none of it reaches.
    let picture = settings.view.is_picture();
    let masked = picture && (settings.mix < 1.0 || effect.clip(MASK_CLIP)?.is_connected());
    let side = if picture && settings.mix <= 0.0 {
        Some(Side::A)
    } else {
        identity_side(node.kind, settings.view, &inputs).filter(|s| !masked || *s == Side::A)
    };
    Ok((side, settings))
}

/// Which source the output is at `inputs`' progress, when it is one unchanged.
fn identity_side(kind: &NodeKind, view: View, inputs: &WarpInputs) -> Option<Side> {
    let transition = &inputs.warp.settings.transition;
    if !(transition.geometry.is_uniform_at(inputs.t) && transition.colour().is_uniform_at(inputs.t))
    {
        return None;
    }
    let side = if inputs.t <= 0.0 {
        Side::A
    } else if inputs.t >= 1.0 && kind.has_b() {
        Side::B
    } else {
        return None;
    };
    match (view, side) {
        (View::Morph, _) | (View::WarpedA, Side::A) | (View::WarpedB, Side::B) => Some(side),
        _ => None,
    }
}

/// The rectangle ST maps are normalised by, as (origin, size): the project
/// when the host says, else the source's region of definition.
pub(super) fn project(effect: &EffectHandle, rod: &RectD) -> (Vec2, Vec2) {
    effect.project().unwrap_or((
        Vec2::new(rod.x1, rod.y1),
        Vec2::new(rod.x2 - rod.x1, rod.y2 - rod.y1),
    ))
}

/// The largest frame (canonical px along a side) a warp covers; a larger or
/// infinite region of definition (allowed by the spec) is cut to the project.
const LARGEST_FRAME: f64 = 65536.0;

/// The canonical frame a warp covers: the output's region of definition,
/// or, where that is infinite or absurdly large, the project.
pub(super) fn warp_region(effect: &EffectHandle, rod: &RectD) -> RectD {
    let r = *rod;
    if r.width() <= LARGEST_FRAME && r.height() <= LARGEST_FRAME && r.is_valid() {
        return r;
    }
    let (origin, size) = project(effect, rod);
    let p = RectD::new(origin.x, origin.y, origin.x + size.x, origin.y + size.y);
    let cut = RectD::new(
        r.x1.max(p.x1),
        r.y1.max(p.y1),
        r.x2.min(p.x2),
        r.y2.min(p.y2),
    );
    if cut.is_valid() && cut.width() > 0.0 && cut.height() > 0.0 {
        cut
    } else {
        p
    }
}
