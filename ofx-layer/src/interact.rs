//! The overlay interact's entry point, made per node type: the same door
//! discipline as [`super::dispatch`] (null checks, unwinds caught, statuses
//! mapped), the host's interact arguments read into typed values, and the
//! painter chosen: the Draw suite when the draw action carries a context,
//! else OpenGL.

use std::ffi::{c_char, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

use morphfx::geom::Vec2;
use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::interact::*;
use openfx::sys::image_effect_v1::key_syms::kOfxPropKeySym;

use super::attach::attachment;
use super::clips::EffectHandle;
use super::draw::DrawSuitePainter;
use super::gl::GlPainter;
use super::plugin::{DrawArgs, ImageEffect, OverlayActions, Pen};
use super::props::PropSet;
use super::{host, Failure, Outcome, Reply};

/// The overlay interact's main entry point of node type `E`.
///
/// # Safety
/// `action` null or NUL-terminated; `handle` null or the interact handle
/// of the action; `in_args` null or the action's property set; all valid
/// until this call returns, as OFX promises of every host. Interacts have
/// no out-args.
pub(super) unsafe extern "C" fn main_entry<E: ImageEffect>(
    action: *const c_char,
    handle: *const c_void,
    in_args: OfxPropertySetHandle,
    _out_args: OfxPropertySetHandle,
) -> OfxStatus {
    if action.is_null() || handle.is_null() {
        return kOfxStatErrBadHandle;
    }
    // SAFETY: non-null and NUL-terminated (the host's action name).
    let action = unsafe { CStr::from_ptr(action) };
    let interact = handle as OfxInteractHandle;
    let in_args = (!in_args.is_null()).then(|| {
        // SAFETY: the action's in-args, per this function's contract.
        unsafe { PropSet::from_raw(in_args) }
    });
    let result = catch_unwind(AssertUnwindSafe(|| {
        let in_args = in_args.transpose()?;
        // SAFETY: `interact` is the action's interact handle.
        unsafe { run::<E>(action, interact, in_args) }
    }));
    match result {
        Ok(Ok(Reply::Done)) => kOfxStatOK,
        Ok(Ok(Reply::Default)) => kOfxStatReplyDefault,
        Ok(Err(failure)) => {
            let _ = catch_unwind(|| {
                eprintln!(
                    "MorphFX overlay: {}: {}",
                    action.to_string_lossy(),
                    failure.message()
                )
            });
            failure.status()
        }
        Err(_) => kOfxStatFailed,
    }
}

/// Reads one interact action's arguments and hands them to `E`'s overlay.
///
/// # Safety
/// `interact` is the live interact handle of the action.
unsafe fn run<E: ImageEffect>(
    action: &CStr,
    interact: OfxInteractHandle,
    in_args: Option<PropSet>,
) -> Outcome<Reply> {
    let suite = host::suites()?
        .interact
        .ok_or_else(|| Failure::Failed("host has no interact suite".into()))?;
    if action == kOfxActionDescribe || action == kOfxActionDestroyInstance {
        return Ok(Reply::Done);
    }
    // Described only for effects with an overlay; a host that calls
    // anyway is left to its default.
    let Some(overlay) = E::OVERLAY else {
        return Ok(Reply::Default);
    };
    // SAFETY: the caller's interact handle.
    let props = unsafe { props_of(suite, interact)? };
    if action == kOfxActionCreateInstance {
        // Redraw when any param the overlay shows changes.
        let ids = (overlay.slave_params)();
        let _ = props.set_strings(
            kOfxInteractPropSlaveToParam,
            &ids.iter().map(String::as_str).collect::<Vec<_>>(),
        );
        return Ok(Reply::Done);
    }
    let args = in_args.ok_or_else(|| {
        Failure::Status(
            kOfxStatErrBadHandle,
            "interact action without in-args".into(),
        )
    })?;
    let effect = effect_of(&args, &props)?;
    let attached = attachment(&effect)?;
    let node = attached.node::<E>()?;
    let time = args.get_double(kOfxPropTime, 0)?;
    if action == kOfxInteractActionDraw {
        // SAFETY: `args` are the draw action's, read during it.
        return unsafe { draw(&overlay, node, &effect, &args, time) };
    }
    if action == kOfxInteractActionKeyDown || action == kOfxInteractActionKeyRepeat {
        let sym = args.get_int(kOfxPropKeySym, 0)?;
        return (overlay.key_down)(node, &effect, sym, time);
    }
    if action == kOfxInteractActionKeyUp {
        return (overlay.key_up)(node, &effect, args.get_int(kOfxPropKeySym, 0)?);
    }
    if action == kOfxInteractActionLoseFocus {
        return (overlay.lose_focus)(node, &effect);
    }
    let pen = || -> Outcome<Pen> {
        let [x, y] = args.get_doubles::<2>(kOfxInteractPropPenPosition)?;
        Ok(Pen {
            time,
            at: Vec2::new(x, y),
            pixel: pixel_scale(&args),
        })
    };
    if action == kOfxInteractActionPenDown {
        (overlay.pen_down)(node, &effect, pen()?)
    } else if action == kOfxInteractActionPenMotion {
        let mut redraw = || {
            if let Some(f) = suite.interactRedraw {
                // SAFETY: the live interact handle.
                unsafe { f(interact) };
            }
        };
        (overlay.pen_motion)(node, &effect, pen()?, &mut redraw)
    } else if action == kOfxInteractActionPenUp {
        (overlay.pen_up)(node, &effect, pen()?)
    } else {
        Ok(Reply::Default)
    }
}

/// # Safety
/// `interact` is a live interact handle.
unsafe fn props_of(suite: &OfxInteractSuiteV1, interact: OfxInteractHandle) -> Outcome<PropSet> {
    let get = suite
        .interactGetPropertySet
        .ok_or_else(|| Failure::Failed("host has no interactGetPropertySet".into()))?;
    let mut props: OfxPropertySetHandle = std::ptr::null_mut();
    // SAFETY: the live handle and an out-pointer on our stack.
    let status = unsafe { get(interact, &mut props) };
    super::check(status, "interactGetPropertySet")?;
    // SAFETY: the host's property set of the interact, live as long as it.
    unsafe { PropSet::from_raw(props) }
}

/// The effect the interact belongs to: named in the action's arguments,
/// or in the interact's own properties.
fn effect_of(args: &PropSet, props: &PropSet) -> Outcome<EffectHandle> {
    let handle = args
        .get_pointer(kOfxPropEffectInstance, 0)
        .ok()
        .filter(|p| !p.is_null())
        .or_else(|| props.get_pointer(kOfxPropEffectInstance, 0).ok())
        .filter(|p| !p.is_null())
        .ok_or_else(|| {
            Failure::Status(kOfxStatErrBadHandle, "interact without its effect".into())
        })?;
    // SAFETY: the host names the interact's effect instance, which
    // outlives its interacts (OFX: an interact is bound to one instance).
    unsafe { EffectHandle::from_raw(handle) }
}

/// Canonical units per screen pixel as the host says (1, 1 when it does not).
fn pixel_scale(args: &PropSet) -> (f64, f64) {
    match args.get_doubles::<2>(kOfxInteractPropPixelScale) {
        Ok([x, y]) if x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite() => (x, y),
        _ => (1.0, 1.0),
    }
}

/// # Safety
/// `args` are the running draw action's arguments.
unsafe fn draw<E>(
    overlay: &OverlayActions<E>,
    node: &E,
    effect: &EffectHandle,
    args: &PropSet,
    time: f64,
) -> Outcome<Reply> {
    let pixel = pixel_scale(args);
    let context = args
        .get_pointer(kOfxInteractPropDrawContext, 0)
        .ok()
        .filter(|p| !p.is_null());
    if let (Some(context), Some(suite)) = (context, host::suites()?.draw) {
        // SAFETY: the draw action's own context, used only during it.
        let mut painter = unsafe { DrawSuitePainter::new(suite, context as OfxDrawContextHandle) };
        let args = DrawArgs {
            time,
            pixel,
            measured: false,
        };
        return (overlay.draw)(node, effect, &args, &mut painter);
    }
    match GlPainter::new(pixel) {
        Some(mut painter) => {
            let args = DrawArgs {
                time,
                pixel: painter.pixel(),
                measured: true,
            };
            (overlay.draw)(node, effect, &args, &mut painter)
        }
        // No Draw suite and no GL context: nothing to draw with.
        None => Ok(Reply::Done),
    }
}
