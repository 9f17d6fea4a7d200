//! Overlays in our host: the interact suite, a Draw suite that records
//! every call (and checks it), and [`Overlay`], which drives a plugin's
//! overlay interact the way a viewer does: draw, pen and key events.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
pub use openfx::sys::image_effect_v1::draw_suite::kOfxDrawSuite;
use openfx::sys::image_effect_v1::draw_suite::*;
use openfx::sys::image_effect_v1::image_effect::*;
pub use openfx::sys::image_effect_v1::interact::kOfxInteractSuite;
use openfx::sys::image_effect_v1::interact::*;
use openfx::sys::image_effect_v1::key_syms::kOfxPropKeySym;
use openfx::sys::image_effect_v1::pixels::OfxRGBAColourF;

use super::params::Inside;
use super::props::{PropertySet, Value};
use super::{violation, HostError, Instance};

/// Our host's own property: 1 when it offers the Draw suite.
pub const DRAW_SUITE_PROP: &CStr = c"net.morphfx.harness.DrawSuite";

/// One call the plugin made on a draw context.
#[derive(Debug, Clone, PartialEq)]
pub enum DrawCall {
    /// `setColour`: straight RGBA.
    Colour([f32; 4]),
    /// `setLineWidth`, screen pixels (0: one pixel).
    Width(f32),
    /// `setLineStipple`.
    Stipple(OfxDrawLineStipplePattern),
    /// `draw`: a primitive and its points (canonical).
    Draw {
        /// `kOfxDrawPrimitive*`.
        primitive: OfxDrawPrimitive,
        /// The points as given.
        points: Vec<[f64; 2]>,
    },
    /// `drawText`.
    Text {
        /// The text.
        text: String,
        /// Its baseline's start (canonical).
        at: [f64; 2],
        /// `kOfxDrawTextAlignment*` flags.
        align: i32,
    },
}

/// A draw context: open during its draw action only.
struct Context {
    calls: Mutex<Vec<DrawCall>>,
    open: AtomicBool,
}

/// An interact object: its properties and the redraws it asked for.
struct Interact {
    props: PropertySet,
    redraws: AtomicUsize,
}

/// # Safety
/// `h` null or a context this host made (they are never freed while the
/// overlay that made them lives).
unsafe fn context<'a>(h: OfxDrawContextHandle, what: &str) -> Option<&'a Context> {
    // SAFETY: per the contract.
    let c = unsafe { (h as *const Context).as_ref() }?;
    if !c.open.load(Ordering::Acquire) {
        violation(format!(
            "{what} on a draw context after its draw action returned"
        ));
        return None;
    }
    Some(c)
}

fn record(h: OfxDrawContextHandle, what: &str, call: DrawCall) -> OfxStatus {
    // SAFETY: the plugin passes the handle we gave it (checked there).
    match unsafe { context(h, what) } {
        Some(c) => {
            c.calls.lock().unwrap_or_else(|e| e.into_inner()).push(call);
            kOfxStatOK
        }
        None => kOfxStatFailed,
    }
}

unsafe extern "C" fn get_colour(
    h: OfxDrawContextHandle,
    _which: OfxStandardColour,
    colour: *mut OfxRGBAColourF,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_colour", || {
        // SAFETY: our own handle, checked.
        if unsafe { context(h, "getColour") }.is_none() || colour.is_null() {
            return kOfxStatFailed;
        }
        // SAFETY: non-null out-pointer from the plugin.
        unsafe {
            *colour = OfxRGBAColourF {
                r: 1.0,
                g: 1.0,
                b: 1.0,
                a: 1.0,
            }
        };
        kOfxStatOK
    })
}

unsafe extern "C" fn set_colour(h: OfxDrawContextHandle, c: *const OfxRGBAColourF) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "set_colour", || {
        // SAFETY: the plugin's colour, checked non-null.
        let Some(c) = (unsafe { c.as_ref() }) else {
            return kOfxStatErrValue;
        };
        record(h, "setColour", DrawCall::Colour([c.r, c.g, c.b, c.a]))
    })
}

unsafe extern "C" fn set_width(h: OfxDrawContextHandle, w: f32) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "set_width", || {
        if !(w >= 0.0 && w.is_finite()) {
            violation(format!("setLineWidth({w})"));
            return kOfxStatErrValue;
        }
        record(h, "setLineWidth", DrawCall::Width(w))
    })
}

