//! The actions that say what a render needs and makes: regions of
//! definition and interest, frames needed, clip preferences, identity.

use morphfx::features::Side;
use morphfx::geom::{RectD, Vec2};
use morphfx::views::View;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::context;
use super::inputs::{warp_inputs, WarpInputs};
use crate::nodes::instance;
use crate::nodes::params::{Reader, Settings, OFFSET_A, OFFSET_B};
use crate::nodes::NodeKind;
use crate::wrapper::clips::Effect;
use crate::wrapper::props::PropSet;
use crate::wrapper::{Outcome, Reply};

/// Each source clip in `context` and the time it is read at for output
/// time `time` (its frame offset added).
fn source_times(
    kind: NodeKind,
    effect: &Effect,
    context: &str,
    time: f64,
) -> impl Iterator<Item = (&'static str, f64)> {
    let (a, b) = kind.source_clips(context);
    let (oa, ob) = offsets(kind, effect, time);
    std::iter::once((a, time + oa)).chain(b.map(|b| (b, time + ob)))
}

/// The frame offsets of the sources (params read without a settings pass).
fn offsets(kind: NodeKind, effect: &Effect, time: f64) -> (f64, f64) {
    let Ok(instance) = instance::get(effect) else {
        return (0.0, 0.0);
    };
    let Ok(params) = instance.params() else {
        return (0.0, 0.0);
    };
    let r = Reader::new(params, kind, time);
    let a = r.int(OFFSET_A) as f64;
    let b = if kind == NodeKind::Morph {
        r.int(OFFSET_B) as f64
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
    kind: NodeKind,
    effect: &Effect,
    context: &str,
    time: f64,
) -> Outcome<Option<OfxRectD>> {
    let mut union: Option<OfxRectD> = None;
    for (name, at) in source_times(kind, effect, context, time) {
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
            Some(u) => OfxRectD {
                x1: u.x1.min(r.x1),
                y1: u.y1.min(r.y1),
                x2: u.x2.max(r.x2),
                y2: u.y2.max(r.y2),
            },
        });
    }
    Ok(union)
}

/// The region of definition; left to the host (its default, which the spec
/// defines per context) while no source is connected: a node just made is
/// not in error, and hosts ask before anything is connected (Natron at
/// once, showing a failure as an ERROR badge on the new node).
pub fn region_of_definition(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let Some(rod) = output_region(kind, effect, &context(effect), time)? else {
        return Ok(Reply::Default);
    };
    out_args.set_doubles(
        kOfxImageEffectPropRegionOfDefinition,
        &[rod.x1, rod.y1, rod.x2, rod.y2],
    )?;
    Ok(Reply::Done)
}

/// Clip preferences: the output changes from frame to frame (line slots,
/// scene keyframes and progress all animate), so a host must not cache one
/// frame for every time; it is premultiplied, as the dissolve is, unless
/// every connected source is straight (then the samplers keep it straight).
pub fn clip_preferences(kind: NodeKind, effect: &Effect, out_args: &PropSet) -> Outcome {
    out_args.set_int(kOfxImageEffectFrameVarying, 0, 1)?;
    let (a, b) = kind.source_clips(&context(effect));
    let mut straight = Vec::new();
    for name in std::iter::once(a).chain(b) {
        let clip = effect.clip(name)?;
        if clip.is_connected() {
            let state = clip
                .props()?
                .get_string(kOfxImageEffectPropPreMultiplication, 0)
                .unwrap_or_default();
            straight.push(state.as_bytes() == kOfxImageUnPreMultiplied.to_bytes());
        }
    }
    let output = if !straight.is_empty() && straight.iter().all(|s| *s) {
        kOfxImageUnPreMultiplied
    } else {
        kOfxImagePreMultiplied
    };
    out_args.set_string(
        kOfxImageEffectPropPreMultiplication,
        0,
        &output.to_string_lossy(),
    )
}

