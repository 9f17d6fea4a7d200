//! The filters' arithmetic shared by the general sampler and the direct
//! float RGBA path: a position's integer part and fraction, snapped near
//! pixel centres, and the Catmull-Rom (a = −0.5) weights.

use wide::f32x8;

/// Fractions this close to a pixel centre snap to it, so warps that land on
/// centres up to float round-off copy pixels exactly instead of blurring.
/// The direct path's four-at-a-time loop leaves positions this close to
/// its one-pixel path, which snaps them as the general sampler does.
pub(crate) const SNAP: f32 = 1e-4;

/// [`catmull_rom_weights`] for eight fractions at once.
#[inline(always)]
pub(crate) fn catmull_rom_weights8(t: f32x8) -> [f32x8; 4] {
    let h = f32x8::splat(0.5);
    let c = f32x8::splat;
    let t2 = t * t;
    let t3 = t2 * t;
    [
        h * (-t3 + c(2.0) * t2 - t),
        h * (c(3.0) * t3 - c(5.0) * t2 + c(2.0)),
        h * (c(-3.0) * t3 + c(4.0) * t2 + t),
        h * (t3 - t2),
    ]
}

/// Catmull-Rom weights for taps at offsets −1, 0, 1, 2 from the fraction `t`.
#[inline]
pub(crate) fn catmull_rom_weights(t: f32) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// Integer part and fraction, with fractions within [`SNAP`] of a centre snapped.
#[inline]
pub(crate) fn split(f: f32) -> (i32, f32) {
    // Beyond 2^24 f32 holds no fraction; clamping keeps the integer part in
    // i32 range. A cast-and-correct floor: `f32::floor` is a libm call on
    // baseline x86-64.
    let f = f.clamp(-16_777_216.0, 16_777_216.0);
    let mut i = f as i32;
    if i as f32 > f {
        i -= 1;
    }
    let t = f - i as f32;
    if t < SNAP {
        (i, 0.0)
    } else if t > 1.0 - SNAP {
        (i + 1, 0.0)
    } else {
        (i, t)
    }
}
