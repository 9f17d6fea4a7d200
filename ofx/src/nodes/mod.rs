//! The nodes, in safe Rust: what each declares (clips, params, capabilities)
//! and what each does per action. All host access goes through `wrapper`.

mod instance;
mod lines;
pub mod morph;
pub mod overlay;
pub mod params;
mod render;
mod snap;
pub mod spec;
mod track;
pub mod warp;

use std::ffi::CStr;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use crate::wrapper::clips::Effect;
use crate::wrapper::props::PropSet;
use crate::wrapper::{Failure, Outcome, Reply};
pub use instance::Instance;

pub const PLUGIN_VERSION: (u32, u32) = (1, 0);
pub const PLUGIN_IDS: [&str; 2] = [morph::INFO.id, warp::INFO.id];

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum NodeKind {
    Morph,
    Warp,
}

pub struct NodeInfo {
    pub id: &'static str,
    pub label: &'static str,
    pub description: &'static str,
    pub contexts: &'static [&'static CStr],
}

impl NodeKind {
    pub const ALL: [NodeKind; 2] = [NodeKind::Morph, NodeKind::Warp];

    pub fn info(self) -> &'static NodeInfo {
        match self {
            NodeKind::Morph => &morph::INFO,
            NodeKind::Warp => &warp::INFO,
        }
    }

    /// The source clips in `context`: (A, B) for Morph, (Source, none) for Warp.
    pub fn source_clips(self, context: &str) -> (&'static str, Option<&'static str>) {
        match self {
            NodeKind::Morph => {
                let [a, b] = morph::source_clips(context);
                (a, Some(b))
            }
            NodeKind::Warp => (warp::SOURCE_CLIP, None),
        }
    }
}

fn is(action: &CStr, name: &CStr) -> bool {
    action == name
}

/// An action's argument set, or the error that says the host sent none.
fn arg(args: Option<PropSet>, which: &str, action: &CStr) -> Outcome<PropSet> {
    args.ok_or_else(|| {
        Failure::Status(
            kOfxStatErrBadHandle,
            format!("{} without {which} arguments", action.to_string_lossy()),
        )
    })
}

/// Runs one action; [`Reply::Default`] for actions we leave to the host.
pub fn action(
    kind: NodeKind,
    action: &CStr,
    effect: Option<Effect>,
    in_args: Option<PropSet>,
    out_args: Option<PropSet>,
) -> Outcome<Reply> {
    if is(action, kOfxActionUnload) {
        return Ok(Reply::Done);
    }
    let effect = effect.ok_or_else(|| {
        Failure::Status(
            kOfxStatErrBadHandle,
            format!("{} without an effect handle", action.to_string_lossy()),
        )
    })?;
    let in_props = || arg(in_args, "in", action);
    let out_props = || arg(out_args, "out", action);
    if is(action, kOfxActionDescribe) {
        describe(kind, &effect)?;
    } else if is(action, kOfxImageEffectActionDescribeInContext) {
        let context = in_props()?.get_string(kOfxImageEffectPropContext, 0)?;
        describe_in_context(kind, &effect, &context)?;
    } else if is(action, kOfxActionCreateInstance) {
        instance::create(kind, &effect)?;
    } else if is(action, kOfxActionDestroyInstance) {
        instance::destroy(&effect)?;
    } else if is(action, kOfxActionPurgeCaches) {
        instance::get(&effect)?.purge();
    } else if is(action, kOfxImageEffectActionGetRegionOfDefinition) {
        return render::region_of_definition(kind, &effect, &in_props()?, &out_props()?);
    } else if is(action, kOfxImageEffectActionGetRegionsOfInterest) {
        render::regions_of_interest(kind, &effect, &in_props()?, &out_props()?)?;
    } else if is(action, kOfxImageEffectActionGetFramesNeeded) {
        render::frames_needed(kind, &effect, &in_props()?, &out_props()?)?;
    } else if is(action, kOfxImageEffectActionGetClipPreferences) {
        render::clip_preferences(kind, &effect, &out_props()?)?;
    } else if is(action, kOfxImageEffectActionIsIdentity) {
        return render::is_identity(kind, &effect, &in_props()?, &out_props()?);
    } else if is(action, kOfxImageEffectActionRender) {
        render::render(kind, &effect, &in_props()?)?;
        crate::wrapper::dispatch::render_succeeded(&effect);
    } else if is(action, kOfxActionInstanceChanged) {
        instance_changed(kind, &effect, &in_props()?)?;
    } else {
        return Ok(Reply::Default);
    }
    Ok(Reply::Done)
}