unsafe extern "C" fn set_stipple(
    h: OfxDrawContextHandle,
    p: OfxDrawLineStipplePattern,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "set_stipple", || {
        if p > kOfxDrawLineStipplePatternDotDash {
            violation(format!("setLineStipple({p}): no such pattern"));
            return kOfxStatErrValue;
        }
        record(h, "setLineStipple", DrawCall::Stipple(p))
    })
}

/// Whether `n` points make a `primitive` (the OpenGL rules the suite names).
pub fn valid_count(primitive: OfxDrawPrimitive, n: usize) -> bool {
    if primitive == kOfxDrawPrimitiveLines {
        n >= 2 && n.is_multiple_of(2)
    } else if primitive == kOfxDrawPrimitiveLineStrip || primitive == kOfxDrawPrimitiveLineLoop {
        n >= 2
    } else if primitive == kOfxDrawPrimitiveRectangle || primitive == kOfxDrawPrimitiveEllipse {
        n == 2
    } else {
        primitive == kOfxDrawPrimitivePolygon && n >= 3
    }
}

unsafe extern "C" fn draw(
    h: OfxDrawContextHandle,
    primitive: OfxDrawPrimitive,
    points: *const OfxPointD,
    count: c_int,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "draw", || {
        let n = usize::try_from(count).unwrap_or(0);
        if points.is_null() || !valid_count(primitive, n) {
            violation(format!("draw(primitive {primitive}, {count} points)"));
            return kOfxStatErrValue;
        }
        // SAFETY: the plugin passes `count` points (checked non-null).
        let pts = unsafe { std::slice::from_raw_parts(points, n) };
        if pts.iter().any(|p| !(p.x.is_finite() && p.y.is_finite())) {
            violation("draw with a non-finite point".into());
            return kOfxStatErrValue;
        }
        let points = pts.iter().map(|p| [p.x, p.y]).collect();
        record(h, "draw", DrawCall::Draw { primitive, points })
    })
}

unsafe extern "C" fn draw_text(
    h: OfxDrawContextHandle,
    text: *const c_char,
    pos: *const OfxPointD,
    align: c_int,
) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "draw_text", || {
        if text.is_null() || pos.is_null() {
            return kOfxStatErrValue;
        }
        // SAFETY: a NUL-terminated string and a point from the plugin.
        let (text, pos) = unsafe { (CStr::from_ptr(text), &*pos) };
        let call = DrawCall::Text {
            text: text.to_string_lossy().into_owned(),
            at: [pos.x, pos.y],
            align,
        };
        record(h, "drawText", call)
    })
}

/// The Draw suite this host offers when asked to.
pub static DRAW_SUITE: OfxDrawSuiteV1 = OfxDrawSuiteV1 {
    getColour: Some(get_colour),
    setColour: Some(set_colour),
    setLineWidth: Some(set_width),
    setLineStipple: Some(set_stipple),
    draw: Some(draw),
    drawText: Some(draw_text),
};

/// # Safety
/// `h` null or an interact this host made and still holds.
unsafe fn interact<'a>(h: OfxInteractHandle) -> Option<&'a Interact> {
    // SAFETY: per the contract.
    unsafe { (h as *const Interact).as_ref() }
}

unsafe extern "C" fn swap_buffers(_: OfxInteractHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "swap_buffers", || {
        violation("interactSwapBuffers from an overlay (the host swaps)".into());
        kOfxStatFailed
    })
}

unsafe extern "C" fn redraw(h: OfxInteractHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "redraw", || {
        // SAFETY: the plugin passes its interact's handle.
        match unsafe { interact(h) } {
            Some(i) => {
                i.redraws.fetch_add(1, Ordering::AcqRel);
                kOfxStatOK
            }
            None => kOfxStatErrBadHandle,
        }
    })
}

unsafe extern "C" fn get_props(h: OfxInteractHandle, out: *mut OfxPropertySetHandle) -> OfxStatus {
    super::guard::guard(kOfxStatErrUnknown, "get_props", || {
        // SAFETY: the plugin's interact handle, and its out-pointer.
        match (unsafe { interact(h) }, out.is_null()) {
            (Some(i), false) => {
                // SAFETY: checked non-null.
                unsafe { *out = i.props.handle() };
                kOfxStatOK
            }
            _ => kOfxStatErrBadHandle,
        }
    })
}

/// The interact suite.
pub static INTERACT_SUITE: OfxInteractSuiteV1 = OfxInteractSuiteV1 {
    interactSwapBuffers: Some(swap_buffers),
    interactRedraw: Some(redraw),
    interactGetPropertySet: Some(get_props),
};

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
        let calls = std::mem::take(&mut *context.calls.lock().unwrap_or_else(|e| e.into_inner()));
        self.contexts
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(context);
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
