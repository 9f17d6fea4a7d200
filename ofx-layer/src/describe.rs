//! The describe actions, made from a node type's constants and its
//! [`ContextSpec`]: what the host is told before any instance exists.

use std::ffi::{c_void, CStr};

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::clips::EffectHandle;
use super::plugin::{
    Components, Context, ContextSpec, ImageEffect, PixelDepth, Sequential, ThreadSafety,
};
use super::props::PropSet;
use super::{host, interact, planes, Outcome};

/// The describe action: labels, contexts, depths, capabilities, overlay.
pub(super) fn describe<E: ImageEffect>(effect: &EffectHandle) -> Outcome {
    let p = effect.props()?;
    p.set_string(kOfxPropLabel, 0, E::LABEL)?;
    let _ = p.set_string(kOfxPropShortLabel, 0, E::LABEL);
    let description = format!("{} ({}.)", E::DESCRIPTION, super::cpu::this_build());
    let _ = p.set_string(kOfxPropPluginDescription, 0, &description);
    p.set_string(kOfxImageEffectPluginPropGrouping, 0, E::GROUPING)?;
    set_names(
        &p,
        kOfxImageEffectPropSupportedContexts,
        E::CONTEXTS.iter().map(|c| c.name()),
    )?;
    let caps = E::CAPABILITIES;
    let depths = caps.depths.iter().map(|d| depth_name(*d));
    set_names(&p, kOfxImageEffectPropSupportedPixelDepths, depths)?;
    // Capabilities: optional for a host to honour, so failures to set them are not fatal.
    let _ = p.set_int(kOfxImageEffectPluginPropSingleInstance, 0, 0);
    let _ = p.set_string(
        kOfxImageEffectPluginRenderThreadSafety,
        0,
        &thread_safety_name(caps.thread_safety).to_string_lossy(),
    );
    let flags = [
        (
            kOfxImageEffectPluginPropHostFrameThreading,
            caps.host_frame_threading,
        ),
        (kOfxImageEffectPropSupportsTiles, caps.tiles),
        (
            kOfxImageEffectPropSupportsMultiResolution,
            caps.multi_resolution,
        ),
        (kOfxImageEffectPropTemporalClipAccess, caps.temporal_access),
        (
            kOfxImageEffectPropSupportsMultipleClipDepths,
            caps.multiple_clip_depths,
        ),
        (
            kOfxImageEffectPropSupportsMultipleClipPARs,
            caps.multiple_clip_aspects,
        ),
    ];
    for (name, on) in flags {
        let _ = p.set_int(name, 0, on as i32);
    }
    let _ = p.set_int(
        kOfxImageEffectInstancePropSequentialRender,
        0,
        sequential_value(caps.sequential),
    );
    // Every plane of the sources, where the host can hand them out; planes
    // the output does not make (none, for an effect that makes them all)
    // pass through rather than vanish.
    if E::MULTI_PLANE && host::multi_planar() {
        let _ = p.set_int(planes::MULTI_PLANAR, 0, 1);
        let _ = p.set_int(planes::PASS_THROUGH_COMPONENTS, 0, 1);
        let _ = p.set_int(planes::RENDER_ALL_PLANES, 0, 1);
    }
    // The viewer overlay, where the effect has one: OpenGL (V1) for every
    // host that draws overlays, the Draw suite entry (V2) only where the
    // host offers that suite.
    if E::OVERLAY.is_some() {
        let entry = interact::main_entry::<E> as *mut c_void;
        let _ = p.set_pointer(kOfxImageEffectPluginPropOverlayInteractV1, 0, entry);
        if host::suites().is_ok_and(|s| s.draw.is_some()) {
            let _ = p.set_pointer(kOfxImageEffectPluginPropOverlayInteractV2, 0, entry);
        }
    }
    Ok(())
}

/// The describe-in-context action: the node's clips and params there.
pub(super) fn describe_in_context<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
) -> Outcome {
    let context = Context::from_host(&in_args.get_string(kOfxImageEffectPropContext, 0)?)?;
    let ContextSpec { clips, params } = E::describe_in_context(context);
    for spec in clips {
        let clip = effect.define_clip(spec.name)?;
        let components = spec.components.iter().map(|c| components_name(*c));
        set_names(&clip, kOfxImageEffectPropSupportedComponents, components)?;
        let _ = clip.set_int(kOfxImageEffectPropSupportsTiles, 0, spec.tiles as i32);
        if spec.name != "Output" {
            let _ = clip.set_int(
                kOfxImageEffectPropTemporalClipAccess,
                0,
                spec.temporal_access as i32,
            );
            let _ = clip.set_int(kOfxImageClipPropOptional, 0, spec.optional as i32);
            if spec.mask {
                let _ = clip.set_int(kOfxImageClipPropIsMask, 0, 1);
            }
        }
    }
    effect.param_set()?.define_all(&params)
}

/// Sets string property `prop` to the spec's `names`.
fn set_names(p: &PropSet, prop: &CStr, names: impl Iterator<Item = &'static CStr>) -> Outcome {
    let names: Vec<String> = names.map(|n| n.to_string_lossy().into_owned()).collect();
    p.set_strings(prop, &names.iter().map(String::as_str).collect::<Vec<_>>())
}

fn depth_name(d: PixelDepth) -> &'static CStr {
    match d {
        PixelDepth::Byte => kOfxBitDepthByte,
        PixelDepth::Short => kOfxBitDepthShort,
        PixelDepth::Float => kOfxBitDepthFloat,
    }
}

fn components_name(c: Components) -> &'static CStr {
    match c {
        Components::Rgba => kOfxImageComponentRGBA,
        Components::Rgb => kOfxImageComponentRGB,
        Components::Alpha => kOfxImageComponentAlpha,
    }
}

fn thread_safety_name(t: ThreadSafety) -> &'static CStr {
    match t {
        ThreadSafety::FullySafe => kOfxImageEffectRenderFullySafe,
        ThreadSafety::InstanceSafe => kOfxImageEffectRenderInstanceSafe,
        ThreadSafety::Unsafe => kOfxImageEffectRenderUnsafe,
    }
}

fn sequential_value(s: Sequential) -> i32 {
    match s {
        Sequential::No => 0,
        Sequential::Always => 1,
        Sequential::Preferred => 2,
    }
}
