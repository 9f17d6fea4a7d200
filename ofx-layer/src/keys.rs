//! The key symbols overlays react to (OFX key symbols, X11's values).

use openfx::sys::image_effect_v1::key_syms::*;

/// Left and right Shift.
pub const SHIFT: [i32; 2] = [kOfxKey_Shift_L as i32, kOfxKey_Shift_R as i32];
/// Left and right Control.
pub const CONTROL: [i32; 2] = [kOfxKey_Control_L as i32, kOfxKey_Control_R as i32];
/// Delete and BackSpace.
pub const DELETE: [i32; 2] = [kOfxKey_Delete as i32, kOfxKey_BackSpace as i32];
/// Return and the keypad's Enter: end the shape being drawn.
pub const FINISH: [i32; 2] = [kOfxKey_Return as i32, kOfxKey_KP_Enter as i32];
/// Escape.
pub const ESCAPE: [i32; 1] = [kOfxKey_Escape as i32];
