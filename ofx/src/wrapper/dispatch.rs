//! The one door every action comes through: null checks, unwinds caught,
//! failures reported through the message suite and mapped to OFX statuses.

use std::ffi::{c_char, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::image_effect::*;

use super::clips::Effect;
use super::props::PropSet;
use super::{Failure, Outcome, Reply, BAD_INPUT_ID};
use crate::nodes::{self, Instance, NodeKind};

/// Runs `action` of a `kind` node and answers its status.
///
/// # Safety
/// The arguments are an OFX main entry's, as the host passed them: `action`
/// null or a NUL-terminated string; `handle` null or the effect handle of
/// the action; `in_args` and `out_args` null or the action's property sets;
/// all valid until this call returns (instance handles longer: until
/// destroyInstance), which the OFX API promises of every host.
pub unsafe fn dispatch(
    kind: NodeKind,
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
        unsafe { Effect::from_raw(handle) }
    });
    let args = |p: OfxPropertySetHandle| {
        (!p.is_null()).then(|| {
            // SAFETY: one of the action's property sets, per this function's contract.
            unsafe { PropSet::from_raw(p) }
        })
    };
    let (in_args, out_args) = (args(in_args), args(out_args));
    let result = catch_unwind(AssertUnwindSafe(|| {
        let forced = &super::host::switches().force_panic;
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
            return super::host::load().map(|()| Reply::Done);
        }
        let effect = effect.clone().transpose()?;
        let in_args = in_args.clone().transpose()?;
        let out_args = out_args.clone().transpose()?;
        nodes::action(kind, action, effect, in_args, out_args)
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

fn report(effect: Option<&Effect>, action: &CStr, failure: &Failure) {
    let id = match failure {
        Failure::BadInput(_) => BAD_INPUT_ID,
        _ => c"net.morphfx.Error",
    };
    let text = failure.message();
    let effect = match effect {
        Some(effect) => effect,
        None => {
            let text = format!("{}: {text}", action.to_string_lossy());
            return super::host::unowned_error(id, &text);
        }
    };
    if RENDER_TIME.contains(&action) {
        if let Ok(instance) = instance(effect) {
            if effect.persistent_error(id, text) {
                instance
                    .error_shown
                    .store(true, std::sync::atomic::Ordering::Release);
                return;
            }
        }
    }
    effect.error(id, text);
}

/// After a good render: clears the persistent error a failed one left.
pub fn render_succeeded(effect: &Effect) {
    if let Ok(instance) = instance(effect) {
        if instance
            .error_shown
            .swap(false, std::sync::atomic::Ordering::AcqRel)
        {
            effect.clear_persistent();
        }
    }
}

/// Stores `instance` in the effect's instance data (created in createInstance).
pub fn attach_instance(effect: &Effect, instance: Arc<Instance>) -> Outcome {
    let raw = Arc::into_raw(instance) as *mut c_void;
    effect
        .props()?
        .set_pointer(kOfxPropInstanceData, 0, raw)
        .inspect_err(|_| {
            // SAFETY: `raw` came from Arc::into_raw just above and was not stored.
            drop(unsafe { Arc::from_raw(raw as *const Instance) });
        })
}

/// Takes the instance data back and drops our reference (destroyInstance).
pub fn detach_instance(effect: &Effect) -> Outcome {
    let props = effect.props()?;
    let raw = props.get_pointer(kOfxPropInstanceData, 0)?;
    if raw.is_null() {
        return Ok(());
    }
    props.set_pointer(kOfxPropInstanceData, 0, std::ptr::null_mut())?;
    // SAFETY: a non-null instance pointer is only ever one made by
    // `attach_instance` from Arc::into_raw; it is cleared above so this is its
    // only release. Renders still running hold their own clones.
    drop(unsafe { Arc::from_raw(raw as *const Instance) });
    Ok(())
}

/// The instance's state, as a reference-counted handle that stays valid even
/// if the host destroys the instance while this call runs.
pub fn instance(effect: &Effect) -> Outcome<Arc<Instance>> {
    let raw = effect.props()?.get_pointer(kOfxPropInstanceData, 0)?;
    if raw.is_null() {
        return Err(Failure::Failed(
            "instance has no data: createInstance was not called".into(),
        ));
    }
    let raw = raw as *const Instance;
    // SAFETY: `raw` came from Arc::into_raw in `attach_instance` and the
    // attachment's count is still held (it is cleared before release), so
    // taking one more strong count and materialising it is sound.
    unsafe {
        Arc::increment_strong_count(raw);
        Ok(Arc::from_raw(raw))
    }
}
