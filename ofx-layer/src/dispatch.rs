//! The one door every action comes through, made per node type: null
//! checks, unwinds caught, each action's arguments read into typed values,
//! the node's answer written back, failures reported through the message
//! suite and mapped to OFX statuses.

use std::ffi::{c_char, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::Ordering;

use morphfx::geom::RectI;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::attach::{attachment, create, detach};
use super::clips::EffectHandle;
use super::plugin::{ClipPreferences, FramesNeeded, ImageEffect, ParamChange, RenderArgs, Rois};
use super::props::PropSet;
use super::{describe, host, planes, Failure, Outcome, Reply, BAD_INPUT_ID};

/// The main entry point of node type `E` (`OfxPluginEntryPoint`).
///
/// # Safety
/// The arguments are an OFX main entry's, as the host passed them: `action`
/// null or a NUL-terminated string; `handle` null or the effect handle of
/// the action; `in_args` and `out_args` null or the action's property sets;
/// all valid until this call returns (instance handles longer: until
/// destroyInstance), which the OFX API promises of every host.
pub unsafe extern "C" fn main_entry<E: ImageEffect>(
    action: *const c_char,
    handle: *const c_void,
    in_args: OfxPropertySetHandle,
    out_args: OfxPropertySetHandle,
) -> OfxStatus {
    if action.is_null() {
        return kOfxStatErrBadHandle;
    }
    // SAFETY: the host passes a NUL-terminated action name (checked non-null).
    let action = unsafe { CStr::from_ptr(action) };
    let effect = (!handle.is_null()).then(|| {
        // SAFETY: the action's effect handle, per this function's contract.
        unsafe { EffectHandle::from_raw(handle) }
    });
    let args = |p: OfxPropertySetHandle| {
        (!p.is_null()).then(|| {
            // SAFETY: one of the action's property sets, per this function's contract.
            unsafe { PropSet::from_raw(p) }
        })
    };
    let (in_args, out_args) = (args(in_args), args(out_args));
    let result = catch_unwind(AssertUnwindSafe(|| {
        let forced = &host::switches().force_panic;
        if forced
            .as_ref()
            .is_some_and(|a| a.as_bytes() == action.to_bytes())
        {
            panic!(
                "forced panic in {} (MORPHFX_FORCE_PANIC)",
                action.to_string_lossy()
            );
        }
        // Suites may be fetched from the load action on (not in setHost).
        if action == kOfxActionLoad {
            return host::load().map(|()| Reply::Done);
        }
        let effect = effect.clone().transpose()?;
        let in_args = in_args.clone().transpose()?;
        let out_args = out_args.clone().transpose()?;
        run::<E>(action, effect, in_args, out_args)
    }));
    let effect = effect.and_then(Result::ok);
    match result {
        Ok(Ok(Reply::Done)) => kOfxStatOK,
        Ok(Ok(Reply::Default)) => kOfxStatReplyDefault,
        Ok(Err(failure)) => {
            report(effect.as_ref(), action, &failure);
            failure.status()
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| panic.downcast_ref::<&str>().copied())
                .unwrap_or("unknown panic");
            let failure = Failure::Failed(format!(
                "internal error in {}: {what}",
                action.to_string_lossy()
            ));
            // Reporting must not unwind either.
            let _ = catch_unwind(AssertUnwindSafe(|| {
                report(effect.as_ref(), action, &failure)
            }));
            kOfxStatFailed
        }
    }
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

/// Runs one action of an `E` node; [`Reply::Default`] for actions left to
/// the host.
fn run<E: ImageEffect>(
    action: &CStr,
    effect: Option<EffectHandle>,
    in_args: Option<PropSet>,
    out_args: Option<PropSet>,
) -> Outcome<Reply> {
    if action == kOfxActionUnload {
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
    if action == kOfxActionDescribe {
        describe::describe::<E>(&effect)?;
    } else if action == kOfxImageEffectActionDescribeInContext {
        describe::describe_in_context::<E>(&effect, &in_props()?)?;
    } else if action == kOfxActionCreateInstance {
        create::<E>(&effect)?;
    } else if action == kOfxActionDestroyInstance {
        detach(&effect)?;
    } else if action == kOfxActionPurgeCaches {
        with_node(&effect, |n: &E| {
            n.purge();
            Ok(())
        })?;
    } else if action == kOfxImageEffectActionGetRegionOfDefinition {
        return region_of_definition::<E>(&effect, &in_props()?, &out_props()?);
    } else if action == kOfxImageEffectActionGetRegionsOfInterest {
        return regions_of_interest::<E>(&effect, &in_props()?, &out_props()?);
    } else if action == kOfxImageEffectActionGetFramesNeeded {
        return frames_needed::<E>(&effect, &in_props()?, &out_props()?);
    } else if action == kOfxImageEffectActionGetClipPreferences {
        return clip_preferences::<E>(&effect, &out_props()?);
    } else if action == kOfxImageEffectActionIsIdentity {
        return is_identity::<E>(&effect, &in_props()?, &out_props()?);
    } else if action == kOfxImageEffectActionRender {
        render::<E>(&effect, &in_props()?)?;
    } else if action == kOfxActionInstanceChanged {
        param_changed::<E>(&effect, &in_props()?)?;
    } else if action == planes::GET_CLIP_COMPONENTS {
        return clip_planes::<E>(&effect, &in_props()?, &out_props()?);
    } else {
        return Ok(Reply::Default);
    }
    Ok(Reply::Done)
}

/// Runs `act` on the instance's node, held for the call even if the host
/// destroys the instance meanwhile.
fn with_node<E: ImageEffect, R>(
    effect: &EffectHandle,
    act: impl FnOnce(&E) -> Outcome<R>,
) -> Outcome<R> {
    let attached = attachment(effect)?;
    act(attached.node::<E>()?)
}

fn region_of_definition<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let Some(r) = with_node(effect, |n: &E| n.region_of_definition(effect, time))? else {
        return Ok(Reply::Default);
    };
    out_args.set_doubles(
        kOfxImageEffectPropRegionOfDefinition,
        &[r.x1, r.y1, r.x2, r.y2],
    )?;
    Ok(Reply::Done)
}

fn regions_of_interest<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let mut rois = Rois::default();
    let reply = with_node(effect, |n: &E| {
        n.regions_of_interest(effect, time, &mut rois)
    })?;
    for (clip, r) in rois.set {
        let prop = CString::new(format!("OfxImageClipPropRoI_{clip}")).unwrap_or_default();
        out_args.set_doubles(&prop, &[r.x1, r.y1, r.x2, r.y2])?;
    }
    Ok(reply)
}

