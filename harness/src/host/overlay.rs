//! [`Overlay`] drives a plugin's overlay interact the way a viewer does:
//! draw, pen and key events, through this host's interact and Draw suites.

use std::ffi::{c_char, c_void, CStr};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::image_effect::*;
use openfx::sys::image_effect_v1::interact::*;
use openfx::sys::image_effect_v1::key_syms::kOfxPropKeySym;

use super::interact_suites::{Context, Interact};
pub use super::interact_suites::{DrawCall, DRAW_SUITE_PROP};
use super::params::Inside;
use super::props::{PropertySet, Value};
use super::{HostError, Instance};
use crate::sync::Locked;

type Entry = unsafe extern "C" fn(
    *const c_char,
    *const c_void,
    OfxPropertySetHandle,
    OfxPropertySetHandle,
) -> OfxStatus;

/// How the plugin answered an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Answer {
    /// It used the event (`kOfxStatOK`).
    Trapped,
    /// It left the event to the host (`kOfxStatReplyDefault`).
    Default,
}

/// A plugin's overlay interact, described and instantiated on an instance.
pub struct Overlay<'i> {
    instance: &'i Instance<'i>,
    entry: Entry,
    _descriptor: Box<Interact>,
    interact: Box<Interact>,
    /// Every draw context ever handed out: kept, so a late use is seen.
    /// Boxed: the plugin holds their addresses, which must not move.
    #[allow(clippy::vec_box)]
    contexts: Mutex<Vec<Box<Context>>>,
    draw_suite: bool,
}

impl<'i> Overlay<'i> {
    /// Describes and creates `instance`'s overlay: the V2 (Draw suite)
    /// entry when `draw_suite`, else V1; `None` when it declares none.
    pub fn new(instance: &'i Instance<'i>, draw_suite: bool) -> Result<Option<Self>, HostError> {
        let props = instance.descriptor_props();
        let pointer = |name: &CStr| match props.get(&name.to_string_lossy()) {
            Some(Value::P(p)) if p.first().is_some_and(|p| *p != 0) => Some(p[0]),
            _ => None,
        };
        let entry = if draw_suite {
            pointer(kOfxImageEffectPluginPropOverlayInteractV2)
        } else {
            None
        };
        let Some(entry) = entry.or_else(|| pointer(kOfxImageEffectPluginPropOverlayInteractV1))
        else {
            return Ok(None);
        };
        // SAFETY: the plugin declared this pointer as an OFX entry point.
        let entry: Entry = unsafe { std::mem::transmute::<usize, Entry>(entry) };
        let new_interact = || {
            Box::new(Interact {
                props: PropertySet::new(),
                redraws: AtomicUsize::new(0),
            })
        };
        let descriptor = new_interact();
        descriptor.props.set_int(kOfxInteractPropHasAlpha, &[1]);
        descriptor.props.set_int(kOfxInteractPropBitDepth, &[8]);
        let interact = new_interact();
        let p = &interact.props;
        p.set_ptr(
            kOfxPropEffectInstance,
            instance.effect.handle() as *mut c_void,
        );
        p.set_double(kOfxInteractPropPixelScale, &[1.0, 1.0]);
        p.set_double(kOfxInteractPropBackgroundColour, &[0.0, 0.0, 0.0]);
        p.set_int(kOfxInteractPropHasAlpha, &[1]);
        p.set_int(kOfxInteractPropBitDepth, &[8]);
        let overlay = Overlay {
            instance,
            entry,
            _descriptor: descriptor,
            interact,
            contexts: Mutex::new(Vec::new()),
            draw_suite,
        };
        let describe = &*overlay._descriptor as *const Interact as *const c_void;
        overlay.call_on(describe, kOfxActionDescribe, None)?;
        overlay.call(kOfxActionCreateInstance, None)?;
        Ok(Some(overlay))
    }

    fn call_on(
        &self,
        handle: *const c_void,
        action: &CStr,
        args: Option<&PropertySet>,
    ) -> Result<Answer, HostError> {
        let _inside = Inside::action(action);
        let a = args.map_or(std::ptr::null_mut(), |a| a.handle());
        // SAFETY: the plugin's own entry point, with our live objects.
        let st = unsafe { (self.entry)(action.as_ptr(), handle, a, std::ptr::null_mut()) };
        match st {
            s if s == kOfxStatOK => Ok(Answer::Trapped),
            s if s == kOfxStatReplyDefault => Ok(Answer::Default),
            s => Err(HostError::failed(format!(
                "overlay {}: OFX status {s}",
                action.to_string_lossy()
            ))),
        }
    }

