//! The suites overlays use in our host: the interact suite, and a Draw
//! suite that records every call (and checks it). [`super::overlay`]
//! drives a plugin's overlay interact through them.

use std::ffi::{c_char, c_int, CStr};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use openfx::sys::generic::core::*;
pub use openfx::sys::image_effect_v1::draw_suite::kOfxDrawSuite;
use openfx::sys::image_effect_v1::draw_suite::*;
pub use openfx::sys::image_effect_v1::interact::kOfxInteractSuite;
use openfx::sys::image_effect_v1::interact::*;
use openfx::sys::image_effect_v1::pixels::OfxRGBAColourF;

use super::checks::violation;
use super::props::PropertySet;
use crate::sync::Locked;

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
pub(super) struct Context {
    pub(super) calls: Mutex<Vec<DrawCall>>,
    pub(super) open: AtomicBool,
}

/// An interact object: its properties and the redraws it asked for.
pub(super) struct Interact {
    pub(super) props: PropertySet,
    pub(super) redraws: AtomicUsize,
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
            c.calls.locked().push(call);
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