fn frames_needed<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let mut needed = FramesNeeded::default();
    let reply = with_node(effect, |n: &E| n.frames_needed(effect, time, &mut needed))?;
    for (clip, (a, b)) in needed.set {
        let prop = CString::new(format!("OfxImageClipPropFrameRange_{clip}")).unwrap_or_default();
        out_args.set_doubles(&prop, &[a, b])?;
    }
    Ok(reply)
}

fn clip_preferences<E: ImageEffect>(effect: &EffectHandle, out_args: &PropSet) -> Outcome<Reply> {
    let mut prefs = ClipPreferences::default();
    let reply = with_node(effect, |n: &E| n.clip_preferences(effect, &mut prefs))?;
    if let Some(varying) = prefs.frame_varying {
        out_args.set_int(kOfxImageEffectFrameVarying, 0, varying as i32)?;
    }
    if prefs.rgba_output {
        // The spec: `OfxImageClipPropComponents_` with the clip's name.
        out_args.set_string(
            c"OfxImageClipPropComponents_Output",
            0,
            &kOfxImageComponentRGBA.to_string_lossy(),
        )?;
    }
    if let Some(premultiplied) = prefs.premultiplied_output {
        let state = if premultiplied {
            kOfxImagePreMultiplied
        } else {
            kOfxImageUnPreMultiplied
        };
        out_args.set_string(
            kOfxImageEffectPropPreMultiplication,
            0,
            &state.to_string_lossy(),
        )?;
    }
    Ok(reply)
}