    fn call(&self, action: &CStr, args: Option<&PropertySet>) -> Result<Answer, HostError> {
        let handle = &*self.interact as *const Interact as *const c_void;
        self.call_on(handle, action, args)
    }

    /// The interact's own properties (slaved params, ...).
    pub fn props(&self) -> &PropertySet {
        &self.interact.props
    }

    /// Redraws the plugin has asked for so far.
    pub fn redraws(&self) -> usize {
        self.interact.redraws.load(Ordering::Acquire)
    }

    fn args(&self, time: f64, pixel: (f64, f64)) -> PropertySet {
        let a = PropertySet::new();
        a.set_ptr(
            kOfxPropEffectInstance,
            self.instance.effect.handle() as *mut c_void,
        );
        a.set_double(kOfxInteractPropPixelScale, &[pixel.0, pixel.1]);
        a.set_double(kOfxInteractPropBackgroundColour, &[0.0, 0.0, 0.0]);
        a.set_double(kOfxPropTime, &[time]);
        a.set_double(kOfxImageEffectPropRenderScale, &[1.0, 1.0]);
        a
    }

    /// The draw action at `time`, `pixel` canonical units per screen pixel:
    /// what the plugin drew (nothing without the Draw suite).
    pub fn draw(&self, time: f64, pixel: (f64, f64)) -> Result<Vec<DrawCall>, HostError> {
        let a = self.args(time, pixel);
        let context = Box::new(Context {
            calls: Mutex::new(Vec::new()),
            open: AtomicBool::new(true),
        });
        if self.draw_suite {
            a.set_ptr(
                kOfxInteractPropDrawContext,
                &*context as *const Context as *mut c_void,
            );
        }
        let result = self.call(kOfxInteractActionDraw, Some(&a));
        context.open.store(false, Ordering::Release);
        let calls = std::mem::take(&mut *context.calls.locked());
        self.contexts.locked().push(context);
        result.map(|_| calls)
    }

    /// A pen event (`kOfxInteractActionPen*`) at canonical `at`.
    pub fn pen(
        &self,
        action: &CStr,
        time: f64,
        at: (f64, f64),
        pixel: (f64, f64),
    ) -> Result<Answer, HostError> {
        let a = self.args(time, pixel);
        a.set_double(kOfxInteractPropPenPosition, &[at.0, at.1]);
        let viewport = [(at.0 / pixel.0) as i32, (at.1 / pixel.1) as i32];
        a.set_int(kOfxInteractPropPenViewportPosition, &viewport);
        a.set_double(kOfxInteractPropPenPressure, &[1.0]);
        self.call(action, Some(&a))
    }

    /// A key event (`kOfxInteractActionKey*`) for keysym `sym`.
    pub fn key(&self, action: &CStr, time: f64, sym: i32) -> Result<Answer, HostError> {
        let a = self.args(time, (1.0, 1.0));
        a.set_int(kOfxPropKeySym, &[sym]);
        a.set_str(
            openfx::sys::image_effect_v1::key_syms::kOfxPropKeyString,
            "",
        );
        self.call(action, Some(&a))
    }

    /// A click: pen down and up at `at`, what the pen down answered.
    pub fn click(&self, time: f64, at: (f64, f64), pixel: (f64, f64)) -> Result<Answer, HostError> {
        let down = self.pen(kOfxInteractActionPenDown, time, at, pixel)?;
        self.pen(kOfxInteractActionPenUp, time, at, pixel)?;
        Ok(down)
    }

    /// A whole drag: pen down at `from`, motion to `to`, pen up there.
    pub fn drag(
        &self,
        time: f64,
        from: (f64, f64),
        to: (f64, f64),
        pixel: (f64, f64),
    ) -> Result<Answer, HostError> {
        let down = self.pen(kOfxInteractActionPenDown, time, from, pixel)?;
        let mid = ((from.0 + to.0) / 2.0, (from.1 + to.1) / 2.0);
        self.pen(kOfxInteractActionPenMotion, time, mid, pixel)?;
        self.pen(kOfxInteractActionPenMotion, time, to, pixel)?;
        self.pen(kOfxInteractActionPenUp, time, to, pixel)?;
        Ok(down)
    }
}

impl Drop for Overlay<'_> {
    fn drop(&mut self) {
        let _ = self.call(kOfxActionDestroyInstance, None);
    }
}