/// A param changed: the buttons act, Line Count shows its slots.
fn instance_changed(kind: NodeKind, effect: &Effect, in_args: &PropSet) -> Outcome {
    let name = in_args.get_string(kOfxPropName, 0)?;
    let time = in_args.get_double(kOfxPropTime, 0)?;
    if name == params::SNAP_LINES {
        snap::snap_lines(kind, effect, time)
    } else if name == params::TRACK_FORWARD {
        track::track_lines(kind, effect, time, 1)
    } else if name == params::TRACK_BACKWARD {
        track::track_lines(kind, effect, time, -1)
    } else if name == params::LINE_COUNT {
        lines::hide_unused(kind, instance::get(effect)?.params()?, time);
        Ok(())
    } else if let Some(k) = params::clear_button_slot(&name) {
        lines::clear(kind, instance::get(effect)?.params()?, k, time)
    } else {
        Ok(())
    }
}

fn describe(kind: NodeKind, effect: &Effect) -> Outcome {
    let info = kind.info();
    let p = effect.props()?;
    p.set_string(kOfxPropLabel, 0, info.label)?;
    let _ = p.set_string(kOfxPropShortLabel, 0, info.label);
    let _ = p.set_string(kOfxPropPluginDescription, 0, info.description);
    p.set_string(kOfxImageEffectPluginPropGrouping, 0, "MorphFX")?;
    let contexts: Vec<String> = info
        .contexts
        .iter()
        .map(|c| c.to_string_lossy().into_owned())
        .collect();
    p.set_strings(
        kOfxImageEffectPropSupportedContexts,
        &contexts.iter().map(String::as_str).collect::<Vec<_>>(),
    )?;
    p.set_strings(
        kOfxImageEffectPropSupportedPixelDepths,
        &["OfxBitDepthByte", "OfxBitDepthShort", "OfxBitDepthFloat"],
    )?;
    // Capabilities: optional for a host to honour, so failures to set them are not fatal.
    let _ = p.set_int(kOfxImageEffectPluginPropSingleInstance, 0, 0);
    let _ = p.set_string(
        kOfxImageEffectPluginRenderThreadSafety,
        0,
        &kOfxImageEffectRenderFullySafe.to_string_lossy(),
    );
    // We split the window across threads ourselves (rayon), so the host need not.
    let _ = p.set_int(kOfxImageEffectPluginPropHostFrameThreading, 0, 0);
    let _ = p.set_int(kOfxImageEffectPropSupportsTiles, 0, 1);
    let _ = p.set_int(kOfxImageEffectPropSupportsMultiResolution, 0, 1);
    let _ = p.set_int(kOfxImageEffectPropTemporalClipAccess, 0, 1);
    let _ = p.set_int(kOfxImageEffectPropSupportsMultipleClipDepths, 0, 0);
    let _ = p.set_int(kOfxImageEffectPropSupportsMultipleClipPARs, 0, 0);
    // A geometric warp must not mix the two fields of interlaced footage,
    // so FieldRenderTwiceAlways keeps its default (1: render each field).
    // Warm starts make a sequence cheaper in frame order, but any order is
    // correct (they are only used when the host says it renders in order).
    let _ = p.set_int(kOfxImageEffectInstancePropSequentialRender, 0, 2);
    // The viewer overlay: OpenGL (V1) for every host that draws overlays,
    // the Draw suite entry (V2) only where the host offers that suite.
    let entry = crate::wrapper::interact::entry(kind);
    let _ = p.set_pointer(kOfxImageEffectPluginPropOverlayInteractV1, 0, entry);
    if crate::wrapper::host::suites().is_ok_and(|s| s.draw.is_some()) {
        let _ = p.set_pointer(kOfxImageEffectPluginPropOverlayInteractV2, 0, entry);
    }
    Ok(())
}

fn describe_in_context(kind: NodeKind, effect: &Effect, context: &str) -> Outcome {
    let (a, b) = kind.source_clips(context);
    for name in std::iter::once(a).chain(b) {
        let clip = effect.define_clip(name)?;
        clip.set_strings(
            kOfxImageEffectPropSupportedComponents,
            &[
                "OfxImageComponentRGBA",
                "OfxImageComponentRGB",
                "OfxImageComponentAlpha",
            ],
        )?;
        let _ = clip.set_int(kOfxImageEffectPropSupportsTiles, 0, 1);
        let _ = clip.set_int(kOfxImageEffectPropTemporalClipAccess, 0, 1);
        let _ = clip.set_int(kOfxImageClipPropOptional, 0, 0);
    }
    let out = effect.define_clip("Output")?;
    out.set_strings(
        kOfxImageEffectPropSupportedComponents,
        &[
            "OfxImageComponentRGBA",
            "OfxImageComponentRGB",
            "OfxImageComponentAlpha",
        ],
    )?;
    let _ = out.set_int(kOfxImageEffectPropSupportsTiles, 0, 1);
    effect
        .param_set()?
        .define_all(&params::table_in_context(kind, context))
}