/// A render's or an identity question's arguments.
fn render_args(in_args: &PropSet) -> Outcome<RenderArgs> {
    let [x1, y1, x2, y2] = in_args.get_ints::<4>(kOfxImageEffectPropRenderWindow)?;
    Ok(RenderArgs {
        time: in_args.get_double(kOfxPropTime, 0)?,
        window: RectI::new(x1, y1, x2, y2),
        sequential: in_args
            .get_int(kOfxImageEffectPropSequentialRenderStatus, 0)
            .unwrap_or(0)
            == 1,
        interactive: in_args
            .get_int(kOfxImageEffectPropInteractiveRenderStatus, 0)
            .unwrap_or(0)
            == 1,
        // Hosts without the extension have no such property: colour alone.
        planes: in_args
            .get_strings(planes::RENDER_PLANES)
            .unwrap_or_default(),
    })
}

/// `GetClipComponents`: the planes each clip needs and the output makes,
/// and where the rest pass through from.
fn clip_planes<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let time = in_args.get_double(kOfxPropTime, 0)?;
    let mut answer = planes::ClipPlanes::default();
    let reply = with_node(effect, |n: &E| n.clip_planes(effect, time, &mut answer))?;
    for (clip, list) in &answer.needed {
        let prop = CString::new(format!("{}{clip}", planes::NEEDED_PREFIX)).unwrap_or_default();
        let list: Vec<&str> = list.iter().map(String::as_str).collect();
        out_args.set_strings(&prop, &list)?;
    }
    if let Some((clip, at)) = answer.pass_through {
        out_args.set_string(planes::PASS_THROUGH_CLIP, 0, clip)?;
        out_args.set_double(planes::PASS_THROUGH_TIME, 0, at)?;
    }
    Ok(reply)
}

fn is_identity<E: ImageEffect>(
    effect: &EffectHandle,
    in_args: &PropSet,
    out_args: &PropSet,
) -> Outcome<Reply> {
    let args = render_args(in_args)?;
    let Some(identity) = with_node(effect, |n: &E| n.is_identity(effect, &args))? else {
        return Ok(Reply::Default);
    };
    out_args.set_string(kOfxPropName, 0, identity.clip)?;
    out_args.set_double(kOfxPropTime, 0, identity.time)?;
    Ok(Reply::Done)
}

fn render<E: ImageEffect>(effect: &EffectHandle, in_args: &PropSet) -> Outcome {
    let args = render_args(in_args)?;
    let attached = attachment(effect)?;
    attached.node::<E>()?.render(effect, &args)?;
    // A good render clears the persistent error a failed one left.
    if attached.error_shown.swap(false, Ordering::AcqRel) {
        effect.clear_persistent();
    }
    Ok(())
}

fn param_changed<E: ImageEffect>(effect: &EffectHandle, in_args: &PropSet) -> Outcome {
    let change = ParamChange {
        name: in_args.get_string(kOfxPropName, 0)?,
        time: in_args.get_double(kOfxPropTime, 0)?,
    };
    with_node(effect, |n: &E| n.param_changed(effect, &change))
}

/// Actions a host runs on render threads (or may): their failures go to the
/// node's persistent message, since a transient one becomes a modal dialog
/// per frame and thread in some hosts (Natron).
const RENDER_TIME: [&CStr; 7] = [
    kOfxImageEffectActionRender,
    kOfxImageEffectActionGetRegionOfDefinition,
    kOfxImageEffectActionGetRegionsOfInterest,
    kOfxImageEffectActionGetFramesNeeded,
    kOfxImageEffectActionIsIdentity,
    kOfxImageEffectActionBeginSequenceRender,
    kOfxImageEffectActionEndSequenceRender,
];

fn report(effect: Option<&EffectHandle>, action: &CStr, failure: &Failure) {
    let id = match failure {
        Failure::BadInput(_) => BAD_INPUT_ID,
        _ => c"net.morphfx.Error",
    };
    let text = failure.message();
    let effect = match effect {
        Some(effect) => effect,
        None => {
            let text = format!("{}: {text}", action.to_string_lossy());
            return host::unowned_error(id, &text);
        }
    };
    if RENDER_TIME.contains(&action) {
        if let Ok(attached) = attachment(effect) {
            if effect.persistent_error(id, text) {
                attached.error_shown.store(true, Ordering::Release);
                return;
            }
        }
    }
    effect.error(id, text);
}