/// A warp can pull from anywhere: ask for each source's whole region, at the
/// frame (offset included) that source is read for this render.
pub fn regions_of_interest(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    for (name, at) in source_times(kind, effect, &context(effect), time) {
        let clip = effect.clip(name)?;
        if !clip.is_connected() {
            continue;
        }
        if let Ok(rod) = clip.rod(at) {
            let prop =
                std::ffi::CString::new(format!("OfxImageClipPropRoI_{name}")).unwrap_or_default();
            out_args.set_doubles(&prop, &[rod.x1, rod.y1, rod.x2, rod.y2])?;
        }
    }
    Ok(())
}

pub fn frames_needed(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    for (name, at) in source_times(kind, effect, &context(effect), time) {
        let prop = std::ffi::CString::new(format!("OfxImageClipPropFrameRange_{name}"))
            .unwrap_or_default();
        out_args.set_doubles(&prop, &[at, at])?;
    }
    Ok(())
}

/// The source a node's output equals bit for bit at this time, if any:
/// progress 0 shows A and 1 shows B unchanged (through the views that pass a
/// picture through), unless a transition paces pixels differently. Answered
/// `kOfxStatOK` with the clip and its time, else `kOfxStatReplyDefault`.
pub fn is_identity(
    kind: NodeKind,
    effect: &Effect,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let instance = instance::get(effect)?;
    let context = context(effect);
    let settings = Settings::read(instance.params()?, time, kind);
    let inputs = warp_inputs(kind, &instance, &settings, time, &context)?;
    let Some(side) = identity_side(kind, settings.view, &inputs) else {
        return Ok(Reply::Default);
    };
    let (a, b) = kind.source_clips(&context);
    let (name, offset) = match (side, b) {
        (Side::B, Some(b)) => (b, settings.offset_b),
        _ => (a, settings.offset_a),
    };
    if !effect.clip(name)?.is_connected() {
        return Ok(Reply::Default); // rendered as transparent black
    }
    out_args.set_string(kOfxPropName, 0, name)?;
    out_args.set_double(kOfxPropTime, 0, time + offset as f64)?;
    Ok(Reply::Done)
}

/// Which source the output is at `inputs`' progress, when it is one unchanged.
fn identity_side(kind: NodeKind, view: View, inputs: &WarpInputs) -> Option<Side> {
    let transition = &inputs.warp.settings.transition;
    if !(transition.geometry.is_uniform_at(inputs.t) && transition.colour().is_uniform_at(inputs.t))
    {
        return None;
    }
    let side = if inputs.t <= 0.0 {
        Side::A
    } else if inputs.t >= 1.0 && kind == NodeKind::Morph {
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
/// when the host says (the spec's project size, placed at the project offset;
/// the extent is rooted at 0,0 and is not the size), else the source's
/// region of definition.
pub(super) fn project(effect: &Effect, rod: &OfxRectD) -> (Vec2, Vec2) {
    let from_host = effect.props().ok().and_then(|p| {
        let size = p.get_doubles::<2>(kOfxImageEffectPropProjectSize).ok()?;
        let origin = p
            .get_doubles::<2>(kOfxImageEffectPropProjectOffset)
            .unwrap_or([0.0, 0.0]);
        (size[0] > 0.0 && size[1] > 0.0)
            .then(|| (Vec2::new(origin[0], origin[1]), Vec2::new(size[0], size[1])))
    });
    from_host.unwrap_or((
        Vec2::new(rod.x1, rod.y1),
        Vec2::new(rod.x2 - rod.x1, rod.y2 - rod.y1),
    ))
}

/// The largest frame (canonical px along a side) a warp covers; a larger or
/// infinite region of definition (allowed by the spec) is cut to the project.
const LARGEST_FRAME: f64 = 65536.0;

/// The canonical frame a warp covers: the output's region of definition,
/// or, where that is infinite or absurdly large, the project.
pub(super) fn warp_region(effect: &Effect, rod: &OfxRectD) -> RectD {
    let r = RectD::new(rod.x1, rod.y1, rod.x2, rod.y2);
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
